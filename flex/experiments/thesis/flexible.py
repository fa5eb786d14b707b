"""Plate couplers as every model of flex's ladder, against their stored converged references.

One steel plate coupler is modelled several times in the same mechanism: as flex's default
flexible body (``ffrf``: floating frame on the chord, NGsolve mesh, Hurty-Craig-Bampton
reduction, the geometric stiffness of its axial force), as the linear FFRF body (``linear``:
``geometric_stiffness = false``) and as its rigid twin (``rigid``: a rigid body with the
plate's own mass and inertia, so it differs from the others only by elasticity).
:func:`twin_cases` builds them for a table of plates (``{model: (thickness [m], mesh size
[m])}``); :func:`simulate_twins` runs them, each reduction built (or loaded from the cache)
once, its facts kept in the run's notes; the default FFRF and rigid runs carry their error
budgets (:mod:`flex.fidelity.error_budget`), the linear comparison none (its error is what the
comparison measures). :func:`summarize_twins` tabulates, per plate, the reduction's
frequencies and mesh, the thesis's n = delta_t / T in both period conventions, the FFRF run's
deviations from its twin and its stated accuracy, and each model against the stored
reference of its physics (:func:`reference_comparison`: the bundled store,
:mod:`flex.data.reference_store`, made once by ``make references``: the calibrated exact beam,
converged, over the whole deployment, with its own stated accuracy); :func:`twin_figures`
draws them. The fully nonlinear FE coupler on the same mesh (what this study ran over the
first 2.5-5 ms until issue 50) is ``make ladder``'s reference, 0.3-10 mm plates.
"""

from __future__ import annotations

import functools
from collections.abc import Hashable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.caseloop import Progress, run_each
from flex.base.physics import Plate, n_values
from flex.base.plotting import MICRO, figure, legend_below, panels
from flex.data.reference_store import MissingReferenceError, StoredReference, reference_for
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import FFRF, RIGID, reduction_for_scene
from flex.experiments.workprecision.stored_references import curve_at
from flex.fidelity.simulation import simulate_case
from flex.fidelity.softening import (
    LABELS,
    MOTION,
    coupler_compression_N,
    motion_error_fractions,
)
from flex.fidelity.stored_budget import budget_rows

Plates = dict[str, tuple[float, float]]  # model -> (thickness [m], mesh size [m])
#: what the summary reports of each FFRF case's reduction (``notes["reductions"][case]``)
REDUCTION_FACTS = ("pinned_pinned_frequency_Hz", "fixed_interface_frequencies_Hz", "n_nodes",
                   "n_elements", "n_dof", "mass_kg")


def _plate_case(scene: Scene, thickness_m: float, mesh_m: float, *more: str) -> Scene:
    """``scene`` with a plate coupler ``thickness_m`` thick meshed at ``mesh_m`` [m] and the
    overrides ``more`` (its model among them); validated."""
    case = derive_scene(scene, [f"coupler.thickness_m={thickness_m}",
                                f"coupler.mesh_size_m={mesh_m}", *more])
    return case


#: the models of each plate (case name suffix -> overrides)
KINDS = {FFRF: [f'coupler.model="{FFRF}"'],
         "linear": [f'coupler.model="{FFRF}"', "coupler.geometric_stiffness=false",
                    "simulation.error_estimate=false"],
         RIGID: [f'coupler.model="{RIGID}"']}


def twin_cases(scene: Scene, plates: Plates) -> dict[str, Scene]:
    """``<model>_ffrf``, ``<model>_linear`` and ``<model>_rigid`` per plate."""
    return {f"{model}_{kind}": _plate_case(scene, thickness_m, mesh_m, *overrides)
            for model, (thickness_m, mesh_m) in plates.items()
            for kind, overrides in KINDS.items()}


def simulate_twin(name: str, scene: Scene, *, cache_dir: Path | None = None
                  ) -> tuple[CaseResult, dict[str, Any] | None]:
    """One case with its reduction (FFRF, cached in ``cache_dir``), its facts in attrs;
    returns it with the reduction's facts the summary reports (None for a case without a
    reduction)."""
    if scene["coupler"]["model"] != FFRF:
        return simulate_case(scene, name, cache_dir=cache_dir), None
    reduction = reduction_for_scene(scene, cache_dir=cache_dir)
    case = simulate_case(scene, name, reduction, cache_dir=cache_dir)
    case.attrs.update(reduction_key=reduction.key, reduction_from_cache=reduction.from_cache,
                      reduction_build_time_s=reduction.build_time_s)
    return case, {key: getattr(reduction, key) for key in REDUCTION_FACTS}


