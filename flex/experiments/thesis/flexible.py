"""Plate couplers as every model of flex's ladder, against a nonlinear FE reference.

One steel plate coupler is modelled several times in the same mechanism: as flex's default
flexible body (``ffrf``: floating frame on the chord, NGsolve mesh, Hurty-Craig-Bampton
reduction, the geometric stiffness of its axial force), as the linear FFRF body (``linear``:
``geometric_stiffness = false``), as its rigid twin (``rigid``: a rigid body with the plate's
own mass and inertia, so it differs from the others only by elasticity) and, for an undamped
scene, as the fully nonlinear FE coupler (``nonlinear_fe``, :mod:`flex.bodies.nonlinear`: the
reference, over a span of its own). :func:`twin_cases` builds them for a table of plates
(``{model: (thickness [m], mesh size [m])}``); :func:`simulate_twins` runs them, each
reduction built (or loaded from the cache) once, its facts kept in the run's notes; the
default FFRF and rigid runs carry their error budgets (:mod:`flex.fidelity.error_budget`),
the linear comparison and the reference none (their error is what the comparison
measures; a reference needs no estimate). :func:`summarize_twins` tabulates, per plate, the
reduction's frequencies and mesh, the thesis's n = delta_t / T in both period conventions,
the FFRF run's deviations from its twin and its stated accuracy, and each model against the
reference (:func:`flex.fidelity.softening.compare_with_reference`); :func:`twin_figures`
draws them.
"""

from __future__ import annotations

import functools
from collections.abc import Hashable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.caseloop import Progress, run_each
from flex.base.physics import Plate, n_values
from flex.base.plotting import MICRO, figure, legend_below, panels
from flex.bodies.nonlinear import nonlinear_plate_for_scene
from flex.data.plates import is_damped
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import (
    FFRF,
    NONLINEAR_FE,
    RIGID,
    reduction_for_scene,
)
from flex.fidelity.simulation import simulate_case
from flex.fidelity.softening import compare_with_reference
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
         RIGID: [f'coupler.model="{RIGID}"'],
         NONLINEAR_FE: [f'coupler.model="{NONLINEAR_FE}"', "simulation.error_estimate=false"]}


def twin_cases(scene: Scene, plates: Plates, reference_spans_s: dict[str, float | None]
               ) -> dict[str, Scene]:
    """``<model>_ffrf``, ``<model>_linear`` and ``<model>_rigid`` per plate; when the scene
    is undamped (the nonlinear FE body has no damping) ``<model>_nonlinear_fe`` too, for each
    plate in ``reference_spans_s``, run to that end time [s] (None: the scene's)."""
    out = {}
    for model, (thickness_m, mesh_m) in plates.items():
        kinds = [kind for kind in KINDS if kind != NONLINEAR_FE]
        if not is_damped(scene["coupler"]) and model in reference_spans_s:
            kinds.append(NONLINEAR_FE)
        for kind in kinds:
            span = reference_spans_s.get(model) if kind == NONLINEAR_FE else None
            out[f"{model}_{kind}"] = _plate_case(
                scene, thickness_m, mesh_m, *KINDS[kind],
                *([] if span is None else [f"simulation.end_time_s={span!r}"]))
    return out


def simulate_twin(name: str, scene: Scene, *, cache_dir: Path | None = None
                  ) -> tuple[CaseResult, dict[str, Any] | None]:
    """One case with its reduction (FFRF, cached in ``cache_dir``) or mesh (nonlinear FE),
    their facts in attrs; returns it with the reduction's facts the summary reports (None
    for a case without a reduction)."""
    model = scene["coupler"]["model"]
    reduction = None
    if model == FFRF:
        reduction = reduction_for_scene(scene, cache_dir=cache_dir)
    elif model == NONLINEAR_FE:
        reduction = nonlinear_plate_for_scene(scene)  # the mesh and its node sets
    case = simulate_case(scene, name, reduction, cache_dir=cache_dir)
    facts = None
    if model == FFRF:
        case.attrs.update(reduction_key=reduction.key,
                          reduction_from_cache=reduction.from_cache,
                          reduction_build_time_s=reduction.build_time_s)
        facts = {key: getattr(reduction, key) for key in REDUCTION_FACTS}
    elif model == NONLINEAR_FE:
        case.attrs.update(fe_nodes=reduction.n_nodes, fe_dof=reduction.n_dof,
                          fe_elements=reduction.n_elements,
                          fe_mesh_time_s=reduction.build_time_s)
    return case, facts


def _plate_of(name: str, scene: Scene) -> Hashable | None:
    """The job of a case on an executor: a plate's reduced models together (they share its
    reduction, built once), the nonlinear FE reference alone."""
    return None if scene["coupler"]["model"] == NONLINEAR_FE else name.rsplit("_", 1)[0]


def _cost(name: str, scene: Scene) -> float:
    """A case's rough cost [s] for ordering the jobs: a nonlinear FE reference's steps
    (~0.1 s x 1 mm / thickness each), a reduced run with its error budget ~10 s."""
    if scene["coupler"]["model"] != NONLINEAR_FE:
        return 10.0
    return (scene["simulation"]["end_time_s"] / scene["simulation"]["step_s"]
            * 1e-4 / scene["coupler"]["thickness_m"])


