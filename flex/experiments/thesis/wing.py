"""A missile wing deployed by the mechanism (thesis sec. 6.4, figs. 59-60): the spring fit,
the wing's flexibility, and the summary and figures of the ``wing`` study.

The thesis gives only the outcome (peak wing-tip angular velocity
:data:`~flex.base.thesis.THESIS_WING_PEAK_RATE_DEG_PER_S` at
:data:`~flex.base.thesis.THESIS_WING_PEAK_TIME_S`, deployment in
:data:`~flex.base.thesis.THESIS_WING_DEPLOYMENT_TIME_S`). :func:`fit_spring` fits the two spring
values it leaves open, stiffness [N/m] and preload [m], to the peak on the reference DAE;
:func:`wing_flexibility` rates the wing plate as a cantilever (frequencies [Hz], n, quasi-static
tip deflection [m]); :func:`summary` reports a run's loads, timing and flexibility, and the
``auto`` fidelity decisions for the other links as the run simulated them.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.physics import n_values
from flex.base.thesis import (
    THESIS_WING_DEPLOYMENT_TIME_S,
    THESIS_WING_PEAK_RATE_DEG_PER_S,
    THESIS_WING_PEAK_TIME_S,
)
from flex.data.headlines import first_maximum_index
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene
from flex.data.scene_edit import derive_scene
from flex.dynamics.reference import crank_mass_properties, solve_reference
from flex.experiments.thesis.beams import Material, timoshenko_bending_rad_per_s

WING_POISSON_RATIO = 0.33
"""Poisson's ratio of the aluminium wing (enters the Timoshenko shear term only)."""
RIGID_TIP_DEFLECTION = 1e-3
"""Elastic tip deflection / span below which a rigid wing is enough [-]."""


def peak_rate(scene: Scene) -> tuple[float, float]:
    """Peak wing angular velocity [deg/s] and its time [s] from the reference DAE."""
    reference = solve_reference(scene, rtol=1e-10, atol=1e-12)
    rate = np.degrees(reference.q_dot[:, 2])
    index = int(np.argmax(rate))
    return float(rate[index]), float(reference.time_s[index])


def fit_spring(scene: Scene) -> tuple[Scene, dict[str, float]]:
    """Spring stiffness [N/m] and preload [m] reproducing the thesis's peak rate and time:
    the fitted scene (validated) and the values with the fit's relative residuals.

    Uses the independent reference DAE (fast, checked against Exudyn) on a log scale.
    """
    from scipy.optimize import least_squares

    def residual(log_values: np.ndarray) -> np.ndarray:
        stiffness_N_per_m, preload_m = np.exp(log_values)
        rate, time_s = peak_rate(derive_scene(scene, {
            "drive.spring_stiffness_N_per_m": stiffness_N_per_m,
            "drive.spring_preload_m": preload_m}))
        return np.array([rate / THESIS_WING_PEAK_RATE_DEG_PER_S - 1,
                         time_s / THESIS_WING_PEAK_TIME_S - 1])

    start = np.log([scene["drive"]["spring_stiffness_N_per_m"] * 4,
                    scene["drive"]["spring_preload_m"]])
    # the peak time moves on the output grid: finite differences need a step above it
    fit = least_squares(residual, start, diff_step=0.02, xtol=1e-6)
    stiffness, preload = np.exp(fit.x)
    fitted = derive_scene(scene, {"drive.spring_stiffness_N_per_m": stiffness,
                                  "drive.spring_preload_m": preload})
    return fitted, {"stiffness_N_per_m": float(stiffness), "preload_m": float(preload),
                    "residual_rate": float(fit.fun[0]), "residual_time": float(fit.fun[1])}


def wing_flexibility(scene: Scene, peak_angular_acceleration_rad_per_s2: float,
                     deployment_time_s: float) -> dict[str, float]:
    """Cantilever frequencies of the wing plate [Hz], n = delta_t / T, and the quasi-static
    tip deflection [m] under the peak angular acceleration (load linear along the span)."""
    wing = scene["wing"]
    material = Material(wing["youngs_modulus_Pa"], wing["density_kg_per_m3"],
                        WING_POISSON_RATIO)
    in_plane = timoshenko_bending_rad_per_s(wing["span_m"], wing["chord_m"],
                                            wing["thickness_m"], "clamped-free", 1,
                                            material=material)[0]
    out_of_plane = timoshenko_bending_rad_per_s(wing["span_m"], wing["thickness_m"],
                                                wing["chord_m"], "clamped-free", 1,
                                                material=material)[0]
    area_m2 = wing["chord_m"] * wing["thickness_m"]
    second_moment_m4 = wing["thickness_m"] * wing["chord_m"] ** 3 / 12
    # q(r) = rho A alpha r: cantilever under a load rising linearly to q0 at the tip
    q0 = wing["density_kg_per_m3"] * area_m2 * peak_angular_acceleration_rad_per_s2 \
        * wing["span_m"]
    tip_m = 11 * q0 * wing["span_m"] ** 4 / (120 * wing["youngs_modulus_Pa"] * second_moment_m4)
    n = n_values(deployment_time_s, in_plane)
    return {"in_plane_frequency_Hz": in_plane / (2 * np.pi),
            "out_of_plane_frequency_Hz": out_of_plane / (2 * np.pi),
            "n_in_plane_physical": n["physical"],
            "n_in_plane_thesis": n["thesis"],
            "quasi_static_tip_deflection_m": tip_m,
            "tip_deflection_over_span": tip_m / wing["span_m"]}


