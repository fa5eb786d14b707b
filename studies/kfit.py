"""Study ``kfit`` (thesis sec. 6.2, Eq. 64-65): fit the rigid-or-flexible threshold k.

Each case is one steel-plate coupler scene run twice with the same integrator settings: as
an FFRF body with geometric stiffness (``coupler.geometric_stiffness = true``; 3 static + 6
in-plane fixed-interface Craig-Bampton modes) and as its rigid twin (same mass and inertia).
The reference has geometric stiffness because the linear FFRF body's response to its axial
force has the wrong sign (docs/validation.md section 4, docs/geometric-stiffness.md). The
error measures of :mod:`flex.fidelity.criteria` compare the two over the deployment
(t <= delta_t_stop). Families of cases:

- ``thk_*``: coupler thickness 0.5-12 mm (20 log-spaced values plus Table 5's 1, 3, 5,
  10 mm), thesis spring (1500 N/m, 22 mm preload);
- ``stf_*``: spring stiffness 150-50000 N/m at t = 0.5, 1, 3 mm: the deployment time
  changes at fixed geometry, so n = delta_t / T varies independently of the geometry; and
  0.15-5 MN/m at t = 3, 5, 10 mm (preload lowered to keep the compression below 0.25 x
  the Euler load), which reaches n ~ 1 without buckling;
- ``pre_*``: preload 11, 16 and 33 mm at five thicknesses (the deployment time barely
  changes with the preload of a linear spring, the load amplitude does);
- every case undamped (``z0``) and with 2 % modal damping (``z2``); candidates whose
  estimated compression exceeds ``EULER_LOAD_LIMIT`` (0.25) x the Euler load are not
  generated (``auto`` refuses such scenes, and the reference failed Newton there: the 0.5 mm
  plate at the thesis spring, 0.5 and 1 mm at the stiffer springs); the report names them;
- ``val_*``: scenes not in the fit (other thicknesses, stiffnesses, link lengths) with
  ``coupler.model = "auto"``, each against a full FFRF run (12 modes, geometric
  stiffness), using the law just fitted.

Mesh, time step and end time per case: :func:`flex.experiments.fitting.kfit.tuned`. The
pipeline (fit cases, laws, criterion, validation) is :mod:`flex.experiments.fitting.lawfit`'s,
with the coupler's cases from :mod:`flex.experiments.fitting.kfit`, its fit and summary from
:mod:`flex.experiments.fitting.kfit_law` and its figures from
:mod:`flex.experiments.fitting.lawplots`.

Every case's file is ``<sweep folder>/cases/<case>.h5`` (default ``results/kfit-cases``);
the sweep resumes from them. The fit (``results/kfit-criterion.toml``) is what
``make calibration-install`` copies to ``flex/config/criteria_fit.toml`` for ``auto``. Executor:
``flex run kfit --scheduler ... --folder DIR --retry-failed`` (see :mod:`flex.sweep`).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from flex.config.settings import pinned_overrides
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.fitting import kfit, kfit_law, lawfit
from flex.experiments.fitting.kfit import THESIS_MODELS
from flex.study import RESULTS_DIR, StudyRun, Summary

SWEEP = True  # cases run on the sweep engine: --scheduler and --workers apply
NAME = "kfit"
DESCRIPTION = "fit the rigid-or-flexible threshold k from FFRF-vs-rigid sweeps"
# the solver entry of flexible links: the rigid entry's 1e-5 s grid with modified Newton (on
# the 1 mm plate every headline equal to full Newton's within 3e-7, in half the time)
OVERRIDES = pinned_overrides("flexible_fallback") + [
    "simulation.error_estimate=false",  # own references
    'coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.modes=6",
    "simulation.output_step_s=0.0"]
# keys the study reads itself (its fit grid and criterion), beside its cases
READS = ("coupler.length_m", "coupler.thickness_m", "coupler.width_m",
         "coupler.youngs_modulus_Pa", "coupler.density_kg_per_m3",
         "coupler.poisson_ratio", "coupler.damping_ratio", "coupler.mesh_size_m",
         "coupler.modes", "drive.spring_stiffness_N_per_m", "drive.spring_preload_m",
         "fidelity.tolerance")

THICKNESSES_M = tuple(sorted({round(float(t), 6) for t in np.geomspace(0.5e-3, 12e-3, 20)}
                             | set(THESIS_MODELS.values())))
STIFFNESS_THICKNESSES_M = (0.5e-3, 1e-3, 3e-3)
STIFFNESSES_N_PER_M = (150.0, 500.0, 5000.0, 15000.0, 50000.0)
#: fast deployments of thicker plates: (thickness, spring rate); preload from
#: flex.experiments.fitting.kfit.FAST_EULER_RATIO
FAST_CASES = ((3e-3, 1.5e5), (3e-3, 5e5), (5e-3, 5e5), (5e-3, 1.5e6), (10e-3, 5e6))
PRELOAD_THICKNESSES_M = (0.826e-3, 1e-3, 1.91e-3, 3e-3, 5.2e-3)
PRELOADS_M = (0.011, 0.016, 0.033)
DAMPING_RATIOS = (0.0, 0.02)

#: validation scenes (not in the fit): name -> (overrides, tolerance)
VALIDATION: dict[str, tuple[list[str], float]] = {
    "val_t0p7mm_tol1pct": (["coupler.thickness_m=0.0007"], 0.01),
    "val_t2p2mm_tol1pct": (["coupler.thickness_m=0.0022"], 0.01),
    "val_t2p2mm_tol0p1pct": (["coupler.thickness_m=0.0022"], 0.001),
    "val_t7mm_tol0p1pct": (["coupler.thickness_m=0.007"], 0.001),
    "val_t1p5mm_k20000_tol1pct": (["coupler.thickness_m=0.0015",
                                   "drive.spring_stiffness_N_per_m=20000.0"], 0.01),
    "val_t4mm_k800_tol0p1pct": (["coupler.thickness_m=0.004",
                                 "drive.spring_stiffness_N_per_m=800.0"], 0.001),
    "val_L100_t1p5mm_tol1pct": (["coupler.length_m=0.1", "coupler.thickness_m=0.0015"], 0.01),
    "val_L60_t0p8mm_tol0p1pct": (["coupler.length_m=0.06", "coupler.thickness_m=0.0008"],
                                 0.001),
    "val_t2p5mm_z2_tol0p1pct": (["coupler.thickness_m=0.0025", "coupler.damping_ratio=0.02"],
                                0.001),
}


def _grid() -> tuple:
    """The fit grid, as :func:`flex.experiments.fitting.kfit.fit_cases` takes it."""
    return (DAMPING_RATIOS, THICKNESSES_M, (STIFFNESS_THICKNESSES_M, STIFFNESSES_N_PER_M),
            FAST_CASES, (PRELOAD_THICKNESSES_M, PRELOADS_M))


def cases(scene: Scene) -> dict[str, Scene]:
    """Fit cases, then validation cases (run after the fit, see :func:`simulate_cases`)."""
    fit = kfit.fit_cases(scene, *_grid())
    return {**fit, **kfit.validation_cases(scene, VALIDATION)}


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """The :mod:`flex.experiments.fitting.lawfit` pipeline on the sweep engine (``run.sweep``:
    where and how; None: a process pool on all cores, ``results/kfit-cases``); the criterion
    goes beside the case folder (``kfit-criterion.toml``)."""
    from contextlib import closing

    from flex.sweep import SweepSettings, make_executor, run_sweep

    settings = run.sweep or SweepSettings()
    folder = settings.folder or RESULTS_DIR / "kfit-cases"
    with closing(make_executor(settings.scheduler, settings.workers)) as executor:
        runner = lawfit.SweepRunner(run_sweep, executor, folder,
                                    kfit.sweep_phases(run.cache_dir), NAME,
                                    run.notes.setdefault("sweep", {}), settings.retry_failed,
                                    settings.progress)
        results, run.notes["analysis"] = kfit_law.fit_then_validate(scenes, runner, folder)
    return results


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*kfit_law.summarize(results, run.notes,
                                       kfit.left_out_cases(scene, *_grid())))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    from flex.experiments.fitting.lawplots import coupler_figures

    return coupler_figures(summary.figure_data.get("analysis") or kfit_law.analyse(results),
                           folder)


if __name__ == "__main__":
    from flex.cli import main

    sys.exit(main(["run", NAME]))
