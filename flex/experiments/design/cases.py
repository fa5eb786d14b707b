"""Design charts of the spring-driven slider-crank, its cases: the design point, the sweep's
families, each case's measures, and a few cases against the reference DAE (``make design``,
``studies/design.py``; docs/design.md).

**The design point** is the study's base scene: its initial crank angle theta0, spring
preload delta0 and rate k0, coupler thickness t0 (the thesis's: 34.19 deg, 22 mm, 1500 N/m,
and the steel plate of Table 1's coupler mass, 12.37 mm). Every case runs with
``coupler.model = "auto"`` at the scene's ``[fidelity] tolerance``. The :class:`Grid` spans

- ``angle_preload``: initial angle x preload (rate k0, thickness t0);
- ``angle_rate``: initial angle x rate at the design point's stored spring energy
  E0 = k0 delta0^2 / 2 (preload sqrt(2 E0 / k));
- ``thickness_rate``: coupler thickness x rate (angle theta0, preload delta0);
- ``final_angle``: initial angle with the preload that brings the crank to rest at the design
  point's own final angle (closed form, :func:`rest_angle_rad`, :func:`preload_for_rest_angle_m`).

A case (:func:`design_case`, on the sweep engine) stores its resolved scene, downsampled
curves (``curves/...``: every n-th stored sample, so they are the run's own values) and its
measures (``measures/...``, :data:`MEASURES`) over the deployment: from release to the
first crank-angle maximum. A scene ``auto`` refuses (a coupler near buckling) is stored as a
``refused`` case (status ok, attribute ``design_outcome``, no measures): a region of the
chart, not a failure.

Peak coupler stress: an FFRF coupler's own peak bending stress; a rigid one's is the
quasi-static beam stress of its joint loads (:func:`flex.fidelity.criteria.quasi_static_stress`)
times the dynamic factor of the first-mode oscillator driven by the same loads
(:func:`flex.fidelity.predictor.predict_deflection`: peak / quasi-static peak), because the
sudden release makes the quasi-static stress an under-estimate (docs/criterion.md).

The table of every case, the lines through the design point and the thesis's claim:
:mod:`flex.experiments.design.summary`; the mechanism checks:
:mod:`flex.experiments.design.mechanism`; the report and charts:
:mod:`flex.experiments.design.report`; ``flex design``: :mod:`flex.experiments.design.question`.
"""

from __future__ import annotations

import contextlib
import io
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import brentq

from flex.base.errors import SceneError
from flex.base.kinematics import slider_crank
from flex.base.mechanism_checks import (
    angle_to_dead_centres_rad,
    dead_centre_angles_rad,
    transmission_angle_rad,
)
from flex.base.thesis import THESIS_ANGLE_MAX_TIME_S, THESIS_SPRING_RATE_N_PER_M
from flex.data.headlines import first_maximum_index
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import RIGID
from flex.experiments.fitting.kfit import mesh_size_m
from flex.experiments.fitting.lawfit import case_data
from flex.fidelity.criteria import quasi_static_stress
from flex.fidelity.predictor import PREDICTION_MARGIN, predict_deflection

CASE_VERSION = 2  # 2: a deployment not completed within the run has no deployment time
#: what the design charts and ``flex design`` put on the scene before the user's values: the
#: coupler as the steel plate of Table 1's 77.67 g (12.37 mm thick), decided by ``auto``;
#: no companion error run (the measures are compared at the tolerance of ``auto``)
BASE_OVERRIDES = ['coupler.geometry="plate"', 'coupler.model="auto"',
                  "coupler.thickness_m=0.01237", "simulation.error_estimate=false",
                  "simulation.output_step_s=0.0"]
