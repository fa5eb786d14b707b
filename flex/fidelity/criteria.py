"""Rigid or flexible: error measures, n in both period conventions, fitted error laws, k.

Thesis sec. 6.2, Eq. 64-65: a link may be modelled as rigid if ``k T < delta_t``, i.e. if
``n = delta_t / T`` exceeds a threshold ``k``. This module makes every part of that
statement explicit:

- **omega**: the first in-plane bending frequency of the link with both ends pinned, from
  Euler-Bernoulli beam theory (:func:`pinned_pinned_omega`, rad/s), as in thesis Table 5;
  computable from a scene without any finite-element model.
- **n, two conventions** (:func:`n_values`): ``n_thesis = delta_t * omega`` (the thesis takes
  T = 1/omega) and ``n_physical = delta_t * omega / (2 pi)`` (T = 2 pi / omega, the period).
  All fits are made in ``n_physical``; a k in the thesis convention is 2 pi times larger.
- **delta_t** (:data:`DELTA_T_DEFINITIONS`, :func:`deployment_times`): the thesis never says
  how its 0.016128 s was measured, so several definitions are computed from the rigid run;
  ``stop`` (the crank's first angle maximum: the end of the deployment swing) is primary.
- **error measures** (:data:`MEASURES`, :func:`error_measures`): FFRF run against its rigid
  twin over the deployment window [0, delta_t_stop], all dimensionless.
- **error laws, k, and the stored criterion** ``auto`` reads: :mod:`flex.fidelity.laws`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from flex.base.kinematics import chord_components
from flex.base.physics import (
    TWO_PI,
    Plate,
)
from flex.base.thesis import (
    THESIS_DELTA_T_S,  # thesis sec. 6.2, Table 5 note (source not stated)
    )
from flex.config.ladder import (
    FFRF_RUNG,
    LINEAR_FFRF_RUNG,
)
from flex.data.headlines import first_maximum_index
from flex.dynamics.link_models import FFRF, NONLINEAR_FE

CONVENTIONS = ("physical", "thesis")
PRIMARY_DELTA_T = "stop"
GOVERNING = "governing"

#: deployment-time definitions, all taken from the rigid run of a spring deployment
DELTA_T_DEFINITIONS: dict[str, str] = {
    "stop": "time of the first crank-angle maximum (the crank comes to rest: end of the "
            "deployment swing)",
    "half_swing": "time at which the crank has covered half its swing (angle midway between "
                  "start and first maximum)",
    "peak_speed": "time of the largest crank speed (the spring passes its free length)",
    "thesis": f"the thesis's constant {THESIS_DELTA_T_S:g} s (sec. 6.2; how it was measured is "
              "not stated)",
}

#: error measures, FFRF against its rigid twin over [0, delta_t_stop]; all dimensionless
MEASURES: dict[str, str] = {
    "deflection": "(a) peak |elastic midpoint deflection| / coupler length L2",
    "crank_angle": "(b) max |crank angle FFRF - rigid twin| / crank swing of the rigid twin",
    "slider_position": "(b) max |slider position FFRF - rigid twin| / slider travel of the "
                       "rigid twin",
    "stress_amplification": "(c) |peak FFRF bending stress / peak quasi-static stress of the "
                            "rigid twin - 1| (dynamic amplification factor minus one)",
    GOVERNING: "max of deflection, crank_angle and slider_position (what auto bounds)",
}


# ------------------------------------------------------------------------------------------
# frequencies and n
# ------------------------------------------------------------------------------------------
def convert_n(n: Any, source: str, target: str) -> Any:
    """Convert n (scalar or array) between the ``physical`` and ``thesis`` conventions."""
    for name in (source, target):
        if name not in CONVENTIONS:
            raise ValueError(f"convention {name!r}: must be one of {', '.join(CONVENTIONS)}")
    if source == target:
        return n
    return n * TWO_PI if target == "thesis" else n / TWO_PI


# ------------------------------------------------------------------------------------------
# deployment time
# ------------------------------------------------------------------------------------------
def half_swing_time(time_s: np.ndarray, angle_rad: np.ndarray, stop: int) -> float:
    """Time [s] at which ``angle_rad`` first covers half its rise from sample 0 to sample
    ``stop`` (its maximum, :func:`first_maximum_index`), interpolated linearly."""
    time_s, angle = np.asarray(time_s, dtype=float), np.asarray(angle_rad, dtype=float)
    half = angle[0] + 0.5 * (angle[stop] - angle[0])
    i = int(np.argmax(angle[:stop + 1] >= half))
    if i == 0:
        return float(time_s[0])
    fraction = (half - angle[i - 1]) / (angle[i] - angle[i - 1])
    return float(time_s[i - 1] + fraction * (time_s[i] - time_s[i - 1]))


def deployment_times(time_s: np.ndarray, crank_angle_rad: np.ndarray,
                     crank_speed_rad_per_s: np.ndarray) -> dict[str, float]:
    """Deployment time [s] by every definition of :data:`DELTA_T_DEFINITIONS`.

    Contract: series of one rigid spring deployment from rest, crank angle rising to a
    first maximum inside the series. ``half_swing`` is interpolated linearly between
    samples; ``stop`` and ``peak_speed`` are sample times. Raises ValueError when the crank
    angle has no maximum in the series (simulate longer).
    """
    time_s = np.asarray(time_s, dtype=float)
    angle = np.asarray(crank_angle_rad, dtype=float)
    speed = np.asarray(crank_speed_rad_per_s, dtype=float)
    stop = first_maximum_index(angle)
    if stop is None:
        raise ValueError(f"the crank angle has no maximum before t = {time_s[-1]:.6g} s: the "
                         f"deployment is not complete; simulate longer")
    return {"stop": float(time_s[stop]), "half_swing": half_swing_time(time_s, angle, stop),
            "peak_speed": float(time_s[int(np.argmax(np.abs(speed[:stop + 1])))]),
            "thesis": THESIS_DELTA_T_S}


# ------------------------------------------------------------------------------------------
# error measures
# ------------------------------------------------------------------------------------------
def quasi_static_stress(force_B_N: np.ndarray, force_C_N: np.ndarray,
                        coupler_angle_rad: np.ndarray, length_m: float, thickness_m: float,
                        width_m: float, x_range_m: tuple[float, float] | None = None,
                        points: int = 101) -> np.ndarray:
    """Peak |sigma_xx| [Pa] per sample of a rigid coupler's loads applied to a static beam.

    Contract: ``force_B_N``, ``force_C_N`` (n, 2) are the joint forces on the coupler at B
    (x = 0) and C (x = L) in global x, y (the rigid twin's ``joints/B|C/force_on_coupler``),
    ``coupler_angle_rad`` (n,) the angle of B -> C. The coupler is an Euler-Bernoulli beam
    pinned at both joints and loaded by its own d'Alembert inertia, distributed linearly
    along it (rigid-body motion); that distribution is fixed by the two joint forces
    (transverse equilibrium and moments), which gives the bending moment in closed form,
    ``M(xi) = L (F_B xi (1 - xi)^2 + F_C xi^2 (1 - xi))`` with xi = x / L and F the
    transverse components. The axial force is interpolated linearly between the axial
    components (exact for uniform axial acceleration). Stress = |N| / A + 6 |M| / (w t^2),
    the outer-fibre value, maximised over ``x_range_m`` (default: one thickness away from
    each end, as :func:`flex.bodies.reduction.bending_stress_history`).
    """
    axial_b, transverse_b = chord_components(force_B_N, coupler_angle_rad)
    axial_c, transverse_c = chord_components(force_C_N, coupler_angle_rad)
    if x_range_m is None:
        x_range_m = (thickness_m, length_m - thickness_m)
    xi = np.linspace(x_range_m[0], x_range_m[1], points) / length_m
    moment = length_m * (transverse_b[:, None] * xi * (1 - xi) ** 2
                         + transverse_c[:, None] * xi**2 * (1 - xi))
    tension = -axial_b[:, None] * (1 - xi) + axial_c[:, None] * xi
    area = width_m * thickness_m
    stress = np.abs(tension) / area + 6.0 * np.abs(moment) / (width_m * thickness_m**2)
    return stress.max(axis=1)


EULER_LOAD_LIMIT = 0.25
"""Largest compressive load / Euler load of the fitted cases and of an ``auto`` decision.

Towards the pinned-pinned buckling load the error is governed by P / P_cr, not by n. Set
when kfit's reference was the linear FFRF coupler (the cases at P / P_cr <= 0.2 followed
the n-law, the 0.5 mm plate at 0.33 and the 1 mm plate at 0.49 lay 2 x above it in
deflection; that body's response to compression has the wrong sign, docs/geometric-
stiffness.md). Against the reference with geometric stiffness (kfit since) the cases
beyond it are not generated: its runs failed Newton at 0.33 (0.5 mm, thesis spring,
undamped) and 0.49 (1 mm, 15000 N/m, undamped) and beyond the Euler load; the fitted cases
reach 0.24 (the kfit report lists what is left out)."""


def flexible_rung(load_ratio: float, tolerance: float, geometric_stiffness: bool = True
                  ) -> tuple[str, float]:
    """The coupler's flexible rung for ``tolerance`` (relative to the quantity: the peak
    deflection or stress the rung computes): ``"ffrf"`` when its measured model error meets
    it (:data:`GEOMETRIC_FFRF_ERROR`, or the linear body's bound at ``load_ratio``, the rigid
    probe's compression / Euler load, without ``geometric_stiffness``), else
    ``"nonlinear_fe"``; and the FFRF rung's relative model error. All dimensionless."""
    rung = FFRF_RUNG if geometric_stiffness else LINEAR_FFRF_RUNG
    relative = rung.bound({}, load_ratio, None)
    return (FFRF if relative <= tolerance else NONLINEAR_FE), relative


def euler_load_ratio(force_B_N: np.ndarray, force_C_N: np.ndarray,
                     coupler_angle_rad: np.ndarray, plate: Plate) -> float:
    """Largest compressive axial force in the coupler / its Euler load pi^2 E I / L^2.

    Contract: joint forces on the coupler at B and C (n, 2) [N] and the angle of B -> C
    [rad], as :func:`quasi_static_stress`; ``plate`` the coupler's (its
    :attr:`~flex.base.physics.Plate.euler_load_N`, I = w t^3 / 12, in-plane bending). The axial
    force is linear between the joints, so its largest compression is at one of them.
    """
    axial_b, _ = chord_components(force_B_N, coupler_angle_rad)
    axial_c, _ = chord_components(force_C_N, coupler_angle_rad)
    compression = max(float(np.max(axial_b)), float(np.max(-axial_c)), 0.0)
    return compression / plate.euler_load_N


def _window(data: Mapping[str, np.ndarray], end_s: float) -> np.ndarray:
    return np.asarray(data["time"]) <= end_s * (1 + 1e-12)


def _common_samples(rigid: Mapping[str, np.ndarray], ffrf: Mapping[str, np.ndarray],
                    window_end_s: float) -> int:
    """How many samples from t = 0 both runs have within [0, ``window_end_s``] [s]; refused
    (ValueError) under three, or where their times differ."""
    w_r, w_f = _window(rigid, window_end_s), _window(ffrf, window_end_s)
    count = min(int(w_r.sum()), int(w_f.sum()))
    if count < 3:
        raise ValueError(f"window [0, {window_end_s:g}] s holds {count} common samples")
    t_r, t_f = np.asarray(rigid["time"])[:count], np.asarray(ffrf["time"])[:count]
    if not np.allclose(t_r, t_f, rtol=0, atol=1e-9 * max(1.0, float(t_r[-1]))):
        raise ValueError("rigid and FFRF runs are not sampled at the same times")
    return count


def error_measures(rigid: Mapping[str, np.ndarray], ffrf: Mapping[str, np.ndarray],
                   plate: Plate, window_end_s: float) -> dict[str, float]:
    """The error measures of :data:`MEASURES` plus their absolute values; ``plate``: the
    coupler's (sizes and Young's modulus read).

    Contract: ``rigid`` and ``ffrf`` map result paths (``time``, ``crank/angle``,
    ``slider/position``, ``coupler/midpoint_deflection``, ``coupler/peak_bending_stress``,
    ``coupler/angle``, ``joints/B/force_on_coupler``, ``joints/C/force_on_coupler``) to arrays
    sampled at the same times (same step and output step) from t = 0; only samples with
    ``time <= window_end_s`` count. Returns dimensionless measures and, with suffixes,
    ``*_abs`` values in SI units (m, rad, Pa): ``deflection_abs_m``,
    ``crank_angle_abs_rad``, ``slider_position_abs_m``, ``peak_stress_ffrf_Pa``,
    ``peak_stress_quasi_static_Pa``, ``crank_swing_rad``, ``slider_travel_m``; and
    ``stress_ratio`` (the signed dynamic amplification factor, peak FFRF / quasi-static) and
    ``euler_load_ratio`` (:func:`euler_load_ratio` of the rigid twin).
    """
    count = _common_samples(rigid, ffrf, window_end_s)

    def series(data: Mapping[str, np.ndarray], key: str) -> np.ndarray:
        return np.asarray(data[key], dtype=float)[:count]

    angle_r, angle_f = series(rigid, "crank/angle"), series(ffrf, "crank/angle")
    slider_r, slider_f = series(rigid, "slider/position"), series(ffrf, "slider/position")
    swing = float(np.max(np.abs(angle_r - angle_r[0])))
    travel = float(np.max(np.abs(slider_r - slider_r[0])))
    deflection = float(np.max(np.abs(series(ffrf, "coupler/midpoint_deflection"))))
    crank_dev = float(np.max(np.abs(angle_f - angle_r)))
    slider_dev = float(np.max(np.abs(slider_f - slider_r)))
    stress_qs = quasi_static_stress(series(rigid, "joints/B/force_on_coupler"),
                                    series(rigid, "joints/C/force_on_coupler"),
                                    series(rigid, "coupler/angle"), *plate.sizes_m)
    peak_qs = float(stress_qs.max())
    peak_ffrf = float(series(ffrf, "coupler/peak_bending_stress").max())
    out = {
        "deflection": deflection / plate.length_m,
        "crank_angle": crank_dev / swing,
        "slider_position": slider_dev / travel,
        "stress_amplification": abs(peak_ffrf / peak_qs - 1.0),
        "stress_ratio": peak_ffrf / peak_qs,
        "euler_load_ratio": euler_load_ratio(series(rigid, "joints/B/force_on_coupler"),
                                             series(rigid, "joints/C/force_on_coupler"),
                                             series(rigid, "coupler/angle"), plate),
        "deflection_abs_m": deflection,
        "crank_angle_abs_rad": crank_dev,
        "slider_position_abs_m": slider_dev,
        "peak_stress_ffrf_Pa": peak_ffrf,
        "peak_stress_quasi_static_Pa": peak_qs,
        "crank_swing_rad": swing,
        "slider_travel_m": travel,
    }
    out[GOVERNING] = max(out["deflection"], out["crank_angle"], out["slider_position"])
    return out
