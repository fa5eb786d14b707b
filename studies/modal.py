"""Study ``modal`` (thesis sec. 6.2-6.3, Tables 5, 7, 9): eigenmodes of the links.

Each link is meshed as a steel plate (NGsolve, second-order tetrahedra): the coupler
0.08 x 0.01 x t for the four Table 5 models, the crank 0.04 x 0.01 x 0.01. First five modes
free-free and with the mechanism's joint conditions (pinned-pinned: each end face pinned
about z at its centre), each classified (in-plane / out-of-plane bending, torsion, axial) and
compared with Euler-Bernoulli and Timoshenko beam theory. Table 5 is reproduced in both
period conventions (thesis T = 1/omega; physical T = 2 pi/omega) with n = delta_t / T;
Tables 7 and 9 (ANSYS BEAM188, units and sections not stated) with flex's reading of them.
Mesh convergence is part of the result: per model the element count, DOF and frequency of
each refinement level, and the production mesh (coarsest level within tolerance).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from flex import modal
from flex.plotting import figure
from flex.results import CaseResult, Dataset
from flex.scene import Scene
from flex.study import Summary

NAME = "modal"
DESCRIPTION = "link eigenmodes: FE vs beam theory, Tables 5, 7, 9, mesh convergence"
OVERRIDES: list[str] = []
# keys the study reads itself (its modal analyses), beside what its cases simulate
READS = ("coupler.length_m", "coupler.width_m", "coupler.youngs_modulus_Pa",
         "coupler.density_kg_per_m3", "coupler.poisson_ratio", "crank.length_m")
CONVERGENCE_TOLERANCE = 0.001  # relative, on the first pinned-pinned in-plane frequency
CRANK_SECTION_M = (0.010, 0.010)  # flex's reading of the thesis's ANSYS section (Table 7)


def cases(scene: Scene) -> dict[str, Scene]:
    return {}


def _unit(key: str) -> str:
    for suffix, unit in (("_rad_per_s", "rad/s"), ("_Hz", "Hz"), ("_s", "s"), ("_m", "m")):
        if key.endswith(suffix):
            return unit
    return "1"


def _store(datasets: dict[str, Dataset], prefix: str, table: dict) -> None:
    for key, value in table.items():
        array = np.asarray(value)
        if array.dtype.kind in "US":
            array = array.astype(object)
        datasets[f"{prefix}/{key}"] = Dataset(array, _unit(key), key.replace("_", " "))


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    datasets: dict[str, Dataset] = {}
    coupler = scene["coupler"]
    material = modal.Material(coupler["youngs_modulus_Pa"], coupler["density_kg_per_m3"],
                              coupler["poisson_ratio"])
    table5 = modal.thesis_table5_reproduction(material=material)
    _store(datasets, "table5", table5)
    lines = ["modal: thesis Table 5 (first pinned-pinned in-plane bending of the coupler)",
             f"  {'t [mm]':>6s} {'thesis':>10s} {'EB [rad/s]':>11s} {'Timo':>10s} "
             f"{'FE':>10s} {'FE/EB-1':>8s} {'FE/Timo-1':>9s} {'n thesis':>9s} "
             f"{'n FE 1/w':>9s} {'n FE 2pi/w':>10s} {'verdict k=108 (1/w | 2pi/w)':>28s}"]
    for i, thickness_m in enumerate(table5["coupler_thickness_m"]):
        lines.append(
            f"  {thickness_m * 1e3:6.0f} {table5['thesis_frequency_as_published'][i]:10.2f} "
            f"{table5['euler_bernoulli_omega_rad_per_s'][i]:11.2f} "
            f"{table5['timoshenko_omega_rad_per_s'][i]:10.2f} "
            f"{table5['fe_omega_rad_per_s'][i]:10.2f} "
            f"{table5['fe_vs_euler_bernoulli_relative'][i]:+8.2%} "
            f"{table5['fe_vs_timoshenko_relative'][i]:+9.2%} "
            f"{table5['thesis_n_as_published'][i]:9.0f} "
            f"{table5['fe_n_thesis_convention'][i]:9.1f} {table5['fe_n_physical'][i]:10.2f} "
            f"{table5['fe_verdict_thesis_convention'][i]:>14s} | "
            f"{table5['fe_verdict_physical'][i]}")
    lines.append("  The thesis's 'Frequency' is the Euler-Bernoulli circular frequency [rad/s] "
                 "and its period T = 1/omega is 2 pi too small; with T = 2 pi/omega every "
                 "model falls below k = 108.")
    for link in modal.THESIS_LINKS:
        table = modal.thesis_link_modal_reproduction(link, material=material)
        _store(datasets, f"table_{link}", table)
        lines.append(f"  {link} (thesis {'Table 7' if link == 'crank' else 'Table 9'}): "
                     f"thesis {np.array2string(table['thesis_value_as_published'], precision=1)}"
                     f"; BEAM188 emulation [Hz] "
                     f"{np.array2string(table['beam188_emulation_frequency_Hz'], precision=1)}; "
                     f"Timoshenko {np.array2string(table['timoshenko_frequency_Hz'], precision=1)}"
                     f"; k thesis {float(table['thesis_k_as_published']):.0f}, "
                     f"k Timoshenko {float(table['timoshenko_k']):.0f}")

    links = {f"coupler_t{t * 1e3:g}mm": (coupler["length_m"], t, coupler["width_m"], h)
             for t, h in zip(table5["coupler_thickness_m"], modal.TABLE5_FE_MESH_SIZES_M,
                             strict=True)}
    links["crank"] = (scene["crank"]["length_m"], *CRANK_SECTION_M, CRANK_SECTION_M[0] / 3)
    lines.append("  first five modes [Hz] (FE | Timoshenko beam), kinds from the mode shapes:")
    for name, (length_m, thickness_m, width_m, mesh_m) in links.items():
        for condition in ("free-free", "pinned-pinned"):
            fe = modal.plate_modes(length_m, thickness_m, width_m, mesh_m, condition,
                                   material=material)
            beam = modal.beam_link_modes(length_m, thickness_m, width_m, condition,
                                         material=material)
            group = f"links/{name}/{condition}"
            datasets[f"{group}/fe_frequencies"] = Dataset(fe.frequencies_Hz, "Hz", "3D FE")
            datasets[f"{group}/fe_mode_kinds"] = Dataset(
                np.array(fe.mode_kinds, dtype=object), "1", "classified from the mode shape")
            datasets[f"{group}/timoshenko_frequencies"] = Dataset(
                beam.frequencies_Hz, "Hz", "Timoshenko beam (all mode kinds)")
            datasets[f"{group}/timoshenko_mode_kinds"] = Dataset(
                np.array(beam.mode_kinds, dtype=object), "1", "beam mode kinds")
            datasets[f"{group}/mesh_dof"] = Dataset(fe.dof_count, "1", "FE degrees of freedom")
            if condition == "pinned-pinned":
                datasets[f"{group}/node_coordinates"] = Dataset(fe.node_coordinates_m, "m",
                                                                "mesh vertices")
                datasets[f"{group}/mode_shapes"] = Dataset(fe.mode_shapes, "1",
                                                           "(mode, node, xyz), max |u| = 1")
            pairs = ", ".join(f"{f:.0f} {k} | {b:.0f}" for f, k, b in
                              zip(fe.frequencies_Hz, fe.mode_kinds, beam.frequencies_Hz,
                                  strict=True))
            lines.append(f"    {name:16s} {condition:13s} {pairs}")

    lines.append(f"  mesh convergence (pinned-pinned in-plane bending, tolerance "
                 f"{CONVERGENCE_TOLERANCE:.1%}):")
    for thickness_m in table5["coupler_thickness_m"]:
        conv = modal.mesh_convergence(coupler["length_m"], thickness_m, coupler["width_m"],
                                      relative_tolerance=CONVERGENCE_TOLERANCE,
                                      material=material)
        group = f"convergence/coupler_t{thickness_m * 1e3:g}mm"
        datasets[f"{group}/mesh_size"] = Dataset(np.asarray(conv.mesh_sizes_m), "m", "maxh")
        datasets[f"{group}/elements"] = Dataset(np.asarray(conv.element_counts), "1", "tets")
        datasets[f"{group}/dof"] = Dataset(np.asarray(conv.dof_counts), "1", "DOF")
        datasets[f"{group}/frequency"] = Dataset(np.asarray(conv.frequencies_Hz), "Hz",
                                                 "first in-plane bending")
        datasets[f"{group}/reference_frequency"] = Dataset(
            conv.selection.reference_frequency, "Hz", conv.selection.reference_method)
        datasets[f"{group}/production_mesh_size"] = Dataset(conv.production_mesh_size_m, "m",
                                                            "coarsest level within tolerance")
        lines.append(f"    t = {thickness_m * 1e3:4g} mm: levels "
                     f"{', '.join(f'{h * 1e3:.2g}' for h in conv.mesh_sizes_m)} mm -> "
                     f"{', '.join(f'{f:.1f}' for f in conv.frequencies_Hz)} Hz; reference "
                     f"{conv.selection.reference_frequency:.2f} Hz "
                     f"({conv.selection.reference_method}); production mesh "
                     f"{conv.production_mesh_size_m * 1e3:.3g} mm")
    return Summary(datasets, "\n".join(lines))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    s = {k: v.data for k, v in summary.datasets.items()}
    paths = []
    thickness_mm = s["table5/coupler_thickness_m"] * 1e3
    path = folder / "modal-table5.png"
    with figure(path, "First pinned-pinned in-plane bending frequency of the coupler",
                "plate thickness [mm]", "frequency / Euler-Bernoulli [-]") as ax:
        eb = s["table5/euler_bernoulli_frequency_Hz"]
        ax.plot(thickness_mm, s["table5/timoshenko_frequency_Hz"] / eb, "s-",
                label="Timoshenko")
        ax.plot(thickness_mm, s["table5/fe_frequency_Hz"] / eb, "o", label="3D FE (NGsolve)")
        ax.axhline(1.0, color="k", lw=0.8, label="Euler-Bernoulli (= thesis Table 5)")
    paths.append(path)
    group = "links/coupler_t1mm/pinned-pinned"
    nodes = s[f"{group}/node_coordinates"]
    shapes = s[f"{group}/mode_shapes"]
    kinds = s[f"{group}/fe_mode_kinds"]
    freqs = s[f"{group}/fe_frequencies"]
    path = folder / "modal-mode-shapes.png"
    with figure(path, "Coupler t = 1 mm, pinned-pinned: first modes (x-y and x-z views)",
                "x [mm]", "normalized displacement [-]") as ax:
        for mode in range(min(4, len(shapes))):
            order = np.argsort(nodes[:, 0])
            component = int(np.argmax(np.abs(shapes[mode]).max(axis=0)))
            kind = kinds[mode].decode() if isinstance(kinds[mode], bytes) else kinds[mode]
            ax.plot(nodes[order, 0] * 1e3, shapes[mode][order, component], ".", ms=2,
                    label=f"mode {mode + 1}: {freqs[mode]:.0f} Hz, {kind} "
                          f"(u_{'xyz'[component]})")
    paths.append(path)
    path = folder / "modal-convergence.png"
    with figure(path, "Mesh convergence, first pinned-pinned in-plane bending",
                "degrees of freedom", "frequency / reference - 1 [-]") as ax:
        for t in thickness_mm:
            group = f"convergence/coupler_t{t:g}mm"
            ax.loglog(s[f"{group}/dof"], np.abs(s[f"{group}/frequency"]
                                                / s[f"{group}/reference_frequency"] - 1)
                      + 1e-9, "o-", label=f"t = {t:g} mm")
        ax.axhline(CONVERGENCE_TOLERANCE, color="r", ls="--", label="tolerance")
    paths.append(path)
    return paths


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