#: curve samples kept per case (every n-th stored sample)
CURVE_SAMPLES = 400
#: ASTM A36 minimum yield strength [Pa] (36 ksi): the thesis's steel (Tables 6 and 8) names
#: the grade, not its strength; the default allowable of the charts and of ``flex design``
A36_YIELD_STRESS_PA = 250e6
#: end time of a case: this many times the thesis half swing scaled by sqrt(k0 / k)
END_TIME_FACTOR = 2.4
#: measure -> (unit, description); all over the deployment (release to first angle maximum)
MEASURES: dict[str, tuple[str, str]] = {
    "peak_crank_speed": ("rad/s", "largest crank angular velocity"),
    "peak_crank_speed_time": ("s", "time of the largest crank angular velocity"),
    "deployment_time": ("s", "time of the first crank-angle maximum (the crank at rest)"),
    "final_crank_angle": ("rad", "crank angle at the first maximum"),
    "slider_travel": ("m", "slider displacement at the first crank-angle maximum"),
    "peak_joint_force_A": ("N", "largest joint force modulus at A (frame-crank)"),
    "peak_joint_force_B": ("N", "largest joint force modulus at B (crank-coupler)"),
    "peak_joint_force_C": ("N", "largest joint force modulus at C (coupler-slider)"),
    "peak_joint_force": ("N", "largest of the peak joint forces at A, B and C"),
    "peak_coupler_stress": ("Pa", "peak coupler bending stress (FFRF: the body's own; rigid: "
                                  "quasi-static x the oscillator's dynamic factor)"),
    "peak_coupler_stress_quasi_static": ("Pa", "peak quasi-static beam stress of the joint "
                                               "loads"),
    "peak_coupler_deflection": ("m", "peak elastic coupler midpoint deflection (FFRF: "
                                     "simulated; rigid: predicted from the loads)"),
    "predicted_rigid_error": ("1", "auto's predicted rigid deflection error x its margin"),
    "min_transmission_angle": ("rad", "smallest transmission angle at the crank pin"),
    "min_dead_centre_distance": ("rad", "smallest crank-angle distance to a dead centre"),
    "stored_spring_energy": ("J", "spring energy at release, k delta^2 / 2"),
    "deployment_complete": ("1", "1 if the crank angle reached its maximum within the run"),
}


# ------------------------------------------------------------------------------------------
# closed forms of the attached linear spring (rigid links: energy conservation)
# ------------------------------------------------------------------------------------------
def slider_position_m(scene: Scene, crank_angle_rad: Any) -> np.ndarray:
    """Slider position [m] of the scene's linkage at ``crank_angle_rad`` (closed form)."""
    return slider_crank(scene["crank"]["length_m"], scene["coupler"]["length_m"],
                        crank_angle_rad, offset_m=scene["slider"]["offset_m"]).slider_position_m


def rest_angle_rad(scene: Scene) -> float:
    """Crank angle [rad] where a rigid deployment comes to rest: the attached linear spring
    has given back its energy, ``k (delta s - s^2 / 2) = 0``, at slider travel s = 2 delta,
    so ``x(theta_f) = x(theta0) - 2 delta`` (between theta0 and the folded dead centre;
    SceneError if the travel passes the dead centre)."""
    theta0 = math.radians(scene["crank"]["initial_angle_deg"])
    fold = dead_centre_angles_rad(scene["crank"]["length_m"], scene["coupler"]["length_m"],
                                  scene["slider"]["offset_m"])[1]
    target = float(slider_position_m(scene, theta0)) - 2 * scene["drive"]["spring_preload_m"]
    if float(slider_position_m(scene, fold)) > target:
        raise SceneError("the slider travel 2 x preload passes the folded dead centre: the "
                         "crank does not come to rest before it")
    return float(brentq(lambda t: float(slider_position_m(scene, t)) - target, theta0, fold,
                        xtol=1e-13))


def preload_for_rest_angle_m(scene: Scene, initial_angle_rad: float,
                             rest_angle: float) -> float:
    """Preload [m] that brings a rigid deployment from ``initial_angle_rad`` to rest at
    ``rest_angle`` [rad]: half the slider travel between them (:func:`rest_angle_rad`)."""
    return float(slider_position_m(scene, initial_angle_rad)
                 - slider_position_m(scene, rest_angle)) / 2


# ------------------------------------------------------------------------------------------
# the plan: which scenes, in which families
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Grid:
    """The sweep's axes: initial angles [deg]; preloads as factors of delta0; rates as factors
    of k0 (at the stored energy E0: ``energy_rate_factors``; with thickness:
    ``thickness_rate_factors``); coupler thicknesses [m]; ``final_angle_step_deg``: the
    initial-angle step of the final-angle line."""

    angles_deg: tuple[float, ...]
    preload_factors: tuple[float, ...]
    energy_rate_factors: tuple[float, ...]
    thicknesses_m: tuple[float, ...]
    thickness_rate_factors: tuple[float, ...]
    final_angle_step_deg: float = 5.0


