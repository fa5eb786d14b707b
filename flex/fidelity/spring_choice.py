"""``drive.spring_model = "auto"``: a massless spring or a chain, by a prediction of the massless
spring's error from the rigid probe's own run.

The massless spring leaves out the coil's mass. Its error on the governing measure (largest of
the crank-angle and slider-position deviations from the continuous coil over the deployment,
relative to swing and travel: the ``governing_error`` of :mod:`flex.experiments.models.spring_mass`)
is predicted here, with no fit, as the sum of two parts:

- **quasi-static** (:func:`rayleigh_warp`): the coil carries Rayleigh's ``m_s / 3`` on the
  slider (:func:`flex.base.spring_waves.spring_effective_mass_kg`). The mechanism is one degree of
  freedom: its kinetic energy is ``M(s) v^2 / 2``, ``M(s)`` its mass reduced to the slider
  (``2 E_kin / v^2`` of the probe, every sample), and the spring's work depends on the path
  only. Adding ``m_s / 3`` therefore keeps the path and slows the motion along it by
  ``sqrt(1 + m_s / (3 M(s)))``: the chain's curves are the probe's, time-warped. The
  deviation between the two over the slower deployment is the prediction; past its first
  crank-angle maximum the massless run retraces its path (undamped: time reversal), which
  extends the probe. The peak-speed change is ``sqrt(M / (M + m_s / 3))`` at equal path.
- **surge** (:func:`flex.base.spring_waves.released_spring_rayleigh_deviation`): the released coil
  (uniformly compressed, at rest; fixed at the frame, the slider at its other end: the
  chain's boundary conditions) against its Rayleigh model, a linear spring carrying the
  mechanism's smallest reduced mass ``M_min``: its waves and the shift of its first
  frequency (``beta tan beta = m_s / M``). Of order ``(m_s / M)^2``.

Their sum bounds the deviation (triangle inequality) as far as the surge part's linear model
holds. Measured on the 14 massless runs of ``make spring_mass`` (thesis and wing scenes, rigid
links and an FFRF coupler judged by its rigid twin's probe, coil masses 3-300 g x slider
masses 26.4 and 100 g; m_s / M_min 0.017-3.1), predicted / measured 1.00-1.17 (the
quasi-static part alone 0.87-1.00; the chain's deployment time within 1 %; docs/spring-mass.md).

``auto`` (:func:`decide_spring`, called first by :func:`flex.fidelity.auto.resolve`):
``"massless"`` when the prediction times :data:`SPRING_PREDICTION_MARGIN` meets
``fidelity.tolerance``; otherwise ``"chain"`` with the fewest segments N whose discretization
error, :data:`CHAIN_ERROR_CONSTANT` x that bound / N^2, stays within
:data:`CHAIN_TOLERANCE_FRACTION` of the tolerance.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import TWO_PI, n_values
from flex.base.spring_waves import released_spring_rayleigh_deviation, spring_effective_mass_kg
from flex.bodies.spring import surge_frequency_fixed_end_mass_Hz
from flex.config.tolerance import Tolerance
from flex.data.headlines import first_maximum_index
from flex.data.scene import SCHEMA
from flex.fidelity.probe import FidelityDecision, deployment_probe

#: what ``auto`` multiplies the predicted massless error by before it compares it with the
#: tolerance. The prediction is a bound: predicted / measured 1.001-1.17 on the 14 massless
#: runs of make spring_mass, never below 1; the margin is for scenes outside that sweep (a
#: damped spring, whose motion past the stop the retraced path only approximates; m_s / M_min
#: beyond 3.1; the surge part's linear model on a mechanism whose reduced mass varies)
SPRING_PREDICTION_MARGIN = 1.1
#: the chain's discretization error, measured (make spring_mass, against 64 segments,
#: Richardson-corrected to the continuous coil): 0.33-0.76 x the massless error / N^2 with
#: rigid links (N = 1-32), up to 1.35 with an FFRF coupler for errors above 1e-3 (N <= 16;
#: 1.67 at N = 32, 4e-4: that chain converges more slowly there); the quasi-static part alone
#: gives 0.5 (the chain's effective mass is m_s / 3 + m_s / (6 N^2))
CHAIN_ERROR_CONSTANT = 1.35
#: the share of ``fidelity.tolerance`` the chain's discretization error may take, a policy:
#: its error adds to the links' (whose own ``auto`` choices still take the whole tolerance),
#: so a scene with both errs by at most 1.5 x the tolerance where each bound holds
CHAIN_TOLERANCE_FRACTION = 0.5
#: largest m_s / M_min the prediction was measured at (make spring_mass: 3.06); beyond it
#: the decision says "extrapolated"
MEASURED_MASS_RATIO_MAX = 3.1
#: a sample whose kinetic energy is below this fraction of the largest carries no reduced
#: mass (0 / 0 at the release and at the stop): interpolated from its neighbours
_KINETIC_FLOOR = 1e-9


@dataclass(frozen=True)
class SpringPrediction:
    """The massless spring's predicted governing error [-] and its parts (module doc)."""

    quasi_static_error: float  #: Rayleigh's m_s / 3, time-warped probe (:func:`rayleigh_warp`)
    surge_error: float  #: the released coil against its Rayleigh model
    mass_ratio: float  #: m_s / M_min [-]
    smallest_reduced_mass_kg: float  #: M_min, the mechanism's least mass at the slider
    deployment_time_s: float  #: the massless probe's first crank-angle maximum
    chain_deployment_time_s: float  #: the deployment time with the coil's mass, predicted

    @property
    def error(self) -> float:
        """The predicted governing error of the massless spring [-]: both parts."""
        return self.quasi_static_error + self.surge_error


