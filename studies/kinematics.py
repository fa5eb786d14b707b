"""Study ``kinematics`` (thesis ch. 4, figures 4-7): crank driven at constant speed.

One crank turn per second for 1 s (sec. 4.3; the data sheet's check shows the reported
stroke, velocity and acceleration extremes belong to omega = 2 pi rad/s). Exudyn's slider
position, velocity and acceleration are compared with the closed-form in-line slider-crank;
the crank midpoint must trace a circle of radius L1/2; the constraint norm stays at round-off.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from flex.kinematics import constant_speed_motion
from flex.plotting import panels, scaled, sparse_ticks
from flex.results import CaseResult, Dataset
from flex.scene import Scene
from flex.study import Summary
from flex.thesis import THESIS_SLIDER_KINEMATICS

NAME = "kinematics"
DESCRIPTION = "constant-speed crank, one turn per second, against the closed form"
OVERRIDES = ['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=6.283185307179586",
             "crank.initial_angle_deg=0.0", "simulation.end_time_s=1.0",
             "simulation.step_s=1e-4", "simulation.output_step_s=1e-3"]

# thesis sec. 4.3-4.4 (MATLAB and SolidWorks agree)
THESIS = THESIS_SLIDER_KINEMATICS


def cases(scene: Scene) -> dict[str, Scene]:
    return {"constant_speed": scene}


def closed_form(scene: Scene, time_s: np.ndarray):
    """Closed-form slider motion at the scene's constant crank speed."""
    return constant_speed_motion(scene["crank"]["length_m"], scene["coupler"]["length_m"],
                                 np.radians(scene["crank"]["initial_angle_deg"]),
                                 scene["drive"]["crank_speed_rad_per_s"], time_s,
                                 scene["slider"]["offset_m"])[1]


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    case = results["constant_speed"]
    if case.status != "ok":
        return Summary(report=f"kinematics: case failed: {case.message}")
    data = {k: v.data for k, v in case.datasets.items()}
    exact = closed_form(scene, data["time"])
    midpoint_radius = np.hypot(*data["crank/midpoint_position"].T)
    position_error = np.abs(data["slider/position"] - exact.slider_position_m).max()
    velocity_error = np.abs(data["slider/velocity"] - exact.slider_velocity_m_per_s).max()
    acceleration_error = np.abs(data["slider/acceleration"]
                                - exact.slider_acceleration_m_per_s2).max()
    flex = {"stroke_m": np.ptp(data["slider/position"]),
            "velocity_max_m_per_s": data["slider/velocity"].max(),
            "velocity_min_m_per_s": data["slider/velocity"].min(),
            "acceleration_max_m_per_s2": data["slider/acceleration"].max(),
            "acceleration_min_m_per_s2": data["slider/acceleration"].min()}
    lines = ["kinematics: thesis sec. 4.3-4.4 against flex (Exudyn, 1 turn/s)",
             f"  {'quantity':28s} {'thesis':>9s} {'flex':>10s}"]
    for key, value in flex.items():
        lines.append(f"  {key:28s} {THESIS[key]:9.3g} {value:10.4f}")
    lines += [f"  max |x - x_closed_form|      {position_error:.2e} m",
              f"  max |v - v_closed_form|      {velocity_error:.2e} m/s",
              f"  max |a - a_closed_form|      {acceleration_error:.2e} m/s^2",
              f"  crank midpoint radius        {midpoint_radius.min():.9f}.."
              f"{midpoint_radius.max():.9f} m (L1/2 = {scene['crank']['length_m'] / 2} m)",
              f"  max constraint norm          {data['constraint_norm'].max():.2e} m"]
    keys = list(flex)
    datasets = {
        "thesis_comparison/quantity": Dataset(np.array(keys, dtype=object), "1", "quantity"),
        "thesis_comparison/thesis": Dataset(np.array([THESIS[k] for k in keys]), "SI (see name)",
                                            "thesis sec. 4.3-4.4"),
        "thesis_comparison/flex": Dataset(np.array([flex[k] for k in keys]), "SI (see name)",
                                          "this run"),
        "closed_form/max_position_error": Dataset(position_error, "m", "vs closed form"),
        "closed_form/max_velocity_error": Dataset(velocity_error, "m/s", "vs closed form"),
        "closed_form/max_acceleration_error": Dataset(acceleration_error, "m/s^2",
                                                      "vs closed form"),
        "closed_form/slider_position": Dataset(exact.slider_position_m, "m", "closed form"),
        "closed_form/slider_velocity": Dataset(exact.slider_velocity_m_per_s, "m/s",
                                               "closed form"),
        "closed_form/slider_acceleration": Dataset(exact.slider_acceleration_m_per_s2, "m/s^2",
                                                   "closed form"),
    }
    return Summary(datasets, "\n".join(lines))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    case = results["constant_speed"]
    data = {k: v.data for k, v in case.datasets.items()}
    closed = {k: v.data for k, v in summary.datasets.items()}
    paths = []
    for key, label, unit, fig in (("position", "Slider position", "m", 4),
                                  ("velocity", "Slider velocity", "m/s", 5),
                                  ("acceleration", "Slider acceleration", "m/s\u00b2", 6)):
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
    path = folder / "kinematics-crank-midpoint.png"
    midpoint_mm = np.asarray(data["crank/midpoint_position"]) * 1e3
    radius_mm = _crank_length_m(case) / 2 * 1e3
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
    paths.append(path)
    path = folder / "kinematics-constraint-norm.png"
    norm = np.asarray(data["constraint_norm"], dtype=float)
    floor = 1e-20
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
    paths.append(path)
    return paths


def _crank_length_m(case: CaseResult) -> float:
    """The crank length L1 of a case's scene (the trajectory's expected radius is L1/2)."""
    import tomllib

    return float(tomllib.loads(case.scene_toml)["crank"]["length_m"])

if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
