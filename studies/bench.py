"""Study ``bench``: how fast flex reaches a stated accuracy (a benchmark, not a timed test).

Every number is measured by this run, on whatever else the machine is doing: wall times are
medians of :data:`REPEATS` runs, and each comparison is a ratio of two times measured here.

- ``rigid``: the thesis deployment (0.03 s) at 1e-7 rad crank-angle accuracy. The reference
  is the scipy DAE at rtol 1e-13 (shown converged by rtol 1e-12 and by flex at h = 1e-6 s).
  flex: the largest step of the tuned setting that reaches 1e-7 rad, and the untuned
  defaults at that step; scipy (DOP853): the loosest rtol that reaches 1e-7 rad.
- ``ffrf_1mm``: the 1 mm plate coupler, 0.03 s, at 1 % peak-deflection accuracy (target:
  under 0.5 s of integration). Reference: flex's FFRF model with 12 modes on a 2 mm mesh at
  h = 5e-6 s (shown converged by coarsening step, modes and mesh). The untuned first set-up
  (h = 1e-5 s, 6 modes, full Newton at 1e-10) is timed beside the fastest candidate that
  reaches 1 %, and the nonlinear FE coupler (if installed) at its coarsest setting.
- ``profile``: Exudyn's CPU-time statistics of the untuned and the tuned run (share of each
  solver phase) and flex's own phases (reduction, build, integration, output).
- ``reduction``: build time of the 1 mm plate reduction, cold (empty cache) and from cache.
- ``make_all``: ``make all`` end to end with an empty reduction cache (cold) and again with
  it filled (warm); ``FLEX_BENCH_MAKE=0`` skips it.

Stored: one case per timed configuration (attrs: knobs, errors, counters; dataset
``wall_times``) and ``/summary/table`` (the printed table) plus ``/summary/<part>/...``.
"""

from __future__ import annotations

import io
import os
import re
import statistics
import subprocess
import tempfile
import time
from collections.abc import Callable
from contextlib import redirect_stdout
from pathlib import Path
from typing import Any

import numpy as np

from flex.errors import FlexError
from flex.results import CaseResult, Dataset
from flex.scene import Scene, apply_overrides, to_toml, validate
from flex.settings import AUTO_OVERRIDES, pinned_overrides
from flex.study import StudyRun, Summary
from flex.tradeoff import (
    Measurement,
    ReductionPool,
    Reference,
    Setting,
    converged_reference,
    fastest,
    measure,
    run_once,
    scene_for,
)

NAME = "bench"
DESCRIPTION = "speed at a stated accuracy: rigid 1e-7 rad, FFRF 1 mm 1 %, cache, make all"
OVERRIDES = pinned_overrides()
REPEATS = 5
RIGID_ACCURACY_RAD = 1e-7
FFRF_ACCURACY = 1e-2  # relative error of the peak midpoint deflection
FFRF_TARGET_S = 0.5
PLATE = ['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.001",
         "coupler.mesh_size_m=0.002"]
S = Setting.of
#: tuned rigid knobs: one Newton iteration per step suffices at 1e-8 (tradeoff study)
RIGID_TUNED = {"newton": "full", "newton_relative_tolerance": 1e-8}
#: FFRF candidates, cheapest first (from the tradeoff study's Pareto front)
FFRF_CANDIDATES = [
    S("h=4e-4 mesh=6mm modes=2 modified tol=1e-8", step_s=4e-4, coupler__mesh_size_m=0.006,
      coupler__modes=2, newton="modified", newton_relative_tolerance=1e-8),
    S("h=4e-4 mesh=4mm modes=2 modified tol=1e-8", step_s=4e-4, coupler__mesh_size_m=0.004,
      coupler__modes=2, newton="modified", newton_relative_tolerance=1e-8),
    S("h=2e-4 mesh=4mm modes=2 modified tol=1e-8", step_s=2e-4, coupler__mesh_size_m=0.004,
      coupler__modes=2, newton="modified", newton_relative_tolerance=1e-8),
    S("h=2e-4 mesh=4mm modes=6 modified tol=1e-8", step_s=2e-4, coupler__mesh_size_m=0.004,
      coupler__modes=6, newton="modified", newton_relative_tolerance=1e-8),
    S("h=1e-4 mesh=2mm modes=6 modified tol=1e-8", step_s=1e-4, coupler__mesh_size_m=0.002,
      coupler__modes=6, newton="modified", newton_relative_tolerance=1e-8),
]
FFRF_UNTUNED = S("untuned: h=1e-5 mesh=2mm modes=6 full tol=1e-10", step_s=1e-5,
                 coupler__mesh_size_m=0.002, coupler__modes=6, newton="full",
                 newton_relative_tolerance=1e-10, spectral_radius=0.9)
