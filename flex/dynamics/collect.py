"""The datasets of a solved mechanism, from its stored sensor data (:func:`collect`): time,
crank, slider, joint forces, constraint norm, energies, the wing, and the elastic response of
flexible links; a link model adds its own (:mod:`flex.dynamics.link_models`, point 6 of its
contract: ``mech.models[link].datasets``). Names, units and descriptions are the result
layout's (:mod:`flex.dynamics.solver`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from flex.data.results import Dataset
from flex.dynamics import planar
from flex.dynamics.builder import Mechanism
from flex.dynamics.link_outputs import (
    elastic_datasets,
    sensor_data,
)


def collect(mech: Mechanism) -> dict[str, Dataset]:
    """Datasets of the result layout from the stored sensor data of a solved mechanism."""
    scene, init = mech.scene, mech.initial
    crank_out = _crank_datasets(mech)
    time_s = crank_out.pop("time")
    out: dict[str, Dataset] = {"time": Dataset(time_s, "s", "simulation time")}
    out.update(crank_out)
    out["slider/position"] = Dataset(sensor_data(mech, "slider.Position")[:, 1], "m",
                                     "slider x (joint C) along the slide line")
    out["slider/velocity"] = Dataset(sensor_data(mech, "slider.Velocity")[:, 1], "m/s",
                                     "slider velocity along the slide line")
    out["slider/acceleration"] = Dataset(sensor_data(mech, "slider.Acceleration")[:, 1], "m/s^2",
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
    out.update(_joint_channel(time_s, mech.channel_cutoff_Hz,
                              {"A": on_crank_a, "B": on_coupler_b, "C": on_coupler_c}))

    residual_sq = np.zeros_like(time_s)
    for first, second in mech.constraint_points:
        gap = (sensor_data(mech, f"marker_{first}.Position")[:, 1:3]
               - sensor_data(mech, f"marker_{second}.Position")[:, 1:3])
        residual_sq += np.sum(gap**2, axis=1)
    slider_y = sensor_data(mech, "slider.Position")[:, 2] - scene["slider"]["offset_m"]
    residual_sq += slider_y**2 + sensor_data(mech, "slider.Rotation")[:, 3] ** 2
    out["constraint_norm"] = Dataset(np.sqrt(residual_sq), "m",
                                     "norm of the position constraint equations (A, B, C, "
                                     "slide line; slider angle in rad)")

    for link, model in mech.models.items():  # the link model's own (the coupler's)
        out.update(_own_datasets(model, link, model.datasets(mech, link, time_s), out))
    if mech.wing:
        out.update(_wing_datasets(mech))
    out.update(_energy_datasets(mech, out["slider/displacement"].data, time_s))
    return out


def _joint_channel(time_s: np.ndarray, cutoff_Hz: float | None,
                   forces: dict[str, np.ndarray]) -> dict[str, Dataset]:
    """Each joint's force modulus on the headline channel [N]: the modulus of the low-passed
    force vector (``forces``: joint -> (samples, 2) [N]), never the low-passed modulus. A
    modulus rectifies the ringing across the force (|F + r| ~ |F| + r^2 / 2|F|), and the
    low-pass keeps that bias: the 1 mm plate's exact beam (128 elements) read joint A's
    deployment peak 6.37989, 6.37935, 6.38430, 6.38216 N at h = 5, 2.5, 1.25, 0.625 us so,
    and 6.355104, 6.354903, 6.354859, 6.354846 N (order 2) on the low-passed vector (session
    13, ``/tmp/s13/jointvec.py``). None without a channel."""
    from flex.base.channel import channel_filter, channel_text

    low_pass = channel_filter(time_s, cutoff_Hz)
    if low_pass is None:
        return {}
    return {f"channel/joints/{joint}/force_modulus": Dataset(
        np.hypot(*low_pass(np.asarray(force, dtype=float)).T), "N",
        f"|force| at {joint}: the modulus of the force {channel_text(cutoff_Hz)}")
        for joint, force in forces.items()}


def _own_datasets(model: Any, link: str, datasets: dict[str, Dataset],
                  collected: dict[str, Dataset]) -> dict[str, Dataset]:
    """A link model's datasets, refused (ArgumentError: the registry given is at fault) when
    one is not its link's (``<link>/...``) or replaces one already collected: a toy model that
    wrote ``crank/angle`` ran as ok, its crank angle silently replaced."""
    from flex.base.errors import ArgumentError

    foreign = [name for name in datasets
               if not name.startswith((f"{link}/", f"channel/{link}/")) or name in collected]
    if foreign:
        raise ArgumentError(f"link model {model.name!r} ({link}) writes {', '.join(foreign)}: a "
                            f"link model's datasets are its own link's, {link}/... (and "
                            f"channel/{link}/...), and never replace the mechanism's (fix the "
                            f"entry's datasets function)")
    return datasets


def _joint_forces(mech: Mechanism) -> dict[str, np.ndarray]:
    """Force on each joint's second body [N], (n, 2) in global x, y, from the 3D joints: A
    (frame on crank), B (crank on coupler), C (slider on coupler), P (frame on slider).

    Joint frames (``mech.joint_frames``) -> global axes; Exudyn reports the force acting on
    body 0, so the force on body 1 is its negative (checked against the reference DAE).
    """
    out = {}
    for joint in "ABCP":
        local = -sensor_data(mech, f"joint_{joint}.Force")[:, 1:3]
        frame_sensor = mech.joint_frames.get(joint)
        if frame_sensor is None:
            out[joint] = local
            continue
        frame_angle = np.unwrap(sensor_data(mech, f"{frame_sensor}.Rotation")[:, 3])
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
    if mech.models["crank"].rigid:
        rotation = sensor_data(mech, "crank.Rotation")
        time_s, crank_angle = rotation[:, 0], rotation[:, 3]
        speed = sensor_data(mech, "crank.AngularVelocity")[:, 3]
        acceleration = sensor_data(mech, "crank.AngularAcceleration")[:, 3]
        how = " (rigid body)"
    else:
        position_a = sensor_data(mech, "marker_crank_A.Position")
        time_s = position_a[:, 0]
        chord = sensor_data(mech, "marker_crank_B.Position")[:, 1:3] - position_a[:, 1:3]
        chord_rate = (sensor_data(mech, "marker_crank_B.Velocity")[:, 1:3]
                      - sensor_data(mech, "marker_crank_A.Velocity")[:, 1:3])
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
    if mech.models["crank"].rigid:
        out["crank/midpoint_position"] = Dataset(sensor_data(mech, "crank.Position")[:, 1:3], "m",
                                                 "crank midpoint (centre of mass) x, y")
    else:  # midpoint and elastic response from the flexible crank's markers
        out.update(elastic_datasets(mech, "crank", "marker_crank_A", "marker_crank_B",
                                     "A-B", time_s))
    return out


def _summed(mech: Mechanism, sensors: int | list[int]) -> np.ndarray:
    """The sum of the first stored column of one sensor or a list of them (a beam link's
    energy: one sensor per element)."""
    return sum(np.asarray(mech.mbs.GetSensorStoredData(sensor))[:, 1]
               for sensor in np.atleast_1d(sensors))


def _energy_datasets(mech: Mechanism, slider_displacement_m: np.ndarray, time_s: np.ndarray
                     ) -> dict[str, Dataset]:
    """Kinetic, strain, spring and total energy; none when a link's energy is unknown.

    Rigid bodies from their sensed velocities; FFRF links from Exudyn's body outputs
    (kinetic energy of rigid and elastic motion, linear strain energy) and, with geometric
    stiffness, its energy (:meth:`flex.bodies.geometric_stiffness.GeometricStiffness.
    energy_J`); a beam link from its elements' outputs (summed). The nonlinear FE coupler
    reports no energy, so its runs have no energy datasets.
    """
    scene = mech.scene
    if not all(model.energy for model in mech.models.values()):
        return {}
    kinetic = np.zeros_like(time_s)
    strain = np.zeros_like(time_s)
    for name, (mass_kg, inertia) in mech.rigid_bodies.items():
        velocity = sensor_data(mech, f"{name}.Velocity")[:, 1:4]
        omega = sensor_data(mech, f"{name}.AngularVelocity")[:, 1:4]
        kinetic += 0.5 * mass_kg * np.sum(velocity**2, axis=1)
        kinetic += 0.5 * np.einsum("ij,jk,ik->i", omega, inertia, omega)
    for link, (kinetic_sensors, strain_sensors) in mech.flexible_energy.items():
        kinetic += _summed(mech, kinetic_sensors)
        strain += _summed(mech, strain_sensors)
        stiffness = (mech.crank if link == "crank" else mech.coupler).get("geometric_data")
        if stiffness is not None:  # the geometric stiffness's energy: not in Exudyn's body
            strain += stiffness.energy_J(sensor_data(mech, f"{link}.modal_coordinates")[:, 1:])
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
    inner = [sensor_data(mech, f"spring_chain.{i}.Coordinates")[:, 1]
             for i in range(chain.segments - 1)]
    speeds = [sensor_data(mech, f"spring_chain.{i}.Coordinates_t")[:, 1]
              for i in range(chain.segments - 1)]
    ends = np.array([-slider_displacement_m, *inner, np.zeros_like(slider_displacement_m)])
    compression = chain.segment_preload_m + ends[:-1] - ends[1:]
    potential = 0.5 * chain.segment_stiffness_N_per_m * np.sum(compression**2, axis=0)
    kinetic = 0.5 * chain.inner_mass_kg * np.sum(np.square(speeds), axis=0) if speeds \
        else np.zeros_like(slider_displacement_m)
    return kinetic, potential


def _wing_datasets(mech: Mechanism) -> dict[str, Dataset]:
    """Wing angle, angular velocity and the root (weld) loads, in global axes."""
    angle = sensor_data(mech, "wing.Rotation")[:, 3]
    span_m = mech.scene["wing"]["span_m"]
    omega = sensor_data(mech, "wing.AngularVelocity")[:, 3]
    if mech.planar:
        force, moment = planar.weld_loads(mech)
    else:
        # weld frame = crank frame at t = 0 turned with the crank; Exudyn reports the load
        # on body 0 (the crank), so the load on the wing is its negative
        turn = angle - mech.initial.crank_angle_rad
        local = -sensor_data(mech, "joint_W.ForceLocal")[:, 1:3]
        c, s = np.cos(turn), np.sin(turn)
        force = np.column_stack([c * local[:, 0] - s * local[:, 1],
                                 s * local[:, 0] + c * local[:, 1]])
        moment = -sensor_data(mech, "joint_W.TorqueLocal")[:, 3]
    return {
        "wing/angle": Dataset(angle, "rad", "wing angle from +x (along the crank)"),
        "wing/angular_velocity": Dataset(omega, "rad/s", "wing (and wing-tip) angular velocity"),
        "wing/angular_velocity_deg": Dataset(np.degrees(omega), "deg/s",
                                             "wing angular velocity in the thesis's unit"),
        "wing/angular_acceleration": Dataset(sensor_data(mech, "wing.AngularAcceleration")[:, 3],
                                             "rad/s^2", "wing angular acceleration"),
        "wing/tip_speed": Dataset(np.abs(omega) * span_m, "m/s", "speed of the wing tip"),
        "joints/W/force_on_wing": Dataset(force, "N", "crank on wing at the root (weld), x y"),
        "joints/W/root_moment": Dataset(moment, "N m",
                                        "in-plane bending moment at the wing root (about z)"),
    }
