"""The ``tradeoff`` study's runs: per scene a converged reference, then every setting.

:func:`run_work_precision` runs, per scene, its
:class:`~flex.experiments.workprecision.reference_plans.ReferencePlan`
(:func:`flex.experiments.workprecision.reference_plans.build_reference`) and then measures each
of its settings against that reference
(:func:`flex.experiments.workprecision.measurement.measure`), sharing reductions within the scene
(:class:`~flex.experiments.workprecision.measurement.ReductionPool`). It returns one case per
run -- ``<scene>__reference`` (the reference's curves) and ``<scene>__<setting>``
(:func:`flex.experiments.workprecision.measurement.measurement_case`: attrs knobs, group, label
and errors; counters with the median wall time [s]; dataset ``wall_times``, every repeat [s];
a failed run is a ``failed`` case with its message and no data) -- and leaves the measurements
in ``notes["runs"]`` (:class:`SceneRuns`), from which
:mod:`flex.experiments.workprecision.tradeoff_report` builds the tables.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, NamedTuple

from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, to_toml
from flex.experiments.workprecision.measurement import (
    Measurement,
    Progress,
    ReductionPool,
    Reference,
    Setting,
    measure,
    measurement_attrs,
    measurement_case,
    scene_for,
)
from flex.experiments.workprecision.reference_plans import (
    ReferencePlan,
    build_reference,
    reference_plan,
)


class SceneRuns(NamedTuple):
    """One scene's runs: the reference, the measured settings in plan order, and the wall
    time [s] of the reference with all its evidence runs (including reduction builds)."""

    reference: Reference
    measurements: list[Measurement]
    reference_time_s: float


def case_name(scene_name: str, label: str) -> str:
    """``<scene>__<label>`` with characters outside ``[A-Za-z0-9_=.+-]`` replaced by ``_``."""
    return f"{scene_name}__" + re.sub(r"[^A-Za-z0-9_=.+-]+", "_", label).strip("_")


def reference_case(scene_name: str, scene: Scene, reference: Reference) -> CaseResult:
    """The case ``<scene>__reference``: time [s], crank angle [rad], slider position [m] and
    (flexible) midpoint deflection [m] of the reference; attrs what it is and how converged."""
    obs = reference.observables
    datasets = {"time": Dataset(obs.time_s, "s", "simulation time"),
                "crank/angle": Dataset(obs.crank_angle_rad, "rad", "reference crank angle"),
                "slider/position": Dataset(obs.slider_position_m, "m",
                                           "reference slider position")}
    if obs.deflection_m is not None:
        datasets["coupler/midpoint_deflection"] = Dataset(
            obs.deflection_m, "m", "reference elastic midpoint deflection")
    reference_scene = scene_for(scene, reference.setting)
    return CaseResult(f"{scene_name}__reference", to_toml(reference_scene), datasets,
                      counters={"wall_time_s": reference.wall_time_s},
                      attrs={"knobs": repr(reference.setting.knobs()),
                             "description": reference.description,
                             "converged": reference.converged,
                             "accuracy": reference.accuracy,
                             "tolerance": reference.tolerance})


def _work_precision_case(scene_name: str, scene: Scene, m: Measurement) -> CaseResult:
    """A setting's case in a work-precision run (a failed one keeps knobs and group only)."""
    attrs = (measurement_attrs(m) if m.ok
             else {"knobs": repr(m.setting.knobs()), "group": m.setting.group})
    return measurement_case(case_name(scene_name, m.setting.label), scene, m, attrs)


def run_work_precision(scenes: Mapping[str, Scene], settings: Mapping[str, Sequence[Setting]],
                       repeats: int, progress: Progress | None = None,
                       notes: dict[str, Any] | None = None,
                       plans: Callable[[str], ReferencePlan] = reference_plan, *,
                       cache_dir: Path | None = None,
                       stored: Mapping[str, Reference] | None = None
                       ) -> dict[str, CaseResult]:
    """Per scene its reference (``stored[scene name]`` where given: a stored reference,
    :func:`~flex.experiments.workprecision.measurement.stored_as_reference`, made once by
    ``make references``, its time 0 here; else built by ``plans(scene name)``) and then each
    of ``settings[scene name]``, measured ``repeats`` times; returns one case per run and
    stores ``notes["runs"][scene name]`` (:class:`SceneRuns`). ``cache_dir``: the reduction
    cache folder (None: reductions are built in memory, no disk cache)."""
    stored = stored or {}
    total = sum(len(plan) + 1 for plan in settings.values())
    done = 0
    results: dict[str, CaseResult] = {}
    runs: dict[str, SceneRuns] = (notes if notes is not None else {}).setdefault("runs", {})
    for scene_name, scene in scenes.items():
        pool = ReductionPool(cache_dir)
        if progress:
            progress(f"{scene_name}: reference", done, total)
        started = time.perf_counter()
        reference = stored.get(scene_name) or build_reference(
            scene, scene_name, plans(scene_name), pool,
            (lambda text, name=scene_name, at=done: progress(f"{name}: {text}", at, total))
            if progress else None)
        reference_time = 0.0 if scene_name in stored else time.perf_counter() - started
        done += 1
        results[f"{scene_name}__reference"] = reference_case(scene_name, scene, reference)
        measurements = []
        for setting in settings[scene_name]:
            if progress:
                progress(f"{scene_name}: {setting.label}", done, total)
            measurement = measure(scene, setting, reference, repeats, pool)
            measurements.append(measurement)
            results[case_name(scene_name, setting.label)] = _work_precision_case(
                scene_name, scene, measurement)
            done += 1
        runs[scene_name] = SceneRuns(reference, measurements, reference_time)
    if progress:
        progress("done", total, total)
    return results
