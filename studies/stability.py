"""Study ``stability``: numerical stability at the extremes, each against a converged reference.

Every run is checked against a reference of the same physics and stored with its verdict
(``within_tolerance``: largest relative error <= :data:`TOLERANCE`); a run that diverges
(Newton failure, NaN, exploding constraint norm) is a ``failed`` case whose message names
the step and the time, with no data. Groups:

- ``thickness``: FFRF plate couplers 0.3 ... 20 mm over ~one period of their first bending
  mode, against the same discretization at a 4x smaller step; ``nonlinear``: the same FFRF
  runs against the fully nonlinear FE coupler on the same mesh and step (a model
  comparison: where the linear FFRF body stops being trustworthy); ``stiff_plate``: the
  20 mm plate over a range of steps (step-size limits);
- ``step``: time steps 1e-3 ... 1e-7 s (rigid) and 1e-3 ... 1e-6 s (FFRF 1 mm);
- ``spectral_radius``: 0, 0.5, 0.9, 1 (rigid and FFRF 1 mm, h = 1e-4 s);
- ``long_horizon``: 1 s of free motion, energy drift (rigid against the reference DAE; FFRF
  1 mm at two steps and 10 mm: kinetic + strain + spring energy, and boundedness);
- ``dead_centre``: initial crank angles at and near 0 and 180 deg with the spring drive;
- ``stiff_drive``: spring 10x and 100x stiffer, crank speed 10x and 100x (one turn);
- ``divergence``: settings that must diverge, to show they are caught and reported.

References: rigid -- the scipy DAE (rtol 1e-12, shown converged by rtol 1e-11); FFRF --
flex's model at a finer step (shown converged by twice that step); constant crank speed --
the closed-form slider-crank (exact).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from flex.errors import FlexError
from flex.kinematics import constant_speed_motion
from flex.physics import euler_buckling_load_N, pinned_pinned_omega
from flex.plotting import figure
from flex.results import CaseResult, Dataset
from flex.scene import Scene, apply_overrides, to_toml, validate
from flex.settings import pinned_overrides
from flex.simulation import simulate_case
from flex.study import StudyRun, Summary
from flex.thesis import (
    THESIS_COUPLER_LENGTH_M,
    THESIS_DENSITY_KG_PER_M3,
    THESIS_SPRING_RATE_N_PER_M,
    THESIS_YOUNGS_MODULUS_PA,
)
from flex.tradeoff import (
    Observables,
    ReductionPool,
    Reference,
    Setting,
    converged_reference,
)

NAME = "stability"
DESCRIPTION = "extremes: thickness, step, spectral radius, 1 s horizon, dead centres, stiff drives"
OVERRIDES = pinned_overrides()
#: verdict threshold: largest relative error (angle / swing, slider / travel, peak / peak)
TOLERANCE = 1e-3
PLATE = ('coupler.geometry="plate"', 'coupler.model="ffrf"')
#: plate thickness [mm] -> mesh size [mm] (about 2 t, at least 2 mm, at most 5 mm)
THICKNESS_MESH_MM = {0.3: 2.0, 0.5: 2.0, 1.0: 2.0, 2.0: 2.0, 3.0: 3.0, 10.0: 5.0, 20.0: 5.0}
NONLINEAR_THICKNESS_MM = (0.3, 0.5, 1.0, 2.0, 3.0)
#: the nonlinear FE coupler costs ~0.4-1.6 s per step: 1e-4 s, or ~40 steps per period of the
#: first bending mode for the stiffer plates
NONLINEAR_STEP_S = {0.3: 1e-4, 0.5: 1e-4, 1.0: 1e-4, 2.0: 2.5e-5, 3.0: 2.5e-5}
#: numerical settings of the fine FFRF references (modified Newton converged to 1e-10)
FINE = ('simulation.newton="modified"', "simulation.newton_relative_tolerance=1e-10")


@dataclass(frozen=True)
class Extreme:
    """One run at an extreme: scene overrides, its group, the reference it is checked
    against (``scipy``, ``fine:<step>`` = flex at that step, ``closed_form``,
    ``nonlinear_fe``), and ``expect = "diverges"`` for the forced divergences."""

    name: str
    group: str
    overrides: tuple[str, ...]
    reference: str
    parameter: float = math.nan  # the varied value (thickness, step, rho, angle, factor)
    expect: str = "within"


def _plate(thickness_mm: float) -> tuple[str, ...]:
    mesh = THICKNESS_MESH_MM[thickness_mm] * 1e-3
    return PLATE + (f"coupler.thickness_m={thickness_mm * 1e-3!r}",
                    f"coupler.mesh_size_m={mesh!r}")


def _period_s(thickness_mm: float) -> float:
    """Euler-Bernoulli pinned-pinned first bending period of the thesis plate [s]."""
    omega = pinned_pinned_omega(THESIS_COUPLER_LENGTH_M, thickness_mm * 1e-3,
                                THESIS_YOUNGS_MODULUS_PA, THESIS_DENSITY_KG_PER_M3)
    return 2 * math.pi / omega


def extremes() -> list[Extreme]:
    """Every run of the study (see the module doc)."""
    out: list[Extreme] = []
    for t in THICKNESS_MESH_MM:
        horizon = max(round(1.1 * _period_s(t), 4), 0.005)
        step = 1e-5
        common = _plate(t) + (f"simulation.end_time_s={horizon!r}", f"simulation.step_s={step}")
        out.append(Extreme(f"thickness_{t:g}mm", "thickness", common, f"fine:{step / 4!r}", t))
        if t in NONLINEAR_THICKNESS_MM:
            out.append(Extreme(f"nonlinear_{t:g}mm", "nonlinear", common, "nonlinear_fe", t))
    for step in (1e-4, 4e-5, 1e-5, 2.5e-6):
        out.append(Extreme(f"stiff_plate_20mm_h{step:g}", "stiff_plate",
                           _plate(20.0) + ("simulation.end_time_s=0.01",
                                           f"simulation.step_s={step!r}"), "fine:1e-06", step))
    for step in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7):
        output = f"simulation.output_step_s={max(step, 1e-5)!r}"
        out.append(Extreme(f"step_rigid_h{step:g}", "step",
                           (f"simulation.step_s={step!r}", output), "scipy", step))
    for step in (1e-3, 1e-4, 1e-5, 1e-6):
        output = f"simulation.output_step_s={max(step, 1e-5)!r}"
        out.append(Extreme(f"step_ffrf1mm_h{step:g}", "step",
                           _plate(1.0) + (f"simulation.step_s={step!r}", output), "fine:2e-06",
                           step))
    for rho in (0.0, 0.5, 0.9, 1.0):
        out.append(Extreme(f"rho_rigid_{rho:g}", "spectral_radius",
                           ("simulation.step_s=1e-4", f"simulation.spectral_radius={rho!r}"),
                           "scipy", rho))
        out.append(Extreme(f"rho_ffrf1mm_{rho:g}", "spectral_radius",
                           _plate(1.0) + ("simulation.step_s=1e-4",
                                          f"simulation.spectral_radius={rho!r}"), "fine:2e-06",
                           rho))
    long = ("simulation.end_time_s=1.0", "simulation.output_step_s=1e-4")
    # index 3 with rho = 1 leaves the algebraic (constraint) modes undamped: Newton fails after
    # ~0.78 s of free motion (measured by this study, README "Numerical stability"); kept to
    # show it is detected, and the reason the default spectral radius is below 1
    for label, knobs, expect in (
            ("rho0.9", (), "within"),
            ("rho1", ("simulation.spectral_radius=1.0",), "diverges"),
            ("index2_rho1", ('simulation.formulation="index2"', "simulation.spectral_radius=1.0"),
             "within"),
            ("explicit_k1e8", ('simulation.integrator="explicit_penalty"',), "within")):
        out.append(Extreme(f"long_rigid_{label}", "long_horizon",
                           long + ("simulation.step_s=1e-5",) + knobs, "scipy", 1.0,
                           expect=expect))
    # FFRF: energy drift over 1 s (kinetic + strain + spring energy, undamped plate) at the
    # 1 % setting of the tradeoff study and at a 10x smaller step; the 10 mm plate at the
    # step its first bending mode (3.5 kHz) needs
    fast = ('simulation.newton="modified"', "simulation.newton_relative_tolerance=1e-8")
    for label, thickness_mm, step in (("long_ffrf1mm", 1.0, 1e-4),
                                      ("long_ffrf1mm_h1e-5", 1.0, 1e-5),
                                      ("long_ffrf10mm", 10.0, 1e-5)):
        out.append(Extreme(label, "long_horizon",
                           _plate(thickness_mm) + long + (f"simulation.step_s={step!r}",)
                           + fast, "none", 1.0))
    for angle in (0.0, 1e-3, 0.1, 1.0, 179.0, 180.0, 181.0):
        out.append(Extreme(f"dead_centre_{angle:g}deg", "dead_centre",
                           (f"crank.initial_angle_deg={angle!r}",), "scipy", angle))
    for factor in (1, 10, 100):
        rate = THESIS_SPRING_RATE_N_PER_M * factor
        out.append(Extreme(f"spring_x{factor}", "stiff_drive",
                           (f"drive.spring_stiffness_N_per_m={rate!r}",), "scipy", factor))
        speed = 2 * math.pi * factor
        out.append(Extreme(f"crank_speed_x{factor}", "stiff_drive",
                           ('drive.kind="constant_speed"',
                            f"drive.crank_speed_rad_per_s={speed!r}",
                            f"simulation.end_time_s={1.0 / factor!r}",
                            f"simulation.output_step_s={1e-3 / factor!r}"),
                           "closed_form", factor))
    out.append(Extreme("diverge_explicit_above_limit", "divergence",
                       ('simulation.integrator="explicit_penalty"', "simulation.step_s=3e-5"),
                       "scipy", 3e-5, expect="diverges"))
    out.append(Extreme("diverge_thin_plate_h1e-4", "divergence",
                       _plate(0.3) + ("simulation.end_time_s=0.01", "simulation.step_s=1e-4"),
                       "none", 1e-4, expect="diverges"))
    return out


#: the runs built to diverge (flex run stability exits 0 when exactly these fail)
EXPECTED_FAILURES = frozenset(e.name for e in extremes() if e.expect == "diverges")


def cases(scene: Scene) -> dict[str, Scene]:
    out = {}
    for extreme in extremes():
        case = apply_overrides(scene, list(extreme.overrides))
        validate(case)
        out[extreme.name] = case
    return out


# ------------------------------------------------------------------------------------------
# references
# ------------------------------------------------------------------------------------------
def _scene_without(scene: Scene, keys: tuple[str, ...]) -> str:
    """TOML of ``scene`` with the numerical knobs ``keys`` of [simulation] dropped (a cache
    key for references of the same physics)."""
    reduced = {section: dict(table) for section, table in scene.items()}
    for key in keys:
        reduced["simulation"].pop(key, None)
    return to_toml(reduced)


_NUMERICAL = ("step_s", "spectral_radius", "integrator", "formulation", "newton",
              "newton_relative_tolerance", "explicit_method", "penalty_stiffness_N_per_m")


def _fine_setting(step: float) -> Setting:
    return Setting(f"flex h={step:g}", (("simulation.step_s", step),
                                        ("simulation.output_step_s", 0.0),
                                        ("simulation.spectral_radius", 0.9),
                                        ("simulation.formulation", "index3"),
                                        ("simulation.newton", "modified"),
                                        ("simulation.newton_relative_tolerance", 1e-10)))


def _nonlinear_setting(step: float) -> Setting:
    return Setting(f"nonlinear FE h={step:g}", (("simulation.step_s", step),
                                                 ("simulation.output_step_s", 0.0)))


def _closed_form(scene: Scene, time_s: np.ndarray) -> Reference:
    theta, state = constant_speed_motion(
        scene["crank"]["length_m"], scene["coupler"]["length_m"],
        math.radians(scene["crank"]["initial_angle_deg"]),
        scene["drive"]["crank_speed_rad_per_s"], time_s, scene["slider"]["offset_m"])
    observables = Observables(time_s, theta, np.asarray(state.slider_position_m, dtype=float))
    exact = {"crank_angle_rad": 0.0, "slider_position_m": 0.0, "error": 0.0}
    return Reference("closed form", observables, Setting("closed-form slider-crank"),
                     {"closed form (exact)": exact}, TOLERANCE, 0.0,
                     "closed-form in-line slider-crank at constant crank speed (exact)")


class References:
    """References built once per physics and shared by the runs that need them."""

    def __init__(self, pool: ReductionPool) -> None:
        self.pool = pool
        self._cache: dict[tuple[str, str], Reference] = {}

    def get(self, kind: str, scene: Scene, run_time_s: np.ndarray | None = None
            ) -> Reference | None:
        """The reference of ``kind`` for ``scene`` (None for ``none``)."""
        if kind == "none":
            return None
        if kind == "closed_form":
            if run_time_s is None:
                raise FlexError("the closed-form reference needs the run's sample times")
            return _closed_form(scene, run_time_s)
        key = (kind, _scene_without(scene, _NUMERICAL + ("output_step_s",)))
        if key in self._cache:
            return self._cache[key]
        if kind == "scipy":  # sampled every 1e-5 s (1e-4 s beyond 0.1 s), cubic in between
            interval = 1e-5 if scene["simulation"]["end_time_s"] <= 0.1 else 1e-4
            base = apply_overrides(scene, [f"simulation.output_step_s={interval!r}",
                                           f"simulation.step_s={interval!r}"])
            reference = converged_reference(
                base, "scipy", Setting("scipy DOP853 rtol=1e-12", engine="scipy", rtol=1e-12,
                                       atol=1e-14),
                {"rtol 1e-12 -> 1e-11": Setting("scipy rtol=1e-11", engine="scipy",
                                                rtol=1e-11, atol=1e-13)},
                TOLERANCE / 10, self.pool,
                "scipy DOP853 on the 9-coordinate DAE, rtol 1e-12 (evidence: rtol 1e-11)")
        elif kind.startswith("fine:"):
            step = float(kind.split(":", 1)[1])
            reference = converged_reference(
                scene, f"flex h={step:g}", _fine_setting(step),
                {f"step {step:g} -> {2 * step:g}": _fine_setting(2 * step)}, TOLERANCE / 10,
                self.pool, f"flex, same discretization, h = {step:g} s, modified Newton 1e-10 "
                           f"(evidence: h = {2 * step:g} s)")
        elif kind == "nonlinear_fe":
            nonlinear = apply_overrides(scene, ['coupler.model="nonlinear_fe"',
                                                "simulation.newton_relative_tolerance=1e-8"])
            thickness_mm = scene["coupler"]["thickness_m"] * 1e3
            step = next((v for k, v in NONLINEAR_STEP_S.items()
                         if math.isclose(k, thickness_mm)), 1e-4)
            reference = converged_reference(
                nonlinear, "nonlinear FE", _nonlinear_setting(step),
                {f"step {step:g} -> {2 * step:g}": _nonlinear_setting(2 * step)}, TOLERANCE,
                self.pool, f"fully nonlinear FE coupler, same mesh, h = {step:g} s (evidence: "
                           f"h = {2 * step:g} s; each step costs ~0.4-1.6 s)")
        else:
            raise FlexError(f"unknown reference kind {kind!r}")
        self._cache[key] = reference
        return reference


# ------------------------------------------------------------------------------------------
# running
# ------------------------------------------------------------------------------------------
KEEP = ("time", "crank/angle", "crank/angular_velocity", "slider/position", "constraint_norm",
        "energy/total", "energy/strain", "coupler/midpoint_deflection")


def _nonlinear_available() -> bool:
    try:
        from flex.nonlinear import add_nonlinear_fe_coupler  # noqa: F401
    except ImportError:
        return False
    return True


def _axial_over_euler(scene: Scene, data: dict[str, np.ndarray]) -> float:
    """Largest compressive force along the coupler's chord over its Euler buckling load
    pi^2 E I / L^2 (pinned-pinned, I = width t^3 / 12): where it nears 1, the axial force
    changes the bending stiffness, which a linear FFRF body leaves out."""
    c = scene["coupler"]
    euler_N = euler_buckling_load_N(c["length_m"], c["thickness_m"], c["width_m"],
                                    c["youngs_modulus_Pa"])
    angle = data["coupler/angle"]
    chord = np.column_stack([np.cos(angle), np.sin(angle)])
    # the slider pushes on the coupler at C; compression is a force pointing from C to B
    along = -np.einsum("ij,ij->i", data["joints/C/force_on_coupler"], chord)
    return float(max(along.max(), 0.0) / euler_N)


def _judge(extreme: Extreme, scene: Scene, case: CaseResult, references: References,
           ) -> dict[str, Any]:
    """Verdict of one run: errors against its reference, energy drift, boundedness."""
    verdict: dict[str, Any] = {"group": extreme.group, "parameter": extreme.parameter,
                               "expect": extreme.expect, "status": case.status,
                               "message": case.message}
    if case.status != "ok":
        verdict["verdict"] = ("diverged as expected, detected" if extreme.expect == "diverges"
                              else "diverged (detected and stored as failed)")
        verdict["within_tolerance"] = False
        return verdict
    data = {key: value.data for key, value in case.datasets.items()}
    flexible = scene["coupler"]["model"] != "rigid"
    if "energy/total" in data:
        energy = data["energy/total"]
        verdict["energy_drift"] = float((energy[-1] - energy[0]) / energy[0])
        verdict["energy_range"] = float(np.ptp(energy) / energy[0])
        if "energy/strain" in data and data["energy/strain"].max() > 0:
            # the plate's own energy is a small part of the total (the spring's): the drift
            # as a fraction of the largest strain energy says how much of the plate's
            # vibration the integrator removed
            verdict["energy_drift_over_peak_strain"] = float(
                (energy[-1] - energy[0]) / data["energy/strain"].max())
    if flexible:
        deflection = np.abs(data["coupler/midpoint_deflection"])
        tenth = max(1, len(deflection) // 10)
        verdict["peak_deflection_first_tenth"] = float(deflection[:tenth].max())
        verdict["peak_deflection_last_tenth"] = float(deflection[-tenth:].max())
        verdict["axial_force_over_euler_load"] = _axial_over_euler(scene, data)
    try:
        reference = references.get(extreme.reference, scene, data["time"])
    except FlexError as exc:
        verdict.update(verdict=f"reference failed: {exc}", within_tolerance=False)
        return verdict
    if reference is None:
        bounded = data["constraint_norm"].max() < 1e-6
        verdict.update(verdict="ran, bounded" if bounded else "ran, constraint drift",
                       within_tolerance=bool(bounded), reference="none")
        if extreme.expect == "diverges":
            verdict["verdict"] = "expected to diverge but did not"
        return verdict
    try:
        errors = reference.errors(Observables.of_datasets(case.datasets, reference.flexible))
    except FlexError as exc:
        verdict.update(verdict=f"comparison failed: {exc}", within_tolerance=False)
        return verdict
    verdict.update({f"error_{key}": value for key, value in errors.items() if key != "error"})
    verdict["reference"] = reference.description
    verdict["reference_accuracy"] = reference.accuracy
    verdict["error"] = errors["error"]
    verdict["within_tolerance"] = bool(errors["error"] <= TOLERANCE)
    if extreme.expect == "diverges":
        verdict["verdict"] = "expected to diverge but did not"
    else:
        verdict["verdict"] = ("within tolerance" if verdict["within_tolerance"]
                              else f"outside tolerance ({errors['error']:.1e} > {TOLERANCE:g})")
        if not reference.converged:
            verdict["verdict"] += (f"; reference itself only shown to {reference.accuracy:.1e}"
                                   if math.isfinite(reference.accuracy)
                                   else "; reference not shown converged (its coarser run "
                                        "failed)")
    return verdict


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Run every extreme, judge it against its reference; keep the main curves only."""
    progress = run.progress
    pool = ReductionPool()
    references = References(pool)
    by_name = {extreme.name: extreme for extreme in extremes()}
    nonlinear = _nonlinear_available()
    results: dict[str, CaseResult] = {}
    verdicts: dict[str, dict[str, Any]] = run.notes.setdefault("verdicts", {})  # by case
    for index, (name, scene) in enumerate(scenes.items()):
        if progress:
            progress(name, index, len(scenes))
        extreme = by_name[name]
        if extreme.reference == "nonlinear_fe" and not nonlinear:
            results[name] = CaseResult(name, to_toml(scene), status="failed",
                                       message="nonlinear FE coupler not available")
            verdicts[name] = {"group": extreme.group, "parameter": extreme.parameter,
                               "status": "failed", "verdict": "pending: no nonlinear FE",
                               "within_tolerance": False, "expect": extreme.expect}
            continue
        try:
            reduction = pool.for_scene(scene)
        except FlexError as exc:
            reduction, failure = None, str(exc)
        else:
            failure = ""
        case = (CaseResult(name, to_toml(scene), status="failed", message=failure) if failure
                else simulate_case(scene, name, reduction))
        try:
            verdict = _judge(extreme, scene, case, references)
        except Exception as exc:  # one broken comparison must not lose a half-hour run
            verdict = {"group": extreme.group, "parameter": extreme.parameter,
                       "expect": extreme.expect, "status": case.status,
                       "message": case.message, "within_tolerance": False,
                       "verdict": f"internal error while judging: {type(exc).__name__}: {exc}"}
        verdicts[name] = verdict
        if case.status == "ok":
            case.datasets = {k: v for k, v in case.datasets.items() if k in KEEP}
        case.attrs.update({key: value for key, value in verdict.items()
                           if isinstance(value, str | float | int | bool)
                           and key not in ("status", "message")})
        results[name] = case
    if progress:
        progress("done", len(scenes), len(scenes))
    return results


