"""Study ``calibrate``: the FFRF settings rule fitted on a family of scenes, validated on others.

Per scene (FFRF coupler, rigid crank, thesis deployment) a converged reference and a grid of
in-plane modes x steps per first period (:mod:`flex.experiments.calibration`); the rule
(:mod:`flex.config.ffrf_rule`) is fitted per damping class and level on ``CALIBRATION`` and
validated on ``VALIDATION``. Some scenes carry 1 % damping: an undamped thick plate's peak is
the highest of many crests, which no affordable reference pins to 1 %. Stored: a case per
scene, ``/summary/rule/toml`` (``make rule-install``), ``levels/*``, ``validation/*``.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Any

from flex.data.results import CaseResult
from flex.data.scene import Scene, derived_scenes
from flex.experiments.calibration import measure_case
from flex.experiments.calibration_report import calibration_summary, draw_calibration
from flex.study import RESULTS_DIR, StudyRun, Summary

NAME = "calibrate"
DESCRIPTION = "the FFRF settings rule: fitted on 10 scenes, validated on 10 others (2 beyond)"
# every grid setting and reference sets its own step, modes and mesh; the numbers below only
# make the cases' scenes concrete
OVERRIDES = ['coupler.geometry="plate"', 'coupler.model="ffrf"',
             "simulation.error_estimate=false", "coupler.modes=6", "coupler.mesh_size_m=0.002"]
REPEATS = 2
SWEEP = True  # resumable cases (flex run calibrate --folder, --retry-failed)

AL = ["coupler.youngs_modulus_Pa=70e9", "coupler.density_kg_per_m3=2700.0",
      "coupler.poisson_ratio=0.33"]
TI = ["coupler.youngs_modulus_Pa=114e9", "coupler.density_kg_per_m3=4430.0",
      "coupler.poisson_ratio=0.34"]
DAMPED = ["coupler.damping_ratio=0.01"]


def t(mm: float) -> list[str]:
    return [f"coupler.thickness_m={mm / 1000!r}"]


CALIBRATION: dict[str, list[str]] = {
    "steel_1mm": t(1), "steel_2mm": t(2), "steel_10mm": t(10),
    "steel_0.5mm_damped_preload_11mm": t(0.5) + DAMPED + ["drive.spring_preload_m=0.011"],
    "steel_5mm_damped": t(5) + DAMPED, "steel_10mm_damped": t(10) + DAMPED,
    "aluminium_3mm": t(3) + AL,
    "titanium_1.5mm": t(1.5) + TI,
    "steel_1mm_spring_5000": t(1) + ["drive.spring_stiffness_N_per_m=5000.0"],
    "steel_2mm_speed_60": t(2) + ['drive.kind="constant_speed"',
                                  "drive.crank_speed_rad_per_s=60.0"],
}
#: the 20 and 15 mm plates (L / t = 4, 5.3) are measured and shown beyond the calibrated family
#: (L / t >= 8): the 20 mm one's shear- and axial-crowded spectrum needs 8 modes at T1 / 64
VALIDATION: dict[str, list[str]] = {
    "steel_20mm_damped": t(20) + DAMPED,
    "steel_0.7mm_damped": t(0.7) + DAMPED, "steel_1.5mm": t(1.5), "steel_3mm": t(3),
    "steel_7mm_damped": t(7) + DAMPED, "steel_15mm_damped": t(15) + DAMPED,
    "aluminium_1mm": t(1) + AL, "aluminium_8mm_damped": t(8) + AL + DAMPED,
    "titanium_4mm": t(4) + TI, "steel_2mm_preload_11mm": t(2) + ["drive.spring_preload_m=0.011"],
    "steel_3mm_spring_3000": t(3) + ["drive.spring_stiffness_N_per_m=3000.0"],
    "steel_5mm_damped_speed_40": t(5) + DAMPED + ['drive.kind="constant_speed"',
                                                  "drive.crank_speed_rad_per_s=40.0"],
}


def cases(scene: Scene) -> dict[str, Scene]:
    return derived_scenes(scene, CALIBRATION | VALIDATION)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """One case per scene on the sweep engine (resumable; ``results/calibrate-cases``), one
    worker unless told otherwise: the grid's timings are what it measures."""
    from flex.sweep import SweepSettings, make_executor, run_sweep

    settings = run.sweep or SweepSettings()
    outcome = run_sweep(scenes, settings.folder or RESULTS_DIR / "calibrate-cases",
                        partial(measure_case, repeats=REPEATS, cache_dir=run.cache_dir),
                        executor=make_executor(settings.scheduler, settings.workers or 1),
                        retry_failed=settings.retry_failed, progress=settings.progress,
                        study=NAME)
    run.notes.setdefault("sweep", {})["wall_time_s"] = outcome.wall_time_s
    return outcome.results


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    all_scenes = cases(scene)
    return Summary(*calibration_summary(
        results, {name: all_scenes[name] for name in CALIBRATION},
        {name: all_scenes[name] for name in VALIDATION}))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return draw_calibration(results, summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
