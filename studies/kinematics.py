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

from flex.kinematics import slider_crank
from flex.plotting import figure
from flex.results import CaseResult, Dataset
from flex.scene import Scene
from flex.study import Summary

NAME = "kinematics"
DESCRIPTION = "constant-speed crank, one turn per second, against the closed form"
OVERRIDES = ['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=6.283185307179586",
             "crank.initial_angle_deg=0.0", "simulation.end_time_s=1.0",
             "simulation.step_s=1e-4", "simulation.output_step_s=1e-3"]

# thesis sec. 4.3-4.4 (MATLAB and SolidWorks agree)
THESIS = {"stroke_m": 0.080, "velocity_max_m_per_s": 0.28, "velocity_min_m_per_s": -0.28,
          "acceleration_max_m_per_s2": 1.2, "acceleration_min_m_per_s2": -2.3}


def cases(scene: Scene) -> dict[str, Scene]:
    return {"constant_speed": scene}


def closed_form(scene: Scene, time_s: np.ndarray):
    """Closed-form slider motion at the scene's constant crank speed."""
    omega = scene["drive"]["crank_speed_rad_per_s"]
    theta = np.radians(scene["crank"]["initial_angle_deg"]) + omega * time_s
    return slider_crank(scene["crank"]["length_m"], scene["coupler"]["length_m"], theta, omega,
                        0.0, scene["slider"]["offset_m"])


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
    data = {k: v.data for k, v in results["constant_speed"].datasets.items()}
    closed = {k: v.data for k, v in summary.datasets.items()}
    paths = []
    for key, label, unit, fig in (("position", "Slider position", "m", 4),
                                  ("velocity", "Slider velocity", "m/s", 5),
                                  ("acceleration", "Slider acceleration", "m/s^2", 6)):
        path = folder / f"kinematics-slider-{key}.png"
        with figure(path, f"{label} (thesis fig. {fig})", "time [s]",
                    f"slider {key} [{unit}]") as ax:
            ax.plot(data["time"], data[f"slider/{key}"], label="flex (Exudyn)")
            ax.plot(data["time"], closed[f"closed_form/slider_{key}"], "--",
                    label="closed form")
        paths.append(path)
    path = folder / "kinematics-crank-midpoint.png"
    with figure(path, "Crank midpoint trajectory (thesis fig. 7)", "x [m]", "y [m]",
                size=(5, 5)) as ax:
        ax.plot(*data["crank/midpoint_position"].T)
        ax.set_aspect("equal")
    paths.append(path)
    path = folder / "kinematics-constraint-norm.png"
    with figure(path, "Norm of the constraint equations", "time [s]", "norm [m]") as ax:
        ax.semilogy(data["time"], np.maximum(data["constraint_norm"], 1e-20))
    paths.append(path)
    return paths


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
