"""Study ``spring`` (thesis sec. 6.1): the deployment spring checked as a designer would.

The thesis's spring data are not self-consistent (1500 N/m from d = 4.4 mm, N = 3 needs a
mean coil diameter near 94 mm, not the stated 150 mm). The study shows which single input
reproduces 1500 N/m, carries on with the stated consistent design
(:data:`flex.bodies.spring.CONSISTENT_THESIS_SPRING`), and checks it: Wahl- and
Bergstrasser-corrected shear stress at the 22 mm press and at solid against ASTM A228's
allowable stress; solid length and clash allowance; surge frequency and the thesis's
rigid-or-flexible ratio n for the spring itself; an NGsolve model of a helix segment for
the peak stress, compared with Wahl (:mod:`flex.experiments.thesis.spring`). No mechanism is
simulated.
"""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.thesis import spring
from flex.study import StudyRun, Summary

NAME = "spring"
DESCRIPTION = "helical spring: rate, stress (Wahl, FE), surge and the rigid criterion"
OVERRIDES: list[str] = []
# keys the study reads itself (the press and the surge check's end mass); not the rate: the
# study checks the thesis's consistent spring (CONSISTENT_THESIS_SPRING), 1500 N/m
READS = ("drive.spring_preload_m", "slider.mass_kg")


def cases(scene: Scene) -> dict[str, Scene]:
    return {}


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*spring.summary(scene))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return spring.draw_stress(summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