def _plate_of(name: str, scene: Scene) -> Hashable:
    """The job of a case on an executor: a plate's models together (they share its
    reduction, built once)."""
    return name.rsplit("_", 1)[0]


def _cost(name: str, scene: Scene) -> float:
    """A plate's rough cost [arbitrary units] for ordering the jobs: thinner plates (more
    steps of their budget's companions, finer meshes) first."""
    return 1e-3 / scene["coupler"]["thickness_m"]


def simulate_twins(scenes: dict[str, Scene], progress: Progress | None,
                   notes: dict[str, Any], *, cache_dir: Path | None = None,
                   executor: Any = None) -> dict[str, CaseResult]:
    """Simulate every case; each plate's reduction is built (or loaded from ``cache_dir``,
    the reduction cache folder; None: built in memory, no disk cache), and what the summary
    reports of it goes to ``notes`` (the run's, handed on to the summary). ``executor``
    (:mod:`flex.sweep`'s, passed in; None: this process): each plate's models in one job,
    the thinnest plate first."""
    done = run_each(scenes, functools.partial(simulate_twin, cache_dir=cache_dir), progress,
                    executor=executor, group=_plate_of, cost=_cost)
    for name, (_, facts) in done.items():
        if facts is not None:
            notes.setdefault("reductions", {})[name] = facts
    return {name: case for name, (case, _) in done.items()}


HEADER = (f"  {'model':14s} {'t [mm]':>6s} {'f_pp [Hz]':>10s} {'n thesis':>9s} "
          f"{'n 2pi/w':>8s} {'peak defl [um]':>15s} {'+- est. [um]':>12s} {'defl/L2':>9s} "
          f"{'d crank [rad]':>13s} {'sigma [MPa]':>11s} {'+- est.':>8s} {'wall [s]':>8s}")


def _budget(case: CaseResult, quantity: str) -> tuple[float, float]:
    """The stored estimated error of ``quantity`` [its units] and its relative value (NaN
    where the case has none)."""
    for row in budget_rows(case.attrs):
        if row.quantity == quantity:
            return row.total, row.relative
    return float("nan"), float("nan")


def _whole_run_peak(case: CaseResult, name: str) -> float:
    """Headline ``name`` of ``case`` [its unit] (:data:`flex.data.headlines.
    BUILTIN_HEADLINES`), NaN where the run has none."""
    from flex.data.headlines import BUILTIN_HEADLINES

    value = BUILTIN_HEADLINES[name].read(case.datasets)
    return float("nan") if value is None else value


