"""The links' modal survey (thesis sec. 6.2-6.3): what the ``modal`` study stores, reports
and draws.

:func:`survey` computes, for the scene's coupler material: Table 5 in both period conventions
and Tables 7 and 9 with flex's reading of them (:mod:`flex.experiments.thesis.thesis_tables`); the
first five
modes of each Table 5 coupler plate and of the crank, free-free and pinned-pinned, by 3D FE
(:mod:`flex.experiments.thesis.fe_modes`) beside the Timoshenko beam
(:mod:`flex.experiments.thesis.beams`), each
classified; and
the mesh convergence of each Table 5 plate (:mod:`flex.experiments.thesis.mesh_convergence`). It
returns the
datasets stored under ``/summary`` (units from the keys: ``_m``, ``_s``, ``_Hz``,
``_rad_per_s``) and the report. :func:`draw_figures` draws them back from those datasets.
"""

from __future__ import annotations

from collections.abc import Callable, MutableMapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.physics import Plate
from flex.base.thesis import THESIS_TABLE5
from flex.bodies.plate import plate_mesh
from flex.data.results import Dataset
from flex.experiments.thesis.beams import Material, beam_link_modes
from flex.experiments.thesis.fe_modes import PlateModes, plate_modes
from flex.experiments.thesis.mesh_convergence import mesh_convergence
from flex.experiments.thesis.thesis_tables import (
    TABLE5_FE_MESH_SIZES_M,
    THESIS_LINKS,
    thesis_link_modal_reproduction,
    thesis_table5_reproduction,
)

CONVERGENCE_TOLERANCE = 0.001
"""Relative tolerance of the production mesh, on the first pinned-pinned in-plane frequency."""
REFERENCE_ORDERS = (3, 4)
"""Element orders raised to on one level's mesh for the converged reference (p-refinement:
order 4 there is within ~3e-5 of the limit on every Table 5 plate, measured, where the
finest second-order levels that Richardson extrapolation needed cost 4x the whole survey's
time; reference notes, /work/shared/reference-notes.md)."""
REFERENCE_MAX_DOF = 25_000
"""Unknowns of the highest order's solve at most: the finest level's mesh within it carries
the orders (each plate's costs 1-4 s on one core)."""
CONVERGENCE_MAX_DOF = 20_000
"""Second-order levels up to about this many unknowns: two to four levels finer than the
production mesh show that it stays within tolerance (the levels above it, up to 60k, cost
two thirds of the survey and served the Richardson reference only)."""
CRANK_SECTION_M = (0.010, 0.010)
"""Thickness and width of the crank plate, m: flex's reading of the thesis's ANSYS section
(Table 7)."""
CONDITIONS = ("free-free", "pinned-pinned")
"""The boundary conditions every link is solved with."""

#: progress callback ``(step, done, total)``, as :func:`flex.study.progress_printer` prints
Progress = Callable[[str, int, int], None]


def scene_material(scene: Any) -> Material:
    """The coupler's material of a scene (E [Pa], rho [kg/m^3], nu), used for every link."""
    return Material.of(Plate.of(scene["coupler"]))


def _unit(key: str) -> str:
    """The unit a table key names by its suffix (``_rad_per_s``, ``_Hz``, ``_s``, ``_m``)."""
    for suffix, unit in (("_rad_per_s", "rad/s"), ("_Hz", "Hz"), ("_s", "s"), ("_m", "m")):
        if key.endswith(suffix):
            return unit
    return "1"


def _store(datasets: dict[str, Dataset], prefix: str, table: dict) -> None:
    """Every entry of ``table`` as ``prefix/key``, its unit read from the key's suffix."""
    for key, value in table.items():
        array = np.asarray(value)
        if array.dtype.kind in "US":
            array = array.astype(object)
        datasets[f"{prefix}/{key}"] = Dataset(array, _unit(key), key.replace("_", " "))