def _trust_boundary(verdicts: dict[str, dict[str, Any]]) -> tuple[float, str]:
    """Thinnest plate [mm] from which linear FFRF agrees with the nonlinear FE coupler within
    1 % in peak deflection, by log-interpolation between the measured thicknesses; the text
    lists each thickness with its difference and its compression / Euler load."""
    rows = sorted((v["parameter"], v["error_peak_deflection_relative"],
                   v.get("axial_force_over_euler_load", math.nan))
                  for v in verdicts.values()
                  if v["group"] == "nonlinear" and "error_peak_deflection_relative" in v)
    if not rows:
        return math.nan, "no nonlinear FE comparison ran"
    measured = ", ".join(f"{t:g} mm: {e * 100:.2g} % (P/P_euler {r:.2g})" for t, e, r in rows)
    for (t0, e0, _), (t1, e1, _) in zip(rows, rows[1:], strict=False):
        if e0 > 1e-2 >= e1:
            fraction = math.log(e0 / 1e-2) / math.log(e0 / e1)
            boundary = math.exp(math.log(t0) + fraction * math.log(t1 / t0))
            return boundary, (f"linear FFRF is within 1 % of the nonlinear FE coupler in peak "
                              f"deflection from t ~ {boundary:.2g} mm; measured {measured}")
    if rows[0][1] <= 1e-2:
        return rows[0][0], (f"linear FFRF within 1 % down to the thinnest plate run; "
                            f"measured {measured}")
    return math.inf, f"linear FFRF differs by more than 1 % at every thickness run: {measured}"


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    judged: dict[str, dict[str, Any]] = (notes or {}).get("verdicts", {})
    datasets: dict[str, Dataset] = {}
    lines = [f"stability: every extreme against its converged reference (tolerance "
             f"{TOLERANCE:g}, largest relative error)"]
    names = [name for name in results if name in judged]
    verdicts = [judged[name] for name in names]

    def column(key: str, default: Any, units: str, text: str, dtype: Any = float) -> Dataset:
        return Dataset(np.array([v.get(key, default) for v in verdicts], dtype=dtype), units,
                       text)

    datasets["runs/name"] = Dataset(np.array(names, dtype=object), "1", "case")
    datasets["runs/group"] = column("group", "", "1", "extreme", object)
    datasets["runs/parameter"] = column("parameter", np.nan, "see group",
                                        "varied value: thickness [mm], step [s], rho, angle "
                                        "[deg], factor, horizon [s]")
    datasets["runs/status"] = column("status", "", "1", "ok | failed", object)
    datasets["runs/verdict"] = column("verdict", "", "1", "what happened", object)
    datasets["runs/within_tolerance"] = column("within_tolerance", False, "1",
                                               f"largest relative error <= {TOLERANCE:g}", bool)
    datasets["runs/error"] = column("error", np.nan, "1", "largest relative error")
    datasets["runs/crank_angle_error"] = column("error_crank_angle_rad", np.nan, "rad",
                                                "max |crank angle - reference|")
    datasets["runs/slider_position_error"] = column("error_slider_position_m", np.nan, "m",
                                                    "max |slider x - reference|")
    datasets["runs/peak_deflection_error"] = column("error_peak_deflection_relative", np.nan,
                                                    "1", "|peak - reference peak| / reference")
    datasets["runs/energy_drift"] = column("energy_drift", np.nan, "1",
                                           "(E_end - E_0) / E_0 (spring drive; kinetic + "
                                           "strain + spring energy)")
    datasets["runs/energy_range"] = column("energy_range", np.nan, "1",
                                           "(max E - min E) / E_0 (spring drive)")
    datasets["runs/energy_drift_over_peak_strain"] = column(
        "energy_drift_over_peak_strain", np.nan, "1",
        "(E_end - E_0) / largest strain energy of the flexible links")
    datasets["runs/message"] = column("message", "", "1", "failure message (step, time)",
                                      object)
    datasets["runs/reference_accuracy"] = column("reference_accuracy", np.nan, "1",
                                                 "largest relative change of the reference "
                                                 "under one-level coarsening")
    datasets["runs/axial_force_over_euler_load"] = column(
        "axial_force_over_euler_load", np.nan, "1",
        "largest coupler compression / pinned-pinned Euler load (flexible couplers)")
    boundary, text = _trust_boundary(judged)
    datasets["nonlinear/trust_thickness"] = Dataset(boundary, "mm", text)
    groups: dict[str, list[str]] = {}
    for name, verdict in zip(names, verdicts, strict=True):
        groups.setdefault(verdict["group"], []).append(name)
    for group, members in groups.items():
        lines.append(f"  {group}:")
        for name in members:
            v = judged[name]
            extra = ""
            if "energy_drift" in v:
                extra += (f", energy drift {v['energy_drift']:+.1e} "
                          f"(range {v['energy_range']:.1e})")
            if "energy_drift_over_peak_strain" in v:
                extra += (f", drift / peak strain energy "
                          f"{v['energy_drift_over_peak_strain']:+.1e}")
            if "peak_deflection_last_tenth" in v and v["group"] == "long_horizon":
                first = v["peak_deflection_first_tenth"] * 1e6
                last = v["peak_deflection_last_tenth"] * 1e6
                extra += f", |w| peak first/last tenth {first:.1f}/{last:.1f} um"
            if "axial_force_over_euler_load" in v and v["group"] in ("thickness", "nonlinear"):
                extra += f", P/P_euler {v['axial_force_over_euler_load']:.3f}"
            error = f"error {v['error']:.1e}, " if "error" in v else ""
            message = f": {v['message'][:150]}" if v.get("message") else ""
            lines.append(f"    {name}: {error}{v['verdict']}{extra}{message}")
    lines.append(f"  nonlinear: {text}")
    return Summary(datasets, "\n".join(lines))


