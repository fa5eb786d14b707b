"""Study ``simulate``: run exactly the scene it is given, as one case; nothing is compared.

    python -m flex run simulate --set crank.initial_angle_deg=50 --set drive.spring_preload_m=0.01

Every study follows this protocol (:mod:`flex.study`; copy this file to start one): ``NAME``,
``DESCRIPTION``, ``OVERRIDES`` declare it; ``cases(scene)`` names the scenes flex simulates
and stores (here ``/cases/case/...``); ``summarize`` returns the report and the datasets stored
under ``/summary``; ``figures`` draws PNGs. Each hook declares, or makes one call into the library
module of its concept (:mod:`flex.experiments.thesis.simulate`): no loops, fits or measurements
here.
"""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.thesis import simulate
from flex.study import STRUCTURAL_KEYS, StudyRun, Summary

NAME = "simulate"
DESCRIPTION = "one case: exactly the given scene"
HONOURS = STRUCTURAL_KEYS  # it runs whatever scene it is given


def cases(scene: Scene) -> dict[str, Scene]:
    return {"case": scene}


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*simulate.summary(results["case"]))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return simulate.draw_crank_angle(results["case"], folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
