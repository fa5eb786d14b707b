"""FFRF plate couplers beside their rigid twins, with a nonlinear FE reference.

A *twin pair* models one steel plate coupler twice in the same mechanism: as a
floating-frame-of-reference body (NGsolve mesh, Hurty-Craig-Bampton reduction) and as its
rigid twin, a rigid body with the plate's own mass and inertia, so the pair differs only by
elasticity. :func:`twin_cases` builds the pairs of a table of plates (``{model:
(thickness [m], mesh size [m])}``) and, for an undamped scene, the fully nonlinear FE coupler
(:mod:`flex.bodies.nonlinear`) of one of them; :func:`simulate_twins` runs them, each reduction
built (or loaded from the cache) once, its facts kept in the run's notes;
:func:`summarize_twins` tabulates, per plate, the reduction's frequencies and mesh, the
thesis's n = delta_t / T in both period conventions and the FFRF run's deviations from its
twin, and compares the nonlinear FE run with its FFRF twin
(:func:`flex.fidelity.softening.compare_with_nonlinear_fe`); :func:`twin_figures` draws them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from flex.base.physics import n_values
from flex.base.plotting import MICRO, figure, legend_below, panels
from flex.bodies.nonlinear import nonlinear_plate_for_scene
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, apply_overrides, validate
from flex.dynamics.solver import reduction_for_scene
from flex.fidelity.caseloop import Progress, run_each
from flex.fidelity.simulation import simulate_case
from flex.fidelity.softening import compare_with_nonlinear_fe, coupler_euler_load_N

Plates = dict[str, tuple[float, float]]  # model -> (thickness [m], mesh size [m])
#: what the summary reports of each FFRF case's reduction (``notes["reductions"][case]``)
REDUCTION_FACTS = ("pinned_pinned_frequency_Hz", "fixed_interface_frequencies_Hz", "n_nodes",
                   "n_elements", "n_dof", "mass_kg")


def _plate_case(scene: Scene, thickness_m: float, mesh_m: float, model: str,
                *more: str) -> Scene:
    """``scene`` with a plate coupler ``thickness_m`` thick meshed at ``mesh_m`` [m], modelled
    as ``model``, and the overrides ``more``; validated."""
    case = apply_overrides(scene, [f"coupler.thickness_m={thickness_m}",
                                   f"coupler.mesh_size_m={mesh_m}", f'coupler.model="{model}"',
                                   *more])
    validate(case)
    return case


def twin_cases(scene: Scene, plates: Plates, nonlinear_model: str,
               nonlinear_end_time_s: float | None = None) -> dict[str, Scene]:
    """``<model>_ffrf`` and ``<model>_rigid`` per plate; ``<nonlinear_model>_nonlinear_fe``
    too when the scene is undamped (the nonlinear FE body has no damping), run to
    ``nonlinear_end_time_s`` [s] (None: the scene's end time)."""
    out = {f"{model}_{kind}": _plate_case(scene, thickness_m, mesh_m, kind)
           for model, (thickness_m, mesh_m) in plates.items() for kind in ("ffrf", "rigid")}
    if scene["coupler"]["damping_ratio"] == 0:
        end_time = ([] if nonlinear_end_time_s is None
                    else [f"simulation.end_time_s={nonlinear_end_time_s}"])
        out[f"{nonlinear_model}_nonlinear_fe"] = _plate_case(
            scene, *plates[nonlinear_model], "nonlinear_fe", *end_time)
    return out


def _simulate_one(name: str, scene: Scene, notes: dict[str, Any],
                  cache_dir: Path | None) -> CaseResult:
    """One case with its reduction (FFRF, cached in ``cache_dir``) or mesh (nonlinear FE);
    their facts in attrs, the reduction's in ``notes["reductions"][name]``."""
    model = scene["coupler"]["model"]
    reduction = None
    if model == "ffrf":
        reduction = reduction_for_scene(scene, cache_dir=cache_dir)
    elif model == "nonlinear_fe":
        reduction = nonlinear_plate_for_scene(scene)  # the mesh and its node sets
    case = simulate_case(scene, name, reduction, cache_dir=cache_dir)
    if model == "ffrf":
        case.attrs.update(reduction_key=reduction.key,
                          reduction_from_cache=reduction.from_cache,
                          reduction_build_time_s=reduction.build_time_s)
        notes.setdefault("reductions", {})[name] = {
            key: getattr(reduction, key) for key in REDUCTION_FACTS}
    elif model == "nonlinear_fe":
        case.attrs.update(fe_nodes=reduction.n_nodes, fe_dof=reduction.n_dof,
                          fe_elements=reduction.n_elements,
                          fe_mesh_time_s=reduction.build_time_s)
    return case


def simulate_twins(scenes: dict[str, Scene], progress: Progress | None,
                   notes: dict[str, Any], *, cache_dir: Path | None = None
                   ) -> dict[str, CaseResult]:
    """Simulate every case; each plate's reduction is built (or loaded from ``cache_dir``,
    the reduction cache folder; None: built in memory, no disk cache), and what the summary
    reports of it goes to ``notes`` (the run's, handed on to the summary)."""
    return run_each(scenes, lambda name, scene: _simulate_one(name, scene, notes, cache_dir),
                    progress)


HEADER = (f"  {'model':14s} {'t [mm]':>6s} {'f_pp [Hz]':>10s} {'n thesis':>9s} "
          f"{'n 2pi/w':>8s} {'peak defl [um]':>15s} {'defl/L2':>9s} "
          f"{'d crank [rad]':>13s} {'sigma [MPa]':>11s} {'wall [s]':>8s}")


def _pair_values(thickness_m: float, facts: dict[str, Any], flex_case: CaseResult,
                 rigid_case: CaseResult, length_m: float,
                 deployment_time_s: float) -> dict[str, tuple[Any, str, str]]:
    """One plate's summary values: (value, units, description) by key."""
    flex_data = {k: v.data for k, v in flex_case.datasets.items()}
    rigid_data = {k: v.data for k, v in rigid_case.datasets.items()}
    n = n_values(deployment_time_s, 2 * np.pi * facts["pinned_pinned_frequency_Hz"])
    peak = np.abs(flex_data["coupler/midpoint_deflection"]).max()
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
        "peak_midpoint_deflection": (peak, "m", "max |elastic midpoint deflection|"),
        "peak_deflection_over_length": (peak / length_m, "1", "peak deflection / L2"),
        "max_crank_angle_deviation": (
            np.abs(flex_data["crank/angle"] - rigid_data["crank/angle"]).max(), "rad",
            "max |FFRF - rigid twin|"),
        "max_slider_position_deviation": (
            np.abs(flex_data["slider/position"] - rigid_data["slider/position"]).max(), "m",
            "max |FFRF - rigid twin|"),
        "peak_bending_stress": (
            flex_data.get("coupler/peak_bending_stress", np.array([np.nan])).max(), "Pa",
            "FFRF peak |sigma_xx|"),
        "ffrf_wall_time": (flex_case.counters["wall_time_s"], "s", "FFRF simulation wall time"),
        "rigid_wall_time": (rigid_case.counters["wall_time_s"], "s",
                            "rigid twin simulation wall time"),
    }


