"""Benchmark: how fast flex reaches a stated accuracy (measured, not a timed test).

Every number is measured by the run, on whatever else the machine is doing: wall times [s]
are medians of ``repeats`` runs, and each comparison is a ratio of two times measured in the
same run. :func:`run_bench` runs the six parts of a :class:`BenchPlan` in order, each into
``notes[<part>]`` (a part that raises :class:`~flex.base.errors.FlexError` is stored as
``notes["<part>_failed"]`` and a failed case ``<part>_failed``; the others still run):

- ``rigid`` (:func:`bench_rigid`): the largest step of the tuned setting that reaches the
  crank-angle accuracy, tuned and untuned at that step, and the loosest scipy tolerance that
  reaches it, against a converged reference; with :func:`profile` of the untuned and tuned run;
- ``ffrf_1mm`` (:func:`bench_ffrf`): the fastest candidate within the peak-deflection
  accuracy, the untuned first set-up, the flex defaults, and the nonlinear FE coupler (if
  installed and asked for: ``nonlinear``, the bench study's ``FLEX_BENCH_NONLINEAR`` not
  ``0``) against its own run at half the step; the FFRF runs against the stored reference of
  the plate's physics (``make references``: the calibrated exact beam);
- ``reduction`` (:func:`bench_reduction`): the plate reduction cold (empty cache), from cache,
  and its first FFRF projection;
- ``step_cost`` (:func:`bench_step_cost`, when the plan has a :class:`StepCostPlan`): the cost
  of an FFRF step against mesh size and mode count, joint markers on every face node (before)
  and on the fewest nodes (now);
- ``plates`` (:func:`bench_plates`, when the plan has a :class:`PlatesPlan`): plates of other
  thicknesses and materials at flex's own settings per tolerance, against the stored
  references of their physics;
- ``budget`` (:func:`flex.experiments.workprecision.budget_cost.bench_budget`, when the plan
  has a :class:`~flex.experiments.workprecision.budget_cost.BudgetPlan`): the 1 % answer's
  cost, the run with its budget against the run alone and the command line against the run
  in process;
- ``make_all`` (:func:`bench_make_all`): ``make all FORCE=1`` with an empty reduction cache and
  again with it filled (``make_all`` False, the bench study's ``FLEX_BENCH_MAKE=0``, skips
  it).

The run-time switches ``nonlinear`` and ``make_all`` and the reduction cache folder
``cache_dir`` are arguments of :func:`run_bench`; the command line reads the environment.

:mod:`flex.experiments.workprecision.benchmark_report` turns the notes into the table and the
figures.
"""

from __future__ import annotations

import math
import os
import re
import statistics
import subprocess
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError
from flex.base.physics import Plate
from flex.data.reference_store import StoredReference
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.dynamics.link_models import NONLINEAR_FE
from flex.experiments.workprecision.budget_cost import BudgetPlan, bench_budget
from flex.experiments.workprecision.measurement import (
    Measurement,
    Progress,
    ReductionPool,
    Reference,
    Setting,
    measure,
    measurement_attrs,
    measurement_case,
    nonlinear_available,
    run_once,
    scene_for,
)
from flex.experiments.workprecision.pareto import fastest
from flex.experiments.workprecision.reference_plans import ReferencePlan, build_reference

Say = Callable[[str], None]


