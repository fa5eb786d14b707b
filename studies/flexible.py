"""Study ``flexible`` (thesis sec. 6.2, figs. 35-50): FFRF couplers of four thicknesses.

The coupler becomes a steel plate 0.08 x 0.01 x t (Table 5, models 0-3: t = 1, 3, 5, 10 mm)
modelled twice in the same mechanism: as a floating-frame-of-reference body (NGsolve mesh,
Hurty-Craig-Bampton reduction with the joint faces as interfaces) and as its rigid twin, a
rigid body with the plate's own mass and inertia, so the pair differs only by elasticity.
The spring deployment is the thesis scene (22 mm preload reading, undamped).

Stored per case: the rigid-body quantities, ``coupler/midpoint_deflection`` (elastic,
relative to the chord B-C), ``coupler/chord_change``, ``coupler/midpoint_acceleration``,
``coupler/modal_coordinates``, ``coupler/peak_bending_stress``; per model under
``/summary/models/<model>``: the reduction's frequencies, mesh statistics and the
deviations of the FFRF run from its rigid twin, and n = delta_t / T in both period
conventions (thesis: T = 1/omega; physical: T = 2 pi / omega).

Accuracy reference: the thinnest model also runs with the fully nonlinear FE coupler
(:mod:`flex.nonlinear`: the same mesh, Green-Lagrange strain, no reduction) over
``NONLINEAR_END_TIME_S`` (default: the whole deployment); ``/summary/nonlinear_reference/
<model>`` holds its first and largest deflection peaks against the FFRF run's over the same
span, the largest difference of the two curves, the axial load of the link against its
Euler load (the geometric softening the linear FFRF body leaves out) and both wall times.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from flex.nonlinear import nonlinear_plate_for_scene
from flex.physics import euler_buckling_load_N, n_values
from flex.plotting import figure
from flex.results import CaseResult, Dataset
from flex.scene import Scene, apply_overrides, validate
from flex.settings import pinned_overrides
from flex.simulation import simulate_case
from flex.solver import reduction_for_scene
from flex.study import StudyRun, Summary
from flex.thesis import THESIS_DELTA_T_S

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
    out = {}
    for model, (thickness_m, mesh_m) in MODELS.items():
        for kind in ("ffrf", "rigid"):
            case = apply_overrides(scene, [f"coupler.thickness_m={thickness_m}",
                                           f"coupler.mesh_size_m={mesh_m}",
                                           f'coupler.model="{kind}"'])
            validate(case)
            out[f"{model}_{kind}"] = case
    if scene["coupler"]["damping_ratio"] != 0:  # the nonlinear FE body has no damping
        return out
    thickness_m, mesh_m = MODELS[NONLINEAR_MODEL]
    end_time = ([] if NONLINEAR_END_TIME_S is None
                else [f"simulation.end_time_s={NONLINEAR_END_TIME_S}"])
    case = apply_overrides(scene, [f"coupler.thickness_m={thickness_m}",
                                   f"coupler.mesh_size_m={mesh_m}",
                                   'coupler.model="nonlinear_fe"', *end_time])
    validate(case)
    out[f"{NONLINEAR_MODEL}_nonlinear_fe"] = case
    return out


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Simulate every case; each model's reduction is built (or loaded) once."""
    progress = run.progress
    results = {}
    for index, (name, scene) in enumerate(scenes.items()):
        if progress:
            progress(name, index, len(scenes))
        model = scene["coupler"]["model"]
        reduction = None
        if model == "ffrf":
            reduction = reduction_for_scene(scene)
        elif model == "nonlinear_fe":
            reduction = nonlinear_plate_for_scene(scene)  # the mesh and its node sets
        case = simulate_case(scene, name, reduction)
        if model == "ffrf":
            case.attrs.update(reduction_key=reduction.key,
                              reduction_from_cache=reduction.from_cache,
                              reduction_build_time_s=reduction.build_time_s)
        elif model == "nonlinear_fe":
            case.attrs.update(fe_nodes=reduction.n_nodes, fe_dof=reduction.n_dof,
                              fe_elements=reduction.n_elements,
                              fe_mesh_time_s=reduction.build_time_s)
        results[name] = case
    if progress:
        progress("done", len(scenes), len(scenes))
    return results


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    datasets: dict[str, Dataset] = {}
    lines = ["flexible: FFRF coupler plates against their rigid twins (22 mm preload)",
             f"  {'model':14s} {'t [mm]':>6s} {'f_pp [Hz]':>10s} {'n thesis':>9s} "
             f"{'n 2pi/w':>8s} {'peak defl [um]':>15s} {'defl/L2':>9s} "
             f"{'d crank [rad]':>13s} {'sigma [MPa]':>11s} {'wall [s]':>8s}"]
    for model, (thickness_m, _) in MODELS.items():
        flex_case, rigid_case = results[f"{model}_ffrf"], results[f"{model}_rigid"]
        if flex_case.status != "ok" or rigid_case.status != "ok":
            lines.append(f"  {model}: failed: {flex_case.message or rigid_case.message}")
            continue
        scene_case = cases(scene)[f"{model}_ffrf"]
        reduction = reduction_for_scene(scene_case)  # cached: loads in well under a second
        flex_data = {k: v.data for k, v in flex_case.datasets.items()}
        rigid_data = {k: v.data for k, v in rigid_case.datasets.items()}
        omega = 2 * np.pi * reduction.pinned_pinned_frequency_Hz
        n = n_values(THESIS_DEPLOYMENT_TIME_S, omega)
        n_thesis, n_physical = n["thesis"], n["physical"]
        peak = np.abs(flex_data["coupler/midpoint_deflection"]).max()
        crank_dev = np.abs(flex_data["crank/angle"] - rigid_data["crank/angle"]).max()
        slider_dev = np.abs(flex_data["slider/position"] - rigid_data["slider/position"]).max()
        stress = flex_data.get("coupler/peak_bending_stress", np.array([np.nan])).max()
        wall = flex_case.counters["wall_time_s"]
        group = f"models/{model}"
        values = {
            "thickness_m": (thickness_m, "m", "plate thickness (in-plane bending height)"),
            "pinned_pinned_frequency_Hz": (reduction.pinned_pinned_frequency_Hz, "Hz",
                                           "first in-plane bending mode of the reduced body"),
            "fixed_interface_frequencies_Hz": (reduction.fixed_interface_frequencies_Hz, "Hz",
                                               "Craig-Bampton fixed-interface modes"),
            "mesh_nodes": (reduction.n_nodes, "1", "mesh nodes (second-order tetrahedra)"),
            "mesh_elements": (reduction.n_elements, "1", "second-order tetrahedra"),
            "mesh_dof": (reduction.n_dof, "1", "unreduced degrees of freedom"),
            "plate_mass": (reduction.mass_kg, "kg", "plate mass (also the rigid twin's)"),
            "n_thesis_convention": (n_thesis, "1", "delta_t * omega (thesis: T = 1/omega)"),
            "n_physical": (n_physical, "1", "delta_t / (2 pi / omega)"),
            "peak_midpoint_deflection": (peak, "m", "max |elastic midpoint deflection|"),
            "peak_deflection_over_length": (peak / scene["coupler"]["length_m"], "1",
                                            "peak deflection / L2"),
            "max_crank_angle_deviation": (crank_dev, "rad", "max |FFRF - rigid twin|"),
            "max_slider_position_deviation": (slider_dev, "m", "max |FFRF - rigid twin|"),
            "peak_bending_stress": (stress, "Pa", "FFRF peak |sigma_xx|"),
            "ffrf_wall_time": (wall, "s", "FFRF simulation wall time"),
            "rigid_wall_time": (rigid_case.counters["wall_time_s"], "s",
                                "rigid twin simulation wall time"),
        }
        for key, (value, unit, text) in values.items():
            datasets[f"{group}/{key}"] = Dataset(value, unit, text)
        lines.append(f"  {model:14s} {thickness_m * 1e3:6.0f} "
                     f"{reduction.pinned_pinned_frequency_Hz:10.1f} {n_thesis:9.1f} "
                     f"{n_physical:8.2f} {peak * 1e6:15.3f} "
                     f"{values['peak_deflection_over_length'][0]:9.2e} "
                     f"{crank_dev:13.2e} {stress / 1e6:11.2f} {wall:8.2f}")
    lines.append("  n thesis = delta_t * omega (thesis Table 5 takes T = 1/omega); "
                 f"n 2pi/w = delta_t / T with the physical period; delta_t = "
                 f"{THESIS_DEPLOYMENT_TIME_S:g} s")
    lines += nonlinear_reference(scene, results, datasets)
    return Summary(datasets, "\n".join(lines))


