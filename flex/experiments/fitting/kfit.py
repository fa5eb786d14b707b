"""The coupler's rigid-or-flexible law (study ``kfit``): its scenes and its cases.

The link-specific half of the :mod:`flex.experiments.fitting.lawfit` pipeline for the coupler
(thesis sec. 6.2, Eq. 64-65). A fit case (:func:`fit_case`, run on a sweep worker) is one
steel-plate coupler scene run twice with the same integrator settings, as an FFRF body with
geometric stiffness (``coupler.geometric_stiffness = true``, :data:`REFERENCE`) and as its rigid
twin (same mass and inertia); the error measures of :mod:`flex.fidelity.criteria` compare the two
over the deployment (t <= delta_t_stop). A validation case (:func:`validation_case`) runs
``coupler.model = "auto"`` with the law just fitted against the full FFRF model
(:data:`flex.experiments.fitting.lawfit.FULL_MODES` modes, geometric stiffness too). The fit,
the criterion file and the summary: :mod:`flex.experiments.fitting.kfit_law`.

Why geometric stiffness: the linear FFRF body, its floating frame on the B face, puts the
axial force's rigid-turn term through its bending with the wrong sign and twice the size
(docs/validation.md section 4, docs/geometric-stiffness.md): compression stiffens it,
tension softens it. Against it the rigid model's error read too low in compression and too
high in tension; with geometric stiffness the FFRF coupler is within ~1 % of the nonlinear
FE coupler (``make ladder``).

Scenes (:func:`fit_cases`): each is :func:`tuned` (mesh maxh = 3 t within [2 mm, 5 mm],
the first frequency within 0.3 % of the converged one; time step h = min(1e-4 s, T/40,
delta_t/400) with T the period of the first pinned-pinned bending mode: T/h = 24 leaves 8 %
on the 12 mm crank deviation, T/h = 48 0.5 %, T/h = 28 keeps the 1 mm peak within 0.3 %).
Cases whose estimated compression (:func:`estimated_euler_ratio`) exceeds
:data:`flex.fidelity.criteria.EULER_LOAD_LIMIT` x the Euler load are not generated
(:func:`left_out_cases` names them, the report lists them): ``auto`` refuses such scenes,
and the FFRF reference with geometric stiffness, linear in the axial force, failed Newton
there (the 0.5 mm plate at the thesis spring, 0.33 P_E; 1 mm at 15000 N/m, 0.49 P_E).
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.physics import TWO_PI, Plate, n_values
from flex.base.thesis import THESIS_ANGLE_MAX_TIME_S
from flex.base.thesis import THESIS_COMPRESSION_M as THESIS_PRELOAD_M  # sec. 6.1
from flex.base.thesis import THESIS_SPRING_RATE_N_PER_M as THESIS_SPRING_N_PER_M  # Table 2
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, to_toml
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import FFRF
from flex.experiments.fitting import lawfit
from flex.experiments.fitting.lawfit import case_data
from flex.fidelity.criteria import (
    DELTA_T_DEFINITIONS,
    EULER_LOAD_LIMIT,
    MEASURES,
    deployment_times,
    error_measures,
    quasi_static_stress,
)
from flex.fidelity.predictor import predict_deflection

#: thesis Table 5: coupler thickness [m] of models 0-3
THESIS_MODELS = {"model0": 1e-3, "model1": 3e-3, "model2": 5e-3, "model3": 10e-3}
#: compressive coupler force / (spring rate x preload), measured on the thesis scene (the
#: spring mostly accelerates the slider); used only to leave out cases beyond the Euler load
#: limit before they run (at the thesis preload it gave 0.33, 0.41, 1.10, 1.37 where the
#: rigid twins measured 0.33, 0.49, 1.09, 1.62 P_E)
COMPRESSION_SHARE = 0.32
#: the FFRF reference of every fit and validation case: with geometric stiffness
REFERENCE = {"model": "ffrf", "geometric_stiffness": True}
#: preload of the fast cases: this fraction of the Euler load, estimated with
#: COMPRESSION_SHARE; fast springs load the coupler more (measured 1.7-2 x the estimate), so
#: this keeps P < 0.25 P_euler
FAST_EULER_RATIO = 0.1
CURVE_SAMPLES = 500


# ------------------------------------------------------------------------------------------
# scenes
# ------------------------------------------------------------------------------------------
def label(value: float, unit_scale: float) -> str:
    """``value * unit_scale`` to 3 digits with ``p`` for the point (case names)."""
    return f"{value * unit_scale:.3g}".replace(".", "p")


def mesh_size_m(thickness_m: float) -> float:
    """Netgen maxh [m] for a plate: 3 t within [2 mm, 5 mm] (see the module doc). The 5 mm
    cap: at 10 mm (one element across the 10 mm width) the 7 mm plate's midpoint marker
    read a spurious 55 um deflection where a 5 mm mesh gives 1.8 um, what the rigid run's
    loads predict (flex.fidelity.predictor)."""
    return float(min(max(3.0 * thickness_m, 2e-3), 5e-3))


def tuned(scene: Scene) -> Scene:
    """The scene with the sweep's mesh, time step and end time (a pure function of it).

    Deployment time estimate: the thesis half swing 0.0265 s at 1500 N/m scaled by
    sqrt(1500 / k) (a linear spring); end time 1.3 x that; step h = min(1e-4, T/40,
    estimate/400) with T = 2 pi / omega (Euler-Bernoulli, pinned-pinned).
    """
    coupler, drive = scene["coupler"], scene["drive"]
    omega = Plate.of(coupler).pinned_pinned_omega
    estimate = THESIS_ANGLE_MAX_TIME_S * math.sqrt(THESIS_SPRING_N_PER_M
                                                   / drive["spring_stiffness_N_per_m"])
    estimate *= max(1.0, drive["spring_preload_m"] / THESIS_PRELOAD_M) ** 0.25
    step = min(1e-4, TWO_PI / omega / 40.0, estimate / 400.0)
    step = float(f"{step:.2g}")
    end = float(f"{1.3 * estimate:.3g}")
    return derive_scene(scene, [f"coupler.mesh_size_m={mesh_size_m(coupler['thickness_m'])}",
                                f"simulation.step_s={step!r}",
                                f"simulation.end_time_s={end!r}"])


def _plate(scene: Scene, thickness_m: float, zeta: float, spring_N_per_m: float,
           preload_m: float) -> Scene:
    # the mesh with the thickness: every scene on the way is valid (tuned sets it again)
    return tuned(derive_scene(scene, [f"coupler.thickness_m={thickness_m!r}",
                                      f"coupler.mesh_size_m={mesh_size_m(thickness_m)!r}",
                                      f"coupler.damping_ratio={zeta!r}",
                                      f"drive.spring_stiffness_N_per_m={spring_N_per_m!r}",
                                      f"drive.spring_preload_m={preload_m!r}",
                                      "coupler.geometric_stiffness=true"]))


def _euler_N(scene: Scene, thickness_m: float) -> float:
    return replace(Plate.of(scene["coupler"]), thickness_m=thickness_m).euler_load_N


def estimated_euler_ratio(scene: Scene, thickness_m: float, spring_N_per_m: float,
                          preload_m: float) -> float:
    """The coupler's largest compression / its Euler load, estimated before the case runs:
    :data:`COMPRESSION_SHARE` x spring rate [N/m] x preload [m] over pi^2 E I / L^2."""
    return COMPRESSION_SHARE * spring_N_per_m * preload_m / _euler_N(scene, thickness_m)


def _grid(scene: Scene, damping_ratios: tuple[float, ...], thicknesses: tuple[float, ...],
          stiffness_grid: tuple[tuple[float, ...], tuple[float, ...]],
          fast: tuple[tuple[float, float], ...],
          preload_grid: tuple[tuple[float, ...], tuple[float, ...]]
          ) -> dict[str, tuple[float, float, float, float]]:
    """Every candidate fit case: name -> (thickness [m], damping ratio, spring rate [N/m],
    preload [m])."""
    out = {}
    for zeta in damping_ratios:
        z = f"z{round(zeta * 100)}"
        for t in thicknesses:
            out[f"thk_t{label(t, 1e3)}mm_{z}"] = (t, zeta, THESIS_SPRING_N_PER_M,
                                                  THESIS_PRELOAD_M)
        for t in stiffness_grid[0]:
            for k in stiffness_grid[1]:
                out[f"stf_t{label(t, 1e3)}mm_k{k:.0f}_{z}"] = (t, zeta, k, THESIS_PRELOAD_M)
        for t, k in fast:
            preload = min(THESIS_PRELOAD_M, round(FAST_EULER_RATIO * _euler_N(scene, t)
                                                  / (COMPRESSION_SHARE * k), 4))
            out[f"stf_t{label(t, 1e3)}mm_k{k:.0f}_{z}"] = (t, zeta, k, preload)
        for t in preload_grid[0]:
            for preload in preload_grid[1]:
                out[f"pre_t{label(t, 1e3)}mm_p{label(preload, 1e3)}mm_{z}"] = (
                    t, zeta, THESIS_SPRING_N_PER_M, preload)
    return out


def left_out_cases(scene: Scene, *grid: Any) -> dict[str, float]:
    """The candidates of :func:`fit_cases` (same arguments after ``scene``) it does not
    generate: name -> estimated compression / Euler load (:func:`estimated_euler_ratio`),
    beyond :data:`flex.fidelity.criteria.EULER_LOAD_LIMIT` (``auto`` refuses such scenes)."""
    out = {}
    for name, (t, _, k, preload) in _grid(scene, *grid).items():
        ratio = estimated_euler_ratio(scene, t, k, preload)
        if ratio > EULER_LOAD_LIMIT:
            out[name] = ratio
    return out


def fit_cases(scene: Scene, damping_ratios: tuple[float, ...], thicknesses: tuple[float, ...],
              stiffness_grid: tuple[tuple[float, ...], tuple[float, ...]],
              fast: tuple[tuple[float, float], ...],
              preload_grid: tuple[tuple[float, ...], tuple[float, ...]]) -> dict[str, Scene]:
    """The fit cases, per damping ratio: ``thk_*`` (each thickness [m], thesis spring),
    ``stf_*`` (thicknesses x spring rates [N/m] of ``stiffness_grid``, thesis preload; then
    the ``fast`` (thickness, rate) pairs with the preload of :data:`FAST_EULER_RATIO`),
    ``pre_*`` (thicknesses x preloads [m]); every FFRF twin with geometric stiffness. Those
    of :func:`left_out_cases` (estimated beyond the Euler load limit) are not generated."""
    grid = (damping_ratios, thicknesses, stiffness_grid, fast, preload_grid)
    skipped = left_out_cases(scene, *grid)
    return {name: _plate(scene, *values) for name, values in _grid(scene, *grid).items()
            if name not in skipped}


def validation_cases(scene: Scene, validation: dict[str, tuple[list[str], float]]
                     ) -> dict[str, Scene]:
    """``val_*`` scenes (name -> (overrides, tolerance)) with ``coupler.model = "auto"``."""
    out = {}
    for name, (changes, tolerance) in validation.items():
        case = tuned(derive_scene(scene, [*changes, 'coupler.model="auto"',
                                          f"fidelity.tolerance={tolerance!r}"]))
        out[name] = case
    return out


def family(name: str) -> str:
    """``thk``, ``stf``, ``pre`` or ``val`` from a case name."""
    return name.split("_", 1)[0]


# ------------------------------------------------------------------------------------------
# reductions (built or loaded once per worker)
# ------------------------------------------------------------------------------------------
def geometry_key(scene: Scene) -> tuple | None:
    """What a reduction depends on (None for scenes that need none)."""
    c = scene["coupler"]
    if c["model"] not in (FFRF, "auto"):
        return None
    return Plate.of(c), c["mesh_size_m"], c["modes"], c["mode_selection"]


@functools.lru_cache(maxsize=3)
def _reduction(key: tuple, cache_dir: Path | None) -> Any:
    from flex.bodies.reduction import build_reduction

    plate, mesh_size_m, modes, selection = key
    return build_reduction(plate, mesh_size_m, modes, cache_dir, mode_selection=selection)


def reduction_of(scene: Scene, cache_dir: Path | None = None) -> Any:
    """The scene's reduction: built (or loaded from the reduction cache folder ``cache_dir``;
    None: built in memory, no disk cache) once per worker."""
    return _reduction(geometry_key(scene), cache_dir)


def prepare_reduction(scene: Scene, *, cache_dir: Path | None = None) -> dict[str, Any]:
    """Sweep preparation: build (or find) the scene's reduction in the reduction cache folder
    ``cache_dir`` (where the cases then find it; None: in memory, this worker only)."""
    reduction = reduction_of(scene, cache_dir)
    if scene["coupler"]["geometric_stiffness"] and not reduction.from_cache:
        from flex.bodies.geometric_stiffness import geometric_stiffness

        # while the build's mesh is at hand, stored beside the reduction: the cases on other
        # workers load it instead of meshing the plate again (0.1 s against 1-2 s)
        geometric_stiffness(reduction)
    return {"key": reduction.key, "from_cache": reduction.from_cache,
            "build_time_s": reduction.build_time_s}


def full_scene(scene: Scene) -> Scene:
    """The validation reference: the scene's coupler as FFRF (:data:`REFERENCE`: with
    geometric stiffness) with the full model's modes."""
    return derive_scene(scene, {"coupler.model": REFERENCE["model"],
                                "coupler.geometric_stiffness": REFERENCE["geometric_stiffness"],
                                "coupler.modes": lawfit.FULL_MODES})


