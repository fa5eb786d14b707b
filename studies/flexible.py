"""Study ``flexible`` (thesis sec. 6.2, figs. 35-50): FFRF couplers of four thicknesses.

The coupler becomes a steel plate 0.08 x 0.01 x t (Table 5, models 0-3: t = 1, 3, 5, 10 mm)
modelled twice in the same mechanism: as a floating-frame-of-reference body (NGsolve mesh,
Hurty-Craig-Bampton reduction with the joint faces as interfaces) and as its rigid twin, a
rigid body with the plate's own mass and inertia, so the pair differs only by elasticity
(:mod:`flex.experiments.twins`). The spring deployment is the thesis scene (22 mm preload reading,
undamped).

Stored per case: the rigid-body quantities, ``coupler/midpoint_deflection`` (elastic,
relative to the chord B-C), ``coupler/chord_change``, ``coupler/midpoint_acceleration``,
``coupler/modal_coordinates``, ``coupler/peak_bending_stress``; per model under
``/summary/models/<model>``: the reduction's frequencies, mesh statistics and the
deviations of the FFRF run from its rigid twin, and n = delta_t / T in both period
conventions (thesis: T = 1/omega; physical: T = 2 pi / omega).

Accuracy reference: the thinnest model also runs with the fully nonlinear FE coupler
(:mod:`flex.bodies.nonlinear`: the same mesh, Green-Lagrange strain, no reduction) over
``NONLINEAR_END_TIME_S`` (default: the whole deployment); ``/summary/nonlinear_reference/
<model>`` holds its first and largest deflection peaks against the FFRF run's over the same
span, the largest difference of the two curves, the axial load of the link against its
Euler load (the geometric softening the linear FFRF body leaves out) and both wall times
(:mod:`flex.fidelity.softening`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from flex.base.thesis import THESIS_DELTA_T_S
from flex.config.settings import pinned_overrides
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.twins import simulate_twins, summarize_twins, twin_cases, twin_figures
from flex.study import StudyRun, Summary

NAME = "flexible"
DESCRIPTION = ("FFRF coupler plates t = 1, 3, 5, 10 mm against their rigid twins; nonlinear FE "
               "reference for t = 1 mm")
OVERRIDES = pinned_overrides() + ['coupler.geometry="plate"']
# keys the study reads itself (its plates and their rigid twins), beside its cases
READS = ("coupler.length_m", "coupler.thickness_m", "coupler.width_m",
         "coupler.youngs_modulus_Pa", "coupler.density_kg_per_m3",
         "coupler.poisson_ratio", "coupler.damping_ratio")

# Table 5 models: thickness [m] and the netgen mesh size used for each (about the thickness,
# at most 2t; quadratic tetrahedra converge within 0.1 % there, see the modal study)
MODELS = {"model0_t1mm": (0.001, 0.002), "model1_t3mm": (0.003, 0.003),
          "model2_t5mm": (0.005, 0.005), "model3_t10mm": (0.010, 0.005)}
THESIS_DEPLOYMENT_TIME_S = THESIS_DELTA_T_S  # thesis sec. 6.2, Table 5 note
# the nonlinear FE reference: the thinnest plate (largest deflection, lowest Euler load)
# over the whole deployment (None: the scene's end time; 0.002 covers the first peak). It
# costs ~0.1 s per step against ~2 ms for the FFRF body: 4.6 min of CPU, 7.4 min wall on the
# shared 2-core machine, most of the study's time
NONLINEAR_MODEL = "model0_t1mm"
NONLINEAR_END_TIME_S: float | None = None


def cases(scene: Scene) -> dict[str, Scene]:
    return twin_cases(scene, MODELS, NONLINEAR_MODEL, NONLINEAR_END_TIME_S)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Simulate every case; each model's reduction is built (or loaded) once."""
    return simulate_twins(scenes, run.progress, run.notes, cache_dir=run.cache_dir)


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    return Summary(*summarize_twins(scene, results, notes or {}, MODELS, NONLINEAR_MODEL,
                                    THESIS_DEPLOYMENT_TIME_S))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return twin_figures(results, summary.datasets, folder, list(MODELS), NONLINEAR_MODEL)

if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
