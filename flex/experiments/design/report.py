"""The design study's report and charts, read from its summary datasets only
(:func:`flex.experiments.design.summary.summary_datasets`): so ``flex report results/design.h5``
and the figures say what the file holds.

Figures (``results/figures/design-*.png``): one contour map per family of two inputs
(``map-angle-preload``, ``map-angle-rate``, ``map-thickness-rate``), each with six panels
(peak crank speed, deployment time, peak joint force, peak coupler stress over the
allowable, smallest transmission angle, auto's predicted rigid error), the rigid/FFRF
boundary for the tolerance dashed (where auto's predicted error crosses it), FFRF cases
circled, refused cases crossed, the design point starred; ``lines``: the measures along the
constraint lines through the design point; ``mechanism``: the transmission angle and the
dead-centre measure over a full crank turn.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flex.data.results import Dataset
from flex.dynamics.link_models import FFRF, RIGID

#: map figure -> (family, x column, x scale and label, y column, y scale and label)
MAPS = {
    "map-angle-preload": ("angle_preload", "angle_deg", 1.0, "initial crank angle [deg]",
                          "preload_m", 1e3, "spring preload [mm]"),
    "map-angle-rate": ("angle_rate", "angle_deg", 1.0, "initial crank angle [deg]",
                       "rate_N_per_m", 1.0, "spring rate at the design energy [N/m]"),
    "map-thickness-rate": ("thickness_rate", "thickness_m", 1e3, "coupler thickness [mm]",
                           "rate_N_per_m", 1.0, "spring rate at the design preload [N/m]"),
}
#: map panel -> (table column, scale, colour-bar label)
PANELS = (("peak_crank_speed", 1.0, "peak crank speed [rad/s]"),
          ("deployment_time", 1e3, "deployment time [ms]"),
          ("peak_joint_force", 1.0, "peak joint force (A, B, C) [N]"),
          ("stress_ratio", 1.0, "peak coupler stress / allowable [-]"),
          ("min_transmission_angle", 180 / np.pi, "smallest transmission angle [deg]"),
          ("log_error", 1.0, "log10 of auto's predicted rigid error [-]"))


def _value(datasets: Mapping[str, Dataset], key: str, default: Any = np.nan) -> Any:
    found = datasets.get(key)
    if found is None:
        return default
    value = np.asarray(found.data)
    return value.item() if value.ndim == 0 else value


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def columns(datasets: Mapping[str, Dataset]) -> dict[str, np.ndarray]:
    """The ``table/*`` columns, plus ``stress_ratio`` and ``log_error``."""
    rows = {key.removeprefix("table/"): np.asarray(value.data)
            for key, value in datasets.items() if key.startswith("table/")}
    rows["case"] = np.array([_text(v) for v in rows["case"]], dtype=object)
    allowable = float(_value(datasets, "design/allowable_stress"))
    rows["stress_ratio"] = rows["peak_coupler_stress"].astype(float) / allowable
    with np.errstate(divide="ignore", invalid="ignore"):
        rows["log_error"] = np.log10(rows["predicted_rigid_error"].astype(float))
    return rows


# ------------------------------------------------------------------------------------------
# the report
# ------------------------------------------------------------------------------------------
def _line_names(datasets: Mapping[str, Dataset]) -> list[str]:
    return sorted({key.split("/")[1] for key in datasets if key.startswith("lines/")},
                  key=lambda name: (name.split("_")[0], _sort_value(name)))


def _sort_value(name: str) -> float:
    tail = name.split("_")[-1].lstrip("pk").replace("p", ".")
    try:
        return float(tail)
    except ValueError:
        return 0.0


def _describe(name: str) -> str:
    if name.startswith("preload_p"):
        return (f"spring as given, preload {name[9:].replace('p', '.')} mm (= fixed stored "
                f"energy and fixed slider travel at this rate)")
    if name.startswith("energy_k"):
        return f"design stored energy, rate {name[8:].replace('p', '.')} N/m"
    return "fixed final crank angle (the design point's rest angle)"


def claim_lines(datasets: Mapping[str, Dataset], measure: str = "peak_crank_speed"
                ) -> list[str]:
    """One Markdown table row per constraint line: extrema of ``measure`` and the verdict."""
    unit = "rad/s" if measure == "peak_crank_speed" else "ms"
    scale = 1.0 if measure == "peak_crank_speed" else 1e3
    rows = [f"| line | constraint | at the design angle [{unit}] | maximum [deg, {unit}] | "
            f"minimum [deg, {unit}] | design angle is |", "|---|---|---|---|---|---|"]
    for name in _line_names(datasets):
        got = {key: _value(datasets, f"lines/{name}/{measure}_{key}")
               for key in ("design_value", "max_x", "max_y", "min_x", "min_y", "max_interior",
                           "min_interior", "design_is_max", "design_is_min")}
        verdict = ("the maximum" if got["design_is_max"] else "the minimum"
                   if got["design_is_min"] else "neither")
        rows.append(
            f"| {name} | {_describe(name)} | {got['design_value'] * scale:.4g} | "
            f"{got['max_x']:.1f}, {got['max_y'] * scale:.4g}"
            f"{'' if got['max_interior'] else ' (range end)'} | "
            f"{got['min_x']:.1f}, {got['min_y'] * scale:.4g}"
            f"{'' if got['min_interior'] else ' (range end)'} | {verdict} |")
    return rows


def claim_answer(datasets: Mapping[str, Dataset]) -> list[str]:
    """The thesis claim answered in words, with the numbers of the file."""
    names = _line_names(datasets)
    angle = float(_value(datasets, "design/point")[0])
    maximal = [n for n in names if _value(datasets, f"lines/{n}/peak_crank_speed_design_is_max")]
    minimal = [n for n in names if _value(datasets, f"lines/{n}/peak_crank_speed_design_is_min")]
    design = next((n for n in names if n.startswith("preload_p")
                   and np.isclose(_sort_value(n) * 1e-3,
                                  float(_value(datasets, "design/point")[1]))), None)
    lines = [f"**Does {angle:g} deg maximise the peak crank speed?** "
             + ("Yes, along: " + ", ".join(maximal) + "." if maximal else
                "No: under none of the constraints swept (fixed preload, fixed stored energy, "
                "fixed slider travel, fixed final crank angle) is it the maximum.")]
    if design is not None:
        got = {k: _value(datasets, f"lines/{design}/peak_crank_speed_{k}")
               for k in ("design_value", "max_x", "max_y", "min_x", "min_y")}
        lines.append(
            f"With the thesis's spring as given ({design}): {got['design_value']:.2f} rad/s at "
            f"{angle:g} deg; the largest peak speed of the range is {got['max_y']:.2f} rad/s "
            f"at {got['max_x']:.1f} deg ({got['max_y'] / got['design_value'] - 1:+.1%}), the "
            f"smallest {got['min_y']:.2f} rad/s at {got['min_x']:.1f} deg "
            f"({got['min_y'] / got['design_value'] - 1:+.2%}, {got['min_x'] - angle:+.1f} deg "
            f"from {angle:g} deg).")
    if minimal:
        lines.append(f"{angle:g} deg is (within half a grid step) the minimum of the peak speed "
                     f"along: {', '.join(minimal)}.")
    final = {k: _value(datasets, f"lines/final_angle/peak_crank_speed_{k}")
             for k in ("max_x", "max_y", "design_value")}
    if np.isfinite(final["max_y"]):
        lines.append(f"To a fixed final angle ({float(_value(datasets, 'design/rest_angle')):.1f} "
                     f"deg) the peak speed is largest at {final['max_x']:.1f} deg "
                     f"({final['max_y']:.2f} rad/s against {final['design_value']:.2f}): a "
                     f"smaller start angle takes a longer slider travel and more energy.")
    return lines


def _mechanism_lines(datasets: Mapping[str, Dataset]) -> list[str]:
    if "mechanism/gruebler_mobility" not in datasets:
        return ["(the design point's case did not run: no mechanism checks)"]
    joints = ", ".join(_text(j) for j in _value(datasets, "mechanism/joints"))
    rows = columns(datasets)
    design = _text(_value(datasets, "design/design_case"))
    at = np.flatnonzero(rows["case"] == design)
    mu = float(np.degrees(rows["min_transmission_angle"][at[0]])) if len(at) else np.nan
    dead = _value(datasets, "mechanism/dead_centre_angles")
    return [
        f"- bodies: {len(_value(datasets, 'mechanism/bodies'))} with the frame; joints: {joints}",
        f"- mobility: Gruebler (Eq. 1) {_value(datasets, 'mechanism/gruebler_mobility')}, "
        f"Kutzbach (Eq. 2) {_value(datasets, 'mechanism/kutzbach_mobility')}; from the "
        f"reference DAE's constraint Jacobian ({_value(datasets, 'mechanism/jacobian_rows')} "
        f"rows, 9 coordinates, smallest rank {_value(datasets, 'mechanism/jacobian_rank_min')} "
        f"along the deployment and a full turn): mobility "
        f"{_value(datasets, 'mechanism/jacobian_mobility')}, redundant constraints "
        f"{_value(datasets, 'mechanism/redundant_constraints')}",
        f"- dead centres at {dead[0]:.1f} and {dead[1]:.1f} deg; with the slider as the input "
        f"the Jacobian's smallest singular value falls from "
        f"{np.max(_value(datasets, 'mechanism/turn_slider_input_singular_value')):.3g} to "
        f"{np.min(_value(datasets, 'mechanism/turn_slider_input_singular_value')):.2g} there; "
        f"along the design deployment it stays above "
        f"{np.min(_value(datasets, 'mechanism/deployment_slider_input_singular_value')):.3g}",
        f"- smallest transmission angle over the design deployment: {mu:.1f} deg (the maps "
        f"show it for every case)"]


def _reference_lines(datasets: Mapping[str, Dataset]) -> list[str]:
    names = sorted({k.split("/")[1] for k in datasets if k.startswith("reference/")})
    rows = ["| case | peak speed flex [rad/s] | reference [rad/s] | max dev. angle [rad] | "
            "max dev. speed [rad/s] | max dev. slider [m] | max dev. B force [N] |",
            "|---|---|---|---|---|---|---|"]
    for name in names:
        def get(key: str, name: str = name) -> float:
            return float(_value(datasets, f"reference/{name}/{key}"))
        rows.append(f"| {name} | {get('peak_crank_speed_flex'):.4f} | "
                    f"{get('peak_crank_speed_reference'):.4f} | {get('crank_angle'):.2e} | "
                    f"{get('crank_angular_velocity'):.2e} | {get('slider_position'):.2e} | "
                    f"{get('joint_B_force'):.2e} |")
    return rows if names else ["(no rigid case to check)"]


def report_text(datasets: Mapping[str, Dataset], sweep: Mapping[str, Any] | None = None
                ) -> str:
    """The design study's report (Markdown), every number read from ``datasets``."""
    rows = columns(datasets)
    point = _value(datasets, "design/point")
    outcomes = {k: int(np.sum(rows["outcome"] == k)) for k in ("simulated", "refused", "failed")}
    models = {k: int(np.sum(rows["model"] == k)) for k in (RIGID, FFRF)}
    head = [
        "# Design charts and the thesis's optimum initial angle", "",
        f"Design point: initial crank angle {point[0]:g} deg, preload {point[1] * 1e3:g} mm, "
        f"rate {point[2]:g} N/m, coupler plate {point[3] * 1e3:g} mm thick; stored energy "
        f"{float(_value(datasets, 'design/stored_energy')):.4g} J. Every case with "
        f"coupler.model = auto at tolerance {float(_value(datasets, 'design/tolerance')):g}.",
        f"Cases: {len(rows['case'])} ({outcomes['simulated']} simulated: {models['rigid']} "
        f"rigid, {models['ffrf']} FFRF; {outcomes['refused']} refused by auto near buckling; "
        f"{outcomes['failed']} failed)"
        + (f"; sweep {sweep['ran']} run, {sweep['resumed']} resumed, "
           f"{sweep['wall_time_s']:.0f} s on {sweep['executor']}" if sweep else "") + ".", "",
        "## The thesis claim (sec. 5.4.5)", "", *claim_answer(datasets), "",
        "Peak crank speed along each line through the design point (extrema over the "
        "deployments that come to rest before the folded dead centre; "
        f"{int(np.sum(rows['valid'] != 1))} cases turn through it or were refused):", "",
        *claim_lines(datasets), "", "Deployment time along the same lines:", "",
        *claim_lines(datasets, "deployment_time"), "",
        "## Mechanism checks", "", *_mechanism_lines(datasets), "",
        "## Cross-check against the reference DAE (rigid cases, stored samples)", "",
        *_reference_lines(datasets), "",
        f"Allowable coupler stress: {float(_value(datasets, 'design/allowable_stress')) / 1e6:g} "
        f"MPa (ASTM A36 yield). Figures: design-map-*.png, design-lines.png, "
        f"design-mechanism.png."]
    return "\n".join(head)


# ------------------------------------------------------------------------------------------
# figures
# ------------------------------------------------------------------------------------------
def grid_of(rows: Mapping[str, np.ndarray], names: Any, x: str, y: str, z: str
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unique x, unique y and z on that grid (NaN where no case) for the cases ``names``."""
    index = {name: i for i, name in enumerate(rows["case"])}
    keep = np.array([index[_text(n)] for n in names if _text(n) in index], dtype=int)
    xs, ys = np.unique(rows[x][keep].astype(float)), np.unique(rows[y][keep].astype(float))
    values = np.full((len(ys), len(xs)), np.nan)
    for i in keep:
        values[np.searchsorted(ys, float(rows[y][i])), np.searchsorted(xs, float(rows[x][i]))] = \
            float(rows[z][i]) if rows[z].dtype != object else np.nan
    return xs, ys, values


def _map_panel(ax, fig, rows, names, spec, panel, point, tolerance) -> None:
    _, x, xscale, xlabel, y, yscale, ylabel = spec
    column, scale, label = panel
    xs, ys, values = grid_of(rows, names, x, y, column)
    values[grid_of(rows, names, x, y, "valid")[2] != 1] = np.nan  # no deployment there
    finite = values[np.isfinite(values)] * scale
    if min(values.shape) >= 2 and finite.size and np.ptp(finite) > 1e-6 * np.max(np.abs(finite)):
        filled = ax.contourf(xs * xscale, ys * yscale, np.ma.masked_invalid(values * scale), 12)
        fig.colorbar(filled, ax=ax).set_label(label, fontsize="small")
    elif finite.size:  # the same everywhere (the transmission angle at one start angle)
        ax.set_title(f"{label.split(' [')[0]}: {finite[0]:.4g} "
                     f"{label.split('[')[1].rstrip(']')} everywhere", fontsize="small")
    _, _, error = grid_of(rows, names, x, y, "predicted_rigid_error")
    if min(error.shape) >= 2 and np.nanmin(error, initial=np.inf) < tolerance < np.nanmax(
            error, initial=-np.inf):
        ax.contour(xs * xscale, ys * yscale, np.ma.masked_invalid(error), [tolerance],
                   colors="k", linestyles="--")
    _, _, valid = grid_of(rows, names, x, y, "valid")
    _, _, model = grid_of({**rows, "is_ffrf": (rows["model"] == FFRF).astype(float)}, names,
                          x, y, "is_ffrf")
    _, _, refused = grid_of({**rows, "is_refused": (rows["outcome"] != "simulated").astype(float)},
                            names, x, y, "is_refused")
    gx, gy = np.meshgrid(xs * xscale, ys * yscale)
    ax.plot(gx[model == 1], gy[model == 1], "o", mfc="none", mec="w", ms=4)
    ax.plot(gx[refused == 1], gy[refused == 1], "x", color="r", ms=4)
    ax.plot(gx[valid == 0], gy[valid == 0], "+", color="0.5", ms=5)
    ax.plot([point[x] * xscale], [point[y] * yscale], "*", color="w", mec="k", ms=12)
    ax.set_xlabel(xlabel, fontsize="small")
    ax.set_ylabel(ylabel, fontsize="small")
    if y == "rate_N_per_m":
        ax.set_yscale("log")
    if x == "thickness_m":
        ax.set_xscale("log")


def draw_map(datasets: Mapping[str, Dataset], figure: str, folder: Path) -> Path:
    """One six-panel contour map (module doc)."""
    from flex.base.plotting import legend_below, panels

    spec = MAPS[figure]
    rows = columns(datasets)
    names = _value(datasets, f"families/{spec[0]}", [])
    values = _value(datasets, "design/point")
    point = {"angle_deg": values[0], "preload_m": values[1], "rate_N_per_m": values[2],
             "thickness_m": values[3]}
    tolerance = float(_value(datasets, "design/tolerance"))
    path = folder / f"design-{figure}.png"
    with panels(path, f"Design map: {spec[6].split(' [')[0]} against {spec[3].split(' [')[0]}",
                3, 2, size=(11.0, 11.5)) as (fig, axes):
        for ax, panel in zip(axes, PANELS, strict=True):
            _map_panel(ax, fig, rows, names, spec, panel, point, tolerance)
        legend_below(fig, [(f"rigid/FFRF boundary: predicted error = tolerance {tolerance:g}",
                            {"linestyle": "--"}),
                           ("FFRF case", {"marker": "o", "mfc": "none"}),
                           ("refused by auto (near buckling) or no deployment",
                            {"marker": "x", "color": "r"}),
                           ("turns through the folded dead centre (left blank)",
                            {"marker": "+", "color": "0.5"}),
                           ("design point", {"marker": "*", "ms": 10})], collect=False)
    return path


def draw_lines(datasets: Mapping[str, Dataset], folder: Path) -> Path:
    """Measures against the initial angle along the constraint lines."""
    from flex.base.plotting import panels

    names = _line_names(datasets)
    angle = float(_value(datasets, "design/point")[0])
    groups = (("preload_p", "peak_crank_speed", 1.0, "peak crank speed [rad/s]"),
              ("energy_k", "peak_crank_speed", 1.0, "peak crank speed [rad/s]"),
              ("final_angle", "peak_crank_speed", 1.0, "peak crank speed [rad/s]"),
              ("preload_p", "deployment_time", 1e3, "deployment time [ms]"))
    path = folder / "design-lines.png"
    with panels(path, "Peak crank speed and deployment time against the initial crank angle "
                      "along the constraint lines", 2, 2, size=(11.0, 8.0)) as (_, axes):
        for ax, (prefix, measure, scale, label) in zip(axes, groups, strict=True):
            for name in (n for n in names if n.startswith(prefix)):
                x = _value(datasets, f"lines/{name}/angle_deg")
                valid = np.asarray(_value(datasets, f"lines/{name}/valid")) == 1
                y = np.asarray(_value(datasets, f"lines/{name}/{measure}")) * scale
                ax.plot(x[valid], y[valid], ".-", label=_describe(name).split(" (")[0])
                ax.plot([_value(datasets, f"lines/{name}/{measure}_max_x")],
                        [_value(datasets, f"lines/{name}/{measure}_max_y") * scale], "k^")
            ax.axvline(angle, color="k", ls=":", label=f"thesis angle {angle:g} deg")
            ax.set_xlabel("initial crank angle [deg]")
            ax.set_ylabel(label)
            ax.legend(fontsize="x-small")
    return path


def draw_mechanism(datasets: Mapping[str, Dataset], folder: Path) -> Path:
    """Transmission angle and the slider-input singular value over a full crank turn."""
    from flex.base.plotting import panels

    turn = _value(datasets, "mechanism/turn_angle")
    deployment = _value(datasets, "mechanism/deployment_angle")
    path = folder / "design-mechanism.png"
    with panels(path, "Mechanism over a full crank turn: transmission angle and distance to "
                      "the dead centres", 2, 1, size=(8.0, 6.5), sharex=True) as (_, axes):
        for ax, key, label in ((axes[0], "turn_transmission_angle", "transmission angle [deg]"),
                               (axes[1], "turn_slider_input_singular_value",
                                "smallest singular value, slider as input [-]")):
            ax.plot(turn, _value(datasets, f"mechanism/{key}"), label="full turn")
            ax.axvspan(np.min(deployment), np.max(deployment), color="C1", alpha=0.2,
                       label="design deployment")
            for dead in _value(datasets, "mechanism/dead_centre_angles"):
                ax.axvline(dead, color="k", ls=":")
            ax.set_ylabel(label)
        axes[1].set_xlabel("crank angle [deg]")
    return path


def draw_figures(datasets: Mapping[str, Dataset], folder: Path) -> list[Path]:
    """Every design figure (module doc) into ``folder``."""
    paths = [draw_map(datasets, name, folder) for name in MAPS]
    paths.append(draw_lines(datasets, folder))
    if "mechanism/turn_angle" in datasets:
        paths.append(draw_mechanism(datasets, folder))
    return paths
