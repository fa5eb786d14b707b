"""Numerical stability at the extremes: each run judged against a reference of the same physics.

An :class:`Extreme` is one run (scene overrides) with the reference it is checked against:

- ``scipy``: the scipy DAE (:mod:`flex.dynamics.reference`, DOP853 rtol 1e-12, shown converged by
  rtol 1e-11), rigid links;
- ``fine:<step>``: flex's own model at ``<step>`` [s] with modified Newton to 1e-10 (shown
  converged by twice that step);
- ``nonlinear_fe:<step>``: the fully nonlinear FE coupler on the same mesh at ``<step>`` [s]
  (shown converged by twice that step): a model comparison;
- ``closed_form``: the closed-form slider-crank at constant crank speed (exact);
- ``none``: no reference (the run is judged by its constraint norm alone).

:class:`References` builds each reference once per physics; :func:`judge` gives a run its
verdict (largest relative error against the reference <= ``tolerance``, energy drift,
boundedness of the deflection, axial load over the Euler load); :func:`simulate_extremes`
runs and judges every case (the verdicts go to the run's notes, the curves a study keeps to
its file); :func:`summarize_extremes` tabulates the verdicts (``runs/...``) and the
thickness from which linear FFRF agrees with the nonlinear FE coupler
(:func:`trust_boundary`); :func:`stability_figures` draws the error against the step and
the energy drift over a long horizon.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.caseloop import Progress, run_each
from flex.base.errors import FlexError
from flex.base.kinematics import constant_speed_motion
from flex.base.physics import Plate, pinned_pinned_omega
from flex.base.plotting import decade_ticks, figure, legend_below, relative_drift
from flex.base.thesis import (
    THESIS_COUPLER_LENGTH_M,
    THESIS_DENSITY_KG_PER_M3,
    THESIS_YOUNGS_MODULUS_PA,
)
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, to_toml
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, FFRF, NONLINEAR_FE
from flex.experiments.workprecision.convergence import converged_reference
from flex.experiments.workprecision.measurement import (
    Observables,
    ReductionPool,
    Reference,
    Setting,
    nonlinear_available,
)
from flex.fidelity.simulation import simulate_case
from flex.fidelity.softening import coupler_compression_N

Verdict = dict[str, Any]


@dataclass(frozen=True)
class Extreme:
    """One run at an extreme: scene overrides, its group, the reference it is checked
    against (see the module doc), the varied value and ``expect = "diverges"`` for the
    forced divergences."""

    name: str
    group: str
    overrides: tuple[str, ...]
    reference: str
    parameter: float = math.nan  # the varied value (thickness, step, rho, angle, factor)
    expect: str = "within"


PLATE = ('coupler.geometry="plate"', f'coupler.model="{FFRF}"')


def plate_overrides(thickness_mm: float, mesh_mm: float) -> tuple[str, ...]:
    """Overrides of an FFRF plate coupler ``thickness_mm`` thick, meshed at ``mesh_mm``."""
    return PLATE + (f"coupler.thickness_m={thickness_mm * 1e-3!r}",
                    f"coupler.mesh_size_m={mesh_mm * 1e-3!r}")


def thesis_plate_period_s(thickness_mm: float) -> float:
    """Euler-Bernoulli pinned-pinned first bending period of the thesis plate [s]."""
    omega = pinned_pinned_omega(THESIS_COUPLER_LENGTH_M, thickness_mm * 1e-3,
                                THESIS_YOUNGS_MODULUS_PA, THESIS_DENSITY_KG_PER_M3)
    return 2 * math.pi / omega


def extreme_cases(scene: Scene, extremes: Sequence[Extreme]) -> dict[str, Scene]:
    """The validated scene of every extreme, by name."""
    out = {}
    for extreme in extremes:
        case = derive_scene(scene, list(extreme.overrides))
        out[extreme.name] = case
    return out


# ------------------------------------------------------------------------------------------
# references
# ------------------------------------------------------------------------------------------
#: the numerical knobs of [simulation]: references of scenes differing only in these are shared
NUMERICAL = ("step_s", "spectral_radius", "integrator", "formulation", "newton",
             "newton_relative_tolerance", "explicit_method", "penalty_stiffness_N_per_m",
             "output_step_s")


def _physics_key(scene: Scene) -> str:
    """TOML of ``scene`` without the :data:`NUMERICAL` knobs of [simulation]."""
    reduced = {section: dict(table) for section, table in scene.items()}
    for key in NUMERICAL:
        reduced["simulation"].pop(key, None)
    return to_toml(reduced)


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


def closed_form_reference(scene: Scene, time_s: np.ndarray, tolerance: float) -> Reference:
    """The exact constant-crank-speed slider-crank of ``scene`` at ``time_s`` [s]."""
    theta, state = constant_speed_motion(
        scene["crank"]["length_m"], scene["coupler"]["length_m"],
        math.radians(scene["crank"]["initial_angle_deg"]),
        scene["drive"]["crank_speed_rad_per_s"], time_s, scene["slider"]["offset_m"])
    observables = Observables(time_s, theta, np.asarray(state.slider_position_m, dtype=float))
    exact = {"crank_angle_rad": 0.0, "slider_position_m": 0.0, "error": 0.0}
    return Reference("closed form", observables, Setting("closed-form slider-crank"),
                     {"closed form (exact)": exact}, tolerance, 0.0,
                     "closed-form in-line slider-crank at constant crank speed (exact)")


class References:
    """References built once per physics and shared by the runs that need them; runs that
    are references use ``pool``'s reductions; ``tolerance``: the verdicts' threshold."""

    def __init__(self, pool: ReductionPool, tolerance: float) -> None:
        self.pool = pool
        self.tolerance = tolerance
        self._cache: dict[tuple[str, str], Reference] = {}

    def get(self, kind: str, scene: Scene, run_time_s: np.ndarray | None = None
            ) -> Reference | None:
        """The reference of ``kind`` for ``scene`` (None for ``none``); ``run_time_s``: the
        run's sample times [s] (the closed form is evaluated there)."""
        if kind == "none":
            return None
        if kind == "closed_form":
            if run_time_s is None:
                raise FlexError("the closed-form reference needs the run's sample times")
            return closed_form_reference(scene, run_time_s, self.tolerance)
        key = (kind, _physics_key(scene))
        if key not in self._cache:
            self._cache[key] = self._build(kind, scene)
        return self._cache[key]

    def _build(self, kind: str, scene: Scene) -> Reference:
        name, _, value = kind.partition(":")
        if name == "scipy":  # sampled every 1e-5 s (1e-4 s beyond 0.1 s), cubic in between
            interval = 1e-5 if scene["simulation"]["end_time_s"] <= 0.1 else 1e-4
            base = derive_scene(scene, [f"simulation.output_step_s={interval!r}",
                                        f"simulation.step_s={interval!r}"])
            return converged_reference(
                base, "scipy", Setting("scipy DOP853 rtol=1e-12", engine="scipy", rtol=1e-12,
                                       atol=1e-14),
                {"rtol 1e-12 -> 1e-11": Setting("scipy rtol=1e-11", engine="scipy",
                                                rtol=1e-11, atol=1e-13)},
                self.tolerance / 10, self.pool,
                "scipy DOP853 on the 9-coordinate DAE, rtol 1e-12 (evidence: rtol 1e-11)")
        if name == "fine" and value:
            step = float(value)
            return converged_reference(
                scene, f"flex h={step:g}", _fine_setting(step),
                {f"step {step:g} -> {2 * step:g}": _fine_setting(2 * step)},
                self.tolerance / 10, self.pool,
                f"flex, same discretization, h = {step:g} s, modified Newton 1e-10 "
                f"(evidence: h = {2 * step:g} s)")
        if name == NONLINEAR_FE and value:
            step = float(value)
            nonlinear = derive_scene(scene, [f'coupler.model="{NONLINEAR_FE}"',
                                             "simulation.newton_relative_tolerance=1e-8"])
            return converged_reference(
                nonlinear, "nonlinear FE", _nonlinear_setting(step),
                {f"step {step:g} -> {2 * step:g}": _nonlinear_setting(2 * step)},
                self.tolerance, self.pool,
                f"fully nonlinear FE coupler, same mesh, h = {step:g} s (evidence: "
                f"h = {2 * step:g} s; each step costs ~0.4-1.6 s)")
        raise FlexError(f"unknown reference kind {kind!r}")


