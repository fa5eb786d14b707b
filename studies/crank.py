"""Study ``crank``: the flexible (FFRF) crank, and whether ``crank.model = "auto"`` holds.

The thesis models only the coupler as flexible. flex also meshes the crank (a steel plate
A-B, ``[crank] geometry = "plate"``, reduced like the coupler) and lets ``auto`` choose
rigid or FFRF for it from the kfit criterion, with the crank's first in-plane elastic
frequency in the assembled mechanism (:func:`flex.criteria.crank_elastic_omega`). Without a
wing that is the plate's pinned-pinned frequency; with the wing welded at A the crank is a
cantilever from the wing carrying coupler and slider at B, an order of magnitude softer.

Each validation scene (crank thicknesses, with and without the wing, tolerances 1 % and
0.1 %; none of them in the kfit fit, which varied the coupler only) runs twice: ``auto``
(the choice and its reason stored) and the full model, an FFRF crank with
:data:`FULL_MODES` modes. The errors of the auto run against the full one, over the
deployment (to the first crank-angle maximum of the full run), are the kfit measures with
the crank in the coupler's place: crank midpoint deflection / L1, crank angle / swing,
slider position / travel; the largest is held against the tolerance. The report says
plainly where the criterion, fitted on couplers, does not hold for the crank.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flex import criteria
from flex.plotting import figure
from flex.results import CaseResult, Dataset
from flex.scene import Scene, apply_overrides
from flex.study import Summary

NAME = "crank"
DESCRIPTION = "flexible FFRF crank against auto's choice, with and without the wing"
OVERRIDES = ['crank.geometry="plate"', "simulation.step_s=2e-5",
             "simulation.end_time_s=0.05"]
FULL_MODES = 12

#: validation scenes: name -> (overrides, fidelity tolerance)
SCENES: dict[str, tuple[list[str], float]] = {
    "wing_t1mm_tol1pct": (["crank.thickness_m=0.001", "wing.enabled=true"], 0.01),
    "wing_t1p5mm_tol1pct": (["crank.thickness_m=0.0015", "wing.enabled=true"], 0.01),
    "wing_t2mm_tol1pct": (["crank.thickness_m=0.002", "wing.enabled=true"], 0.01),
    "wing_t3mm_tol0p1pct": (["crank.thickness_m=0.003", "wing.enabled=true"], 0.001),
    "wing_t4p56mm_tol0p1pct": (["wing.enabled=true"], 0.001),
    "t1mm_tol0p1pct": (["crank.thickness_m=0.001"], 0.001),
}


def cases(scene: Scene) -> dict[str, Scene]:
    """Per validation scene an ``auto`` case and a ``full`` FFRF-crank case."""
    out = {}
    for name, (changes, tolerance) in SCENES.items():
        base = apply_overrides(scene, changes)
        out[f"{name}__auto"] = apply_overrides(base, ['crank.model="auto"',
                                                     f"fidelity.tolerance={tolerance!r}"])
        out[f"{name}__full"] = apply_overrides(base, ['crank.model="ffrf"',
                                                     f"crank.modes={FULL_MODES}"])
    return out


def errors(auto: dict[str, np.ndarray], full: dict[str, np.ndarray],
           crank_length_m: float) -> dict[str, float]:
    """Relative errors of ``auto`` against ``full`` over the full run's deployment (see the
    module doc); ``governing`` is the largest. Series of the result layout."""
    times = criteria.deployment_times(full["time"], full["crank/angle"],
                                      full["crank/angular_velocity"])
    count = int(np.sum(full["time"] <= times["stop"] * (1 + 1e-12)))

    def deviation(key: str) -> float:
        mine = auto.get(key, np.zeros(count))
        return float(np.max(np.abs(mine[:count] - full[key][:count])))

    swing = float(np.max(np.abs(full["crank/angle"][:count] - full["crank/angle"][0])))
    travel = float(np.max(np.abs(full["slider/position"][:count]
                                 - full["slider/position"][0])))
    out = {"deflection": deviation("crank/midpoint_deflection") / crank_length_m,
           "crank_angle": deviation("crank/angle") / swing,
           "slider_position": deviation("slider/position") / travel}
    out[criteria.GOVERNING] = max(out.values())
    out["delta_t"] = times["stop"]
    return out


def summarize(scene: Scene, results: dict[str, CaseResult]) -> Summary:
    datasets: dict[str, Dataset] = {}
    lines = ["crank: auto against a full FFRF crank (12 modes); errors over the deployment",
             f"  {'scene':24s} {'tol':>6s} {'choice':>8s} {'omega':>9s} {'n':>6s} {'k':>6s} "
             f"{'predicted':>9s} {'error':>9s} {'ok':>3s} {'auto s':>7s} {'full s':>7s}"]
    failures = []
    for name, (_, tolerance) in SCENES.items():
        auto, full = results[f"{name}__auto"], results[f"{name}__full"]
        if auto.status != "ok" or full.status != "ok":
            lines.append(f"  {name:24s} failed: {auto.message or full.message}")
            continue
        data = {label: {k: np.asarray(v.data) for k, v in case.datasets.items()}
                for label, case in (("auto", auto), ("full", full))}
        measured = errors(data["auto"], data["full"], scene["crank"]["length_m"])
        attrs = auto.attrs
        model = str(attrs["fidelity_crank_model"])
        choice = model + (f"/{attrs['fidelity_crank_modes']}" if model == "ffrf" else "")
        ok = measured[criteria.GOVERNING] <= tolerance
        if not ok:
            failures.append(name)
        group = f"validation/{name}"
        for key in ("deflection", "crank_angle", "slider_position", criteria.GOVERNING):
            datasets[f"{group}/errors/{key}"] = Dataset(measured[key], "1",
                                                        f"auto against full: {key}")
        datasets[f"{group}/tolerance"] = Dataset(tolerance, "1", "fidelity.tolerance")
        datasets[f"{group}/within_tolerance"] = Dataset(int(ok), "1", "1 if error <= tol")
        datasets[f"{group}/choice"] = Dataset(np.array(choice), "1", "auto's choice")
        datasets[f"{group}/reason"] = Dataset(np.array(str(attrs["fidelity_crank_reason"])),
                                              "1", "auto's reason")
        for key, units in (("omega_rad_per_s", "rad/s"), ("n_physical", "1"),
                           ("k_physical", "1"), ("predicted_error", "1")):
            datasets[f"{group}/{key}"] = Dataset(float(attrs[f"fidelity_crank_{key}"]), units,
                                                 f"auto decision: {key}")
        datasets[f"{group}/delta_t"] = Dataset(measured["delta_t"], "s",
                                               criteria.DELTA_T_DEFINITIONS["stop"])
        for label, case in (("auto", auto), ("full", full)):
            datasets[f"{group}/wall_time/{label}"] = Dataset(
                case.counters["wall_time_s"], "s", f"integration of the {label} model")
        datasets[f"{group}/peak_crank_deflection"] = Dataset(
            float(np.abs(data["full"]["crank/midpoint_deflection"]).max()), "m",
            "full model: peak |crank midpoint deflection|")
        numbers = [attrs[f"fidelity_crank_{key}"] for key in
                   ("omega_rad_per_s", "n_physical", "k_physical", "predicted_error")]
        lines.append(
            f"  {name:24s} {tolerance:6g} {choice:>8s} {numbers[0]:9.4g} {numbers[1]:6.3g} "
            f"{numbers[2]:6.3g} {numbers[3]:9.2e} {measured[criteria.GOVERNING]:9.2e} "
            f"{'yes' if ok else 'NO':>3s} {auto.counters['wall_time_s']:7.2f} "
            f"{full.counters['wall_time_s']:7.2f}")
    datasets["failures"] = Dataset(len(failures), "1",
                                   "validation scenes whose auto error exceeds the tolerance")
    if failures:
        lines.append(f"  NOT within tolerance: {', '.join(failures)} -- the criterion is fitted "
                     "on couplers; a crank carrying the wing bends under a larger quasi-static "
                     "load for the same n, so its rigid error is larger than the coupler law "
                     "predicts (README, 'The crank')")
    else:
        lines.append("  every auto choice within its tolerance")
    return Summary(datasets, "\n".join(lines))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    deflection = folder / "crank-deflection.png"
    with figure(deflection, "full FFRF crank (12 modes): elastic midpoint deflection",
                "time [ms]", "crank midpoint deflection [um]") as ax:
        for name in SCENES:
            full = results[f"{name}__full"]
            if full.status == "ok":
                ax.plot(full.datasets["time"].data * 1e3,
                        full.datasets["crank/midpoint_deflection"].data * 1e6, label=name)
    validation = folder / "crank-validation.png"
    with figure(validation, "auto for the crank (o rigid, s ffrf; red: above tolerance)",
                "n = delta_t / T (crank's first in-plane elastic mode in the mechanism)",
                "error of auto against the full FFRF crank") as ax:
        for name in SCENES:
            key = f"validation/{name}"
            if f"{key}/n_physical" not in summary.datasets:
                continue
            n = float(summary.datasets[f"{key}/n_physical"].data)
            error = max(float(summary.datasets[f"{key}/errors/governing"].data), 1e-9)
            tolerance = float(summary.datasets[f"{key}/tolerance"].data)
            rigid = str(summary.datasets[f"{key}/choice"].data) == "rigid"
            ax.loglog([n], [error], "o" if rigid else "s",
                      color="C0" if error <= tolerance else "C3")
            ax.annotate(f" {name}", (n, error), fontsize=7)
    return [deflection, validation]