def _long_label(name: str) -> str:
    """``long_rigid_index2_rho1`` -> a legend entry saying model and settings."""
    text = name.removeprefix("long_")
    for old, new in (("rigid_", "rigid, "), ("ffrf1mm", "FFRF coupler t = 1 mm"),
                     ("ffrf10mm", "FFRF coupler t = 10 mm, h = 1e-05 s"),
                     ("_h1e-5", ", h = 1e-05 s"), ("index2_", "index-2 formulation, "),
                     ("rho", "spectral radius "),
                     ("explicit_k1e8", "explicit Runge-Kutta, joint springs 1e8")):
        text = text.replace(old, new)
    if text == "FFRF coupler t = 1 mm":
        text += ", h = 1e-04 s"
    return text


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    from flex.plotting import decade_ticks, legend_below, relative_drift

    table = {key[len("runs/"):]: value.data for key, value in summary.datasets.items()
             if key.startswith("runs/")}
    paths = []
    path = folder / "stability-step.png"
    with figure(path, "Largest relative error against the time step (0.03 s deployment)",
                "time step h [s]", "largest relative error against the reference [-]") as ax:
        for (prefix, label), marker in zip((("step_rigid", "rigid links (reference: scipy "
                                             "DAE)"),
                                            ("step_ffrf1mm", "FFRF coupler t = 1 mm "
                                             "(reference: h = 2e-6 s)")), "os", strict=True):
            mask = np.array([str(n).startswith(prefix) for n in table["name"]])
            mask &= table["status"] == "ok"
            order = np.argsort(table["parameter"][mask])
            ax.loglog(table["parameter"][mask][order], table["error"][mask][order],
                      f"{marker}-", label=label)
        ax.axhline(TOLERANCE, color="grey", ls=":", label=f"tolerance {TOLERANCE:g}")
        decade_ticks(ax)
    paths.append(path)
    path = folder / "stability-energy.png"
    floor = 1e-16
    with figure(path, "Energy drift over 1 s of free motion, |E \u2212 E0| / E0 on a log "
                "scale (the runs differ by orders of magnitude)", "time [s]",
                "|E \u2212 E0| / E0 [-] (E: kinetic + strain + spring)",
                size=(8.0, 5.5)) as ax:
        for name, case in results.items():
            if (name.startswith("long_") and case.status == "ok"
                    and "energy/total" in case.datasets):
                drift = np.abs(relative_drift(case.datasets["energy/total"].data))
                ax.semilogy(case.datasets["time"].data, np.maximum(drift, floor),
                            label=_long_label(name), lw=0.8)
        ax.set_ylim(floor / 2, None)
        ax.text(0.99, 0.01, f"values below {floor:g} drawn at {floor:g}", fontsize="x-small",
                ha="right", va="bottom", transform=ax.transAxes)
        legend_below(ax.figure)
    paths.append(path)
    return paths

if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