def _pair_values(thickness_m: float, facts: dict[str, Any], flex_case: CaseResult,
                 rigid_case: CaseResult, length_m: float,
                 deployment_time_s: float) -> dict[str, tuple[Any, str, str]]:
    """One plate's summary values: (value, units, description) by key."""
    flex_data = {k: v.data for k, v in flex_case.datasets.items()}
    rigid_data = {k: v.data for k, v in rigid_case.datasets.items()}
    n = n_values(deployment_time_s, 2 * np.pi * facts["pinned_pinned_frequency_Hz"])
    # the values the budgets are of: the whole-run peaks on the headline channel
    peak, stress = (_whole_run_peak(flex_case, name) for name in (
        "coupler_peak_deflection_m", "coupler_peak_bending_stress_Pa"))
    deflection_error, deflection_relative = _budget(flex_case, "coupler_peak_deflection_m")
    stress_error, stress_relative = _budget(flex_case, "coupler_peak_bending_stress_Pa")
    return {
        "thickness_m": (thickness_m, "m", "plate thickness (in-plane bending height)"),
        "pinned_pinned_frequency_Hz": (facts["pinned_pinned_frequency_Hz"], "Hz",
                                       "first in-plane bending mode of the reduced body"),
        "fixed_interface_frequencies_Hz": (facts["fixed_interface_frequencies_Hz"], "Hz",
                                           "Craig-Bampton fixed-interface modes"),
        "mesh_nodes": (facts["n_nodes"], "1", "mesh nodes (second-order tetrahedra)"),
        "mesh_elements": (facts["n_elements"], "1", "second-order tetrahedra"),
        "mesh_dof": (facts["n_dof"], "1", "unreduced degrees of freedom"),
        "plate_mass": (facts["mass_kg"], "kg", "plate mass (also the rigid twin's)"),
        "n_thesis_convention": (n["thesis"], "1", "delta_t * omega (thesis: T = 1/omega)"),
        "n_physical": (n["physical"], "1", "delta_t / (2 pi / omega)"),
        "peak_midpoint_deflection": (peak, "m", "max |elastic midpoint deflection| over the "
                                     "whole run on the headline channel, FFRF"),
        "peak_midpoint_deflection_estimated_error": (
            deflection_error, "m", "its estimated error (the error budget)"),
        "peak_midpoint_deflection_estimated_relative_error": (
            deflection_relative, "1", "that over the peak"),
        "peak_deflection_over_length": (peak / length_m, "1", "peak deflection / L2"),
        "peak_deflection_crest_gap": (
            flex_case.attrs.get("crest_gap_coupler_peak_deflection_m", float("nan")), "m",
            "how far the second-largest crest lies below the peak (the peak races between "
            "crests when its error exceeds this)"),
        "first_crest_deflection": (
            flex_case.attrs.get("headline_coupler_first_crest_deflection_m", float("nan")),
            "m", "first crest: largest |deflection| of the first lobe (does not race)"),
        "max_crank_angle_deviation": (
            np.abs(flex_data["crank/angle"] - rigid_data["crank/angle"]).max(), "rad",
            "max |FFRF - rigid twin|"),
        "max_slider_position_deviation": (
            np.abs(flex_data["slider/position"] - rigid_data["slider/position"]).max(), "m",
            "max |FFRF - rigid twin|"),
        "peak_bending_stress": (stress, "Pa", "FFRF peak |sigma_xx| over the whole run on "
                                "the headline channel"),
        "peak_bending_stress_estimated_error": (
            stress_error, "Pa", "its estimated error (the error budget)"),
        "peak_bending_stress_estimated_relative_error": (stress_relative, "1",
                                                         "that over the peak stress"),
        "ffrf_wall_time": (flex_case.counters["wall_time_s"], "s", "FFRF simulation wall time"),
        "rigid_wall_time": (rigid_case.counters["wall_time_s"], "s",
                            "rigid twin simulation wall time"),
    }


def _row(model: str, v: dict[str, Any]) -> str:
    """One plate's line of the report table (``v``: values by key, without units)."""
    return (f"  {model:14s} {v['thickness_m'] * 1e3:6.0f} "
            f"{v['pinned_pinned_frequency_Hz']:10.1f} {v['n_thesis_convention']:9.1f} "
            f"{v['n_physical']:8.2f} {v['peak_midpoint_deflection'] * 1e6:15.4g} "
            f"{v['peak_midpoint_deflection_estimated_error'] * 1e6:12.2g} "
            f"{v['peak_deflection_over_length']:9.2e} "
            f"{v['max_crank_angle_deviation']:13.2e} {v['peak_bending_stress'] / 1e6:11.4g} "
            f"{v['peak_bending_stress_estimated_relative_error']:8.1%} "
            f"{v['ffrf_wall_time']:8.2f}")


#: the headline quantities each model is held against the stored reference on (values over
#: the deployment on the headline channel, the first crest, the motion at the end time)
COMPARED = {"coupler_deployment_peak_deflection_m": ("deployment peak", 1e6, "um"),
            "coupler_first_crest_deflection_m": ("first crest", 1e6, "um"),
            "coupler_deployment_peak_bending_stress_Pa": ("bending stress", 1e-6, "MPa"),
            "joint_C_deployment_peak_force_N": ("joint C force", 1.0, "N"),
            "deployment_time_s": ("deployment time", 1e3, "ms")}
#: the curves held against the stored reference's over the whole run: path -> (key, unit)
CURVES = {"coupler/midpoint_deflection": ("max_curve_difference_over_peak", "1"),
          "crank/angle": ("max_crank_angle_difference", "rad"),
          "slider/position": ("max_slider_position_difference", "m")}
#: a difference to the reference is resolved when it is at least this many times the
#: reference's own stated accuracy (as ``make estimates`` judges, estimate_check.pair_rows)
RESOLVED = 3.0


def _headlines(case: CaseResult) -> dict[str, float]:
    """A run's stored headline values (``headline_<quantity>``) by quantity [its unit]."""
    return {key.removeprefix("headline_"): float(value) for key, value in case.attrs.items()
            if key.startswith("headline_")}


