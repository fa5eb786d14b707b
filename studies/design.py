"""Study ``design``: design charts, and the thesis's optimum initial angle (sec. 5.4.5) settled.

The thesis starts every deployment at theta1 = 34.19 deg, "the maximum value of angular
velocity" according to a design-charts study it cites. This study sweeps the initial crank
angle, the spring preload and rate, and the coupler thickness around the design point (the
base scene: the thesis's angle, spring and the steel plate of Table 1's coupler mass), each
case with ``coupler.model = "auto"`` at the stated tolerance (0.1 % here, so that the thin
couplers of the thickness map go flexible), on the sweep engine (resumable, Dask-ready). It
stores each case's scene, curves and measures, the lines through the design point under
each constraint, the mechanism checks, and a few cases against the reference DAE.
Families, measures and the lines: :mod:`flex.experiments.design.cases`; figures and report:
:mod:`flex.experiments.design.report`; ``flex design`` answers a question about one scene
(:mod:`flex.experiments.design.question`). docs/design.md.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.design.cases import (
    BASE_OVERRIDES,
    Grid,
    design_case,
    plan,
    reference_names,
    run_references,
)
from flex.experiments.design.summary import summary_datasets
from flex.study import RESULTS_DIR, StudyRun, Summary

SWEEP = True  # cases run on the sweep engine: --scheduler and --workers apply
NAME = "design"
DESCRIPTION = "design charts over angle, spring and coupler; the thesis's optimum angle"
# the coupler as the plate of Table 1's mass, auto at 0.1 % (BASE_OVERRIDES)
OVERRIDES = BASE_OVERRIDES + ["fidelity.tolerance=0.001"]
# the design point and the tolerance: the study's grid is built around them
READS = ("crank.initial_angle_deg", "drive.spring_preload_m",
         "drive.spring_stiffness_N_per_m", "coupler.thickness_m", "coupler.mesh_size_m",
         "simulation.end_time_s", "fidelity.tolerance")

GRID = Grid(
    angles_deg=tuple(float(a) for a in np.arange(5.0, 85.1, 2.5)),
    preload_factors=(0.5, 0.75, 1.0, 1.25, 1.5),
    energy_rate_factors=(0.5, 0.75, 1.5, 2.0, 3.0, 4.0),
    thicknesses_m=(0.6e-3, 0.8e-3, 1e-3, 1.5e-3, 2e-3, 3e-3, 5e-3, 8e-3),
    thickness_rate_factors=(0.5, 1.0, 2.0, 4.0, 8.0),
    final_angle_step_deg=2.5)
#: cases held against the reference DAE beside the design point (initial angles [deg])
REFERENCE_ANGLES_DEG = (5.0, 60.0)


def cases(scene: Scene) -> dict[str, Scene]:
    return plan(scene, GRID)[0]


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Every case on the sweep engine (``run.sweep``; default: a process pool on all cores,
    case files in ``results/design-cases``), then the reference DAE checks."""
    from flex.sweep import SweepSettings, run_sweep

    settings = run.sweep or SweepSettings()
    outcome = run_sweep(scenes, settings.folder or RESULTS_DIR / "design-cases",
                        functools.partial(design_case, cache_dir=run.cache_dir),
                        scheduler=settings.scheduler, workers=settings.workers,
                        retry_failed=settings.retry_failed, progress=settings.progress,
                        study=NAME)
    run.notes["sweep"] = {"executor": outcome.executor, "ran": outcome.ran,
                          "resumed": outcome.resumed, "wall_time_s": outcome.wall_time_s}
    return outcome.results


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    from flex.experiments.design.report import report_text

    names = reference_names(scene, GRID, REFERENCE_ANGLES_DEG)
    datasets = summary_datasets(scene, GRID, results, run_references(results, names))
    return Summary(datasets, report_text(datasets, run.notes.get("sweep")))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    from flex.experiments.design.report import draw_figures

    return draw_figures(summary.datasets, folder)
