"""Study ``wing`` (thesis sec. 6.4, figs. 59-60): a missile wing deployed by the mechanism.

The thesis gives only the outcome: deployment ~0.017 s, wing-tip angular velocity peaking
near 7219 deg/s at ~0.008 s; no wing geometry, inertia or spring. flex states a wing (an
aluminium switchblade plate in the mechanism plane, welded to the crank at the pivot A, the
``[wing]`` keys of the scene) and fits the two spring values the thesis leaves open --
stiffness and preload -- so that the deployment reproduces the reported peak speed and its
time. The deployment time (first crank-angle maximum) is then a prediction, compared with
the thesis's ~0.017 s.

Reported beside it: the joint loads and the wing-root bending moment; the wing's own
flexibility (cantilever bending frequencies in and out of plane, the thesis's ratio n, and
the quasi-static tip deflection under the peak inertial load); and, for the other bodies,
the ``auto`` fidelity decision of :mod:`flex.criteria` where a fitted criterion exists.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from flex import modal
from flex.criteria import first_maximum_index
from flex.physics import n_values
from flex.plotting import figure
from flex.reference import solve_reference
from flex.results import CaseResult, Dataset
from flex.scene import Scene, apply_overrides, validate
from flex.simulation import simulate_case
from flex.study import StudyRun, Summary
from flex.thesis import (  # noqa: F401 - the thesis's sec. 6.4 values, named here as before
    THESIS_WING_DEPLOYMENT_TIME_S as THESIS_DEPLOYMENT_TIME_S,
)
from flex.thesis import THESIS_WING_PEAK_RATE_DEG_PER_S as THESIS_PEAK_RATE_DEG_PER_S
from flex.thesis import THESIS_WING_PEAK_TIME_S as THESIS_PEAK_TIME_S

NAME = "wing"
DESCRIPTION = "wing deployment (sec. 6.4): fitted spring, loads, wing flexibility"
OVERRIDES = ["wing.enabled=true", "simulation.end_time_s=0.025"]
# keys the study reads itself (the wing's frequency and tip deflection, the spring fit)
READS = ("wing.span_m", "wing.chord_m", "wing.thickness_m", "wing.density_kg_per_m3",
         "wing.youngs_modulus_Pa", "drive.spring_preload_m",
         "drive.spring_stiffness_N_per_m")


def peak_rate(scene: Scene) -> tuple[float, float]:
    """Peak wing angular velocity [deg/s] and its time [s] from the reference DAE."""
    reference = solve_reference(scene, rtol=1e-10, atol=1e-12)
    rate = np.degrees(reference.q_dot[:, 2])
    index = int(np.argmax(rate))
    return float(rate[index]), float(reference.time_s[index])


def fit_spring(scene: Scene) -> tuple[Scene, dict[str, float]]:
    """Spring stiffness [N/m] and preload [m] reproducing the thesis's peak rate and time.

    Uses the independent reference DAE (fast, checked against Exudyn) on a log scale.
    """
    def residual(log_values: np.ndarray) -> np.ndarray:
        stiffness, preload = np.exp(log_values)
        trial = apply_overrides(scene, [f"drive.spring_stiffness_N_per_m={stiffness}",
                                        f"drive.spring_preload_m={preload}"])
        rate, time_s = peak_rate(trial)
        return np.array([rate / THESIS_PEAK_RATE_DEG_PER_S - 1, time_s / THESIS_PEAK_TIME_S - 1])

    start = np.log([scene["drive"]["spring_stiffness_N_per_m"] * 4,
                    scene["drive"]["spring_preload_m"]])
    # the peak time moves on the output grid: finite differences need a step above it
    fit = least_squares(residual, start, diff_step=0.02, xtol=1e-6)
    stiffness, preload = np.exp(fit.x)
    fitted = apply_overrides(scene, [f"drive.spring_stiffness_N_per_m={stiffness}",
                                     f"drive.spring_preload_m={preload}"])
    validate(fitted)
    return fitted, {"stiffness_N_per_m": float(stiffness), "preload_m": float(preload),
                    "residual_rate": float(fit.fun[0]), "residual_time": float(fit.fun[1])}


def cases(scene: Scene) -> dict[str, Scene]:
    fitted, _ = fit_spring(scene)
    return {"wing_deployment": fitted}


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    progress = run.progress
    results = {}
    for index, (name, scene) in enumerate(scenes.items()):
        if progress:
            progress(name, index, len(scenes))
        results[name] = simulate_case(scene, name)
    return results


def wing_flexibility(scene: Scene, peak_angular_acceleration_rad_per_s2: float,
                     deployment_time_s: float) -> dict[str, float]:
    """Cantilever frequencies of the wing plate [Hz], n = delta_t / T, and the quasi-static
    tip deflection [m] under the peak angular acceleration (load linear along the span)."""
    wing = scene["wing"]
    material = modal.Material(wing["youngs_modulus_Pa"], wing["density_kg_per_m3"], 0.33)
    in_plane = modal.timoshenko_bending_rad_per_s(wing["span_m"], wing["chord_m"],
                                                  wing["thickness_m"], "clamped-free", 1,
                                                  material=material)[0]
    out_of_plane = modal.timoshenko_bending_rad_per_s(wing["span_m"], wing["thickness_m"],
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


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    case = results["wing_deployment"]
    if case.status != "ok":
        return Summary(report=f"wing: case failed: {case.message}")
    scene_case = tomllib.loads(case.scene_toml)  # the fitted scene this case ran
    data = {k: v.data for k, v in case.datasets.items()}
    drive = scene_case["drive"]
    time_s, angle = data["time"], data["wing/angle"]
    rate_deg = data["wing/angular_velocity_deg"]
    peak = int(np.argmax(rate_deg))
    stop = first_maximum_index(angle)
    deployment_s = float(time_s[stop]) if stop is not None else float("nan")
    stop = len(angle) - 1 if stop is None else stop  # still rising: the swing so far
    alpha_peak = float(np.abs(data["wing/angular_acceleration"]).max())
    flexibility = wing_flexibility(scene_case, alpha_peak, deployment_s)
    from flex.reference import crank_mass_properties

    mass_kg, inertia_kgm2, centre_m = crank_mass_properties(scene_case)
    loads = {name: float(np.abs(data[f"joints/{name}/force_modulus"]).max())
             for name in ("A", "B", "C")}
    root_moment = float(np.abs(data["joints/W/root_moment"]).max())
    values = {
        "spring_stiffness": (drive["spring_stiffness_N_per_m"], "N/m", "fitted"),
        "spring_preload": (drive["spring_preload_m"], "m", "fitted"),
        "peak_rate": (float(rate_deg[peak]), "deg/s",
                      f"thesis {THESIS_PEAK_RATE_DEG_PER_S:g} deg/s"),
        "peak_rate_time": (float(time_s[peak]), "s", f"thesis ~{THESIS_PEAK_TIME_S:g} s"),
        "deployment_time": (deployment_s, "s", "first wing-angle maximum; thesis "
                            f"~{THESIS_DEPLOYMENT_TIME_S:g} s"),
        "swing": (float(angle[stop] - angle[0]), "rad", "wing rotation during deployment"),
        "wing_plus_crank_inertia_about_A": (inertia_kgm2 + mass_kg * centre_m**2, "kg m^2",
                                            "rotating inertia about the pivot"),
        "peak_force_A": (loads["A"], "N", "max |reaction| at A"),
        "peak_force_B": (loads["B"], "N", "max |reaction| at B"),
        "peak_force_C": (loads["C"], "N", "max |reaction| at C"),
        "peak_root_moment": (root_moment, "N m", "max |in-plane wing-root moment|"),
        "peak_tip_speed": (float(data["wing/tip_speed"].max()), "m/s", "wing tip"),
        **{key: (value, "Hz" if key.endswith("Hz") else ("m" if key.endswith("_m") else "1"),
                 key.replace("_", " ")) for key, value in flexibility.items()},
    }
    datasets = {f"wing/{k}": Dataset(v, u, d) for k, (v, u, d) in values.items()}
    verdict = ("a rigid wing is enough here (elastic tip deflection below 0.1 % of the span)"
               if flexibility["tip_deflection_over_span"] < 1e-3 else
               "the wing's elasticity matters here: model it flexible")
    lines = [
        "wing: thesis sec. 6.4 (only the outcome is given; wing and spring are flex's choice)",
        f"  wing plate {scene_case['wing']['span_m'] * 1e3:g} x "
        f"{scene_case['wing']['chord_m'] * 1e3:g} x {scene_case['wing']['thickness_m'] * 1e3:g}"
        f" mm aluminium; spring fitted: k = {drive['spring_stiffness_N_per_m']:.0f} N/m, "
        f"preload {drive['spring_preload_m'] * 1e3:.2f} mm",
        f"  peak wing rate {rate_deg[peak]:.0f} deg/s at {time_s[peak]:.4f} s (thesis 7219 deg/s"
        f" at ~0.008 s, fitted); deployment (first angle maximum) {deployment_s:.4f} s "
        f"(thesis ~0.017 s, predicted)",
        f"  peak joint loads |A| {loads['A']:.0f} N, |B| {loads['B']:.0f} N, |C| "
        f"{loads['C']:.0f} N; wing-root moment {root_moment:.2f} N m; tip speed "
        f"{data['wing/tip_speed'].max():.1f} m/s",
        f"  wing flexibility: cantilever in-plane {flexibility['in_plane_frequency_Hz']:.0f} Hz"
        f" (n = {flexibility['n_in_plane_physical']:.0f}, thesis convention "
        f"{flexibility['n_in_plane_thesis']:.0f}), out-of-plane "
        f"{flexibility['out_of_plane_frequency_Hz']:.0f} Hz (not excited by planar motion); "
        f"quasi-static tip deflection {flexibility['quasi_static_tip_deflection_m'] * 1e6:.2f}"
        f" um = {flexibility['tip_deflection_over_span']:.1e} of the span -> {verdict}",
    ]
    lines += _auto_decisions(scene_case, datasets)
    return Summary(datasets, "\n".join(lines))


def _auto_decisions(scene: Scene, datasets: dict[str, Dataset]) -> list[str]:
    """The ``auto`` fidelity decisions for the coupler (as a 3 mm steel plate) and the crank."""
    try:
        from flex.criteria import resolve_fidelity
    except ImportError:
        return ["  auto fidelity: no fitted criterion in this installation"]
    trial = apply_overrides(scene, ['coupler.geometry="plate"', "coupler.thickness_m=0.003",
                                    'coupler.model="auto"', 'crank.model="auto"'])
    try:
        validate(trial)
        _, decisions = resolve_fidelity(trial)
    except Exception as exc:  # a refusal is itself the answer worth reporting
        return [f"  auto fidelity (coupler as a 3 mm plate): {exc}"]
    lines = []
    for decision in decisions:
        datasets[f"auto/{decision.link}/model"] = Dataset(np.array(decision.model, dtype=object),
                                                          "1", decision.reason)
        lines.append(f"  auto fidelity: {decision.reason} -> {decision.model}")
    return lines


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    data = {k: v.data for k, v in results["wing_deployment"].datasets.items()}
    paths = []
    path = folder / "wing-angle.png"
    with figure(path, "Wing angular displacement (cf. thesis fig. 59)", "time [s]",
                "wing rotation since release [deg]") as ax:
        ax.plot(data["time"], np.degrees(data["wing/angle"] - data["wing/angle"][0]))
    paths.append(path)
    path = folder / "wing-angular-velocity.png"
    with figure(path, "Wing-tip angular velocity (cf. thesis fig. 60)", "time [s]",
                "angular velocity [deg/s]") as ax:
        ax.plot(data["time"], data["wing/angular_velocity_deg"], label="flex (Exudyn)")
        ax.plot([THESIS_PEAK_TIME_S], [THESIS_PEAK_RATE_DEG_PER_S], "r*", ms=12,
                label="thesis peak (7219 deg/s, ~0.008 s)")
    paths.append(path)
    path = folder / "wing-loads.png"
    with figure(path, "Joint reaction forces during the wing deployment (moduli)", "time [s]",
                "|reaction force| [N]") as ax:
        for name, where in (("A", "crank pivot"), ("B", "crank-coupler"),
                            ("C", "coupler-slider")):
            ax.plot(data["time"], data[f"joints/{name}/force_modulus"],
                    label=f"joint {name} ({where})")
        ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3)
    paths.append(path)
    return paths


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