def _model_values(case: CaseResult, reference: StoredReference) -> dict[str, tuple[Any, str,
                                                                                    str]]:
    """One model's run against the stored reference: each :data:`COMPARED` quantity the
    run has, its relative error and whether that is resolved (:data:`RESOLVED`), and the
    largest difference of each :data:`CURVES` curve over the whole run (the deflection's
    over the reference's peak); (value, units, description) by key."""
    label = LABELS.get(case.name.rsplit("_", 1)[1], case.name)
    ours, out = _headlines(case), {}
    for quantity in COMPARED:
        if quantity not in ours or quantity not in reference.values:
            continue
        theirs = reference.values[quantity]
        out[quantity] = (ours[quantity], reference.units[quantity], f"{label}: its value")
        out[f"{quantity}_error"] = (ours[quantity] / theirs - 1.0, "1",
                                    f"{label} / stored reference - 1")
        out[f"{quantity}_resolved"] = (
            not _resolved_mark(ours, reference, quantity), "1",
            f"the difference is at least {RESOLVED:g}x the reference's own accuracy")
    time_s = np.asarray(case.datasets["time"].data, dtype=float)
    for path, (key, unit) in CURVES.items():
        if (path not in case.datasets or path not in reference.curves
                or not np.any(case.datasets[path].data)):  # a rigid twin has no deflection
            continue
        theirs, _ = curve_at(reference, path, time_s)
        difference = float(np.max(np.abs(np.asarray(case.datasets[path].data) - theirs)))
        if unit == "1":
            difference /= float(np.max(np.abs(reference.curves[path])))
        out[key] = (difference, unit, f"max |{label} - stored reference| {path} over the "
                    "whole run" + (" / the reference's peak" if unit == "1" else ""))
    return out


def _error_text(values: dict[str, tuple[Any, str, str]], quantity: str) -> str:
    """``<value> <unit> (<error>)`` of one compared quantity; an error the reference cannot
    resolve is marked ``~``."""
    name, scale, unit = COMPARED[quantity]
    if quantity not in values:
        return f"{name} -"
    mark = "" if values[f"{quantity}_resolved"][0] else "~"
    return (f"{name} {values[quantity][0] * scale:.4g} {unit} "
            f"({mark}{values[f'{quantity}_error'][0]:+.2%})")


def _resolved_mark(ours: Mapping[str, float], reference: StoredReference,
                   quantity: str) -> str:
    """``~`` when the run's ``quantity`` is within :data:`RESOLVED` x the stored reference's
    own accuracy of its value (the difference is not resolved), else nothing."""
    if quantity not in ours or quantity not in reference.values:
        return ""
    difference = abs(ours[quantity] - reference.values[quantity])
    return "" if difference >= RESOLVED * reference.accuracies[quantity] else "~"