def deployment_values(scene: Scene, data: dict[str, np.ndarray]
                      ) -> dict[str, tuple[float, str, str]]:
    """What a wing deployment run reports, ``{key: (value, unit, description)}``: the
    fitted spring, the peak rate [deg/s] and its time [s], the deployment time [s] (first
    wing-angle maximum), the swing [rad], the rotating inertia [kg m^2], the peak joint
    loads [N], root moment [N m] and tip speed [m/s], and :func:`wing_flexibility`."""
    drive = scene["drive"]
    time_s, angle = data["time"], data["wing/angle"]
    rate_deg = data["wing/angular_velocity_deg"]
    peak = int(np.argmax(rate_deg))
    stop = first_maximum_index(angle)
    deployment_s = float(time_s[stop]) if stop is not None else float("nan")
    stop = len(angle) - 1 if stop is None else stop  # still rising: the swing so far
    alpha_peak = float(np.abs(data["wing/angular_acceleration"]).max())
    flexibility = wing_flexibility(scene, alpha_peak, deployment_s)
    mass_kg, inertia_kgm2, centre_m = crank_mass_properties(scene)
    loads = {name: float(np.abs(data[f"joints/{name}/force_modulus"]).max())
             for name in ("A", "B", "C")}
    return {
        "spring_stiffness": (drive["spring_stiffness_N_per_m"], "N/m", "fitted"),
        "spring_preload": (drive["spring_preload_m"], "m", "fitted"),
        "peak_rate": (float(rate_deg[peak]), "deg/s",
                      f"thesis {THESIS_WING_PEAK_RATE_DEG_PER_S:g} deg/s"),
        "peak_rate_time": (float(time_s[peak]), "s", f"thesis ~{THESIS_WING_PEAK_TIME_S:g} s"),
        "deployment_time": (deployment_s, "s", "first wing-angle maximum; thesis "
                            f"~{THESIS_WING_DEPLOYMENT_TIME_S:g} s"),
        "swing": (float(angle[stop] - angle[0]), "rad", "wing rotation during deployment"),
        "wing_plus_crank_inertia_about_A": (inertia_kgm2 + mass_kg * centre_m**2, "kg m^2",
                                            "rotating inertia about the pivot"),
        **{f"peak_force_{name}": (value, "N", f"max |reaction| at {name}")
           for name, value in loads.items()},
        "peak_root_moment": (float(np.abs(data["joints/W/root_moment"]).max()), "N m",
                             "max |in-plane wing-root moment|"),
        "peak_tip_speed": (float(data["wing/tip_speed"].max()), "m/s", "wing tip"),
        **{key: (value, "Hz" if key.endswith("Hz") else ("m" if key.endswith("_m") else "1"),
                 key.replace("_", " ")) for key, value in flexibility.items()},
    }


