"""The model ladder of a plate coupler: linear FFRF, FFRF (flex's default), the exact beam,
nonlinear FE.

For one plate thickness, the thesis deployment (spring release) is run by each model on the same
mesh, step and samples: the linear FFRF coupler (``coupler.geometric_stiffness = false``),
flex's default FFRF coupler (chord frame, the geometric stiffness of its axial force,
:mod:`flex.bodies.geometric_stiffness`) and the fully nonlinear FE coupler
(:mod:`flex.bodies.nonlinear`), the reference. :func:`ladder_rung` returns each model's peak
elastic midpoint deflection over the span, its relative difference to the nonlinear FE
peak, the largest compression over the Euler load and the wall times; :func:`ladder_table`
prints a set of rungs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from flex.base.physics import Plate
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import EXACT_BEAM, FFRF, NONLINEAR_FE
from flex.fidelity.simulation import simulate_case
from flex.fidelity.softening import coupler_compression_N

#: the models, cheapest first: name -> coupler overrides (the exact beam at 64 elements,
#: within 0.03 % of its element limit on the first crest: its idealization, not its
#: discretization, is what the ladder measures)
MODELS = {
    "linear": (f'coupler.model="{FFRF}"', "coupler.geometric_stiffness=false"),
    FFRF: (f'coupler.model="{FFRF}"', "coupler.geometric_stiffness=true"),
    EXACT_BEAM: (f'coupler.model="{EXACT_BEAM}"', "coupler.elements=64"),
    NONLINEAR_FE: (f'coupler.model="{NONLINEAR_FE}"', "coupler.geometric_stiffness=false"),
}
REFERENCE = NONLINEAR_FE
#: the curves a ladder run keeps
KEEP = ("time", "crank/angle", "coupler/midpoint_deflection", "coupler/angle",
        "joints/B/force_on_coupler", "joints/C/force_on_coupler")


@dataclass
class Rung:
    """One thickness: per model, the peak |midpoint deflection| [m], its relative difference
    to the nonlinear FE peak (dimensionless), the wall time [s] (NaN for a failed run, whose
    message is in ``failures``; a run that finished but may not be valid has its
    ``validity_warning`` in ``warnings``), and the plate's largest compression over its
    Euler load."""

    thickness_m: float
    step_s: float
    end_time_s: float
    peak_deflection_m: dict[str, float] = field(default_factory=dict)
    difference_to_reference: dict[str, float] = field(default_factory=dict)
    wall_time_s: dict[str, float] = field(default_factory=dict)
    compression_over_euler_load: float = math.nan
    failures: dict[str, str] = field(default_factory=dict)
    warnings: dict[str, str] = field(default_factory=dict)


def first_period_s(scene: Scene) -> float:
    """Euler-Bernoulli pinned-pinned first bending period of the scene's coupler plate [s]."""
    return 2 * math.pi / Plate.of(scene["coupler"]).pinned_pinned_omega


def rung_scenes(scene: Scene, thickness_m: float, mesh_size_m: float, step_s: float,
                end_time_s: float) -> dict[str, Scene]:
    """The validated scene of each model in :data:`MODELS` for a plate ``thickness_m`` [m]
    meshed at ``mesh_size_m`` [m], integrated at ``step_s`` [s] over ``end_time_s`` [s]
    (every step stored, no companion run)."""
    common = ['coupler.geometry="plate"', f"coupler.thickness_m={thickness_m!r}",
              f"coupler.mesh_size_m={mesh_size_m!r}", f"simulation.step_s={step_s!r}",
              f"simulation.end_time_s={end_time_s!r}", "simulation.output_step_s=0.0",
              "simulation.error_estimate=false"]
    out = {}
    for name, overrides in MODELS.items():
        model_scene = derive_scene(scene, common + list(overrides))
        out[name] = model_scene
    return out


def simulate_model(name: str, scene: Scene, cache_dir: Path | None,
                   keep: tuple[str, ...] = KEEP) -> CaseResult:
    """One model's run (a failure becomes a failed case), with only the curves ``keep``."""
    case = simulate_case(scene, name, cache_dir=cache_dir)
    case.datasets = {k: v for k, v in case.datasets.items() if k in keep}
    return case