def survey(scene: Any, progress: Progress | None = None) -> tuple[dict[str, Dataset], str]:
    """The whole modal survey of ``scene``'s links: ``(datasets, report)``. ``progress`` gets
    one call per long step (about 20 s in all, measured on 2 shared cores) and a final
    ``done``. Each plate is
    meshed once per maxh: its free-free and pinned-pinned modes, Table 5's FE column (the
    pinned-pinned solutions themselves) and its convergence levels share the meshes."""
    material = scene_material(scene)
    thicknesses_m = THESIS_TABLE5["coupler_thickness_m"]
    links = link_plates(scene, thicknesses_m)
    steps = ([f"modes of {name}, {condition}" for name in links for condition in CONDITIONS]
             + ["Table 5: 3D FE of the four coupler plates", "Tables 7 and 9: BEAM188 emulation"]
             + [f"mesh convergence, coupler t = {t * 1e3:g} mm" for t in thicknesses_m])
    counter = iter(range(len(steps)))

    def step() -> None:
        index = next(counter)
        if progress:
            progress(steps[index], index, len(steps))

    datasets: dict[str, Dataset] = {}
    meshes: dict[tuple[float, ...], dict[float, Any]] = {}  # plate sizes [m] -> maxh -> mesh
    mode_lines, pinned = [], {}
    for name, (plate, mesh_m) in links.items():
        for condition in CONDITIONS:
            step()
            line, fe = link_modes(datasets, name, plate, mesh_m, condition,
                                  meshes.setdefault(plate.sizes_m, {}))
            mode_lines.append(line)
            pinned[name, condition] = fe
    step()
    table5 = thesis_table5_reproduction(material=material, fe_modes=[
        pinned[f"coupler_t{t * 1e3:g}mm", "pinned-pinned"] for t in thicknesses_m])
    _store(datasets, "table5", table5)
    lines = table5_report(table5)
    step()
    for link in THESIS_LINKS:
        table = thesis_link_modal_reproduction(link, material=material)
        _store(datasets, f"table_{link}", table)
        lines.append(link_table_line(link, table))
    lines.append("  first five modes [Hz] (FE | Timoshenko beam), kinds from the mode shapes:")
    lines += mode_lines
    lines.append(f"  mesh convergence (pinned-pinned in-plane bending, second-order tetrahedra, "
                 f"tolerance {CONVERGENCE_TOLERANCE:.1%}; reference: the element order raised "
                 f"to {REFERENCE_ORDERS[-1]} on one level's mesh):")
    for thickness_m in thicknesses_m:
        step()
        coupler = replace(Plate.of(scene["coupler"]), thickness_m=float(thickness_m))
        lines.append(convergence(datasets, scene, thickness_m, material,
                                 meshes.setdefault(coupler.sizes_m, {})))
    if progress:
        progress("done", len(steps), len(steps))
    return datasets, "\n".join(lines)


def table5_report(table5: dict[str, np.ndarray]) -> list[str]:
    """Report lines of Table 5: thesis, beams and FE, n in both conventions, verdicts."""
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
    return lines


def link_table_line(link: str, table: dict[str, np.ndarray]) -> str:
    """One report line of Table 7 (crank) or 9 (coupler) beside the BEAM188 emulation [Hz]."""
    return (f"  {link} (thesis {'Table 7' if link == 'crank' else 'Table 9'}): "
            f"thesis {np.array2string(table['thesis_value_as_published'], precision=1)}"
            f"; BEAM188 emulation [Hz] "
            f"{np.array2string(table['beam188_emulation_frequency_Hz'], precision=1)}; "
            f"Timoshenko {np.array2string(table['timoshenko_frequency_Hz'], precision=1)}"
            f"; k thesis {float(table['thesis_k_as_published']):.0f}, "
            f"k Timoshenko {float(table['timoshenko_k']):.0f}")


