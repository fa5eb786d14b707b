"""Time integration of a built mechanism and collection of its outputs.

:func:`simulate` is the one entry point the studies use. Contract:

- input: a validated scene (and, for an FFRF coupler, its reduction);
- output: a :class:`~flex.data.results.CaseResult` whose datasets are the quantities of the
  result layout (``time``, ``crank/...``, ``slider/...``, ``joints/<A|B|C>/...``,
  ``constraint_norm``, ``energy/...`` (rigid and FFRF links), ``coupler/...``), each with units;
- refused before anything is built: what :func:`flex.config.settings.check_concrete` refuses
  (:class:`~flex.base.errors.SceneError`, a ``failed`` case from :func:`simulate_case`);
- status: ``ok``; a diverging run (solver failure, NaN, exploding constraint norm) raises
  :class:`~flex.base.errors.SimulationError` naming the step and time and what may help
  (:func:`divergence_advice`: a smaller step only where the step does not resolve the
  scene's fastest time scale; the extreme inputs), and :func:`simulate_case` turns that
  into a ``failed`` case instead of data; an ``ok`` run whose validity is in doubt (a
  linear FFRF link deflecting beyond 1 % of its length) carries the case attribute
  ``validity_warning`` (:func:`validity_warning`);
- counters: steps, Newton iterations, Jacobian updates, wall time [s].

The integrator follows the scene's ``[simulation]`` knobs (:func:`solver_settings`): Exudyn's
implicit generalized-alpha (index 3; or Newmark with index-2 constraints), full or modified
Newton (or a Jacobian once per step), or an explicit Runge-Kutta method with penalty joints;
always at a fixed step (a Newton failure is reported, not retried with a smaller step). Step
N covers t = (N - 1) h ... N h: a Newton failure names the step and its start time, a
non-finite or exploding output the step that produced it and its end time.
"""

from __future__ import annotations

import io
import signal
import threading
import time
from contextlib import redirect_stdout
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import SimulationError, Terminated
from flex.base.progress import heartbeat
from flex.config.settings import check_concrete
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, check_meshed_plate, estimate_mesh, to_toml
from flex.dynamics import planar
from flex.dynamics.mechanism import Mechanism, _rotation_z, build_mechanism
from flex.dynamics.runtime import SolverOutput, announce_integration

# a constraint norm above this is a failed assembly, not a tolerance question
CONSTRAINT_NORM_LIMIT_M = 1e-4

#: nonlinear FE coupler (~10k coordinates): a sparse LU (a dense one would take seconds and
#: ~1 GB per Newton step), reused while Newton converges -- the Jacobian and its
#: factorisation dominate a full Newton iteration. Measured on the 1 mm plate, 30 steps:
#: modified Newton 3 iterations per step and one Jacobian in all, 5x faster than full Newton
#: (2 iterations per step, each with a new Jacobian)
NONLINEAR_FE_SOLVER = {"linear_solver": "EigenSparse", "modified_newton": True}
#: the Newton residual of the nonlinear FE system stalls at ~9e-8 (Exudyn's residual norm,
#: measured at step 1e-5 s over the deployment): round-off of the face-marker positions
#: (weighted sums over ~100 nodes), scaled by 1 / step^2 in the index-3 equations. Relative
#: tolerances cannot reach below it (Newton failed at 6.6 ms with 1e-8 and at 7.9 ms with
#: 1e-7), so the absolute tolerance is raised above it; 1e-8 and 1e-7 relative gave midpoint
#: deflections 5e-12 m apart
NONLINEAR_FE_NEWTON_ABSOLUTE_TOLERANCE = 1e-6


def solver_settings(scene: Scene) -> dict[str, Any]:
    """The integrator settings used for a concrete ``scene`` (stored in every result
    file)."""
    sim = scene["simulation"]
    settings = {
        "integrator": "generalized-alpha (Exudyn, index 3)",
        "step_s": sim["step_s"],
        "end_time_s": sim["end_time_s"],
        "steps": int(round(sim["end_time_s"] / sim["step_s"])),
        "output_step_s": sim["output_step_s"] or sim["step_s"],
        "spectral_radius": sim["spectral_radius"],
        "newton_relative_tolerance": sim["newton_relative_tolerance"],
        "newton_absolute_tolerance": 1e-2 * sim["newton_relative_tolerance"],
        "modified_newton": sim["newton"] in ("modified", "jacobian_per_step"),
        "adaptive_step": False,  # fixed step: a Newton failure is a divergence, not a retry
    }
    if sim["newton"] == "jacobian_per_step":  # only then: other runs' stored settings stay
        settings["jacobian_per_step"] = True
    settings.update(_integrator_settings(sim))
    if scene["coupler"]["model"] == "nonlinear_fe":
        settings.update(NONLINEAR_FE_SOLVER)
        settings["newton_absolute_tolerance"] = max(settings["newton_absolute_tolerance"],
                                                    NONLINEAR_FE_NEWTON_ABSOLUTE_TOLERANCE)
    return settings


def _integrator_settings(sim: dict[str, Any]) -> dict[str, Any]:
    """Settings of the ``[simulation]`` integrator knobs (``integrator``, ``formulation``).

    ``index2`` is Exudyn's Newmark integrator with velocity-level constraints (Exudyn allows
    index 2 only with Newmark); its numerical damping follows ``spectral_radius`` rho:
    gamma = 1/2 + a, beta = (1 + a)^2 / 4 with a = (1 - rho) / (1 + rho), which has the same
    spectral radius at infinity (rho = 1: trapezoidal rule; rho < 1 is first-order accurate).
    """
    if sim["integrator"] == "explicit_penalty":
        return {"integrator": f"explicit {sim['explicit_method']} (Exudyn), penalty joints",
                "explicit_method": sim["explicit_method"],
                "penalty_stiffness_N_per_m": sim["penalty_stiffness_N_per_m"]}
    if sim["formulation"] == "index2":
        damping = (1 - sim["spectral_radius"]) / (1 + sim["spectral_radius"])
        return {"integrator": "Newmark (Exudyn, index 2)", "newmark_gamma": 0.5 + damping,
                "newmark_beta": (1 + damping) ** 2 / 4}
    return {}


def _is_explicit(settings: dict[str, Any]) -> bool:
    return "explicit_method" in settings


