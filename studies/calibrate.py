"""Study ``calibrate``: the FFRF settings rule fitted on a family of scenes, validated on others.

Per scene (FFRF coupler, rigid crank, thesis deployment) a grid of in-plane modes x steps per
first period measured against the stored reference of its physics (``make references``:
the calibrated exact beam, :mod:`flex.data.reference_store`) on the coupler's deployment peak
deflection, on the headline channel (:mod:`flex.experiments.fitting.calibration`). The rule
(:mod:`flex.config.ffrf_rule`) is refitted per level on ``CALIBRATION`` and validated on
``VALIDATION`` (the scenes: ``calibrate.toml`` beside this file), whose scenes are also asked
1 %, 0.3 % and 0.1 % as a user would, first guess and refined, with the installed rule
(:mod:`flex.experiments.workprecision.tolerance_check`). Every scene is undamped: the beam has
no damping model, and the damped levels are carried over from the installed rule. Stored: a
case per scene (its grid), ``/summary/rule/toml`` (``make calibration-install``),
``levels/*``, ``validation/*``, ``cross_validation/*``, ``design_frontier/*`` and the
findings table ``tolerances``.
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
from flex.experiments.workprecision.tolerance_check import (
    SEPARATOR,
    USER_KEYS,
    check_tolerances,
    tolerance_findings,
    tolerance_scenes,
)
from flex.study import RESULTS_DIR, StudyRun, Summary

NAME = "calibrate"
DESCRIPTION = ("the FFRF settings rule refitted on 17 undamped scenes against stored references, "
               "validated on 5 others, which are also asked 1 %, 0.3 % and 0.1 %")
# every grid setting and reference sets its own step, modes and mesh; the numbers below only
# make the cases' scenes concrete
# (no "auto" left: the cases' identity is then the scene and the bound mesh constants, so a
# refitted rule installed later does not make them stale)
OVERRIDES = ['coupler.geometry="plate"', 'coupler.model="ffrf"',
             "simulation.error_estimate=false", "coupler.modes=6", "coupler.mesh_size_m=0.002",
             "simulation.step_s=1e-5", "simulation.spectral_radius=0.9",
             'simulation.newton="modified"', "simulation.newton_relative_tolerance=1e-8"]
REPEATS = 1  # the fit compares laws by a time model over each grid (modelled_time_s)
SWEEP = True  # resumable cases (flex run calibrate --folder, --retry-failed)

#: the scenes, as --set overrides per name (studies/calibrate.toml: what each set is for)
SCENES = tomllib.loads(Path(__file__).with_suffix(".toml").read_text("utf-8"))
CALIBRATION: dict[str, list[str]] = SCENES["calibration"]
VALIDATION: dict[str, list[str]] = SCENES["validation"]


def cases(scene: Scene) -> dict[str, Scene]:
    asked = {name: [*overrides, *USER_KEYS] for name, overrides in VALIDATION.items()}
    return (derived_scenes(scene, CALIBRATION | VALIDATION)
            | tolerance_scenes(derived_scenes(scene, asked)))


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """The grids on the sweep engine (resumable; ``results/calibrate-cases``; a scene's grid
    runs in one worker, so its timings, which the fit compares, share one load), then the
    held-out scenes' tolerance runs (each against the store)."""
    from contextlib import closing

    from flex.data.reference_store import bundled_store, read_store, store_digest
    from flex.sweep import SweepSettings, make_executor, run_sweep

    store_file = bundled_store()
    store = read_store(store_file)
    grids = {name: s for name, s in scenes.items() if SEPARATOR not in name}
    asked = {name: s for name, s in scenes.items() if SEPARATOR in name}
    settings = run.sweep or SweepSettings()
    with closing(make_executor(settings.scheduler, settings.workers)) as executor:
        outcome = run_sweep(grids, settings.folder or RESULTS_DIR / "calibrate-cases",
                            partial(measure_case, reference_store=store_file,
                                    reference_store_digest=store_digest(store),
                                    repeats=REPEATS, cache_dir=run.cache_dir,
                                    mesh_rule=dict(rule_constants()["mesh"])),
                            executor=executor, retry_failed=settings.retry_failed,
                            progress=settings.progress, study=NAME)
        run.notes.setdefault("sweep", {})["wall_time_s"] = outcome.wall_time_s
        return outcome.results | check_tolerances(asked, store, run.cache_dir, run.progress,
                                                  executor)


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    all_scenes = cases(scene)
    grids = {name: case for name, case in results.items() if SEPARATOR not in name}
    datasets, report = calibration_summary(
        grids, {name: all_scenes[name] for name in CALIBRATION},
        {name: all_scenes[name] for name in VALIDATION})
    table, findings, asked_report = tolerance_findings(results)
    return Summary(datasets | table, report + "\n\n" + asked_report, findings=findings)


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    grids = {name: case for name, case in results.items() if SEPARATOR not in name}
    return draw_calibration(grids, summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