def link_plates(scene: Any, thicknesses_m: np.ndarray) -> dict[str, tuple[Plate, float]]:
    """The surveyed plates, ``name: (plate, netgen maxh [m])``, all of the coupler's material
    (:func:`scene_material`): each Table 5 coupler (``coupler_t<t>mm``) at its production
    mesh, and the crank."""
    coupler = Plate.of(scene["coupler"])
    links = {f"coupler_t{t * 1e3:g}mm": (replace(coupler, thickness_m=t), h)
             for t, h in zip(thicknesses_m, TABLE5_FE_MESH_SIZES_M, strict=True)}
    thickness_m, width_m = CRANK_SECTION_M
    links["crank"] = (replace(coupler, length_m=scene["crank"]["length_m"],
                              thickness_m=thickness_m, width_m=width_m), thickness_m / 3)
    return links


def link_modes(datasets: dict[str, Dataset], name: str, plate: Plate, mesh_size_m: float,
               condition: str, meshes: MutableMapping[float, Any] | None = None
               ) -> tuple[str, PlateModes]:
    """Store the first five FE and Timoshenko modes of one plate (meshed at netgen maxh
    ``mesh_size_m`` [m]) under ``links/<name>/<condition>/`` (pinned-pinned also the mesh and
    the mode shapes); return the report line and the FE modes. ``meshes``: the plate's
    meshes by maxh [m], used and filled (None: meshed here)."""
    material = Material.of(plate)
    meshes = {} if meshes is None else meshes
    if mesh_size_m not in meshes:
        meshes[mesh_size_m] = plate_mesh(*plate.sizes_m, mesh_size_m)
    fe = plate_modes(*plate.sizes_m, mesh_size_m, condition, material=material,
                     mesh=meshes[mesh_size_m])
    beam = beam_link_modes(*plate.sizes_m, condition, material=material)
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
                      zip(fe.frequencies_Hz, fe.mode_kinds, beam.frequencies_Hz, strict=True))
    return f"    {name:16s} {condition:13s} {pairs}", fe


def convergence(datasets: dict[str, Dataset], scene: Any, thickness_m: float,
                material: Material, meshes: MutableMapping[float, Any] | None = None) -> str:
    """Store the mesh convergence of the coupler plate of thickness ``thickness_m`` [m] under
    ``convergence/coupler_t<t>mm/`` (the levels, the order raised on one of them, the
    reference and the production mesh); return the report line. ``meshes``: the plate's
    meshes by maxh [m], used and filled."""
    coupler = scene["coupler"]
    conv = mesh_convergence(coupler["length_m"], thickness_m, coupler["width_m"],
                            relative_tolerance=CONVERGENCE_TOLERANCE,
                            max_dof_count=CONVERGENCE_MAX_DOF, material=material,
                            reference_orders=REFERENCE_ORDERS,
                            reference_max_dof_count=REFERENCE_MAX_DOF, meshes=meshes)
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
    orders = conv.orders
    datasets[f"{group}/order/mesh_size"] = Dataset(orders.mesh_size_m, "m",
                                                   "maxh of the mesh the order is raised on")
    datasets[f"{group}/order/order"] = Dataset(orders.orders, "1", "tetrahedra's order")
    datasets[f"{group}/order/dof"] = Dataset(orders.dof_counts, "1", "DOF")
    datasets[f"{group}/order/frequency"] = Dataset(orders.frequencies_Hz, "Hz",
                                                   "first in-plane bending")
    datasets[f"{group}/order/relative_error_estimate"] = Dataset(
        orders.relative_error_estimate, "1", "reference: |f(p max) - f(p max - 1)| / f(p max)")
    return (f"    t = {thickness_m * 1e3:4g} mm: levels "
            f"{', '.join(f'{h * 1e3:.2g}' for h in conv.mesh_sizes_m)} mm -> "
            f"{', '.join(f'{f:.1f}' for f in conv.frequencies_Hz)} Hz; orders "
            f"{', '.join(str(p) for p in orders.orders)} on the "
            f"{orders.mesh_size_m * 1e3:.2g} mm mesh -> "
            f"{', '.join(f'{f:.2f}' for f in orders.frequencies_Hz)} Hz; reference "
            f"{conv.selection.reference_frequency:.2f} Hz (estimated error "
            f"{orders.relative_error_estimate:.0e}); production mesh "
            f"{conv.production_mesh_size_m * 1e3:.3g} mm")


