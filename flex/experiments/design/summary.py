"""The design study's summary: the table of every case, the lines of measures against initial
angle through the design point, their extrema and the thesis's optimum-angle claim, and the
datasets the report and the figures read (:func:`summary_datasets`). The cases:
:mod:`flex.experiments.design.cases`.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from typing import Any

import numpy as np

from flex.base.mechanism_checks import (
    dead_centre_angles_rad,
)
from flex.data.headlines import first_maximum_index
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene
from flex.experiments.design.cases import (
    A36_YIELD_STRESS_PA,
    MEASURES,
    DesignPoint,
    Grid,
    design_case_name,
    plan,
    rest_angle_rad,
)
from flex.experiments.design.mechanism import mechanism_checks

# ------------------------------------------------------------------------------------------
# the table of every case
# ------------------------------------------------------------------------------------------
INPUTS = {"angle_deg": ("deg", "crank", "initial_angle_deg"),
          "preload_m": ("m", "drive", "spring_preload_m"),
          "rate_N_per_m": ("N/m", "drive", "spring_stiffness_N_per_m"),
          "thickness_m": ("m", "coupler", "thickness_m")}


def table(results: Mapping[str, CaseResult]) -> dict[str, np.ndarray]:
    """One row per case (in ``results`` order): ``case``, ``outcome``, ``model``, the
    :data:`INPUTS`, every measure (NaN where refused or failed) and ``valid``: 1 for a
    deployment that comes to rest before the folded dead centre (a crank that turns through
    it is no deployment: its speeds are left out of the extrema)."""
    rows: dict[str, list] = {key: [] for key in ("case", "outcome", "model", *INPUTS, *MEASURES,
                                                 "valid")}
    for name, case in results.items():
        scene = tomllib.loads(case.scene_toml)
        fold = dead_centre_angles_rad(scene["crank"]["length_m"], scene["coupler"]["length_m"],
                                      scene["slider"]["offset_m"])[1]
        rows["case"].append(name)
        outcome = case.attrs.get("design_outcome", "failed") if case.status == "ok" else "failed"
        rows["outcome"].append(outcome)
        rows["model"].append(str(case.attrs.get("design_model", "-")))
        for key, (_, section, field_name) in INPUTS.items():
            rows[key].append(float(scene[section][field_name]))
        for key in MEASURES:
            dataset = case.datasets.get(f"measures/{key}")
            rows[key].append(float(np.asarray(dataset.data)) if dataset is not None else np.nan)
        rows["valid"].append(float(rows["deployment_complete"][-1] == 1
                                   and rows["final_crank_angle"][-1] < fold))
    return {key: np.asarray(values, dtype=object if key in ("case", "outcome", "model")
                            else float) for key, values in rows.items()}


def table_datasets(rows: Mapping[str, np.ndarray]) -> dict[str, Dataset]:
    """The table as ``table/<column>`` datasets with units."""
    units = {**{k: (u, f"case input: {s}.{f}") for k, (u, s, f) in INPUTS.items()},
             **MEASURES, "case": ("1", "case name"),
             "outcome": ("1", "simulated, or refused by auto (near buckling)"),
             "model": ("1", "the coupler model auto chose"),
             "valid": ("1", "1: comes to rest before the folded dead centre")}
    return {f"table/{key}": Dataset(values, *units[key]) for key, values in rows.items()}


def rows_of(rows: Mapping[str, np.ndarray], names: list[str]) -> dict[str, np.ndarray]:
    """The table restricted to ``names`` (in that order)."""
    index = {name: i for i, name in enumerate(rows["case"])}
    keep = np.array([index[name] for name in names if name in index], dtype=int)
    return {key: np.asarray(values)[keep] for key, values in rows.items()}


# ------------------------------------------------------------------------------------------
# extrema along a line, and the thesis claim
# ------------------------------------------------------------------------------------------
def vertex(x: np.ndarray, y: np.ndarray, i: int) -> tuple[float, float]:
    """The extremum of the parabola through points i-1, i, i+1 (``(x[i], y[i])`` at an end)."""
    if i <= 0 or i >= len(x) - 1:
        return float(x[i]), float(y[i])
    a, b, c = np.polyfit(x[i - 1:i + 2], y[i - 1:i + 2], 2)
    if a == 0:
        return float(x[i]), float(y[i])
    at = -b / (2 * a)
    return float(at), float(np.polyval([a, b, c], at))


def extrema(x: Any, y: Any) -> dict[str, float]:
    """Largest and smallest of ``y(x)`` (finite points, x ascending), each refined by a
    parabola through its neighbours; ``*_interior`` 1 when not at an end of the range."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    x, y = x[ok], y[ok]
    out: dict[str, float] = {}
    for kind, index in (("max", int(np.argmax(y))), ("min", int(np.argmin(y)))):
        out[f"{kind}_x"], out[f"{kind}_y"] = vertex(x, y, index)
        out[f"{kind}_interior"] = float(0 < index < len(x) - 1)
    return out


def line(rows: Mapping[str, np.ndarray], names: list[str], select: Mapping[str, float]
         ) -> dict[str, np.ndarray]:
    """The rows of ``names`` whose inputs equal ``select`` (relative 1e-6), sorted by angle."""
    part = rows_of(rows, names)
    keep = np.ones(len(part["case"]), dtype=bool)
    for key, value in select.items():
        keep &= np.isclose(part[key], value, rtol=1e-6, atol=0)
    order = np.argsort(part["angle_deg"][keep])
    return {key: values[keep][order] for key, values in part.items()}