def simulate_twins(scenes: dict[str, Scene], progress: Progress | None,
                   notes: dict[str, Any], *, cache_dir: Path | None = None,
                   executor: Any = None) -> dict[str, CaseResult]:
    """Simulate every case; each plate's reduction is built (or loaded from ``cache_dir``,
    the reduction cache folder; None: built in memory, no disk cache), and what the summary
    reports of it goes to ``notes`` (the run's, handed on to the summary). ``executor``
    (:mod:`flex.sweep`'s, passed in; None: this process): each plate's reduced models in one
    job, each nonlinear FE reference in its own, the longest first."""
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


def _pair_values(thickness_m: float, facts: dict[str, Any], flex_case: CaseResult,
                 rigid_case: CaseResult, length_m: float,
                 deployment_time_s: float) -> dict[str, tuple[Any, str, str]]:
    """One plate's summary values: (value, units, description) by key."""
    flex_data = {k: v.data for k, v in flex_case.datasets.items()}
    rigid_data = {k: v.data for k, v in rigid_case.datasets.items()}
    n = n_values(deployment_time_s, 2 * np.pi * facts["pinned_pinned_frequency_Hz"])
    peak = np.abs(flex_data["coupler/midpoint_deflection"]).max()
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
        "peak_midpoint_deflection": (peak, "m", "max |elastic midpoint deflection|, FFRF"),
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
        "peak_bending_stress": (
            flex_data.get("coupler/peak_bending_stress", np.array([np.nan])).max(), "Pa",
            "FFRF peak |sigma_xx|"),
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


def _reference_lines(scene: Scene, results: dict[str, CaseResult], plates: Plates,
                     datasets: dict[str, Dataset]) -> list[str]:
    """Each plate with a nonlinear FE run: every other model of it against that reference
    (``reference/<model>/...`` added to ``datasets``); the report lines."""
    lines = []
    for model, (thickness_m, _) in plates.items():
        reference = results.get(f"{model}_{NONLINEAR_FE}")
        if reference is None:
            continue
        euler_load_N = replace(Plate.of(scene["coupler"]), thickness_m=thickness_m).euler_load_N
        runs = {kind: results[f"{model}_{kind}"] for kind in KINDS
                if kind != NONLINEAR_FE and f"{model}_{kind}" in results}
        found, more = compare_with_reference(model, runs, reference, euler_load_N,
                                             f"reference/{model}")
        datasets.update(found)
        lines += more
    if not lines and is_damped(scene["coupler"]):
        lines.append("nonlinear FE reference: not run (the coupler is damped; the "
                     "nonlinear FE body has no damping model)")
    return lines


def summarize_twins(scene: Scene, results: dict[str, CaseResult], notes: dict[str, Any],
                    plates: Plates, deployment_time_s: float
                    ) -> tuple[dict[str, Dataset], str]:
    """The summary datasets and report: ``models/<model>/...`` per plate (see
    :func:`_pair_values`), each plate's models against its nonlinear FE reference
    (``reference/<model>/...``) and the report table. ``notes``: the run's, with the
    reductions' facts (:func:`simulate_twins`); ``deployment_time_s``: delta_t of n [s]."""
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
    lines += _reference_lines(scene, results, plates, datasets)
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


def _reference_figure(ok: dict[str, dict[str, np.ndarray]], models: list[str],
                      folder: Path) -> Path:
    """One panel per plate with a nonlinear FE run: the midpoint deflection of each model
    over the reference's span (own scale each)."""
    path = folder / "flexible-nonlinear-reference.png"
    styles = {FFRF: ("C0", "-", "FFRF (flex's default)"),
              "linear": ("C1", "-.", "linear FFRF"),
              NONLINEAR_FE: ("k", "--", "nonlinear FE (reference)")}
    with panels(path, "Midpoint deflection of each coupler model against the nonlinear FE "
                "reference, one panel per plate (own scale each)", rows=len(models),
                size=(7.5, 1.6 + 2.0 * len(models)), sharex=True) as (fig, axes):
        for ax, model in zip(axes, models, strict=True):
            samples = len(ok[f"{model}_{NONLINEAR_FE}"]["time"])
            for kind, (color, style, label) in styles.items():
                data = ok.get(f"{model}_{kind}")
                if data is not None:
                    ax.plot(data["time"][:samples],
                            np.asarray(data["coupler/midpoint_deflection"][:samples]) * 1e6,
                            color=color, ls=style, lw=1.0, label=label)
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
    against the nonlinear FE reference and the peak deflection against thickness (whichever
    have their runs); ``summary``: the summary datasets."""
    ok = {n: {k: v.data for k, v in c.datasets.items()} for n, c in results.items()
          if c.status == "ok"}
    drawn = [model for model in models if f"{model}_ffrf" in ok]
    paths = [_deflection_panels(ok, drawn, folder)] if drawn else []
    paths += [_acceleration_pair(model, ok[f"{model}_ffrf"], ok[f"{model}_rigid"], folder)
              for model in models if f"{model}_ffrf" in ok and f"{model}_rigid" in ok]
    referenced = [model for model in models if f"{model}_{NONLINEAR_FE}" in ok]
    if referenced:
        paths.append(_reference_figure(ok, referenced, folder))
    found = [model for model in models
             if f"models/{model}/peak_midpoint_deflection" in summary]
    if found:
        paths.append(_peak_figure(
            [float(summary[f"models/{m}/thickness_m"].data) * 1e3 for m in found],
            [float(summary[f"models/{m}/peak_midpoint_deflection"].data) * 1e6
             for m in found], folder))
    return paths