@dataclass(frozen=True)
class DesignPoint:
    """The design point of a base scene (see the module doc)."""

    angle_deg: float
    preload_m: float
    rate_N_per_m: float
    thickness_m: float

    @classmethod
    def of(cls, scene: Scene) -> DesignPoint:
        return cls(float(scene["crank"]["initial_angle_deg"]),
                   float(scene["drive"]["spring_preload_m"]),
                   float(scene["drive"]["spring_stiffness_N_per_m"]),
                   float(scene["coupler"]["thickness_m"]))

    @property
    def energy_J(self) -> float:
        return 0.5 * self.rate_N_per_m * self.preload_m**2


Point = tuple[float, float, float, float]  # angle [deg], preload [m], rate [N/m], thickness [m]


def _rounded(angle: float, preload: float, rate: float, thickness: float) -> Point:
    return (round(float(angle), 4), round(float(preload), 7), round(float(rate), 3),
            round(float(thickness), 7))


def case_name(point: Point) -> str:
    """``a34p19_p22_k1500_t12p37``: angle [deg], preload [mm], rate [N/m], thickness [mm]."""
    angle, preload, rate, thickness = point
    parts = (f"a{angle:.4g}", f"p{preload * 1e3:.4g}", f"k{rate:.5g}", f"t{thickness * 1e3:.4g}")
    return "_".join(parts).replace(".", "p").replace("+", "")


def family_points(scene: Scene, grid: Grid) -> dict[str, list[Point]]:
    """The points of every family of the module doc (rounded; duplicates across families)."""
    d = DesignPoint.of(scene)
    angles = sorted(set(grid.angles_deg) | {d.angle_deg})
    out: dict[str, list[Point]] = {
        "angle_preload": [_rounded(a, f * d.preload_m, d.rate_N_per_m, d.thickness_m)
                          for f in grid.preload_factors for a in angles],
        "angle_rate": [_rounded(a, math.sqrt(2 * d.energy_J / (f * d.rate_N_per_m)),
                                f * d.rate_N_per_m, d.thickness_m)
                       for f in grid.energy_rate_factors for a in angles],
        "thickness_rate": [_rounded(d.angle_deg, d.preload_m, f * d.rate_N_per_m, t)
                           for f in grid.thickness_rate_factors
                           for t in sorted(set(grid.thicknesses_m) | {d.thickness_m})]}
    rest = rest_angle_rad(scene)
    start = np.arange(grid.angles_deg[0], math.degrees(rest) - grid.final_angle_step_deg / 2,
                      grid.final_angle_step_deg)
    out["final_angle"] = [_rounded(a, preload_for_rest_angle_m(scene, math.radians(a), rest),
                                   d.rate_N_per_m, d.thickness_m)
                          for a in sorted(set(start.round(4)) | {d.angle_deg})]
    return out


def point_scene(scene: Scene, point: Point) -> Scene:
    """The case scene of a point: its inputs, the coupler's mesh for its thickness
    (:func:`flex.experiments.fitting.kfit.mesh_size_m`), and an end time long enough for the
    deployment (:data:`END_TIME_FACTOR`)."""
    angle, preload, rate, thickness = point
    end = END_TIME_FACTOR * THESIS_ANGLE_MAX_TIME_S * math.sqrt(THESIS_SPRING_RATE_N_PER_M / rate)
    case = derive_scene(scene, [f"crank.initial_angle_deg={angle!r}",
                                f"drive.spring_preload_m={preload!r}",
                                f"drive.spring_stiffness_N_per_m={rate!r}",
                                f"coupler.thickness_m={thickness!r}",
                                f"coupler.mesh_size_m={mesh_size_m(thickness)!r}",
                                f"simulation.end_time_s={float(f'{end:.3g}')!r}"])
    return case


def plan(scene: Scene, grid: Grid) -> tuple[dict[str, Scene], dict[str, list[str]]]:
    """The sweep's scenes by case name and each family's case names (in axis order)."""
    families = family_points(scene, grid)
    points = dict.fromkeys(p for members in families.values() for p in members)
    names = {p: case_name(p) for p in points}
    if len(set(names.values())) != len(names):
        raise SceneError("design grid: two points share a case name; use coarser values")
    return ({names[p]: point_scene(scene, p) for p in points},
            {family: [names[p] for p in members] for family, members in families.items()})


