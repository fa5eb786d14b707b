"""Study ``calibrate``: the FFRF settings rule fitted on a family of scenes, validated on others.

Per scene (FFRF coupler, rigid crank, thesis deployment) a converged reference and a grid of
in-plane modes x steps per first period (:mod:`flex.experiments.fitting.calibration`); the rule
(:mod:`flex.config.ffrf_rule`) is fitted per damping class and level on ``CALIBRATION`` and
validated on ``VALIDATION`` (the scenes: ``calibrate.toml`` beside this file). Some scenes
carry 1 % damping: an undamped thick plate's peak is the highest of many crests, which no
affordable reference pins to 1 %. Stored: a case per scene, ``/summary/rule/toml`` (``make
calibration-install``), ``levels/*``, ``validation/*``, ``cross_validation/*`` and
``design_frontier/*`` (rule designs compared, :mod:`flex.experiments.fitting.rule_designs`).
"""

from __future__ import annotations

import tomllib
from functools import partial
from pathlib import Path

from flex.config.ffrf_rule import rule_constants
from flex.data.results import CaseResult
from flex.data.scene import Scene, derived_scenes
from flex.experiments.fitting.calibration import measure_case
from flex.experiments.fitting.calibration_report import calibration_summary, draw_calibration
from flex.study import RESULTS_DIR, StudyRun, Summary

NAME = "calibrate"
DESCRIPTION = "the FFRF settings rule: fitted on 38 scenes, validated on 16 others, 2 beyond"
# every grid setting and reference sets its own step, modes and mesh; the numbers below only
# make the cases' scenes concrete
# (no "auto" left: the cases' identity is then the scene and the bound mesh constants, so a
# refitted rule installed later does not make them stale)
OVERRIDES = ['coupler.geometry="plate"', 'coupler.model="ffrf"',
             "simulation.error_estimate=false", "coupler.modes=6", "coupler.mesh_size_m=0.002",
             "simulation.step_s=1e-5", "simulation.spectral_radius=0.9",
             'simulation.newton="modified"', "simulation.newton_relative_tolerance=1e-8"]
REPEATS = 2
SWEEP = True  # resumable cases (flex run calibrate --folder, --retry-failed)

#: the scenes, as --set overrides per name (studies/calibrate.toml: what each set is for)
SCENES = tomllib.loads(Path(__file__).with_suffix(".toml").read_text("utf-8"))
CALIBRATION: dict[str, list[str]] = SCENES["calibration"]
VALIDATION: dict[str, list[str]] = SCENES["validation"]
BEYOND: dict[str, list[str]] = SCENES["beyond"]


def cases(scene: Scene) -> dict[str, Scene]:
    return derived_scenes(scene, CALIBRATION | VALIDATION | BEYOND)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """One case per scene on the sweep engine (resumable; ``results/calibrate-cases``), one
    worker unless told otherwise: the grid's timings are what it measures."""
    from contextlib import closing

    from flex.sweep import SweepSettings, make_executor, run_sweep

    settings = run.sweep or SweepSettings()
    with closing(make_executor(settings.scheduler, settings.workers or 1)) as executor:
        outcome = run_sweep(scenes, settings.folder or RESULTS_DIR / "calibrate-cases",
                            partial(measure_case, repeats=REPEATS, cache_dir=run.cache_dir,
                                    mesh_rule=dict(rule_constants()["mesh"])),
                            executor=executor, retry_failed=settings.retry_failed,
                            progress=settings.progress, study=NAME)
    run.notes.setdefault("sweep", {})["wall_time_s"] = outcome.wall_time_s
    return outcome.results


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    all_scenes = cases(scene)
    return Summary(*calibration_summary(
        results, {name: all_scenes[name] for name in CALIBRATION},
        {name: all_scenes[name] for name in VALIDATION | BEYOND}))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return draw_calibration(results, summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