#: what a user gets: the scene's "auto" solver keys (flex/settings.py) on the 2 mm mesh, 6 modes
FFRF_DEFAULTS = Setting("flex defaults (auto)", AUTO_OVERRIDES)
NONLINEAR_FINE = S("nonlinear FE h=1e-4 mesh=4mm modified tol=1e-8",
                   coupler__model="nonlinear_fe", coupler__mesh_size_m=0.004, step_s=1e-4,
                   newton="modified", newton_relative_tolerance=1e-8)
NONLINEAR_COARSE = S("nonlinear FE h=2e-4 mesh=4mm modified tol=1e-8",
                     coupler__model="nonlinear_fe", coupler__mesh_size_m=0.004, step_s=2e-4,
                     newton="modified", newton_relative_tolerance=1e-8)


def cases(scene: Scene) -> dict[str, Scene]:
    out = {"rigid": scene, "ffrf_1mm": apply_overrides(scene, PLATE)}
    for case in out.values():
        validate(case)
    return out


# ------------------------------------------------------------------------------------------
# profiling
# ------------------------------------------------------------------------------------------
_TIMER = re.compile(r"^\s*(_{0,2}[A-Za-z/ 0-9]+?)\s*=\s*([0-9.eE+-]+)%")


def profile(scene: Scene, pool: ReductionPool) -> dict[str, float]:
    """One run with flex's phases timed [s] and Exudyn's CPU-time shares [%] (``exudyn_*``)."""
    import exudyn as exu

    from flex.mechanism import build_mechanism
    from flex.solver import _exudyn_settings, collect, solver_settings

    out: dict[str, float] = {}
    start = time.perf_counter()
    reduction = pool.for_scene(scene)
    out["phase_reduction_s"] = time.perf_counter() - start
    start = time.perf_counter()
    mech = build_mechanism(scene, reduction)
    out["phase_build_s"] = time.perf_counter() - start
    settings = _exudyn_settings(solver_settings(scene))
    settings.show.computationTime = True
    settings.timeIntegration.verboseMode = 1  # the statistics are printed only when verbose
    solver = exu.MainSolverImplicitSecondOrder()
    captured = io.StringIO()
    start = time.perf_counter()
    with redirect_stdout(captured):
        ok = solver.SolveSystem(mech.mbs, settings)
    out["phase_integration_s"] = time.perf_counter() - start
    if not ok:
        raise FlexError("profiled run failed")
    start = time.perf_counter()
    collect(mech)
    out["phase_output_s"] = time.perf_counter() - start
    out["steps"] = float(solver.it.currentStepIndex)
    out["newton_iterations"] = float(solver.it.newtonStepsCount)
    out["jacobian_updates"] = float(solver.it.newtonJacobiCount)
    for line in captured.getvalue().splitlines():
        match = _TIMER.match(line)
        if match and "time" not in match[1]:
            name = re.sub(r"[^A-Za-z0-9_]+", "_", match[1].strip())
            out[f"exudyn_{name}_percent"] = float(match[2])
    return out