# ------------------------------------------------------------------------------------------
# one case
# ------------------------------------------------------------------------------------------
def _window(data: Mapping[str, np.ndarray]) -> tuple[int, bool]:
    stop = first_maximum_index(data["crank/angle"])
    return (len(data["time"]) - 1, False) if stop is None else (stop, True)


def coupler_stress(data: Mapping[str, np.ndarray], coupler: Mapping[str, Any], stop: int
                   ) -> dict[str, Any]:
    """Peak stress [Pa], quasi-static peak [Pa], peak deflection [m] and the stress curve over
    the whole run (see the module doc) of a case's coupler, over samples 0..``stop``."""
    window = slice(0, stop + 1)
    quasi = quasi_static_stress(data["joints/B/force_on_coupler"],
                                data["joints/C/force_on_coupler"], data["coupler/angle"],
                                coupler["length_m"], coupler["thickness_m"], coupler["width_m"])
    if "coupler/peak_bending_stress" in data:
        curve = np.asarray(data["coupler/peak_bending_stress"])
        deflection = float(np.abs(data["coupler/midpoint_deflection"][window]).max())
        return {"peak": float(curve[window].max()), "quasi_static": float(quasi[window].max()),
                "deflection": deflection, "curve": curve}
    series = {key: np.asarray(value)[window] for key, value in data.items()
              if np.ndim(value) and len(value) == len(data["time"])}
    prediction = predict_deflection(series, coupler, "coupler")
    factor = (prediction.peak_deflection_m / prediction.quasi_static_peak_m
              if prediction.quasi_static_peak_m > 0 else 1.0)
    return {"peak": float(quasi[window].max()) * factor, "quasi_static": float(quasi[window].max()),
            "deflection": prediction.peak_deflection_m, "curve": quasi * factor}


def case_measures(data: Mapping[str, np.ndarray], scene: Scene, attrs: Mapping[str, Any]
                  ) -> tuple[dict[str, float], np.ndarray]:
    """The :data:`MEASURES` of one simulated case (``data``: its stored curves; ``scene``:
    its resolved scene; ``attrs``: its fidelity attributes) and its stress curve [Pa]."""
    stop, complete = _window(data)
    window = slice(0, stop + 1)
    speed = np.asarray(data["crank/angular_velocity"])[window]
    angle = np.asarray(data["crank/angle"])[window]
    stress = coupler_stress(data, scene["coupler"], stop)
    forces = {j: float(np.max(data[f"joints/{j}/force_modulus"][window])) for j in "ABC"}
    dead = dead_centre_angles_rad(scene["crank"]["length_m"], scene["coupler"]["length_m"],
                                  scene["slider"]["offset_m"])
    drive = scene["drive"]
    values = {
        "peak_crank_speed": float(speed.max()),
        "peak_crank_speed_time": float(data["time"][int(np.argmax(speed))]),
        # not completed within the run: the deployment time, the final angle and the travel
        # did not happen (missing, not the end time)
        "deployment_time": float(data["time"][stop]) if complete else math.nan,
        "final_crank_angle": float(angle[-1]) if complete else math.nan,
        "slider_travel": float(data["slider/displacement"][stop]) if complete else math.nan,
        **{f"peak_joint_force_{j}": value for j, value in forces.items()},
        "peak_joint_force": max(forces.values()), "peak_coupler_stress": stress["peak"],
        "peak_coupler_stress_quasi_static": stress["quasi_static"],
        "peak_coupler_deflection": stress["deflection"],
        "predicted_rigid_error": float(attrs.get("fidelity_coupler_predicted_rigid_error",
                                                 math.nan)) * PREDICTION_MARGIN,
        "min_transmission_angle": float(transmission_angle_rad(
            angle, np.asarray(data["coupler/angle"])[window]).min()),
        "min_dead_centre_distance": float(angle_to_dead_centres_rad(angle, dead).min()),
        "stored_spring_energy": 0.5 * drive["spring_stiffness_N_per_m"]
        * drive["spring_preload_m"] ** 2,
        "deployment_complete": float(complete)}
    return values, stress["curve"]


#: curves a case keeps (downsampled), and their units
CURVES = {"time": "s", "crank/angle": "rad", "crank/angular_velocity": "rad/s",
          "slider/position": "m", "coupler/angle": "rad", "joints/A/force_modulus": "N",
          "joints/B/force_modulus": "N", "joints/C/force_modulus": "N",
          "joints/B/force_on_coupler": "N"}