def _exudyn_settings(settings: dict[str, Any]):
    import exudyn as exu

    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.numberOfSteps = settings["steps"]
    ti.endTime = settings["steps"] * settings["step_s"]
    ti.adaptiveStep = settings["adaptive_step"]
    ti.automaticStepSize = False
    ti.generalizedAlpha.spectralRadius = settings["spectral_radius"]
    if "newmark_beta" in settings:
        ti.generalizedAlpha.useNewmark = True
        ti.generalizedAlpha.useIndex2Constraints = True
        ti.generalizedAlpha.newmarkBeta = settings["newmark_beta"]
        ti.generalizedAlpha.newmarkGamma = settings["newmark_gamma"]
    if _is_explicit(settings):
        ti.solverType = getattr(exu.DynamicSolverType, settings["explicit_method"])
        ti.explicit.eliminateConstraints = True  # the planar-motion coordinate constraints
    ti.newton.relativeTolerance = settings["newton_relative_tolerance"]
    ti.newton.absoluteTolerance = settings["newton_absolute_tolerance"]
    ti.newton.useModifiedNewton = settings["modified_newton"]
    ti.newton.modifiedNewtonJacUpdatePerStep = settings.get("jacobian_per_step", False)
    if "linear_solver" in settings:
        s.linearSolver.solverType = getattr(exu.LinearSolverType, settings["linear_solver"])
    ti.verboseMode = 1  # Exudyn's step lines every 2 s: progress (:class:`_SolverOutput`)
    s.solution.file.write = False
    s.solution.sensors.writePeriod = settings["output_step_s"]
    s.solution.sensors.writeHeader = False
    s.show.computationTime = False
    s.show.statistics = False
    return s


