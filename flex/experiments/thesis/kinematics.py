"""A crank driven at constant speed (thesis ch. 4, figs. 4-7): a run checked against the
closed-form in-line slider-crank (:mod:`flex.base.kinematics`) and the thesis's reported extremes
(sec. 4.3-4.4, :data:`flex.base.thesis.THESIS_SLIDER_KINEMATICS`); the summary and figures of the
``kinematics`` study.

Slider position in m, velocity in m/s, acceleration in m/s^2, times in s, angles in rad.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np

from flex.base.kinematics import SliderCrankState, constant_speed_motion
from flex.base.thesis import (
    THESIS_COUPLER_LENGTH_M,
    THESIS_CRANK_LENGTH_M,
    THESIS_SLIDER_KINEMATICS,
)
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene

#: the slider curves compared, with their units and the thesis's figure numbers
CURVES = (("position", "Slider position", "m", 4), ("velocity", "Slider velocity", "m/s", 5),
          ("acceleration", "Slider acceleration", "m/s\u00b2", 6))


def closed_form(scene: Scene, time_s: np.ndarray) -> SliderCrankState:
    """Closed-form slider motion at the scene's constant crank speed, at ``time_s`` [s]."""
    return constant_speed_motion(scene["crank"]["length_m"], scene["coupler"]["length_m"],
                                 np.radians(scene["crank"]["initial_angle_deg"]),
                                 scene["drive"]["crank_speed_rad_per_s"], time_s,
                                 scene["slider"]["offset_m"])[1]


def extremes(data: dict[str, np.ndarray]) -> dict[str, float]:
    """The slider extremes the thesis reports (keys of ``THESIS_SLIDER_KINEMATICS``): stroke
    [m], velocity max and min [m/s], acceleration max and min [m/s^2]."""
    return {"stroke_m": np.ptp(data["slider/position"]),
            "velocity_max_m_per_s": data["slider/velocity"].max(),
            "velocity_min_m_per_s": data["slider/velocity"].min(),
            "acceleration_max_m_per_s2": data["slider/acceleration"].max(),
            "acceleration_min_m_per_s2": data["slider/acceleration"].min()}


def thesis_setup_differences(scene: Scene, turns: float) -> str:
    """How a constant-speed run differs from the thesis's set-up of sec. 4.3 ("" if it does
    not): crank speed [rad/s], turns covered, link lengths [m], slide-line offset [m]."""
    found = []
    if not np.isclose(abs(scene["drive"]["crank_speed_rad_per_s"]), 2 * np.pi, rtol=1e-9):
        found.append(f"drive.crank_speed_rad_per_s = {scene['drive']['crank_speed_rad_per_s']:g}")
    if turns < 1 - 1e-6:
        found.append(f"{turns:.3g} of a turn")
    for key, value in (("crank.length_m", THESIS_CRANK_LENGTH_M),
                       ("coupler.length_m", THESIS_COUPLER_LENGTH_M), ("slider.offset_m", 0.0)):
        section, name = key.split(".")
        if not np.isclose(scene[section][name], value, rtol=1e-9, atol=1e-15):
            found.append(f"{key} = {scene[section][name]:g}")
    return ", ".join(found)


def summary(case: CaseResult) -> tuple[dict[str, Dataset], str]:
    """The ``kinematics`` summary of one constant-speed run: the thesis comparison, the
    largest deviations from the closed form and the closed-form curves; ``(datasets,
    report)``."""
    if case.status != "ok":
        return {}, f"kinematics: case failed: {case.message}"
    scene = tomllib.loads(case.scene_toml)
    data = {k: v.data for k, v in case.datasets.items()}
    exact = closed_form(scene, data["time"])
    midpoint_radius = np.hypot(*data["crank/midpoint_position"].T)
    error = {"position": np.abs(data["slider/position"] - exact.slider_position_m).max(),
             "velocity": np.abs(data["slider/velocity"] - exact.slider_velocity_m_per_s).max(),
             "acceleration": np.abs(data["slider/acceleration"]
                                    - exact.slider_acceleration_m_per_s2).max()}
    flex = extremes(data)
    thesis = THESIS_SLIDER_KINEMATICS
    speed = scene["drive"]["crank_speed_rad_per_s"]
    turns = abs(speed) * float(data["time"][-1] - data["time"][0]) / (2 * np.pi)
    lines = [f"kinematics: thesis sec. 4.3-4.4 against flex (Exudyn, {speed / (2 * np.pi):.4g} "
             f"turn/s, {turns:.4g} turns)"]
    differs = thesis_setup_differences(scene, turns)
    if differs:
        lines.append(f"  the thesis column is for its own set-up (1 turn/s, one whole turn, L1 = "
                     f"{THESIS_CRANK_LENGTH_M:g} m, L2 = {THESIS_COUPLER_LENGTH_M:g} m, in-line); "
                     f"this run differs ({differs}): compare flex with the closed form below")
    lines.append(f"  {'quantity':28s} {'thesis':>9s} {'flex':>10s}")
    lines += [f"  {key:28s} {thesis[key]:9.3g} {value:10.4f}" for key, value in flex.items()]
    lines += [f"  max |x - x_closed_form|      {error['position']:.2e} m",
              f"  max |v - v_closed_form|      {error['velocity']:.2e} m/s",
              f"  max |a - a_closed_form|      {error['acceleration']:.2e} m/s^2",
              f"  crank midpoint radius        {midpoint_radius.min():.9f}.."
              f"{midpoint_radius.max():.9f} m (L1/2 = {scene['crank']['length_m'] / 2} m)",
              f"  max constraint norm          {data['constraint_norm'].max():.2e} m"]
    keys = list(flex)
    units = {"position": "m", "velocity": "m/s", "acceleration": "m/s^2"}
    exact_curves = {"position": exact.slider_position_m,
                    "velocity": exact.slider_velocity_m_per_s,
                    "acceleration": exact.slider_acceleration_m_per_s2}
    datasets = {
        "thesis_comparison/quantity": Dataset(np.array(keys, dtype=object), "1", "quantity"),
        "thesis_comparison/thesis": Dataset(np.array([thesis[k] for k in keys]),
                                            "SI (see name)", "thesis sec. 4.3-4.4"),
        "thesis_comparison/flex": Dataset(np.array([flex[k] for k in keys]), "SI (see name)",
                                          "this run"),
        **{f"closed_form/max_{key}_error": Dataset(error[key], unit, "vs closed form")
           for key, unit in units.items()},
        **{f"closed_form/slider_{key}": Dataset(exact_curves[key], unit, "closed form")
           for key, unit in units.items()},
    }
    return datasets, "\n".join(lines)