# ------------------------------------------------------------------------------------------
# figures
# ------------------------------------------------------------------------------------------
def draw_figures(datasets: dict[str, Dataset], folder: Path) -> list[Path]:
    """``modal-table5.png``, ``modal-mode-shapes.png`` and ``modal-convergence.png`` in
    ``folder``, from the datasets of :func:`survey`."""
    from flex.base.plotting import figure

    s = {k: v.data for k, v in datasets.items()}
    thickness_mm = s["table5/coupler_thickness_m"] * 1e3
    table5 = folder / "modal-table5.png"
    with figure(table5, "First pinned-pinned in-plane bending frequency of the coupler, "
                "relative to Euler-Bernoulli (thesis Table 5)",
                "plate thickness t [mm]", "frequency / Euler-Bernoulli frequency [-]") as ax:
        eb = s["table5/euler_bernoulli_frequency_Hz"]
        ax.plot(thickness_mm, s["table5/timoshenko_frequency_Hz"] / eb, "s-",
                label="Timoshenko beam")
        ax.plot(thickness_mm, s["table5/fe_frequency_Hz"] / eb, "o", label="3D FE (NGsolve)")
        ax.axhline(1.0, color="k", lw=0.8, label="Euler-Bernoulli beam (= thesis Table 5)")
    shapes = folder / "modal-mode-shapes.png"
    draw_mode_shapes(shapes, s, "links/coupler_t1mm/pinned-pinned")
    return [table5, shapes, draw_convergence(folder / "modal-convergence.png", datasets)]


def draw_convergence(path: Path, datasets: dict[str, Dataset]) -> Path:
    """Relative error of each Table 5 plate's frequency against its reference, by DOF: the
    second-order levels and, where stored, the orders raised on the reference's mesh."""
    from flex.base.plotting import decade_ticks, figure

    s = {k: v.data for k, v in datasets.items()}
    with figure(path, "Mesh convergence of the first pinned-pinned in-plane bending "
                "frequency", "degrees of freedom of the FE mesh [-]",
                "|f / f_reference \u2212 1| [-]") as ax:
        for index, t in enumerate(s["table5/coupler_thickness_m"] * 1e3):
            group = f"convergence/coupler_t{t:g}mm"
            dof = np.asarray(s[f"{group}/dof"], dtype=float)
            frequency = np.asarray(s[f"{group}/frequency"], dtype=float)
            reference = float(s[f"{group}/reference_frequency"])
            method = str(datasets[f"{group}/reference_frequency"].description)
            error = np.abs(frequency / reference - 1)
            drawn = error > 0  # the finest level is the reference itself when not extrapolated
            how = ("Richardson extrapolation" if method == "richardson"
                   else "finest level, not drawn" if method == "finest"
                   else method.split(", estimated")[0])
            ax.loglog(dof[drawn], error[drawn], "o-", color=f"C{index}",
                      label=f"t = {t:g} mm (reference: {how})")
            production = np.isclose(s[f"{group}/mesh_size"],
                                    float(s[f"{group}/production_mesh_size"]))
            ax.loglog(dof[production & drawn], error[production & drawn], "o", ms=11,
                      mfc="none", color=f"C{index}")
            if f"{group}/order/dof" in s:  # the order raised on one mesh (the reference's)
                order_error = np.abs(np.asarray(s[f"{group}/order/frequency"]) / reference - 1)
                shown = order_error > 0  # the highest order is the reference
                ax.loglog(np.asarray(s[f"{group}/order/dof"])[shown], order_error[shown], "s--",
                          color=f"C{index}", mfc="none")
        ax.axhline(CONVERGENCE_TOLERANCE, color="r", ls="--",
                   label=f"tolerance {CONVERGENCE_TOLERANCE:.1%}")
        ax.plot([], [], "o", ms=11, mfc="none", color="k",
                label="production mesh (coarsest within tolerance)")
        ax.plot([], [], "s--", mfc="none", color="k",
                label="element order 2, 3 on the reference's mesh (order 4)")
        decade_ticks(ax)
    return path


