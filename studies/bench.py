"""Study ``bench``: how fast flex reaches a stated accuracy (a benchmark, not a timed test).

Every number is measured by this run, on whatever else the machine is doing: wall times are
medians of :data:`REPEATS` runs, and each comparison is a ratio of two times measured here
(:mod:`flex.experiments.workprecision.benchmark`).

- ``rigid``: the thesis deployment (0.03 s) at 1e-7 rad crank-angle accuracy. The reference
  is the scipy DAE at rtol 1e-13 (shown converged by rtol 1e-12 and by flex at h = 1e-6 s).
  flex: the largest step of the tuned setting that reaches 1e-7 rad, and the untuned
  defaults at that step; scipy (DOP853): the loosest rtol that reaches 1e-7 rad.
- ``ffrf_1mm``: the 1 mm plate coupler, 0.03 s, at 1 % peak-deflection accuracy (target:
  under 0.5 s of integration). Reference: the stored one of its physics (``make references``:
  the calibrated exact beam, 256 elements at 1.25e-6 s). The untuned first set-up
  (h = 1e-5 s, 6 modes, full Newton at 1e-10) is timed beside the fastest candidate that
  reaches 1 %, and the nonlinear FE coupler (if installed; ``FLEX_BENCH_NONLINEAR=0`` skips
  it) at its coarsest setting.
- ``profile``: Exudyn's CPU-time statistics of the untuned and the tuned run (share of each
  solver phase) and flex's own phases (reduction, build, integration, output).
- ``step_cost``: the cost of an FFRF step (1 mm plate, h = 1e-5 s, 3 ms) against mesh size
  (4, 2, 1 mm) and mode count (6, 12, 24), joint markers on every face node (before) and on
  the fewest nodes (now), alternating runs.
- ``reduction``: build time of the 1 mm plate reduction, cold (empty cache) and from cache.
- ``budget``: the thesis plates (0.7-3 mm, FFRF, 1 %, flex's settings): each run with its error
  budget against the run alone, and the 1 mm plate's command line (whole process, figures)
  against the same run in process; ratios of medians.
- ``make_all``: ``make all`` end to end with an empty reduction cache (cold) and again with
  it filled (warm); ``FLEX_BENCH_MAKE=0`` skips it.

The two switches are environment variables of the command (``FLEX_BENCH_MAKE=0 make bench``):
declared in :data:`ENVIRONMENT`, read once by the command line (or :func:`flex.api.run_study`)
and handed to the run as ``run.environment``.

Stored: one case per timed configuration (attrs: knobs, errors, counters; dataset
``wall_times``) and ``/summary/table`` (the printed table) plus ``/summary/<part>/...``
(:mod:`flex.experiments.workprecision.benchmark_report`).
"""

from __future__ import annotations

from pathlib import Path

from flex.config.settings import AUTO_OVERRIDES, pinned_overrides
from flex.data.results import CaseResult
from flex.data.scene import Scene, derived_scenes
from flex.experiments.workprecision.benchmark import BenchPlan, PlatesPlan, StepCostPlan, run_bench
from flex.experiments.workprecision.benchmark_report import bench_figures, bench_summary
from flex.experiments.workprecision.budget_cost import BudgetPlan
from flex.experiments.workprecision.measurement import Setting
from flex.experiments.workprecision.reference_plans import ReferencePlan
from flex.study import StudyRun, Summary

NAME = "bench"
DESCRIPTION = "speed at a stated accuracy: rigid 1e-7 rad, FFRF 1 mm 1 %, cache, make all"
OVERRIDES = pinned_overrides() + ["simulation.error_estimate=false"]  # own references
REPEATS = 5
#: environment variables the command line reads for this study (``run.environment``):
#: ``"0"`` skips the ``make all`` timing / the nonlinear FE coupler; anything else runs it
ENVIRONMENT = ("FLEX_BENCH_MAKE", "FLEX_BENCH_NONLINEAR")
PLATE = ['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.001",
         "coupler.mesh_size_m=0.002"]
S = Setting.of


