"""Study ``ladder``: linear FFRF, FFRF (flex's default), exact beam and nonlinear FE couplers.

The thesis deployment (spring release, 22 mm preload reading) with a steel plate coupler
0.08 x 0.01 x t, t = 0.3 ... 10 mm, each thickness run by every model on the same mesh, step and
samples (:mod:`flex.experiments.models.ladder`): the linear FFRF body (``coupler.geometric_stiffness
= false``), flex's default FFRF body (chord frame, the geometric stiffness of its axial
force, :mod:`flex.bodies.geometric_stiffness`), the geometrically exact beam (64 elements)
and the fully nonlinear FE body (the
reference), over max(1.1 first bending periods, 5 ms). Stored per thickness under
``/summary/t<t>mm``: each model's peak elastic midpoint deflection, its relative
difference to the nonlinear FE peak, the wall times, the coupler's largest compression
over its Euler load, and a model's validity warning where it has one (the FFRF bodies
beyond the Euler load: a linear-in-load model has nothing to hold a buckled plate). Then each
rung against the p-converged 3-D plate of 0.5-3 mm on its linear first bending frequency
(:mod:`flex.experiments.models.linear_reference`: the exact beam uncalibrated and calibrated,
the order-2 tetrahedra). ~3 min on 2 cores, most of it the nonlinear FE runs.
"""

from __future__ import annotations

import math

from flex.base.caseloop import run_each
from flex.config.settings import pinned_overrides
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.models.ladder import (
    MODELS,
    REFERENCE,
    first_period_s,
    ladder_table,
    rung_datasets,
    rung_from_cases,
    rung_scenes,
    simulate_model,
)
from flex.experiments.models.linear_reference import linear_summary
from flex.study import StudyRun, Summary

NAME = "ladder"
DESCRIPTION = ("coupler plates 0.3-10 mm: linear FFRF, FFRF with geometric stiffness, exact beam, "
               "nonlinear FE")
OVERRIDES = pinned_overrides()
#: thickness [mm] -> (mesh size [mm], step [s]): meshes as the stability study's (about 2 t,
#: 2 ... 5 mm); steps of >= 40 per first bending period, at most 5e-5 s (the nonlinear FE
#: peak of the 0.5 mm plate moves by 0.03 % from 1e-4 to 5e-5 s)
PLATES = {0.3: (2.0, 2.5e-5), 0.5: (2.0, 5e-5), 0.6: (2.0, 5e-5), 0.7: (2.0, 5e-5),
          1.0: (2.0, 5e-5), 2.0: (2.0, 2.5e-5), 3.0: (3.0, 2.5e-5), 5.0: (5.0, 1e-5),
          10.0: (5.0, 5e-6)}

#: the plates compared with their p-converged 3-D reference too [mm]
LINEAR_MM = (0.5, 0.7, 1.0, 2.0, 3.0)


def _label(thickness_mm: float) -> str:
    return f"t{thickness_mm:g}mm"


def cases(scene: Scene) -> dict[str, Scene]:
    out = {}
    for thickness_mm, (mesh_mm, step_s) in PLATES.items():
        plate = dict(scene, coupler=dict(scene["coupler"], thickness_m=thickness_mm * 1e-3))
        end_time_s = round(max(1.1 * first_period_s(plate), 0.005), 4)
        for model, model_scene in rung_scenes(scene, thickness_mm * 1e-3, mesh_mm * 1e-3,
                                              step_s, end_time_s).items():
            out[f"{_label(thickness_mm)}_{model}"] = model_scene
    return out


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    return run_each(scenes, lambda name, scene: simulate_model(name, scene, run.cache_dir),
                    run.progress)


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    rungs, datasets = [], {}
    for thickness_mm in PLATES:
        label = _label(thickness_mm)
        names = {model: f"{label}_{model}" for model in MODELS}
        if not all(name in results for name in names.values()):
            continue
        reference = cases(scene)[names[REFERENCE]]
        rung = rung_from_cases({m: results[n] for m, n in names.items()}, reference)
        rungs.append(rung)
        datasets.update(rung_datasets(rung, label))
    within = [r.thickness_m * 1e3 for r in rungs if "ffrf" not in r.warnings
              and abs(r.difference_to_reference.get("ffrf", math.nan)) <= 0.01]
    beam = [r.thickness_m * 1e3 for r in rungs
            if abs(r.difference_to_reference.get("exact_beam", math.nan)) <= 0.001]
    linear, table = linear_summary(scene, {t * 1e-3: PLATES[t][0] * 1e-3 for t in LINEAR_MM},
                                   run.cache_dir)
    datasets.update(linear)
    report = (ladder_table(rungs) + "\n\nflex's default FFRF body within 1 % of the "
              f"nonlinear FE peak at t = {', '.join(f'{t:g}' for t in within) or 'none'} mm; "
              f"the exact beam within 0.1 % at t = {', '.join(f'{t:g}' for t in beam) or 'none'}"
              " mm (the FE coupler's own mesh error is of that size).\n\n" + table)
    return Summary(datasets, report)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
