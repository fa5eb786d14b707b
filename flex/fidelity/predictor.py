"""Predict the elastic deflection a rigid link leaves out, from the rigid run's own loads.

Contract of :func:`predict_deflection`: given the series of a rigid run (``time``, the link's
angle, rate and acceleration, the joint forces on it, global x-y [N]) and the link's plate
(length, thickness in the mechanism plane, width, Young's modulus, density), it returns a
:class:`DeflectionPrediction`: the quasi-static midpoint deflection relative to the chord at
every sample, amplified by the axial compression at midspan (``1 / (1 - P / P_Euler)``,
:func:`flex.base.physics.axial_load_amplification`); then the response of the link's first
bending mode to that history, a single-degree-of-freedom oscillator starting at rest
(``x'' + w^2 x = w^2 x_qs(t)``, scipy's ``lsim``: the Duhamel integral). Its peak over the
window is the predicted peak elastic deflection [m], and that over the length the rigid
model's predicted deflection error. Beside it, the simpler bound the dynamic load factor of
the load's rise gives (:func:`flex.base.physics.ramp_load_factor` times the quasi-static
peak: 2 for a load that starts at its peak), which misses the free vibration a load step at
the start leaves under a later, higher quasi-static peak.

The quasi-static deflection, per link (one beam model, two load paths):

- **coupler** B-C: a pinned-pinned beam under its own d'Alembert inertia, whose total is
  the sum of the transverse joint reactions
  (:func:`flex.base.physics.pinned_beam_midpoint_deflection_m`); mode: pinned-pinned.
- **crank** A-B (pivot A): the plate's d'Alembert load ``-mu alpha x`` from the rigid run's
  angular acceleration, and at A the moment that balances it against the coupler's force at
  B (a welded wing's inertia moment, a drive torque;
  :func:`flex.base.physics.pinned_beam_end_moment_midpoint_deflection_m`); mode: the
  crank's first elastic mode in the mechanism, passed in (``omega_rad_per_s``).

Nothing here is fitted. Measured against FFRF couplers (6 in-plane modes, h = 1e-5 s) on 12
scenes (steel 1-10 mm, springs 500-20000 N/m, 11 and 22 mm preloads, aluminium, titanium):
the oscillator's peak / the FFRF peak 0.79-0.99 (0.79 at the stiffest spring, P / P_E =
0.075), the load-factor bound 0.63-1.06. Against FFRF cranks (12 modes, h = 2e-5 s) on 15
scenes (steel 0.8-4.56 mm, aluminium, springs 500-20000 N/m, 11 and 22 mm preloads, 2 %
damping, 4 with the wing): 0.89-1.23 (1.23 at the stiffest spring, P / P_E = 0.11;
docs/criterion.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from flex.base.kinematics import chord_components
from flex.base.physics import (
    Plate,
    axial_load_amplification,
    pinned_beam_end_moment_midpoint_deflection_m,
    pinned_beam_midpoint_deflection_m,
    ramp_load_factor,
)

#: a load that starts at no less than this fraction of its peak counts as a step (r = 0)
STEP_FRACTION = 0.5
#: what ``auto`` multiplies the prediction by before it compares it with the tolerance: the
#: largest measured / predicted deflection error measured, 1.12 both over make kfit's 106
#: fitted cases (against FFRF with geometric stiffness; its 95 % quantile 1.06) and over the
#: crank's 15 scenes (tests/test_crank_predictor.py), rounded up. The kfit report prints the
#: run's quantile and largest ratio beside this value every run. (1.31 before, the quantile
#: against the linear FFRF reference, whose geometric stiffening has the wrong sign.)
PREDICTION_MARGIN = 1.15


@dataclass(frozen=True)
class DeflectionPrediction:
    """What :func:`predict_deflection` found (see the module doc)."""

    peak_deflection_m: float  #: predicted peak elastic midpoint deflection (oscillator)
    quasi_static_peak_m: float  #: peak of the amplified quasi-static deflection
    load_factor_peak_m: float  #: quasi-static peak times the ramp load factor (the bound)
    load_factor: float  #: that ramp load factor
    rise_time_s: float  #: the load's rise time (0: a step)
    period_s: float  #: period of the link's first bending mode (as passed, or pinned-pinned)
    euler_load_ratio: float  #: largest midspan compression / Euler load

    def relative_error(self, length_m: float) -> float:
        """The rigid model's predicted deflection error: peak deflection / length."""
        return self.peak_deflection_m / length_m


def _sizes(plate: Plate) -> tuple[float, float, float, float]:
    """What the beam formulas read: ``(length_m, thickness_m, width_m, youngs_modulus_Pa)``."""
    return (*plate.sizes_m, plate.youngs_modulus_Pa)


