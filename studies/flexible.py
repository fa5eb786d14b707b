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
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from flex.plotting import figure
from flex.results import CaseResult, Dataset
from flex.scene import Scene, apply_overrides, validate
from flex.solver import reduction_for_scene, simulate_case
from flex.study import Summary

NAME = "flexible"
DESCRIPTION = "FFRF coupler plates t = 1, 3, 5, 10 mm against their rigid twins"
OVERRIDES = ['coupler.geometry="plate"']

# Table 5 models: thickness [m] and the netgen mesh size used for each (about the thickness,
# at most 2t; quadratic tetrahedra converge within 0.1 % there, see the modal study)
MODELS = {"model0_t1mm": (0.001, 0.002), "model1_t3mm": (0.003, 0.003),
          "model2_t5mm": (0.005, 0.005), "model3_t10mm": (0.010, 0.005)}
THESIS_DEPLOYMENT_TIME_S = 0.016128  # thesis sec. 6.2, Table 5 note


def cases(scene: Scene) -> dict[str, Scene]:
    out = {}
    for model, (thickness_m, mesh_m) in MODELS.items():
        for kind in ("ffrf", "rigid"):
            case = apply_overrides(scene, [f"coupler.thickness_m={thickness_m}",
                                           f"coupler.mesh_size_m={mesh_m}",
                                           f'coupler.model="{kind}"'])
            validate(case)
            out[f"{model}_{kind}"] = case
    return out


def simulate_cases(scenes: dict[str, Scene],
                   progress: Callable[[str, int, int], None] | None) -> dict[str, CaseResult]:
    """Simulate every case; each model's reduction is built (or loaded) once."""
    results = {}
    for index, (name, scene) in enumerate(scenes.items()):
        if progress:
            progress(name, index, len(scenes))
        reduction = reduction_for_scene(scene) if scene["coupler"]["model"] == "ffrf" else None
        case = simulate_case(scene, name, reduction)
        if reduction is not None:
            case.attrs.update(reduction_key=reduction.key,
                              reduction_from_cache=reduction.from_cache,
                              reduction_build_time_s=reduction.build_time_s)
        results[name] = case
    if progress:
        progress("done", len(scenes), len(scenes))
    return results


def summarize(scene: Scene, results: dict[str, CaseResult]) -> Summary:
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
        n_thesis = THESIS_DEPLOYMENT_TIME_S * omega
        n_physical = n_thesis / (2 * np.pi)
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
                     f"{n_physical:8.2f} {peak * 1e6:15.3f} {peak / 0.08:9.2e} "
                     f"{crank_dev:13.2e} {stress / 1e6:11.2f} {wall:8.2f}")
    lines.append("  n thesis = delta_t * omega (thesis Table 5 takes T = 1/omega); "
                 "n 2pi/w = delta_t / T with the physical period; delta_t = 0.016128 s")
    return Summary(datasets, "\n".join(lines))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    ok = {n: {k: v.data for k, v in c.datasets.items()} for n, c in results.items()
          if c.status == "ok"}
    paths = []
    path = folder / "flexible-midpoint-deflection.png"
    with figure(path, "Elastic midpoint deflection of the coupler (cf. thesis figs. 47-50)",
                "time [s]", "deflection [um]") as ax:
        for model in MODELS:
            data = ok.get(f"{model}_ffrf")
            if data is not None:
                ax.plot(data["time"], data["coupler/midpoint_deflection"] * 1e6, label=model)
    paths.append(path)
    for model in MODELS:
        flex_data, rigid_data = ok.get(f"{model}_ffrf"), ok.get(f"{model}_rigid")
        if flex_data is None or rigid_data is None:
            continue
        path = folder / f"flexible-midpoint-acceleration-{model}.png"
        with figure(path, f"Coupler midpoint acceleration, {model} (cf. thesis figs. 35-42)",
                    "time [s]", "acceleration [m/s^2]") as ax:
            for column, axis in enumerate("xy"):
                ax.plot(flex_data["time"], flex_data["coupler/midpoint_acceleration"][:, column],
                        label=f"FFRF {axis}", lw=0.8)
                ax.plot(rigid_data["time"],
                        rigid_data["coupler/midpoint_acceleration"][:, column], "--",
                        label=f"rigid twin {axis}")
        paths.append(path)
    thickness, peak = [], []
    for model in MODELS:
        key = f"models/{model}/peak_midpoint_deflection"
        if key in summary.datasets:
            thickness.append(summary.datasets[f"models/{model}/thickness_m"].data * 1e3)
            peak.append(summary.datasets[key].data * 1e6)
    if thickness:
        path = folder / "flexible-peak-deflection.png"
        with figure(path, "Peak elastic midpoint deflection against plate thickness",
                    "thickness [mm]", "peak deflection [um]") as ax:
            ax.loglog(thickness, peak, "o-")
        paths.append(path)
    return paths


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