# ------------------------------------------------------------------------------------------
# parts
# ------------------------------------------------------------------------------------------
def _case(name: str, scene: Scene, m: Measurement, extra: dict[str, Any] | None = None
          ) -> CaseResult:
    try:
        scene_toml = to_toml(scene_for(scene, m.setting))
    except FlexError:
        scene_toml = to_toml(scene)
    attrs: dict[str, Any] = {"knobs": repr(m.setting.knobs()), "label": m.setting.label}
    attrs.update({f"error_{k}": v for k, v in m.errors.items() if k != "error"})
    attrs["error"] = m.error
    attrs.update(extra or {})
    if not m.ok:
        return CaseResult(name, scene_toml, status="failed", message=m.message, attrs=attrs)
    return CaseResult(name, scene_toml,
                      {"wall_times": Dataset(np.array(m.wall_times_s), "s",
                                             "integration wall time of each repeat")},
                      counters={"wall_time_s": m.wall_time_s, "total_time_s": m.total_time_s,
                                "steps": m.steps, "newton_iterations": m.newton_iterations,
                                "jacobian_updates": m.jacobian_updates,
                                "repeats": len(m.wall_times_s)}, attrs=attrs)


def _rigid(scene: Scene, pool: ReductionPool, say: Callable[[str], None],
           notes: dict[str, Any]) -> dict[str, CaseResult]:
    reference = converged_reference(
        scene, "rigid", Setting("scipy DOP853 rtol=1e-13", engine="scipy", rtol=1e-13,
                                atol=1e-15),
        {"rtol 1e-13 -> 1e-12": Setting("scipy rtol=1e-12", engine="scipy", rtol=1e-12,
                                        atol=1e-14),
         "flex h = 1e-6 s": S("flex h=1e-6", step_s=1e-6)}, 1e-8, pool,
        "scipy DOP853 rtol 1e-13")
    say(f"rigid reference: accuracy {reference.accuracy:.1e}")
    chosen = None
    for step in (1e-5, 8e-6, 6e-6, 5e-6, 4e-6, 3e-6):
        probe = measure(scene, S(f"tuned h={step:g}", step_s=step, **RIGID_TUNED), reference, 1)
        if probe.ok and probe.errors["crank_angle_rad"] <= RIGID_ACCURACY_RAD:
            chosen = step
            break
    if chosen is None:
        raise FlexError("no flex step reached 1e-7 rad")
    say(f"rigid: flex reaches 1e-7 rad at h = {chosen:g} s")
    tuned = measure(scene, S(f"flex tuned h={chosen:g} tol=1e-8", step_s=chosen, **RIGID_TUNED),
                    reference, REPEATS, pool)
    untuned = measure(scene, S(f"flex untuned h={chosen:g} tol=1e-10", step_s=chosen,
                               newton="full", newton_relative_tolerance=1e-10),
                      reference, REPEATS, pool)
    scipy_pick = None
    for rtol in (1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8):
        setting = Setting(f"scipy DOP853 rtol={rtol:g}", engine="scipy", rtol=rtol,
                          atol=rtol * 1e-2)
        probe = measure(scene, setting, reference, 1)
        if probe.ok and probe.errors["crank_angle_rad"] <= RIGID_ACCURACY_RAD:
            scipy_pick = setting
            break
    if scipy_pick is None:
        raise FlexError("no scipy tolerance reached 1e-7 rad")
    scipy_run = measure(scene, scipy_pick, reference, REPEATS)
    say(f"rigid: scipy reaches 1e-7 rad at {scipy_pick.label}")
    notes["rigid"] = {"reference": reference, "tuned": tuned, "untuned": untuned,
                      "scipy": scipy_run,
                      "profile_untuned": profile(scene_for(scene, untuned.setting), pool),
                      "profile_tuned": profile(scene_for(scene, tuned.setting), pool)}
    return {"rigid_tuned": _case("rigid_tuned", scene, tuned),
            "rigid_untuned": _case("rigid_untuned", scene, untuned),
            "rigid_scipy": _case("rigid_scipy", scene, scipy_run)}


