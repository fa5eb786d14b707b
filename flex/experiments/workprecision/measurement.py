"""Work-precision measurement: how much wall time buys how much accuracy.

The core every work-precision study shares (``tradeoff``, ``bench``, ``calibrate``, ``stability``).
A :class:`Setting` is one combination of knobs: scene overrides (``simulation.step_s``,
``simulation.spectral_radius``, ``simulation.formulation``, ``simulation.newton``,
``simulation.integrator``, ``coupler.modes``, ``coupler.mesh_size_m``, ``coupler.model``, ...) run
by flex's Exudyn model, or the independent scipy reference DAE (:mod:`flex.dynamics.reference`,
``engine = "scipy"``) at a given method and tolerance. :func:`measure` runs a setting ``repeats``
times and returns a :class:`Measurement`: the median wall time of the integration, steps, Newton
iterations, and the errors against a converged :class:`Reference`:

- ``crank_angle_rad``: max over the run's samples of |theta - theta_ref| [rad] (on the
  headline channel where the run has one, as the history headlines read it: the reference's
  stored accuracy is of that curve);
- ``slider_position_m``: max |x - x_ref| [m] (the same);
- ``peak_deflection_m``: |peak - peak_ref| of the elastic midpoint deflection [m] (flexible
  couplers): the peak is the certified headline a user's tolerance applies to, the coupler's
  deployment peak on the headline channel (:data:`PEAK_HEADLINE`; a raw maximum of undamped
  ringing races between sub-crests and has no order of convergence); observables made
  without it (arrays only) use the raw peak, refined by a parabola through the three samples
  around the largest |w|;
- relative errors: the first two divided by the reference's range (swing of the crank,
  travel of the slider; 1 rad and 1 mm for a reference that does not move), the third by
  the reference peak; ``error`` is the largest of the
  relative errors a scene has (the work-precision diagrams plot it).

How a reference is shown converged: :mod:`flex.experiments.workprecision.convergence`; the
Pareto front and the recommended settings: :mod:`flex.experiments.workprecision.pareto`.
:func:`measurement_case` stores one measurement as a case.

Wall times are medians over repeats on a shared machine: compare ratios measured in one run.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError, SceneError
from flex.base.physics import Plate
from flex.config.settings import has_auto_link_keys, resolve_link_keys, resolved_simulation
from flex.data.reference_store import StoredReference
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, to_toml
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, FFRF
from flex.dynamics.reference import solve_reference

#: a reference certifies an accuracy level only if the level is at least this many times the
#: reference's estimated own error (:attr:`Reference.accuracy`)
REFERENCE_MARGIN = 3.0
#: settings whose first run takes longer than this [s] are not repeated (median of one)
REPEAT_LIMIT_S = 5.0
#: a progress callback of a plan: (what, done, total)
Progress = Callable[[str, int, int], None]


def certifies(reference_accuracy: float, level: float) -> bool:
    """Whether a reference accurate to ``reference_accuracy`` (relative) can certify the
    accuracy ``level``: at least :data:`REFERENCE_MARGIN` times its own error."""
    return reference_accuracy * REFERENCE_MARGIN <= level


@dataclass(frozen=True)
class Setting:
    """One knob combination.

    ``overrides``: scene keys ``"section.key"`` -> value, applied to the scene being studied;
    ``engine``: ``"exudyn"`` (flex's model, :func:`flex.fidelity.simulation.simulate`) or
    ``"scipy"`` (the reference DAE of :mod:`flex.dynamics.reference`, rigid coupler only)
    with ``method``, ``rtol`` and ``atol`` for ``solve_ivp``; ``group``: which sweep it belongs
    to (one knob at a time, or a combination), used to colour the diagrams.
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


def scene_for(base: Scene, setting: Setting) -> Scene:
    """``base`` with the setting's overrides, validated (raises SceneError;
    :func:`flex.data.scene_edit.derive_scene`)."""
    return derive_scene(base, dict(setting.overrides))


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


#: the headline the peak deflection error is measured on (:mod:`flex.data.headlines`)
PEAK_HEADLINE = "coupler_deployment_peak_deflection_m"


@dataclass
class Observables:
    """What the errors are computed from: time [s], crank angle [rad], slider position [m],
    elastic midpoint deflection [m] (None for a rigid coupler) and the run's
    :data:`PEAK_HEADLINE` [m] (None: not read, the raw peak stands in)."""

    time_s: np.ndarray
    crank_angle_rad: np.ndarray
    slider_position_m: np.ndarray
    deflection_m: np.ndarray | None = None
    headline_peak_m: float | None = None

    @staticmethod
    def of_datasets(datasets: dict[str, Dataset], flexible: bool) -> Observables:
        """From a :class:`~flex.data.results.CaseResult`'s datasets (a flexible coupler's
        :data:`PEAK_HEADLINE` read as the run's headlines read it)."""
        from flex.data.headlines import BUILTIN_HEADLINES

        time_s, angle, slider = _motion_curves(datasets)
        return Observables(time_s, angle, slider,
                           np.asarray(datasets["coupler/midpoint_deflection"].data)[
                               :time_s.size] if flexible else None,
                           BUILTIN_HEADLINES[PEAK_HEADLINE].read(datasets) if flexible
                           else None)

    @property
    def peak_m(self) -> float:
        """The peak the errors compare [m]: the headline, or (not read) the raw peak
        (:func:`peak_value`); nan for a rigid coupler."""
        if self.headline_peak_m is not None:
            return float(self.headline_peak_m)
        if self.deflection_m is None:
            return float("nan")
        return peak_value(self.time_s, self.deflection_m)


@dataclass
class Reference:
    """A converged solution of one scene and the evidence that it is converged.

    ``evidence`` maps each coarsening (``"step_s x2"``, ``"modes 12 -> 8"``, ...) or
    refinement sequence (``"step_s"``, ...) to its record: ``error`` is the knob's estimate of
    the reference's own relative error (largest over the error measures: the change itself
    for a one-level coarsening,
    :func:`~flex.experiments.workprecision.convergence.richardson`'s estimate for a sequence,
    with ``order``, ``change_fine``, ``change_coarse``, ``asymptotic``, ``values``);
    ``tolerance`` is the relative accuracy the reference claims, ``accuracy`` the sum of the
    knobs' estimates.
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
        """Estimated relative error of the reference: the sum of every knob's estimate (the
        knobs' errors add up in the worst case); 0 if no coarsening was run."""
        return float(sum(change["error"] for change in self.evidence.values()))

    @property
    def converged(self) -> bool:
        return bool(self.evidence) and self.accuracy <= self.tolerance

    @property
    def peak_deflection_m(self) -> float:
        return self.observables.peak_m

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
            if (run.headline_peak_m is None) != (self.observables.headline_peak_m is None):
                raise FlexError("the run and the reference read their peak deflection "
                                "differently (headline and raw peak): not comparable")
            out["peak_deflection_m"] = abs(run.peak_m - self.peak_deflection_m)
            out["peak_deflection_relative"] = out["peak_deflection_m"] / self.peak_deflection_m
        relative = [value for key, value in out.items()
                    if key.endswith("_relative") and math.isfinite(value)]
        out["error"] = max(relative)
        return out


#: what a stored reference's accuracy covers (:func:`stored_as_reference`): its peak only
#: (the calibration grid, which certifies the peak), or every error measure of
#: :meth:`Reference.errors` (the crank angle's and slider position's curves and the peak:
#: the work-precision studies, whose error is the largest of them)
PEAK_ONLY, EVERY_MEASURE = "peak", "every measure"


def stored_as_reference(stored: StoredReference, covers: str = PEAK_ONLY) -> Reference:
    """A stored reference (:mod:`flex.data.reference_store`: made once by ``make references``)
    as the :class:`Reference` runs are measured against: its curves (every
    :data:`~flex.data.reference_store.CURVE_STEP_S`), its :data:`PEAK_HEADLINE` and, as its
    accuracy (relative), what ``covers`` says: :data:`PEAK_ONLY`, that headline's stored
    accuracy relative to it (what a grid's certified peak error adds; the curves' own errors
    are not added); :data:`EVERY_MEASURE`, the largest of each measure's relative accuracy:
    the crank angle's and slider position's stored history accuracies plus their cubic
    interpolation's error (:func:`~flex.experiments.workprecision.stored_references.curve_at`),
    over the scales :meth:`Reference.errors` divides by, and the peak's (the error of a
    largest relative error is at most the largest error of its parts)."""
    curves = {path: Dataset(values, stored.curve_units.get(path, "1"))
              for path, values in stored.curves.items()}
    peak = stored.values[PEAK_HEADLINE]
    time_s, angle, slider = _motion_curves(curves)
    observables = Observables(time_s, angle, slider, np.asarray(
        curves["coupler/midpoint_deflection"].data, dtype=float)[:time_s.size], peak)
    accuracies = {"peak_deflection_relative": stored.accuracies[PEAK_HEADLINE] / abs(peak)}
    if covers == EVERY_MEASURE:
        accuracies |= _curve_accuracies(stored, observables)
    elif covers != PEAK_ONLY:
        raise ValueError(f"covers = {covers!r}; accepted: {PEAK_ONLY!r}, {EVERY_MEASURE!r}")
    relative = max(accuracies.values())
    measures = ", ".join(f"{name.removesuffix('_relative').replace('_', ' ')} {value:.1e}"
                         for name, value in accuracies.items())
    return Reference(f"stored reference {stored.name}", observables, Setting(stored.model),
                     {"stored reference": {"error": relative, **accuracies}}, relative, 0.0,
                     f"the stored reference {stored.name} (make references): {stored.model}; "
                     f"relative accuracy {measures} (its evidence in the store)")


def _motion_curves(datasets: dict[str, Dataset]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time [s], crank angle [rad] and slider position [m] as the history headlines read them:
    on the headline channel up to its undetermined tail where the run (or the stored
    reference) has one (:func:`flex.data.headlines.channel_curve`; the stored accuracy is of
    that curve), else raw."""
    from flex.data.headlines import channel_curve

    time_s, angle = channel_curve(datasets, "crank/angle")
    _, slider = channel_curve(datasets, "slider/position")
    size = min(angle.size, slider.size)
    return time_s[:size], angle[:size], slider[:size]


def _curve_accuracies(stored: StoredReference, observables: Observables) -> dict[str, float]:
    """The crank angle's and slider position's relative accuracy as :meth:`Reference.errors`
    reads them: the stored history accuracy plus the interpolation's, over the curve's
    scale."""
    from flex.experiments.workprecision.stored_references import curve_at

    out = {}
    for measure, path, history, fallback in (
            ("crank_angle_relative", "crank/angle", "history_crank_angle", ANGLE_SCALE_RAD),
            ("slider_position_relative", "slider/position", "history_slider_position",
             SLIDER_SCALE_M)):
        stored_path = f"channel/{path}" if f"channel/{path}" in stored.curves else path
        _, sampling = curve_at(stored, stored_path, observables.time_s)
        scale = _scale(np.asarray(stored.curves[stored_path], dtype=float), fallback)
        out[measure] = (stored.accuracies[history] + sampling) / scale
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
    peak_m: float = float("nan")  #: the run's peak deflection as the errors compare it [m]

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def error(self) -> float:
        return self.errors.get("error", float("nan"))


def describe(m: Measurement | None) -> str:
    """One line: label, median wall time [ms], error, steps, Newton iterations ("-" for
    None)."""
    if m is None:
        return "-"
    return (f"{m.setting.label} ({m.wall_time_s * 1e3:.1f} ms, error {m.error:.1e}, "
            f"{m.steps} steps, {m.newton_iterations} Newton iterations)")


class ReductionPool:
    """Reductions (and their FFRF interfaces) built once per key and shared by all runs.

    ``cache_dir``: the reduction cache folder they are loaded from or written to, also used
    by the runs of :func:`run_once` for what they build themselves (None: built in memory,
    no disk cache). ``solve_modes``: every reduction of fewer modes is the first modes of
    one eigen-solve of this many (:func:`flex.bodies.reduction.build_reduction`; a grid of
    1, 2, 4 and 8 modes then meshes and solves each plate once), None: each its own solve.
    """

    def __init__(self, cache_dir: Path | None = None, solve_modes: int | None = None) -> None:
        self._by_key: dict[tuple, Any] = {}
        self.cache_dir = cache_dir
        self.solve_modes = solve_modes

    def for_scene(self, scene: Scene, order: int = 2) -> Any:
        """The scene's reduction (tetrahedra of ``order``) for an ``ffrf`` coupler, else
        None. ``"auto"`` modes and mesh size are keyed by what the rule fills in at the
        scene's ``fidelity.tolerance`` (:func:`flex.config.settings.resolve_link_keys`), as
        the run resolves them."""
        if scene["coupler"]["model"] != FFRF:
            return None
        if has_auto_link_keys(scene):
            scene, _ = resolve_link_keys(scene)
        from flex.dynamics.link_models import reduction_for_scene

        c = scene["coupler"]
        solve = max(self.solve_modes, c["modes"]) if self.solve_modes else None
        key = (Plate.of(c), c["mesh_size_m"], c["modes"], order, solve)
        if key not in self._by_key:
            self._by_key[key] = reduction_for_scene(scene, cache_dir=self.cache_dir,
                                                    mesh_order=order, solve_modes=solve)
        return self._by_key[key]


def run_once(scene: Scene, setting: Setting, pool: ReductionPool | None = None
             ) -> tuple[Observables, dict[str, float]]:
    """Run ``setting`` on ``scene`` (already overridden) once: observables and counters
    (``wall_time_s`` = integration only, ``total_time_s``, steps, Newton iterations).
    Raises :class:`~flex.base.errors.FlexError` (SimulationError, SceneError) on failure."""
    start = time.perf_counter()
    flexible = not BUILTIN_LINK_MODELS[scene["coupler"]["model"]].rigid
    if setting.engine == "scipy":
        if flexible:
            raise SceneError("the scipy reference DAE models a rigid coupler only")
        sim = resolved_simulation(scene)
        interval = sim["output_step_s"] or sim["step_s"]
        count = int(round(sim["end_time_s"] / interval))
        solution = solve_reference(scene, np.linspace(0.0, count * interval, count + 1),
                                   rtol=setting.rtol, atol=setting.atol, method=setting.method)
        observables = Observables(solution.time_s, solution.q[:, 2], solution.q[:, 6])
        counters = {"wall_time_s": solution.wall_time_s, "steps": 0,
                    "newton_iterations": 0, "jacobian_updates": 0,
                    "function_evaluations": solution.function_evaluations}
    else:
        from flex.fidelity.simulation import simulate

        pool = pool or ReductionPool()
        reduction = pool.for_scene(scene, setting.element_order)
        # timed alone: a companion run for an error estimate would be timed with it
        untimed = derive_scene(scene, {"simulation.error_estimate": False})
        result = simulate(untimed, setting.label, reduction, cache_dir=pool.cache_dir)
        observables = Observables.of_datasets(result.datasets, flexible)
        counters = dict(result.counters)
    counters["total_time_s"] = time.perf_counter() - start
    return observables, counters


def measure(base: Scene, setting: Setting, reference: Reference, repeats: int = 3,
            pool: ReductionPool | None = None) -> Measurement:
    """Run ``setting`` on ``base`` ``repeats`` times (once if the first run takes longer
    than :data:`REPEAT_LIMIT_S`) and measure it against ``reference``.

    Never raises for a diverged or refused run: it comes back ``failed`` with the message;
    nor for an internal error of one setting, which comes back ``failed`` naming it (a long
    study goes on with its other settings and exits as having failed cases: make tradeoff
    once stopped with a traceback after minutes at one setting).
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
        measurement.peak_m = observables.peak_m if reference.flexible else float("nan")
    except FlexError as exc:
        measurement.status, measurement.message = "failed", str(exc)
        return measurement
    except Exception as exc:  # a bug in one setting's run: said, not lost with the others
        measurement.status = "failed"
        measurement.message = f"internal error: {type(exc).__name__}: {exc}"
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


def nonlinear_available() -> bool:
    """Whether the nonlinear FE coupler (:mod:`flex.bodies.nonlinear`, NGsolve) is installed."""
    try:
        from flex.bodies.nonlinear import add_nonlinear_fe_coupler  # noqa: F401
    except ImportError:
        return False
    return True


def measurement_attrs(m: Measurement, group: bool = True) -> dict[str, Any]:
    """Case attrs of a measurement: knobs, (``group``) its sweep, label, ``error_<measure>``
    for each error measure and ``error``."""
    attrs: dict[str, Any] = {"knobs": repr(m.setting.knobs())}
    if group:
        attrs["group"] = m.setting.group
    attrs["label"] = m.setting.label
    attrs.update({f"error_{key}": value for key, value in m.errors.items() if key != "error"})
    attrs["error"] = m.error
    return attrs


def measurement_case(name: str, base: Scene, m: Measurement, attrs: dict[str, Any]
                     ) -> CaseResult:
    """The case of one measurement of a setting on ``base``: its scene (``base`` itself if the
    setting was refused), ``attrs``, and if it ran: dataset ``wall_times`` [s] and counters
    (median wall and total time [s], steps, Newton iterations, Jacobian updates, repeats);
    a failed run carries its message and no data."""
    try:
        scene_toml = to_toml(scene_for(base, m.setting))
    except FlexError:  # a refused setting: store the base scene and the message
        scene_toml = to_toml(base)
    if not m.ok:
        return CaseResult(name, scene_toml, status="failed", message=m.message, attrs=attrs)
    return CaseResult(name, scene_toml,
                      {"wall_times": Dataset(np.array(m.wall_times_s), "s",
                                             "integration wall time of each repeat")},
                      counters={"wall_time_s": m.wall_time_s, "total_time_s": m.total_time_s,
                                "steps": m.steps, "newton_iterations": m.newton_iterations,
                                "jacobian_updates": m.jacobian_updates,
                                "repeats": len(m.wall_times_s)}, attrs=attrs)
