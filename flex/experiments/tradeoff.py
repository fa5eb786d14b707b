"""Work-precision measurement: how much wall time buys how much accuracy.

A :class:`Setting` is one combination of knobs: scene overrides (``simulation.step_s``,
``simulation.spectral_radius``, ``simulation.formulation``, ``simulation.newton``,
``simulation.integrator``, ``coupler.modes``, ``coupler.mesh_size_m``, ``coupler.model``,
...) run by flex's Exudyn model, or the independent scipy reference DAE
(:mod:`flex.dynamics.reference`, ``engine = "scipy"``) at a given method and tolerance.
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
then each knob is coarsened. A :class:`Refinement` coarsens one knob by two levels (three
runs at a constant ratio r: fine, medium, coarse); :func:`richardson` turns the two changes
into the observed order p and an estimate of the fine run's own error (grid-convergence-index
style, safety factor :data:`RICHARDSON_SAFETY`; oscillating or pre-asymptotic sequences get
the conservative :data:`FALLBACK_FACTOR` x the largest change). A plain one-level coarsening
(``coarsenings``) contributes its change itself. The reference's accuracy is the sum of the
knobs' estimates; it counts as converged to ``tolerance`` when that sum is below it.

:func:`pareto_front` marks the settings no other setting beats in both wall time and error;
:func:`recommend` picks, per accuracy level, the fastest setting whose measured error plus
the reference's accuracy is within it (it lies on the front of the candidates), refusing
levels finer than the reference can certify.

Wall times are medians over repeats on a shared machine: compare ratios measured in one run.
"""

from __future__ import annotations

import contextlib
import math
import statistics
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError, SceneError
from flex.config.settings import has_auto_link_keys, resolve_link_keys, resolved_simulation
from flex.data.results import Dataset
from flex.data.scene import Scene, apply_overrides, validate
from flex.dynamics.reference import solve_reference

#: relative accuracy levels for which a setting is recommended (1 %, 0.1 %, 0.01 %)
ACCURACY_LEVELS = (1e-2, 1e-3, 1e-4)
#: a reference certifies an accuracy level only if the level is at least this many times the
#: reference's estimated own error (:attr:`Reference.accuracy`)
REFERENCE_MARGIN = 3.0


def certifies(reference_accuracy: float, level: float) -> bool:
    """Whether a reference accurate to ``reference_accuracy`` (relative) can certify the
    accuracy ``level``: at least :data:`REFERENCE_MARGIN` times its own error."""
    return reference_accuracy * REFERENCE_MARGIN <= level

#: safety factor on a Richardson error estimate from three levels in the asymptotic range
#: (Roache's grid convergence index for three grids)
RICHARDSON_SAFETY = 1.25
#: an observed order below this (or an oscillating sequence) is not trusted as asymptotic
MIN_ASYMPTOTIC_ORDER = 1.0
#: estimate outside the asymptotic range: this factor x the larger of the two changes (the
#: factor of safety of a study whose order is not verified; Roache, Eca & Hoekstra)
FALLBACK_FACTOR = 3.0
#: wall times within this fraction of the fastest count as a tie (broken by accuracy)
TIE_FRACTION = 0.1
#: settings whose first run takes longer than this [s] are not repeated (median of one)
REPEAT_LIMIT_S = 5.0


@dataclass(frozen=True)
class Setting:
    """One knob combination.

    ``overrides``: scene keys ``"section.key"`` -> value, applied to the scene being studied;
    ``engine``: ``"exudyn"`` (flex's model, :func:`flex.dynamics.solver.simulate`) or ``"scipy"``
    (the reference DAE of :mod:`flex.dynamics.reference`, rigid coupler only) with ``method``,
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
        """From a :class:`~flex.data.results.CaseResult`'s datasets."""
        return Observables(np.asarray(datasets["time"].data),
                           np.asarray(datasets["crank/angle"].data),
                           np.asarray(datasets["slider/position"].data),
                           np.asarray(datasets["coupler/midpoint_deflection"].data)
                           if flexible else None)