def inverse_reduced_mass_per_kg(probe: Mapping[str, np.ndarray]) -> np.ndarray:
    """``1 / M`` [1/kg] per sample of a rigid spring run: ``v^2 / (2 E_kin)``, v the slider's
    speed, E_kin the mechanism's kinetic energy (one degree of freedom: ``E_kin = M v^2 / 2``);
    samples with almost no kinetic energy (release, stop) interpolated from their neighbours.
    0 where the slider stands while the crank turns (a dead centre: M infinite)."""
    time = np.asarray(probe["time"], dtype=float)
    speed = np.asarray(probe["slider/velocity"], dtype=float).reshape(len(time), -1)[:, 0]
    kinetic = np.asarray(probe["energy/kinetic"], dtype=float)
    moving = kinetic > _KINETIC_FLOOR * np.max(kinetic)
    if moving.sum() < 2:
        raise SceneError('drive.spring_model = "auto": the rigid probe barely moves (no '
                         "kinetic energy): no deployment to judge the spring by")
    inverse = speed[moving] ** 2 / (2.0 * kinetic[moving])
    return np.interp(time, time[moving], inverse)


def _mirrored(values: np.ndarray, stop: int, time: bool = False) -> np.ndarray:
    """``values[:stop + 1]`` continued past ``stop`` by its mirror image (a time axis: by
    ``2 t_stop - t``): the undamped motion after a standstill retraces its path."""
    head = values[:stop + 1]
    tail = head[-2::-1]
    return np.concatenate([head, 2.0 * head[-1] - tail if time else tail])


