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
- **error law** (:func:`fit_error_law`, :class:`ErrorLaw`): ``e(n) = floor + c n^-p``
  fitted in log space (floor = 0: a straight line in log-log, ordinary least squares) with
  95 % confidence and prediction bands (delta method, Student t).
- **k for a tolerance** (:meth:`ErrorLaw.k`): for a tolerance eps, ``k(eps)`` is the
  smallest n such that the fitted error ``e(n) <= eps`` for all larger n (the law is
  decreasing); ``inf`` when the law never gets below eps (a floor, or no decrease). The
  ``upper`` bound uses the upper 95 % prediction band instead of the central fit: a
  conservative k that covers the scatter of the sweep's cases around the law.
- **the fitted laws** ``auto`` reads (:mod:`flex.fidelity.auto` decides) are read from
  :data:`DEFAULT_CRITERION` (``flex/fidelity/criteria_fit.toml``, written by ``make kfit``),
  or passed as a :class:`Criterion`.
"""

from __future__ import annotations

import functools
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError
from flex.base.kinematics import chord_components
from flex.base.physics import (  # noqa: F401 - part of this module's face
    IN_PLANE_KINDS,
    TWO_PI,
    clamped_plate_frequencies,
    euler_buckling_load_N,
    n_values,
    pinned_pinned_omega,
    plate_thickness_for_mass_m,
)
from flex.base.thesis import (  # noqa: F401 - part of this module's face
    THESIS_DELTA_T_S,  # thesis sec. 6.2, Table 5 note (source not stated)
    THESIS_K,  # thesis sec. 6.2, in the thesis convention (n = delta_t * omega)
    THESIS_YOUNGS_MODULUS_PA,
)
from flex.dynamics.link_models import FFRF, NONLINEAR_FE
from flex.fidelity.predictor import PREDICTION_MARGIN

CRITERION_FORMAT = "flex-criterion/1"
DEFAULT_CRITERION = Path(__file__).with_name("criteria_fit.toml")
#: the crank's own law (``make crank``, copied by ``make crank-criterion``): the coupler law
#: under-predicts a crank carrying a wing (README, "The crank")
DEFAULT_CRANK_CRITERION = Path(__file__).with_name("crank_criteria_fit.toml")
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
def first_maximum_index(values: np.ndarray) -> int | None:
    """Index of the first local maximum of a rising series (None if it only rises)."""
    values = np.asarray(values, dtype=float)
    if len(values) < 3:
        return None
    falling = np.flatnonzero(np.diff(values) < 0)
    if len(falling) == 0:
        return None
    return int(falling[0])


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


LINEAR_FFRF_ERROR_FLOOR = 0.005
LINEAR_FFRF_ERROR_PER_LOAD = 1.0
GEOMETRIC_FFRF_ERROR = 0.005
"""The FFRF rungs' model errors relative to the quantity, measured by ``make ladder``
(thesis deployment, steel plates 0.5-10 mm, peak elastic midpoint deflection against the
nonlinear FE coupler's, docs/geometric-stiffness.md): the FFRF coupler (chord frame, with
the geometric stiffness of its axial force, flex's default) stayed within 0.35 % (largest at
0.5-0.7 mm and at 10 mm, where both FFRF bodies differ alike from the nonlinear FE one: the
rigid end faces), bounded by ``GEOMETRIC_FFRF_ERROR``; the linear FFRF coupler
(``geometric_stiffness = false``) below ``LINEAR_FFRF_ERROR_FLOOR + LINEAR_FFRF_ERROR_PER_LOAD
x`` (x the rigid probe's compression / Euler load, :func:`euler_load_ratio`; measured 0.32 %
at x = 1e-4, 0.53 % at 0.0076, 3.2 % at 0.049, 13 % at 0.13, 16 % at 0.20, 18 % at 0.33)."""


FFRF_MOTION_ERROR_FRACTION = 0.15
"""The FFRF body's error against the nonlinear FE coupler on the quantities of the motion
(crank angle and slider position at the end time, peak joint forces, deployment time), as a
fraction of what the link's elasticity changes in them (the FFRF run against its rigid twin),
measured by ``make flexible`` (1-10 mm plates over the reference's span; its report prints
the run's fractions): up to 0.13 on the joint forces' peaks (the axial ringing the reduced
body represents with one axial mode), up to 0.16 on the crank angle."""


def flexible_rung(load_ratio: float, tolerance: float, geometric_stiffness: bool = True
                  ) -> tuple[str, float]:
    """The coupler's flexible rung for ``tolerance`` (relative to the quantity: the peak
    deflection or stress the rung computes): ``"ffrf"`` when its measured model error meets
    it (:data:`GEOMETRIC_FFRF_ERROR`, or the linear body's bound at ``load_ratio``, the rigid
    probe's compression / Euler load, without ``geometric_stiffness``), else
    ``"nonlinear_fe"``; and the FFRF rung's relative model error. All dimensionless."""
    relative = (GEOMETRIC_FFRF_ERROR if geometric_stiffness
                else LINEAR_FFRF_ERROR_FLOOR + LINEAR_FFRF_ERROR_PER_LOAD * load_ratio)
    return (FFRF if relative <= tolerance else NONLINEAR_FE), relative


def euler_load_ratio(force_B_N: np.ndarray, force_C_N: np.ndarray,
                     coupler_angle_rad: np.ndarray, length_m: float, thickness_m: float,
                     width_m: float, youngs_modulus_Pa: float) -> float:
    """Largest compressive axial force in the coupler / its Euler load pi^2 E I / L^2.

    Contract: joint forces on the coupler at B and C (n, 2) [N] and the angle of B -> C
    [rad], as :func:`quasi_static_stress`; I = w t^3 / 12 (in-plane bending). The axial
    force is linear between the joints, so its largest compression is at one of them.
    """
    axial_b, _ = chord_components(force_B_N, coupler_angle_rad)
    axial_c, _ = chord_components(force_C_N, coupler_angle_rad)
    compression = max(float(np.max(axial_b)), float(np.max(-axial_c)), 0.0)
    return compression / euler_buckling_load_N(length_m, thickness_m, width_m,
                                               youngs_modulus_Pa)


def _window(data: Mapping[str, np.ndarray], end_s: float) -> np.ndarray:
    return np.asarray(data["time"]) <= end_s * (1 + 1e-12)


def error_measures(rigid: Mapping[str, np.ndarray], ffrf: Mapping[str, np.ndarray],
                   length_m: float, thickness_m: float, width_m: float,
                   window_end_s: float, youngs_modulus_Pa: float = THESIS_YOUNGS_MODULUS_PA
                   ) -> dict[str, float]:
    """The error measures of :data:`MEASURES` plus their absolute values.

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
    w_r, w_f = _window(rigid, window_end_s), _window(ffrf, window_end_s)
    count = min(int(w_r.sum()), int(w_f.sum()))
    if count < 3:
        raise ValueError(f"window [0, {window_end_s:g}] s holds {count} common samples")
    t_r, t_f = np.asarray(rigid["time"])[:count], np.asarray(ffrf["time"])[:count]
    if not np.allclose(t_r, t_f, rtol=0, atol=1e-9 * max(1.0, float(t_r[-1]))):
        raise ValueError("rigid and FFRF runs are not sampled at the same times")

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
                                    series(rigid, "coupler/angle"), length_m, thickness_m,
                                    width_m)
    peak_qs = float(stress_qs.max())
    peak_ffrf = float(series(ffrf, "coupler/peak_bending_stress").max())
    out = {
        "deflection": deflection / length_m,
        "crank_angle": crank_dev / swing,
        "slider_position": slider_dev / travel,
        "stress_amplification": abs(peak_ffrf / peak_qs - 1.0),
        "stress_ratio": peak_ffrf / peak_qs,
        "euler_load_ratio": euler_load_ratio(series(rigid, "joints/B/force_on_coupler"),
                                             series(rigid, "joints/C/force_on_coupler"),
                                             series(rigid, "coupler/angle"), length_m,
                                             thickness_m, width_m, youngs_modulus_Pa),
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


# ------------------------------------------------------------------------------------------
# error laws
# ------------------------------------------------------------------------------------------
def errors_against_full(run: Mapping[str, np.ndarray], full: Mapping[str, np.ndarray],
                        link: str, length_m: float) -> dict[str, float]:
    """Relative errors of ``run`` (rigid or auto) against the ``full`` flexible model.

    Contract: series of the result layout; over the full run's deployment (samples up to
    its first crank-angle maximum): ``deflection`` = max |midpoint deflection of ``link``
    (``"coupler"`` or ``"crank"``) difference| / ``length_m`` (a run without that dataset
    counts as 0: a rigid link), ``crank_angle`` / swing and ``slider_position`` / travel of
    the full run; ``governing`` the largest of the three; ``delta_t`` [s] the full run's
    deployment time.
    """
    times = deployment_times(full["time"], full["crank/angle"], full["crank/angular_velocity"])
    count = int(np.sum(np.asarray(full["time"]) <= times["stop"] * (1 + 1e-12)))

    def deviation(key: str) -> float:
        mine = np.asarray(run.get(key, np.zeros(count)))
        return float(np.max(np.abs(mine[:count] - np.asarray(full[key])[:count])))

    angle, slider = np.asarray(full["crank/angle"]), np.asarray(full["slider/position"])
    swing = float(np.max(np.abs(angle[:count] - angle[0])))
    travel = float(np.max(np.abs(slider[:count] - slider[0])))
    out = {"deflection": deviation(f"{link}/midpoint_deflection") / length_m,
           "crank_angle": deviation("crank/angle") / swing,
           "slider_position": deviation("slider/position") / travel}
    out[GOVERNING] = max(out.values())
    out["delta_t"] = times["stop"]
    return out


@functools.lru_cache(maxsize=64)
def _t_quantile(dof: int, level: float) -> float:
    from scipy.special import stdtrit  # scipy.stats takes seconds to import

    return float(stdtrit(max(dof, 1), 0.5 + level / 2))


@dataclass
class ErrorLaw:
    """A fitted error law ``e(n) = floor + exp(log_coefficient) * n^-exponent``.

    ``n`` is in the **physical** convention (T = 2 pi / omega); pass ``convention="thesis"``
    to the methods to use ``n_thesis = 2 pi n_physical`` instead. The fit is made on
    ``ln e`` (relative errors count alike over decades); ``covariance`` is that of the
    parameters ``(log_coefficient, exponent[, floor])``, ``residual_std`` the standard
    deviation of the ``ln e`` residuals (so the prediction band is a factor
    ``exp(t * residual_std)`` wide around the law, plus parameter uncertainty).
    """

    log_coefficient: float
    exponent: float
    floor: float
    covariance: np.ndarray
    residual_std: float
    dof: int
    r_squared: float
    n_min: float
    n_max: float
    e_min: float
    e_max: float
    n_points: int
    with_floor: bool = False
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def coefficient(self) -> float:
        """``c`` of ``c n^-p`` (physical convention)."""
        return math.exp(self.log_coefficient)

    def coefficient_in(self, convention: str) -> float:
        """``c`` such that ``e = floor + c n^-p`` with n in ``convention``."""
        return self.coefficient * (TWO_PI ** self.exponent if convention == "thesis" else 1.0)

    def exponent_half_width(self, level: float = 0.95) -> float:
        """Half width of the two-sided ``level`` confidence interval of the exponent p
        (Student t on the law's degrees of freedom)."""
        return _t_quantile(self.dof, level) * math.sqrt(self.covariance[1, 1])

    def _params(self) -> np.ndarray:
        values = [self.log_coefficient, self.exponent]
        if self.with_floor:
            values.append(self.floor)
        return np.array(values)

    def _log_model(self, x: np.ndarray, params: np.ndarray) -> np.ndarray:
        power = params[0] - params[1] * x
        if not self.with_floor:
            return power
        return np.logaddexp(power, math.log(max(params[2], 1e-300)))

    def _gradient(self, x: np.ndarray) -> np.ndarray:
        params = self._params()
        if not self.with_floor:
            return np.column_stack([np.ones_like(x), -x])
        return _floor_gradient(x, params)

    def predict(self, n: Any, convention: str = "physical") -> np.ndarray:
        """Central fitted error at ``n`` (scalar or array; dimensionless)."""
        x = np.log(convert_n(np.asarray(n, dtype=float), convention, "physical"))
        return np.exp(self._log_model(x, self._params()))

    def band(self, n: Any, convention: str = "physical", level: float = 0.95,
             kind: str = "prediction") -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper band at ``n``: ``confidence`` (of the law) or ``prediction``
        (of one more case: adds the scatter ``residual_std``), at ``level`` (two-sided)."""
        if kind not in ("confidence", "prediction"):
            raise ValueError(f"kind {kind!r}: must be 'confidence' or 'prediction'")
        x = np.atleast_1d(np.log(convert_n(np.asarray(n, dtype=float), convention,
                                           "physical")))
        centre = self._log_model(x, self._params())
        gradient = self._gradient(x)
        variance = np.einsum("ij,jk,ik->i", gradient, self.covariance, gradient)
        if kind == "prediction":
            variance = variance + self.residual_std**2
        half = _t_quantile(self.dof, level) * np.sqrt(np.maximum(variance, 0.0))
        with np.errstate(over="ignore"):  # a band wider than a float holds is unbounded: inf
            lower, upper = np.exp(centre - half), np.exp(centre + half)
        if np.ndim(n) == 0:
            return lower[0], upper[0]
        return lower, upper

    def k(self, tolerance: float, convention: str = "physical", bound: str = "central",
          level: float = 0.95) -> float:
        """Smallest n with error <= ``tolerance`` for every larger n; ``inf`` if none.

        ``bound``: ``central`` (the fitted law), ``upper`` (upper prediction band),
        ``upper_confidence`` (upper confidence band of the law). A law that does not decrease
        (exponent <= 0) or whose floor is at or above the tolerance gives ``inf``.
        """
        if not tolerance > 0:
            raise ValueError(f"tolerance = {tolerance!r}: must be > 0")
        if self.exponent <= 0 or (self.with_floor and self.floor >= tolerance):
            return math.inf
        if bound == "central":
            n = (self.coefficient / (tolerance - (self.floor if self.with_floor else 0.0))
                 ) ** (1.0 / self.exponent)
            return float(convert_n(n, "physical", convention))
        kind = {"upper": "prediction", "upper_confidence": "confidence"}.get(bound)
        if kind is None:
            raise ValueError(f"bound {bound!r}: must be central, upper or upper_confidence")
        # the band is not monotone far outside the data: scan a wide log grid from the
        # top down, keep the last n (going down) where it still holds
        grid = np.geomspace(self.n_min * 1e-3, self.n_max * 1e4, 2000)
        upper = self.band(grid, "physical", level, kind)[1]
        ok = upper <= tolerance
        if not ok[-1]:
            return math.inf
        bad = np.flatnonzero(~ok)
        if len(bad) == 0:
            return float(convert_n(grid[0], "physical", convention))
        lo, hi = grid[bad[-1]], grid[bad[-1] + 1]
        for _ in range(60):  # bisection in log n
            mid = math.sqrt(lo * hi)
            if self.band(mid, "physical", level, kind)[1] <= tolerance:
                hi = mid
            else:
                lo = mid
        return float(convert_n(hi, "physical", convention))

    def extrapolated(self, n_physical: float) -> bool:
        """True if ``n_physical`` lies outside the n range of the fitted data."""
        return not (self.n_min <= n_physical <= self.n_max)

    def to_dict(self) -> dict[str, Any]:
        """Plain values for TOML/HDF5 (the inverse of :meth:`from_dict`)."""
        return {"log_coefficient": self.log_coefficient, "exponent": self.exponent,
                "floor": self.floor, "with_floor": self.with_floor,
                "covariance": [list(map(float, row)) for row in self.covariance],
                "residual_std": self.residual_std, "dof": self.dof,
                "r_squared": self.r_squared, "n_min": self.n_min, "n_max": self.n_max,
                "e_min": self.e_min, "e_max": self.e_max, "n_points": self.n_points,
                **{f"meta_{k}": v for k, v in self.meta.items()}}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ErrorLaw:
        """Rebuild a law stored by :meth:`to_dict`."""
        meta = {k[5:]: v for k, v in data.items() if k.startswith("meta_")}
        return cls(log_coefficient=float(data["log_coefficient"]),
                   exponent=float(data["exponent"]), floor=float(data["floor"]),
                   covariance=np.asarray(data["covariance"], dtype=float),
                   residual_std=float(data["residual_std"]), dof=int(data["dof"]),
                   r_squared=float(data["r_squared"]), n_min=float(data["n_min"]),
                   n_max=float(data["n_max"]), e_min=float(data["e_min"]),
                   e_max=float(data["e_max"]), n_points=int(data["n_points"]),
                   with_floor=bool(data["with_floor"]), meta=meta)


def _floor_gradient(x: np.ndarray, params: np.ndarray) -> np.ndarray:
    log_c, p, floor = params
    power = np.exp(log_c - p * x)
    total = power + max(floor, 1e-300)
    return np.column_stack([power / total, -x * power / total, 1.0 / total])


def fit_error_law(n: Any, errors: Any, convention: str = "physical",
                  floor: bool = False) -> ErrorLaw:
    """Fit ``e = floor + c n^-p`` to positive errors, by least squares on ``ln e``.

    ``n`` in ``convention`` (stored in the physical one). ``floor=False``: ordinary least
    squares of ``ln e`` on ``ln n`` (exact covariance). ``floor=True``: nonlinear least
    squares with ``floor >= 0`` (scipy), covariance from the Jacobian. Non-finite or
    non-positive errors are dropped (a measure of exactly 0 carries no scale). Needs at least
    3 points (4 with a floor); raises ValueError otherwise.
    """
    n_phys = convert_n(np.asarray(n, dtype=float), convention, "physical")
    e = np.asarray(errors, dtype=float)
    keep = np.isfinite(n_phys) & np.isfinite(e) & (e > 0) & (n_phys > 0)
    n_phys, e = n_phys[keep], e[keep]
    n_params = 3 if floor else 2
    if len(e) < n_params + 1:
        raise ValueError(f"fit_error_law: {len(e)} usable points, need at least "
                         f"{n_params + 1}")
    x, y = np.log(n_phys), np.log(e)
    if not floor:
        design = np.column_stack([np.ones_like(x), -x])
        params, *_ = np.linalg.lstsq(design, y, rcond=None)
        residual = y - design @ params
        dof = len(y) - 2
        s2 = float(residual @ residual) / dof
        covariance = s2 * np.linalg.inv(design.T @ design)
        floor_value = 0.0
    else:
        from scipy.optimize import least_squares

        start = np.linalg.lstsq(np.column_stack([np.ones_like(x), -x]), y, rcond=None)[0]
        guess = np.array([start[0], max(start[1], 0.1), 0.5 * float(e.min())])

        def residuals(theta: np.ndarray) -> np.ndarray:
            return np.logaddexp(theta[0] - theta[1] * x, math.log(max(theta[2], 1e-300))) - y

        solution = least_squares(residuals, guess, bounds=([-np.inf, -10.0, 0.0],
                                                           [np.inf, 20.0, np.inf]),
                                 x_scale="jac")
        params = solution.x
        residual = -solution.fun
        dof = len(y) - 3
        s2 = float(residual @ residual) / dof
        jacobian = _floor_gradient(x, params)
        covariance = s2 * np.linalg.pinv(jacobian.T @ jacobian)
        floor_value = float(params[2])
    total = float(np.sum((y - y.mean()) ** 2))
    r_squared = 1.0 - float(residual @ residual) / total if total > 0 else 1.0
    return ErrorLaw(log_coefficient=float(params[0]), exponent=float(params[1]),
                    floor=floor_value, covariance=np.asarray(covariance),
                    residual_std=math.sqrt(s2), dof=int(dof), r_squared=r_squared,
                    n_min=float(n_phys.min()), n_max=float(n_phys.max()),
                    e_min=float(e.min()), e_max=float(e.max()), n_points=int(len(e)),
                    with_floor=floor)


# ------------------------------------------------------------------------------------------
# stored criterion
# ------------------------------------------------------------------------------------------
@dataclass
class Criterion:
    """Fitted laws for the ``auto`` decision: ``laws[(damping_ratio, measure)]``.

    All laws use the ``delta_t_definition`` deployment time, Euler-Bernoulli pinned-pinned
    omega, and n in the physical convention.
    """

    laws: dict[tuple[float, str], ErrorLaw]
    delta_t_definition: str = PRIMARY_DELTA_T
    source: str = ""
    meta: dict[str, Any] = field(default_factory=dict)

    def law(self, damping_ratio: float, measure: str = GOVERNING) -> tuple[float, ErrorLaw]:
        """The law for the largest fitted damping ratio not above ``damping_ratio``
        (damping lowers the error, so this is the conservative choice)."""
        ratios = sorted({ratio for ratio, name in self.laws if name == measure})
        if not ratios:
            raise FlexError(f"criterion {self.source or '(in memory)'} has no law for "
                            f"measure '{measure}'")
        chosen = [r for r in ratios if r <= damping_ratio + 1e-12]
        ratio = chosen[-1] if chosen else ratios[0]
        return ratio, self.laws[(ratio, measure)]

    def to_toml(self, header: str = "") -> str:
        """The criterion as TOML text (what ``make kfit`` writes)."""
        import tomli_w

        data: dict[str, Any] = {"criterion": {"format": CRITERION_FORMAT,
                                              "delta_t_definition": self.delta_t_definition,
                                              "omega": "euler_bernoulli_pinned_pinned",
                                              "n_convention": "physical", **self.meta},
                                "laws": []}
        for (ratio, measure), law in sorted(self.laws.items()):
            data["laws"].append({"damping_ratio": ratio, "measure": measure, **law.to_dict()})
        return header + tomli_w.dumps(data)


def criteria_in_force_text(scene: Mapping[str, Mapping[str, Any]]) -> str:
    """The text of the installed criterion files ``scene``'s ``model = "auto"`` links read
    when no law is passed (``""`` for none; a missing file as its path), with the load
    prediction's margin they are decided by: part of a sweep case's identity."""
    parts = []
    for link, path in (("coupler", DEFAULT_CRITERION), ("crank", DEFAULT_CRANK_CRITERION)):
        if scene.get(link, {}).get("model") == "auto":
            try:
                parts.append(f"{link}:{path.read_text('utf-8')}")
            except OSError:
                parts.append(f"{link}:missing {path}")
    if parts:
        parts.append(f"prediction margin {PREDICTION_MARGIN!r}")
    return "\n".join(parts)


def load_criterion(path: str | Path | None = None) -> Criterion:
    """Read a criterion file: ``path``, else :data:`DEFAULT_CRITERION`. Raises
    :class:`FlexError` naming the file if it is missing or malformed."""
    path = Path(path or DEFAULT_CRITERION)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FlexError(f"criterion file '{path}' does not exist; run 'make kfit' and "
                        f"'make kfit-criterion' to create it") from None
    return parse_criterion(text, str(path))


def parse_criterion(text: str, source: str = "") -> Criterion:
    """A criterion from its TOML text (what :meth:`Criterion.to_toml` writes); ``source``
    names it in messages and decisions. Raises :class:`FlexError` if it is malformed."""
    label = source or "(in memory)"
    try:
        data = tomllib.loads(text)
        if data["criterion"]["format"] != CRITERION_FORMAT:
            raise FlexError(f"criterion {label}: format {data['criterion']['format']!r}"
                            f", expected {CRITERION_FORMAT!r}")
        laws = {(float(entry["damping_ratio"]), str(entry["measure"])): ErrorLaw.from_dict(entry)
                for entry in data["laws"]}
    except (KeyError, TypeError, ValueError, tomllib.TOMLDecodeError) as exc:
        raise FlexError(f"criterion file '{label}' is malformed: {exc}") from None
    meta = {k: v for k, v in data["criterion"].items()
            if k not in ("format", "delta_t_definition", "omega", "n_convention")}
    return Criterion(laws, data["criterion"]["delta_t_definition"], source, meta)