@dataclass(frozen=True)
class StepCostPlan:
    """Per-step cost of the FFRF coupler: the thesis deployment's first ``end_time_s`` [s] at
    ``step_s`` [s] (modified Newton, relative tolerance 1e-8, spectral radius 0.9) on each mesh
    size [m] and mode count, with the joint markers on every face node (before) and on the
    fewest nodes (now, :func:`flex.bodies.reduction.add_ffrf_link`). ``newton``: label ->
    (Newton variant, relative tolerance), each timed on the first mesh and the largest mode
    count below the largest (iterations per step against the cost of a step)."""

    meshes_m: Sequence[float]
    modes: Sequence[int]
    step_s: float
    end_time_s: float
    newton: Mapping[str, tuple[str, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class PlatesPlan:
    """Plates timed as a user runs them, at flex's own settings for each tolerance.

    ``plates``: name -> ``--set`` overrides of the FFRF bench scene; ``tolerances``: the
    ``fidelity.tolerance`` values (relative peak-deflection error); ``targets_s``: tolerance
    -> the in-process time target [s] (build + integration + output, reduction in memory)."""

    plates: Mapping[str, Sequence[str]]
    tolerances: Sequence[float]
    targets_s: Mapping[float, float]


@dataclass(frozen=True)
class BenchPlan:
    """What the benchmark measures.

    Rigid: ``rigid_reference``; the crank-angle accuracy [rad]; the tuned Newton knobs
    (``simulation`` keys) and the untuned ones; the steps [s] probed for the tuned setting,
    largest first; the scipy DOP853 relative tolerances probed, loosest first. FFRF (its
    reference the stored one of its physics, ``make references``): the relative
    peak-deflection accuracy; the target integration time [s]; the
    candidate settings, cheapest first; the untuned first set-up; the flex defaults; the
    nonlinear FE coupler at a fine and a coarse step.
    """

    rigid_reference: ReferencePlan
    rigid_accuracy_rad: float
    rigid_tuned: Mapping[str, Any]
    rigid_untuned: Mapping[str, Any]
    rigid_steps: Sequence[float]
    scipy_rtols: Sequence[float]
    ffrf_accuracy: float
    ffrf_target_s: float
    ffrf_candidates: Sequence[Setting]
    ffrf_untuned: Setting
    ffrf_defaults: Setting
    nonlinear_fine: Setting
    nonlinear_coarse: Setting
    step_cost: StepCostPlan | None = None
    plates: PlatesPlan | None = None
    #: what the 1 % answer costs (:mod:`flex.experiments.workprecision.budget_cost`)
    budget: BudgetPlan | None = None


def _g(value: float) -> str:
    """Scientific, shortest: 1e-4 -> ``1e-4`` (how the plan's numbers read in labels and
    messages)."""
    return str(np.format_float_scientific(value, trim="-", exp_digits=1))


# ------------------------------------------------------------------------------------------
# profiling
# ------------------------------------------------------------------------------------------
_TIMER = re.compile(r"^\s*(_{0,2}[A-Za-z/ 0-9]+?)\s*=\s*([0-9.eE+-]+)%")


def profile(scene: Scene, pool: ReductionPool) -> dict[str, float]:
    """One run of ``scene`` with flex's phases timed [s] (``phase_reduction_s``,
    ``phase_build_s``, ``phase_integration_s``, ``phase_output_s``), its counters and
    Exudyn's CPU-time shares [%] (``exudyn_<phase>_percent``)."""
    from flex.dynamics.collect import collect
    from flex.dynamics.mechanism import build_mechanism
    from flex.dynamics.solver import run_profiled

    out: dict[str, float] = {}
    start = time.perf_counter()
    reduction = pool.for_scene(scene)
    out["phase_reduction_s"] = time.perf_counter() - start
    start = time.perf_counter()
    mech = build_mechanism(scene, reduction)
    out["phase_build_s"] = time.perf_counter() - start
    counters, statistics_text = run_profiled(mech)
    out["phase_integration_s"] = counters.pop("wall_time_s")
    start = time.perf_counter()
    collect(mech)
    out["phase_output_s"] = time.perf_counter() - start
    out.update(counters)
    for line in statistics_text.splitlines():
        match = _TIMER.match(line)
        if match and "time" not in match[1]:
            name = re.sub(r"[^A-Za-z0-9_]+", "_", match[1].strip())
            out[f"exudyn_{name}_percent"] = float(match[2])
    return out


# ------------------------------------------------------------------------------------------
# parts
# ------------------------------------------------------------------------------------------
def bench_case(name: str, scene: Scene, m: Measurement, extra: dict[str, Any] | None = None
               ) -> CaseResult:
    """A timed configuration's case
    (:func:`flex.experiments.workprecision.measurement.measurement_case`; attrs knobs, label,
    errors and ``extra``)."""
    return measurement_case(name, scene, m, measurement_attrs(m, group=False) | (extra or {}))


def first_within(scene: Scene, settings: Sequence[Setting], reference: Reference,
                 accepts: Callable[[Measurement], bool]) -> Setting | None:
    """The first of ``settings`` whose single run is ok and ``accepts``, or None."""
    for setting in settings:
        probe = measure(scene, setting, reference, 1)
        if probe.ok and accepts(probe):
            return setting
    return None


def bench_rigid(scene: Scene, plan: BenchPlan, repeats: int, pool: ReductionPool, say: Say,
                notes: dict[str, Any]) -> dict[str, CaseResult]:
    """Rigid part: flex tuned and untuned, and scipy, at the plan's crank-angle accuracy."""
    reference = build_reference(scene, "rigid", plan.rigid_reference, pool)
    say(f"rigid reference: accuracy {reference.accuracy:.1e}")
    accuracy = f"{_g(plan.rigid_accuracy_rad)} rad"

    def reaches(m: Measurement) -> bool:
        return m.errors["crank_angle_rad"] <= plan.rigid_accuracy_rad

    tuned_tol = _g(plan.rigid_tuned["newton_relative_tolerance"])
    probe = first_within(scene, [Setting.of(f"tuned h={step:g}", step_s=step, **plan.rigid_tuned)
                                 for step in plan.rigid_steps], reference, reaches)
    if probe is None:
        raise FlexError(f"no flex step reached {accuracy}")
    chosen = dict(probe.overrides)["simulation.step_s"]
    say(f"rigid: flex reaches {accuracy} at h = {chosen:g} s")
    tuned = measure(scene, Setting.of(f"flex tuned h={chosen:g} tol={tuned_tol}", step_s=chosen,
                                      **plan.rigid_tuned), reference, repeats, pool)
    untuned_tol = _g(plan.rigid_untuned["newton_relative_tolerance"])
    untuned = measure(scene, Setting.of(f"flex untuned h={chosen:g} tol={untuned_tol}",
                                        step_s=chosen, **plan.rigid_untuned),
                      reference, repeats, pool)
    scipy_pick = first_within(scene, [
        Setting(f"scipy DOP853 rtol={rtol:g}", engine="scipy", rtol=rtol, atol=rtol * 1e-2)
        for rtol in plan.scipy_rtols], reference, reaches)
    if scipy_pick is None:
        raise FlexError(f"no scipy tolerance reached {accuracy}")
    scipy_run = measure(scene, scipy_pick, reference, repeats)
    say(f"rigid: scipy reaches {accuracy} at {scipy_pick.label}")
    notes["rigid"] = {"reference": reference, "tuned": tuned, "untuned": untuned,
                      "scipy": scipy_run,
                      "profile_untuned": profile(scene_for(scene, untuned.setting), pool),
                      "profile_tuned": profile(scene_for(scene, tuned.setting), pool)}
    return {"rigid_tuned": bench_case("rigid_tuned", scene, tuned),
            "rigid_untuned": bench_case("rigid_untuned", scene, untuned),
            "rigid_scipy": bench_case("rigid_scipy", scene, scipy_run)}


def bench_ffrf(scene: Scene, plan: BenchPlan, repeats: int, pool: ReductionPool, say: Say,
               notes: dict[str, Any], store: Mapping[str, StoredReference],
               nonlinear: bool = True) -> dict[str, CaseResult]:
    """FFRF part: the fastest candidate within the peak accuracy, untuned, defaults,
    nonlinear FE (if installed and ``nonlinear``), against the stored reference of the
    scene's physics in ``store`` (:func:`_stored`)."""
    reference = _stored(store, scene)
    say(f"ffrf_1mm reference: accuracy {reference.accuracy:.1e}, peak "
        f"{reference.peak_deflection_m * 1e6:.2f} um")
    out: dict[str, CaseResult] = {}
    probes = [measure(scene, setting, reference, 1, pool) for setting in plan.ffrf_candidates]
    for index, probe in enumerate(probes, 1):
        out[f"ffrf_probe_{index}"] = bench_case(f"ffrf_probe_{index}", scene, probe)
    within = [p for p in probes if p.ok
              and p.errors["peak_deflection_relative"] <= plan.ffrf_accuracy]
    if not within:
        raise FlexError(f"no FFRF candidate reached {plan.ffrf_accuracy * 100:g} % peak "
                        f"deflection")
    best = fastest(within)  # by integration time (the first total includes a projection)
    tuned = measure(scene, best.setting, reference, repeats, pool)
    say(f"ffrf_1mm: tuned {tuned.setting.label}: {tuned.wall_time_s:.3f} s")
    untuned = measure(scene, plan.ffrf_untuned, reference, 1, pool)
    say(f"ffrf_1mm: untuned {untuned.wall_time_s:.2f} s")
    default = measure(scene, plan.ffrf_defaults, reference, repeats, pool)
    say(f"ffrf_1mm: flex defaults {default.wall_time_s:.3f} s")
    out["ffrf_tuned"] = bench_case("ffrf_tuned", scene, tuned)
    out["ffrf_untuned"] = bench_case("ffrf_untuned", scene, untuned)
    out["ffrf_default"] = bench_case("ffrf_default", scene, default)
    results: dict[str, Any] = {
        "reference": reference, "tuned": tuned, "untuned": untuned, "default": default,
        "probes": probes,
        "profile_untuned": profile(scene_for(scene, plan.ffrf_untuned), pool),
        "profile_tuned": profile(scene_for(scene, tuned.setting), pool)}
    if nonlinear and nonlinear_available():
        out.update(_bench_nonlinear(scene, plan, reference, pool, say, results))
    notes["ffrf_1mm"] = results
    return out


def _bench_nonlinear(scene: Scene, plan: BenchPlan, reference: Reference,
                     pool: ReductionPool, say: Say, results: dict[str, Any]
                     ) -> dict[str, CaseResult]:
    """The nonlinear FE coupler is another model (it keeps the axial force's effect on
    bending): its accuracy is judged against its own run at the fine step, and its difference
    to the converged FFRF reference is reported beside it."""
    fine_setting, coarse_setting = plan.nonlinear_fine, plan.nonlinear_coarse
    fine_step = _g(dict(fine_setting.overrides)["simulation.step_s"])
    say(f"ffrf_1mm: nonlinear FE coupler at h = {fine_step} s (minutes)")
    try:
        fine, counters = run_once(scene_for(scene, fine_setting), fine_setting, pool)
    except FlexError as exc:
        results["nonlinear_failed"] = str(exc)
        return {}
    own = Reference(f"nonlinear FE h={fine_step}", fine, fine_setting, {}, plan.ffrf_accuracy,
                    float(counters["wall_time_s"]), f"nonlinear FE, h = {fine_step} s")
    say(f"ffrf_1mm: nonlinear FE coupler at h = "
        f"{_g(dict(coarse_setting.overrides)['simulation.step_s'])} s")
    coarse = measure(scene, coarse_setting, own, 1, pool)
    results["nonlinear"] = {"fine_wall_time_s": own.wall_time_s, "coarse": coarse,
                            "model_difference": own.errors(reference.observables)}
    return {NONLINEAR_FE: bench_case(NONLINEAR_FE, scene, coarse, {
        "fine_wall_time_s": own.wall_time_s,
        "note": f"errors against the nonlinear FE run at h = {fine_step} s"})}


def bench_step_cost(scene: Scene, plan: StepCostPlan, repeats: int, pool: ReductionPool,
                    say: Say, notes: dict[str, Any]) -> None:
    """``notes["step_cost"]``: per mesh and mode count, the median wall time per step [ms]
    and Newton iterations per step of both joint-marker kinds (runs of the two kinds
    alternate, so a change in the machine's load touches both alike)."""
    from flex.bodies.reduction import JOINT_MARKERS
    from flex.dynamics.mechanism import build_mechanism
    from flex.dynamics.solver import run

    rows = []
    for mesh in plan.meshes_m:
        for modes in plan.modes:
            case = _step_case(scene, plan, mesh, modes)
            reduction = pool.for_scene(case)
            samples: dict[str, list[tuple[float, float]]] = {kind: [] for kind in JOINT_MARKERS}
            for _ in range(repeats):
                for kind in JOINT_MARKERS:
                    samples[kind].append(_per_step(run(build_mechanism(
                        case, reduction, ffrf_joint_markers=kind))))
            row: dict[str, Any] = {"mesh_size_m": mesh, "modes": modes,
                                   "mesh_nodes": reduction.n_nodes}
            for kind, values in samples.items():
                row[f"{kind}_ms_per_step"] = statistics.median(v[0] for v in values)
                row[f"{kind}_newton_per_step"] = statistics.median(v[1] for v in values)
            rows.append(row)
            say(f"step cost, mesh {mesh * 1e3:g} mm, {modes} modes: "
                f"{row['fewest_ms_per_step']:.3f} ms (all face nodes "
                f"{row['all_face_nodes_ms_per_step']:.3f} ms)")
    notes["step_cost"] = rows
    if plan.newton:
        notes["newton"] = _newton_variants(scene, plan, repeats, pool, say)


def _step_case(scene: Scene, plan: StepCostPlan, mesh_m: float, modes: int,
               newton: str = "modified", tolerance: float = 1e-8) -> Scene:
    """The plan's short run on ``mesh_m`` with ``modes``, Newton ``newton`` at ``tolerance``."""
    from flex.data.scene_edit import derive_scene

    return derive_scene(scene, [
        f"coupler.mesh_size_m={mesh_m}", f"coupler.modes={modes}",
        f"simulation.step_s={plan.step_s}", f"simulation.end_time_s={plan.end_time_s}",
        f'simulation.newton="{newton}"', f"simulation.newton_relative_tolerance={tolerance}",
        "simulation.spectral_radius=0.9"])


def _per_step(counters: Mapping[str, float]) -> tuple[float, float]:
    """Wall time [ms] and Newton iterations per step of a run's counters."""
    return (1e3 * counters["wall_time_s"] / counters["steps"],
            counters["newton_iterations"] / counters["steps"])


def _newton_variants(scene: Scene, plan: StepCostPlan, repeats: int, pool: ReductionPool,
                     say: Say) -> list[dict[str, Any]]:
    """Per Newton variant of the plan: median ms and Newton iterations per step."""
    from flex.dynamics.mechanism import build_mechanism
    from flex.dynamics.solver import run

    modes = sorted(plan.modes)[-2] if len(plan.modes) > 1 else plan.modes[0]
    rows = []
    for label, (variant, tolerance) in plan.newton.items():
        case = _step_case(scene, plan, plan.meshes_m[0], modes, variant, tolerance)
        reduction = pool.for_scene(case)
        samples = [_per_step(run(build_mechanism(case, reduction))) for _ in range(repeats)]
        rows.append({"label": label, "mesh_size_m": plan.meshes_m[0], "modes": modes,
                     "ms_per_step": statistics.median(v[0] for v in samples),
                     "newton_per_step": statistics.median(v[1] for v in samples)})
        say(f"Newton {label}: {rows[-1]['ms_per_step']:.3f} ms, "
            f"{rows[-1]['newton_per_step']:.2f} iterations per step")
    return rows


def bench_plates(scene: Scene, plan: PlatesPlan, repeats: int, pool: ReductionPool, say: Say,
                 notes: dict[str, Any], store: Mapping[str, StoredReference]
                 ) -> dict[str, CaseResult]:
    """Per plate: the stored reference of its physics (``store``, :func:`_stored`; its
    accuracy certifies a level only within a third of it), then per tolerance flex's own
    choice (every solver and link key ``"auto"``: :mod:`flex.config.ffrf_rule`, or the
    visible fallback) timed and measured against it. ``notes["plates"]``: one row each."""
    from flex.config.settings import AUTO_OVERRIDES, resolve_solver_settings
    from flex.data.scene_edit import derive_scene
    from flex.experiments.workprecision.measurement import certifies

    rows, out = [], {}
    for name, overrides in plan.plates.items():
        plate = derive_scene(scene, list(overrides))
        reference = _stored(store, plate)
        say(f"{name}: reference accuracy {reference.accuracy:.1e}")
        for tolerance in plan.tolerances:
            auto = Setting(f"flex defaults at {tolerance:g}", tuple(AUTO_OVERRIDES) + (
                ("coupler.modes", "auto"), ("coupler.mesh_size_m", "auto"),
                ("fidelity.tolerance", tolerance)))
            resolved, choice = resolve_solver_settings(scene_for(plate, auto))
            concrete = Setting(auto.label, auto.overrides + (
                ("coupler.modes", resolved["coupler"]["modes"]),
                ("coupler.mesh_size_m", resolved["coupler"]["mesh_size_m"])))
            pool.for_scene(scene_for(plate, concrete))  # warm: the reduction is not timed
            m = measure(plate, concrete, reference, repeats, pool)
            label = f"plate_{name}_tol_{tolerance:g}"
            out[label] = bench_case(label, plate, m, {"rule_entry": choice.entry if choice
                                                      else "", "tolerance": tolerance})
            rows.append({"plate": name, "tolerance": tolerance, "measurement": m,
                         "entry": choice.entry if choice else "",
                         "step_s": resolved["simulation"]["step_s"],
                         "modes": resolved["coupler"]["modes"],
                         "mesh_size_m": resolved["coupler"]["mesh_size_m"],
                         "reference_accuracy": reference.accuracy,
                         "certifiable": certifies(reference.accuracy, tolerance),
                         "target_s": plan.targets_s.get(tolerance, math.nan)})
            say(f"{name} at {tolerance:g}: {m.total_time_s:.3f} s, error "
                f"{m.errors.get('peak_deflection_relative', math.nan):.2e}")
    notes["plates"] = rows
    return out


def bench_reduction(scene: Scene, say: Say, notes: dict[str, Any]) -> None:
    """Build time [s] of the scene's coupler reduction: cold (empty cache, median of 2),
    loaded from cache (median of 6), and its first FFRF projection (median of 2)."""
    from flex.bodies.reduction import build_reduction

    c = scene["coupler"]
    args = (Plate.of(c), c["mesh_size_m"], c["modes"])
    selection = {"mode_selection": c["mode_selection"]}
    cold, cached, interface = [], [], []
    for _ in range(2):
        with tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            build_reduction(*args, cache_dir=folder, **selection)
            cold.append(time.perf_counter() - start)
            for _ in range(3):
                start = time.perf_counter()
                reduction = build_reduction(*args, cache_dir=folder, **selection)
                cached.append(time.perf_counter() - start)
                assert reduction.from_cache
            start = time.perf_counter()
            reduction.ffrf_interface()  # what the first mechanism build of a loaded one costs
            interface.append(time.perf_counter() - start)
    notes["reduction"] = {"cold_s": statistics.median(cold),
                          "cached_s": statistics.median(cached),
                          "ffrf_interface_s": statistics.median(interface),
                          "cold_runs": cold, "cached_runs": cached}
    say(f"reduction: cold {statistics.median(cold):.2f} s, cached "
        f"{statistics.median(cached):.3f} s")


def repository_root() -> Path | None:
    """The clone holding flex's package: the nearest folder above it with a ``Makefile`` and a
    ``pyproject.toml`` (None for an installed flex). A fixed ``parents[k]`` went stale when
    this module moved a folder deeper: make bench ran ``make all`` inside ``flex/`` ("No rule
    to make target 'all'") and timed nothing."""
    for folder in Path(__file__).resolve().parents:
        if (folder / "Makefile").is_file() and (folder / "pyproject.toml").is_file():
            return folder
    return None


def _run_make(argv: list[str], root: Path, env: dict[str, str]
              ) -> subprocess.CompletedProcess:
    """``argv`` (a make) in ``root``, ending with this process however it ends: SIGTERM
    when it is killed (:func:`flex.base.lifetime.dying_with_this_process`) or interrupted
    (make passes SIGTERM on to its recipes, each to its flex run; subprocess.run would
    SIGKILL make and leave its runs computing)."""
    from flex.base.lifetime import dying_with_this_process

    with subprocess.Popen(dying_with_this_process(argv), cwd=root, env=env, text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE) as proc:
        try:
            out, err = proc.communicate()
        except BaseException:
            proc.terminate()
            proc.wait()
            raise
    return subprocess.CompletedProcess(argv, proc.returncode, out, err)


def bench_make_all(say: Say, notes: dict[str, Any], run: bool = True) -> None:
    """``make all FORCE=1`` [s] in the repository holding flex, with an empty reduction cache
    (cold) and again with it filled (warm); skipped when not ``run`` (``FLEX_BENCH_MAKE=0``).
    The child ``make`` gets this process's environment with ``FLEX_CACHE_DIR`` set to a
    temporary folder."""
    if not run:
        notes["make_all"] = {"skipped": "FLEX_BENCH_MAKE=0"}
        return
    root = repository_root()
    if root is None:
        notes["make_all"] = {"skipped": "no Makefile above flex's package (an installed flex, "
                                        "not a clone): make all cannot be timed"}
        return
    subprocess.run(["make", "-s", "setup"], cwd=root, capture_output=True, check=False)
    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, FLEX_CACHE_DIR=str(folder))
        for label in ("cold", "warm"):
            say(f"make all ({label} reduction cache)")
            start = time.perf_counter()
            done = _run_make(["make", "all", "FORCE=1"], root, env)
            out[f"{label}_s"] = time.perf_counter() - start
            out[f"{label}_returncode"] = done.returncode
            if done.returncode:
                out[f"{label}_error"] = (done.stderr or done.stdout)[-400:]
    notes["make_all"] = out
    failed = [label for label in ("cold", "warm") if out[f"{label}_returncode"]]
    if failed:  # a failed case of the study (its exit status says so), not a table line only
        raise FlexError(f"make all failed ({', '.join(failed)} reduction cache) in {root}: "
                        f"{out[f'{failed[0]}_error'][-200:]}")


def _stored(store: Mapping[str, StoredReference], scene: Scene) -> Reference:
    """The stored reference of ``scene``'s physics as what runs are measured against, its
    accuracy the peak's (what the FFRF parts certify); :class:`FlexError` naming the command
    that makes it when the store lacks it."""
    from flex.data.reference_store import MissingReferenceError, reference_for
    from flex.experiments.workprecision.measurement import stored_as_reference

    try:
        return stored_as_reference(reference_for(store, scene))
    except MissingReferenceError as exc:
        raise FlexError(str(exc)) from exc


def run_bench(scenes: Mapping[str, Scene], plan: BenchPlan, repeats: int,
              progress: Progress | None = None, notes: dict[str, Any] | None = None, *,
              cache_dir: Path | None = None, nonlinear: bool = True, make_all: bool = True,
              store: Mapping[str, StoredReference] | None = None) -> dict[str, CaseResult]:
    """Run the seven parts in order on ``scenes["rigid"]`` and ``scenes["ffrf_1mm"]`` (see the
    module doc); each part's failure is stored, the others still run.

    ``cache_dir``: the reduction cache folder of the timed runs (None: reductions built in
    memory, no disk cache; the ``reduction`` part always times its own empty folders);
    ``nonlinear``: time the nonlinear FE coupler too (if installed); ``make_all``: time
    ``make all`` (the ``make_all`` part); ``store``: the stored references the FFRF parts
    are measured against (:mod:`flex.data.reference_store`; None: the bundled store).
    """
    if store is None:
        from flex.data.reference_store import bundled_store, read_store

        store = read_store(bundled_store())
    pool = ReductionPool(cache_dir)
    notes = {} if notes is None else notes
    results: dict[str, CaseResult] = {}
    parts: list[tuple[str, Callable[[Say], Any]]] = [
        ("rigid", lambda say: bench_rigid(scenes["rigid"], plan, repeats, pool, say, notes)),
        ("ffrf_1mm", lambda say: bench_ffrf(scenes["ffrf_1mm"], plan, repeats, pool, say,
                                            notes, store, nonlinear)),
        ("reduction", lambda say: bench_reduction(scenes["ffrf_1mm"], say, notes)),
        ("step_cost", lambda say: plan.step_cost and bench_step_cost(
            scenes["ffrf_1mm"], plan.step_cost, repeats, pool, say, notes)),
        ("plates", lambda say: plan.plates and bench_plates(
            scenes["ffrf_1mm"], plan.plates, repeats, pool, say, notes, store)),
        ("budget", lambda say: plan.budget and bench_budget(
            plan.budget, repeats, cache_dir, say, notes)),
        ("make_all", lambda say: bench_make_all(say, notes, make_all))]
    for index, (name, part) in enumerate(parts):
        if progress:
            progress(name, index, len(parts))

        def say(text: str, _name: str = name, _index: int = index) -> None:
            if progress:
                progress(f"{_name}: {text}", _index, len(parts))

        try:
            results.update(part(say) or {})
        except FlexError as exc:
            notes[f"{name}_failed"] = str(exc)
            results[f"{name}_failed"] = CaseResult(f"{name}_failed", "", status="failed",
                                                   message=str(exc))
    if progress:
        progress("done", len(parts), len(parts))
    return results
