"""Work-precision measurement: how much wall time buys how much accuracy.

A :class:`Setting` is one combination of knobs: scene overrides (``simulation.step_s``,
``simulation.spectral_radius``, ``simulation.formulation``, ``simulation.newton``,
``simulation.integrator``, ``coupler.modes``, ``coupler.mesh_size_m``, ``coupler.model``,
...) run by flex's Exudyn model, or the independent scipy reference DAE
(:mod:`flex.reference`, ``engine = "scipy"``) at a given method and tolerance.
:func:`measure` runs a setting ``repeats`` times and returns a :class:`Measurement`: the
median wall time of the integration, steps, Newton iterations, and the errors against a
converged :class:`Reference`:

- ``crank_angle_rad``: max over the run's samples of |theta - theta_ref| [rad];
- ``slider_position_m``: max |x - x_ref| [m];
- ``peak_deflection_m``: |peak - peak_ref| of the elastic midpoint deflection [m] (flexible
  couplers; peaks refined by a parabola through the three samples around the largest |w|);
- relative errors: the first two divided by the reference's range (swing of the crank,
  travel of the slider; 1 rad and 1 mm for a reference that does not move), the third by
  the reference peak; ``error`` is the largest of the
  relative errors a scene has (the work-precision diagrams plot it).

A reference is *shown* converged (:func:`converged_reference`): the finest setting is run,
then each knob is coarsened by one level (step x 2, fewer modes, coarser mesh, looser
tolerance) and the relative change of every error measure is stored as the evidence; the
reference counts as converged to ``tolerance`` when every change is below it (for a
convergent sequence the finest run's own error is then below the change).

:func:`pareto_front` marks the settings no other setting beats in both wall time and error;
:func:`recommend` picks, per accuracy level, the fastest setting within it (it lies on the
front), refusing levels finer than the reference can certify.

Wall times are medians over repeats on a shared machine: compare ratios measured in one run.
"""

from __future__ import annotations

import contextlib
import math
import statistics
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import FlexError, SceneError
from .reference import solve_reference
from .results import Dataset
from .scene import Scene, apply_overrides, validate

#: relative accuracy levels for which a setting is recommended (1 %, 0.1 %, 0.01 %)
ACCURACY_LEVELS = (1e-2, 1e-3, 1e-4)
#: a reference certifies an accuracy level only if the level is at least this many times the
#: largest change under one-level coarsening (the change estimates the *coarser* run's error;
#: the reference's own is smaller again, by 2^p - 1 for a method of order p and halving)
REFERENCE_MARGIN = 3.0
#: wall times within this fraction of the fastest count as a tie (broken by accuracy)
TIE_FRACTION = 0.1
#: settings whose first run takes longer than this [s] are not repeated (median of one)
REPEAT_LIMIT_S = 5.0


@dataclass(frozen=True)
class Setting:
    """One knob combination.

    ``overrides``: scene keys ``"section.key"`` -> value, applied to the scene being studied;
    ``engine``: ``"exudyn"`` (flex's model, :func:`flex.solver.simulate`) or ``"scipy"``
    (the reference DAE of :mod:`flex.reference`, rigid coupler only) with ``method``,
    ``rtol`` and ``atol`` for ``solve_ivp``; ``group``: which sweep it belongs to (one knob
    at a time, or a combination), used to colour the diagrams.
    """

    label: str
    overrides: tuple[tuple[str, Any], ...] = ()
    engine: str = "exudyn"
    method: str = "DOP853"
    rtol: float = 1e-12
    atol: float = 1e-14
    group: str = ""
    element_order: int = 2  #: FFRF mesh: 2 = quadratic tetrahedra (flex's), 1 = linear

    @staticmethod
    def of(label: str, group: str = "", **knobs: Any) -> Setting:
        """``Setting.of("h=1e-4", step_s=1e-4)``: knob names without section map to
        ``[simulation]`` keys, ``coupler__modes`` to ``coupler.modes``."""
        overrides = []
        for name, value in knobs.items():
            key = name.replace("__", ".") if "__" in name else f"simulation.{name}"
            overrides.append((key, value))
        return Setting(label, tuple(overrides), group=group)

    def knobs(self) -> dict[str, Any]:
        """Everything that defines the run (stored with each measurement)."""
        out: dict[str, Any] = {"engine": self.engine}
        if self.engine == "scipy":
            out.update(method=self.method, rtol=self.rtol, atol=self.atol)
        out.update({key: value for key, value in self.overrides})
        if self.element_order != 2:
            out["element_order"] = self.element_order
        return out