def first_peak_index(deflection: np.ndarray) -> int:
    """Index of the first extreme: the largest |deflection| of the first lobe.

    The first lobe starts where |deflection| first exceeds 10 % of its largest value and
    ends where the deflection changes sign (or with the series), so the ripple of higher
    modes riding on the first swing does not count as a peak.
    """
    magnitude = np.abs(deflection)
    start = int(np.argmax(magnitude > 0.1 * magnitude.max()))
    sign_changes = np.flatnonzero(np.sign(deflection[start:]) != np.sign(deflection[start]))
    end = start + int(sign_changes[0]) if len(sign_changes) else len(deflection)
    return start + int(np.argmax(magnitude[start:end]))


def nonlinear_reference(scene: Scene, results: dict[str, CaseResult],
                        datasets: dict[str, Dataset]) -> list[str]:
    """Compare the nonlinear FE run with the FFRF run of the same plate; return report lines.

    Adds ``nonlinear_reference/<model>/...`` to ``datasets``. Both runs share the step and
    the samples, so the curves are compared sample by sample over the nonlinear run's span.
    The axial load is the compression of the link (joint C force along the chord B-C) in the
    FFRF run; the Euler load of the pinned-pinned plate is pi^2 E I / L^2, I = w t^3 / 12.
    """
    model = NONLINEAR_MODEL
    if f"{model}_nonlinear_fe" not in results:
        return [f"nonlinear FE reference {model}: not run (coupler.damping_ratio > 0; the "
                f"nonlinear FE body has no damping model)"]
    nonlinear_case, flex_case = results[f"{model}_nonlinear_fe"], results[f"{model}_ffrf"]
    if nonlinear_case.status != "ok" or flex_case.status != "ok":
        return [f"nonlinear FE reference {model}: failed: "
                f"{nonlinear_case.message or flex_case.message}"]
    nonlinear = {k: v.data for k, v in nonlinear_case.datasets.items()}
    flexible = {k: v.data for k, v in flex_case.datasets.items()}
    samples = len(nonlinear["time"])
    time_s = flexible["time"][:samples]
    if len(time_s) != samples or not np.allclose(time_s, nonlinear["time"], rtol=0,
                                                 atol=1e-12):
        return [f"nonlinear FE reference {model}: the two runs have different time samples"]
    curves = {"ffrf": flexible["coupler/midpoint_deflection"][:samples],
              "nonlinear_fe": nonlinear["coupler/midpoint_deflection"]}
    values: dict[str, tuple[object, str, str]] = {
        "span_end_time": (float(time_s[-1]), "s", "both runs compared over 0 .. this time"),
        "fe_dof": (nonlinear_case.attrs.get("fe_dof", -1), "1",
                   "coordinates of the nonlinear FE body (3 per mesh node)"),
    }
    for name, curve in curves.items():
        label = "FFRF" if name == "ffrf" else "nonlinear FE"
        first, largest = first_peak_index(curve), int(np.argmax(np.abs(curve)))
        values[f"first_peak_deflection_{name}"] = (float(curve[first]), "m",
                                                   f"first deflection extreme (signed), {label}")
        values[f"first_peak_time_{name}"] = (float(time_s[first]), "s",
                                             f"time of the first extreme, {label}")
        values[f"peak_deflection_{name}"] = (float(np.abs(curve[largest])), "m",
                                             f"max |midpoint deflection| over the span, {label}")
        values[f"peak_time_{name}"] = (float(time_s[largest]), "s",
                                       f"time of that peak, {label}")
    first_ratio = (values["first_peak_deflection_nonlinear_fe"][0]
                   / values["first_peak_deflection_ffrf"][0])
    peak_ratio = values["peak_deflection_nonlinear_fe"][0] / values["peak_deflection_ffrf"][0]
    deviation = np.abs(curves["nonlinear_fe"] - curves["ffrf"])
    worst = int(np.argmax(deviation))
    chord = np.column_stack([np.cos(flexible["coupler/angle"][:samples]),
                             np.sin(flexible["coupler/angle"][:samples])])
    compression_N = np.einsum("ij,ij->i", flexible["joints/C/force_on_coupler"][:samples],
                              -chord)  # the slider pushes C toward B
    plate = cases(scene)[f"{model}_nonlinear_fe"]["coupler"]
    euler_load_N = euler_buckling_load_N(plate["length_m"], plate["thickness_m"],
                                         plate["width_m"], plate["youngs_modulus_Pa"])
    walls = {name: case.counters["wall_time_s"]
             for name, case in (("ffrf", flex_case), ("nonlinear_fe", nonlinear_case))}
    steps = {name: max(int(case.counters["steps"]), 1)
             for name, case in (("ffrf", flex_case), ("nonlinear_fe", nonlinear_case))}
    values.update({
        "first_peak_ratio": (first_ratio, "1", "first extreme, nonlinear FE / FFRF"),
        "peak_deflection_ratio": (peak_ratio, "1", "largest peak, nonlinear FE / FFRF"),
        "max_deflection_deviation": (float(deviation[worst]), "m",
                                     "max |nonlinear FE - FFRF| midpoint deflection over the "
                                     "span"),
        "max_deflection_deviation_over_ffrf_peak": (
            float(deviation[worst]) / values["peak_deflection_ffrf"][0], "1",
            "that deviation / the FFRF peak"),
        "time_of_max_deflection_deviation": (float(time_s[worst]), "s", "where it occurs"),
        "max_crank_angle_deviation": (
            float(np.abs(nonlinear["crank/angle"] - flexible["crank/angle"][:samples]).max()),
            "rad", "max |nonlinear FE - FFRF| crank angle over the span"),
        "max_midpoint_out_of_plane": (
            float(np.abs(nonlinear["coupler/midpoint_out_of_plane"]).max()), "m",
            "nonlinear FE: max |z| of the midpoint (face-marker tilt artefact; 0 ideal)"),
        "max_compression_over_euler_load": (float(compression_N.max()) / euler_load_N, "1",
                                            "max axial compression (FFRF joint C force along "
                                            "B-C) / pinned-pinned Euler load"),
        "euler_load": (euler_load_N, "N", "pi^2 E I / L^2 of the plate (I = w t^3 / 12)"),
    })
    for name, label in (("ffrf", "FFRF"), ("nonlinear_fe", "nonlinear FE")):
        values[f"{name}_wall_time"] = (walls[name], "s", f"{label} run wall time (its whole "
                                       "end time)")
        values[f"{name}_wall_time_per_step"] = (walls[name] / steps[name], "s",
                                                f"{label} wall time per step")
    for key, (value, unit, text) in values.items():
        datasets[f"nonlinear_reference/{model}/{key}"] = Dataset(value, unit, text)

    def peak(name: str, kind: str) -> str:
        deflection = values[f"{kind}_deflection_{name}"][0]
        return f"{deflection * 1e6:.1f} um at {values[f'{kind}_time_{name}'][0] * 1e3:.2f} ms"

    return [
        f"nonlinear FE reference, {model} ({values['fe_dof'][0]} coordinates, the same mesh, "
        f"0 .. {time_s[-1] * 1e3:.1f} ms):",
        f"  first peak    FFRF {peak('ffrf', 'first_peak')}, nonlinear FE "
        f"{peak('nonlinear_fe', 'first_peak')} (ratio {first_ratio:.3f})",
        f"  largest peak  FFRF {peak('ffrf', 'peak')}, nonlinear FE "
        f"{peak('nonlinear_fe', 'peak')} (ratio {peak_ratio:.3f})",
        f"  max |difference| of the curves {deviation[worst] * 1e6:.1f} um "
        f"({values['max_deflection_deviation_over_ffrf_peak'][0]:.1%} of the FFRF peak) at "
        f"{time_s[worst] * 1e3:.2f} ms; crank angle "
        f"{values['max_crank_angle_deviation'][0]:.2e} rad; midpoint out of plane "
        f"{values['max_midpoint_out_of_plane'][0]:.1e} m",
        f"  axial compression up to {compression_N.max():.1f} N = "
        f"{compression_N.max() / euler_load_N:.2f} of the Euler load {euler_load_N:.0f} N "
        f"(geometric softening, absent from the linear FFRF body)",
        f"  wall time: FFRF {walls['ffrf']:.1f} s for {steps['ffrf']} steps "
        f"({walls['ffrf'] / steps['ffrf'] * 1e3:.2f} ms/step), nonlinear FE "
        f"{walls['nonlinear_fe']:.1f} s for {steps['nonlinear_fe']} steps "
        f"({walls['nonlinear_fe'] / steps['nonlinear_fe'] * 1e3:.0f} ms/step)",
    ]


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    from flex.plotting import MICRO, legend_below, panels

    ok = {n: {k: v.data for k, v in c.datasets.items()} for n, c in results.items()
          if c.status == "ok"}
    paths = []
    um = f"{MICRO}m"
    drawn = [model for model in MODELS if f"{model}_ffrf" in ok]
    if drawn:
        # per-model panels: the peaks differ by two orders of magnitude (180 um at 1 mm,
        # under 1 um at 10 mm), one shared scale would flatten the stiffer plates
        path = folder / "flexible-midpoint-deflection.png"
        with panels(path, "Elastic midpoint deflection of the FFRF coupler, one panel per "
                    "plate thickness (own scale each; cf. thesis figs. 47-50)",
                    rows=len(drawn), size=(7.5, 1.4 + 1.9 * len(drawn)), sharex=True
                    ) as (_, axes):
            for index, (ax, model) in enumerate(zip(axes, drawn, strict=True)):
                data = ok[f"{model}_ffrf"]
                deflection = np.asarray(data["coupler/midpoint_deflection"]) * 1e6
                ax.plot(data["time"], deflection, color=f"C{index}", lw=1.0)
                ax.set_title(f"{_model_label(model)}: peak |deflection| "
                             f"{np.abs(deflection).max():.3g} {um}", fontsize="small")
                ax.set_ylabel(f"deflection [{um}]")
                ax.axhline(0.0, color="k", lw=0.5)
            axes[-1].set_xlabel("time [s]")
        paths.append(path)
    for model in MODELS:
        flex_data, rigid_data = ok.get(f"{model}_ffrf"), ok.get(f"{model}_rigid")
        if flex_data is None or rigid_data is None:
            continue
        path = folder / f"flexible-midpoint-acceleration-{model}.png"
        with panels(path, f"Coupler midpoint acceleration, {_model_label(model)}: FFRF "
                    "coupler against its rigid twin (cf. thesis figs. 35-42)", rows=2,
                    size=(7.5, 6.0), sharex=True) as (fig, axes):
            for column, (ax, axis) in enumerate(zip(axes, "xy", strict=True)):
                ax.plot(flex_data["time"], flex_data["coupler/midpoint_acceleration"][:, column],
                        color="C0", lw=0.6, label="FFRF (flexible coupler)")
                ax.plot(rigid_data["time"],
                        rigid_data["coupler/midpoint_acceleration"][:, column], "k--", lw=1.4,
                        label="rigid twin")
                ax.set_ylabel(f"{axis} acceleration [m/s\u00b2]")
            axes[-1].set_xlabel("time [s]")
            legend_below(fig)
        paths.append(path)
    flex_data = ok.get(f"{NONLINEAR_MODEL}_ffrf")
    nonlinear_data = ok.get(f"{NONLINEAR_MODEL}_nonlinear_fe")
    if flex_data is not None and nonlinear_data is not None:
        path = folder / "flexible-nonlinear-reference.png"
        samples = len(nonlinear_data["time"])
        with figure(path, f"Midpoint deflection, {_model_label(NONLINEAR_MODEL)}: FFRF "
                    "(linear elastic body) against the nonlinear FE body",
                    "time [s]", f"midpoint deflection [{um}]") as ax:
            ax.plot(flex_data["time"][:samples],
                    flex_data["coupler/midpoint_deflection"][:samples] * 1e6, label="FFRF")
            ax.plot(nonlinear_data["time"],
                    nonlinear_data["coupler/midpoint_deflection"] * 1e6, "k--",
                    label="nonlinear FE (reference)")
        paths.append(path)
    thickness, peak = [], []
    for model in MODELS:
        key = f"models/{model}/peak_midpoint_deflection"
        if key in summary.datasets:
            thickness.append(float(summary.datasets[f"models/{model}/thickness_m"].data) * 1e3)
            peak.append(float(summary.datasets[key].data) * 1e6)
    if thickness:
        path = folder / "flexible-peak-deflection.png"
        with figure(path, "Peak elastic midpoint deflection of the coupler against plate "
                    "thickness", "plate thickness t [mm] (log scale)",
                    f"peak |midpoint deflection| [{um}]") as ax:
            ax.loglog(thickness, peak, "o-", label="FFRF runs")
            if len(thickness) >= 2 and min(peak) > 0:
                slope, _ = np.polyfit(np.log(thickness), np.log(peak), 1)
                ax.plot([], [], " ", label=f"fitted slope: peak \u221d $t^{{{slope:.2f}}}$")
            ax.set_xticks(thickness, [f"{t:g}" for t in thickness])
            ax.minorticks_off()
            for t, p in zip(thickness, peak, strict=True):
                ax.annotate(f"{p:.3g} {um}", (t, p), xytext=(6, 4), textcoords="offset points",
                            fontsize="small")
        paths.append(path)
    return paths


def _model_label(model: str) -> str:
    """``model1_t3mm`` -> ``model 1, t = 3 mm`` (Table 5 model and plate thickness)."""
    number, _, thickness = model.partition("_t")
    return f"model {number.removeprefix('model')}, t = {thickness.removesuffix('mm')} mm"

if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
