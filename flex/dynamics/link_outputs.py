"""What a flexible link's sensors give: its markers' and modal coordinates' data read back
as the datasets every flexible link has (midpoint motion and deflection from the chord, chord
change, an FFRF link's modal coordinates, stresses and floating frame), and the sensors that
feed them. Shared by the link models' entries (:mod:`flex.dynamics.link_models`,
:mod:`flex.dynamics.exact_beam_link`) and :mod:`flex.dynamics.collect`."""

from __future__ import annotations

from typing import Any

import numpy as np

from flex.data.results import Dataset


# ------------------------------------------------------------------------------------------
# what a flexible link's markers and modal coordinates give (FFRF and nonlinear FE)
# ------------------------------------------------------------------------------------------
def sensor_data(mech: Any, name: str) -> np.ndarray:
    """The stored data of ``mech``'s sensor ``name`` (time in column 0, then its values)."""
    return np.asarray(mech.mbs.GetSensorStoredData(mech.sensors[name]))


def elastic_datasets(mech: Any, link: str, start_marker: str, end_marker: str,
                      chord_name: str, time_s: np.ndarray) -> dict[str, Dataset]:
    """Midpoint motion and elastic response of a flexible ``link`` (FFRF or nonlinear FE).

    From its joint markers (``start_marker``, ``end_marker``: sensor names) and its midpoint
    marker; an FFRF link adds its modal coordinates and bending stress.
    """
    from flex.bodies.reduction import bending_stress_history, midpoint_deflection
    from flex.bodies.stress import peak_datasets

    position_start = sensor_data(mech, f"{start_marker}.Position")[:, 1:4]
    position_end = sensor_data(mech, f"{end_marker}.Position")[:, 1:4]
    position_mid = sensor_data(mech, f"marker_{link}_mid.Position")[:, 1:4]
    velocity_mid = sensor_data(mech, f"marker_{link}_mid.Velocity")[:, 1:3]
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
    if not mech.models[link].modal:  # nonlinear FE: nodal coordinates, no modes, no stress
        return out
    modal = sensor_data(mech, f"{link}.modal_coordinates")[:, 1:]
    out[f"{link}/modal_coordinates"] = Dataset(
        modal, "1", "elastic coordinates: the static modes, then the fixed-interface eigenmodes")
    reduction = body["reduction"]
    if reduction.has_stress_modes:
        out[f"{link}/peak_bending_stress"] = Dataset(
            bending_stress_history(reduction, modal, stress_window_m(reduction)), "Pa",
            "largest |sigma_xx| away from the end faces (bending + membrane)")
        out.update(peak_datasets(link, reduction, modal))
    out.update(frame_datasets(mech, link))
    return out


def frame_datasets(mech: Any, link: str) -> dict[str, Dataset]:
    """The pose of an FFRF link's floating frame (what :mod:`flex.tools.export` places the
    nodal field with): origin x, y [m] and angle about z [rad]."""
    origin = sensor_data(mech, f"{link}.frame_Position")[:, 1:3]
    angle = np.unwrap(sensor_data(mech, f"{link}.frame_Rotation")[:, 3])
    return {f"{link}/frame_position": Dataset(origin, "m", "floating frame origin x, y"),
            f"{link}/frame_angle": Dataset(angle, "rad", "floating frame angle from +x")}


def stress_window_m(reduction: Any) -> tuple[float, float]:
    """Where a link's peak bending stress is read [m along it]: one thickness from each end
    face (Saint-Venant), but never narrower than one element about the midpoint, so a plate
    as thick as half its length (the stubbiest accepted) still has mesh nodes in it."""
    length, half = reduction.length_m, 0.5 * reduction.length_m - reduction.thickness_m
    half = max(half, 0.5 * min(reduction.mesh_size_m, length))
    return (0.5 * length - half, 0.5 * length + half)


# ------------------------------------------------------------------------------------------
# flexible links: the coupler's datasets from its markers
# ------------------------------------------------------------------------------------------
def flexible_datasets(mech: Any, link: str, time_s: np.ndarray) -> dict[str, Dataset]:
    """A flexible coupler's chord angle and elastic response from its B, C and midpoint
    markers (a flexible crank's are read with its motion, :mod:`flex.dynamics.collect`)."""
    if link != "coupler":
        return {}
    position_b = sensor_data(mech, "marker_coupler_B.Position")[:, 1:4]
    position_c = sensor_data(mech, "marker_coupler_C.Position")[:, 1:4]
    chord = position_c - position_b
    out = {"coupler/angle": Dataset(np.unwrap(np.arctan2(chord[:, 1], chord[:, 0])), "rad",
                                    "angle of the chord B-C from +x")}
    out.update(elastic_datasets(mech, "coupler", "marker_coupler_B", "marker_coupler_C",
                                 "B-C", time_s))
    return out


def flexible_sensors(builder: Any, link: str, handles: dict[str, Any]) -> None:
    """A flexible link's midpoint marker (position, velocity; a flexible crank's joint-marker
    velocities too, its chord's turning rate) and, for a modal (FFRF) link, its modal
    coordinates, floating frame pose (:mod:`flex.tools.export`) and energies (Exudyn's FFRF
    body reports its kinetic and strain energy)."""
    if link == "crank":
        for name in ("crank_A", "crank_B"):
            builder.add(f"marker_{name}.Velocity", builder.sensor(
                "Marker", "Velocity", markerNumber=builder.markers[name]))
    for output in ("Position", "Velocity"):
        builder.add(f"marker_{link}_mid.{output}",
                    builder.sensor("Marker", output, markerNumber=handles["marker_mid"]))
    if not builder.models[link].modal:  # nonlinear FE: nodal coordinates only
        return
    builder.add(f"{link}.modal_coordinates",
                builder.sensor("Node", "Coordinates", nodeNumber=handles["node_modal"]))
    for output in ("Position", "Rotation"):
        builder.add(f"{link}.frame_{output}",
                    builder.sensor("Node", output, nodeNumber=handles["node_frame"]))
    sensors = [builder.mbs.AddSensor(builder.sensor("Body", kind, bodyNumber=handles["object"]))
               for kind in ("KineticEnergy", "PotentialEnergy")]
    builder.mech.flexible_energy[link] = (sensors[0], sensors[1])


__all__ = ["elastic_datasets", "flexible_datasets", "flexible_sensors", "frame_datasets",
           "sensor_data", "stress_window_m"]