def _toml_value(value: Any) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value)


def scene_for(base: Scene, setting: Setting) -> Scene:
    """``base`` with the setting's overrides, validated (raises SceneError)."""
    scene = apply_overrides(base, [f"{key}={_toml_value(value)}"
                                   for key, value in setting.overrides])
    validate(scene)
    return scene


# ------------------------------------------------------------------------------------------
# observables and errors
# ------------------------------------------------------------------------------------------
#: scales of the relative errors for a reference that hardly moves (a start at a dead
#: centre): 1 rad of crank angle, 1 mm of slider travel
ANGLE_SCALE_RAD = 1.0
SLIDER_SCALE_M = 1e-3


def _scale(reference: np.ndarray, fallback: float) -> float:
    """Range of ``reference`` (its swing or travel), or ``fallback`` if it is below 1e-6 of
    the fallback (the relative error would then divide by round-off)."""
    spread = float(np.ptp(reference))
    return spread if spread > 1e-6 * fallback else fallback


def peak_value(time_s: np.ndarray, signal: np.ndarray) -> float:
    """Largest |signal|, refined by a parabola through the three samples around it.

    The refinement removes most of the sampling error of a coarse output grid (a sampled
    sine peak is low by up to 1 - cos(pi f dt)); at the ends of the series the sample
    itself is returned.
    """
    magnitude = np.abs(np.asarray(signal, dtype=float))
    if magnitude.size == 0:
        return float("nan")
    i = int(np.argmax(magnitude))
    if i == 0 or i == magnitude.size - 1:
        return float(magnitude[i])
    y0, y1, y2 = magnitude[i - 1:i + 2]
    curvature = y0 - 2 * y1 + y2
    if curvature >= 0:  # not a maximum of a smooth curve (flat or a kink): keep the sample
        return float(y1)
    offset = 0.5 * (y0 - y2) / curvature
    return float(y1 - 0.25 * (y0 - y2) * offset)


@dataclass
class Observables:
    """What the errors are computed from: time [s], crank angle [rad], slider position [m],
    elastic midpoint deflection [m] (None for a rigid coupler)."""

    time_s: np.ndarray
    crank_angle_rad: np.ndarray
    slider_position_m: np.ndarray
    deflection_m: np.ndarray | None = None

    @staticmethod
    def of_datasets(datasets: dict[str, Dataset], flexible: bool) -> Observables:
        """From a :class:`~flex.results.CaseResult`'s datasets."""
        return Observables(np.asarray(datasets["time"].data),
                           np.asarray(datasets["crank/angle"].data),
                           np.asarray(datasets["slider/position"].data),
                           np.asarray(datasets["coupler/midpoint_deflection"].data)
                           if flexible else None)