#: FFRF candidates, cheapest first (from the tradeoff study's Pareto front)
FFRF_CANDIDATES = (
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
)
PLAN = BenchPlan(
    rigid_reference=ReferencePlan(
        Setting("scipy DOP853 rtol=1e-13", engine="scipy", rtol=1e-13, atol=1e-15),
        {"rtol 1e-13 -> 1e-12": Setting("scipy rtol=1e-12", engine="scipy", rtol=1e-12,
                                        atol=1e-14),
         "flex h = 1e-6 s": S("flex h=1e-6", step_s=1e-6)}, 1e-8, "scipy DOP853 rtol 1e-13"),
    rigid_accuracy_rad=1e-7,
    # tuned: one Newton iteration per step suffices at 1e-8 (tradeoff study)
    rigid_tuned={"newton": "full", "newton_relative_tolerance": 1e-8},
    rigid_untuned={"newton": "full", "newton_relative_tolerance": 1e-10},
    rigid_steps=(1e-5, 8e-6, 6e-6, 5e-6, 4e-6, 3e-6),
    scipy_rtols=(1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8),
    ffrf_accuracy=1e-2,  # relative error of the peak midpoint deflection
    ffrf_target_s=0.5,
    ffrf_candidates=FFRF_CANDIDATES,
    ffrf_untuned=S("untuned: h=1e-5 mesh=2mm modes=6 full tol=1e-10", step_s=1e-5,
                   coupler__mesh_size_m=0.002, coupler__modes=6, newton="full",
                   newton_relative_tolerance=1e-10, spectral_radius=0.9),
    # what a user gets: the scene's "auto" solver keys (flex/config/settings.py) on the 2 mm
    # mesh, 6 modes
    ffrf_defaults=Setting("flex defaults (auto)", AUTO_OVERRIDES),
    nonlinear_fine=S("nonlinear FE h=1e-4 mesh=4mm modified tol=1e-8",
                     coupler__model="nonlinear_fe", coupler__mesh_size_m=0.004, step_s=1e-4,
                     newton="modified", newton_relative_tolerance=1e-8),
    nonlinear_coarse=S("nonlinear FE h=2e-4 mesh=4mm modified tol=1e-8",
                       coupler__model="nonlinear_fe", coupler__mesh_size_m=0.004, step_s=2e-4,
                       newton="modified", newton_relative_tolerance=1e-8),
    step_cost=StepCostPlan(meshes_m=(0.004, 0.002, 0.001), modes=(6, 12, 24), step_s=1e-5,
                           end_time_s=0.003, newton={  # issue 15: at most 2 iterations?
                               "modified 1e-8 (flex)": ("modified", 1e-8),
                               "full 1e-8": ("full", 1e-8), "full 1e-6": ("full", 1e-6),
                               "Jacobian per step 1e-5": ("jacobian_per_step", 1e-5)}),
    # issue 15's plates: at 1 % within 0.3 s, at 0.1 % within 2 s (in process, warm)
    plates=PlatesPlan({f"steel_{mm:g}mm": [f"coupler.thickness_m={mm / 1000!r}"]
                       for mm in (2, 3, 5, 10)} | {"aluminium_2mm": [
                           "coupler.thickness_m=0.002", "coupler.youngs_modulus_Pa=70e9",
                           "coupler.density_kg_per_m3=2700.0", "coupler.poisson_ratio=0.33"]},
                      tolerances=(0.01, 0.001), targets_s={0.01: 0.3, 0.001: 2.0}),
    # issue 49: the thesis plates at 1 %, flex's own settings; the 1 mm plate's command line
    budget=BudgetPlan({f"{mm:g}mm": ['coupler.geometry="plate"', 'coupler.model="ffrf"',
                                     f"coupler.thickness_m={mm / 1000!r}",
                                     "simulation.end_time_s=0.03"]
                       for mm in (0.7, 1, 2, 3)}, 0.01, "1mm"),
)


def cases(scene: Scene) -> dict[str, Scene]:
    return derived_scenes(scene, {"rigid": [], "ffrf_1mm": PLATE})


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Run the six parts in order; each part's failure is stored, the others still run."""
    return run_bench(scenes, PLAN, REPEATS, run.progress, run.notes, cache_dir=run.cache_dir,
                     make_all=run.environment.get("FLEX_BENCH_MAKE", "1") != "0",
                     nonlinear=run.environment.get("FLEX_BENCH_NONLINEAR", "1") != "0")


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    """The table and the per-part datasets
    (:func:`flex.experiments.workprecision.benchmark_report.bench_summary`)."""
    datasets, report, findings = bench_summary(run.notes, PLAN)
    return Summary(datasets, report, findings=findings)


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    """Bar charts: integration times at equal accuracy (log scale) and the Exudyn CPU shares
    of the untuned and tuned runs."""
    return bench_figures(summary.datasets, folder, PLAN.ffrf_target_s)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