def _centre_line(nodes_mm: np.ndarray, u_y: np.ndarray, bins: int = 40
                 ) -> tuple[np.ndarray, np.ndarray]:
    """x [mm] of the filled bins along the plate and the mean of ``u_y`` in each."""
    edges = np.linspace(nodes_mm[:, 0].min(), nodes_mm[:, 0].max(), bins + 1)
    index = np.clip(np.digitize(nodes_mm[:, 0], edges) - 1, 0, len(edges) - 2)
    centres = 0.5 * (edges[1:] + edges[:-1])
    filled = np.bincount(index, minlength=len(centres)) > 0
    mean = np.bincount(index, u_y, len(centres))[filled] / np.bincount(
        index, minlength=len(centres))[filled]
    return centres[filled], mean


def draw_mode_shapes(path: Path, s: dict, group: str, count: int = 4) -> None:
    """The first ``count`` FE modes of a plate in two views: x-y (the mechanism plane; the
    in-plane displacement u_y averaged over each cross-section, i.e. the centre line) and
    x-z (the plate's face, coloured by u_y: bending is uniform across the width, torsion
    changes sign across it)."""
    import matplotlib.pyplot as plt

    from flex.base.plotting import save

    nodes = np.asarray(s[f"{group}/node_coordinates"]) * 1e3
    shapes = np.asarray(s[f"{group}/mode_shapes"])
    kinds = [k.decode() if isinstance(k, bytes) else str(k) for k in s[f"{group}/fe_mode_kinds"]]
    freqs = np.asarray(s[f"{group}/fe_frequencies"])
    count = min(count, len(shapes))
    fig, axes = plt.subplot_mosaic([["line", f"face{mode}"] for mode in range(count)],
                                   figsize=(12.0, 1.2 + 1.45 * count),
                                   layout="constrained", width_ratios=[1.0, 1.25])
    fig.suptitle(f"Coupler plate t = {np.ptp(nodes[:, 1]):g} mm, pinned-pinned: first "
                 f"{count} FE modes in two views (normalized, max |u| = 1)")
    line = axes["line"]
    face = nodes[:, 1] >= nodes[:, 1].max() - 1e-9  # one face: the x-z view
    for mode in range(count):
        u_y = shapes[mode][:, 1]
        line.plot(*_centre_line(nodes, u_y), "-", color=f"C{mode}",
                  label=f"mode {mode + 1}: {freqs[mode]:.0f} Hz, {kinds[mode]}")
        ax = axes[f"face{mode}"]
        contour = ax.tricontourf(nodes[face, 0], nodes[face, 2], u_y[face],
                                 levels=np.linspace(-1, 1, 21), cmap="RdBu_r")
        ax.set_aspect("equal")
        ax.set_title(f"mode {mode + 1}: {freqs[mode]:.0f} Hz, {kinds[mode]}",
                     fontsize="small", color=f"C{mode}")
        ax.set_ylabel("z [mm]")
        if mode < count - 1:
            ax.tick_params(labelbottom=False)
        else:
            ax.set_xlabel("x along the coupler [mm]")
    line.set_title("x-y view (mechanism plane): centre line, u_y averaged over the "
                   "cross-section", fontsize="small")
    line.set_xlabel("x along the coupler [mm]")
    line.set_ylabel("normalized in-plane displacement u_y [-]")
    line.axhline(0.0, color="k", lw=0.6)
    line.grid(True, alpha=0.3)
    line.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2)
    colourbar = fig.colorbar(contour, ax=[axes[f"face{m}"] for m in range(count)],
                             shrink=0.8)
    colourbar.set_label("normalized u_y [-]")
    axes["face0"].annotate("x-z view (plate face): colour = u_y", (0.5, 1.45),
                           xycoords="axes fraction", ha="center", fontsize="small")
    save(fig, path)