def _ffrf_reference(scene: Scene, pool: ReductionPool) -> Reference:
    def ref(label: str, **knobs: Any) -> Setting:
        values = {"step_s": 5e-6, "coupler__mesh_size_m": 0.002, "coupler__modes": 12,
                  "newton": "modified", "newton_relative_tolerance": 1e-10}
        values.update(knobs)
        return S(label, **values)

    return converged_reference(scene, "ffrf_1mm", ref("reference"), {
        "step_s 5e-6 -> 1e-5": ref("coarser step", step_s=1e-5),
        "modes 12 -> 8": ref("fewer modes", coupler__modes=8),
        "mesh_size_m 0.002 -> 0.003": ref("coarser mesh", coupler__mesh_size_m=0.003),
    }, 3e-3, pool, "flex FFRF, 12 modes, 2 mm mesh, h = 5e-6 s, modified Newton 1e-10")


def _nonlinear_available() -> bool:
    try:
        from flex.nonlinear import add_nonlinear_fe_coupler  # noqa: F401
    except ImportError:
        return False
    return True


def _ffrf(scene: Scene, pool: ReductionPool, say: Callable[[str], None],
          notes: dict[str, Any]) -> dict[str, CaseResult]:
    reference = _ffrf_reference(scene, pool)
    say(f"ffrf_1mm reference: accuracy {reference.accuracy:.1e}, peak "
        f"{reference.peak_deflection_m * 1e6:.2f} um")
    out: dict[str, CaseResult] = {}
    probes = []
    for setting in FFRF_CANDIDATES:
        probe = measure(scene, setting, reference, 1, pool)
        probes.append(probe)
        out[f"ffrf_probe_{len(probes)}"] = _case(f"ffrf_probe_{len(probes)}", scene, probe)
    within = [p for p in probes if p.ok
              and p.errors["peak_deflection_relative"] <= FFRF_ACCURACY]
    if not within:
        raise FlexError("no FFRF candidate reached 1 % peak deflection")
    best = fastest(within)  # by integration time (the first total includes a projection)
    tuned = measure(scene, best.setting, reference, REPEATS, pool)
    say(f"ffrf_1mm: tuned {tuned.setting.label}: {tuned.wall_time_s:.3f} s")
    untuned = measure(scene, FFRF_UNTUNED, reference, 1, pool)
    say(f"ffrf_1mm: untuned {untuned.wall_time_s:.2f} s")
    default = measure(scene, FFRF_DEFAULTS, reference, REPEATS, pool)
    say(f"ffrf_1mm: flex defaults {default.wall_time_s:.3f} s")
    out["ffrf_tuned"] = _case("ffrf_tuned", scene, tuned)
    out["ffrf_untuned"] = _case("ffrf_untuned", scene, untuned)
    out["ffrf_default"] = _case("ffrf_default", scene, default)
    results: dict[str, Any] = {"reference": reference, "tuned": tuned, "untuned": untuned,
                               "default": default,
                               "probes": probes,
                               "profile_untuned": profile(scene_for(scene, FFRF_UNTUNED), pool),
                            "profile_tuned": profile(scene_for(scene, tuned.setting), pool)}
    if _nonlinear_available() and os.environ.get("FLEX_BENCH_NONLINEAR", "1") != "0":
        # the nonlinear FE coupler is another model (it keeps the axial force's effect on
        # bending): its accuracy is judged against its own run at half the step, and its
        # difference to the converged FFRF reference is reported beside it
        say("ffrf_1mm: nonlinear FE coupler at h = 1e-4 s (minutes)")
        try:
            fine, counters = run_once(scene_for(scene, NONLINEAR_FINE), NONLINEAR_FINE, pool)
        except FlexError as exc:
            results["nonlinear_failed"] = str(exc)
        else:
            own = Reference("nonlinear FE h=1e-4", fine, NONLINEAR_FINE, {}, FFRF_ACCURACY,
                            float(counters["wall_time_s"]), "nonlinear FE, h = 1e-4 s")
            say("ffrf_1mm: nonlinear FE coupler at h = 2e-4 s")
            coarse = measure(scene, NONLINEAR_COARSE, own, 1, pool)
            results["nonlinear"] = {"fine_wall_time_s": own.wall_time_s, "coarse": coarse,
                                    "model_difference": own.errors(reference.observables)}
            out["nonlinear_fe"] = _case("nonlinear_fe", scene, coarse, {
                "fine_wall_time_s": own.wall_time_s,
                "note": "errors against the nonlinear FE run at h = 1e-4 s"})
    notes["ffrf_1mm"] = results
    return out


