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
the closed-form slider-crank (exact). The references, the judging, the verdict tables, the
trust boundary and the figures are :mod:`flex.experiments.models.stability`'s.
"""

from __future__ import annotations

import math
from pathlib import Path

from flex.base.thesis import THESIS_SPRING_RATE_N_PER_M
from flex.config.settings import pinned_overrides
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.models.stability import (
    Extreme,
    extreme_cases,
    plate_overrides,
    simulate_extremes,
    stability_figures,
    summarize_extremes,
    thesis_plate_period_s,
)
from flex.study import StudyRun, Summary

NAME = "stability"
DESCRIPTION = "extremes: thickness, step, spectral radius, 1 s horizon, dead centres, stiff drives"
OVERRIDES = pinned_overrides() + ["simulation.error_estimate=false"]  # own references
#: verdict threshold: largest relative error (angle / swing, slider / travel, peak / peak)
TOLERANCE = 1e-3
#: plate thickness [mm] -> mesh size [mm] (about 2 t, at least 2 mm, at most 5 mm)
THICKNESS_MESH_MM = {0.3: 2.0, 0.5: 2.0, 1.0: 2.0, 2.0: 2.0, 3.0: 3.0, 10.0: 5.0, 20.0: 5.0}
NONLINEAR_THICKNESS_MM = (0.3, 0.5, 1.0, 2.0, 3.0)
#: the nonlinear FE coupler costs ~0.4-1.6 s per step: 1e-4 s, or ~40 steps per period of the
#: first bending mode for the stiffer plates
NONLINEAR_STEP_S = {0.3: 1e-4, 0.5: 1e-4, 1.0: 1e-4, 2.0: 2.5e-5, 3.0: 2.5e-5}
#: the curves each case keeps in the file
KEEP = ("time", "crank/angle", "crank/angular_velocity", "slider/position", "constraint_norm",
        "energy/total", "energy/strain", "coupler/midpoint_deflection")


def _plate(thickness_mm: float) -> tuple[str, ...]:
    """Overrides of the FFRF plate coupler of that thickness [mm] at its mesh size."""
    return plate_overrides(thickness_mm, THICKNESS_MESH_MM[thickness_mm])


def extremes() -> list[Extreme]:
    """Every run of the study (see the module doc)."""
    out: list[Extreme] = []
    for t in THICKNESS_MESH_MM:
        horizon = max(round(1.1 * thesis_plate_period_s(t), 4), 0.005)
        step = 1e-5
        common = _plate(t) + (f"simulation.end_time_s={horizon!r}", f"simulation.step_s={step}")
        out.append(Extreme(f"thickness_{t:g}mm", "thickness", common, f"fine:{step / 4!r}", t))
        if t in NONLINEAR_THICKNESS_MM:
            out.append(Extreme(f"nonlinear_{t:g}mm", "nonlinear", common,
                               f"nonlinear_fe:{NONLINEAR_STEP_S[t]!r}", t))
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
    # the bundled scene's own solver choice (auto modes, modified Newton) at 1e-3 s on the
    # 0.3 mm plate: 0.1 steps per period of its highest mode, Newton cannot follow (measured:
    # at 1e-4 s, or with full Newton, the stiffened body runs -- the scheme damps what it misses)
    auto_solver = ('coupler.modes="auto"', 'simulation.newton="auto"',
                   'simulation.newton_relative_tolerance="auto"',
                   'simulation.spectral_radius="auto"')
    out.append(Extreme("diverge_thin_plate_h1e-3", "divergence",
                       _plate(0.3) + auto_solver + ("simulation.end_time_s=0.01",
                                                    "simulation.step_s=1e-3"),
                       "none", 1e-3, expect="diverges"))
    return out


#: the runs built to diverge (flex run stability exits 0 when exactly these fail)
EXPECTED_FAILURES = frozenset(e.name for e in extremes() if e.expect == "diverges")


def cases(scene: Scene) -> dict[str, Scene]:
    return extreme_cases(scene, extremes())


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Run every extreme, judge it against its reference; keep the main curves only."""
    return simulate_extremes(extremes(), scenes, run.progress, run.notes, KEEP, TOLERANCE,
                             cache_dir=run.cache_dir)


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*summarize_extremes(results, run.notes, TOLERANCE))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return stability_figures(results, summary.datasets, folder, TOLERANCE)

if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
