"""Study ``estimates``: is the error estimate every run stores honest?

Each scene runs as a user would run it (its own, "auto", step; the estimate on: a companion
run at twice the step, :mod:`flex.fidelity.error_estimate`) and against two references of
the same model at 4 and 8 times smaller steps (:mod:`flex.experiments.estimate_check`).
Stored per case: the run, its ``estimated_error_*``, ``true_error_*``,
``reference_accuracy_*`` and ``estimate_ratio_*`` attributes; under ``/summary/pairs`` one
entry per case and headline quantity. Target (issue 15): estimated / true within 3x, never
optimistic by more than 1.5x, on at least 10 scenes. The step estimate covers the step only:
every scene's reference keeps its modes and mesh.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from flex.data.results import CaseResult
from flex.data.scene import Scene, derived_scenes
from flex.experiments.estimate_check import check_estimates, draw_estimates, estimate_summary
from flex.study import StudyRun, Summary

NAME = "estimates"
DESCRIPTION = "the stored error estimates against true step errors on 13 scenes"

PLATE = ['coupler.geometry="plate"', 'coupler.model="ffrf"']
STEEL = [f"coupler.thickness_m={t}" for t in ("0.001", "0.002", "0.003", "0.005", "0.01")]
SCENES: dict[str, list[str]] = {
    "rigid": [],
    "rigid_preload_11mm": ["drive.spring_preload_m=0.011"],
    "rigid_spring_5000": ["drive.spring_stiffness_N_per_m=5000.0"],
    "rigid_h1e-4": ["simulation.step_s=1e-4"],
    "rigid_constant_speed": ['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=60.0"],
    "ffrf_1mm": PLATE + [STEEL[0]],
    "ffrf_1mm_h1e-5": PLATE + [STEEL[0], "simulation.step_s=1e-5"],
    "ffrf_2mm": PLATE + [STEEL[1], "coupler.mesh_size_m=0.003"],
    "ffrf_3mm": PLATE + [STEEL[2], "coupler.mesh_size_m=0.003"],
    "ffrf_5mm": PLATE + [STEEL[3], "coupler.mesh_size_m=0.005"],
    "ffrf_10mm": PLATE + [STEEL[4], "coupler.mesh_size_m=0.005"],
    "ffrf_aluminium_2mm": PLATE + [STEEL[1], "coupler.mesh_size_m=0.003",
                                   "coupler.youngs_modulus_Pa=70e9",
                                   "coupler.density_kg_per_m3=2700.0",
                                   "coupler.poisson_ratio=0.33"],
    "ffrf_crank": ['crank.geometry="plate"', 'crank.model="ffrf"'],
}


def cases(scene: Scene) -> dict[str, Scene]:
    return derived_scenes(scene, SCENES)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    return check_estimates(scenes, run.cache_dir, run.progress)


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    return Summary(*estimate_summary(results))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return draw_estimates(summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