@dataclass
class Reference:
    """A converged solution of one scene and the evidence that it is converged.

    ``evidence`` maps each coarsening (``"step_s x2"``, ``"modes 12 -> 8"``, ...) or
    refinement sequence (``"step_s"``, ...) to its record: ``error`` is the knob's estimate of
    the reference's own relative error (largest over the error measures: the change itself
    for a one-level coarsening, :func:`richardson`'s estimate for a sequence, with ``order``,
    ``change_fine``, ``change_coarse``, ``asymptotic``, ``values``); ``tolerance`` is the
    relative accuracy the reference claims, ``accuracy`` the sum of the knobs' estimates.
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


def describe(m: Measurement | None) -> str:
    """One line: label, median wall time [ms], error, steps, Newton iterations ("-" for
    None)."""
    if m is None:
        return "-"
    return (f"{m.setting.label} ({m.wall_time_s * 1e3:.1f} ms, error {m.error:.1e}, "
            f"{m.steps} steps, {m.newton_iterations} Newton iterations)")


@contextlib.contextmanager
def element_order(order: int) -> Iterator[None]:
    """Build reductions with tetrahedra of ``order`` (1 or 2) inside the block.

    :mod:`flex.bodies.reduction` fixes quadratic tetrahedra (module constant ``_MESH_ORDER``, part
    of
    the cache key); the work-precision study sets it for the duration of one build to show
    what linear tetrahedra cost in accuracy. Raises SceneError if the constant is gone.
    """
    from flex.bodies import reduction

    if order not in (1, 2):
        raise SceneError(f"element_order = {order!r}: must be 1 or 2")
    if not hasattr(reduction, "_MESH_ORDER"):
        raise SceneError("element_order: flex.bodies.reduction no longer exposes _MESH_ORDER")
    previous = reduction._MESH_ORDER
    reduction._MESH_ORDER = order
    try:
        yield
    finally:
        reduction._MESH_ORDER = previous


class ReductionPool:
    """Reductions (and their FFRF interfaces) built once per key and shared by all runs.

    ``cache_dir``: the reduction cache folder they are loaded from or written to, also used
    by the runs of :func:`run_once` for what they build themselves (None: built in memory,
    no disk cache).
    """

    def __init__(self, cache_dir: Path | None = None) -> None:
        self._by_key: dict[tuple, Any] = {}
        self.cache_dir = cache_dir

    def for_scene(self, scene: Scene, order: int = 2) -> Any:
        """The scene's reduction (tetrahedra of ``order``) for an ``ffrf`` coupler, else
        None. ``"auto"`` modes and mesh size are keyed by what the rule fills in at the
        scene's ``fidelity.tolerance`` (:func:`flex.config.settings.resolve_link_keys`), as
        the run resolves them."""
        if scene["coupler"]["model"] != "ffrf":
            return None
        if has_auto_link_keys(scene):
            scene, _ = resolve_link_keys(scene)
        from flex.dynamics.solver import reduction_for_scene

        c = scene["coupler"]
        key = tuple(c[k] for k in ("length_m", "thickness_m", "width_m", "youngs_modulus_Pa",
                                   "density_kg_per_m3", "poisson_ratio", "mesh_size_m",
                                   "modes")) + (order,)
        if key not in self._by_key:
            with element_order(order):
                self._by_key[key] = reduction_for_scene(scene, cache_dir=self.cache_dir)
        return self._by_key[key]


def run_once(scene: Scene, setting: Setting, pool: ReductionPool | None = None
             ) -> tuple[Observables, dict[str, float]]:
    """Run ``setting`` on ``scene`` (already overridden) once: observables and counters
    (``wall_time_s`` = integration only, ``total_time_s``, steps, Newton iterations).
    Raises :class:`~flex.base.errors.FlexError` (SimulationError, SceneError) on failure."""
    start = time.perf_counter()
    flexible = scene["coupler"]["model"] != "rigid"
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
        untimed = apply_overrides(scene, ["simulation.error_estimate=false"])
        result = simulate(untimed, setting.label, reduction, cache_dir=pool.cache_dir)
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


MEASURES = ("crank_angle_relative", "slider_position_relative", "peak_deflection_relative")


@dataclass(frozen=True)
class Refinement:
    """One knob coarsened by two levels at a constant ``ratio`` (> 1): ``levels`` = (fine,
    medium, coarse) settings. The fine level is normally the reference's own setting (then
    not run twice); it may be a cheaper one when the knob's error is measured at a coarser
    value of another knob (errors of independent knobs add up). ``max_order``: the formal
    order of the knob (generalized-alpha: 2 in the step); a larger observed order is capped
    to it, which keeps the estimate conservative. With two levels only (fine, coarse) the
    estimate is the change itself, as for a one-level coarsening (e.g. a Newton tolerance:
    the change bounds the looser run's error, the finer one's is smaller)."""

    knob: str
    levels: tuple[Setting, ...]
    ratio: float
    max_order: float


def richardson(change_fine: float, change_coarse: float, ratio: float, max_order: float,
               monotone: bool = True) -> dict[str, Any]:
    """Estimate of the fine run's own error from the changes fine -> medium
    (``change_fine``) and medium -> coarse (``change_coarse``) of a sequence refined by
    ``ratio``.

    In the asymptotic range (``monotone``, the coarse change larger, observed order
    p = ln(change_coarse / change_fine) / ln(ratio) at least :data:`MIN_ASYMPTOTIC_ORDER`):
    :data:`RICHARDSON_SAFETY` x change_fine / (ratio^min(p, max_order) - 1), the
    Richardson-extrapolated error with a safety factor (grid convergence index). Otherwise
    (oscillating, stalling or too slow to be asymptotic): :data:`FALLBACK_FACTOR` x the
    larger change. Returns ``estimate``, ``order`` (observed, nan if none), ``asymptotic``.
    """
    out: dict[str, Any] = {"change_fine": change_fine, "change_coarse": change_coarse,
                           "order": math.nan, "asymptotic": False}
    if not (math.isfinite(change_fine) and math.isfinite(change_coarse)):
        out["estimate"] = math.inf
        return out
    if change_fine == 0.0 and change_coarse == 0.0:
        out.update(estimate=0.0, asymptotic=True)
        return out
    if monotone and change_coarse > change_fine:
        order = (math.inf if change_fine == 0.0
                 else math.log(change_coarse / change_fine) / math.log(ratio))
        out["order"] = order
        if order >= MIN_ASYMPTOTIC_ORDER:
            used = min(order, max_order)
            out.update(estimate=RICHARDSON_SAFETY * change_fine / (ratio**used - 1.0),
                       asymptotic=True)
            return out
    out["estimate"] = FALLBACK_FACTOR * max(change_fine, change_coarse)
    return out


def _signed_peak(observables: Observables) -> float:
    if observables.deflection_m is None:
        return math.nan
    return peak_value(observables.time_s, observables.deflection_m)


def converged_reference(base: Scene, label: str, finest: Setting,
                        coarsenings: dict[str, Setting], tolerance: float,
                        pool: ReductionPool | None = None, description: str = "",
                        progress: Callable[[str], None] | None = None,
                        refinements: Sequence[Refinement] = (),
                        anchor: Setting | None = None) -> Reference:
    """Run ``finest``, each one-knob ``coarsenings`` of it and each :class:`Refinement`
    sequence; return the reference with its evidence.

    A coarsening's evidence is its :meth:`Reference.errors` against the finest run (relative
    changes of crank angle, slider position and peak deflection, and their maximum
    ``error``, which is also its contribution to the accuracy). A refinement's evidence, per
    error measure, is :func:`richardson` on the changes fine -> medium -> coarse (relative to
    the fine run; the peak deflection's sequence is monotone when both changes have the same
    sign); ``error`` is the largest estimate, ``order``, ``change_fine``, ``change_coarse``
    and ``asymptotic`` are those of that measure, ``values`` the three peak deflections (or
    final crank angles) and ``wall_times_s`` the runs' integration times. A failed run makes
    its evidence infinite (the reference is then not converged).

    Sequences run at cheaper values of the other knobs rest on the knobs' errors adding up.
    ``anchor`` checks it: a setting with each knob at a value one of its sequence's levels
    has (typically the finest level of the first sequence). The additive prediction of the
    reference's value is the anchor's plus, per three-level sequence, its fine level minus
    its level at the anchor's value of the knob; the relative difference between the
    reference and that prediction is stored as the evidence ``interaction`` and counts in the
    accuracy like a knob (the knobs' joint effect that the sequences do not see). Raises
    :class:`~flex.base.errors.FlexError` if the finest run fails.
    """
    scene = scene_for(base, finest)
    if progress:
        progress(f"reference {label}: {finest.label}")
    observables, counters = run_once(scene, finest, pool)
    reference = Reference(label, observables, finest, {}, tolerance,
                          float(counters["wall_time_s"]), description)
    runs: dict[str, tuple[Observables, float]] = {
        repr(finest.knobs()): (observables, float(counters["wall_time_s"]))}

    def run(setting: Setting) -> tuple[Observables, float]:
        key = repr(setting.knobs())
        if key not in runs:
            if progress:
                progress(f"reference {label}: evidence {setting.label}")
            obs, count = run_once(scene_for(base, setting), setting, pool)
            runs[key] = (obs, float(count["wall_time_s"]))
        return runs[key]

    for name, coarser in coarsenings.items():
        try:
            coarse_observables, wall = run(coarser)
        except FlexError as exc:  # no evidence: the reference then counts as not converged
            reference.evidence[name] = {"error": math.inf, "failed": str(exc)}
            continue
        reference.evidence[name] = reference.errors(coarse_observables)
        reference.evidence[name]["wall_times_s"] = [wall]
    for refinement in refinements:
        try:
            levels = [run(setting) for setting in refinement.levels]
        except FlexError as exc:
            reference.evidence[refinement.knob] = {"error": math.inf, "failed": str(exc)}
            continue
        reference.evidence[refinement.knob] = _refinement_evidence(reference, refinement,
                                                                   levels)
    if anchor is not None and refinements:
        reference.evidence["interaction"] = _interaction(reference, refinements, anchor, run)
    return reference


def _refinement_evidence(reference: Reference, refinement: Refinement,
                         levels: Sequence[tuple[Observables, float]]) -> dict[str, Any]:
    """The evidence record of one knob sequence from its levels' runs (observables, wall
    time [s]), finest first (see :func:`converged_reference`)."""
    tolerance = reference.tolerance
    fine_ref = Reference("fine", levels[0][0], refinement.levels[0], {}, tolerance, 0.0)
    changes_fine = fine_ref.errors(levels[1][0])
    three = len(levels) == 3
    if three:
        medium_ref = Reference("medium", levels[1][0], refinement.levels[1], {},
                               tolerance, 0.0)
        changes_coarse = medium_ref.errors(levels[2][0])
    peaks = [_signed_peak(obs) for obs, _ in levels]
    record: dict[str, Any] = {"error": 0.0}
    for measure_name in MEASURES:
        d1 = changes_fine[measure_name]
        if not math.isfinite(d1) and measure_name == "peak_deflection_relative" \
                and not reference.flexible:
            continue  # a measure the scene does not have (peak of a rigid coupler)
        if not three:
            estimate = {"estimate": d1, "change_fine": d1, "change_coarse": math.nan,
                        "order": math.nan, "asymptotic": False}
        else:
            d2 = changes_coarse[measure_name]
            monotone = True
            if measure_name == "peak_deflection_relative":
                monotone = (peaks[1] - peaks[0]) * (peaks[2] - peaks[1]) > 0
            estimate = richardson(d1, d2, refinement.ratio, refinement.max_order, monotone)
        record[measure_name] = estimate["estimate"]
        if estimate["estimate"] >= record["error"]:
            record.update(error=estimate["estimate"], governing=measure_name,
                          **{k: v for k, v in estimate.items() if k != "estimate"})
    record["values"] = (peaks if reference.flexible
                        else [float(obs.crank_angle_rad[-1]) for obs, _ in levels])
    record["settings"] = [setting.label for setting in refinement.levels]
    record["wall_times_s"] = [wall for _, wall in levels]
    record["ratio"] = refinement.ratio
    return record


def _knob_key(knob: str) -> str:
    return knob if "." in knob else f"simulation.{knob}"


def _value(observables: Observables, flexible: bool) -> float:
    return (_signed_peak(observables) if flexible
            else float(observables.crank_angle_rad[-1]))


def _interaction(reference: Reference, refinements: Sequence[Refinement], anchor: Setting,
                 run: Callable[[Setting], tuple[Observables, float]]) -> dict[str, Any]:
    """Evidence that the knobs' errors add up (see :func:`converged_reference`)."""
    flexible = reference.flexible
    try:
        anchor_observables, wall = run(anchor)
    except FlexError as exc:
        return {"error": math.inf, "failed": str(exc)}
    anchor_knobs = dict(anchor.overrides)
    actual = _value(reference.observables, flexible)
    predicted = _value(anchor_observables, flexible)
    walls = [wall]
    for refinement in refinements:
        if len(refinement.levels) != 3:
            continue
        key = _knob_key(refinement.knob)
        at_anchor = [setting for setting in refinement.levels
                     if key in anchor_knobs and dict(setting.overrides).get(key)
                     == anchor_knobs[key]]
        if not at_anchor:
            return {"error": math.inf, "failed": f"no level of {refinement.knob} at the "
                                                 f"anchor's value"}
        fine, fine_wall = run(refinement.levels[0])
        level, level_wall = run(at_anchor[0])
        predicted += _value(fine, flexible) - _value(level, flexible)
        walls += [fine_wall, level_wall]
    scale = abs(actual) if flexible else ANGLE_SCALE_RAD
    difference = abs(actual - predicted) / scale
    return {"error": difference, "change_fine": difference, "values": [actual, predicted],
            "settings": [reference.setting.label, f"additive prediction from {anchor.label}"],
            "wall_times_s": [wall], "governing": "peak_deflection_relative" if flexible
            else "crank_angle_relative"}


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
    """Per accuracy level the fastest ``ok`` measurement whose error is certified within it,
    ``error + reference.accuracy <= level`` (the reference's own error could add to the
    measured one; ties by :func:`fastest`).

    Levels finer than ``REFERENCE_MARGIN`` x the reference's own accuracy are refused (the
    reference cannot tell such errors apart). ``eligible`` filters the candidates (e.g. only
    settings of flex's Exudyn model, not the scipy reference). The chosen setting is on the
    Pareto front of the candidates.
    """
    candidates = [m for m in measurements if m.ok and (eligible is None or eligible(m))]
    out = []
    for level in levels:
        if not certifies(reference.accuracy, level):
            out.append(Recommendation(level, None, f"reference accurate to "
                                      f"{reference.accuracy:.1e} only: cannot certify "
                                      f"{level:.0e}"))
            continue
        # certified: the measured error plus the reference's own possible error
        within = [m for m in candidates if m.error + reference.accuracy <= level]
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