def _coupler_history(series: Mapping[str, np.ndarray], plate: Plate
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Signed quasi-static midpoint deflection [m] and midspan compression [N] per sample of
    a rigid coupler B-C: its d'Alembert load's total is the sum of the transverse joint
    reactions; the axial force is linear between the joints."""
    axial_b, transverse_b = chord_components(series["joints/B/force_on_coupler"],
                                             series["coupler/angle"])
    axial_c, transverse_c = chord_components(series["joints/C/force_on_coupler"],
                                             series["coupler/angle"])
    return (pinned_beam_midpoint_deflection_m(transverse_b + transverse_c, *_sizes(plate)),
            (axial_b - axial_c) / 2)


def _crank_history(series: Mapping[str, np.ndarray], plate: Plate
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Signed quasi-static midpoint deflection [m] and midspan compression [N] per sample of
    a rigid crank A-B (x from the pivot A; ``plate``: the crank's plate, or the equivalent
    plate of a lumped crank).

    The plate turning at rate w and acceleration alpha carries the d'Alembert load
    ``-mu alpha x`` across its chord (mu = rho t w; linear, total ``-mu alpha L^2 / 2``) and
    ``mu w^2 x`` along it; the coupler pushes at B (the rigid run's ``joints/B/
    force_on_crank``, transverse ``F_B``). What balances their moment about A acts at A:
    ``M_A = mu alpha L^3 / 3 - F_B L``, the inertia moment of a wing welded there (equal to
    the rigid run's ``joints/W/root_moment`` to the plate's rotary inertia, t^2 / 4 L^2), or a
    drive torque; zero for a bare plate crank under the spring. Midspan compression: minus
    the axial force of B on the crank minus the centrifugal pull of the outer half, ``mu w^2
    (3/8) L^2``."""
    length = plate.length_m
    per_length = plate.density_kg_per_m3 * plate.thickness_m * plate.width_m
    alpha = np.asarray(series["crank/angular_acceleration"], dtype=float)
    rate = np.asarray(series["crank/angular_velocity"], dtype=float)
    axial_b, transverse_b = chord_components(series["joints/B/force_on_crank"],
                                             series["crank/angle"])
    moment_a = per_length * alpha * length**3 / 3 - transverse_b * length
    deflection = (pinned_beam_midpoint_deflection_m(-per_length * alpha * length**2 / 2,
                                                    *_sizes(plate))
                  + pinned_beam_end_moment_midpoint_deflection_m(moment_a, *_sizes(plate)))
    return deflection, -axial_b - per_length * rate**2 * 3 * length**2 / 8


def predict_deflection(series: Mapping[str, np.ndarray], plate: Mapping[str, Any],
                       link: str = "coupler", window_end_s: float = np.inf,
                       omega_rad_per_s: float | None = None) -> DeflectionPrediction:
    """The predicted peak elastic midpoint deflection of ``link`` (``"coupler"`` or
    ``"crank"``) from a rigid run's ``series`` (see the module doc); ``plate``: the link's
    scene values (``length_m``, ``thickness_m``, ``width_m``, ``youngs_modulus_Pa``,
    ``density_kg_per_m3``; ``damping_ratio`` of the first mode if given, else 0); samples
    after ``window_end_s`` [s] are left out; ``omega_rad_per_s``: the first elastic mode's
    circular frequency [rad/s] (None: the plate's pinned-pinned one)."""
    histories = {"coupler": _coupler_history, "crank": _crank_history}
    if link not in histories:
        raise ValueError(f"link {link!r}: must be 'coupler' or 'crank'")
    time_s = np.asarray(series["time"], dtype=float)
    keep = time_s <= window_end_s * (1 + 1e-12)
    shape = Plate.of(plate)
    signed_static, compression = (np.asarray(values)[keep]
                                  for values in histories[link](series, shape))
    if omega_rad_per_s is None:
        omega_rad_per_s = shape.pinned_pinned_omega
    euler = shape.euler_load_N
    return _respond(time_s[keep], signed_static, compression, euler, float(omega_rad_per_s),
                    float(plate.get("damping_ratio", 0.0)))


def _respond(time_s: np.ndarray, signed_static_m: np.ndarray, compression_N: np.ndarray,
             euler_N: float, omega_rad_per_s: float, damping_ratio: float
             ) -> DeflectionPrediction:
    """The quasi-static history amplified by its compression, the first mode's oscillator
    response to it, and the ramp-load-factor bound (one link, one window)."""
    static = np.abs(signed_static_m)
    amplification = axial_load_amplification(compression_N, euler_N)
    amplified = static * amplification
    period = 2 * np.pi / omega_rad_per_s
    peak_index = int(np.argmax(amplified))
    starts_high = static[0] >= STEP_FRACTION * static.max()
    rise = 0.0 if starts_high else float(time_s[peak_index] - time_s[0])
    factor = float(ramp_load_factor(rise, period))
    ratio = float(max(compression_N.max(), 0.0) / euler_N)
    if not np.all(np.isfinite(amplification)):  # at or beyond the Euler load: it buckles
        return DeflectionPrediction(np.inf, np.inf, np.inf, factor, rise, float(period), ratio)
    response = oscillator_response(time_s, np.sign(signed_static_m) * amplified,
                                   omega_rad_per_s, damping_ratio)
    return DeflectionPrediction(float(np.max(np.abs(response))), float(amplified[peak_index]),
                                float(factor * amplified[peak_index]), factor, rise,
                                float(period), ratio)


def oscillator_response(time_s: np.ndarray, quasi_static: np.ndarray, omega_rad_per_s: float,
                        damping_ratio: float = 0.0) -> np.ndarray:
    """Response x(t) of an oscillator ``x'' + 2 zeta w x' + w^2 x = w^2 x_qs(t)`` starting at
    rest (x = x' = 0 at the first sample) to the quasi-static history ``quasi_static`` sampled
    at ``time_s`` (linear between samples; scipy.signal.lsim). Undamped, a step gives 2 x its
    static value, a slow rise x_qs itself."""
    from scipy.signal import lsim

    if len(time_s) < 2:
        return np.asarray(quasi_static, dtype=float)
    _, response, _ = lsim(([omega_rad_per_s**2],
                           [1.0, 2.0 * damping_ratio * omega_rad_per_s, omega_rad_per_s**2]),
                          np.asarray(quasi_static, dtype=float),
                          np.asarray(time_s, dtype=float) - time_s[0])
    return np.asarray(response, dtype=float)


#: the prediction's own error, relative to it: the measured ratio of the FFRF body's peak to
#: the predicted one lay within 0.79-1.23 over 27 scenes (module doc; coupler 0.79-0.99,
#: crank 0.89-1.23), so a prediction is stated +- this fraction of itself
PREDICTION_SPREAD = 0.25
#: case attribute prefix of a rigid link's predicted quantities
PREDICTED_PREFIX = "predicted_"


def rigid_link_predictions(scene: Mapping[str, Mapping[str, Any]],
                           series: Mapping[str, np.ndarray], rigid_links: list[str],
                           window_end_s: float = np.inf) -> dict[str, Any]:
    """What a rigid run's loads predict of its rigid plate links' bending over the deployment
    (samples up to ``window_end_s`` [s]): case attributes ``predicted_<link>_peak_deflection_m``
    [m] (:func:`predict_deflection`) and, for the coupler, ``predicted_coupler_peak_bending_
    stress_Pa`` [Pa] (the quasi-static beam stress of its loads,
    :func:`flex.fidelity.criteria.quasi_static_stress`, amplified as the deflection is), each
    with ``..._error`` (:data:`PREDICTION_SPREAD` of it) and one ``predicted_method`` line.
    ``rigid_links``: the rigid links with plate geometry."""
    from flex.data.headlines import ROUNDOFF_ULPS
    from flex.fidelity.criteria import quasi_static_stress

    out: dict[str, Any] = {}
    skipped: dict[str, str] = {}
    for link in rigid_links:
        prediction = predict_deflection(series, scene[link], link, window_end_s)
        if not np.isfinite(prediction.peak_deflection_m):  # it was "nan +- nan"
            skipped[link] = "compressed to its plate's Euler load or beyond, where it buckles"
            continue
        if prediction.peak_deflection_m <= ROUNDOFF_ULPS * np.finfo(float).eps * float(
                scene[link]["length_m"]):  # loads at round-off: it was "4.9e-16 m +- 25 %"
            skipped[link] = "its loads bend it by round-off only (nothing loads it)"
            continue
        values = {f"{link}_peak_deflection_m": prediction.peak_deflection_m}
        if link == "coupler" and prediction.quasi_static_peak_m > 0:
            plate = Plate.of(scene[link])
            keep = np.asarray(series["time"]) <= window_end_s * (1 + 1e-12)
            static = quasi_static_stress(*(np.asarray(series[path])[keep] for path in (
                "joints/B/force_on_coupler", "joints/C/force_on_coupler", "coupler/angle")),
                plate.length_m, plate.thickness_m, plate.width_m)
            values["coupler_peak_bending_stress_Pa"] = float(static.max()) * (
                prediction.peak_deflection_m / prediction.quasi_static_peak_m)
        for name, value in values.items():
            out[f"{PREDICTED_PREFIX}{name}"] = value
            out[f"{PREDICTED_PREFIX}{name}_error"] = PREDICTION_SPREAD * value
    predicted = [link for link in rigid_links if link not in skipped]
    method = [f"a prediction, not a run: the rigid {' and '.join(predicted)}'s own loads on a "
              f"pinned beam, amplified by the axial compression, through the first bending "
              f"mode's oscillator (flex.fidelity.predictor), over the deployment; its error, "
              f"{PREDICTION_SPREAD:g} of it, from the measured spread against FFRF bodies "
              f"(0.79-1.23 over 27 scenes)"] if predicted else []
    method += [f"none for the rigid {link}: {why}" for link, why in skipped.items()]
    if method:
        out[f"{PREDICTED_PREFIX}method"] = "; ".join(method)
    return out


__all__ = ["DeflectionPrediction", "PREDICTED_PREFIX", "PREDICTION_MARGIN", "PREDICTION_SPREAD",
           "STEP_FRACTION", "oscillator_response", "predict_deflection",
           "rigid_link_predictions"]
