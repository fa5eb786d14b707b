"""Study ``spring_mass`` (issue 16): the deployment spring with its mass.

``make spring`` finds the thesis spring's surge at n = delta_t / T = 0.96: by flex's own
criterion the spring is the mechanism's flexible part, yet the mechanism models treat it as
massless. ``drive.spring_model = "chain"`` lumps the coil's mass along it
(:class:`flex.dynamics.builder.SpringChain`). The study measures the chain's convergence to
the continuous coil (``beta tan beta = m_s / M``) and what the mass changes in the thesis
deployment (bundled scene, 22 mm preload) and the wing deployment (the wing study's fitted
spring, its coil re-sized from the thesis design): massless against chains of 1-16
segments, rigid links and an FFRF plate coupler (:mod:`flex.experiments.models.spring_mass`).
"""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.models import spring_mass
from flex.study import StudyRun, Summary

NAME = "spring_mass"
DESCRIPTION = "the deployment spring with its mass: chain convergence, deployment changes"
OVERRIDES: list[str] = []
# keys the study reads itself (the chain's frequencies; the wing spring's mass)
READS = ("drive.spring_mass_kg", "drive.spring_segments", "drive.spring_model")


def _scenes(scene: Scene) -> dict[str, Scene]:
    return {"thesis": scene, "wing": spring_mass.wing_spring_scene(scene)}


def cases(scene: Scene) -> dict[str, Scene]:
    return {**spring_mass.deployment_cases(_scenes(scene)), **spring_mass.sweep_cases(scene)}


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*spring_mass.summary(_scenes(scene), results))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return spring_mass.draw_speed(results, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