def draw_figures(case: CaseResult, datasets: dict[str, Dataset], folder: Path) -> list[Path]:
    """The ``kinematics-*.png`` figures of one run: each slider curve over the closed form
    (``datasets``: the summary's) with their difference, the crank midpoint's circle and
    the constraint norm."""
    from flex.base.plotting import panels, scaled

    data = {k: v.data for k, v in case.datasets.items()}
    closed = {k: v.data for k, v in datasets.items()}
    paths = []
    for key, label, unit, fig in CURVES:
        path = folder / f"kinematics-slider-{key}.png"
        with panels(path, f"{label}: Exudyn against the closed form (thesis fig. {fig})",
                    rows=2, size=(7.0, 5.5), sharex=True,
                    gridspec_kw={"height_ratios": [3, 1.3]}) as (_, (ax, difference)):
            ax.plot(data["time"], data[f"slider/{key}"], lw=2.2, label="flex (Exudyn)")
            ax.plot(data["time"], closed[f"closed_form/slider_{key}"], "k--", lw=1.0,
                    label="closed form (in-line slider-crank)")
            ax.set_ylabel(f"slider {key} [{unit}]")
            error, error_unit = scaled(data[f"slider/{key}"]
                                       - closed[f"closed_form/slider_{key}"], unit)
            difference.plot(data["time"], error, color="C3", lw=0.8)
            difference.set_ylabel(f"Exudyn \u2212 closed\nform [{error_unit}]")
            difference.set_xlabel("time [s]")
        paths.append(path)
    crank_length_m = float(tomllib.loads(case.scene_toml)["crank"]["length_m"])
    paths.append(_crank_midpoint(folder / "kinematics-crank-midpoint.png", data,
                                 crank_length_m))
    paths.append(_constraint_norm(folder / "kinematics-constraint-norm.png", data))
    return paths


def _crank_midpoint(path: Path, data: dict[str, np.ndarray], crank_length_m: float) -> Path:
    """The crank midpoint's trajectory [mm] on the circle of radius L1/2."""
    from flex.base.plotting import panels, sparse_ticks

    midpoint_mm = np.asarray(data["crank/midpoint_position"]) * 1e3
    radius_mm = crank_length_m / 2 * 1e3
    deviation_m = np.abs(np.hypot(*midpoint_mm.T) - radius_mm).max() * 1e-3
    with panels(path, "Crank midpoint trajectory, one crank turn (thesis fig. 7)",
                size=(5.2, 6.0)) as (fig, (ax,)):
        angle = np.linspace(0, 2 * np.pi, 361)
        ax.plot(radius_mm * np.cos(angle), radius_mm * np.sin(angle), color="0.6", lw=4,
                alpha=0.5, label=f"circle of radius L1/2 = {radius_mm:g} mm")
        ax.plot(*midpoint_mm.T, color="C0", lw=1.2,
                label=f"flex (Exudyn): max |r \u2212 L1/2| = {deviation_m:.1g} m")
        ax.plot(*midpoint_mm[0], "o", color="C0", label="start (t = 0)")
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        sparse_ticks(ax)
        limit = radius_mm * 1.12
        ax.set_xlim(-limit, limit)
        ax.set_ylim(-limit, limit)
        fig.legend(fontsize="small", loc="outside lower center")
    return path


def _constraint_norm(path: Path, data: dict[str, np.ndarray], floor: float = 1e-20) -> Path:
    """The constraint norm [m] on a log scale; samples below ``floor`` (incl. exactly 0)
    drawn at it."""
    from flex.base.plotting import panels

    norm = np.asarray(data["constraint_norm"], dtype=float)
    low = norm < floor
    with panels(path, "Norm of the position constraint equations (round-off level)",
                size=(7.0, 5.0)) as (fig, (ax,)):
        ax.semilogy(data["time"][~low], norm[~low], ".", ms=2.5, label="flex (Exudyn)")
        if low.any():
            ax.semilogy(data["time"][low], np.full(np.count_nonzero(low), floor), "v",
                        ms=3, color="C1", label=f"below {floor:g} m (incl. exactly 0): "
                                                f"{np.count_nonzero(low)} of {norm.size} "
                                                f"samples, drawn at {floor:g} m")
        ax.axhline(np.finfo(float).eps * 0.1, color="k", ls=":", lw=0.8,
                   label="machine epsilon \u00d7 0.1 m (round-off of the link lengths)")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("constraint norm [m]")
        ax.set_ylim(floor / 3, None)
        fig.legend(fontsize="small", loc="outside lower center")
    return path