def _reduction(scene: Scene, say: Callable[[str], None], notes: dict[str, Any]) -> None:
    from flex.reduction import build_reduction

    c = scene["coupler"]
    args = (c["length_m"], c["thickness_m"], c["width_m"], c["youngs_modulus_Pa"],
            c["density_kg_per_m3"], c["poisson_ratio"], c["mesh_size_m"], c["modes"])
    cold, cached, interface = [], [], []
    for _ in range(2):
        with tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            build_reduction(*args, cache_dir=folder)
            cold.append(time.perf_counter() - start)
            for _ in range(3):
                start = time.perf_counter()
                reduction = build_reduction(*args, cache_dir=folder)
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


def _make_all(say: Callable[[str], None], notes: dict[str, Any]) -> None:
    if os.environ.get("FLEX_BENCH_MAKE", "1") == "0":
        notes["make_all"] = {"skipped": "FLEX_BENCH_MAKE=0"}
        return
    root = Path(__file__).resolve().parent.parent
    subprocess.run(["make", "-s", "setup"], cwd=root, capture_output=True, check=False)
    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, FLEX_CACHE_DIR=str(folder))
        for label in ("cold", "warm"):
            say(f"make all ({label} reduction cache)")
            start = time.perf_counter()
            done = subprocess.run(["make", "all", "FORCE=1"], cwd=root, env=env,
                                  capture_output=True, text=True, check=False)
            out[f"{label}_s"] = time.perf_counter() - start
            out[f"{label}_returncode"] = done.returncode
            if done.returncode:
                out[f"{label}_error"] = (done.stderr or done.stdout)[-400:]
    notes["make_all"] = out


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Run the four parts in order; each part's failure is stored, the others still run."""
    progress = run.progress
    pool = ReductionPool()
    notes = run.notes  # each part's measurements, read by summarize
    results: dict[str, CaseResult] = {}
    parts = [("rigid", lambda say: _rigid(scenes["rigid"], pool, say, notes)),
             ("ffrf_1mm", lambda say: _ffrf(scenes["ffrf_1mm"], pool, say, notes)),
             ("reduction", lambda say: _reduction(scenes["ffrf_1mm"], say, notes)),
             ("make_all", lambda say: _make_all(say, notes))]
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


