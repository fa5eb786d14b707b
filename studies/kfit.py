"""Study ``kfit`` (thesis sec. 6.2, Eq. 64-65): fit the rigid-or-flexible threshold k.

Each case is one steel-plate coupler scene run twice with the same integrator settings: as
an FFRF body (6 static + 6 fixed-interface Craig-Bampton modes) and as its rigid twin (same
mass and inertia). The error measures of :mod:`flex.criteria` compare the two over the
deployment (t <= delta_t_stop). Families of cases:

- ``thk_*``: coupler thickness 0.5-12 mm (20 log-spaced values plus Table 5's 1, 3, 5,
  10 mm), thesis spring (1500 N/m, 22 mm preload);
- ``stf_*``: spring stiffness 150-50000 N/m at t = 0.5, 1, 3 mm: the deployment time
  changes at fixed geometry, so n = delta_t / T varies independently of the geometry; and
  0.15-5 MN/m at t = 3, 5, 10 mm (preload lowered to keep the compression below 0.25 x
  the Euler load), which reaches n ~ 1 without buckling;
- ``pre_*``: preload 11, 16 and 33 mm at five thicknesses (the deployment time barely
  changes with the preload of a linear spring, the load amplitude does);
- every case undamped (``z0``) and with 2 % modal damping (``z2``); stiffness cases whose
  estimated compression exceeds 2 x the Euler load are left out (the linear FFRF model
  diverges there: measured at 3.3 and 11 x);
- ``val_*``: scenes not in the fit (other thicknesses, stiffnesses, link lengths) with
  ``coupler.model = "auto"``, each against a full FFRF run (12 modes), using the law
  just fitted.

Time step: h = min(1e-4 s, T/40, delta_t/400) with T the physical period of the first
pinned-pinned bending mode (measured: T/h = 24 leaves 8 % on the 12 mm crank deviation,
T/h = 48 0.5 %; T/h = 28 keeps the 1 mm peak within 0.3 %). Mesh: maxh = 3 t, within
[2 mm, 10 mm] (the first frequency within 0.3 % of the converged one).

Every case's file is ``<sweep folder>/cases/<case>.h5`` (default ``results/kfit-cases``);
the sweep resumes from them. The fit (``results/kfit-criterion.toml``) is what
``make kfit-criterion`` copies to ``flex/criteria_fit.toml`` for ``auto``. Executor:
``flex run kfit --scheduler ...`` / ``python -m flex.sweep kfit ...`` (see :mod:`flex.sweep`).
"""

from __future__ import annotations

import copy
import functools
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from flex import criteria
from flex.criteria import (
    DELTA_T_DEFINITIONS,
    GOVERNING,
    MEASURES,
    TWO_PI,
    Criterion,
    ErrorLaw,
    fit_error_law,
)
from flex.physics import euler_buckling_load_N
from flex.results import CaseResult, Dataset
from flex.scene import Scene, apply_overrides, to_toml, validate
from flex.settings import pinned_overrides
from flex.study import RESULTS_DIR, StudyRun, Summary
from flex.thesis import THESIS_ANGLE_MAX_TIME_S, THESIS_DELTA_T_S
from flex.thesis import THESIS_COMPRESSION_M as THESIS_PRELOAD_M  # sec. 6.1
from flex.thesis import THESIS_SPRING_RATE_N_PER_M as THESIS_SPRING_N_PER_M  # Table 2

SWEEP = True  # cases run on the sweep engine: --scheduler and --workers apply
NAME = "kfit"
DESCRIPTION = "fit the rigid-or-flexible threshold k from FFRF-vs-rigid sweeps"
OVERRIDES = pinned_overrides() + ['coupler.geometry="plate"', 'coupler.model="ffrf"',
                                   "coupler.modes=6", "simulation.output_step_s=0.0"]
# keys the study reads itself (its fit grid and criterion), beside its cases
READS = ("coupler.length_m", "coupler.thickness_m", "coupler.width_m",
         "coupler.youngs_modulus_Pa", "coupler.density_kg_per_m3",
         "coupler.poisson_ratio", "coupler.damping_ratio", "coupler.mesh_size_m",
         "coupler.modes", "drive.spring_stiffness_N_per_m", "drive.spring_preload_m",
         "fidelity.tolerance")

THICKNESSES_M = tuple(sorted({round(float(t), 6) for t in np.geomspace(0.5e-3, 12e-3, 20)}
                             | {1e-3, 3e-3, 5e-3, 10e-3}))
THESIS_MODELS = {"model0": 1e-3, "model1": 3e-3, "model2": 5e-3, "model3": 10e-3}
STIFFNESS_THICKNESSES_M = (0.5e-3, 1e-3, 3e-3)
STIFFNESSES_N_PER_M = (150.0, 500.0, 5000.0, 15000.0, 50000.0)
#: fast deployments of thicker plates: (thickness, spring rate); preload from FAST_EULER_RATIO
FAST_CASES = ((3e-3, 1.5e5), (3e-3, 5e5), (5e-3, 5e5), (5e-3, 1.5e6), (10e-3, 5e6))
FAST_EULER_RATIO = 0.1  # estimated with COMPRESSION_SHARE; fast springs load the coupler
#                          more (measured 1.7-2 x the estimate), so this keeps P < 0.25 P_euler
PRELOAD_THICKNESSES_M = (0.826e-3, 1e-3, 1.91e-3, 3e-3, 5.2e-3)
PRELOADS_M = (0.011, 0.016, 0.033)
DAMPING_RATIOS = (0.0, 0.02)
TOLERANCES = (0.1, 0.01, 0.001)
#: a case whose deflection exceeds this fraction of L2 is outside the small-deformation
#: FFRF model, one loaded beyond criteria.EULER_LOAD_LIMIT of its Euler load is governed by
#: buckling: stored, shown, but not fitted
VALIDITY_DEFLECTION = 0.05
#: compressive coupler force / (spring rate x preload), measured on the thesis scene (the
#: spring mostly accelerates the slider); used only to leave out cases that would diverge
COMPRESSION_SHARE = 0.32
SKIP_EULER_RATIO = 2.0
FULL_MODES = 12
CURVE_SAMPLES = 500