def _case_datasets(data: Mapping[str, np.ndarray], values: dict[str, float],
                   stress_curve: np.ndarray) -> dict[str, Dataset]:
    pick = slice(None, None, max(1, math.ceil(len(data["time"]) / CURVE_SAMPLES)))
    out = {f"measures/{key}": Dataset(values[key], unit, text)
           for key, (unit, text) in MEASURES.items()}
    out.update({f"curves/{key}": Dataset(np.asarray(data[key])[pick], unit,
                                         f"{key} (every {pick.step}th stored sample)")
                for key, unit in CURVES.items()})
    out["curves/coupler/stress"] = Dataset(np.asarray(stress_curve)[pick], "Pa",
                                           "peak coupler stress (basis: measures doc)")
    return out


def design_case(name: str, scene: Scene, *, cache_dir: Path | None = None) -> CaseResult:
    """One design case: :func:`flex.fidelity.simulation.simulate` (``auto`` resolved; its
    reason stored in ``fidelity_coupler_*``, not printed), then its measures and curves; a
    scene ``auto`` refuses is a ``refused`` case (module doc). ``cache_dir``: the reduction
    cache folder (None: built in memory)."""
    from flex.data.scene import to_toml
    from flex.fidelity.simulation import simulate

    try:
        with contextlib.redirect_stderr(io.StringIO()):
            case = simulate(scene, name, cache_dir=cache_dir)
    except SceneError as exc:
        return CaseResult(name, to_toml(scene), attrs={"design_outcome": "refused",
                                                       "design_reason": str(exc)})
    data = case_data(case)
    resolved = tomllib.loads(case.scene_toml)
    values, stress_curve = case_measures(data, resolved, case.attrs)
    case.datasets = _case_datasets(data, values, stress_curve)
    case.attrs.update(design_outcome="simulated",
                      design_model=resolved["coupler"]["model"])
    return case


design_case.case_version = CASE_VERSION


# ------------------------------------------------------------------------------------------
# the independent reference DAE at a few points
# ------------------------------------------------------------------------------------------
def reference_check(case: CaseResult) -> dict[str, tuple[float, str]]:
    """A rigid case's stored curves against the reference DAE of its resolved scene
    (:func:`flex.dynamics.reference.deviations_from_reference` at the stored samples), and
    both peak crank speeds over those samples: ``{name: (value, unit)}``."""
    from flex.dynamics.reference import deviations_from_reference

    data = {key.removeprefix("curves/"): np.asarray(value.data)
            for key, value in case.datasets.items() if key.startswith("curves/")}
    reference, deviations = deviations_from_reference(tomllib.loads(case.scene_toml), data)
    stop, _ = _window(data)
    deviations["peak_crank_speed_reference"] = (float(reference.q_dot[:stop + 1, 2].max()),
                                                "rad/s")
    deviations["peak_crank_speed_flex"] = (float(data["crank/angular_velocity"][:stop + 1].max()),
                                           "rad/s")
    deviations["reference_wall_time"] = (reference.wall_time_s, "s")
    return deviations


def design_case_name(scene: Scene) -> str:
    """The case name of the design point itself."""
    d = DesignPoint.of(scene)
    return case_name(_rounded(d.angle_deg, d.preload_m, d.rate_N_per_m, d.thickness_m))


def reference_names(scene: Scene, grid: Grid, angles_deg: tuple[float, ...]) -> list[str]:
    """Cases checked against the reference DAE: the design point, the preload line at
    ``angles_deg``, and the design angle on the stiffest fixed-energy line."""
    d = DesignPoint.of(scene)
    stiff = max(grid.energy_rate_factors) * d.rate_N_per_m
    points = [_rounded(d.angle_deg, d.preload_m, d.rate_N_per_m, d.thickness_m),
              *(_rounded(a, d.preload_m, d.rate_N_per_m, d.thickness_m) for a in angles_deg),
              _rounded(d.angle_deg, math.sqrt(2 * d.energy_J / stiff), stiff, d.thickness_m)]
    return [case_name(p) for p in dict.fromkeys(points)]


def run_references(results: Mapping[str, CaseResult], names: list[str]
                   ) -> dict[str, dict[str, tuple[float, str]]]:
    """:func:`reference_check` of each named case that ran with a rigid coupler."""
    return {name: reference_check(results[name]) for name in names
            if name in results and results[name].attrs.get("design_model") == RIGID}
