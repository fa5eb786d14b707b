"""Spring-driven deployment from rest against the thesis (sec. 5.5, figs. 14-23) and the
independent reference DAE: the measures, the comparison table, the summary and the figures of
the ``dynamics`` study.

:func:`measures` reads the thesis's reported quantities off one run's stored curves (crank
angle maximum [rad] and its time [s], crank speed maximum [rad/s] and its time, slider travel
[m] at the angle maximum, slider start position [m], constraint norm [m], half-swing time
[s]); :func:`comparison_table` sets them beside the thesis's numbers (:data:`THESIS_ROWS`)
with the reason for each difference (:data:`REASONS`); :func:`summary` adds per case the
deviation from the reference DAE (:func:`flex.dynamics.reference.deviations_from_reference`) and the
energy drift; :func:`draw_figures` draws the thesis's figures 14-23 and the energy balance.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.thesis import (
    THESIS_ANGLE_MAX_TIME_S,
    THESIS_CONSTRAINT_NORM_MAX_M,
    THESIS_CRANK_ANGLE_MAX_RAD,
    THESIS_CRANK_SPEED_MAX_RAD_PER_S,
    THESIS_CRANK_SPEED_MAX_TIME_S,
    THESIS_DELTA_T_S,
    THESIS_SLIDER_INITIAL_POSITION_M,
    THESIS_SLIDER_TRAVEL_M,
)
from flex.data.headlines import first_maximum_index
from flex.data.results import CaseResult, Dataset
from flex.dynamics.reference import deviations_from_reference
from flex.fidelity.criteria import half_swing_time

#: thesis sec. 5.5 (values read off its figures, "approx."); delta_t from sec. 6.2:
#: (key of :func:`measures`, label, thesis value, unit)
THESIS_ROWS = (
    ("angle_max", "crank angle maximum", THESIS_CRANK_ANGLE_MAX_RAD, "rad"),
    ("angle_max_time", "time of crank angle maximum", THESIS_ANGLE_MAX_TIME_S, "s"),
    ("speed_max", "crank speed maximum", THESIS_CRANK_SPEED_MAX_RAD_PER_S, "rad/s"),
    ("speed_max_time", "time of crank speed maximum", THESIS_CRANK_SPEED_MAX_TIME_S, "s"),
    ("slider_travel_at_angle_max", "slider displacement at angle maximum",
     THESIS_SLIDER_TRAVEL_M, "m"),
    ("slider_initial_position", "slider position at t = 0", THESIS_SLIDER_INITIAL_POSITION_M,
     "m"),
    ("constraint_norm_max", "norm of constraint equations", THESIS_CONSTRAINT_NORM_MAX_M, "m"),
    ("half_swing_time", "half-swing time, against the thesis's delta_t (sec. 6.2; flex's "
                        "delta_t is the time of the crank angle maximum)", THESIS_DELTA_T_S, "s"),
)
#: why flex and the thesis differ, per row, for the two preload readings (22 mm and 11 mm)
REASONS = {
    "angle_max": "22 mm: the spring stays attached and overshoots its free length, so the "
                 "swing doubles; 11 mm is close (the thesis value is read off a plot)",
    "angle_max_time": "both readings agree: the half period does not depend on the preload "
                      "of a linear spring (nearly)",
    "speed_max": "the speed scales with the preload: 11 mm is the closer reading, 22 mm "
                 "gives twice as much",
    "speed_max_time": "agrees: the speed peaks where the spring passes its free length",
    "slider_travel_at_angle_max": "11 mm reproduces the stated 0.022 m travel; 22 mm "
                                  "travels 0.044 m",
    "slider_initial_position": "geometry only: L1 cos(34.19 deg) + L2 cos(theta2)",
    "constraint_norm_max": "flex's index-3 integrator satisfies the constraints to "
                           "round-off; the thesis's integration of accelerations drifts",
    "half_swing_time": "the thesis's delta_t: source not stated and not reproduced; this row "
                       "is one candidate definition, the time at which the crank covers half "
                       "its swing (flex's own delta_t, of auto and docs/criterion.md, is the "
                       "time of the first crank angle maximum, two rows up)",
}
#: keys whose values the reasons above were written for: the bundled thesis scene's
REASON_SECTIONS = ("crank", "coupler", "wing", "slider", "drive")


def scene_differences(scene: dict[str, dict[str, Any]]) -> list[str]:
    """The keys of a case's scene (sections :data:`REASON_SECTIONS`, the spring preload
    aside: the study's cases set it) whose values differ from the bundled thesis scene's:
    ``["drive.spring_stiffness_N_per_m = 3000", ...]``."""
    from flex.data.scene import default_scene

    bundled = default_scene()
    found = []
    for section in REASON_SECTIONS:
        for key, value in scene.get(section, {}).items():
            if key == "spring_preload_m" and section == "drive":
                continue
            if bundled[section].get(key) != value:
                shown = f"{value:g}" if isinstance(value, float) else repr(value)
                found.append(f"{section}.{key} = {shown}")
    return found


def measures(data: dict[str, np.ndarray]) -> dict[str, float]:
    """The thesis's reported quantities (keys of :data:`THESIS_ROWS`, SI units), computed
    from one case's stored curves."""
    time_s, angle, speed = data["time"], data["crank/angle"], data["crank/angular_velocity"]
    peak = first_maximum_index(angle)
    values = {"speed_max": float(speed.max()), "speed_max_time": float(time_s[np.argmax(speed)]),
              "slider_initial_position": float(data["slider/position"][0]),
              "constraint_norm_max": float(data["constraint_norm"].max())}
    if peak is None:  # still rising at the end: the maximum did not happen within the run
        return {**values, "angle_max": math.nan, "angle_max_time": math.nan,
                "slider_travel_at_angle_max": math.nan, "half_swing_time": math.nan}
    return {**values, "angle_max": float(angle[peak]), "angle_max_time": float(time_s[peak]),
            "slider_travel_at_angle_max": float(data["slider/displacement"][peak]),
            "half_swing_time": half_swing_time(time_s, angle, peak)}


