"""Study ``kinematics`` (thesis ch. 4, figures 4-7): crank driven at constant speed.

One crank turn per second for 1 s (sec. 4.3; the data sheet's check shows the reported
stroke, velocity and acceleration extremes belong to omega = 2 pi rad/s). Exudyn's slider
position, velocity and acceleration are compared with the closed-form in-line slider-crank;
the crank midpoint must trace a circle of radius L1/2; the constraint norm stays at round-off
(:mod:`flex.experiments.thesis.kinematics`).
"""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.thesis import kinematics
from flex.study import StudyRun, Summary

NAME = "kinematics"
DESCRIPTION = "constant-speed crank, one turn per second, against the closed form"
OVERRIDES = ['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=6.283185307179586",
             "crank.initial_angle_deg=0.0", "simulation.end_time_s=1.0",
             "simulation.step_s=1e-4", "simulation.output_step_s=1e-3"]


def cases(scene: Scene) -> dict[str, Scene]:
    return {"constant_speed": scene}


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*kinematics.summary(results["constant_speed"]))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return kinematics.draw_figures(results["constant_speed"], summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