def summary(case: CaseResult, cache_dir: Path | None = None) -> tuple[dict[str, Dataset], str]:
    """The ``wing`` summary of one deployment run (its own, fitted scene): ``wing/*`` and
    ``auto/*`` datasets and the report. ``cache_dir``: the reduction cache folder of the
    ``auto`` decisions (None: built in memory, no disk cache)."""
    if case.status != "ok":
        return {}, f"wing: case failed: {case.message}"
    scene = tomllib.loads(case.scene_toml)  # the fitted scene this case ran
    data = {k: v.data for k, v in case.datasets.items()}
    values = deployment_values(scene, data)
    datasets = {f"wing/{k}": Dataset(v, u, d) for k, (v, u, d) in values.items()}
    value = {key: entry[0] for key, entry in values.items()}
    verdict = ("a rigid wing is enough here (elastic tip deflection below 0.1 % of the span)"
               if value["tip_deflection_over_span"] < RIGID_TIP_DEFLECTION else
               "the wing's elasticity matters here: model it flexible")
    wing = scene["wing"]
    lines = [
        "wing: thesis sec. 6.4 (only the outcome is given; wing and spring are flex's choice)",
        f"  wing plate {wing['span_m'] * 1e3:g} x {wing['chord_m'] * 1e3:g} x "
        f"{wing['thickness_m'] * 1e3:g} mm aluminium; spring fitted: k = "
        f"{value['spring_stiffness']:.0f} N/m, preload {value['spring_preload'] * 1e3:.2f} mm",
        f"  peak wing rate {value['peak_rate']:.0f} deg/s at {value['peak_rate_time']:.4f} s "
        f"(thesis 7219 deg/s at ~0.008 s, fitted); deployment (first angle maximum) "
        f"{value['deployment_time']:.4f} s (thesis ~0.017 s, predicted)",
        f"  peak joint loads |A| {value['peak_force_A']:.0f} N, |B| {value['peak_force_B']:.0f}"
        f" N, |C| {value['peak_force_C']:.0f} N; wing-root moment "
        f"{value['peak_root_moment']:.2f} N m; tip speed {value['peak_tip_speed']:.1f} m/s",
        f"  wing flexibility: cantilever in-plane {value['in_plane_frequency_Hz']:.0f} Hz"
        f" (n = {value['n_in_plane_physical']:.0f}, thesis convention "
        f"{value['n_in_plane_thesis']:.0f}), out-of-plane "
        f"{value['out_of_plane_frequency_Hz']:.0f} Hz (not excited by planar motion); "
        f"quasi-static tip deflection {value['quasi_static_tip_deflection_m'] * 1e6:.2f}"
        f" um = {value['tip_deflection_over_span']:.1e} of the span -> {verdict}",
    ]
    lines += auto_decisions(scene, datasets, cache_dir)
    return datasets, "\n".join(lines)


def auto_decisions(scene: Scene, datasets: dict[str, Dataset],
                   cache_dir: Path | None = None) -> list[str]:
    """The ``auto`` fidelity decisions for the links as this run simulated them (its own
    scene, ``model = "auto"`` in place of each link's model): the crank (a lumped crank is
    analysed as the plate of its mass) and the coupler when it is a plate (a lumped coupler
    has no stiffness to decide on: said so). Stored as ``auto/<link>/model`` in
    ``datasets``; the report lines. ``cache_dir``: the reduction cache folder of the crank's
    frequency analysis (None: built in memory)."""
    try:
        from flex.fidelity.auto import decide_links
    except ImportError:
        return ["  auto fidelity: no fitted criterion in this installation"]
    overrides = ['crank.model="auto"']
    lines = []
    if scene["coupler"]["geometry"] == "plate":
        overrides.append('coupler.model="auto"')
    else:
        lines.append('  auto fidelity: coupler as simulated: lumped (mass and inertia only), '
                     'no stiffness to decide on (auto needs coupler.geometry = "plate")')
    try:
        trial = derive_scene(scene, overrides)
        _, decisions = decide_links(trial, cache_dir=cache_dir)
    except Exception as exc:  # a refusal is itself the answer worth reporting
        return lines + [f"  auto fidelity (the links as simulated): {exc}"]
    for decision in decisions:
        datasets[f"auto/{decision.link}/model"] = Dataset(np.array(decision.model, dtype=object),
                                                          "1", decision.reason)
        lines.append(f"  auto fidelity: {decision.link} as simulated: {decision.reason} -> "
                     f"{decision.model}")
    return lines


def draw_figures(case: CaseResult, folder: Path) -> list[Path]:
    """``wing-angle.png``, ``wing-angular-velocity.png`` (with the thesis's peak) and
    ``wing-loads.png`` of one deployment run, in ``folder``."""
    from flex.base.plotting import figure

    data: dict[str, Any] = {k: v.data for k, v in case.datasets.items()}
    paths = [folder / "wing-angle.png", folder / "wing-angular-velocity.png",
             folder / "wing-loads.png"]
    with figure(paths[0], "Wing angular displacement (cf. thesis fig. 59)", "time [s]",
                "wing rotation since release [deg]") as ax:
        ax.plot(data["time"], np.degrees(data["wing/angle"] - data["wing/angle"][0]))
    with figure(paths[1], "Wing-tip angular velocity (cf. thesis fig. 60)", "time [s]",
                "angular velocity [deg/s]") as ax:
        ax.plot(data["time"], data["wing/angular_velocity_deg"], label="flex (Exudyn)")
        ax.plot([THESIS_WING_PEAK_TIME_S], [THESIS_WING_PEAK_RATE_DEG_PER_S], "r*", ms=12,
                label="thesis peak (7219 deg/s, ~0.008 s)")
    with figure(paths[2], "Joint reaction forces during the wing deployment (moduli)",
                "time [s]", "|reaction force| [N]") as ax:
        for name, where in (("A", "crank pivot"), ("B", "crank-coupler"),
                            ("C", "coupler-slider")):
            ax.plot(data["time"], data[f"joints/{name}/force_modulus"],
                    label=f"joint {name} ({where})")
        ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3)
    return paths