def reasons_for(differences: list[str]) -> dict[str, str]:
    """The "why" column: :data:`REASONS` for the thesis's scene, else one note naming how the
    run's scene differs (the reasons were written for the thesis's values only)."""
    if not differences:
        return dict(REASONS)
    note = (f"not known for this scene: it differs from the thesis's in "
            f"{', '.join(differences[:4])}{', ...' if len(differences) > 4 else ''} (the "
            f"reasons of the thesis's scene do not carry over)")
    return {key: note for key in REASONS}


def comparison_table(table: dict[str, dict[str, float]],
                     reasons: dict[str, str] | None = None) -> str:
    """Markdown table: every thesis number beside flex's for each case (README copy);
    ``table``: ``{case: measures(...)}``; ``reasons``: the "why" column (default
    :data:`REASONS`). A quantity the run did not reach (NaN) reads "not reached"."""
    reasons = REASONS if reasons is None else reasons
    names = list(table)
    head = "| quantity | unit | thesis | " + " | ".join(f"flex {n}" for n in names) + " | why |"
    lines = [head, "|" + "---|" * (4 + len(names))]
    for key, label, thesis, unit in THESIS_ROWS:
        values = " | ".join(_fmt(table[n][key]) for n in names)
        lines.append(f"| {label} | {unit} | {_fmt(thesis)} | {values} | {reasons[key]} |")
    return "\n".join(lines)


def _fmt(value: float) -> str:
    """A table cell: 4 significant digits, or scientific below 1e-3; NaN: "not reached"
    (the crank angle had no maximum within the run)."""
    if math.isnan(value):
        return "not reached"
    return f"{value:.2e}" if abs(value) < 1e-3 else f"{value:.4g}"