def rayleigh_warp(probe: Mapping[str, np.ndarray], added_mass_kg: float
                  ) -> tuple[float, float]:
    """The governing deviation [-] of the probe's motion from the same mechanism with
    ``added_mass_kg`` on the slider, and the latter's deployment time [s].

    Contract: ``probe`` the series of a rigid spring run from rest (``time``, ``crank/angle``,
    ``slider/position``, ``slider/velocity``, ``energy/kinetic``), up to or past its first
    crank-angle maximum (the last sample if none). The heavier run follows the same path,
    ``dt' = sqrt(1 + m_a / M) dt`` (module doc); deviations of crank angle and slider
    position over its deployment, relative to the probe's swing and travel; the larger. The
    mirrored probe covers twice its deployment: a run more than twice as slow (m_a / M above
    3 on average) is compared over that span only, the error then a lower bound.
    """
    time = np.asarray(probe["time"], dtype=float)
    angle = np.asarray(probe["crank/angle"], dtype=float)
    found = first_maximum_index(angle)
    stop = len(time) - 1 if found is None else found
    factor = np.sqrt(1.0 + added_mass_kg * _mirrored(inverse_reduced_mass_per_kg(probe), stop))
    span = _mirrored(time, stop, time=True)
    warped = np.concatenate([[span[0]], span[0] + np.cumsum(
        0.5 * (factor[1:] + factor[:-1]) * np.diff(span))])
    window = span <= min(warped[stop], span[-1]) * (1 + 1e-12)
    errors = []
    for key in ("crank/angle", "slider/position"):
        curve = _mirrored(np.asarray(probe[key], dtype=float).reshape(len(time), -1)[:, 0],
                          stop)
        heavier = np.interp(span[window], warped, curve)
        swing = np.max(np.abs(curve[:stop + 1] - curve[0]))
        errors.append(float(np.max(np.abs(curve[window] - heavier)) / swing))
    return max(errors), float(warped[stop])


def predict_massless_spring_error(probe: Mapping[str, np.ndarray], spring_mass_kg: float
                                  ) -> SpringPrediction:
    """The massless spring's predicted governing error (module doc) from a rigid massless
    spring run ``probe`` (as :func:`rayleigh_warp`) and the coil's mass ``spring_mass_kg``
    [kg]."""
    quasi_static, chain_time_s = rayleigh_warp(probe, spring_effective_mass_kg(spring_mass_kg))
    smallest_kg = 1.0 / float(np.max(inverse_reduced_mass_per_kg(probe)))
    ratio = spring_mass_kg / smallest_kg
    time = np.asarray(probe["time"], dtype=float)
    found = first_maximum_index(np.asarray(probe["crank/angle"]))
    return SpringPrediction(quasi_static, released_spring_rayleigh_deviation(ratio), ratio,
                            smallest_kg, float(time[-1 if found is None else found]),
                            chain_time_s)


def chain_segments(bound: float, tolerance: float) -> int:
    """Fewest chain segments N with ``CHAIN_ERROR_CONSTANT x bound / N^2 <=
    CHAIN_TOLERANCE_FRACTION x tolerance`` (``bound``: the massless error with its margin;
    dimensionless); SceneError beyond the scene's largest ``drive.spring_segments``."""
    wanted = max(1, math.ceil(math.sqrt(CHAIN_ERROR_CONSTANT * bound
                                        / (CHAIN_TOLERANCE_FRACTION * tolerance)) - 1e-9))
    largest = int(SCHEMA["drive"]["spring_segments"].maximum)
    if wanted > largest:
        raise SceneError(f'drive.spring_model = "auto": the massless spring\'s predicted error '
                         f"{bound:.3g} needs {wanted} chain segments for fidelity.tolerance = "
                         f"{tolerance:g}, more than the {largest} a chain may have; use a "
                         f"larger tolerance")
    return wanted