def _row(model: str, v: dict[str, Any]) -> str:
    """One plate's line of the report table (``v``: values by key, without units)."""
    return (f"  {model:14s} {v['thickness_m'] * 1e3:6.0f} "
            f"{v['pinned_pinned_frequency_Hz']:10.1f} {v['n_thesis_convention']:9.1f} "
            f"{v['n_physical']:8.2f} {v['peak_midpoint_deflection'] * 1e6:15.3f} "
            f"{v['peak_deflection_over_length']:9.2e} "
            f"{v['max_crank_angle_deviation']:13.2e} {v['peak_bending_stress'] / 1e6:11.2f} "
            f"{v['ffrf_wall_time']:8.2f}")


def _nonlinear_lines(scene: Scene, results: dict[str, CaseResult], plates: Plates,
                     model: str, datasets: dict[str, Dataset]) -> list[str]:
    """Compare the nonlinear FE run with its FFRF twin (``nonlinear_reference/<model>/...``
    added to ``datasets``); the report lines."""
    if f"{model}_nonlinear_fe" not in results:
        return [f"nonlinear FE reference {model}: not run (coupler.damping_ratio > 0; the "
                f"nonlinear FE body has no damping model)"]
    euler_load_N = coupler_euler_load_N({**scene["coupler"], "thickness_m": plates[model][0]})
    found, lines = compare_with_nonlinear_fe(model, results[f"{model}_ffrf"],
                                             results[f"{model}_nonlinear_fe"], euler_load_N,
                                             f"nonlinear_reference/{model}")
    datasets.update(found)
    return lines


