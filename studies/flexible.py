"""Study ``flexible`` (thesis sec. 6.2, figs. 35-50): coupler plates of four thicknesses.

The coupler becomes a steel plate 0.08 x 0.01 x t (Table 5, models 0-3: t = 1, 3, 5, 10 mm)
modelled in the same mechanism as flex's default flexible body (``<model>_ffrf``: FFRF on the chord
frame with the geometric stiffness of its axial force), as the linear FFRF body
(``<model>_linear``) and as its rigid twin (``<model>_rigid``: the plate's own mass and inertia),
each against the stored converged reference of its physics (``flex/data/references.h5``, ``make
references``: the calibrated exact beam, over the whole deployment, with its own accuracy;
:mod:`flex.experiments.thesis.flexible`). The spring deployment is the thesis scene (22 mm preload
reading, undamped). Until issue 50 the reference was the fully nonlinear FE coupler on the same
mesh, run over the first 2.5-5 ms (most of the study's time); it is ``make ladder``'s now.

Stored per case: the rigid-body quantities, ``coupler/midpoint_deflection`` (elastic,
relative to the chord B-C), ``coupler/chord_change``, ``coupler/midpoint_acceleration``,
``coupler/modal_coordinates``, ``coupler/peak_bending_stress``; the default FFRF and rigid
runs their error budgets (``estimated_error_*``). Per plate under ``/summary/models/<model>``:
the reduction's frequencies, mesh statistics, the FFRF run's deviations from its rigid
twin, its peaks with their estimated errors, and n = delta_t / T in both period
conventions; under ``/summary/reference/<model>``: each model's deployment peak, first crest,
peak bending stress, joint C force and deployment time against the stored values (relative
errors, resolved or not by the reference's accuracy), its curves' largest differences over the
whole run, the FFRF error on the motion over the elasticity's effect, the compression over the
Euler load.
"""

from __future__ import annotations

from pathlib import Path

from flex.base.thesis import THESIS_DELTA_T_S
from flex.config.settings import pinned_overrides
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.thesis.flexible import (
    simulate_twins,
    summarize_twins,
    twin_cases,
    twin_figures,
)
from flex.study import StudyRun, Summary

NAME = "flexible"
DESCRIPTION = ("coupler plates t = 1, 3, 5, 10 mm as FFRF (flex's default), linear FFRF and "
               "rigid twins against their stored converged references")
# the solver entry of flexible links: the rigid entry's 1e-5 s grid with modified Newton (on
# the 1 mm plate every headline equal to full Newton's within 3e-7, in half the time)
OVERRIDES = pinned_overrides("flexible_fallback") + ['coupler.geometry="plate"']
# keys the study reads itself (its plates and their rigid twins), beside its cases (not the
# thickness: each plate has its own, MODELS)
READS = ("coupler.length_m", "coupler.width_m",
         "coupler.youngs_modulus_Pa", "coupler.density_kg_per_m3",
         "coupler.poisson_ratio", "coupler.damping_ratio")

# Table 5 models: thickness [m] and the netgen mesh size used for each (about the thickness,
# at most 2t; quadratic tetrahedra converge within 0.1 % there, see the modal study)
MODELS = {"model0_t1mm": (0.001, 0.002), "model1_t3mm": (0.003, 0.003),
          "model2_t5mm": (0.005, 0.005), "model3_t10mm": (0.010, 0.005)}
THESIS_DEPLOYMENT_TIME_S = THESIS_DELTA_T_S  # thesis sec. 6.2, Table 5 note


def cases(scene: Scene) -> dict[str, Scene]:
    return twin_cases(scene, MODELS)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Simulate every case, in parallel on local processes; each model's reduction is built
    (or loaded) once."""
    from contextlib import closing

    from flex.sweep import make_executor

    with closing(make_executor()) as executor:
        return simulate_twins(scenes, run.progress, run.notes, cache_dir=run.cache_dir,
                              executor=executor)


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    from flex.data.reference_store import bundled_store, read_store

    return Summary(*summarize_twins(scene, results, run.notes, MODELS,
                                    THESIS_DEPLOYMENT_TIME_S, read_store(bundled_store())))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return twin_figures(results, summary.datasets, folder, list(MODELS))

if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