def full_geometry_key(scene: Scene) -> tuple | None:
    """Preparation key of a validation case: its full model's reduction."""
    return geometry_key(full_scene(scene))


def prepare_full_reduction(scene: Scene, *, cache_dir: Path | None = None) -> dict[str, Any]:
    """Validation preparation: the full model's reduction (auto builds its own if FFRF), in
    the reduction cache folder ``cache_dir`` (as :func:`prepare_reduction`)."""
    return prepare_reduction(full_scene(scene), cache_dir=cache_dir)


# ------------------------------------------------------------------------------------------
# one fit case and one validation case (run on a worker)
# ------------------------------------------------------------------------------------------
def _run_pair(scene: Scene, reduction: Any, cache_dir: Path | None
              ) -> tuple[dict, dict, dict[str, float], dict]:
    """Rigid twin (long enough to stop), then the FFRF run to just past delta_t_stop
    (``cache_dir``: the reduction cache folder of anything else they build)."""
    from flex.fidelity.simulation import simulate

    rigid_scene = derive_scene(scene, {"coupler.model": "rigid"})
    for _ in range(3):
        rigid = simulate(rigid_scene, "rigid", cache_dir=cache_dir)
        rigid_data = case_data(rigid)
        try:
            times = deployment_times(rigid_data["time"], rigid_data["crank/angle"],
                                     rigid_data["crank/angular_velocity"])
            break
        except ValueError:
            end = 2 * rigid_scene["simulation"]["end_time_s"]
            rigid_scene = derive_scene(rigid_scene, {"simulation.end_time_s": end})
    else:
        raise ValueError("no crank-angle maximum within 4 x the estimated deployment time")
    step = scene["simulation"]["step_s"]
    end = min(rigid_scene["simulation"]["end_time_s"],
              step * math.ceil(1.02 * times["stop"] / step + 2))
    ffrf = simulate(derive_scene(scene, {
        "coupler.model": REFERENCE["model"],
        "coupler.geometric_stiffness": REFERENCE["geometric_stiffness"],
        "simulation.end_time_s": end}), "ffrf", reduction, cache_dir=cache_dir)
    walls = {"rigid": rigid.counters["wall_time_s"], "ffrf": ffrf.counters["wall_time_s"],
             "ffrf_steps": ffrf.counters["steps"], "rigid_steps": rigid.counters["steps"]}
    return rigid_data, case_data(ffrf), times, walls