@dataclass
class SpringDecision(FidelityDecision):
    """What ``drive.spring_model = "auto"`` chose (``link`` = ``"spring"``), and why."""

    segments: int = 0  #: the chain's segments; 0 for the massless spring
    prediction: SpringPrediction | None = None

    def attrs(self) -> dict[str, Any]:
        """Flat attributes ``fidelity_spring_*`` for :class:`flex.data.results.CaseResult`."""
        prefix, p = "fidelity_spring_", self.prediction
        out = {"model": self.model, "segments": self.segments, "reason": self.reason,
               "tolerance": self.tolerance, "delta_t_s": self.delta_t_s,
               "omega_rad_per_s": self.omega_rad_per_s, "n_physical": self.n_physical,
               "n_thesis": self.n_thesis, "predicted_massless_error": self.predicted_error,
               "extrapolated": self.extrapolated}
        if p is not None:
            out |= {"quasi_static_error": p.quasi_static_error, "surge_error": p.surge_error,
                    "mass_ratio": p.mass_ratio,
                    "smallest_reduced_mass_kg": p.smallest_reduced_mass_kg}
        return {prefix + key: value for key, value in out.items()}


def decide_spring(resolved: dict[str, dict[str, Any]]) -> SpringDecision:
    """Resolve ``drive.spring_model = "auto"`` in ``resolved`` (in place: ``"massless"``, or
    ``"chain"`` with ``spring_segments``) from a rigid massless probe run
    (:func:`flex.fidelity.probe.deployment_probe`) and ``fidelity.tolerance``; return the
    decision. SceneError without a spring drive."""
    drive = resolved["drive"]
    if drive["kind"] != "spring":
        raise SceneError('drive.spring_model = "auto" needs drive.kind = "spring"')
    tolerance = Tolerance.of(resolved).relative
    massless = copy.deepcopy(resolved)
    massless["drive"]["spring_model"] = "massless"
    delta_t_s, _, probe = deployment_probe(massless)
    prediction = predict_massless_spring_error(probe, drive["spring_mass_kg"])
    bound = prediction.error * SPRING_PREDICTION_MARGIN
    segments = 0 if bound <= tolerance else chain_segments(bound, tolerance)
    drive["spring_model"] = "chain" if segments else "massless"
    if segments:
        drive["spring_segments"] = segments
    omega = TWO_PI * surge_frequency_fixed_end_mass_Hz(
        drive["spring_stiffness_N_per_m"], drive["spring_mass_kg"],
        prediction.smallest_reduced_mass_kg)
    n = n_values(delta_t_s, omega)
    return SpringDecision(
        link="spring", model=drive["spring_model"], modes=None,
        reason=_reason(prediction, bound, tolerance, segments, delta_t_s),
        tolerance=tolerance, delta_t_s=delta_t_s, omega_rad_per_s=omega,
        n_physical=n["physical"], n_thesis=n["thesis"], k_physical=math.nan,
        predicted_error=prediction.error,
        extrapolated=prediction.mass_ratio > MEASURED_MASS_RATIO_MAX, segments=segments,
        prediction=prediction)


def _reason(p: SpringPrediction, bound: float, tolerance: float, segments: int,
            delta_t_s: float) -> str:
    """The decision's one-sentence reason."""
    verdict = (f"<= tolerance {tolerance:g}: massless" if not segments else
               f"> tolerance {tolerance:g}: chain of {segments} segments (discretization "
               f"error {CHAIN_ERROR_CONSTANT:g} x {bound:.3g} / {segments}^2 = "
               f"{CHAIN_ERROR_CONSTANT * bound / segments**2:.3g} <= "
               f"{CHAIN_TOLERANCE_FRACTION:g} x tolerance)")
    return (f"spring: the rigid probe predicts a governing error of {p.error:.3g} for the "
            f"massless spring ({p.quasi_static_error:.3g} from the coil's Rayleigh mass m_s/3 "
            f"on the mechanism's reduced mass, deployment {delta_t_s * 1e3:.4g} -> "
            f"{p.chain_deployment_time_s * 1e3:.4g} ms, + {p.surge_error:.3g} from its surge "
            f"at m_s/M_min = {p.mass_ratio:.3g}), x {SPRING_PREDICTION_MARGIN:g} margin: "
            f"{bound:.3g} {verdict}"
            + ("; m_s/M_min beyond the measured 3.1: extrapolated"
               if p.mass_ratio > MEASURED_MASS_RATIO_MAX else ""))