def reference_comparison(model: str, runs: dict[str, CaseResult],
                         reference: StoredReference, euler_load_N: float
                         ) -> tuple[dict[str, Dataset], list[str]]:
    """Each model's run of one plate (``runs``: ``ffrf``, ``linear``, ``rigid``, any of them,
    all ``ok``) against the stored reference of its physics over the whole run: the
    datasets ``reference/<model>/<kind>/<key>`` (:func:`_model_values`), ``reference/<model>/
    <key>`` (the reference's values and accuracies, its deflection curve, the compression over
    the Euler load, the FFRF error on the motion as a fraction of the elasticity's effect)
    and the report lines."""
    prefix = f"reference/{model}"
    datasets = {f"{prefix}/span_end_time": Dataset(float(reference.curves["time"][-1]), "s",
                                                   "runs compared over 0 .. this time"),
                f"{prefix}/curve_time": Dataset(reference.curves["time"], "s",
                                                "the stored reference's samples"),
                f"{prefix}/curve_midpoint_deflection": Dataset(
                    reference.curves["coupler/midpoint_deflection"], "m",
                    f"stored reference: {reference.model}")}
    for quantity in COMPARED:
        if quantity in reference.values:
            datasets[f"{prefix}/stored/{quantity}"] = Dataset(
                reference.values[quantity], reference.units[quantity], reference.model)
            datasets[f"{prefix}/stored/{quantity}_accuracy"] = Dataset(
                reference.accuracies[quantity], reference.units[quantity],
                "the stored reference's own error")
    compression = (float(coupler_compression_N(
        {k: v.data for k, v in runs[FFRF].datasets.items()}).max()) / euler_load_N
        if FFRF in runs else float("nan"))
    datasets[f"{prefix}/max_compression_over_euler_load"] = Dataset(
        compression, "1", "max axial compression (FFRF joint C force along B-C) / "
        "pinned-pinned Euler load")
    peak, accuracy = (reference.values["coupler_deployment_peak_deflection_m"],
                      reference.accuracies["coupler_deployment_peak_deflection_m"])
    lines = [f"stored reference, {model} ({reference.name}: {reference.model}, 0 .. "
             f"{reference.curves['time'][-1] * 1e3:.0f} ms): deployment peak "
             f"{peak * 1e6:.4g} um +- {accuracy * 1e6:.2g}; compression up to "
             f"{compression:.3g} of the Euler load"]
    for kind, case in runs.items():
        values = _model_values(case, reference)
        datasets.update({f"{prefix}/{kind}/{key}": Dataset(value, unit, text)
                         for key, (value, unit, text) in values.items()})
        curve = values.get("max_curve_difference_over_peak", (float("nan"),))[0]
        lines.append(f"  {LABELS.get(kind, kind):45s} " + ", ".join(
            _error_text(values, quantity) for quantity in COMPARED)
            + (f"; curves {curve:.1%} of the peak apart" if np.isfinite(curve) else "")
            + f"; crank angle {values['max_crank_angle_difference'][0]:.2g} rad apart")
    if FFRF in runs and RIGID in runs:
        fractions = motion_error_fractions(_headlines(runs[FFRF]), _headlines(runs[RIGID]),
                                           reference.values)
        datasets.update({f"{prefix}/ffrf/motion_error_fraction/{name.replace(' ', '_')}":
                         Dataset(value, "1", f"|FFRF - reference| / |FFRF - rigid twin|, "
                                 f"{name}") for name, value in fractions.items()})
        ffrf = _headlines(runs[FFRF])
        lines.append("  FFRF against the reference on the motion, as a fraction of the "
                     "elasticity's effect (FFRF - rigid twin): " + ", ".join(
                         f"{name} {_resolved_mark(ffrf, reference, MOTION[name])}{value:.3g}"
                         for name, value in fractions.items()))
    return datasets, lines


def _reference_lines(scene: Scene, results: dict[str, CaseResult], plates: Plates,
                     store: Mapping[str, StoredReference],
                     datasets: dict[str, Dataset]) -> list[str]:
    """Each plate's models against the stored reference of its physics
    (:func:`reference_comparison`, its datasets added to ``datasets``); the report lines (a
    plate whose physics the store lacks says so)."""
    lines = []
    for model, (thickness_m, mesh_m) in plates.items():
        runs = {kind: results[f"{model}_{kind}"] for kind in KINDS
                if f"{model}_{kind}" in results and results[f"{model}_{kind}"].status == "ok"}
        if not runs:
            continue
        try:
            reference = reference_for(store, _plate_case(scene, thickness_m, mesh_m))
        except MissingReferenceError as exc:
            lines.append(f"stored reference, {model}: none ({exc})")
            continue
        euler_load_N = replace(Plate.of(scene["coupler"]), thickness_m=thickness_m).euler_load_N
        found, more = reference_comparison(model, runs, reference, euler_load_N)
        datasets.update(found)
        lines += more
    if lines:
        lines.append(f"  (~: a difference below {RESOLVED:g}x the reference's own accuracy, "
                     "not resolved; the nonlinear FE coupler on the same mesh: make ladder)")
    return lines