#: validation scenes (not in the fit): name -> (overrides, tolerance)
VALIDATION: dict[str, tuple[list[str], float]] = {
    "val_t0p7mm_tol1pct": (["coupler.thickness_m=0.0007"], 0.01),
    "val_t2p2mm_tol1pct": (["coupler.thickness_m=0.0022"], 0.01),
    "val_t2p2mm_tol0p1pct": (["coupler.thickness_m=0.0022"], 0.001),
    "val_t7mm_tol0p1pct": (["coupler.thickness_m=0.007"], 0.001),
    "val_t1p5mm_k20000_tol1pct": (["coupler.thickness_m=0.0015",
                                   "drive.spring_stiffness_N_per_m=20000.0"], 0.01),
    "val_t4mm_k800_tol0p1pct": (["coupler.thickness_m=0.004",
                                 "drive.spring_stiffness_N_per_m=800.0"], 0.001),
    "val_L100_t1p5mm_tol1pct": (["coupler.length_m=0.1", "coupler.thickness_m=0.0015"], 0.01),
    "val_L60_t0p8mm_tol0p1pct": (["coupler.length_m=0.06", "coupler.thickness_m=0.0008"],
                                 0.001),
    "val_t2p5mm_z2_tol0p1pct": (["coupler.thickness_m=0.0025", "coupler.damping_ratio=0.02"],
                                0.001),
}


# ------------------------------------------------------------------------------------------
# scenes
# ------------------------------------------------------------------------------------------
def _label(value: float, unit_scale: float) -> str:
    text = f"{value * unit_scale:.3g}"
    return text.replace(".", "p")


def mesh_size_m(thickness_m: float) -> float:
    """Netgen maxh for a plate: 3 t within [2 mm, 10 mm] (see the module doc)."""
    return float(min(max(3.0 * thickness_m, 2e-3), 10e-3))


def tuned(scene: Scene) -> Scene:
    """The scene with the sweep's mesh, time step and end time (a pure function of it).

    Deployment time estimate: the thesis half swing 0.0265 s at 1500 N/m scaled by
    sqrt(1500 / k) (a linear spring); end time 1.3 x that; step h = min(1e-4, T/40,
    estimate/400) with T = 2 pi / omega (Euler-Bernoulli, pinned-pinned).
    """
    coupler, drive = scene["coupler"], scene["drive"]
    omega = criteria.pinned_pinned_omega(coupler["length_m"], coupler["thickness_m"],
                                         coupler["youngs_modulus_Pa"],
                                         coupler["density_kg_per_m3"])
    estimate = THESIS_ANGLE_MAX_TIME_S * math.sqrt(THESIS_SPRING_N_PER_M
                                                   / drive["spring_stiffness_N_per_m"])
    estimate *= max(1.0, drive["spring_preload_m"] / THESIS_PRELOAD_M) ** 0.25
    step = min(1e-4, TWO_PI / omega / 40.0, estimate / 400.0)
    step = float(f"{step:.2g}")
    end = float(f"{1.3 * estimate:.3g}")
    return apply_overrides(scene, [f"coupler.mesh_size_m={mesh_size_m(coupler['thickness_m'])}",
                                   f"simulation.step_s={step!r}",
                                   f"simulation.end_time_s={end!r}"])


def fit_cases(scene: Scene) -> dict[str, Scene]:
    """The cases of the fit (families ``thk``, ``stf``, ``pre``; see the module doc)."""
    out: dict[str, Scene] = {}

    def add(name: str, changes: list[str]) -> None:
        case = tuned(apply_overrides(scene, changes))
        validate(case)
        out[name] = case

    for zeta in DAMPING_RATIOS:
        z = f"z{round(zeta * 100)}"
        for t in THICKNESSES_M:
            add(f"thk_t{_label(t, 1e3)}mm_{z}",
                [f"coupler.thickness_m={t!r}", f"coupler.damping_ratio={zeta!r}",
                 f"drive.spring_stiffness_N_per_m={THESIS_SPRING_N_PER_M!r}",
                 f"drive.spring_preload_m={THESIS_PRELOAD_M!r}"])
        for t in STIFFNESS_THICKNESSES_M:
            for k in STIFFNESSES_N_PER_M:
                euler = euler_buckling_load_N(scene["coupler"]["length_m"], t,
                                              scene["coupler"]["width_m"],
                                              scene["coupler"]["youngs_modulus_Pa"])
                if COMPRESSION_SHARE * k * THESIS_PRELOAD_M > SKIP_EULER_RATIO * euler:
                    continue
                add(f"stf_t{_label(t, 1e3)}mm_k{k:.0f}_{z}",
                    [f"coupler.thickness_m={t!r}", f"coupler.damping_ratio={zeta!r}",
                     f"drive.spring_stiffness_N_per_m={k!r}",
                     f"drive.spring_preload_m={THESIS_PRELOAD_M!r}"])
        for t, k in FAST_CASES:
            euler = euler_buckling_load_N(scene["coupler"]["length_m"], t,
                                          scene["coupler"]["width_m"],
                                          scene["coupler"]["youngs_modulus_Pa"])
            preload = min(THESIS_PRELOAD_M,
                          round(FAST_EULER_RATIO * euler / (COMPRESSION_SHARE * k), 4))
            add(f"stf_t{_label(t, 1e3)}mm_k{k:.0f}_{z}",
                [f"coupler.thickness_m={t!r}", f"coupler.damping_ratio={zeta!r}",
                 f"drive.spring_stiffness_N_per_m={k!r}",
                 f"drive.spring_preload_m={preload!r}"])
        for t in PRELOAD_THICKNESSES_M:
            for preload in PRELOADS_M:
                add(f"pre_t{_label(t, 1e3)}mm_p{_label(preload, 1e3)}mm_{z}",
                    [f"coupler.thickness_m={t!r}", f"coupler.damping_ratio={zeta!r}",
                     f"drive.spring_stiffness_N_per_m={THESIS_SPRING_N_PER_M!r}",
                     f"drive.spring_preload_m={preload!r}"])
    return out


def validation_cases(scene: Scene) -> dict[str, Scene]:
    """``val_*`` scenes with ``coupler.model = "auto"`` and their tolerance."""
    out = {}
    for name, (changes, tolerance) in VALIDATION.items():
        case = tuned(apply_overrides(scene, [*changes, 'coupler.model="auto"',
                                             f"fidelity.tolerance={tolerance!r}"]))
        validate(case)
        out[name] = case
    return out


def cases(scene: Scene) -> dict[str, Scene]:
    """Fit cases, then validation cases (run after the fit, see :func:`simulate_cases`)."""
    return {**fit_cases(scene), **validation_cases(scene)}