@dataclass
class Reference:
    """A converged solution of one scene and the evidence that it is converged.

    ``evidence`` maps each coarsening (``"step_s x2"``, ``"modes 12 -> 8"``, ...) to the
    largest relative change of the error measures it caused; ``tolerance`` is the relative
    accuracy the reference claims (``accuracy`` the largest change actually seen).
    """

    label: str
    observables: Observables
    setting: Setting
    evidence: dict[str, dict[str, float]]
    tolerance: float
    wall_time_s: float
    description: str = ""
    _splines: dict[str, Any] = field(default_factory=dict, repr=False)

    @property
    def flexible(self) -> bool:
        return self.observables.deflection_m is not None

    @property
    def accuracy(self) -> float:
        """Largest relative change seen under one-level coarsening (the reference's error
        is at most about this); 0 if no coarsening was run."""
        changes = [change["error"] for change in self.evidence.values()]
        return max(changes) if changes else 0.0

    @property
    def converged(self) -> bool:
        return bool(self.evidence) and self.accuracy <= self.tolerance

    @property
    def peak_deflection_m(self) -> float:
        if self.observables.deflection_m is None:
            return float("nan")
        return peak_value(self.observables.time_s, self.observables.deflection_m)

    def at(self, name: str, time_s: np.ndarray) -> np.ndarray:
        """The reference's ``crank_angle_rad`` or ``slider_position_m`` at ``time_s`` (cubic
        spline through the reference samples)."""
        from scipy.interpolate import CubicSpline

        if name not in self._splines:
            self._splines[name] = CubicSpline(self.observables.time_s,
                                              getattr(self.observables, name))
        return self._splines[name](np.clip(time_s, self.observables.time_s[0],
                                           self.observables.time_s[-1]))

    def errors(self, run: Observables) -> dict[str, float]:
        """Absolute and relative errors of ``run`` (see the module doc) and ``error``.

        Compared at the run's samples inside the reference's span; a run whose step does not
        divide the horizon may end up to 1 % early (a shorter run raises FlexError)."""
        ref = self.observables
        if run.time_s[-1] < 0.99 * ref.time_s[-1]:
            raise FlexError(f"run ends at t = {run.time_s[-1]:g} s, well before the reference "
                            f"({ref.time_s[-1]:g} s)")
        inside = run.time_s <= ref.time_s[-1] * (1 + 1e-9)  # a step count that rounds up
        time_s = run.time_s[inside]
        angle = float(np.max(np.abs(run.crank_angle_rad[inside]
                                    - self.at("crank_angle_rad", time_s))))
        slider = float(np.max(np.abs(run.slider_position_m[inside]
                                     - self.at("slider_position_m", time_s))))
        out = {"crank_angle_rad": angle,
               "crank_angle_relative": angle / _scale(ref.crank_angle_rad, ANGLE_SCALE_RAD),
               "slider_position_m": slider,
               "slider_position_relative": slider / _scale(ref.slider_position_m,
                                                           SLIDER_SCALE_M),
               "peak_deflection_m": float("nan"), "peak_deflection_relative": float("nan")}
        if self.flexible:
            if run.deflection_m is None:
                raise FlexError("a flexible reference needs a run with a midpoint deflection")
            peak = peak_value(run.time_s, run.deflection_m)
            out["peak_deflection_m"] = abs(peak - self.peak_deflection_m)
            out["peak_deflection_relative"] = out["peak_deflection_m"] / self.peak_deflection_m
        relative = [value for key, value in out.items()
                    if key.endswith("_relative") and math.isfinite(value)]
        out["error"] = max(relative)
        return out


# ------------------------------------------------------------------------------------------
# running a setting
# ------------------------------------------------------------------------------------------
@dataclass
class Measurement:
    """One setting measured: knobs, status, median wall time [s] of the integration (over
    ``repeats`` runs; ``wall_times_s`` all of them), ``total_time_s`` (build + integration +
    output, median), counters and errors (see :meth:`Reference.errors`). A failed setting
    has ``status = "failed"``, a ``message`` naming step and time, and no errors."""

    setting: Setting
    status: str = "ok"
    message: str = ""
    wall_time_s: float = float("nan")
    wall_times_s: list[float] = field(default_factory=list)
    total_time_s: float = float("nan")
    steps: int = 0
    newton_iterations: int = 0
    jacobian_updates: int = 0
    errors: dict[str, float] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def error(self) -> float:
        return self.errors.get("error", float("nan"))


@contextlib.contextmanager
def element_order(order: int) -> Iterator[None]:
    """Build reductions with tetrahedra of ``order`` (1 or 2) inside the block.

    :mod:`flex.reduction` fixes quadratic tetrahedra (module constant ``_MESH_ORDER``, part of
    the cache key); the work-precision study sets it for the duration of one build to show
    what linear tetrahedra cost in accuracy. Raises SceneError if the constant is gone.
    """
    from . import reduction

    if order not in (1, 2):
        raise SceneError(f"element_order = {order!r}: must be 1 or 2")
    if not hasattr(reduction, "_MESH_ORDER"):
        raise SceneError("element_order: flex.reduction no longer exposes _MESH_ORDER")
    previous = reduction._MESH_ORDER
    reduction._MESH_ORDER = order
    try:
        yield
    finally:
        reduction._MESH_ORDER = previous


class ReductionPool:
    """Reductions (and their FFRF interfaces) built once per key and shared by all runs."""

    def __init__(self) -> None:
        self._by_key: dict[tuple, Any] = {}

    def for_scene(self, scene: Scene, order: int = 2) -> Any:
        """The scene's reduction (tetrahedra of ``order``) for an ``ffrf`` coupler, else
        None."""
        if scene["coupler"]["model"] != "ffrf":
            return None
        from .solver import reduction_for_scene

        c = scene["coupler"]
        key = tuple(c[k] for k in ("length_m", "thickness_m", "width_m", "youngs_modulus_Pa",
                                   "density_kg_per_m3", "poisson_ratio", "mesh_size_m",
                                   "modes")) + (order,)
        if key not in self._by_key:
            with element_order(order):
                self._by_key[key] = reduction_for_scene(scene)
        return self._by_key[key]


