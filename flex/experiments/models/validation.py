"""Validation against the IVP test set's flexible slider-crank ("crank"): the ``validation``
study's scenes, independent two-mode runs, comparisons, report and figures.

The benchmark (:mod:`flex.experiments.models.ivp_crank`: source, parameters, published values) is a
steel rod 0.3 m x 8 x 8 mm on a 0.15 m crank turned at 150 rad/s, slider 0.075552 kg, no
gravity, undamped. Three kinds of runs meet here:

- the published reference values at t = 0.1 s (crank.f SOLN), from the published initial
  state, which starts the rod "close to smooth motion" (deflected, with the velocities of
  the quasi-static response);
- :func:`flex.experiments.models.ivp_crank.solve`, an independent implementation of the published
  two-mode model (same matrices, derived here from the shape functions): it must reproduce
  the published values, and it runs the variants that isolate each modelling choice;
- flex's Exudyn runs: a rigid rod (against the closed form,
  :func:`flex.base.kinematics.constant_speed_motion`), the FFRF rod (a meshed 3-D steel
  bar, Craig-Bampton modes) under mode, mesh and step refinement, and the nonlinear FE rod.

flex starts every run on the rigid motion, undeformed (the test set's second initial state,
INIT2): it has no scene key for an initial deflection. So flex is compared with the two-mode
model started there too, against two references: the beam with consistent axial mass and
consistent geometric stiffening (:data:`BEST_BEAM`) and flex's nonlinear FE rod (3-D solid,
Green-Lagrange strain), which agree in-plane; the FE rod's slider position is not a
reference here (its midpoint drifts out of the mechanism plane, docs/validation.md).

flex's default FFRF rod against the beam (report section 4, :func:`_ffrf_explained`): its
floating frame is the chord, and it carries the geometric stiffness of its axial force on
its bending coordinates; the two-mode model with the same physics (``lateral_only``: the
stiffening on the bending coordinates alone, no foreshortening pull on the axial ones) and
the linear FFRF rod say what remains and what the stiffness does. Why flex left the frame
on the B face (its old default): a rod linear elastic in a frame tangent at B gets the axial
force's geometric stiffness reversed and doubled (:func:`first_mode_geometric_stiffness_per_N`,
the two-mode models ``tangent_frame``; :data:`EXPLAINED`).
Units: m, s, rad, Hz; deflections and positions in m (reports in um).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.caseloop import run_each
from flex.base.kinematics import constant_speed_motion
from flex.base.physics import euler_buckling_load_N, pinned_pinned_omega
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, derived_scenes
from flex.data.tables import table_datasets
from flex.experiments.models import ivp_crank
from flex.experiments.models.ivp_crank import (
    PUBLISHED_AT_0P1S,
    PUBLISHED_PI,
    PUBLISHED_TIME_S,
    CrankBenchmark,
    CrankSolution,
)

BENCH = CrankBenchmark()
#: the published components compared, index into PUBLISHED_AT_0P1S, and unit
COMPONENTS = (("phi2", 1, "rad"), ("x3", 2, "m"), ("q1", 3, "m"), ("q2", 4, "m"),
              ("q3", 5, "m"), ("q4", 6, "m"), ("phi2_rate", 8, "rad/s"),
              ("x3_rate", 9, "m/s"), ("q1_rate", 10, "m/s"), ("q2_rate", 11, "m/s"))
#: stored sample interval of every run [s]
OUTPUT_STEP_S = 1e-4


def benchmark_overrides(bench: CrankBenchmark = BENCH) -> list[str]:
    """The benchmark as flex scene keys: constant crank speed from angle 0, a steel plate
    rod (in-plane height ``thickness_m``, out-of-plane ``width_m``), the slider mass, 0.1 s.
    Not expressible in a scene, and irrelevant here: the crank's mass and inertia (its speed
    is prescribed; set from M1, J1 anyway) and the rod's initial deflection (flex starts
    undeformed on the rigid motion)."""
    crank_inertia_about_centre = (bench.crank_inertia_about_A_kgm2
                                  - bench.crank_mass_kg * (bench.crank_length_m / 2) ** 2)
    return [f"crank.length_m={bench.crank_length_m!r}", "crank.initial_angle_deg=0.0",
            f"crank.mass_kg={bench.crank_mass_kg!r}",
            f"crank.inertia_kgm2={crank_inertia_about_centre!r}",
            f"coupler.length_m={bench.rod_length_m!r}", 'coupler.geometry="plate"',
            f"coupler.thickness_m={bench.rod_height_m!r}",
            f"coupler.width_m={bench.rod_width_m!r}",
            f"coupler.youngs_modulus_Pa={bench.youngs_modulus_Pa!r}",
            f"coupler.density_kg_per_m3={bench.density_kg_per_m3!r}",
            f"coupler.poisson_ratio={bench.poisson_ratio!r}", "coupler.damping_ratio=0.0",
            f"slider.mass_kg={bench.slider_mass_kg!r}", "slider.offset_m=0.0",
            'drive.kind="constant_speed"',
            f"drive.crank_speed_rad_per_s={bench.crank_speed_rad_per_s!r}",
            f"simulation.end_time_s={PUBLISHED_TIME_S!r}",
            f"simulation.output_step_s={OUTPUT_STEP_S!r}", "simulation.error_estimate=false"]


def flex_cases(scene: Scene, runs: dict[str, tuple[str, float, int, float, bool]]
               ) -> dict[str, Scene]:
    """One scene per flex run: name -> (coupler model, mesh size [m], modes, step [s],
    ``coupler.geometric_stiffness``)."""
    return derived_scenes(scene, {
        name: [f'coupler.model="{model}"', f"coupler.mesh_size_m={mesh!r}",
               f"coupler.modes={modes}", f"simulation.step_s={step!r}",
               f"coupler.geometric_stiffness={str(geometric).lower()}"]
        for name, (model, mesh, modes, step, geometric) in runs.items()})


#: the two-mode runs: name -> (lateral modes, axial bubbles, axial mass factor, geometric
#: stiffening, initial state, pi of the stiffness) -- the published model, then one change
#: at a time (``mass_fixed``: axial mass block / 15; ``cross``: the published nonlinear term
#: alone; ``locked``: consistent stiffening on the published axial element; ``stiffened``:
#: consistent stiffening with 4 axial bubbles; ``lateral_only``: the stiffening force on
#: the bending coordinates only, no foreshortening pull on the axial ones; ``tangent_frame``:
#: the strain of a rod linear elastic in a frame tangent at B, as flex's FFRF rod;
#: ``tangent_frame_geometric``: that plus the geometric stiffness in that frame, as flex's FFRF
#: rod with ``coupler.geometric_stiffness``, :mod:`flex.experiments.models.ivp_crank`)
TWO_MODE_RUNS: dict[str, tuple[int, int, float, str, str, float]] = {
    "published": (2, 0, 15.0, "none", "published", PUBLISHED_PI),
    "published_mass_fixed": (2, 0, 1.0, "none", "published", math.pi),
    "published_cross": (2, 0, 15.0, "published", "published", PUBLISHED_PI),
    "published_stiffened": (2, 4, 1.0, "consistent", "published", math.pi),
    "rigid_start": (2, 0, 15.0, "none", "rigid", PUBLISHED_PI),
    "rigid_start_mass_fixed": (2, 0, 1.0, "none", "rigid", math.pi),
    "rigid_start_8_modes": (8, 0, 1.0, "none", "rigid", math.pi),
    "rigid_start_cross": (2, 0, 1.0, "published", "rigid", math.pi),
    "rigid_start_locked": (2, 0, 1.0, "consistent", "rigid", math.pi),
    "rigid_start_stiffened": (2, 4, 1.0, "consistent", "rigid", math.pi),
    "rigid_start_lateral_only": (2, 0, 1.0, "lateral_only", "rigid", math.pi),
    "rigid_start_tangent_frame": (2, 4, 1.0, "tangent_frame", "rigid", math.pi),
    "rigid_start_tangent_frame_geometric": (2, 4, 1.0, "tangent_frame_geometric", "rigid",
                                            math.pi),
}
#: the best beam: consistent axial mass, consistent geometric stiffening, no locking
BEST_BEAM = "two-mode rigid_start_stiffened"
#: section 4, flex's default FFRF rod against the beam: the runs compared (flex's default FFRF
#: rod and the linear one, the two-mode models with the B-frame strain, the linear and the
#: stiffening-on-the-bending-only two-mode models)
FFRF_DEFAULT, FFRF_LINEAR = "ffrf_h1e-5", "ffrf_linear_h1e-5"
TANGENT_FRAME = "two-mode rigid_start_tangent_frame"
TANGENT_GEOMETRIC = "two-mode rigid_start_tangent_frame_geometric"
LATERAL_ONLY = "two-mode rigid_start_lateral_only"
EXPLAINED = ("two-mode rigid_start_mass_fixed", BEST_BEAM, LATERAL_ONLY, FFRF_DEFAULT,
             FFRF_LINEAR, TANGENT_FRAME, TANGENT_GEOMETRIC)
#: window of the early / late comparison in section 4 [s]
WINDOW_S = 0.01


def two_mode_runs(runs: dict[str, tuple[int, int, float, str, str, float]] | None = None,
                  rtol: float = 1e-10,
                  progress: Callable[[str, int, int], None] | None = None,
                  executor: Any = None) -> dict[str, CrankSolution]:
    """The independent model's runs (:data:`TWO_MODE_RUNS` by default), 5-140 s each (axial
    bubbles make the explicit integration stiff: ~0.9 M evaluations); ``progress(name, done,
    total)`` as :func:`flex.base.caseloop.run_each` reports; on ``executor`` (one of
    :mod:`flex.sweep`'s) in parallel."""
    def told(name: str, done: int, total: int) -> None:
        if progress:
            progress(f"two-mode model: {name}", done, total)

    return run_each(dict(runs or TWO_MODE_RUNS), functools.partial(_two_mode_run, rtol=rtol),
                    told, executor=executor)


def _two_mode_run(name: str, run: tuple[int, int, float, str, str, float], rtol: float
                  ) -> CrankSolution:
    modes, bubbles, factor, stiffening, initial, pi_value = run
    return ivp_crank.solve(BENCH, modes, factor, stiffening, initial,
                           output_step_s=OUTPUT_STEP_S, rtol=rtol, atol=rtol * 1e-3,
                           pi_value=pi_value, axial_bubbles=bubbles)


def dominant_frequency_hz(time_s: np.ndarray, signal: np.ndarray,
                          band_hz: tuple[float, float] = (100.0, 1000.0)) -> float:
    """Frequency [Hz] of the largest spectral peak of ``signal`` within ``band_hz``
    (Hann window, 64x zero padding, parabolic interpolation of the peak)."""
    step = float(time_s[1] - time_s[0])
    detrended = signal - np.polyval(np.polyfit(time_s, signal, 1), time_s)
    padded = 64 * detrended.size
    spectrum = np.abs(np.fft.rfft(detrended * np.hanning(detrended.size), padded))
    freqs = np.fft.rfftfreq(padded, step)
    inside = np.flatnonzero((freqs >= band_hz[0]) & (freqs <= band_hz[1]))
    i = inside[np.argmax(spectrum[inside])]
    a, b, c = np.log(spectrum[i - 1:i + 2])
    return float(freqs[i] + 0.5 * (a - c) / (a - 2 * b + c) * (freqs[1] - freqs[0]))


def _curves(case: CaseResult | CrankSolution) -> dict[str, np.ndarray]:
    """Time, midpoint deflection, slider position and chord change of a run."""
    if isinstance(case, CrankSolution):
        return {"time": case.time_s, "deflection": case.midpoint_deflection_m,
                "slider": case.slider_position_m, "chord": case.chord_change_m}
    data = case.datasets
    return {"time": data["time"].data, "deflection": data["coupler/midpoint_deflection"].data,
            "slider": data["slider/position"].data,
            "chord": (data["coupler/chord_change"].data if "coupler/chord_change" in data
                      else np.zeros_like(data["time"].data))}


def _against(curves: dict[str, np.ndarray], reference: dict[str, np.ndarray]
             ) -> dict[str, float]:
    """Deflection and slider differences from ``reference`` (same time grid): RMS over the
    run relative to the reference's largest |deflection|, and the largest |slider
    difference| [m]."""
    peak = np.abs(reference["deflection"]).max()
    return {"deflection_rms_rel": float(np.sqrt(np.mean(
                (curves["deflection"] - reference["deflection"]) ** 2)) / peak),
            "slider_max_diff_m": float(np.abs(curves["slider"] - reference["slider"]).max())}


def analyse(scene: Scene, results: dict[str, CaseResult], solutions: dict[str, CrankSolution],
            reference: str) -> tuple[dict[str, Dataset], str]:
    """The study's datasets and report: the rigid limit, the published values against the
    independent model and one change at a time, every run from the rigid start at t = 0.1 s
    and over time against :data:`BEST_BEAM` and ``reference`` (a flex case, the nonlinear FE
    rod), and why flex's FFRF rod differs (:data:`EXPLAINED`; skipped if one is missing)."""
    lines = ["validation: the IVP test set's flexible slider-crank (Simeon; Mazzia & "
             "Magherini, Test Set for IVP Solvers, Bari: problem crank, crank.f)"]
    datasets: dict[str, Dataset] = {}
    for part_lines, part_datasets in (_rigid_limit(results), _published(solutions),
                                      _runs(results, solutions, reference),
                                      _ffrf_explained(results, solutions, reference)):
        lines += part_lines
        datasets.update(part_datasets)
    return datasets, "\n".join(lines)


def _rigid_limit(results: dict[str, CaseResult]) -> tuple[list[str], dict[str, Dataset]]:
    """Section 1: flex's rigid rod at t = 0.1 s against the closed form."""
    lines: list[str] = []
    datasets: dict[str, Dataset] = {}
    # 1. rigid limit
    rigid = results["rigid"].datasets
    time = rigid["time"].data
    _, exact = constant_speed_motion(BENCH.crank_length_m, BENCH.rod_length_m, 0.0,
                                     BENCH.crank_speed_rad_per_s, time)
    position_error = rigid["slider/position"].data - exact.slider_position_m
    velocity_error = rigid["slider/velocity"].data - exact.slider_velocity_m_per_s
    lines += ["", "1. Rigid limit at t = 0.1 s (phi1 = 150 t = 15 rad) against the closed form",
              f"   slider x: flex {rigid['slider/position'].data[-1]:.12f} m, closed form "
              f"{exact.slider_position_m[-1]:.12f} m (diff {position_error[-1]:.2e} m; "
              f"max over the run {np.abs(position_error).max():.2e} m)",
              f"   slider v: flex {rigid['slider/velocity'].data[-1]:.9f} m/s, closed form "
              f"{exact.slider_velocity_m_per_s[-1]:.9f} m/s (max diff "
              f"{np.abs(velocity_error).max():.2e} m/s)",
              f"   rod angle: closed form {exact.coupler_angle_rad[-1]:.10f} rad; published "
              f"(flexible) {PUBLISHED_AT_0P1S[1]:.10f} rad (diff "
              f"{PUBLISHED_AT_0P1S[1] - exact.coupler_angle_rad[-1]:.2e} rad)",
              f"   published flexible x3 - rigid x3 = "
              f"{(PUBLISHED_AT_0P1S[2] - exact.slider_position_m[-1]) * 1e6:.3f} um"]
    datasets.update({
        "rigid_limit/slider_position_error": Dataset(position_error, "m", "flex - closed form"),
        "rigid_limit/slider_velocity_error": Dataset(velocity_error, "m/s",
                                                     "flex - closed form"),
        "rigid_limit/closed_form_slider_position": Dataset(exact.slider_position_m, "m",
                                                           "closed form, phi1 = 150 t")})
    return lines, datasets


def _published(solutions: dict[str, CrankSolution]) -> tuple[list[str], dict[str, Dataset]]:
    """Section 2: the published values against the independent two-mode model, and one
    change at a time from the published model."""
    lines: list[str] = []
    datasets: dict[str, Dataset] = {}
    # 2. published values against the independent implementation
    published = solutions["published"].state[-1]
    index = [i for _, i, _ in COMPONENTS]
    relative = np.abs(published[index] - PUBLISHED_AT_0P1S[index]) / np.abs(
        PUBLISHED_AT_0P1S[index])
    lines += ["", "2. Published reference at t = 0.1 s (crank.f SOLN) against flex's "
              "independent implementation of the two-mode model (scipy DOP853, rtol 1e-10)",
              f"   {'component':10s} {'published':>16s} {'independent':>16s} {'rel. diff':>9s}"]
    lines += [f"   {name:10s} {PUBLISHED_AT_0P1S[i]:16.9e} {published[i]:16.9e} {r:9.1e}"
              for (name, i, _), r in zip(COMPONENTS, relative, strict=True)]
    datasets.update({
        "published/component": Dataset(np.array([c[0] for c in COMPONENTS], dtype=object),
                                       "1", "crank.f solution component"),
        "published/value": Dataset(PUBLISHED_AT_0P1S[index], "SI (see component)",
                                   "crank.f SOLN at t = 0.1 s"),
        "published/independent": Dataset(published[index], "SI (see component)",
                                         "flex.experiments.models.ivp_crank, published settings"),
        "published/relative_difference": Dataset(relative, "1", "|independent - published| "
                                                 "/ |published|")})
    consistent, published_mass = (first_axial_frequency_hz(f) for f in (1.0, 15.0))
    lines.append(f"   first axial mode (rod pinned at B, slider at C): {consistent:.0f} Hz with "
                 f"the consistent axial mass, {published_mass:.0f} Hz with the published one")
    lines.append("   one change at a time from the published model, same published start:")
    for name, label in (("published_mass_fixed", "axial mass block / 15 (consistent mass)"),
                        ("published_cross", "published nonlinear term (IPAR(1) = 1)"),
                        ("published_stiffened", "consistent mass, consistent stiffening")):
        state = solutions[name].state[-1]
        lines.append(f"   {label:42s} q1 = {state[3] * 1e6:8.3f} um "
                     f"({(state[3] / PUBLISHED_AT_0P1S[3] - 1) * 100:+6.2f} %), x3 - published "
                     f"= {(state[2] - PUBLISHED_AT_0P1S[2]) * 1e6:+.3f} um")
    return lines, datasets


def first_axial_frequency_hz(axial_mass_factor: float, bench: CrankBenchmark = BENCH) -> float:
    """First axial eigenfrequency [Hz] of the published quadratic axial element, pinned at B,
    with the slider's mass at C, its mass block times ``axial_mass_factor`` (15: as
    published, 1: consistent)."""
    rod = ivp_crank.rod_matrices(bench, 2, axial_mass_factor=axial_mass_factor)
    mass, stiffness = rod.mass[2:, 2:].copy(), rod.stiffness[2:, 2:]
    mass[1, 1] += bench.slider_mass_kg
    omega_squared = np.linalg.eigvals(np.linalg.solve(mass, stiffness)).real.min()
    return float(np.sqrt(omega_squared) / (2 * math.pi))


def _axial_load_lines(buckling_N: float) -> list[str]:
    """The slider's inertia force over a crank turn (rigid closed form) and the change of the
    first bending frequency it makes, ``sqrt(1 + P / P_Euler)``, tension positive."""
    turn = np.linspace(0.0, 2 * math.pi / BENCH.crank_speed_rad_per_s, 2001)
    _, exact = constant_speed_motion(BENCH.crank_length_m, BENCH.rod_length_m, 0.0,
                                     BENCH.crank_speed_rad_per_s, turn)
    force = -BENCH.slider_mass_kg * exact.slider_acceleration_m_per_s2
    shift = [(math.sqrt(1 + f / buckling_N) - 1) * 100 for f in (force.min(), force.max())]
    return [f"   slider inertia force -m3 x3'' (rigid, tension +): {force.min():+.0f} .. "
            f"{force.max():+.0f} N; first bending frequency x sqrt(1 + P/P_Euler): "
            f"{shift[0]:+.1f} .. {shift[1]:+.1f} % (the rod's own inertia adds to it)"]


#: section 3, one change at a time from the linear model from the rigid start: label, run
RIGID_START_CHANGES = (("published axial mass (x15) and pi", "two-mode rigid_start"),
                       ("8 lateral modes", "two-mode rigid_start_8_modes"),
                       ("consistent stiffening (beam)", BEST_BEAM))


def _change_lines(runs: dict[str, Any], published: CrankSolution) -> list[str]:
    """Section 3: largest deflections, and one change at a time from the linear two-mode
    model with consistent mass (RMS deflection difference over its peak, x3 at 0.1 s)."""
    needed = ["two-mode rigid_start_mass_fixed", *(name for _, name in RIGID_START_CHANGES)]
    if not all(name in runs for name in needed):
        return []
    linear = _curves(runs["two-mode rigid_start_mass_fixed"])
    lines = [f"   largest |midpoint deflection|: two-mode from the published start (close to "
             f"smooth motion) {np.abs(published.midpoint_deflection_m).max() * 1e6:.0f} um; "
             f"beam from the rigid start "
             f"{np.abs(_curves(runs[BEST_BEAM])['deflection']).max() * 1e6:.0f} um",
             "   one change at a time from 'two-mode rigid_start_mass_fixed' (linear, "
             "consistent mass), same rigid start:"]
    for label, name in RIGID_START_CHANGES:
        curves = _curves(runs[name])
        rms = _against(curves, linear)["deflection_rms_rel"]
        lines.append(f"   {label:42s} RMS deflection difference {rms:.3f}, x3(0.1) "
                     f"{(curves['slider'][-1] - linear['slider'][-1]) * 1e6:+.2f} um")
    return lines


def _runs(results: dict[str, CaseResult], solutions: dict[str, CrankSolution],
          reference: str) -> tuple[list[str], dict[str, Dataset]]:
    """Section 3: every run from the rigid start against the best beam and ``reference``."""
    lines: list[str] = []
    datasets: dict[str, Dataset] = {}
    # 3. every run from the rigid start, against two references
    height = BENCH.rod_height_m
    omega_eb = pinned_pinned_omega(BENCH.rod_length_m, height, BENCH.youngs_modulus_Pa,
                                   BENCH.density_kg_per_m3)
    buckling = euler_buckling_load_N(BENCH.rod_length_m, height, BENCH.rod_width_m,
                                     BENCH.youngs_modulus_Pa)
    runs: dict[str, Any] = {f"two-mode {k}": v for k, v in solutions.items()
                            if k.startswith("rigid_start")}
    runs.update({k: v for k, v in results.items() if v.status == "ok" and k != "rigid"})
    references = {"beam": _curves(runs[BEST_BEAM]), "fe": _curves(results[reference])}
    lines += _runs_header(reference, omega_eb, buckling)
    rows = []
    for name, run in runs.items():
        curves = _curves(run)
        beam, fe = _against(curves, references["beam"]), _against(curves, references["fe"])
        out_of_plane = (float(np.abs(run.datasets["coupler/midpoint_out_of_plane"].data).max())
                        if isinstance(run, CaseResult)
                        and "coupler/midpoint_out_of_plane" in run.datasets else 0.0)
        wall = (run.counters.get("wall_time_s", float("nan")) if isinstance(run, CaseResult)
                else run.wall_time_s)
        row = (name, curves["deflection"][-1], curves["slider"][-1],
               dominant_frequency_hz(curves["time"], curves["deflection"]),
               beam["deflection_rms_rel"], fe["deflection_rms_rel"], beam["slider_max_diff_m"],
               fe["slider_max_diff_m"], out_of_plane, wall)
        rows.append(row)
        lines.append(f"   {name:44s} {row[1] * 1e6:10.2f} {row[2]:12.9f} {row[3]:6.1f} "
                     f"{row[4]:8.3f} {row[5]:6.3f} {row[6] * 1e6:8.2f} {row[7] * 1e6:7.2f} "
                     f"{row[8] * 1e6:6.0f} {row[9]:5.1f}")
        key = name.replace(" ", "_")
        datasets[f"runs/{key}/midpoint_deflection"] = Dataset(curves["deflection"], "m",
                                                              f"{name}: v(L2/2) from chord B-C")
        datasets[f"runs/{key}/slider_position"] = Dataset(curves["slider"], "m", name)
        datasets[f"runs/{key}/chord_change"] = Dataset(curves["chord"], "m", name)
    lines += _change_lines(runs, solutions["published"])
    datasets["runs/time"] = Dataset(references["fe"]["time"], "s", "sample times of every run")
    datasets.update(_runs_table(rows, reference))
    datasets["published/two_mode_published_start/midpoint_deflection"] = Dataset(
        solutions["published"].midpoint_deflection_m, "m", "independent two-mode model from "
        "the published initial state, published settings")
    datasets["published/euler_bernoulli_frequency"] = Dataset(
        omega_eb / (2 * math.pi), "Hz", "pinned-pinned first bending, 8 mm steel, 0.3 m")
    return lines, datasets


def _runs_header(reference: str, omega_eb: float, buckling: float) -> list[str]:
    """Section 3's heading: its references, the rod's bending frequency and buckling load
    (``omega_eb`` rad/s, ``buckling`` N), the crank harmonics, the axial loads, the columns."""
    return ["", "3. From the rigid start (undeformed, as flex starts), t = 0.1 s and over "
            "0-0.1 s, against two references:",
            f"   beam = '{BEST_BEAM}' (consistent mass and stiffening, 4 axial bubbles); "
            f"fe = '{reference}' (nonlinear FE rod)",
            f"   Euler-Bernoulli pinned-pinned first bending: {omega_eb / (2 * math.pi):.1f} "
            f"Hz; Euler buckling load {buckling:.0f} N; crank harmonics 8 and 9: "
            f"{8 * BENCH.crank_speed_rad_per_s / (2 * math.pi):.1f}, "
            f"{9 * BENCH.crank_speed_rad_per_s / (2 * math.pi):.1f} Hz",
            *_axial_load_lines(buckling),
            f"   {'run':44s} {'q_mid(0.1)':>10s} {'x3(0.1)':>12s} {'peak':>6s} {'rms/beam':>8s} "
            f"{'rms/fe':>6s} {'dx3/beam':>8s} {'dx3/fe':>7s} {'oop':>6s} {'wall':>5s}",
            f"   {'':44s} {'[um]':>10s} {'[m]':>12s} {'[Hz]':>6s} {'[1]':>8s} {'[1]':>6s} "
            f"{'[um]':>8s} {'[um]':>7s} {'[um]':>6s} {'[s]':>5s}"]


def _runs_table(rows: list[tuple], reference: str) -> dict[str, Dataset]:
    """Section 3's table, one dataset per column (``table/*``), one row per run."""
    datasets = {"table/run": Dataset(np.array([r[0] for r in rows], dtype=object), "1", "run")}
    for column, (name, unit, what) in enumerate((
            ("deflection_at_0p1s", "m", "midpoint deflection at 0.1 s"),
            ("slider_at_0p1s", "m", "slider position at 0.1 s"),
            ("spectral_peak", "Hz", "largest spectral peak of the deflection in 100-1000 Hz "
             "(free vibration mixed with crank harmonics 8, 9)"),
            ("deflection_rms_rel_beam", "1", f"RMS deflection difference from {BEST_BEAM} / "
             "its peak |deflection|"),
            ("deflection_rms_rel_fe", "1", f"RMS deflection difference from {reference} / its "
             "peak |deflection|"),
            ("slider_max_diff_beam", "m", f"largest |slider difference| from {BEST_BEAM}"),
            ("slider_max_diff_fe", "m", f"largest |slider difference| from {reference}"),
            ("out_of_plane_max", "m", "largest midpoint displacement out of the mechanism "
             "plane (nonlinear FE)"),
            ("wall_time", "s", "wall time")), start=1):
        datasets[f"table/{name}"] = Dataset(np.array([r[column] for r in rows]), unit, what)
    return datasets


def first_mode_geometric_stiffness_per_N(bench: CrankBenchmark = BENCH,
                                         amplitude_m: float = 1e-7) -> tuple[float, float]:
    """Generalized stiffness [1/m] that 1 N of uniform axial tension adds to the first
    pinned-pinned bending mode ``v = a sin(pi x / L)``: with the true strain of the axis
    ``u' + v'^2 / 2`` (``pi^2 / (2 L)``) and with the strain of a rod linear elastic in a
    frame tangent to it at B, flex's FFRF rod (``-pi^2 / L``,
    :func:`flex.experiments.models.ivp_crank.
    tangent_frame_membrane_force`). By finite difference at ``amplitude_m`` [m]."""
    rod = ivp_crank.rod_matrices(bench, 2)
    strain = 1e-6
    length = bench.rod_length_m
    q = np.array([amplitude_m, 0.0, strain * length / 2, strain * length])  # u = strain x
    tension_N = bench.youngs_modulus_Pa * bench.area_m2 * strain
    true = (rod.stiffening @ q @ q)[0] / amplitude_m / tension_N
    tangent = ivp_crank.tangent_frame_membrane_force(bench, rod, q)[0] / amplitude_m / tension_N
    return float(true), float(tangent)


def windowed_rms(curves: dict[str, np.ndarray], reference: dict[str, np.ndarray],
                 window_s: float = WINDOW_S) -> tuple[float, float]:
    """RMS deflection difference from ``reference`` over the first and the last ``window_s``
    [s] of the run, relative to the reference's largest |deflection| over the whole run."""
    time, peak = reference["time"], np.abs(reference["deflection"]).max()
    difference = curves["deflection"] - reference["deflection"]
    first, last = time <= time[0] + window_s, time >= time[-1] - window_s
    return (float(np.sqrt(np.mean(difference[first] ** 2)) / peak),
            float(np.sqrt(np.mean(difference[last] ** 2)) / peak))


def _explained_runs(results: dict[str, CaseResult], solutions: dict[str, CrankSolution]
                    ) -> dict[str, Any] | None:
    """The runs of :data:`EXPLAINED` by name, or None if one is missing or failed."""
    runs: dict[str, Any] = {}
    for name in EXPLAINED:
        if name.startswith("two-mode "):
            runs[name] = solutions.get(name.removeprefix("two-mode "))
        elif name in results and results[name].status == "ok":
            runs[name] = results[name]
    complete = len(runs) == len(EXPLAINED) and all(run is not None for run in runs.values())
    return runs if complete else None


def _ffrf_explained(results: dict[str, CaseResult], solutions: dict[str, CrankSolution],
                    reference: str) -> tuple[list[str], dict[str, Dataset]]:
    """Section 4: why flex's FFRF rod differs from the beam models, measured."""
    runs = _explained_runs(results, solutions)
    if runs is None:
        return ["", f"4. (skipped: needs the runs {', '.join(EXPLAINED)})"], {}
    true, tangent = first_mode_geometric_stiffness_per_N()
    length = BENCH.rod_length_m
    lines = ["", "4. flex's default FFRF rod (floating frame on the chord, geometric stiffness of "
             "its axial force) against the beam",
             "   first-mode geometric stiffness per N of axial tension [1/m]: true strain "
             f"u' + v'^2/2: {true:+.3f} (pi^2/2L = {math.pi**2 / (2 * length):.3f}); a rod "
             "linear elastic in a frame tangent at B (flex's old default, the B face), "
             f"u' + theta v' - theta^2/2 with theta = v'(0): {tangent:+.3f} (-pi^2/L = "
             f"{-math.pi**2 / length:.3f}); ratio {tangent / true:+.2f}: why the frame is now "
             "the chord"]
    table, table_lines = _explained_table(runs, results[reference])
    lines += table_lines + _explained_verdict(table)
    datasets = {"ffrf_explained/first_mode_geometric_stiffness_true": Dataset(
                    true, "1/m", "first bending mode, per N of tension, strain u' + v'^2/2"),
                "ffrf_explained/first_mode_geometric_stiffness_tangent_frame": Dataset(
                    tangent, "1/m", "the same with the strain linear in a frame tangent at B "
                    "(flex's FFRF rod)")}
    datasets.update(table_datasets(table.values(), _EXPLAINED_COLUMNS, "ffrf_explained"))
    datasets["ffrf_explained/run"] = Dataset(np.array(list(table), dtype=object), "1", "run")
    return lines, datasets


_EXPLAINED_COLUMNS = {
    "rms_beam": ("1", f"RMS deflection difference from {BEST_BEAM} / its peak |deflection|"),
    "rms_fe": ("1", "RMS deflection difference from the nonlinear FE rod / its peak "
                    "|deflection|"),
    "rms_ffrf": ("1", f"RMS deflection difference from {FFRF_DEFAULT} / its peak "
                      "|deflection|"),
    "rms_ffrf_linear": ("1", f"RMS deflection difference from {FFRF_LINEAR} / its peak "
                             "|deflection|"),
    "peak_over_beam": ("1", f"peak |deflection| / that of {BEST_BEAM} - 1"),
    "first_window": ("1", f"as rms_beam over the first {WINDOW_S} s"),
    "last_window": ("1", f"as rms_beam over the last {WINDOW_S} s"),
    "chord_change_max": ("m", "largest change of the distance B-C")}


def _explained_table(runs: dict[str, Any], fe: CaseResult
                     ) -> tuple[dict[str, dict[str, float]], list[str]]:
    """Per run of section 4: RMS against the beam, the FE rod and the plain FFRF rod, early
    and late windows against the beam, largest chord change; and its report lines."""
    beam, fe_curves = _curves(runs[BEST_BEAM]), _curves(fe)
    ffrf, ffrf_linear = _curves(runs[FFRF_DEFAULT]), _curves(runs[FFRF_LINEAR])
    beam_peak = np.abs(beam["deflection"]).max()
    lines = [f"   {'run':44s} {'q_mid(0.1)':>10s} {'peak':>7s} {'rms/beam':>8s} {'rms/fe':>6s} "
             f"{'rms/ffrf':>8s} {'/linear':>8s} {'first':>6s} {'last':>6s} {'chord':>6s}",
             f"   {'':44s} {'[um]':>10s} {'/beam-1':>7s} {'[1]':>8s} {'[1]':>6s} {'[1]':>8s} "
             f"{'[1]':>8s} {'10 ms':>6s} {'10 ms':>6s} {'[um]':>6s}"]
    table = {}
    for name, run in runs.items():
        curves = _curves(run)
        first, last = windowed_rms(curves, beam)
        row = {"deflection": float(curves["deflection"][-1]),
               "peak_over_beam": float(np.abs(curves["deflection"]).max() / beam_peak - 1),
               "rms_beam": _against(curves, beam)["deflection_rms_rel"],
               "rms_fe": _against(curves, fe_curves)["deflection_rms_rel"],
               "rms_ffrf": _against(curves, ffrf)["deflection_rms_rel"],
               "rms_ffrf_linear": _against(curves, ffrf_linear)["deflection_rms_rel"],
               "first_window": first, "last_window": last,
               "chord_change_max": float(np.abs(curves["chord"]).max())}
        table[name] = row
        lines.append(f"   {name:44s} {row['deflection'] * 1e6:10.2f} "
                     f"{row['peak_over_beam']:+7.2%} {row['rms_beam']:8.3f} "
                     f"{row['rms_fe']:6.3f} {row['rms_ffrf']:8.3f} "
                     f"{row['rms_ffrf_linear']:8.3f} {first:6.3f} {last:6.3f} "
                     f"{row['chord_change_max'] * 1e6:6.1f}")
    return table, lines


def _explained_verdict(table: dict[str, dict[str, float]]) -> list[str]:
    """The section's conclusions, from its table."""
    default, linear = table[FFRF_DEFAULT], table[FFRF_LINEAR]
    lateral, tangent = table[LATERAL_ONLY], table[TANGENT_FRAME]
    return [
        f"   flex's default FFRF rod: peak |deflection| {default['peak_over_beam']:+.2%} of the "
        f"beam's, {default['rms_beam']:.3f} RMS from the beam ({default['first_window']:.3f} "
        f"over the first {WINDOW_S * 1e3:.0f} ms, {default['last_window']:.3f} over the last), "
        f"{default['rms_fe']:.3f} from the FE rod; the linear FFRF rod "
        f"{linear['rms_beam']:.3f} from the beam (peak {linear['peak_over_beam']:+.2%})",
        f"   the two-mode model with the default FFRF's physics (stiffening on the bending "
        f"coordinates only) is {lateral['rms_beam']:.3f} from the beam and "
        f"{lateral['rms_ffrf']:.3f} from the default FFRF rod: what remains between the FFRF "
        "rod and the beam is the foreshortening's pull on the axial coordinates, which the "
        "default FFRF drops (docs/geometric-stiffness.md: kept, it made the reduced coupler "
        "resonate where the nonlinear FE one does not)",
        f"   a rod linear in the B-face frame (flex's old default) is {tangent['rms_beam']:.3f} "
        "from the beam: its frame's turn against the chord lengthens the chord at no strain"]


def draw_figures(summary_data: dict[str, Dataset], folder: Path,
                 shown: tuple[str, ...]) -> list[Path]:
    """``validation-deflection.png`` (midpoint deflection of the ``shown`` runs over time,
    and their difference from the first) and ``validation-slider.png`` (slider position minus
    the rigid closed form)."""
    from flex.base.plotting import MICRO, panels

    data = {k: v.data for k, v in summary_data.items()}
    time = data["runs/time"]
    rigid = data["rigid_limit/closed_form_slider_position"]
    paths = []
    for stem, key, label, baseline in (
            ("deflection", "midpoint_deflection", "midpoint deflection", 0.0),
            ("slider", "slider_position", "slider x \u2212 rigid closed form", rigid)):
        path = folder / f"validation-{stem}.png"
        with panels(path, f"IVP test set crank, rigid start: {label}", rows=2,
                    size=(7.5, 6.0), sharex=True) as (_, (ax, difference)):
            first = None
            for name in shown:
                values = (data[f"runs/{name}/{key}"] - baseline) * 1e6
                first = values if first is None else first
                ax.plot(time, values, lw=1.0, label=name.replace("_", " "))
                difference.plot(time, values - first, lw=0.8)
            ax.set_ylabel(f"{label} [{MICRO}m]")
            difference.set_ylabel(f"\u2212 {shown[0].replace('_', ' ')}\n[{MICRO}m]")
            difference.set_xlabel("time [s]")
        paths.append(path)
    return paths