def rung_from_cases(cases: dict[str, CaseResult], scene: Scene) -> Rung:
    """The :class:`Rung` of one thickness from its runs (by model name, as
    :data:`MODELS`); ``scene``: any of them (plate, step and span are read from it)."""
    sim = scene["simulation"]
    rung = Rung(scene["coupler"]["thickness_m"], sim["step_s"], sim["end_time_s"])
    for name, case in cases.items():
        if case.status != "ok":
            rung.failures[name] = case.message
            rung.peak_deflection_m[name] = rung.wall_time_s[name] = math.nan
            continue
        data = {k: v.data for k, v in case.datasets.items()}
        if case.attrs.get("validity_warning"):
            rung.warnings[name] = str(case.attrs["validity_warning"])
        rung.peak_deflection_m[name] = float(np.abs(data["coupler/midpoint_deflection"]).max())
        rung.wall_time_s[name] = float(case.counters["wall_time_s"])
        if name == "linear":
            rung.compression_over_euler_load = float(
                coupler_compression_N(data).max() / Plate.of(scene["coupler"]).euler_load_N)
    reference = rung.peak_deflection_m.get(REFERENCE, math.nan)
    for name, peak in rung.peak_deflection_m.items():
        rung.difference_to_reference[name] = peak / reference - 1.0
    return rung


def ladder_rung(scene: Scene, thickness_m: float, mesh_size_m: float, step_s: float,
                end_time_s: float, cache_dir: Path | None) -> Rung:
    """Run the models of one thickness (see the module doc) and compare their peaks.

    ``scene``: the base scene (drive, solver keys other than the step, coupler modes);
    ``cache_dir``: the reduction cache folder (None: no disk cache).
    """
    scenes = rung_scenes(scene, thickness_m, mesh_size_m, step_s, end_time_s)
    cases = {name: simulate_model(name, model_scene, cache_dir)
             for name, model_scene in scenes.items()}
    return rung_from_cases(cases, scenes[REFERENCE])


def rung_datasets(rung: Rung, prefix: str) -> dict[str, Dataset]:
    """The summary datasets of one rung, ``<prefix>/<key>``."""
    out = {f"{prefix}/compression_over_euler_load": Dataset(
        rung.compression_over_euler_load, "1", "largest compression of the linear FFRF "
        "coupler (joint C along B-C) / pinned-pinned Euler load")}
    for name, warning in rung.warnings.items():
        out[f"{prefix}/validity_warning_{name}"] = Dataset(warning, "", f"{name}: why its "
                                                           "result may not be valid")
    for name in MODELS:
        out[f"{prefix}/peak_deflection_{name}"] = Dataset(
            rung.peak_deflection_m[name], "m", f"max |midpoint deflection|, {name}")
        out[f"{prefix}/wall_time_{name}"] = Dataset(rung.wall_time_s[name], "s",
                                                    f"integration wall time, {name}")
        if name != REFERENCE:
            out[f"{prefix}/difference_{name}"] = Dataset(
                rung.difference_to_reference[name], "1",
                f"peak deflection {name} / nonlinear FE - 1")
    return out


def ladder_table(rungs: list[Rung]) -> str:
    """A Markdown table of the rungs: thickness, P/P_E, step, each model's peak [um] and
    relative difference to the nonlinear FE peak [%], and wall times [s]."""
    lines = ["| t [mm] | max P/P_E | step [s] | span [ms] | nonlinear FE peak [um] | "
             "linear FFRF | FFRF (default) | exact beam | wall linear / FFRF / beam / FE [s] |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rungs:
        peak, diff, wall = r.peak_deflection_m, r.difference_to_reference, r.wall_time_s
        lines.append(
            f"| {r.thickness_m * 1e3:g} | {r.compression_over_euler_load:.3g} | {r.step_s:g} | "
            f"{r.end_time_s * 1e3:.3g} | {peak[REFERENCE] * 1e6:.4g} | "
            f"{peak['linear'] * 1e6:.4g} ({diff['linear']:+.2%}) | "
            f"{peak['ffrf'] * 1e6:.4g} ({diff['ffrf']:+.2%}) | "
            f"{peak[EXACT_BEAM] * 1e6:.4g} ({diff[EXACT_BEAM]:+.2%}) | "
            f"{wall['linear']:.2g} / {wall['ffrf']:.2g} / {wall[EXACT_BEAM]:.2g} / "
            f"{wall[REFERENCE]:.3g} |")
    for r in rungs:
        for name, message in r.failures.items():
            lines.append(f"\n{r.thickness_m * 1e3:g} mm {name} failed: {message}")
        for name, message in r.warnings.items():
            lines.append(f"\n{r.thickness_m * 1e3:g} mm {name} is not valid: {message}")
    return "\n".join(lines)