def comparison_datasets(table: dict[str, dict[str, float]],
                        reasons: dict[str, str] | None = None) -> dict[str, Dataset]:
    """The comparison table as ``thesis_comparison/*`` datasets (one column per case)."""
    datasets = {
        "thesis_comparison/quantity": Dataset(
            np.array([row[1] for row in THESIS_ROWS], dtype=object), "1", "reported quantity"),
        "thesis_comparison/units": Dataset(
            np.array([row[3] for row in THESIS_ROWS], dtype=object), "1", "unit of each row"),
        "thesis_comparison/thesis": Dataset(
            np.array([row[2] for row in THESIS_ROWS]), "see units", "thesis sec. 5.5 / 6.2")}
    for name in table:
        datasets[f"thesis_comparison/{name}"] = Dataset(
            np.array([table[name][row[0]] for row in THESIS_ROWS]), "see units", name)
    reasons = REASONS if reasons is None else reasons
    datasets["thesis_comparison/reason"] = Dataset(
        np.array([reasons[row[0]] for row in THESIS_ROWS], dtype=object), "1",
        "why flex and the thesis differ")
    return datasets


def reference_check(name: str, case: CaseResult) -> tuple[dict[str, Dataset], str]:
    """One case against the reference DAE of its own scene (largest deviations, the
    reference's crank angle [rad] and wall time [s]) and its energy drift [-]: the datasets
    under ``reference/<name>/`` and ``energy/<name>/`` and the report line."""
    data = {k: v.data for k, v in case.datasets.items()}
    reference, deviations = deviations_from_reference(tomllib.loads(case.scene_toml), data)
    datasets = {f"reference/{name}/max_deviation_{key}": Dataset(
        value, unit, f"max |Exudyn - reference DAE| of {key}")
        for key, (value, unit) in deviations.items()}
    datasets[f"reference/{name}/crank_angle"] = Dataset(reference.q[:, 2], "rad",
                                                        "reference DAE crank angle")
    datasets[f"reference/{name}/wall_time_s"] = Dataset(reference.wall_time_s, "s",
                                                        "solve_ivp DOP853 wall time")
    energy = data["energy/total"]
    datasets[f"energy/{name}/relative_drift"] = Dataset(
        np.ptp(energy) / energy[0], "1", "energy balance: (max - min) / initial")
    line = (f"  {name}: max |Exudyn - reference| crank angle "
            f"{deviations['crank_angle'][0]:.2e} rad, slider "
            f"{deviations['slider_position'][0]:.2e} m, B force "
            f"{deviations['joint_B_force'][0]:.2e} N; energy drift "
            f"{np.ptp(energy) / energy[0]:.1e} (relative)")
    return datasets, line


def summary(results: dict[str, CaseResult]) -> tuple[dict[str, Dataset], str]:
    """The ``dynamics`` summary: per case the reference check, then the thesis comparison
    of every successful case; ``(datasets, report)``."""
    datasets: dict[str, Dataset] = {}
    table = {}
    lines = []
    differences: list[str] = []
    for name, case in results.items():
        if case.status != "ok":
            lines.append(f"dynamics: case {name} failed: {case.message}")
            continue
        table[name] = measures({k: v.data for k, v in case.datasets.items()})
        if math.isnan(table[name]["angle_max"]):
            lines.append(f"  {name}: the crank angle is still rising at the end of the run "
                         f"(t = {case.datasets['time'].data[-1]:g} s): its maximum, the "
                         f"deployment time and what is read at it are not reached")
        differences = differences or scene_differences(tomllib.loads(case.scene_toml))
        checked, line = reference_check(name, case)
        datasets.update(checked)
        lines.append(line)
    reasons = reasons_for(differences)
    report = ["dynamics: thesis sec. 5.5 against flex (both spring-preload readings)",
              comparison_table(table, reasons)] + lines
    if table:
        datasets.update(comparison_datasets(table, reasons))
    return datasets, "\n".join(report)


# ------------------------------------------------------------------------------------------
# figures
# ------------------------------------------------------------------------------------------
def case_label(name: str) -> str:
    """``preload_22mm`` -> ``spring preload 22 mm`` (figure legends spell case names out)."""
    return name.replace("preload_", "spring preload ").replace("mm", " mm")