# ------------------------------------------------------------------------------------------
# summary
# ------------------------------------------------------------------------------------------
def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    notes = notes or {}
    datasets: dict[str, Dataset] = {}
    rows: list[tuple[str, str, str]] = []

    def put(key: str, value: Any, units: str, text: str) -> None:
        datasets[key] = Dataset(value, units, text)

    rigid = notes.get("rigid")
    if rigid:
        tuned, untuned, scipy = rigid["tuned"], rigid["untuned"], rigid["scipy"]
        ratio = tuned.wall_time_s / scipy.wall_time_s
        ratio_total = tuned.total_time_s / scipy.total_time_s
        put("rigid/reference_accuracy", rigid["reference"].accuracy, "1",
            "largest relative change of the reference under coarsening")
        for name, m in (("flex_tuned", tuned), ("flex_untuned", untuned), ("scipy", scipy)):
            put(f"rigid/{name}/wall_time", m.wall_time_s, "s", "median integration time")
            put(f"rigid/{name}/total_time", m.total_time_s, "s",
                "median build + integration + output")
            put(f"rigid/{name}/crank_angle_error", m.errors.get("crank_angle_rad", np.nan),
                "rad", "max |crank angle - reference|")
            put(f"rigid/{name}/setting", m.setting.label, "1", "setting")
        put("rigid/ratio_flex_over_scipy", ratio, "1", "integration time ratio, same run")
        put("rigid/ratio_flex_over_scipy_total", ratio_total, "1",
            "end-to-end ratio (build + integration + output), same run")
        put("rigid/speedup_tuning", untuned.wall_time_s / tuned.wall_time_s, "1",
            "untuned / tuned integration time at the same step")
        rows += [
            ("rigid 1e-7 rad: flex tuned", f"{tuned.wall_time_s * 1e3:.0f} ms",
             f"{tuned.setting.label}, error {tuned.errors['crank_angle_rad']:.1e} rad, "
             f"{tuned.steps} steps, {tuned.newton_iterations} Newton iterations"),
            ("rigid 1e-7 rad: flex untuned", f"{untuned.wall_time_s * 1e3:.0f} ms",
             f"{untuned.setting.label}, {untuned.newton_iterations} Newton iterations"),
            ("rigid 1e-7 rad: scipy DAE", f"{scipy.wall_time_s * 1e3:.1f} ms",
             f"{scipy.setting.label}, error {scipy.errors['crank_angle_rad']:.1e} rad "
             f"(end to end {scipy.total_time_s * 1e3:.0f} ms)"),
            ("rigid: flex / scipy", f"{ratio:.1f}",
             f"integration; end to end {ratio_total:.1f}"),
        ]
    ffrf = notes.get("ffrf_1mm")
    if ffrf:
        tuned, untuned = ffrf["tuned"], ffrf["untuned"]
        put("ffrf_1mm/reference_accuracy", ffrf["reference"].accuracy, "1",
            "largest relative change of the reference under coarsening")
        put("ffrf_1mm/reference_peak_deflection", ffrf["reference"].peak_deflection_m, "m",
            "reference peak |midpoint deflection|")
        default = ffrf["default"]
        for name, m in (("tuned", tuned), ("untuned", untuned), ("default", default)):
            put(f"ffrf_1mm/{name}/wall_time", m.wall_time_s, "s", "median integration time")
            put(f"ffrf_1mm/{name}/total_time", m.total_time_s, "s",
                "median build + integration + output")
            put(f"ffrf_1mm/{name}/peak_deflection_error", m.errors.get(
                "peak_deflection_relative", np.nan), "1", "relative peak deflection error")
            put(f"ffrf_1mm/{name}/setting", m.setting.label, "1", "setting")
        put("ffrf_1mm/target_met", bool(tuned.wall_time_s < FFRF_TARGET_S), "1",
            f"tuned integration under {FFRF_TARGET_S} s")
        put("ffrf_1mm/speedup_tuning", untuned.wall_time_s / tuned.wall_time_s, "1",
            "untuned / tuned integration time")
        rows += [
            ("FFRF 1 mm 1 %: tuned", f"{tuned.wall_time_s:.3f} s",
             f"{tuned.setting.label}, peak error "
             f"{tuned.errors['peak_deflection_relative'] * 100:.2f} %, {tuned.steps} steps, "
             f"end to end {tuned.total_time_s:.2f} s; target < {FFRF_TARGET_S} s: "
             f"{'met' if tuned.wall_time_s < FFRF_TARGET_S else 'NOT met'}"),
            ("FFRF 1 mm: untuned first set-up", f"{untuned.wall_time_s:.2f} s",
             f"{untuned.setting.label}, peak error "
             f"{untuned.errors.get('peak_deflection_relative', np.nan) * 100:.3f} %"),
            ("FFRF 1 mm: untuned / tuned", f"{untuned.wall_time_s / tuned.wall_time_s:.1f}",
             "integration time"),
            ("FFRF 1 mm: flex defaults", f"{default.wall_time_s:.3f} s",
             f"the scene's \"auto\" solver keys, 2 mm mesh, 6 modes: peak error "
             f"{default.errors.get('peak_deflection_relative', np.nan) * 100:.2f} %, "
             f"{default.steps} steps; target < {FFRF_TARGET_S} s: "
             f"{'met' if default.wall_time_s < FFRF_TARGET_S else 'NOT met'}"),
        ]
        nonlinear = ffrf.get("nonlinear")
        if nonlinear is not None and nonlinear["coarse"].ok:
            coarse = nonlinear["coarse"]
            own_error = coarse.errors["peak_deflection_relative"]
            pick_wall = (coarse.wall_time_s if own_error <= FFRF_ACCURACY
                         else nonlinear["fine_wall_time_s"])
            ratio = pick_wall / tuned.wall_time_s
            model = nonlinear["model_difference"]["peak_deflection_relative"]
            put("ffrf_1mm/nonlinear/wall_time_h2e-4", coarse.wall_time_s, "s", "integration")
            put("ffrf_1mm/nonlinear/wall_time_h1e-4", nonlinear["fine_wall_time_s"], "s",
                "integration")
            put("ffrf_1mm/nonlinear/peak_change_h2e-4_to_h1e-4", own_error, "1",
                "its own time-discretization error estimate at h = 2e-4 s")
            put("ffrf_1mm/nonlinear/peak_difference_to_ffrf_reference", model, "1",
                "converged FFRF peak against the nonlinear FE peak (h = 1e-4 s)")
            put("ffrf_1mm/ratio_nonlinear_over_tuned", ratio, "1",
                "integration time ratio at 1 % (each model against its own finer run)")
            rows.append(("FFRF 1 mm: nonlinear FE / tuned FFRF", f"{ratio:.0f}",
                         f"nonlinear FE {pick_wall:.0f} s at h = "
                         f"{'2e-4' if own_error <= FFRF_ACCURACY else '1e-4'} s (peak changes "
                         f"{own_error * 100:.2f} % when the step halves); the models differ by "
                         f"{model * 100:.1f} % in peak deflection"))
        elif nonlinear is not None:
            rows.append(("FFRF 1 mm: nonlinear FE", "failed", nonlinear["coarse"].message[:120]))
        else:
            why = ffrf.get("nonlinear_failed", "not run (not installed or FLEX_BENCH_NONLINEAR=0)")
            rows.append(("FFRF 1 mm: nonlinear FE", "-", why[:150]))
    for part in ("rigid", "ffrf_1mm"):
        data = notes.get(part)
        if not data:
            continue
        for which in ("profile_untuned", "profile_tuned"):
            for key, value in data[which].items():
                units = "%" if key.endswith("_percent") else ("s" if key.endswith("_s") else "1")
                put(f"{part}/{which}/{key}", value, units, "profile of one run")
        for which in ("untuned", "tuned"):
            prof = data[f"profile_{which}"]
            top = sorted(((v, k) for k, v in prof.items()
                          if k.endswith("_percent") and not k.startswith("exudyn___")),
                         reverse=True)[:4]
            rows.append((f"{part}: {which} profile", f"{prof['phase_integration_s']:.2f} s",
                         ", ".join(f"{k[7:-8]} {v:.0f} %" for v, k in top)
                         + f"; {prof['newton_iterations'] / max(prof['steps'], 1):.1f} Newton "
                         f"iterations and {prof['jacobian_updates'] / max(prof['steps'], 1):.2f}"
                         f" Jacobians per step"))
    reduction = notes.get("reduction")
    if reduction:
        put("reduction/cold", reduction["cold_s"], "s", "build, empty cache (median of 2)")
        put("reduction/cached", reduction["cached_s"], "s", "load from cache (median of 6)")
        put("reduction/ffrf_interface", reduction["ffrf_interface_s"], "s",
            "projection of the loaded reduction for its first mechanism")
        rows += [("reduction 1 mm plate: cold", f"{reduction['cold_s']:.2f} s", "empty cache"),
                 ("reduction 1 mm plate: from cache", f"{reduction['cached_s']:.3f} s",
                  f"+ {reduction['ffrf_interface_s']:.2f} s projection at the first build")]
    make_all = notes.get("make_all", {})
    for label in ("cold", "warm"):
        if f"{label}_s" in make_all:
            put(f"make_all/{label}", make_all[f"{label}_s"], "s", f"make all, {label} cache")
            put(f"make_all/{label}_returncode", make_all[f"{label}_returncode"], "1",
                "exit status")
            status = ("ok" if make_all[f"{label}_returncode"] == 0
                      else f"FAILED: {make_all.get(f'{label}_error', '')[-120:]}")
            rows.append((f"make all, {label} reduction cache", f"{make_all[f'{label}_s']:.0f} s",
                         status))
    if "skipped" in make_all:
        rows.append(("make all", "-", make_all["skipped"]))
    for key, value in notes.items():
        if key.endswith("_failed"):
            rows.append((key, "failed", value[:150]))
    put("table/what", np.array([r[0] for r in rows], dtype=object), "1", "measurement")
    put("table/value", np.array([r[1] for r in rows], dtype=object), "see value", "result")
    put("table/detail", np.array([r[2] for r in rows], dtype=object), "1", "how")
    width = max((len(r[0]) for r in rows), default=10)
    lines = ["bench (medians of repeats; ratios from this run)"]
    lines += [f"  {what:{width}s}  {value:>10s}  {detail}" for what, value, detail in rows]
    return Summary(datasets, "\n".join(lines))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    """Bar charts: integration times at equal accuracy (log scale) and the Exudyn CPU shares
    of the untuned and tuned runs."""
    from flex.plotting import figure

    data = summary.datasets
    paths = []
    bars = [(label, data[key].data) for label, key in (
        ("rigid 1e-7 rad: flex untuned", "rigid/flex_untuned/wall_time"),
        ("rigid 1e-7 rad: flex tuned", "rigid/flex_tuned/wall_time"),
        ("rigid 1e-7 rad: scipy DAE", "rigid/scipy/wall_time"),
        ("FFRF 1 mm 1 %: untuned", "ffrf_1mm/untuned/wall_time"),
        ("FFRF 1 mm 1 %: tuned", "ffrf_1mm/tuned/wall_time"),
        ("FFRF 1 mm: flex defaults", "ffrf_1mm/default/wall_time"),
        ("FFRF 1 mm 1 %: nonlinear FE (h = 2e-4 s)", "ffrf_1mm/nonlinear/wall_time_h2e-4"),
    ) if key in data]
    if bars:
        path = folder / "bench-times.png"
        with figure(path, "Integration wall time at equal accuracy (median of repeats, log "
                    "scale)", "integration wall time [s]", "run (model, accuracy: settings)",
                    size=(8.5, 4.2)) as ax:
            ax.barh([b[0] for b in bars], [b[1] for b in bars], color="tab:blue")
            ax.set_xscale("log")
            ax.axvline(FFRF_TARGET_S, color="grey", ls=":",
                       label=f"FFRF target {FFRF_TARGET_S:g} s")
            for index, (_, seconds) in enumerate(bars):
                ax.annotate(f"{float(seconds):.3g} s", (float(seconds), index), xytext=(3, 0),
                            textcoords="offset points", va="center", fontsize="x-small")
            times = [float(b[1]) for b in bars] + [FFRF_TARGET_S]
            ax.set_xlim(min(times) / 3, max(times) * 4)  # room for the value labels
            ax.invert_yaxis()
        paths.append(path)
    for part in ("rigid", "ffrf_1mm"):
        shares = {}
        for which in ("profile_untuned", "profile_tuned"):
            prefix = f"{part}/{which}/exudyn_"
            shares[which] = {key[len(prefix):-len("_percent")]: value.data
                             for key, value in data.items()
                             if key.startswith(prefix) and key.endswith("_percent")
                             and not key[len(prefix):].startswith("__")}
        names = sorted(set(shares["profile_untuned"]) | set(shares["profile_tuned"]),
                       key=lambda n: -shares["profile_untuned"].get(n, 0.0))
        if not names:
            continue
        path = folder / f"bench-profile-{part}.png"
        model = {"rigid": "rigid links", "ffrf_1mm": "FFRF coupler t = 1 mm"}.get(part, part)
        with figure(path, f"Exudyn CPU share per solver phase, {model}: untuned against "
                    "tuned settings", "share of the Exudyn CPU time [%]", "solver phase",
                    size=(8.0, 4.5)) as ax:
            y = np.arange(len(names))
            for offset, which in ((-0.2, "profile_untuned"), (0.2, "profile_tuned")):
                ax.barh(y + offset, [shares[which].get(n, 0.0) for n in names], height=0.4,
                        label=which.replace("profile_", "") + " settings")
            ax.set_yticks(y, names)
            ax.invert_yaxis()
        paths.append(path)
    return paths


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