# ------------------------------------------------------------------------------------------
# one case (runs on a worker)
# ------------------------------------------------------------------------------------------
def geometry_key(scene: Scene) -> tuple | None:
    """What a reduction depends on (None for scenes that need none)."""
    c = scene["coupler"]
    if c["model"] not in ("ffrf", "auto"):
        return None
    return (c["length_m"], c["thickness_m"], c["width_m"], c["youngs_modulus_Pa"],
            c["density_kg_per_m3"], c["poisson_ratio"], c["mesh_size_m"], c["modes"])


@functools.lru_cache(maxsize=3)
def _reduction(key: tuple) -> Any:
    from flex.reduction import build_reduction
    from flex.solver import reduction_cache_dir

    return build_reduction(*key, reduction_cache_dir())


def reduction_of(scene: Scene) -> Any:
    """The scene's reduction: built (or loaded from the disk cache) once per worker."""
    return _reduction(geometry_key(scene))


def prepare_reduction(scene: Scene) -> dict[str, Any]:
    """Sweep preparation: build (or find) the scene's reduction in the disk cache."""
    reduction = reduction_of(scene)
    return {"key": reduction.key, "from_cache": reduction.from_cache,
            "build_time_s": reduction.build_time_s}


def full_scene(scene: Scene) -> Scene:
    """The validation reference: the scene's coupler as FFRF with :data:`FULL_MODES` modes."""
    return _with(scene, coupler__model="ffrf", coupler__modes=FULL_MODES)


def full_geometry_key(scene: Scene) -> tuple | None:
    """Preparation key of a validation case: its full model's reduction."""
    return geometry_key(full_scene(scene))


def prepare_full_reduction(scene: Scene) -> dict[str, Any]:
    """Validation preparation: the full model's reduction (auto builds its own if FFRF)."""
    return prepare_reduction(full_scene(scene))


def _with(scene: Scene, **changes: Any) -> Scene:
    out = copy.deepcopy(scene)
    for dotted, value in changes.items():
        section, key = dotted.split("__")
        out[section][key] = value
    return out


def _downsample(count: int) -> slice:
    return slice(None, None, max(1, math.ceil(count / CURVE_SAMPLES)))


def _data(result: CaseResult) -> dict[str, np.ndarray]:
    return {k: np.asarray(v.data) for k, v in result.datasets.items()}


def _run_pair(scene: Scene, reduction: Any) -> tuple[dict, dict, dict[str, float], dict]:
    """Rigid twin (long enough to stop), then the FFRF run to just past delta_t_stop."""
    from flex.simulation import simulate

    rigid_scene = _with(scene, coupler__model="rigid")
    for _ in range(3):
        rigid = simulate(rigid_scene, "rigid")
        rigid_data = _data(rigid)
        try:
            times = criteria.deployment_times(rigid_data["time"], rigid_data["crank/angle"],
                                              rigid_data["crank/angular_velocity"])
            break
        except ValueError:
            end = 2 * rigid_scene["simulation"]["end_time_s"]
            rigid_scene = _with(rigid_scene, simulation__end_time_s=end)
    else:
        raise ValueError("no crank-angle maximum within 4 x the estimated deployment time")
    step = scene["simulation"]["step_s"]
    end = min(rigid_scene["simulation"]["end_time_s"],
              step * math.ceil(1.02 * times["stop"] / step + 2))
    ffrf = simulate(_with(scene, coupler__model="ffrf", simulation__end_time_s=end), "ffrf",
                    reduction)
    walls = {"rigid": rigid.counters["wall_time_s"], "ffrf": ffrf.counters["wall_time_s"],
             "ffrf_steps": ffrf.counters["steps"], "rigid_steps": rigid.counters["steps"]}
    return rigid_data, _data(ffrf), times, walls


def kfit_case(name: str, scene: Scene) -> CaseResult:
    """One fit case: FFRF and rigid twin, the error measures, n by every definition.

    Stores ``parameters/*``, ``delta_t/<definition>`` [s], ``n_physical/<definition>``,
    ``n_thesis/<definition>``, ``measures/<measure>`` (dimensionless) and absolute values,
    ``frequency/*`` and downsampled ``curves/*`` with units.
    """
    coupler, drive = scene["coupler"], scene["drive"]
    reduction = reduction_of(scene)
    rigid, ffrf, times, walls = _run_pair(scene, reduction)
    length, thickness, width = coupler["length_m"], coupler["thickness_m"], coupler["width_m"]
    measures = criteria.error_measures(rigid, ffrf, length, thickness, width, times["stop"],
                                       coupler["youngs_modulus_Pa"])
    omega = criteria.pinned_pinned_omega(length, thickness, coupler["youngs_modulus_Pa"],
                                         coupler["density_kg_per_m3"])
    out: dict[str, Dataset] = {
        "parameters/thickness": Dataset(thickness, "m", "plate thickness (in-plane height)"),
        "parameters/length": Dataset(length, "m", "coupler length L2"),
        "parameters/spring_stiffness": Dataset(drive["spring_stiffness_N_per_m"], "N/m",
                                               "deployment spring rate"),
        "parameters/spring_preload": Dataset(drive["spring_preload_m"], "m",
                                             "spring compression at t = 0"),
        "parameters/damping_ratio": Dataset(coupler["damping_ratio"], "1",
                                            "modal damping ratio of the first bending mode"),
        "parameters/step": Dataset(scene["simulation"]["step_s"], "s", "time step"),
        "parameters/mesh_size": Dataset(coupler["mesh_size_m"], "m", "netgen maxh"),
        "parameters/mesh_dof": Dataset(reduction.n_dof, "1", "unreduced FE degrees of freedom"),
        "frequency/omega_euler_bernoulli": Dataset(omega, "rad/s",
                                                   "pinned-pinned first bending, beam theory"),
        "frequency/pinned_pinned_fe": Dataset(reduction.pinned_pinned_frequency_Hz, "Hz",
                                              "pinned-pinned first bending of the reduction"),
        "wall_time/ffrf": Dataset(walls["ffrf"], "s", "FFRF simulation wall time"),
        "wall_time/rigid": Dataset(walls["rigid"], "s", "rigid twin simulation wall time"),
    }
    for definition, delta_t in times.items():
        n = criteria.n_values(delta_t, omega)
        out[f"delta_t/{definition}"] = Dataset(delta_t, "s", DELTA_T_DEFINITIONS[definition])
        out[f"n_physical/{definition}"] = Dataset(n["physical"], "1",
                                                  "delta_t / T, T = 2 pi / omega")
        out[f"n_thesis/{definition}"] = Dataset(n["thesis"], "1",
                                                "delta_t * omega (thesis: T = 1 / omega)")
    units = {"deflection_abs_m": "m", "crank_angle_abs_rad": "rad", "slider_position_abs_m": "m",
             "peak_stress_ffrf_Pa": "Pa", "peak_stress_quasi_static_Pa": "Pa",
             "crank_swing_rad": "rad", "slider_travel_m": "m", "stress_ratio": "1",
             "euler_load_ratio": "1"}
    notes = {"stress_ratio": "peak FFRF / quasi-static bending stress (dynamic amplification)",
             "euler_load_ratio": "largest compressive force / Euler load pi^2 E I / L^2"}
    for key, value in measures.items():
        out[f"measures/{key}"] = Dataset(value, units.get(key, "1"), MEASURES.get(
            key, notes.get(key, key.replace("_", " "))))
    count = int(np.sum(ffrf["time"] <= times["stop"] * (1 + 1e-12)))
    pick = _downsample(count)
    window = slice(0, count)
    qs = criteria.quasi_static_stress(rigid["joints/B/force_on_coupler"][window],
                                      rigid["joints/C/force_on_coupler"][window],
                                      rigid["coupler/angle"][window], length, thickness, width)
    curves = {
        "time": (ffrf["time"], "s", "time (deployment window, downsampled)"),
        "crank_angle_ffrf": (ffrf["crank/angle"], "rad", "crank angle, FFRF"),
        "crank_angle_rigid": (rigid["crank/angle"], "rad", "crank angle, rigid twin"),
        "slider_position_ffrf": (ffrf["slider/position"], "m", "slider position, FFRF"),
        "slider_position_rigid": (rigid["slider/position"], "m", "slider position, rigid twin"),
        "midpoint_deflection": (ffrf["coupler/midpoint_deflection"], "m",
                                "elastic midpoint deflection, FFRF"),
        "peak_bending_stress_ffrf": (ffrf["coupler/peak_bending_stress"], "Pa",
                                     "peak |sigma_xx|, FFRF"),
        "peak_bending_stress_quasi_static": (qs, "Pa", "quasi-static beam stress of the rigid "
                                             "twin's loads"),
    }
    for key, (values, unit, text) in curves.items():
        out[f"curves/{key}"] = Dataset(np.asarray(values)[window][pick], unit, text)
    counters = {"wall_time_s": walls["ffrf"] + walls["rigid"], "steps": walls["ffrf_steps"]}
    return CaseResult(name, to_toml(scene), out, counters=counters,
                      attrs={"reduction_key": reduction.key,
                             "reduction_cold_build_time_s": reduction.cold_build_time_s})