def draw_figures(results: dict[str, CaseResult], datasets: dict[str, Dataset],
                 folder: Path) -> list[Path]:
    """The ``dynamics-*.png`` figures of the successful cases (thesis figs. 14-23 and the
    energy balance); ``datasets``: the summary's, for the reference DAE's crank angle."""
    from flex.base.plotting import figure

    ok = {n: {k: v.data for k, v in c.datasets.items()} for n, c in results.items()
          if c.status == "ok"}
    colour = {name: f"C{index}" for index, name in enumerate(ok)}

    def each(name: str, title: str, ylabel: str, key: str) -> Path:
        with figure(folder / name, title, "time [s]", ylabel) as ax:
            for case, data in ok.items():
                ax.plot(data["time"], np.asarray(data[key]), color=colour[case],
                        label=case_label(case))
        return folder / name

    return [
        _crank_angle(folder / "dynamics-crank-angle.png", ok, colour, datasets),
        each("dynamics-crank-speed.png", "Crank angular velocity (thesis fig. 15)",
             "crank angular velocity [rad/s]", "crank/angular_velocity"),
        each("dynamics-crank-acceleration.png", "Crank angular acceleration (thesis fig. 16)",
             "crank angular acceleration [rad/s\u00b2]", "crank/angular_acceleration"),
        each("dynamics-constraint-norm.png",
             "Norm of the position constraint equations (thesis fig. 17)",
             "constraint norm [m]", "constraint_norm"),
        _crank_midpoint(folder / "dynamics-crank-midpoint.png", ok, colour),
        each("dynamics-slider-position.png", "Slider position (thesis fig. 19)",
             "slider position x [m]", "slider/position"),
        *_joint_forces(folder, ok, colour),
        each("dynamics-force-B-modulus.png", "Modulus of the reaction force at joint B "
             "(thesis fig. 23)", "|force at B| [N]", "joints/B/force_modulus"),
        _energy(folder / "dynamics-energy.png", ok, colour),
    ]


def _crank_angle(path: Path, ok: dict[str, dict[str, Any]], colour: dict[str, str],
                 datasets: dict[str, Dataset]) -> Path:
    """Crank angle [rad] of each case over the reference DAE's, and their difference [urad]."""
    from flex.base.plotting import legend_below, panels

    with panels(path, "Crank angle: Exudyn against the reference DAE (thesis fig. 14)", rows=2,
                size=(7.0, 6.0), sharex=True, gridspec_kw={"height_ratios": [3, 1.4]}
                ) as (fig, (ax, difference)):
        for name, data in ok.items():
            ax.plot(data["time"], data["crank/angle"], color=colour[name], lw=2.2,
                    label=case_label(name))
            reference = datasets.get(f"reference/{name}/crank_angle")
            if reference is not None:
                ax.plot(data["time"], reference.data, "k:", lw=1.2)
                difference.plot(data["time"], (np.asarray(data["crank/angle"])
                                               - np.asarray(reference.data)) * 1e6,
                                color=colour[name], lw=1.0)
        ax.set_ylabel("crank angle [rad]")
        difference.set_ylabel("Exudyn \u2212\nreference [\u00b5rad]")
        difference.set_xlabel("time [s]")
        legend_below(fig, [("flex (Exudyn): solid, case colour",
                            {"color": "0.5", "lw": 2.2, "linestyle": "-"}),
                           ("reference DAE (9 coordinates, scipy): dotted",
                            {"linestyle": ":", "lw": 1.2})])
    return path


