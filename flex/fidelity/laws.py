"""Fitted error laws and the stored criterion ``auto`` reads (:mod:`flex.fidelity.criteria`
has the measures they are fitted to and the module doc of the whole statement).

- **error law** (:func:`fit_error_law`, :class:`ErrorLaw`): ``e(n) = floor + c n^-p``
  fitted in log space (floor = 0: a straight line in log-log, ordinary least squares) with
  95 % confidence and prediction bands (delta method, Student t).
- **k for a tolerance** (:meth:`ErrorLaw.k`): for a tolerance eps, ``k(eps)`` is the
  smallest n such that the fitted error ``e(n) <= eps`` for all larger n (the law is
  decreasing); ``inf`` when the law never gets below eps (a floor, or no decrease). The
  ``upper`` bound uses the upper 95 % prediction band instead of the central fit: a
  conservative k that covers the scatter of the sweep's cases around the law.
- **the fitted laws** ``auto`` reads (:mod:`flex.fidelity.auto` decides) are read from
  a calibration (:func:`criterion_of`; the bundled ``flex/config/criteria_fit.toml`` is written
  by ``make kfit`` and installed by ``make calibration-install``), or passed as a
  :class:`Criterion`.
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
from flex.base.physics import TWO_PI
from flex.config.calibration import BUNDLED_FOLDER, FILES, Calibration, calibration_of
from flex.fidelity.criteria import GOVERNING, PRIMARY_DELTA_T, convert_n, deployment_times
from flex.fidelity.predictor import PREDICTION_MARGIN

CRITERION_FORMAT = "flex-criterion/1"
#: the bundled coupler law (``make kfit``, installed by ``make calibration-install``)
DEFAULT_CRITERION = BUNDLED_FOLDER / FILES["coupler_criterion"]
#: the bundled crank law (``make crank``): the coupler law under-predicts a crank carrying a
#: wing (README, "The crank")
DEFAULT_CRANK_CRITERION = BUNDLED_FOLDER / FILES["crank_criterion"]
#: the parts of a calibration holding each link's law
CRITERION_PARTS = {"coupler": "coupler_criterion", "crank": "crank_criterion"}


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
    """What ``scene``'s ``model = "auto"`` links are decided by beyond their calibration's
    laws (:attr:`flex.config.calibration.Calibration.digest` holds those): the load
    prediction's margin (``""`` without such links); part of a sweep case's identity."""
    if any(scene.get(link, {}).get("model") == "auto" for link in CRITERION_PARTS):
        return f"prediction margin {PREDICTION_MARGIN!r}"
    return ""


def criterion_of(calibration: Calibration | None = None, link: str = "coupler") -> Criterion:
    """The fitted law ``link``'s ``model = "auto"`` reads: ``calibration``'s (None: the
    bundled calibration's). Raises :class:`FlexError` naming the file if it is not installed
    or malformed."""
    calibration = calibration_of(calibration)
    part = CRITERION_PARTS[link]
    text = getattr(calibration, f"{part}_toml")
    path = calibration.path(part)
    if text is None:
        study = "kfit" if link == "coupler" else "crank"
        raise FlexError(f"criterion file '{path}' does not exist; run 'make {study}' and "
                        f"'make calibration-install' to create it")
    return parse_criterion(text, str(path))


def load_criterion(path: str | Path | None = None) -> Criterion:
    """Read a criterion file: ``path``, else the bundled calibration's coupler law
    (:func:`criterion_of`). Raises :class:`FlexError` naming the file if it is missing or
    malformed."""
    if path is None:
        return criterion_of()
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FlexError(f"criterion file '{path}' does not exist; run 'make kfit' and "
                        f"'make calibration-install' to create it") from None
    except (OSError, UnicodeDecodeError) as exc:  # a folder, unreadable, not UTF-8
        raise FlexError(f"criterion file '{path}' cannot be read: "
                        f"{getattr(exc, 'strerror', None) or exc}") from None
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