# ------------------------------------------------------------------------------------------
# validation of auto (runs on a worker, after the fit)
# ------------------------------------------------------------------------------------------
def validation_case(name: str, scene: Scene, criterion_toml: str = "") -> CaseResult:
    """``auto`` against the full FFRF model (12 modes) on a scene outside the fit.

    The ``auto`` run goes through :func:`flex.simulation.simulate` with the law just fitted
    (``criterion_toml``, passed as an argument). Stores the decision, the error measures of
    the auto run against the full FFRF run and both wall times.
    """
    from flex.simulation import simulate

    law = criteria.parse_criterion(criterion_toml, "kfit (this run's fit)")
    start = time.perf_counter()
    auto = simulate(scene, "auto", criterion=law)
    auto_total = time.perf_counter() - start
    reference = full_scene(scene)
    start = time.perf_counter()
    full_reduction = reduction_of(reference)
    full_reduction_s = time.perf_counter() - start
    full = simulate(reference, "full", full_reduction)
    auto_data, full_data = _data(auto), _data(full)
    errors = criteria.errors_against_full(auto_data, full_data, "coupler",
                                          scene["coupler"]["length_m"])
    delta_t_s = errors.pop("delta_t")
    tolerance = scene["fidelity"]["tolerance"]
    out = {f"errors/{k}": Dataset(v, "1", f"auto against full FFRF: {MEASURES[k]}")
           for k, v in errors.items()}
    out.update({
        "tolerance": Dataset(tolerance, "1", "requested [fidelity] tolerance"),
        "within_tolerance": Dataset(int(errors[GOVERNING] <= tolerance), "1",
                                    "1 if the governing error <= tolerance"),
        "wall_time/auto_simulation": Dataset(auto.counters["wall_time_s"], "s",
                                             "integration of the chosen model"),
        "wall_time/auto_total": Dataset(auto_total, "s", "auto: decision (rigid probe run) + "
                                        "reduction (if FFRF) + build + integration"),
        "wall_time/full_simulation": Dataset(full.counters["wall_time_s"], "s",
                                             "integration of the full FFRF model"),
        "wall_time/full_reduction": Dataset(full_reduction_s, "s",
                                            "full model's reduction (cache load or build)"),
        "delta_t/stop": Dataset(delta_t_s, "s", DELTA_T_DEFINITIONS["stop"]),
    })
    attrs = {k: v for k, v in auto.attrs.items() if k.startswith("fidelity_")}
    return CaseResult(name, to_toml(scene), out, counters=dict(auto.counters), attrs=attrs)