def _crank_midpoint(path: Path, ok: dict[str, dict[str, Any]], colour: dict[str, str]
                    ) -> Path:
    """Trajectory of the crank midpoint [mm] of each case, on its circle about A."""
    from flex.base.plotting import legend_below, panels, sparse_ticks

    with panels(path, "Crank midpoint trajectory during the deployment (thesis fig. 18)",
                size=(6.4, 4.5)) as (fig, (ax,)):
        radius = max(np.hypot(*np.asarray(d["crank/midpoint_position"][0]) * 1e3)
                     for d in ok.values()) if ok else 20.0
        angle = np.linspace(0, np.pi, 181)
        ax.plot(radius * np.cos(angle), radius * np.sin(angle), color="0.75", lw=0.8,
                ls="--", label=f"circle of radius {radius:.3g} mm (crank pivot A at 0, 0)")
        for index, (name, data) in enumerate(ok.items()):
            midpoint = np.asarray(data["crank/midpoint_position"]) * 1e3
            # the cases sweep the same arc: the later ones thinner and dashed on top
            ax.plot(*midpoint.T, color=colour[name], lw=4.0 if index == 0 else 1.6,
                    ls="-" if index == 0 else "--", alpha=0.6 if index == 0 else 1.0,
                    label=f"{case_label(name)} (x: t = {data['time'][-1]:g} s)")
            ax.plot(*midpoint[-1], "x", color=colour[name], ms=9, mew=2)
        if ok:
            ax.plot(*np.asarray(next(iter(ok.values()))["crank/midpoint_position"][0]) * 1e3,
                    "ko", ms=5, label="release (t = 0, both cases)")
        ax.plot(0, 0, "k+", ms=10)
        ax.set_aspect("equal")
        ax.set_xlim(-radius * 1.1, radius * 1.1)
        ax.set_ylim(-radius * 0.1, radius * 1.1)
        sparse_ticks(ax)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        legend_below(fig)
    return path


def _joint_forces(folder: Path, ok: dict[str, dict[str, Any]], colour: dict[str, str]
                  ) -> list[Path]:
    """Reaction forces [N] at A on the crank, B on the crank and B on the coupler (x, y)."""
    from flex.base.plotting import figure, legend_below

    paths = []
    for joint, body, fig_number in (("A", "crank", 20), ("B", "crank", 21),
                                    ("B", "coupler", 22)):
        path = folder / f"dynamics-force-{joint}-on-{body}.png"
        with figure(path, f"Reaction force at joint {joint} on the {body}, x and y "
                    f"components (thesis fig. {fig_number})", "time [s]", "force [N]") as ax:
            for name, data in ok.items():
                force = data[f"joints/{joint}/force_on_{body}"]
                ax.plot(data["time"], force[:, 0], "-", color=colour[name],
                        label=case_label(name))
                ax.plot(data["time"], force[:, 1], "--", color=colour[name])
            legend_below(ax.figure, [("x component (solid)", {"linestyle": "-"}),
                                     ("y component (dashed)", {"linestyle": "--"})])
        paths.append(path)
    return paths


def _energy(path: Path, ok: dict[str, dict[str, Any]], colour: dict[str, str]) -> Path:
    """Total, kinetic and spring energy [J] of each case, and the total's relative drift."""
    from flex.base.plotting import legend_below, panels, relative_drift

    with panels(path, "Energy balance of the undamped deployment: kinetic + spring energy",
                rows=2, size=(7.0, 6.5), sharex=True) as (fig, (energy, drift)):
        for name, data in ok.items():
            energy.plot(data["time"], data["energy/total"], "-", color=colour[name], lw=2,
                        label=case_label(name))
            if "energy/kinetic" in data:
                energy.plot(data["time"], data["energy/kinetic"], "--", color=colour[name])
            if "energy/spring_potential" in data:
                energy.plot(data["time"], data["energy/spring_potential"], ":",
                            color=colour[name])
            drift.plot(data["time"], relative_drift(data["energy/total"]), color=colour[name],
                       label=case_label(name))
        energy.set_ylabel("energy [J]")
        legend_below(fig, [("total energy, kinetic + spring (solid)",
                            {"linestyle": "-", "lw": 2}),
                           ("kinetic energy (dashed)", {"linestyle": "--"}),
                           ("spring potential energy (dotted)", {"linestyle": ":"})])
        drift.set_ylabel("relative drift of the total\n(E \u2212 E0) / E0 [-]")
        drift.set_xlabel("time [s]")
        drift.axhline(0.0, color="k", lw=0.6)
    return path
