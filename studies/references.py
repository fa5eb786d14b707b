"""Study ``references``: the truths flex's error estimates are judged against, made once.

Each physics of ``references.toml`` (beside this file: the thesis mechanism with lumped or
plate links, other springs, preloads, materials and a constant-speed drive) is converged
once on the top rung that has its physics, the calibrated exact beam for a plate link
(:mod:`flex.experiments.workprecision.stored_references`: 256 elements, 64 for a stocky
plate, at 1.25e-6 s; one coarser level of each knob and the beam's measured idealization as
its accuracy). Stored per case: the headline series every 1e-5 s and ``reference_value_*`` /
``reference_accuracy_*``. ``make references-install`` writes them to
``flex/data/references.h5`` (committed), which ``make estimates`` reads. Long: ~2 min per
plate on one core (~4 GB per worker). """

from __future__ import annotations

import tomllib
from functools import partial
from pathlib import Path

from flex.data.reference_store import distinct_physics
from flex.data.results import CaseResult
from flex.data.scene import Scene, derived_scenes
from flex.experiments.workprecision.stored_references import make_reference, reference_table
from flex.study import RESULTS_DIR, StudyRun, Summary

NAME = "references"
DESCRIPTION = "converged references (calibrated exact beam), stored once for make estimates"
SWEEP = True  # resumable cases (flex run references --folder, --retry-failed)
PHYSICS: dict[str, list[str]] = tomllib.loads(
    Path(__file__).with_suffix(".toml").read_text("utf-8"))["physics"]
#: the calibrate study's scenes (calibrate.toml beside this file): its grids are measured
#: against these references; one per physics (a scene equal to one above is not made twice)
CALIBRATE_SCENES = tomllib.loads((Path(__file__).parent / "calibrate.toml").read_text("utf-8"))
CALIBRATE_PHYSICS = {name: ['coupler.geometry="plate"', *overrides]
                     for section in ("calibration", "validation")
                     for name, overrides in CALIBRATE_SCENES[section].items()}


def cases(scene: Scene) -> dict[str, Scene]:
    return distinct_physics(derived_scenes(scene, PHYSICS | CALIBRATE_PHYSICS))


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    from contextlib import closing

    from flex.sweep import SweepSettings, make_executor, run_sweep

    settings = run.sweep or SweepSettings()
    with closing(make_executor(settings.scheduler, settings.workers)) as executor:
        return run_sweep(scenes, settings.folder or RESULTS_DIR / "references-cases",
                         partial(make_reference, cache_dir=run.cache_dir), executor=executor,
                         retry_failed=settings.retry_failed, progress=settings.progress,
                         study=NAME).results


def summarize(scene: Scene, results: dict[str, CaseResult], run: StudyRun) -> Summary:
    tables, findings = reference_table(results)
    return Summary(tables, findings, findings=findings)


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return []


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