def summarize_twins(scene: Scene, results: dict[str, CaseResult], notes: dict[str, Any],
                    plates: Plates, nonlinear_model: str, deployment_time_s: float
                    ) -> tuple[dict[str, Dataset], str]:
    """The summary datasets and report: ``models/<model>/...`` per plate (see
    :func:`_pair_values`), the nonlinear reference (``nonlinear_reference/<model>/...``) and
    the report table. ``notes``: the run's, with the reductions' facts
    (:func:`simulate_twins`); ``deployment_time_s``: delta_t of n [s]."""
    datasets: dict[str, Dataset] = {}
    lines = ["flexible: FFRF coupler plates against their rigid twins (22 mm preload)", HEADER]
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
    lines.append("  n thesis = delta_t * omega (thesis Table 5 takes T = 1/omega); "
                 f"n 2pi/w = delta_t / T with the physical period; delta_t = "
                 f"{deployment_time_s:g} s")
    lines += _nonlinear_lines(scene, results, plates, nonlinear_model, datasets)
    return datasets, "\n".join(lines)


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


def _nonlinear_figure(model: str, flex_data: dict[str, np.ndarray],
                      nonlinear_data: dict[str, np.ndarray], folder: Path) -> Path:
    """Midpoint deflection of the FFRF run against the nonlinear FE run over its span."""
    path = folder / "flexible-nonlinear-reference.png"
    samples = len(nonlinear_data["time"])
    with figure(path, f"Midpoint deflection, {model_label(model)}: FFRF (linear elastic "
                "body) against the nonlinear FE body", "time [s]",
                f"midpoint deflection [{UM}]") as ax:
        ax.plot(flex_data["time"][:samples],
                flex_data["coupler/midpoint_deflection"][:samples] * 1e6, label="FFRF")
        ax.plot(nonlinear_data["time"], nonlinear_data["coupler/midpoint_deflection"] * 1e6,
                "k--", label="nonlinear FE (reference)")
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
                 models: list[str], nonlinear_model: str) -> list[Path]:
    """The deflection panels, each plate's accelerations against its twin, the nonlinear
    reference and the peak deflection against thickness (whichever have their runs);
    ``summary``: the summary datasets."""
    ok = {n: {k: v.data for k, v in c.datasets.items()} for n, c in results.items()
          if c.status == "ok"}
    drawn = [model for model in models if f"{model}_ffrf" in ok]
    paths = [_deflection_panels(ok, drawn, folder)] if drawn else []
    paths += [_acceleration_pair(model, ok[f"{model}_ffrf"], ok[f"{model}_rigid"], folder)
              for model in models if f"{model}_ffrf" in ok and f"{model}_rigid" in ok]
    if f"{nonlinear_model}_ffrf" in ok and f"{nonlinear_model}_nonlinear_fe" in ok:
        paths.append(_nonlinear_figure(nonlinear_model, ok[f"{nonlinear_model}_ffrf"],
                                       ok[f"{nonlinear_model}_nonlinear_fe"], folder))
    found = [model for model in models
             if f"models/{model}/peak_midpoint_deflection" in summary]
    if found:
        paths.append(_peak_figure(
            [float(summary[f"models/{m}/thickness_m"].data) * 1e3 for m in found],
            [float(summary[f"models/{m}/peak_midpoint_deflection"].data) * 1e6
             for m in found], folder))
    return paths