def run_once(scene: Scene, setting: Setting, pool: ReductionPool | None = None
             ) -> tuple[Observables, dict[str, float]]:
    """Run ``setting`` on ``scene`` (already overridden) once: observables and counters
    (``wall_time_s`` = integration only, ``total_time_s``, steps, Newton iterations).
    Raises :class:`~flex.errors.FlexError` (SimulationError, SceneError) on failure."""
    start = time.perf_counter()
    flexible = scene["coupler"]["model"] != "rigid"
    if setting.engine == "scipy":
        if flexible:
            raise SceneError("the scipy reference DAE models a rigid coupler only")
        sim = scene["simulation"]
        interval = sim["output_step_s"] or sim["step_s"]
        count = int(round(sim["end_time_s"] / interval))
        solution = solve_reference(scene, np.linspace(0.0, count * interval, count + 1),
                                   rtol=setting.rtol, atol=setting.atol, method=setting.method)
        observables = Observables(solution.time_s, solution.q[:, 2], solution.q[:, 6])
        counters = {"wall_time_s": solution.wall_time_s, "steps": 0,
                    "newton_iterations": 0, "jacobian_updates": 0,
                    "function_evaluations": solution.function_evaluations}
    else:
        from .solver import simulate

        reduction = (pool or ReductionPool()).for_scene(scene, setting.element_order)
        result = simulate(scene, setting.label, reduction)
        observables = Observables.of_datasets(result.datasets, flexible)
        counters = dict(result.counters)
    counters["total_time_s"] = time.perf_counter() - start
    return observables, counters


def measure(base: Scene, setting: Setting, reference: Reference, repeats: int = 3,
            pool: ReductionPool | None = None) -> Measurement:
    """Run ``setting`` on ``base`` ``repeats`` times (once if the first run takes longer
    than :data:`REPEAT_LIMIT_S`) and measure it against ``reference``.

    Never raises for a diverged or refused run: it comes back ``failed`` with the message.
    """
    measurement = Measurement(setting)
    try:
        scene = scene_for(base, setting)
        walls, totals = [], []
        for index in range(max(1, repeats)):
            observables, counters = run_once(scene, setting, pool)
            walls.append(float(counters["wall_time_s"]))
            totals.append(float(counters["total_time_s"]))
            if index == 0 and counters["total_time_s"] > REPEAT_LIMIT_S:
                break
        measurement.errors = reference.errors(observables)
    except FlexError as exc:
        measurement.status, measurement.message = "failed", str(exc)
        return measurement
    measurement.wall_times_s = walls
    measurement.wall_time_s = statistics.median(walls)
    measurement.total_time_s = statistics.median(totals)
    measurement.steps = int(counters.get("steps", 0))
    measurement.newton_iterations = int(counters.get("newton_iterations", 0))
    measurement.jacobian_updates = int(counters.get("jacobian_updates", 0))
    if not math.isfinite(measurement.error):
        measurement.status = "failed"
        measurement.message = "errors not finite"
    return measurement


def converged_reference(base: Scene, label: str, finest: Setting,
                        coarsenings: dict[str, Setting], tolerance: float,
                        pool: ReductionPool | None = None, description: str = "",
                        progress: Callable[[str], None] | None = None) -> Reference:
    """Run ``finest`` and each one-knob ``coarsenings`` of it; return the reference.

    The evidence of each coarsening is its :meth:`Reference.errors` against the finest run
    (relative changes of crank angle, slider position and peak deflection, and their
    maximum ``error``). Raises :class:`~flex.errors.FlexError` if the finest run fails.
    """
    scene = scene_for(base, finest)
    if progress:
        progress(f"reference {label}: {finest.label}")
    observables, counters = run_once(scene, finest, pool)
    reference = Reference(label, observables, finest, {}, tolerance,
                          float(counters["wall_time_s"]), description)
    for name, coarser in coarsenings.items():
        if progress:
            progress(f"reference {label}: evidence {name}")
        try:
            coarse_observables, _ = run_once(scene_for(base, coarser), coarser, pool)
        except FlexError as exc:  # no evidence: the reference then counts as not converged
            reference.evidence[name] = {"error": math.inf, "failed": str(exc)}
            continue
        reference.evidence[name] = reference.errors(coarse_observables)
    return reference


