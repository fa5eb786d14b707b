"""Study ``estimates``: is the error budget every run stores honest?

Each scene runs as a user would run it (its own, "auto", settings; the error budget on: step,
modes, mesh and model, :mod:`flex.fidelity.error_budget`) and against its reference, the next
rung of flex's ladder converged in step, modes and mesh
(:mod:`flex.experiments.workprecision.estimate_check`: an FFRF coupler against the nonlinear FE
coupler at a quarter of the step, mesh-corrected; rigid plate couplers, 0.7-3 mm over the whole
deployment, against the calibrated exact beam, the flexible truth their user gets; lumped rigid
links against the same rigid model at a quarter of the step). Stored per case: the run, its
``estimated_error_*``, ``true_error_*``, ``reference_accuracy_*`` and ``estimate_ratio_*``
attributes; under ``/summary/pairs`` one entry per case and headline quantity; the findings
and their tables (``/summary/findings``) and a figure per quantity
(:mod:`flex.experiments.workprecision.estimate_report`). Targets (issue
35): true / estimated within [1/2, 1.5] for every pair in the asymptotic range, at most 10 % of
the pairs flagged outside it, no certificate exceeded; on at least 12 scenes (thin and thick
plates, springs, a constant-speed drive, the crank as FFRF, damped). The flexible scenes run the
first 10 ms (the nonlinear FE reference's cost); the rigid ones the whole deployment (the
deployment time).
"""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult
from flex.data.scene import Scene, derived_scenes
from flex.experiments.workprecision.estimate_check import (
    check_estimates,
    draw_estimates,
    estimate_summary,
)
from flex.experiments.workprecision.estimate_report import draw_ratio_figures, estimate_findings
from flex.study import StudyRun, Summary

NAME = "estimates"
DESCRIPTION = "the stored error budgets against true errors on 18 scenes"

FLEXIBLE = ['coupler.geometry="plate"', 'coupler.model="ffrf"', "simulation.end_time_s=0.01"]
SCENES: dict[str, list[str]] = {
    "rigid": [],
    "rigid_preload_11mm": ["drive.spring_preload_m=0.011"],
    "rigid_spring_5000": ["drive.spring_stiffness_N_per_m=5000.0"],
    "rigid_constant_speed": ['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=60.0"],
    **{f"rigid_plate_{t}mm": ['coupler.geometry="plate"', f"coupler.thickness_m={t / 1000}"]
       for t in (0.7, 1, 2, 3)},
    "ffrf_1mm": FLEXIBLE + ["coupler.thickness_m=0.001"],
    "ffrf_1mm_spring_3000": FLEXIBLE + ["coupler.thickness_m=0.001",
                                        "drive.spring_stiffness_N_per_m=3000.0"],
    "ffrf_2mm": FLEXIBLE + ["coupler.thickness_m=0.002"],
    "ffrf_3mm": FLEXIBLE + ["coupler.thickness_m=0.003"],
    "ffrf_5mm": FLEXIBLE + ["coupler.thickness_m=0.005"],
    "ffrf_10mm": FLEXIBLE + ["coupler.thickness_m=0.01"],
    "ffrf_aluminium_2mm": FLEXIBLE + ["coupler.thickness_m=0.002",
                                      "coupler.youngs_modulus_Pa=70e9",
                                      "coupler.density_kg_per_m3=2700.0",
                                      "coupler.poisson_ratio=0.33"],
    "ffrf_3mm_constant_speed": FLEXIBLE + ["coupler.thickness_m=0.003",
                                           'drive.kind="constant_speed"',
                                           "drive.crank_speed_rad_per_s=60.0"],
    "ffrf_2mm_damped": FLEXIBLE + ["coupler.thickness_m=0.002", "coupler.damping_ratio=0.02"],
    "ffrf_crank": ['crank.geometry="plate"', 'crank.model="ffrf"',
                   "simulation.end_time_s=0.01"],
}


def cases(scene: Scene) -> dict[str, Scene]:
    return derived_scenes(scene, SCENES)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    from contextlib import closing

    from flex.sweep import make_executor

    with closing(make_executor()) as executor:
        return check_estimates(scenes, run.cache_dir, run.progress, executor)


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    datasets, report = estimate_summary(results)
    tables, findings = estimate_findings(results)
    return Summary(datasets | tables, report, findings=findings)


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return draw_estimates(summary.datasets, folder) + draw_ratio_figures(summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