def summarize_twins(scene: Scene, results: dict[str, CaseResult], notes: dict[str, Any],
                    plates: Plates, deployment_time_s: float,
                    store: Mapping[str, StoredReference]) -> tuple[dict[str, Dataset], str]:
    """The summary datasets and report: ``models/<model>/...`` per plate (see
    :func:`_pair_values`), each plate's models against the stored reference of its physics
    in ``store`` (``reference/<model>/...``, :func:`reference_comparison`) and the report
    table. ``notes``: the run's, with the reductions' facts (:func:`simulate_twins`);
    ``deployment_time_s``: delta_t of n [s]."""
    datasets: dict[str, Dataset] = {}
    lines = ["flexible: FFRF coupler plates (flex's default body) against their rigid twins "
             "(22 mm preload); +- est.: the stored estimated error of the peak (step, modes, "
             "mesh, model)", HEADER]
    for model, (thickness_m, _) in plates.items():
        flex_case, rigid_case = results[f"{model}_ffrf"], results[f"{model}_rigid"]
        if flex_case.status != "ok" or rigid_case.status != "ok":
            lines.append(f"  {model}: failed: {flex_case.message or rigid_case.message}")
            continue
        facts = notes.get("reductions", {}).get(f"{model}_ffrf")
        if facts is None:
            lines.append(f"  {model}: no reduction recorded (run by simulate_twins)")
            continue
        values = _pair_values(thickness_m, facts, flex_case, rigid_case,
                              scene["coupler"]["length_m"], deployment_time_s)
        datasets.update({f"models/{model}/{key}": Dataset(value, unit, text)
                         for key, (value, unit, text) in values.items()})
        lines.append(_row(model, {key: value for key, (value, _, _) in values.items()}))
    lines.append(_crest_line(datasets, plates))
    lines.append("  n thesis = delta_t * omega (thesis Table 5 takes T = 1/omega); "
                 f"n 2pi/w = delta_t / T with the physical period; delta_t = "
                 f"{deployment_time_s:g} s")
    lines += _reference_lines(scene, results, plates, store, datasets)
    return datasets, "\n".join(lines)


def _crest_line(datasets: dict[str, Dataset], plates: Plates) -> str:
    """Each plate's first crest and its peak's crest gap [um] (and the gap over the peak)."""
    parts = []
    for model in plates:
        if f"models/{model}/first_crest_deflection" not in datasets:
            continue
        first, gap, peak = (float(datasets[f"models/{model}/{key}"].data) for key in (
            "first_crest_deflection", "peak_deflection_crest_gap", "peak_midpoint_deflection"))
        parts.append(f"{model} {1e6 * first:.4g} / {1e6 * gap:.3g} ({100 * gap / peak:.2g} %)")
    return "  first crest [um] / crest gap of the peak [um] (% of the peak): " + "; ".join(parts)


# ------------------------------------------------------------------------------------------
# figures
# ------------------------------------------------------------------------------------------
UM = f"{MICRO}m"


def model_label(model: str) -> str:
    """``model1_t3mm`` -> ``model 1, t = 3 mm`` (Table 5 model and plate thickness)."""
    number, _, thickness = model.partition("_t")
    return f"model {number.removeprefix('model')}, t = {thickness.removesuffix('mm')} mm"


def _deflection_panels(ok: dict[str, dict[str, np.ndarray]], drawn: list[str],
                       folder: Path) -> Path:
    """One panel per plate: the peaks differ by two orders of magnitude (180 um at 1 mm,
    under 1 um at 10 mm), one shared scale would flatten the stiffer plates."""
    path = folder / "flexible-midpoint-deflection.png"
    with panels(path, "Elastic midpoint deflection of the FFRF coupler, one panel per "
                "plate thickness (own scale each; cf. thesis figs. 47-50)",
                rows=len(drawn), size=(7.5, 1.4 + 1.9 * len(drawn)), sharex=True
                ) as (_, axes):
        for index, (ax, model) in enumerate(zip(axes, drawn, strict=True)):
            data = ok[f"{model}_ffrf"]
            deflection = np.asarray(data["coupler/midpoint_deflection"]) * 1e6
            ax.plot(data["time"], deflection, color=f"C{index}", lw=1.0)
            ax.set_title(f"{model_label(model)}: peak |deflection| "
                         f"{np.abs(deflection).max():.3g} {UM}", fontsize="small")
            ax.set_ylabel(f"deflection [{UM}]")
            ax.axhline(0.0, color="k", lw=0.5)
        axes[-1].set_xlabel("time [s]")
    return path


def _acceleration_pair(model: str, flex_data: dict[str, np.ndarray],
                       rigid_data: dict[str, np.ndarray], folder: Path) -> Path:
    """Midpoint acceleration x and y of one plate, FFRF against its rigid twin."""
    path = folder / f"flexible-midpoint-acceleration-{model}.png"
    with panels(path, f"Coupler midpoint acceleration, {model_label(model)}: FFRF "
                "coupler against its rigid twin (cf. thesis figs. 35-42)", rows=2,
                size=(7.5, 6.0), sharex=True) as (fig, axes):
        for column, (ax, axis) in enumerate(zip(axes, "xy", strict=True)):
            ax.plot(flex_data["time"], flex_data["coupler/midpoint_acceleration"][:, column],
                    color="C0", lw=0.6, label="FFRF (flexible coupler)")
            ax.plot(rigid_data["time"], rigid_data["coupler/midpoint_acceleration"][:, column],
                    "k--", lw=1.4, label="rigid twin")
            ax.set_ylabel(f"{axis} acceleration [m/s\u00b2]")
        axes[-1].set_xlabel("time [s]")
        legend_below(fig)
    return path