#: units and descriptions of the measures beyond flex.fidelity.criteria.MEASURES
_MEASURE_UNITS = {"deflection_abs_m": "m", "crank_angle_abs_rad": "rad",
                  "slider_position_abs_m": "m", "peak_stress_ffrf_Pa": "Pa",
                  "peak_stress_quasi_static_Pa": "Pa", "crank_swing_rad": "rad",
                  "slider_travel_m": "m", "stress_ratio": "1", "euler_load_ratio": "1"}
_MEASURE_NOTES = {"stress_ratio": "peak FFRF / quasi-static bending stress (dynamic "
                                  "amplification)",
                  "euler_load_ratio": "largest compressive force / Euler load pi^2 E I / L^2"}


def _case_parameters(scene: Scene, reduction: Any, omega: float, walls: dict
                     ) -> dict[str, Dataset]:
    coupler, drive = scene["coupler"], scene["drive"]
    return {
        "parameters/thickness": Dataset(coupler["thickness_m"], "m",
                                        "plate thickness (in-plane height)"),
        "parameters/length": Dataset(coupler["length_m"], "m", "coupler length L2"),
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


def _case_curves(scene: Scene, rigid: dict, ffrf: dict, stop_s: float) -> dict[str, Dataset]:
    """The deployment window's curves, downsampled to about :data:`CURVE_SAMPLES`."""
    coupler = scene["coupler"]
    count = int(np.sum(ffrf["time"] <= stop_s * (1 + 1e-12)))
    pick = slice(None, None, max(1, math.ceil(count / CURVE_SAMPLES)))
    window = slice(0, count)
    qs = quasi_static_stress(rigid["joints/B/force_on_coupler"][window],
                             rigid["joints/C/force_on_coupler"][window],
                             rigid["coupler/angle"][window], coupler["length_m"],
                             coupler["thickness_m"], coupler["width_m"])
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
    return {f"curves/{key}": Dataset(np.asarray(values)[window][pick], unit, text)
            for key, (values, unit, text) in curves.items()}


def _predictor_datasets(rigid: dict, coupler: dict, stop_s: float) -> dict[str, Dataset]:
    """The rigid model's deflection error predicted from the rigid twin's own loads
    (:func:`flex.fidelity.predictor.predict_deflection`), and the ramp-load-factor bound."""
    prediction = predict_deflection(rigid, coupler, "coupler", stop_s)
    length = coupler["length_m"]
    return {
        "predictor/deflection": Dataset(prediction.relative_error(length), "1",
                                        "predicted peak elastic deflection / L2 (the rigid "
                                        "twin's loads, first-mode oscillator)"),
        "predictor/load_factor_deflection": Dataset(
            prediction.load_factor_peak_m / length, "1",
            "quasi-static peak deflection x ramp load factor / L2"),
    }


def fit_case(name: str, scene: Scene, *, cache_dir: Path | None = None) -> CaseResult:
    """One fit case: FFRF and rigid twin, the error measures, n by every definition.

    Stores ``parameters/*``, ``delta_t/<definition>`` [s], ``n_physical/<definition>``,
    ``n_thesis/<definition>``, ``measures/<measure>`` (dimensionless) and absolute values,
    ``frequency/*`` and downsampled ``curves/*`` with units. ``cache_dir``: the reduction
    cache folder (None: built in memory, no disk cache).
    """
    coupler = scene["coupler"]
    reduction = reduction_of(scene, cache_dir)
    rigid, ffrf, times, walls = _run_pair(scene, reduction, cache_dir)
    plate = Plate.of(coupler)
    measures = error_measures(rigid, ffrf, plate, times["stop"])
    omega = plate.pinned_pinned_omega
    out = _case_parameters(scene, reduction, omega, walls)
    for definition, delta_t in times.items():
        n = n_values(delta_t, omega)
        out[f"delta_t/{definition}"] = Dataset(delta_t, "s", DELTA_T_DEFINITIONS[definition])
        out[f"n_physical/{definition}"] = Dataset(n["physical"], "1",
                                                  "delta_t / T, T = 2 pi / omega")
        out[f"n_thesis/{definition}"] = Dataset(n["thesis"], "1",
                                                "delta_t * omega (thesis: T = 1 / omega)")
    for key, value in measures.items():
        out[f"measures/{key}"] = Dataset(value, _MEASURE_UNITS.get(key, "1"), MEASURES.get(
            key, _MEASURE_NOTES.get(key, key.replace("_", " "))))
    out.update(_predictor_datasets(rigid, coupler, times["stop"]))
    out.update(_case_curves(scene, rigid, ffrf, times["stop"]))
    counters = {"wall_time_s": walls["ffrf"] + walls["rigid"], "steps": walls["ffrf_steps"]}
    return CaseResult(name, to_toml(scene), out, counters=counters,
                      attrs={"reduction_key": reduction.key,
                             "reduction_cold_build_time_s": reduction.cold_build_time_s})


#: bumped when what a fit case stores changes (the sweep reruns older case files): 2 adds
#: the load-based predictor, 3 the FFRF twin with geometric stiffness (also in the scene;
#: the mesh rule is in the scene, so the scene hash follows it)
fit_case.case_version = 3


def validation_case(name: str, scene: Scene, criterion_toml: str | None = None, *,
                    cache_dir: Path | None = None) -> CaseResult:
    """``auto`` against the full FFRF model on a scene outside the fit.

    The ``auto`` run goes through :func:`flex.fidelity.simulation.simulate` with the law just fitted
    (``criterion_toml``, passed as an argument; None: the installed one). Stores the
    decision, the errors of the auto run against the full FFRF run and both wall times.
    ``cache_dir``: the reduction cache folder (None: built in memory, no disk cache).
    """
    from flex.fidelity.simulation import simulate

    start = time.perf_counter()
    auto = lawfit.simulate_with_law(scene, "auto", "coupler", criterion_toml,
                                    "kfit (this run's fit)", raising=True,
                                    cache_dir=cache_dir)
    auto_total = time.perf_counter() - start
    reference = full_scene(scene)
    start = time.perf_counter()
    full_reduction = reduction_of(reference, cache_dir)
    full_reduction_s = time.perf_counter() - start
    full = simulate(reference, "full", full_reduction, cache_dir=cache_dir)
    check = lawfit.against_full(name, "coupler", scene["fidelity"]["tolerance"],
                                case_data(auto), case_data(full), scene["coupler"]["length_m"],
                                auto.attrs)
    errors = dict(check.errors)
    delta_t_s = errors.pop("delta_t")
    out = {f"errors/{k}": Dataset(v, "1", f"auto against full FFRF: {MEASURES[k]}")
           for k, v in errors.items()}
    out.update({
        "tolerance": Dataset(check.tolerance, "1", "requested [fidelity] tolerance"),
        "within_tolerance": Dataset(int(check.ok), "1", "1 if the governing error <= tolerance"),
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


#: 2: auto decides the coupler by the load-based prediction, 3: the full FFRF reference
#: with geometric stiffness (older files are rerun)
validation_case.case_version = 3


# ------------------------------------------------------------------------------------------
# the pipeline on the sweep engine
# ------------------------------------------------------------------------------------------
def sweep_phases(cache_dir: Path | None = None) -> dict[str, lawfit.SweepPhase]:
    """The fit and validation phases on the sweep engine. Their case functions and
    preparations get the reduction cache folder ``cache_dir`` as an argument (so do the
    workers; None: each worker builds in memory); it is not part of a case's identity
    (:func:`flex.sweep.case_hash`), so a moved cache resumes the same cases."""
    where = {"cache_dir": cache_dir}
    fit = functools.partial(fit_case, **where)
    return {
        "fit": lawfit.SweepPhase(lambda _: fit, functools.partial(prepare_reduction, **where),
                                 geometry_key, "fit cases"),
        "validation": lawfit.SweepPhase(
            lambda text: functools.partial(validation_case, criterion_toml=text, **where),
            functools.partial(prepare_full_reduction, **where), full_geometry_key,
            "validation"),
    }