# ------------------------------------------------------------------------------------------
# judging
# ------------------------------------------------------------------------------------------
def run_measures(scene: Scene, data: dict[str, np.ndarray]) -> Verdict:
    """What a run shows by itself: energy drift and range (relative to E0 and to the largest
    strain energy), |deflection| peaks in the first and last tenth [m] and the largest
    compression over the Euler load (flexible couplers)."""
    out: Verdict = {}
    if "energy/total" in data:
        energy = data["energy/total"]
        out["energy_drift"] = float((energy[-1] - energy[0]) / energy[0])
        out["energy_range"] = float(np.ptp(energy) / energy[0])
        if "energy/strain" in data and data["energy/strain"].max() > 0:
            # the plate's own energy is a small part of the total (the spring's): the drift
            # as a fraction of the largest strain energy says how much of the plate's
            # vibration the integrator removed
            out["energy_drift_over_peak_strain"] = float(
                (energy[-1] - energy[0]) / data["energy/strain"].max())
    if not BUILTIN_LINK_MODELS[scene["coupler"]["model"]].rigid:
        deflection = np.abs(data["coupler/midpoint_deflection"])
        tenth = max(1, len(deflection) // 10)
        out["peak_deflection_first_tenth"] = float(deflection[:tenth].max())
        out["peak_deflection_last_tenth"] = float(deflection[-tenth:].max())
        out["axial_force_over_euler_load"] = float(
            max(coupler_compression_N(data).max(), 0.0) / Plate.of(scene["coupler"]).euler_load_N)
    return out


def _against(extreme: Extreme, case: CaseResult, reference: Reference, tolerance: float
             ) -> Verdict:
    """Errors of ``case`` against ``reference`` and the verdict they give."""
    try:
        errors = reference.errors(Observables.of_datasets(case.datasets, reference.flexible))
    except FlexError as exc:
        return {"verdict": f"comparison failed: {exc}", "within_tolerance": False}
    out: Verdict = {f"error_{key}": value for key, value in errors.items() if key != "error"}
    out["reference"] = reference.description
    out["reference_accuracy"] = reference.accuracy
    out["error"] = errors["error"]
    out["within_tolerance"] = bool(errors["error"] <= tolerance)
    if extreme.expect == "diverges":
        out["verdict"] = "expected to diverge but did not"
        return out
    out["verdict"] = ("within tolerance" if out["within_tolerance"]
                      else f"outside tolerance ({errors['error']:.1e} > {tolerance:g})")
    if not reference.converged:
        out["verdict"] += (f"; reference itself only shown to {reference.accuracy:.1e}"
                           if math.isfinite(reference.accuracy)
                           else "; reference not shown converged (its coarser run failed)")
    return out


def judge(extreme: Extreme, scene: Scene, case: CaseResult, references: References,
          tolerance: float) -> Verdict:
    """Verdict of one run: errors against its reference, energy drift, boundedness."""
    verdict: Verdict = {"group": extreme.group, "parameter": extreme.parameter,
                        "expect": extreme.expect, "status": case.status,
                        "message": case.message}
    if case.status != "ok":
        verdict["verdict"] = ("diverged as expected, detected" if extreme.expect == "diverges"
                              else "diverged (detected and stored as failed)")
        verdict["within_tolerance"] = False
        return verdict
    data = {key: value.data for key, value in case.datasets.items()}
    verdict.update(run_measures(scene, data))
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
    verdict.update(_against(extreme, case, reference, tolerance))
    return verdict


def _run_extreme(extreme: Extreme, scene: Scene, pool: ReductionPool, references: References,
                 keep: Sequence[str], tolerance: float) -> tuple[CaseResult, Verdict]:
    """Run one extreme and judge it; keep the curves ``keep``, the verdict in attrs."""
    try:
        reduction = pool.for_scene(scene)
    except FlexError as exc:
        case = CaseResult(extreme.name, to_toml(scene), status="failed", message=str(exc))
    else:
        case = simulate_case(scene, extreme.name, reduction, cache_dir=pool.cache_dir)
    try:
        verdict = judge(extreme, scene, case, references, tolerance)
    except Exception as exc:  # one broken comparison must not lose a half-hour run
        verdict = {"group": extreme.group, "parameter": extreme.parameter,
                   "expect": extreme.expect, "status": case.status,
                   "message": case.message, "within_tolerance": False,
                   "verdict": f"internal error while judging: {type(exc).__name__}: {exc}"}
    if case.status == "ok":
        case.datasets = {k: v for k, v in case.datasets.items() if k in keep}
    case.attrs.update({key: value for key, value in verdict.items()
                       if isinstance(value, str | float | int | bool)
                       and key not in ("status", "message")})
    return case, verdict


def simulate_extremes(extremes: Sequence[Extreme], scenes: dict[str, Scene],
                      progress: Progress | None, notes: dict[str, Any], keep: Sequence[str],
                      tolerance: float, *, cache_dir: Path | None = None
                      ) -> dict[str, CaseResult]:
    """Run every extreme, judge it against its reference (``notes["verdicts"][name]``);
    keep only the curves ``keep``. A nonlinear FE reference that cannot be built here makes
    its case failed ("pending"). ``cache_dir``: the reduction cache folder (None: reductions
    are built in memory, no disk cache)."""
    pool = ReductionPool(cache_dir)
    references = References(pool, tolerance)
    by_name = {extreme.name: extreme for extreme in extremes}
    nonlinear = nonlinear_available()
    verdicts: dict[str, Verdict] = notes.setdefault("verdicts", {})

    def run_one(name: str, scene: Scene) -> CaseResult:
        extreme = by_name[name]
        if extreme.reference.startswith(NONLINEAR_FE) and not nonlinear:
            verdicts[name] = {"group": extreme.group, "parameter": extreme.parameter,
                              "status": "failed", "verdict": "pending: no nonlinear FE",
                              "within_tolerance": False, "expect": extreme.expect}
            return CaseResult(name, to_toml(scene), status="failed",
                              message="nonlinear FE coupler not available")
        case, verdicts[name] = _run_extreme(extreme, scene, pool, references, keep, tolerance)
        return case

    return run_each(scenes, run_one, progress)


# ------------------------------------------------------------------------------------------
# summary
# ------------------------------------------------------------------------------------------
def trust_boundary(verdicts: dict[str, Verdict]) -> tuple[float, str]:
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


def _columns(tolerance: float) -> tuple[tuple[str, str, Any, str, str, Any], ...]:
    """The ``runs/`` table: (dataset, verdict key, default, units, description, dtype)."""
    return (
        ("group", "group", "", "1", "extreme", object),
        ("parameter", "parameter", np.nan, "see group", "varied value: thickness [mm], step "
         "[s], rho, angle [deg], factor, horizon [s]", float),
        ("status", "status", "", "1", "ok | failed", object),
        ("verdict", "verdict", "", "1", "what happened", object),
        ("within_tolerance", "within_tolerance", False, "1",
         f"largest relative error <= {tolerance:g}", bool),
        ("error", "error", np.nan, "1", "largest relative error", float),
        ("crank_angle_error", "error_crank_angle_rad", np.nan, "rad",
         "max |crank angle - reference|", float),
        ("slider_position_error", "error_slider_position_m", np.nan, "m",
         "max |slider x - reference|", float),
        ("peak_deflection_error", "error_peak_deflection_relative", np.nan, "1",
         "|peak - reference peak| / reference", float),
        ("energy_drift", "energy_drift", np.nan, "1",
         "(E_end - E_0) / E_0 (spring drive; kinetic + strain + spring energy)", float),
        ("energy_range", "energy_range", np.nan, "1", "(max E - min E) / E_0 (spring drive)",
         float),
        ("energy_drift_over_peak_strain", "energy_drift_over_peak_strain", np.nan, "1",
         "(E_end - E_0) / largest strain energy of the flexible links", float),
        ("message", "message", "", "1", "failure message (step, time)", object),
        ("reference_accuracy", "reference_accuracy", np.nan, "1",
         "largest relative change of the reference under one-level coarsening", float),
        ("axial_force_over_euler_load", "axial_force_over_euler_load", np.nan, "1",
         "largest coupler compression / pinned-pinned Euler load (flexible couplers)", float),
    )


def _verdict_line(name: str, v: Verdict) -> str:
    """One run's report line: error, verdict, energy, deflection, axial load, message."""
    extra = ""
    if "energy_drift" in v:
        extra += f", energy drift {v['energy_drift']:+.1e} (range {v['energy_range']:.1e})"
    if "energy_drift_over_peak_strain" in v:
        extra += f", drift / peak strain energy {v['energy_drift_over_peak_strain']:+.1e}"
    if "peak_deflection_last_tenth" in v and v["group"] == "long_horizon":
        first = v["peak_deflection_first_tenth"] * 1e6
        last = v["peak_deflection_last_tenth"] * 1e6
        extra += f", |w| peak first/last tenth {first:.1f}/{last:.1f} um"
    if "axial_force_over_euler_load" in v and v["group"] in ("thickness", "nonlinear"):
        extra += f", P/P_euler {v['axial_force_over_euler_load']:.3f}"
    error = f"error {v['error']:.1e}, " if "error" in v else ""
    message = f": {v['message'][:150]}" if v.get("message") else ""
    return f"    {name}: {error}{v['verdict']}{extra}{message}"


def summarize_extremes(results: dict[str, CaseResult], notes: dict[str, Any],
                       tolerance: float) -> tuple[dict[str, Dataset], str]:
    """The ``runs/...`` table of every judged run, ``nonlinear/trust_thickness`` [mm] and
    the report (one line per run, by group); ``notes``: the run's (its ``verdicts``)."""
    judged: dict[str, Verdict] = notes.get("verdicts", {})
    names = [name for name in results if name in judged]
    verdicts = [judged[name] for name in names]
    datasets = {"runs/name": Dataset(np.array(names, dtype=object), "1", "case")}
    for column, key, default, units, text, dtype in _columns(tolerance):
        datasets[f"runs/{column}"] = Dataset(
            np.array([v.get(key, default) for v in verdicts], dtype=dtype), units, text)
    boundary, text = trust_boundary(judged)
    datasets["nonlinear/trust_thickness"] = Dataset(boundary, "mm", text)
    lines = [f"stability: every extreme against its converged reference (tolerance "
             f"{tolerance:g}, largest relative error)"]
    for group in dict.fromkeys(v["group"] for v in verdicts):
        lines.append(f"  {group}:")
        lines += [_verdict_line(name, judged[name])
                  for name in names if judged[name]["group"] == group]
    lines.append(f"  nonlinear: {text}")
    return datasets, "\n".join(lines)


# ------------------------------------------------------------------------------------------
# figures
# ------------------------------------------------------------------------------------------
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


#: the step series of the step figure: case-name prefix -> legend entry
STEP_SERIES = {"step_rigid": "rigid links (reference: scipy DAE)",
               "step_ffrf1mm": "FFRF coupler t = 1 mm (reference: h = 2e-6 s)"}


def _step_figure(table: dict[str, np.ndarray], folder: Path, tolerance: float) -> Path:
    """Largest relative error against the step, per series of :data:`STEP_SERIES`."""
    path = folder / "stability-step.png"
    with figure(path, "Largest relative error against the time step (0.03 s deployment)",
                "time step h [s]", "largest relative error against the reference [-]") as ax:
        for (prefix, label), marker in zip(STEP_SERIES.items(), "os", strict=True):
            mask = np.array([str(n).startswith(prefix) for n in table["name"]])
            mask &= table["status"] == "ok"
            order = np.argsort(table["parameter"][mask])
            ax.loglog(table["parameter"][mask][order], table["error"][mask][order],
                      f"{marker}-", label=label)
        ax.axhline(tolerance, color="grey", ls=":", label=f"tolerance {tolerance:g}")
        decade_ticks(ax)
    return path


def _energy_figure(results: dict[str, CaseResult], folder: Path) -> Path:
    """|E - E0| / E0 over the long-horizon runs (``long_*``), log scale."""
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
    return path


def stability_figures(results: dict[str, CaseResult], summary: dict[str, Dataset],
                      folder: Path, tolerance: float) -> list[Path]:
    """``stability-step.png`` and ``stability-energy.png``; ``summary``: the summary
    datasets (the ``runs/`` table)."""
    table = {key[len("runs/"):]: value.data for key, value in summary.items()
             if key.startswith("runs/")}
    return [_step_figure(table, folder, tolerance), _energy_figure(results, folder)]