# ------------------------------------------------------------------------------------------
# the sweep (study hook)
# ------------------------------------------------------------------------------------------
def sweep_folder(settings: Any = None) -> Path:
    """The sweep's folder of per-case files: ``settings.folder`` (a
    :class:`flex.sweep.SweepSettings`) or ``results/kfit-cases``."""
    return (settings.folder if settings is not None else None) or RESULTS_DIR / "kfit-cases"


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Phase 1: the fit cases (one reduction per geometry, then its cases); fit; write
    ``<folder>/../kfit-criterion.toml``; phase 2: the ``val_*`` cases with that fit.
    ``sweep``: where and how the cases run (:class:`flex.sweep.SweepSettings`, from the
    command line; None: a process pool on all cores, ``results/kfit-cases``)."""
    from flex.sweep import SweepSettings, make_executor, run_sweep

    settings = run.sweep or SweepSettings()
    sweep_notes = run.notes.setdefault("sweep", {})
    folder = sweep_folder(settings)
    fit_scenes = {n: s for n, s in scenes.items() if not n.startswith("val_")}
    val_scenes = {n: s for n, s in scenes.items() if n.startswith("val_")}
    executor = make_executor(settings.scheduler, settings.workers)
    try:
        first = run_sweep(fit_scenes, folder, kfit_case, prepare=prepare_reduction,
                          prepare_key=geometry_key, executor=executor,
                          retry_failed=settings.retry_failed, progress=settings.progress,
                          study="kfit fit cases")
        results = dict(first.results)
        sweep_notes.update(executor=executor.description, workers=executor.workers,
                          fit_wall_time_s=first.wall_time_s, ran=first.ran,
                          resumed=first.resumed, failed=first.failed)
        _phase(settings, f"kfit: fitting the error laws to {len(results)} fit cases")
        analysis = analyse(results)
        run.notes["analysis"] = analysis  # summarize and figures reuse it: fitted once
        criterion_text = criterion_toml(analysis, provenance=False)
        path = criterion_path(folder)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(criterion_toml(analysis), encoding="utf-8")
        _phase(settings, f"kfit: wrote {path}" + (f"; next: {len(val_scenes)} validation "
                                                  f"cases" if val_scenes else ""))
        if val_scenes:
            second = run_sweep(val_scenes, folder,
                               functools.partial(validation_case, criterion_toml=criterion_text),
                               prepare=prepare_full_reduction, prepare_key=full_geometry_key,
                               executor=executor, retry_failed=settings.retry_failed,
                               progress=settings.progress, study="kfit validation")
            results.update(second.results)
            sweep_notes.update(validation_wall_time_s=second.wall_time_s,
                              ran=sweep_notes["ran"] + second.ran,
                              resumed=sweep_notes["resumed"] + second.resumed,
                              failed=sweep_notes["failed"] + second.failed)
    finally:
        executor.close()
    _phase(settings, "kfit: cases done; next: the summary and the figures")
    return results


def _phase(settings: Any, text: str) -> None:
    """A phase-change line on stderr (progress only; ``FLEX_PROGRESS=0`` hides it)."""
    if settings.progress:
        print(text, file=sys.stderr, flush=True)


def criterion_path(folder: Path) -> Path:
    """Where the sweep writes its fitted criterion: beside the case folder."""
    return Path(folder).parent / "kfit-criterion.toml"


# ------------------------------------------------------------------------------------------
# analysis
# ------------------------------------------------------------------------------------------
def _scalar(case: CaseResult, key: str) -> float:
    dataset = case.datasets.get(key)
    return float(np.asarray(dataset.data)) if dataset is not None else float("nan")


def family(name: str) -> str:
    """``thk``, ``stf``, ``pre`` or ``val`` from a case name."""
    return name.split("_", 1)[0]


def table(results: dict[str, CaseResult]) -> dict[str, np.ndarray]:
    """One row per successful fit case: parameters, delta_t, n, measures (arrays)."""
    rows = [(n, c) for n, c in results.items() if c.status == "ok" and family(n) != "val"]
    columns: dict[str, list] = {"name": [n for n, _ in rows],
                                "family": [family(n) for n, _ in rows]}
    keys = (["parameters/thickness", "parameters/spring_stiffness", "parameters/spring_preload",
             "parameters/damping_ratio", "parameters/length", "parameters/step",
             "parameters/mesh_dof", "frequency/omega_euler_bernoulli",
             "frequency/pinned_pinned_fe", "wall_time/ffrf", "wall_time/rigid"]
            + [f"delta_t/{d}" for d in DELTA_T_DEFINITIONS]
            + [f"n_physical/{d}" for d in DELTA_T_DEFINITIONS]
            + [f"measures/{m}" for m in MEASURES]
            + ["measures/deflection_abs_m", "measures/peak_stress_ffrf_Pa",
               "measures/peak_stress_quasi_static_Pa", "measures/stress_ratio",
               "measures/euler_load_ratio"])
    for key in keys:
        columns[key] = [_scalar(c, key) for _, c in rows]
    out = {k: np.asarray(v) for k, v in columns.items()}
    out["fitted"] = ((out["measures/deflection"] <= VALIDITY_DEFLECTION)
                     & (out["measures/euler_load_ratio"] <= criteria.EULER_LOAD_LIMIT)
                     ) if rows else np.zeros(0, dtype=bool)
    return out


def analyse(results: dict[str, CaseResult]) -> dict[str, Any]:
    """Fits per (damping, delta_t definition, measure), k table, thesis comparison."""
    data = table(results)
    fits: dict[tuple[float, str, str], ErrorLaw] = {}
    if len(data["name"]) == 0:
        return {"table": data, "fits": fits}
    for zeta in DAMPING_RATIOS:
        rows = data["fitted"] & np.isclose(data["parameters/damping_ratio"], zeta)
        for definition in DELTA_T_DEFINITIONS:
            n = data[f"n_physical/{definition}"][rows]
            for measure in MEASURES:
                try:
                    law = fit_error_law(n, data[f"measures/{measure}"][rows],
                                        floor=measure == "stress_amplification")
                except ValueError:
                    continue
                law.meta.update(damping_ratio=zeta, delta_t_definition=definition,
                                measure=measure)
                fits[(zeta, definition, measure)] = law
    # the thesis threshold, in our terms: Table 5's model 1 (t = 3 mm, thesis spring) is
    # where the thesis puts k = 108; its n by each definition is the thesis's k there
    model1 = [i for i, name in enumerate(data["name"])
              if name == f"thk_t{_label(THESIS_MODELS['model1'], 1e3)}mm_z0"]
    thesis_k = {d: (float(data[f"n_physical/{d}"][model1[0]]) if model1 else float("nan"))
                for d in DELTA_T_DEFINITIONS}
    return {"table": data, "fits": fits, "thesis_k_physical": thesis_k}


def criterion_toml(analysis: dict[str, Any], provenance: bool = True) -> str:
    """The fitted criterion (primary delta_t, both damping ratios, every measure) as TOML.

    ``provenance=False`` leaves out the creation time and git commit: the text then depends
    on the fit alone (the validation cases' identity, so that a rerun resumes them).
    """
    laws = {(zeta, measure): law for (zeta, definition, measure), law in analysis["fits"].items()
            if definition == criteria.PRIMARY_DELTA_T}
    from flex.results import provenance as code_provenance

    meta: dict[str, Any] = {
        "source": "make kfit (studies/kfit.py); copy with make kfit-criterion",
        "cases_fitted": int(np.sum(analysis["table"]["fitted"]))
        if len(analysis["table"]["name"]) else 0,
        "euler_load_limit": criteria.EULER_LOAD_LIMIT}
    if provenance:
        info = code_provenance()
        meta.update(created_utc=info["created_utc"], git_commit=info["git_commit"],
                    git_dirty=info["git_dirty"])
    header = ("# Fitted rigid-or-flexible criterion read by coupler.model = \"auto\".\n"
              "# Generated by `make kfit` (results/kfit-criterion.toml); `make kfit-criterion`\n"
              "# copies it here. Laws: e(n) = floor + exp(log_coefficient) n^-exponent, n =\n"
              "# delta_t / T with T = 2 pi / omega (Euler-Bernoulli pinned-pinned) and\n"
              "# delta_t the time of the first crank-angle maximum (rigid run).\n")
    return Criterion(laws, criteria.PRIMARY_DELTA_T, meta=meta).to_toml(header)


def _k_table(analysis: dict[str, Any]) -> dict[tuple, float]:
    out = {}
    for key, law in analysis["fits"].items():
        for tolerance in TOLERANCES:
            for bound in ("central", "upper"):
                out[(*key, tolerance, bound)] = law.k(tolerance, "physical", bound)
    return out


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    notes = notes or {}
    analysis = notes.get("analysis") or analyse(results)
    data, fits = analysis["table"], analysis["fits"]
    datasets: dict[str, Dataset] = {}
    lines = [f"kfit: rigid-or-flexible threshold from {len(data['name'])} FFRF/rigid pairs "
             f"({int(np.sum(data['fitted']))} fitted; "
             f"{sum(c.status != 'ok' for c in results.values())} failed)"]
    descriptions = {"name": ("1", "case name"), "family": ("1", "thk, stf or pre"),
                    "fitted": ("1", "1 if used in the fits (deflection <= 5 % L2 and "
                               "compression <= 0.25 Euler load)")}
    for key, values in data.items():
        unit = descriptions.get(key, (None,))[0]
        if unit is None:
            source = next((c.datasets.get(key) for c in results.values()
                           if c.status == "ok" and key in c.datasets), None)
            unit, text = (source.units, source.description) if source else ("1", key)
        else:
            text = descriptions[key][1]
        array = values.astype(int) if values.dtype == bool else values
        datasets[f"table/{key}"] = Dataset(array, unit, text)
    if not fits:
        return Summary(datasets, "\n".join(lines + ["  no fit: too few successful cases"]))
    ks = _k_table(analysis)
    thesis_k = analysis["thesis_k_physical"]
    for (zeta, definition, measure), law in fits.items():
        group = f"fits/zeta_{zeta:g}/{definition}/{measure}"
        half = criteria._t_quantile(law.dof, 0.95) * math.sqrt(law.covariance[1, 1])
        values = {"coefficient": (law.coefficient, "1", "c in e = floor + c n^-p (physical)"),
                  "coefficient_thesis": (law.coefficient_in("thesis"), "1",
                                         "c with n in the thesis convention"),
                  "exponent": (law.exponent, "1", "p"),
                  "exponent_ci95": (np.array([law.exponent - half, law.exponent + half]), "1",
                                    "95 % confidence interval of p"),
                  "floor": (law.floor, "1", "error floor (stress amplification only)"),
                  "covariance": (law.covariance, "1", "of (ln c, p[, floor])"),
                  "residual_std": (law.residual_std, "1", "std of ln e residuals"),
                  "r_squared": (law.r_squared, "1", "on ln e"),
                  "n_range": (np.array([law.n_min, law.n_max]), "1",
                              "fitted n_physical range"),
                  "n_points": (law.n_points, "1", "fitted cases")}
        for key, (value, unit, text) in values.items():
            datasets[f"{group}/{key}"] = Dataset(value, unit, text)
        tols = np.array(TOLERANCES)
        for bound in ("central", "upper"):
            physical = np.array([ks[(zeta, definition, measure, t, bound)] for t in TOLERANCES])
            datasets[f"k/zeta_{zeta:g}/{definition}/{measure}/{bound}_physical"] = Dataset(
                physical, "1", f"k(tolerance) for tolerances {list(TOLERANCES)}, "
                f"n = delta_t / T ({bound}; inf: not reached)")
            datasets[f"k/zeta_{zeta:g}/{definition}/{measure}/{bound}_thesis"] = Dataset(
                physical * TWO_PI, "1", "same, thesis convention n = delta_t * omega")
        datasets[f"k/zeta_{zeta:g}/{definition}/{measure}/tolerance"] = Dataset(
            tols, "1", "tolerances")
        if measure != "stress_amplification" and math.isfinite(thesis_k[definition]):
            datasets[f"thesis/implied_tolerance/zeta_{zeta:g}/{definition}/{measure}"] = Dataset(
                float(law.predict(thesis_k[definition])), "1",
                "fitted error at the thesis threshold (model 1's n)")
    for definition, value in thesis_k.items():
        datasets[f"thesis/k_equivalent/{definition}/physical"] = Dataset(
            value, "1", "the thesis threshold (Table 5 model 1, t = 3 mm) as n = delta_t / T")
        datasets[f"thesis/k_equivalent/{definition}/thesis"] = Dataset(
            value * TWO_PI, "1",
            f"same in the thesis convention ({criteria.THESIS_K:g} with delta_t = "
            f"{THESIS_DELTA_T_S:g})")
    datasets["thesis/k"] = Dataset(criteria.THESIS_K, "1", "thesis sec. 6.2, n = delta_t*omega")

    # report: the laws (primary delta_t)
    lines.append("  error laws e = c n^-p (+ floor), n = delta_t/T (T = 2 pi/omega), "
                 "delta_t = stop (first crank-angle maximum); 95 % CI of p:")
    for zeta in DAMPING_RATIOS:
        for measure in MEASURES:
            law = fits.get((zeta, "stop", measure))
            if law is None:
                continue
            half = criteria._t_quantile(law.dof, 0.95) * math.sqrt(law.covariance[1, 1])
            floor = f" floor {law.floor:.3g}" if law.with_floor else ""
            lines.append(f"    zeta {zeta:<4g} {measure:21s} c {law.coefficient:9.3g} "
                         f"p {law.exponent:5.2f} +- {half:4.2f}{floor}  R2 {law.r_squared:5.3f}"
                         f"  scatter x{math.exp(law.residual_std):4.2f}  "
                         f"n {law.n_min:.3g}-{law.n_max:.3g} ({law.n_points} cases)")
    lines.append("  k(tolerance), governing error, central / conservative (95 % prediction "
                 "band); physical n | thesis n = 2 pi x; thesis k = 108:")
    for zeta in DAMPING_RATIOS:
        for definition in DELTA_T_DEFINITIONS:
            if (zeta, definition, GOVERNING) not in fits:
                continue
            cells = []
            for tolerance in TOLERANCES:
                central = ks[(zeta, definition, GOVERNING, tolerance, "central")]
                upper = ks[(zeta, definition, GOVERNING, tolerance, "upper")]
                cells.append(f"{tolerance:g}: {central:6.3g}/{upper:6.3g} | "
                             f"{central * TWO_PI:6.3g}/{upper * TWO_PI:6.3g}")
            lines.append(f"    zeta {zeta:<4g} delta_t {definition:10s} " + ";  ".join(cells))
    lines.append("  the thesis's k = 108 (model 1, t = 3 mm) in each delta_t definition, and the "
                 "governing error the fit gives there (undamped):")
    for definition in DELTA_T_DEFINITIONS:
        law = fits.get((0.0, definition, GOVERNING))
        implied = law.predict(thesis_k[definition]) if law is not None else float("nan")
        lines.append(f"    {definition:10s} n_physical {thesis_k[definition]:7.3g}  n_thesis "
                     f"{thesis_k[definition] * TWO_PI:7.3g}  error there {float(implied):.3g}")
    lines.extend(_validation_report(results, datasets))
    sweep = notes.get("sweep", {})
    if sweep:
        lines.append(f"  sweep: {sweep.get('executor')}; ran {sweep.get('ran')}, resumed "
                     f"{sweep.get('resumed')}, failed {sweep.get('failed')}; fit cases "
                     f"{sweep.get('fit_wall_time_s', 0):.0f} s, validation "
                     f"{sweep.get('validation_wall_time_s', 0):.0f} s")
        for key, value in sweep.items():
            datasets[f"sweep/{key}"] = Dataset(value if not isinstance(value, str)
                                               else np.array(value), "s" if "time" in key
                                               else "1", f"sweep {key.replace('_', ' ')}")
    return Summary(datasets, "\n".join(lines), {"analysis": analysis})


def _validation_report(results: dict[str, CaseResult], datasets: dict[str, Dataset]
                       ) -> list[str]:
    rows = [(n, c) for n, c in results.items() if family(n) == "val"]
    if not rows:
        return []
    lines = ["  auto validation (scenes not in the fit; governing error of the auto choice "
             "against a full FFRF run, 12 modes; wall times: integration, and total with the "
             "decision's rigid probe run / the full model's reduction):",
             f"    {'case':28s} {'tol':>6s} {'choice':>8s} {'n_phys':>7s} {'k':>7s} "
             f"{'error':>9s} {'ok':>3s} {'auto sim':>9s} {'auto tot':>9s} {'full sim':>9s} "
             f"{'full tot':>9s}"]
    for name, case in rows:
        if case.status != "ok":
            lines.append(f"    {name:28s} failed: {case.message}")
            continue
        model = str(case.attrs.get("fidelity_coupler_model", "?"))
        modes = int(case.attrs.get("fidelity_coupler_modes", -1))
        choice = model + (f"/{modes}" if model == "ffrf" else "")
        error = _scalar(case, f"errors/{GOVERNING}")
        tolerance = _scalar(case, "tolerance")
        auto_sim = _scalar(case, "wall_time/auto_simulation")
        auto_s = _scalar(case, "wall_time/auto_total")
        full_sim = _scalar(case, "wall_time/full_simulation")
        full_s = full_sim + _scalar(case, "wall_time/full_reduction")
        lines.append(f"    {name:28s} {tolerance:6g} {choice:>8s} "
                     f"{float(case.attrs.get('fidelity_coupler_n_physical', np.nan)):7.3g} "
                     f"{float(case.attrs.get('fidelity_coupler_k_physical', np.nan)):7.3g} "
                     f"{error:9.3g} {'yes' if error <= tolerance else 'NO':>3s} "
                     f"{auto_sim:9.2f} {auto_s:9.2f} {full_sim:9.2f} {full_s:9.2f}")
        for key in ("errors/governing", "wall_time/auto_simulation", "wall_time/auto_total",
                    "wall_time/full_simulation", "wall_time/full_reduction"):
            datasets[f"validation/{name}/{key}"] = case.datasets[key]
        datasets[f"validation/{name}/choice"] = Dataset(np.array(choice), "1", "auto choice")
    return lines


# ------------------------------------------------------------------------------------------
# figures
# ------------------------------------------------------------------------------------------
#: the case families' prefixes spelt out for figures (see the module doc)
FAMILY_NAMES = {"thk": "thickness sweep", "stf": "spring stiffness sweep",
                "pre": "preload sweep"}
#: the error measures as axis labels (definitions: flex.criteria.MEASURES)
MEASURE_LABELS = {GOVERNING: "governing error = largest of\ndeflection, angle, slider [-]",
                  "deflection": "peak deflection\n/ coupler length L2 [-]",
                  "crank_angle": "crank angle error\n/ crank swing [-]",
                  "slider_position": "slider position error\n/ slider travel [-]",
                  "stress_amplification": "|stress amplification\n\u2212 1| [-]"}


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    import matplotlib.pyplot as plt

    from flex.plotting import decade_ticks, legend_below, save, wrap

    analysis = summary.figure_data.get("analysis") or analyse(results)
    data, fits = analysis["table"], analysis["fits"]
    if not fits:
        return []
    thesis_k = analysis["thesis_k_physical"]["stop"]
    paths = []
    path = folder / "kfit-error-vs-n.png"
    measures = [GOVERNING, "deflection", "crank_angle", "slider_position", "stress_amplification"]
    fig, axes = plt.subplots(len(measures), 1, figsize=(8.5, 2.9 * len(measures) + 2.2),
                             layout="constrained", sharex=True)
    n_all = data["n_physical/stop"]
    grid = np.geomspace(max(n_all.min() / 2, 1e-2), n_all.max() * 2, 200)
    styles = {"thk": "o", "stf": "s", "pre": "^"}
    colors = {0.0: "tab:blue", 0.02: "tab:orange"}
    for ax, measure in zip(axes, measures, strict=True):
        values = data[f"measures/{measure}"]
        for fam, marker in styles.items():
            for zeta, color in colors.items():
                rows = (data["family"] == fam) & np.isclose(data["parameters/damping_ratio"],
                                                            zeta)
                if rows.any():
                    ax.loglog(n_all[rows], np.abs(values[rows]), marker, color=color,
                              mfc="none" if fam != "thk" else color, ms=5, alpha=0.8)
        excluded = ~data["fitted"]
        if excluded.any():
            ax.loglog(n_all[excluded], np.abs(values[excluded]), "x", color="red", ms=7)
        for zeta, color in colors.items():
            law = fits.get((zeta, "stop", measure))
            if law is None:
                continue
            lower, upper = law.band(grid, kind="prediction")
            ax.loglog(grid, law.predict(grid), "-", color=color,
                      label=f"fit \u03b6 = {zeta:g}: p = {law.exponent:.2f}")
            ax.fill_between(grid, lower, upper, color=color, alpha=0.12)
        for model, thickness in THESIS_MODELS.items():
            name = f"thk_t{_label(thickness, 1e3)}mm_z0"
            rows = data["name"] == name
            if rows.any():
                ax.loglog(n_all[rows], np.abs(values[rows]), "*", color="k", ms=12)
                ax.annotate(model.replace("model", "model "),
                            (n_all[rows][0], abs(values[rows][0])), fontsize=7,
                            xytext=(4, 4), textcoords="offset points")
        if math.isfinite(thesis_k):
            ax.axvline(thesis_k, color="k", ls="--", lw=1)
        ax.set_ylabel(MEASURE_LABELS.get(measure, measure.replace("_", " ") + " [-]"))
        ax.grid(True, which="major", alpha=0.3)
        decade_ticks(ax, "y")
        floor = any(law.with_floor for (_, d, m), law in fits.items()
                    if d == "stop" and m == measure)
        ax.legend(fontsize="x-small", loc="lower left", title_fontsize="x-small",
                  title="error law $e = $" + ("floor + " if floor else "") + "$c\\,n^{-p}$")
    secondary = axes[0].secondary_xaxis("top", functions=(lambda n: n * TWO_PI,
                                                          lambda n: n / TWO_PI))
    secondary.set_xlabel("n in the thesis convention = \u0394t \u00b7 \u03c9 [-]")
    decade_ticks(axes[-1], "x")
    fig.suptitle(wrap("Rigid-coupler error against n = \u0394t / T (\u0394t: time to the first "
                      "crank-angle maximum; bands: 95 % prediction)", 8.5))
    axes[-1].set_xlabel("n = \u0394t / T [-], T = 2\u03c0 / \u03c9 (period of the coupler's "
                        "first bending mode)")
    legend_below(fig, [(f"{FAMILY_NAMES[fam]} ({shape})",
                        {"marker": marker, "mfc": "k" if fam == "thk" else "none", "ms": 6})
                       for fam, marker, shape in (("thk", "o", "filled circles"),
                                                  ("stf", "s", "open squares"),
                                                  ("pre", "^", "open triangles"))]
                 + [("colour: undamped (\u03b6 = 0)",
                     {"marker": "s", "color": "tab:blue", "ms": 7}),
                    ("colour: 2 % modal damping (\u03b6 = 0.02)",
                     {"marker": "s", "color": "tab:orange", "ms": 7}),
                    ("not fitted: deflection > 5 % of L2 or compression > 0.25 Euler "
                     "buckling load", {"marker": "x", "color": "red", "ms": 7}),
                    ("thesis Table 5 models 0-3 (t = 1, 3, 5, 10 mm, undamped)",
                     {"marker": "*", "ms": 10}),
                    (f"thesis threshold k = 108 (model 1) = n {thesis_k:.3g}",
                     {"linestyle": "--"})], ncol=2, collect=False)
    save(fig, path)
    paths.append(path)

    path = folder / "kfit-k-vs-tolerance.png"
    tolerances = np.geomspace(1e-5, 0.2, 60)
    fig, ax = plt.subplots(figsize=(8.5, 6.8), layout="constrained")
    measure_styles = ((GOVERNING, "-"), ("deflection", "--"), ("crank_angle", ":"),
                      ("slider_position", "-."),
                      ("stress_amplification", (0, (6, 2, 1, 2, 1, 2))))
    entries, floors = [], []
    for measure, style in measure_styles:
        entries.append((MEASURE_LABELS[measure].replace("\n", " ").replace(" [-]", ""),
                        {"linestyle": style, "lw": 2 if measure == GOVERNING else 1.2}))
        for zeta, color in colors.items():
            law = fits.get((zeta, "stop", measure))
            if law is None:
                continue
            ks = np.array([law.k(t) for t in tolerances])
            finite = np.isfinite(ks)
            ax.loglog(tolerances[finite], ks[finite], linestyle=style, color=color,
                      lw=2 if measure == GOVERNING else 1)
            if law.with_floor:
                floors.append((f"stress amplification, \u03b6 = {zeta:g}: no k below its "
                               f"error floor {law.floor:.2g}", {"linestyle": "none"}))
            if measure == GOVERNING:
                upper = [law.k(t, bound="upper") for t in tolerances]
                ax.loglog(tolerances, upper, linestyle=style, color=color, alpha=0.4, lw=5)
    if math.isfinite(thesis_k):
        ax.axhline(thesis_k, color="k", ls="--", lw=1)
    for tolerance in TOLERANCES:
        ax.axvline(tolerance, color="grey", lw=0.5)
    ax.set_xlabel("tolerance on the error measure [-]")
    ax.set_ylabel("threshold k: smallest n = \u0394t / T for a rigid coupler [-]")
    secondary = ax.secondary_yaxis("right", functions=(lambda n: n * TWO_PI,
                                                       lambda n: n / TWO_PI))
    secondary.set_ylabel("k in the thesis convention, \u0394t \u00b7 \u03c9 [-]")
    ax.set_title(wrap("Threshold k against tolerance, per error measure (\u0394t: time to the "
                      "first crank-angle maximum)", 8.5))
    ax.grid(True, which="major", alpha=0.3)
    decade_ticks(ax)
    legend_below(fig, [*entries,
                       ("governing, conservative (95 % prediction band)",
                        {"linestyle": "-", "lw": 5, "alpha": 0.4}),
                       ("colour: undamped (\u03b6 = 0)",
                        {"marker": "s", "color": "tab:blue", "ms": 7}),
                       ("colour: 2 % modal damping (\u03b6 = 0.02)",
                        {"marker": "s", "color": "tab:orange", "ms": 7}),
                       (f"thesis threshold k = 108 (model 1) = n {thesis_k:.3g}",
                        {"linestyle": "--"}),
                       (f"tolerances tabulated in the report "
                        f"({', '.join(f'{t:g}' for t in TOLERANCES)})",
                        {"linestyle": "-", "color": "grey", "lw": 0.5}),
                       *floors], ncol=2)
    save(fig, path)
    paths.append(path)
    return paths

if __name__ == "__main__":
    from flex.cli import main

    sys.exit(main(["run", NAME]))