def line_name(family: str, value: float) -> str:
    """``preload_p22``, ``energy_k3000``: a line's name from its family and fixed value."""
    if family == "angle_preload":
        return f"preload_p{value * 1e3:.4g}".replace(".", "p")
    return f"energy_k{value:.5g}".replace(".", "p")


def claim_lines(rows: Mapping[str, np.ndarray], families: Mapping[str, list[str]]
                ) -> dict[str, dict[str, np.ndarray]]:
    """The lines of measures against initial angle: ``preload_p<mm>`` (the spring as given,
    one preload: fixed preload = fixed stored energy = fixed slider travel 2 delta at that
    rate), ``energy_k<N/m>`` (the design point's stored energy with that rate) and
    ``final_angle`` (rest at the design point's own final angle); lines of 3 points or more."""
    out = {"final_angle": line(rows, families["final_angle"], {})}
    for family, key in (("angle_preload", "preload_m"), ("angle_rate", "rate_N_per_m")):
        for value in sorted(set(rows_of(rows, families[family])[key])):
            out[line_name(family, value)] = line(rows, families[family], {key: value})
    return {name: part for name, part in out.items() if np.sum(part["valid"] == 1) >= 3}


def claim_verdict(part: Mapping[str, np.ndarray], point: DesignPoint,
                  measure: str = "peak_crank_speed") -> dict[str, float]:
    """Where ``measure`` peaks and dips along one line, its value at the design angle, and
    ``design_is_max`` (1 when the interior maximum lies within half a grid step of the design
    angle)."""
    x, y = part["angle_deg"], np.where(part["valid"] == 1, part[measure], np.nan)
    found = extrema(x, y)
    at = float(np.interp(point.angle_deg, x, part[measure]))
    step = float(np.median(np.diff(x))) if len(x) > 1 else math.inf
    found.update(design_value=at, design_angle=point.angle_deg,
                 design_is_max=float(bool(found["max_interior"])
                                     and abs(found["max_x"] - point.angle_deg) <= step / 2),
                 design_is_min=float(bool(found["min_interior"])
                                     and abs(found["min_x"] - point.angle_deg) <= step / 2),
                 gain_over_design=found["max_y"] / at - 1)
    return found


# ------------------------------------------------------------------------------------------
# the study's summary
# ------------------------------------------------------------------------------------------
def _line_datasets(name: str, part: Mapping[str, np.ndarray], point: DesignPoint
                   ) -> dict[str, Dataset]:
    out = {f"lines/{name}/{key}": Dataset(part[key], MEASURES[key][0] if key in MEASURES
                                          else INPUTS.get(key, ("1",))[0], f"along line {name}")
           for key in ("angle_deg", "preload_m", "rate_N_per_m", "peak_crank_speed",
                       "deployment_time", "peak_joint_force", "peak_coupler_stress",
                       "min_transmission_angle", "valid")}
    for measure, unit in (("peak_crank_speed", "rad/s"), ("deployment_time", "s")):
        verdict = claim_verdict(part, point, measure)
        for key, value in verdict.items():
            kind = unit if key.endswith("_y") or key == "design_value" else (
                "deg" if key.endswith("_x") or key == "design_angle" else "1")
            out[f"lines/{name}/{measure}_{key}"] = Dataset(value, kind, f"{measure}: {key}")
    return out


def summary_datasets(scene: Scene, grid: Grid, results: Mapping[str, CaseResult],
                     references: Mapping[str, Mapping[str, tuple[float, str]]]
                     ) -> dict[str, Dataset]:
    """Everything the report and the figures read: the table, the families, the lines with
    their extrema, the mechanism checks along the design deployment, the reference checks
    (``references``: :func:`reference_check` by case) and the design inputs."""
    rows = table(results)
    _, families = plan(scene, grid)
    point = DesignPoint.of(scene)
    out = table_datasets(rows)
    out.update({f"families/{name}": Dataset(np.array(names, dtype=object), "1",
                                            f"cases of family {name}")
                for name, names in families.items()})
    for name, part in claim_lines(rows, families).items():
        out.update(_line_datasets(name, part, point))
    design = results.get(design_case_name(scene))
    if design is not None and design.status == "ok" and "curves/crank/angle" in design.datasets:
        angles = np.asarray(design.datasets["curves/crank/angle"].data)
        stop = first_maximum_index(angles)
        out.update(mechanism_checks(tomllib.loads(design.scene_toml), angles[:None if stop is None
                                                                             else stop + 1]))
    for name, values in references.items():
        out.update({f"reference/{name}/{key}": Dataset(value, unit, "against the reference DAE")
                    for key, (value, unit) in values.items()})
    out.update({
        "design/point": Dataset(np.array([point.angle_deg, point.preload_m, point.rate_N_per_m,
                                          point.thickness_m]), "deg, m, N/m, m",
                                "design point: initial angle, preload, rate, thickness"),
        "design/stored_energy": Dataset(point.energy_J, "J", "design point spring energy"),
        "design/rest_angle": Dataset(math.degrees(rest_angle_rad(scene)), "deg",
                                     "closed-form rest angle of the design point"),
        "design/tolerance": Dataset(float(scene["fidelity"]["tolerance"]), "1",
                                    "auto's tolerance"),
        "design/allowable_stress": Dataset(A36_YIELD_STRESS_PA, "Pa", "ASTM A36 yield"),
        "design/design_case": Dataset(design_case_name(scene), "1", "the design point's case")})
    return out