def run(mech: Mechanism, label: str = "") -> dict[str, Any]:
    """Integrate ``mech`` in place; return counters. Raises SimulationError on failure.
    A solve that takes more than a few seconds prints progress lines to stderr (``label``
    names the case in them)."""
    import exudyn as exu

    settings = solver_settings(mech.scene)
    solver = (exu.MainSolverExplicit() if _is_explicit(settings)
              else exu.MainSolverImplicitSecondOrder())
    captured = SolverOutput(label, settings["steps"] * settings["step_s"],
                             lambda: mech.mbs.SetRenderEngineStopFlag(True))
    if mech.scene["coupler"]["model"] == "nonlinear_fe":
        captured.progress.first_s = float("inf")  # the nonlinear FE body reports its own
    start = time.perf_counter()
    # Ctrl-C (or SIGTERM) inside Exudyn's C++ loop may come back as a failed solve; note it
    # ourselves so an interrupt is never mistaken for (and stored as) a diverged case
    interrupted: list[int] = []
    previous: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        def on_interrupt(signum, frame):
            interrupted.append(signum)
            raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt
        previous = {sig: signal.signal(sig, on_interrupt)
                    for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        with redirect_stdout(captured):
            ok = solver.SolveSystem(mech.mbs, _exudyn_settings(settings))
    except Exception as exc:  # Exudyn raises RuntimeError/ValueError on Newton failure
        ok = False
        captured.write(str(exc))
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if interrupted:
        if previous.get(interrupted[0]) not in (None, signal.SIG_DFL, signal.SIG_IGN,
                                                signal.default_int_handler):
            previous[interrupted[0]](interrupted[0], None)  # the caller's handler notes it
        raise Terminated if interrupted[0] == signal.SIGTERM else KeyboardInterrupt
    wall = time.perf_counter() - start
    if not ok:
        step, now = solver.it.currentStepIndex, solver.it.currentTime
        failure = "explicit solver failed" if _is_explicit(settings) else "Newton failed"
        detail = " ".join(captured.getvalue().split())[-300:]
        raise SimulationError(f"solver diverged at step {step} (t = {now:.6g} s, step "
                              f"{settings['step_s']:g} s): {failure}"
                              f"{f' ({detail})' if detail else ''}; "
                              f"{divergence_advice(mech.scene, _reductions(mech))}")
    return {"steps": int(solver.it.currentStepIndex), "newton_iterations":
            int(solver.it.newtonStepsCount), "jacobian_updates": int(solver.it.newtonJacobiCount),
            "wall_time_s": wall}


def run_profiled(mech: Mechanism) -> tuple[dict[str, float], str]:
    """Integrate ``mech`` once (implicit integrator) with Exudyn's CPU-time statistics on, for
    benchmarks (:mod:`flex.experiments.workprecision.benchmark`; :func:`run` is the production
    path): counters (``steps``, ``newton_iterations``, ``jacobian_updates``; ``wall_time_s`` [s],
    the solve alone) and the statistics text Exudyn printed. Raises SimulationError if it fails."""
    import exudyn as exu

    settings = _exudyn_settings(solver_settings(mech.scene))
    settings.show.computationTime = True
    settings.timeIntegration.verboseMode = 1  # the statistics are printed only when verbose
    solver = exu.MainSolverImplicitSecondOrder()
    captured = io.StringIO()
    start = time.perf_counter()
    with redirect_stdout(captured):
        ok = solver.SolveSystem(mech.mbs, settings)
    wall = time.perf_counter() - start
    if not ok:
        raise SimulationError("profiled run failed")
    return {"wall_time_s": wall, "steps": float(solver.it.currentStepIndex),
            "newton_iterations": float(solver.it.newtonStepsCount),
            "jacobian_updates": float(solver.it.newtonJacobiCount)}, captured.getvalue()


def _sensor(mech: Mechanism, name: str) -> np.ndarray:
    return np.asarray(mech.mbs.GetSensorStoredData(mech.sensors[name]))


def collect(mech: Mechanism) -> dict[str, Dataset]:
    """Datasets of the result layout from the stored sensor data of a solved mechanism."""
    scene, init = mech.scene, mech.initial
    crank_out = _crank_datasets(mech)
    time_s = crank_out.pop("time")
    out: dict[str, Dataset] = {"time": Dataset(time_s, "s", "simulation time")}
    out.update(crank_out)
    out["slider/position"] = Dataset(_sensor(mech, "slider.Position")[:, 1], "m",
                                     "slider x (joint C) along the slide line")
    out["slider/velocity"] = Dataset(_sensor(mech, "slider.Velocity")[:, 1], "m/s",
                                     "slider velocity along the slide line")
    out["slider/acceleration"] = Dataset(_sensor(mech, "slider.Acceleration")[:, 1], "m/s^2",
                                         "slider acceleration along the slide line")
    out["slider/displacement"] = Dataset(init.joint_C_m[0] - out["slider/position"].data, "m",
                                         "slider travel toward the crank pivot since t = 0")

    forces = planar.joint_forces(mech) if mech.planar else _joint_forces(mech)
    on_crank_a, on_coupler_b, on_coupler_c, on_slider_p = (forces[j] for j in "ABCP")
    out["joints/A/force_on_crank"] = Dataset(on_crank_a, "N", "frame on crank at A, x y")
    out["joints/A/force_modulus"] = Dataset(np.hypot(*on_crank_a.T), "N", "|force| at A")
    out["joints/B/force_on_crank"] = Dataset(-on_coupler_b, "N", "coupler on crank at B, x y")
    out["joints/B/force_on_coupler"] = Dataset(on_coupler_b, "N", "crank on coupler at B, x y")
    out["joints/B/force_modulus"] = Dataset(np.hypot(*on_coupler_b.T), "N", "|force| at B")
    out["joints/C/force_on_coupler"] = Dataset(on_coupler_c, "N", "slider on coupler at C, x y")
    out["joints/C/force_on_slider"] = Dataset(-on_coupler_c, "N", "coupler on slider at C, x y")
    out["joints/C/force_modulus"] = Dataset(np.hypot(*on_coupler_c.T), "N", "|force| at C")
    out["joints/P/force_on_slider"] = Dataset(on_slider_p, "N",
                                              "frame on slider, prismatic joint, x y")

    residual_sq = np.zeros_like(time_s)
    for first, second in mech.constraint_points:
        gap = (_sensor(mech, f"marker_{first}.Position")[:, 1:3]
               - _sensor(mech, f"marker_{second}.Position")[:, 1:3])
        residual_sq += np.sum(gap**2, axis=1)
    slider_y = _sensor(mech, "slider.Position")[:, 2] - scene["slider"]["offset_m"]
    residual_sq += slider_y**2 + _sensor(mech, "slider.Rotation")[:, 3] ** 2
    out["constraint_norm"] = Dataset(np.sqrt(residual_sq), "m",
                                     "norm of the position constraint equations (A, B, C, "
                                     "slide line; slider angle in rad)")

    out.update(_coupler_datasets(mech, time_s))
    if mech.wing:
        out.update(_wing_datasets(mech))
    if scene["coupler"]["model"] == "rigid":
        out["coupler/angle"] = Dataset(_sensor(mech, "coupler.Rotation")[:, 3], "rad",
                                       "coupler angle from +x (B to C)")
    out.update(_energy_datasets(mech, out["slider/displacement"].data, time_s))
    return out


def _joint_forces(mech: Mechanism) -> dict[str, np.ndarray]:
    """Force on each joint's second body [N], (n, 2) in global x, y, from the 3D joints: A
    (frame on crank), B (crank on coupler), C (slider on coupler), P (frame on slider).

    Joint frames (``mech.joint_frames``) -> global axes; Exudyn reports the force acting on
    body 0, so the force on body 1 is its negative (checked against the reference DAE).
    """
    out = {}
    for joint in "ABCP":
        local = -_sensor(mech, f"joint_{joint}.Force")[:, 1:3]
        frame_sensor = mech.joint_frames.get(joint)
        if frame_sensor is None:
            out[joint] = local
            continue
        frame_angle = np.unwrap(_sensor(mech, f"{frame_sensor}.Rotation")[:, 3])
        frame_angle = frame_angle - frame_angle[0]  # joint frames are global at t = 0
        c, s = np.cos(frame_angle), np.sin(frame_angle)
        out[joint] = np.column_stack([c * local[:, 0] - s * local[:, 1],
                                      s * local[:, 0] + c * local[:, 1]])
    return out


def _crank_datasets(mech: Mechanism) -> dict[str, Any]:
    """Crank angle, speed, acceleration and midpoint (and, if flexible, its elastic response).

    A rigid crank's angle is its node's; a flexible crank's is the angle of its chord A-B
    (the joint centres), its speed the chord's turning rate from the joint-marker
    velocities, its acceleration the time derivative of that (second-order differences).
    Returns ``"time"`` (an array) beside the datasets.
    """
    init = mech.initial
    if not mech.crank:
        rotation = _sensor(mech, "crank.Rotation")
        time_s, crank_angle = rotation[:, 0], rotation[:, 3]
        speed = _sensor(mech, "crank.AngularVelocity")[:, 3]
        acceleration = _sensor(mech, "crank.AngularAcceleration")[:, 3]
        how = " (rigid body)"
    else:
        position_a = _sensor(mech, "marker_crank_A.Position")
        time_s = position_a[:, 0]
        chord = _sensor(mech, "marker_crank_B.Position")[:, 1:3] - position_a[:, 1:3]
        chord_rate = (_sensor(mech, "marker_crank_B.Velocity")[:, 1:3]
                      - _sensor(mech, "marker_crank_A.Velocity")[:, 1:3])
        crank_angle = np.unwrap(np.arctan2(chord[:, 1], chord[:, 0]))
        speed = (chord[:, 0] * chord_rate[:, 1] - chord[:, 1] * chord_rate[:, 0]) \
            / np.sum(chord**2, axis=1)
        acceleration = np.gradient(speed, time_s)
        how = " of the chord A-B (flexible crank)"
    # the angle starts in (-pi, pi] (from a rotation matrix or atan2): put the series on the
    # branch of the scene's initial angle (181 deg stays 181 deg, not -179 deg)
    crank_angle = crank_angle + 2 * np.pi * np.round((init.crank_angle_rad - crank_angle[0])
                                                     / (2 * np.pi))
    out: dict[str, Any] = {"time": time_s}
    out["crank/angle"] = Dataset(crank_angle, "rad", "crank angle from the slide line (+x)"
                                 + how)
    out["crank/angular_velocity"] = Dataset(speed, "rad/s", "crank angular velocity" + how)
    out["crank/angular_acceleration"] = Dataset(acceleration, "rad/s^2",
                                                "crank angular acceleration" + how)
    if not mech.crank:
        out["crank/midpoint_position"] = Dataset(_sensor(mech, "crank.Position")[:, 1:3], "m",
                                                 "crank midpoint (centre of mass) x, y")
    else:  # midpoint and elastic response from the flexible crank's markers
        out.update(_elastic_datasets(mech, "crank", "marker_crank_A", "marker_crank_B",
                                     "A-B", time_s))
    return out


def _energy_datasets(mech: Mechanism, slider_displacement_m: np.ndarray, time_s: np.ndarray
                     ) -> dict[str, Dataset]:
    """Kinetic, strain, spring and total energy; none when a link's energy is unknown.

    Rigid bodies from their sensed velocities; FFRF links from Exudyn's body outputs
    (kinetic energy of rigid and elastic motion, linear strain energy) and, with geometric
    stiffness, its energy (:meth:`flex.bodies.geometric_stiffness.GeometricStiffness.
    energy_J`). The nonlinear FE coupler reports no energy, so its runs have no energy
    datasets.
    """
    scene = mech.scene
    if scene["coupler"]["model"] == "nonlinear_fe":
        return {}
    kinetic = np.zeros_like(time_s)
    strain = np.zeros_like(time_s)
    for name, (mass_kg, inertia) in mech.rigid_bodies.items():
        velocity = _sensor(mech, f"{name}.Velocity")[:, 1:4]
        omega = _sensor(mech, f"{name}.AngularVelocity")[:, 1:4]
        kinetic += 0.5 * mass_kg * np.sum(velocity**2, axis=1)
        kinetic += 0.5 * np.einsum("ij,jk,ik->i", omega, inertia, omega)
    for link, (kinetic_sensor, strain_sensor) in mech.flexible_energy.items():
        kinetic += np.asarray(mech.mbs.GetSensorStoredData(kinetic_sensor))[:, 1]
        strain += np.asarray(mech.mbs.GetSensorStoredData(strain_sensor))[:, 1]
        stiffness = (mech.crank if link == "crank" else mech.coupler).get("geometric_data")
        if stiffness is not None:  # the geometric stiffness's energy: not in Exudyn's body
            strain += stiffness.energy_J(_sensor(mech, f"{link}.modal_coordinates")[:, 1:])
    out = {"energy/kinetic": Dataset(kinetic, "J", "kinetic energy of all links")}
    if mech.flexible_energy:
        out["energy/strain"] = Dataset(strain, "J", "elastic strain energy of the flexible links")
    drive = scene["drive"]
    if mech.spring_chain:
        chain_kinetic, potential = _spring_chain_energy(mech, slider_displacement_m)
        kinetic += chain_kinetic
        out["energy/kinetic"] = Dataset(kinetic, "J", "kinetic energy of all links and of "
                                                      "the spring chain's inner masses")
        out["energy/spring_potential"] = Dataset(potential, "J", "spring strain energy "
                                                 "(sum over the chain's segments)")
    elif drive["kind"] == "spring":
        compression = drive["spring_preload_m"] - slider_displacement_m
        potential = 0.5 * drive["spring_stiffness_N_per_m"] * compression**2
        out["energy/spring_potential"] = Dataset(potential, "J", "spring strain energy")
    if drive["kind"] == "spring":
        out["energy/total"] = Dataset(kinetic + strain + potential, "J",
                                      "kinetic + strain + spring energy (constant if undamped)")
    return out


def _spring_chain_energy(mech: Mechanism, slider_displacement_m: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic energy of a spring chain's inner masses and the strain energy of its
    segments [J] (:class:`flex.dynamics.builder.SpringChain`; the slider's share of the coil
    is in the slider's kinetic energy). Segment j's compression is the segment preload plus
    the x displacement of its slider-side end minus its frame-side end's (x = -travel)."""
    chain = mech.spring_chain["chain"]
    inner = [_sensor(mech, f"spring_chain.{i}.Coordinates")[:, 1]
             for i in range(chain.segments - 1)]
    speeds = [_sensor(mech, f"spring_chain.{i}.Coordinates_t")[:, 1]
              for i in range(chain.segments - 1)]
    ends = np.array([-slider_displacement_m, *inner, np.zeros_like(slider_displacement_m)])
    compression = chain.segment_preload_m + ends[:-1] - ends[1:]
    potential = 0.5 * chain.segment_stiffness_N_per_m * np.sum(compression**2, axis=0)
    kinetic = 0.5 * chain.inner_mass_kg * np.sum(np.square(speeds), axis=0) if speeds \
        else np.zeros_like(slider_displacement_m)
    return kinetic, potential


def reduction_for_scene(scene: Scene, link: str = "coupler", *,
                        cache_dir: Path | None = None, mesh_order: int = 2):
    """The Craig-Bampton reduction of the scene's plate ``link`` (coupler or crank).

    ``cache_dir``: the reduction cache folder (loaded from there if present, written there
    if built; :func:`flex.bodies.reduction.reduction_cache_dir` names the user's), or None to
    build it in memory without any disk cache. ``mesh_order``: the tetrahedra's order (2, or
    1 for the work-precision study's linear ones).
    """
    from flex.bodies.reduction import build_reduction

    c = scene[link]
    if "auto" in (c["modes"], c["mesh_size_m"]):
        raise ValueError(f'{link}: resolve its "auto" modes and mesh first '
                         f"(flex.fidelity.auto.resolve, flex.config.settings.resolve_link_keys)")
    check_meshed_plate(link, dict(c, model="ffrf"))  # refused before any meshing
    _announce_mesh(link, c, f"reduction with {c['modes']} modes (instant if cached)",
                   c["modes"])
    with heartbeat(f"{link} reduction ({c['modes']} modes)"):
        return build_reduction(c["length_m"], c["thickness_m"], c["width_m"],
                               c["youngs_modulus_Pa"], c["density_kg_per_m3"],
                               c["poisson_ratio"], c["mesh_size_m"], c["modes"], cache_dir,
                               mode_selection=c["mode_selection"], mesh_order=mesh_order)


def scene_reductions(scene: Scene, reduction: Any = None, crank_reduction: Any = None, *,
                     cache_dir: Path | None = None) -> tuple[Any, Any]:
    """The reductions of the scene's ``ffrf`` coupler and crank: the given ones, else built
    or loaded from ``cache_dir`` (:func:`reduction_for_scene`); None for other links."""
    if scene["coupler"]["model"] == "ffrf" and reduction is None:
        reduction = reduction_for_scene(scene, cache_dir=cache_dir)
    if scene["crank"]["model"] == "ffrf" and crank_reduction is None:
        crank_reduction = reduction_for_scene(scene, "crank", cache_dir=cache_dir)
    return reduction, crank_reduction


def _highest_retained_omega(values: dict[str, Any]) -> float:
    """Beam estimate of the highest fixed-interface circular frequency [rad/s] a link's
    reduction keeps (its ``modes`` lowest of the kinds its ``mode_selection`` keeps)."""
    from flex.base.physics import clamped_plate_frequencies, in_plane_fixed_interface_omegas

    plate = (values["length_m"], values["thickness_m"], values["width_m"],
             values["youngs_modulus_Pa"], values["density_kg_per_m3"], values["poisson_ratio"])
    if values["mode_selection"] == "in_plane":
        return in_plane_fixed_interface_omegas(*plate, count=values["modes"])[-1]
    return clamped_plate_frequencies(*plate, count=values["modes"])[-1][0]


#: a mesh whose estimated build takes longer than this is announced on stderr first [s]
ANNOUNCE_MESH_S = 30.0
def _announce_mesh(link: str, values: dict[str, Any], what: str, modes: int | None = None
                   ) -> None:
    """Say on stderr what a long meshing job will cost before it starts (so a big mesh, or
    a reduction to many modes, is not a silent hang)."""
    estimate = estimate_mesh(values["length_m"], values["thickness_m"], values["width_m"],
                             values["mesh_size_m"], modes)
    if estimate.build_time_s > ANNOUNCE_MESH_S:
        import sys

        print(f"flex: meshing the {link} plate for its {what}: {estimate.text()} "
              f"(estimate)", file=sys.stderr, flush=True)


def _coupler_datasets(mech: Mechanism, time_s: np.ndarray) -> dict[str, Dataset]:
    """Coupler midpoint motion; for a flexible coupler also its elastic response.

    FFRF and nonlinear FE couplers give the same datasets from their B, C and midpoint
    markers; the FFRF coupler adds its modal coordinates and bending stress.
    """
    out: dict[str, Dataset] = {}
    if mech.scene["coupler"]["model"] == "rigid":
        out["coupler/midpoint_position"] = Dataset(_sensor(mech, "coupler.Position")[:, 1:3],
                                                   "m", "coupler midpoint x, y")
        out["coupler/midpoint_acceleration"] = Dataset(
            _sensor(mech, "coupler.Acceleration")[:, 1:3], "m/s^2",
            "coupler midpoint acceleration x, y (thesis figs. 35-42)")
        out["coupler/midpoint_deflection"] = Dataset(np.zeros_like(time_s), "m",
                                                     "elastic midpoint deflection (rigid: 0)")
        return out
    position_b = _sensor(mech, "marker_coupler_B.Position")[:, 1:4]
    position_c = _sensor(mech, "marker_coupler_C.Position")[:, 1:4]
    chord = position_c - position_b
    out["coupler/angle"] = Dataset(np.unwrap(np.arctan2(chord[:, 1], chord[:, 0])), "rad",
                                   "angle of the chord B-C from +x")
    out.update(_elastic_datasets(mech, "coupler", "marker_coupler_B", "marker_coupler_C",
                                 "B-C", time_s))
    if mech.scene["coupler"]["model"] == "nonlinear_fe":
        # the face markers' linearised rotation can tilt the faces out of plane (see
        # flex.bodies.nonlinear): record how far the midpoint leaves the plane
        position_mid = _sensor(mech, "marker_coupler_mid.Position")[:, 1:4]
        out["coupler/midpoint_out_of_plane"] = Dataset(
            position_mid[:, 2] - position_mid[0, 2], "m",
            "midpoint displacement normal to the mechanism plane (z), 0 at t = 0")
    return out


def _elastic_datasets(mech: Mechanism, link: str, start_marker: str, end_marker: str,
                      chord_name: str, time_s: np.ndarray) -> dict[str, Dataset]:
    """Midpoint motion and elastic response of a flexible ``link`` (FFRF or nonlinear FE).

    From its joint markers (``start_marker``, ``end_marker``: sensor names) and its midpoint
    marker; an FFRF link adds its modal coordinates and bending stress.
    """
    from flex.bodies.reduction import bending_stress_history, midpoint_deflection
    from flex.bodies.stress import peak_datasets

    position_start = _sensor(mech, f"{start_marker}.Position")[:, 1:4]
    position_end = _sensor(mech, f"{end_marker}.Position")[:, 1:4]
    position_mid = _sensor(mech, f"marker_{link}_mid.Position")[:, 1:4]
    velocity_mid = _sensor(mech, f"marker_{link}_mid.Velocity")[:, 1:3]
    deflection = midpoint_deflection(position_start, position_end, position_mid)
    out: dict[str, Dataset] = {}
    out[f"{link}/midpoint_position"] = Dataset(position_mid[:, :2], "m",
                                               f"{link} midpoint x, y")
    # the superelement marker reports no acceleration: differentiate its velocity (2nd order)
    out[f"{link}/midpoint_acceleration"] = Dataset(
        np.gradient(velocity_mid, time_s, axis=0), "m/s^2",
        f"{link} midpoint acceleration x, y (thesis figs. 35-42), from the marker velocity")
    out[f"{link}/midpoint_deflection"] = Dataset(
        deflection.transverse_m, "m",
        f"transverse elastic deflection of the midpoint from the chord {chord_name}, 0 at t = 0")
    out[f"{link}/chord_change"] = Dataset(deflection.chord_change_m, "m",
                                          f"change of the distance {chord_name} (axial strain "
                                          "x length)")
    body = mech.crank if link == "crank" else mech.coupler
    if "reduction" not in body:  # nonlinear FE: nodal coordinates, no modes, no stress yet
        return out
    modal = _sensor(mech, f"{link}.modal_coordinates")[:, 1:]
    out[f"{link}/modal_coordinates"] = Dataset(
        modal, "1", "elastic coordinates: the static modes, then the fixed-interface eigenmodes")
    reduction = body["reduction"]
    if reduction.has_stress_modes:
        out[f"{link}/peak_bending_stress"] = Dataset(
            bending_stress_history(reduction, modal, stress_window_m(reduction)), "Pa",
            "largest |sigma_xx| away from the end faces (bending + membrane)")
        out.update(peak_datasets(link, reduction, modal))
    out.update(_frame_datasets(mech, link))
    return out


def _frame_datasets(mech: Mechanism, link: str) -> dict[str, Dataset]:
    """The pose of an FFRF link's floating frame (what :mod:`flex.tools.export` places the
    nodal field with): origin x, y [m] and angle about z [rad]."""
    origin = _sensor(mech, f"{link}.frame_Position")[:, 1:3]
    angle = np.unwrap(_sensor(mech, f"{link}.frame_Rotation")[:, 3])
    return {f"{link}/frame_position": Dataset(origin, "m", "floating frame origin x, y"),
            f"{link}/frame_angle": Dataset(angle, "rad", "floating frame angle from +x")}


def flexible_link_attrs(scene: Scene, datasets: dict[str, Dataset],
                        reductions: dict[str, Any]) -> dict[str, Any]:
    """Case attributes of each FFRF link: the identity of its mode basis (what its stored
    modal coordinates mean) and its peak von Mises stresses, where and when
    (:mod:`flex.bodies.stress`)."""
    from flex.bodies.stress import basis_identity, peak_attrs

    out: dict[str, Any] = {}
    for link, reduction in reductions.items():
        if scene[link]["model"] != "ffrf" or f"{link}/modal_coordinates" not in datasets:
            continue
        out.update(basis_identity(link, reduction))
        if reduction.has_stress_modes:
            out.update(peak_attrs(link, reduction, datasets[f"{link}/modal_coordinates"].data,
                                  datasets["time"].data))
    return out


def stress_window_m(reduction: Any) -> tuple[float, float]:
    """Where a link's peak bending stress is read [m along it]: one thickness from each end
    face (Saint-Venant), but never narrower than one element about the midpoint, so a plate
    as thick as half its length (the stubbiest accepted) still has mesh nodes in it."""
    length, half = reduction.length_m, 0.5 * reduction.length_m - reduction.thickness_m
    half = max(half, 0.5 * min(reduction.mesh_size_m, length))
    return (0.5 * length - half, 0.5 * length + half)


def _wing_datasets(mech: Mechanism) -> dict[str, Dataset]:
    """Wing angle, angular velocity and the root (weld) loads, in global axes."""
    angle = _sensor(mech, "wing.Rotation")[:, 3]
    span_m = mech.scene["wing"]["span_m"]
    omega = _sensor(mech, "wing.AngularVelocity")[:, 3]
    if mech.planar:
        force, moment = planar.weld_loads(mech)
    else:
        # weld frame = crank frame at t = 0 turned with the crank; Exudyn reports the load
        # on body 0 (the crank), so the load on the wing is its negative
        turn = angle - mech.initial.crank_angle_rad
        local = -_sensor(mech, "joint_W.ForceLocal")[:, 1:3]
        c, s = np.cos(turn), np.sin(turn)
        force = np.column_stack([c * local[:, 0] - s * local[:, 1],
                                 s * local[:, 0] + c * local[:, 1]])
        moment = -_sensor(mech, "joint_W.TorqueLocal")[:, 3]
    return {
        "wing/angle": Dataset(angle, "rad", "wing angle from +x (along the crank)"),
        "wing/angular_velocity": Dataset(omega, "rad/s", "wing (and wing-tip) angular velocity"),
        "wing/angular_velocity_deg": Dataset(np.degrees(omega), "deg/s",
                                             "wing angular velocity in the thesis's unit"),
        "wing/angular_acceleration": Dataset(_sensor(mech, "wing.AngularAcceleration")[:, 3],
                                             "rad/s^2", "wing angular acceleration"),
        "wing/tip_speed": Dataset(np.abs(omega) * span_m, "m/s", "speed of the wing tip"),
        "joints/W/force_on_wing": Dataset(force, "N", "crank on wing at the root (weld), x y"),
        "joints/W/root_moment": Dataset(moment, "N m",
                                        "in-plane bending moment at the wing root (about z)"),
    }


def _check_finite(datasets: dict[str, Dataset], settings: dict[str, Any],
                  scene: Scene | None = None, reductions: dict[str, Any] | None = None
                  ) -> None:
    """Raise :class:`SimulationError` at the earliest sample where the solution diverged.

    Diverged: any dataset not finite (NaN, inf), or the constraint norm above
    :data:`CONSTRAINT_NORM_LIMIT_M` (an exploding or torn-apart assembly). The message names
    the integration step (time / step_s), the time [s] and what went wrong, and, given the
    ``scene`` (and its ``reductions`` by link), what may help (:func:`divergence_advice`).
    """
    time_s = np.asarray(datasets["time"].data, dtype=float)
    problems: list[tuple[int, str]] = []
    for name, dataset in datasets.items():
        data = np.asarray(dataset.data, dtype=float)
        bad = ~np.isfinite(data.reshape(len(time_s), -1)).all(axis=1)
        if bad.any():
            problems.append((int(np.argmax(bad)), f"{name} is not finite"))
    norm = np.asarray(datasets["constraint_norm"].data, dtype=float)
    above = norm > CONSTRAINT_NORM_LIMIT_M
    if above.any():
        index = int(np.argmax(above))
        problems.append((index, f"constraint norm {norm[index]:.3g} m exceeds "
                                f"{CONSTRAINT_NORM_LIMIT_M:g} m"))
    if not problems:
        return
    index, what = min(problems, key=lambda problem: problem[0])
    now = time_s[index] if np.isfinite(time_s[index]) else float("nan")
    step = int(round(now / settings["step_s"])) if np.isfinite(now) else index
    advice = "" if scene is None else f"; {divergence_advice(scene, reductions or {})}"
    raise SimulationError(f"solution diverged at step {step} (t = {now:.6g} s, step "
                          f"{settings['step_s']:g} s): {what}{advice}")


def integrate(scene: Scene, name: str = "case", reduction: Any = None,
              crank_reduction: Any = None, *, cache_dir: Path | None = None) -> CaseResult:
    """Build, integrate and collect one case of a concrete scene (every ``"auto"`` decided
    a layer above, :func:`flex.fidelity.auto.resolve`; here it is refused); raises on
    divergence (see module doc). ``reduction`` / ``crank_reduction``: the reductions of an
    ``ffrf`` coupler / crank (None: :func:`reduction_for_scene` builds them, or loads them from
    ``cache_dir``: the reduction cache folder; None: built in memory, no disk cache).
    ``scene_toml`` holds the scene.
    """
    check_concrete(scene)  # no "auto" left, steps and meshes, before anything is built
    reduction, crank_reduction = scene_reductions(scene, reduction, crank_reduction,
                                                  cache_dir=cache_dir)
    if scene["coupler"]["model"] == "nonlinear_fe" and reduction is None:
        _announce_mesh("coupler", scene["coupler"], "nonlinear FE body")
    announce_integration(scene, name, {"coupler": reduction, "crank": crank_reduction})
    with heartbeat(f"building {name}"):
        mech = build_mechanism(scene, reduction, crank_reduction)
    recorder = _nodal_recorder(mech)
    counters = run(mech, name)
    with np.errstate(all="ignore"):  # a diverged run overflows; _check_finite reports it
        datasets = collect(mech)
    settings = solver_settings(scene)
    _check_finite(datasets, settings, scene, _reductions(mech))
    if recorder is not None:  # its own time: after the check of the sampled datasets
        datasets.update(recorder.datasets())
    import tomli_w

    result = CaseResult(name, to_toml(scene), datasets, counters=counters,
                        solver_settings_toml=tomli_w.dumps(settings))
    result.attrs.update(flexible_link_attrs(scene, datasets, _reductions(mech)))
    warning = validity_warning(scene, datasets)
    if warning:
        result.attrs[VALIDITY_WARNING] = warning
    return result


def _nodal_recorder(mech: Mechanism):
    """A :class:`flex.bodies.nonlinear.NodalRecorder` for a nonlinear FE coupler, else None."""
    if mech.scene["coupler"]["model"] != "nonlinear_fe":
        return None
    from flex.bodies.nonlinear import NodalRecorder

    settings = solver_settings(mech.scene)
    return NodalRecorder(mech.mbs, mech.coupler["nodes"], settings["step_s"],
                         settings["output_step_s"], settings["end_time_s"])


# ------------------------------------------------------------------------------------------
# validity of a finished run
# ------------------------------------------------------------------------------------------
#: case attribute holding why a finished (``ok``) run may not mean what it says
VALIDITY_WARNING = "validity_warning"
#: largest peak elastic midpoint deflection of an FFRF link, as a fraction of its length,
#: within which its results are trusted: the FFRF body is linear elasticity in a floating
#: frame (small strains and elastic rotations; its geometric stiffness is of second order);
#: beyond ~1 % of the length the stability study's comparison with the nonlinear FE coupler
#: (README "Numerical stability") shows the two models part
FFRF_DEFLECTION_LIMIT = 0.01


def _buckling_warnings(scene: Scene, datasets: dict[str, Dataset]) -> list[str]:
    """An FFRF coupler compressed beyond its Euler load pi^2 E I / L^2: its geometric
    stiffness is linear in the load and holds no buckled shape."""
    from flex.base.kinematics import chord_components
    from flex.base.physics import euler_buckling_load_N

    coupler = scene["coupler"]
    if coupler["model"] != "ffrf" or "joints/C/force_on_coupler" not in datasets:
        return []
    axial, _ = chord_components(datasets["joints/C/force_on_coupler"].data,
                                datasets["coupler/angle"].data)
    ratio = float(np.max(-axial, initial=0.0)) / euler_buckling_load_N(
        coupler["length_m"], coupler["thickness_m"], coupler["width_m"],
        coupler["youngs_modulus_Pa"])
    if ratio <= 1.0:
        return []
    return [f"coupler: compressed to {ratio:.3g} x its Euler load (pi^2 E I / L^2): the FFRF "
            f"body's geometric stiffness is linear in the load and holds no buckled shape; "
            f'use coupler.model = "nonlinear_fe" or a thicker coupler']


def validity_warning(scene: Scene, datasets: dict[str, Dataset]) -> str:
    """Why the results of a finished run may not be valid ("" if nothing is known against
    them): an FFRF coupler compressed beyond its Euler load; an FFRF link whose peak
    elastic midpoint deflection exceeds :data:`FFRF_DEFLECTION_LIMIT` of its length (linear
    FFRF validity)."""
    warnings = _buckling_warnings(scene, datasets)
    for link in ("crank", "coupler"):
        name = f"{link}/midpoint_deflection"
        if scene[link]["model"] != "ffrf" or name not in datasets:
            continue
        peak = float(np.max(np.abs(datasets[name].data)))
        length = scene[link]["length_m"]
        if peak > FFRF_DEFLECTION_LIMIT * length:
            warnings.append(
                f"{link}: peak elastic midpoint deflection {peak:.3g} m is "
                f"{100 * peak / length:.3g} % of {link}.length_m = {length:g} m, beyond the "
                f"{100 * FFRF_DEFLECTION_LIMIT:g} % within which the FFRF body (small "
                f"elastic rotations in its floating frame) is trusted; "
                + ('compare with coupler.model = "nonlinear_fe" or use a stiffer coupler'
                   if link == "coupler" else "use a stiffer crank"))
    return "; ".join(warnings)


# ------------------------------------------------------------------------------------------
# divergence advice: is a smaller step the answer?
# ------------------------------------------------------------------------------------------
#: steps per period that resolve a time scale with the implicit integrator (generalized-
#: alpha period error (2 pi / 20)^2 / 12 = 0.8 %)
STEPS_PER_PERIOD = 20.0
#: an input this far (factor) from the bundled scene's value is named as extreme
EXTREME_FACTOR = 100.0
#: keys the step advice speaks of itself (not "extreme inputs")
_STEP_KEYS = ("simulation.end_time_s", "simulation.step_s", "simulation.output_step_s")


def _reductions(mech: Mechanism) -> dict[str, Any]:
    return {link: body["reduction"] for link, body in (("crank", mech.crank),
                                                       ("coupler", mech.coupler))
            if "reduction" in body}


def mechanism_mass_at_slider(scene: Scene) -> float:
    """Smallest inertia of the rigid mechanism reduced to the slider coordinate [kg].

    Kinetic energy 2 T = m_eff(theta) v_slider^2 (crank about A with the wing, coupler,
    slider; links with their lumped or plate mass properties), minimised over the crank
    angle (away from the dead centres, where the slider stops and m_eff is infinite).
    """
    from flex.base.kinematics import slider_crank
    from flex.data.scene import plate_mass_properties
    from flex.dynamics.mechanism import wing_mass_properties

    l1, l2 = scene["crank"]["length_m"], scene["coupler"]["length_m"]
    theta = np.linspace(-np.pi, np.pi, 721)
    state = slider_crank(l1, l2, theta, 1.0, 0.0, scene["slider"]["offset_m"])
    m1, j1 = plate_mass_properties(scene, "crank")
    m2, j2 = plate_mass_properties(scene, "coupler")
    inertia_a = j1 + m1 * (l1 / 2) ** 2
    if scene["wing"]["enabled"]:
        mass_w, inertia_w, centre_w = wing_mass_properties(scene)
        inertia_a += inertia_w + mass_w * centre_w**2
    v_slider = state.slider_velocity_m_per_s
    centre_x = (-l1 * np.sin(theta) + v_slider) / 2
    centre_y = l1 * np.cos(theta) / 2
    energy = (inertia_a + m2 * (centre_x**2 + centre_y**2)
              + j2 * state.coupler_angular_velocity_rad_per_s**2
              + scene["slider"]["mass_kg"] * v_slider**2)
    moving = np.abs(v_slider) > 1e-3 * np.max(np.abs(v_slider))
    return float(np.min(energy[moving] / v_slider[moving] ** 2))


def time_scales(scene: Scene, reductions: dict[str, Any] | None = None
                ) -> list[tuple[float, float, str]]:
    """The scene's time scales a fixed step must resolve: ``(period [s], steps per period
    needed, what)``, shortest first. ``reductions``: the built reductions by link (their
    highest retained mode is then known, else estimated from the plate)."""
    from flex.base.physics import pinned_pinned_omega
    from flex.data.scene import plate_mass_properties

    reductions = reductions or {}
    out: list[tuple[float, float, str]] = []
    drive, sim = scene["drive"], scene["simulation"]
    with np.errstate(all="ignore"):
        if drive["kind"] == "spring" and drive["spring_stiffness_N_per_m"] > 0:
            mass = mechanism_mass_at_slider(scene)
            out.append((2 * np.pi * np.sqrt(mass / drive["spring_stiffness_N_per_m"]),
                        STEPS_PER_PERIOD, "period of the spring on the mechanism's inertia"))
        elif drive["kind"] == "constant_speed" and drive["crank_speed_rad_per_s"] != 0:
            out.append((2 * np.pi / abs(drive["crank_speed_rad_per_s"]),
                        STEPS_PER_PERIOD, "crank turn (constant speed)"))
        for link in ("crank", "coupler"):
            values = scene[link]
            if values["model"] == "ffrf":
                if link in reductions:
                    hertz = float(np.max(reductions[link].fixed_interface_frequencies_Hz))
                    omega, how = 2 * np.pi * hertz, "highest retained mode"
                else:
                    omega = _highest_retained_omega(values)
                    how = "highest retained mode (beam estimate)"
                out.append((2 * np.pi / omega, STEPS_PER_PERIOD, f"period of the {link}'s {how}"))
            elif values["model"] == "nonlinear_fe":
                omega = pinned_pinned_omega(values["length_m"], values["thickness_m"],
                                            values["youngs_modulus_Pa"],
                                            values["density_kg_per_m3"])
                out.append((2 * np.pi / omega, STEPS_PER_PERIOD,
                            f"period of the {link}'s first bending mode"))
        if sim["integrator"] == "explicit_penalty":
            # lightest inertia a joint spring moves: body masses and J / (L/2)^2; two
            # bodies on one spring: 2 k / m. Explicit Runge-Kutta is stable up to
            # omega h ~ 2.8 (RK44): omega h <= 1 keeps a margin (measured limit 1.6e-5 s at
            # 1e8 N/m on the thesis links: omega h = 2.8)
            m1, j1 = plate_mass_properties(scene, "crank")
            m2, j2 = plate_mass_properties(scene, "coupler")
            lightest = min(m1, m2, scene["slider"]["mass_kg"],
                           j1 / (scene["crank"]["length_m"] / 2) ** 2,
                           j2 / (scene["coupler"]["length_m"] / 2) ** 2)
            omega = np.sqrt(2 * sim["penalty_stiffness_N_per_m"] / lightest)
            out.append((2 * np.pi / omega, 2 * np.pi,
                        "period of the penalty joints (explicit_penalty)"))
    return sorted((float(period), need, what) for period, need, what in out)


def extreme_inputs(scene: Scene) -> list[str]:
    """The inputs the scene's models use that are not finite or lie :data:`EXTREME_FACTOR`
    or more from the bundled scene's values (``"auto"`` solver keys: the rigid entry of
    ``flex/config/solver_defaults.toml``), most extreme first, as ``key = value (bundled: x)``."""
    from flex.config.settings import AUTO, solver_defaults
    from flex.config.usage import unused_keys
    from flex.data.scene import DEFAULT_SCENE, SCHEMA, _read_toml, _scene_path

    bundled = _read_toml(_scene_path(DEFAULT_SCENE), DEFAULT_SCENE)
    unused = unused_keys(scene)
    found: list[tuple[float, str]] = []
    for section, fields in SCHEMA.items():
        for key, field in fields.items():
            name = f"{section}.{key}"
            value = scene.get(section, {}).get(key)
            default = bundled.get(section, {}).get(key)
            if default == AUTO:
                default = solver_defaults()["rigid"].get(key)
            if (name in unused or name in _STEP_KEYS or field.kind is not float
                    or isinstance(value, bool) or not isinstance(value, int | float)
                    or not isinstance(default, int | float) or default <= 0):
                continue
            if not np.isfinite(value):
                found.append((np.inf, f"{name} = {value!r}"))
            elif value > 0:
                factor = abs(np.log10(value / default))
                if factor >= np.log10(EXTREME_FACTOR):
                    found.append((factor, f"{name} = {value:g} (bundled: {default:g})"))
    return [text for _, text in sorted(found, key=lambda item: -item[0])]


def divergence_advice(scene: Scene, reductions: dict[str, Any] | None = None) -> str:
    """What may help a diverged run, in one line: a smaller step only where the step does
    not resolve the scene's fastest time scale (:func:`time_scales`); the extreme inputs
    (:func:`extreme_inputs`) always."""
    try:
        step = float(scene["simulation"]["step_s"])
        scales = time_scales(scene, reductions)
        extremes = extreme_inputs(scene)
    except Exception:  # noqa: BLE001 - advice must never hide the divergence itself
        return "check the scene's extreme inputs and simulation.step_s"
    parts = []
    unresolved = [(period, need, what) for period, need, what in scales
                  if not (np.isfinite(period) and step <= period / need)]
    if unresolved:
        period, need, what = unresolved[0]
        if np.isfinite(period):
            parts.append(f"try a smaller simulation.step_s: h = {step:g} s is "
                         f"{period / step:.3g} steps per {what} ({period:.3g} s); it needs "
                         f"h <= {period / need:.3g} s")
        else:
            parts.append(f"the {what} is not finite")
    elif scales:
        period, need, what = scales[0]
        parts.append(f"the step already resolves the fastest time scale flex knows of "
                     f"({what}, {period:.3g} s: {period / step:.3g} steps), so a smaller "
                     f"simulation.step_s is unlikely to help")
    if extremes:
        parts.append("extreme inputs: " + ", ".join(extremes[:3]))
    elif not unresolved:
        sim = scene["simulation"]
        if (sim["integrator"] == "generalized_alpha" and sim["formulation"] == "index3"
                and sim["spectral_radius"] == 1.0):
            parts.append("simulation.spectral_radius = 1 leaves the index-3 constraint modes "
                         "undamped: try 0.9 or less")
        else:
            parts.append(f"no input is {EXTREME_FACTOR:g}x from the bundled scene: check the "
                         f"solver settings ([simulation])")
    return "; ".join(parts)


__all__ = ["integrate", "solver_settings", "run", "collect", "_rotation_z",
           "divergence_advice", "time_scales", "validity_warning", "VALIDITY_WARNING",
           "reduction_for_scene", "scene_reductions"]