# ------------------------------------------------------------------------------------------
# Pareto front and recommendation
# ------------------------------------------------------------------------------------------
def pareto_front(points: Sequence[tuple[float, float]]) -> list[int]:
    """Indices of the non-dominated (wall time, error) points, by increasing wall time.

    A point is dominated if another is no slower and no less accurate and better in one of
    the two. Points with a non-finite coordinate are never on the front.
    """
    finite = [i for i, (wall, error) in enumerate(points)
              if math.isfinite(wall) and math.isfinite(error)]
    finite.sort(key=lambda i: (points[i][0], points[i][1]))
    front: list[int] = []
    best_error = math.inf
    for i in finite:
        if points[i][1] < best_error:
            front.append(i)
            best_error = points[i][1]
    return front


@dataclass
class Recommendation:
    """The fastest measured setting within an accuracy ``level`` (relative), or why none."""

    level: float
    measurement: Measurement | None
    reason: str = ""


def recommend(measurements: Iterable[Measurement], reference: Reference,
              levels: Sequence[float] = ACCURACY_LEVELS,
              eligible: Callable[[Measurement], bool] | None = None) -> list[Recommendation]:
    """Per accuracy level the fastest ``ok`` measurement with ``error <= level`` (ties by
    :func:`fastest`).

    Levels finer than ``REFERENCE_MARGIN`` x the reference's own accuracy are refused (the
    reference cannot tell such errors apart). ``eligible`` filters the candidates (e.g. only
    settings of flex's Exudyn model, not the scipy reference). The chosen setting is on the
    Pareto front of the candidates.
    """
    candidates = [m for m in measurements if m.ok and (eligible is None or eligible(m))]
    out = []
    for level in levels:
        if reference.accuracy * REFERENCE_MARGIN > level:
            out.append(Recommendation(level, None, f"reference accurate to "
                                      f"{reference.accuracy:.1e} only: cannot certify "
                                      f"{level:.0e}"))
            continue
        within = [m for m in candidates if m.error <= level]
        if not within:
            out.append(Recommendation(level, None, "no measured setting reaches it"))
            continue
        out.append(Recommendation(level, fastest(within)))
    return out


def fastest(measurements: Sequence[Measurement]) -> Measurement:
    """The fastest measurement; settings within :data:`TIE_FRACTION` of its wall time count
    as equally fast (timing noise on a shared machine) and the most accurate of them wins.
    The pick is never dominated, so it lies on the Pareto front."""
    quickest = min(m.wall_time_s for m in measurements)
    ties = [m for m in measurements if m.wall_time_s <= quickest * (1 + TIE_FRACTION)]
    return min(ties, key=lambda m: (m.error, m.wall_time_s))


def measurements_table(measurements: Sequence[Measurement], front: Iterable[int] = ()
                       ) -> dict[str, Dataset]:
    """Columns of the per-run table (stored under ``/summary/<scene>/runs/``)."""
    on_front = set(front)
    rows = list(measurements)

    def column(values, units, text, dtype=float):
        return Dataset(np.array(values, dtype=dtype), units, text)

    return {
        "label": column([m.setting.label for m in rows], "1", "setting", object),
        "group": column([m.setting.group for m in rows], "1", "sweep the setting belongs to",
                        object),
        "knobs": column([repr(m.setting.knobs()) for m in rows], "1",
                        "engine and scene overrides of the setting", object),
        "status": column([m.status for m in rows], "1", "ok | failed", object),
        "message": column([m.message for m in rows], "1", "why a run failed", object),
        "wall_time": column([m.wall_time_s for m in rows], "s",
                            "median integration wall time over the repeats"),
        "repeats": column([len(m.wall_times_s) for m in rows], "1", "runs timed", int),
        "total_time": column([m.total_time_s for m in rows], "s",
                             "median build + integration + output time"),
        "steps": column([m.steps for m in rows], "1", "time steps", int),
        "newton_iterations": column([m.newton_iterations for m in rows], "1",
                                    "Newton iterations", int),
        "jacobian_updates": column([m.jacobian_updates for m in rows], "1",
                                   "Jacobian computations", int),
        "crank_angle_error": column([m.errors.get("crank_angle_rad", np.nan) for m in rows],
                                    "rad", "max |crank angle - reference|"),
        "slider_position_error": column([m.errors.get("slider_position_m", np.nan)
                                         for m in rows], "m", "max |slider x - reference|"),
        "peak_deflection_error": column([m.errors.get("peak_deflection_m", np.nan)
                                         for m in rows], "m",
                                        "|peak midpoint deflection - reference peak|"),
        "error": column([m.error for m in rows], "1",
                        "largest relative error (angle / swing, slider / travel, peak / peak)"),
        "on_pareto_front": column([i in on_front for i in range(len(rows))], "1",
                                  "not beaten in both wall time and error", bool),
    }