def _reference_figure(ok: dict[str, dict[str, np.ndarray]], summary: dict[str, Dataset],
                      models: list[str], folder: Path) -> Path:
    """One panel per plate with a stored reference: the midpoint deflection of each model
    and of the reference over the whole run (own scale each)."""
    path = folder / "flexible-stored-reference.png"
    styles = {FFRF: ("C0", "-", "FFRF (flex's default)"),
              "linear": ("C1", "-.", "linear FFRF")}
    with panels(path, "Midpoint deflection of each coupler model against the stored "
                "converged reference (calibrated exact beam), one panel per plate (own scale "
                "each)", rows=len(models), size=(7.5, 1.6 + 2.0 * len(models)), sharex=True
                ) as (fig, axes):
        for ax, model in zip(axes, models, strict=True):
            ax.plot(summary[f"reference/{model}/curve_time"].data,
                    np.asarray(summary[f"reference/{model}/curve_midpoint_deflection"].data)
                    * 1e6, color="k", ls="--", lw=1.0, label="stored reference")
            for kind, (color, style, label) in styles.items():
                data = ok.get(f"{model}_{kind}")
                if data is not None:
                    ax.plot(data["time"], np.asarray(data["coupler/midpoint_deflection"]) * 1e6,
                            color=color, ls=style, lw=0.8, label=label)
            ax.set_title(model_label(model), fontsize="small")
            ax.set_ylabel(f"deflection [{UM}]")
        axes[-1].set_xlabel("time [s]")
        legend_below(fig)
    return path


def _peak_figure(thickness: list[float], peak: list[float], folder: Path) -> Path:
    """Peak deflection [um] against plate thickness [mm], log-log, with the fitted slope."""
    path = folder / "flexible-peak-deflection.png"
    with figure(path, "Peak elastic midpoint deflection of the coupler against plate "
                "thickness", "plate thickness t [mm] (log scale)",
                f"peak |midpoint deflection| [{UM}]") as ax:
        ax.loglog(thickness, peak, "o-", label="FFRF runs")
        if len(thickness) >= 2 and min(peak) > 0:
            slope, _ = np.polyfit(np.log(thickness), np.log(peak), 1)
            ax.plot([], [], " ", label=f"fitted slope: peak \u221d $t^{{{slope:.2f}}}$")
        ax.set_xticks(thickness, [f"{t:g}" for t in thickness])
        ax.minorticks_off()
        for t, p in zip(thickness, peak, strict=True):
            ax.annotate(f"{p:.3g} {UM}", (t, p), xytext=(6, 4), textcoords="offset points",
                        fontsize="small")
    return path


def twin_figures(results: dict[str, CaseResult], summary: dict[str, Dataset], folder: Path,
                 models: list[str]) -> list[Path]:
    """The deflection panels, each plate's accelerations against its twin, the models
    against the stored reference and the peak deflection against thickness (whichever
    have their runs); ``summary``: the summary datasets."""
    ok = {n: {k: v.data for k, v in c.datasets.items()} for n, c in results.items()
          if c.status == "ok"}
    drawn = [model for model in models if f"{model}_ffrf" in ok]
    paths = [_deflection_panels(ok, drawn, folder)] if drawn else []
    paths += [_acceleration_pair(model, ok[f"{model}_ffrf"], ok[f"{model}_rigid"], folder)
              for model in models if f"{model}_ffrf" in ok and f"{model}_rigid" in ok]
    referenced = [model for model in models
                  if f"reference/{model}/curve_midpoint_deflection" in summary]
    if referenced:
        paths.append(_reference_figure(ok, summary, referenced, folder))
    found = [model for model in models
             if f"models/{model}/peak_midpoint_deflection" in summary]
    if found:
        paths.append(_peak_figure(
            [float(summary[f"models/{m}/thickness_m"].data) * 1e3 for m in found],
            [float(summary[f"models/{m}/peak_midpoint_deflection"].data) * 1e6
             for m in found], folder))
    return paths
