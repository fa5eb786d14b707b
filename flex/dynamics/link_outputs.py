"""What a flexible link's sensors give: its markers' and modal coordinates' data read back
as the datasets every flexible link has (midpoint motion and deflection from the chord, chord
change, an FFRF link's modal coordinates, stresses and floating frame), and the sensors that
feed them. Shared by the link models' entries (:mod:`flex.dynamics.link_models`,
:mod:`flex.dynamics.exact_beam_link`) and :mod:`flex.dynamics.collect`.

And how a link's stored motion is read back from a result file (the link models' contract,
point 10): each entry names its :class:`MotionReader` (:data:`RIGID_MOTION`,
:func:`modal_motion`, :data:`NODAL_MOTION`, :data:`NO_MOTION`), which rebuilds the link's
mesh (:class:`Body`) and its state at a sample (:class:`BodyState`);
:func:`flex.tools.motion.case_motion` calls through it."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError
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
    if body.get("reduction") is None:  # nonlinear FE: nodal coordinates, no modes, no stress
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
        out.update(channel_stress_datasets(link, reduction, modal, time_s,
                                           mech.channel_cutoff_Hz))
    out.update(frame_datasets(mech, link))
    return out


def channel_stress_datasets(link: str, reduction: Any, modal: np.ndarray, time_s: np.ndarray,
                            cutoff_Hz: float | None) -> dict[str, Dataset]:
    """An FFRF ``link``'s stress peaks on the headline channel [Pa]:
    ``channel/<link>/peak_bending_stress`` and ``channel/<link>/peak_von_mises_stress``, the
    largest over the mesh nodes of the low-passed field. The stress is linear in the modal
    coordinates ``modal`` (samples, coordinates), so the field low-passed is the field of the
    low-passed coordinates (:mod:`flex.base.channel`: a peak series low-passed would rectify
    the field's ringing). None without a channel (``cutoff_Hz`` None, or a sampling at
    ``time_s`` [s] that holds nothing above it)."""
    from flex.base.channel import channel_filter, channel_text
    from flex.bodies.reduction import bending_stress_history
    from flex.bodies.stress import region_nodes, von_mises_history

    low_pass = channel_filter(time_s, cutoff_Hz)
    if low_pass is None:
        return {}
    smooth = low_pass(modal)
    on = channel_text(cutoff_Hz)
    out = {f"channel/{link}/peak_bending_stress": Dataset(
        bending_stress_history(reduction, smooth, stress_window_m(reduction)), "Pa",
        f"largest |sigma_xx| away from the end faces (bending + membrane) of the field {on}")}
    away = region_nodes(reduction)["away"]
    if away.size:
        out[f"channel/{link}/peak_von_mises_stress"] = Dataset(
            von_mises_history(reduction, smooth, away)[0], "Pa",
            f"largest nodal von Mises stress away from the joint faces of the field {on}")
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
    if "node_modal" not in handles:  # nonlinear FE, a beam: nodal coordinates only
        return
    builder.add(f"{link}.modal_coordinates",
                builder.sensor("Node", "Coordinates", nodeNumber=handles["node_modal"]))
    for output in ("Position", "Rotation"):
        builder.add(f"{link}.frame_{output}",
                    builder.sensor("Node", output, nodeNumber=handles["node_frame"]))
    sensors = [builder.mbs.AddSensor(builder.sensor("Body", kind, bodyNumber=handles["object"]))
               for kind in ("KineticEnergy", "PotentialEnergy")]
    builder.mech.flexible_energy[link] = (sensors[0], sensors[1])


__all__ = ["channel_stress_datasets", "elastic_datasets", "flexible_datasets", "flexible_sensors",
           "frame_datasets", "sensor_data", "stress_window_m"]


# ------------------------------------------------------------------------------------------
# how a link's stored motion is read back (export, animate): the contract's point 10
# ------------------------------------------------------------------------------------------
@dataclass
class Body:
    """One body of the mechanism as a tetrahedral mesh: ``reference_m`` (nodes, 3) in body
    coordinates [m], ``cells`` (cells, 10) quadratic tetrahedra (node indices, VTK order),
    ``corners`` (cells, 4) their corner nodes."""

    name: str
    model: str  #: the name of its link model (the slider: the rigid model's; set by the caller)
    reference_m: np.ndarray
    cells: np.ndarray
    corners: np.ndarray
    has_stress: bool = False
    facts: dict[str, Any] = field(default_factory=dict)  #: provenance (reduction key, ...)
    #: how its motion is stored (its reader's kind: rigid, modal, nodal)
    kind: str = "rigid"


@dataclass
class BodyState:
    """A body at one sample: global node positions [m] (nodes, 3), elastic displacement in
    its link frame [m] (nodes, 3; zero for a rigid body) and, for an FFRF link, the nodal
    stress [Pa] (nodes, 6; body axes; None otherwise)."""

    position_m: np.ndarray
    elastic_m: np.ndarray
    stress_Pa: np.ndarray | None


#: a stored case's datasets by path below ``cases/<case>/`` (time, ``<link>/...``)
CaseData = dict[str, np.ndarray]
#: the rigid frame of a link at a sample, computed only when asked: (origin [m] (x, y),
#: angle [rad]) from the stored angles and joint positions
RigidFrame = Callable[[], tuple[np.ndarray, float]]


@dataclass(frozen=True)
class MotionReader:
    """How one kind of stored motion is read back (the link model's ``stored_motion``).

    ``body(link, scene, data, attrs, where, cache_dir)`` -> ``(Body, source)``: the link's
    mesh and what its states need (a reduction, a meshed plate; refused with
    :class:`~flex.base.errors.FlexError`, naming ``where``, when the case does not hold it);
    ``state(body, source, data, sample, index, frame)`` -> :class:`BodyState` at case sample
    ``sample`` (motion sample ``index``; ``frame``: the link's rigid frame). ``body`` None:
    the kind is not read back (export and animate refuse it, naming the model)."""

    kind: str
    body: Callable[[str, Any, CaseData, dict[str, Any], str, Path | None],
                   tuple[Body, Any]] | None
    state: Callable[[Body, Any, CaseData, int, int, RigidFrame], BodyState] | None


def place(points_m: np.ndarray, origin_m: np.ndarray, angle_rad: float) -> np.ndarray:
    """Body points [m] turned by ``angle_rad`` about z and moved to ``origin_m`` (x, y) [m]."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    out = np.array(points_m, dtype=float)
    out[:, 0] = c * points_m[:, 0] - s * points_m[:, 1] + origin_m[0]
    out[:, 1] = s * points_m[:, 0] + c * points_m[:, 1] + origin_m[1]
    return out


def _rigid_body(link: str, scene: Any, data: CaseData, attrs: dict[str, Any], where: str,
                cache_dir: Path | None) -> tuple[Body, Any]:
    from flex.bodies.plate import quadratic_box

    values = scene[link]
    points, cells, corners = quadratic_box(values["length_m"], values["thickness_m"],
                                           values["width_m"], centred=False)
    return Body(link, "", points, cells, corners), None


def _rigid_state(body: Body, source: Any, data: CaseData, sample: int, index: int,
                 frame: RigidFrame) -> BodyState:
    origin, angle = frame()
    return BodyState(place(body.reference_m, origin, angle), np.zeros_like(body.reference_m),
                     None)


def _modal_body(link: str, scene: Any, data: CaseData, attrs: dict[str, Any], where: str,
                cache_dir: Path | None, *, reduction_for_scene: Callable[..., Any]
                ) -> tuple[Body, Any]:
    from flex.bodies.plate import tet10_cells
    from flex.bodies.stress import check_basis_identity

    missing = [name for name in ("modal_coordinates", "frame_position", "frame_angle")
               if f"{link}/{name}" not in data]
    if missing:
        raise FlexError(f"{where}: the FFRF {link} has no {', '.join(missing)} (written "
                        f"before flex stored them): rerun the case")
    reduction = reduction_for_scene(scene, link, cache_dir=cache_dir)
    problem = check_basis_identity(link, reduction, attrs)
    if problem:
        raise FlexError(f"{where}: {problem}")
    found = np.shape(data[f"{link}/modal_coordinates"])
    if len(found) != 2 or found[1] != reduction.n_modal_coordinates:
        raise FlexError(f"{where}: {link}/modal_coordinates has shape {found}, expected "
                        f"(samples, {reduction.n_modal_coordinates}): one column per mode of "
                        f"the reduction; the file was changed after flex wrote it: rerun the "
                        f"case")
    positions = reduction.fem.GetNodePositionsAsArray()
    corners = np.asarray(reduction.fem.elements[0]["Tet4"], dtype=np.int64)
    body = Body(link, "", positions, tet10_cells(corners, positions), corners,
                has_stress=reduction.has_stress_modes,
                facts={"reduction_key": reduction.key, "from_cache": reduction.from_cache},
                kind="modal")
    return body, reduction


def _modal_state(body: Body, reduction: Any, data: CaseData, sample: int, index: int,
                 frame: RigidFrame) -> BodyState:
    """A reduction's modal coordinates in its floating frame."""
    from flex.bodies.stress import nodal_displacement, nodal_stress

    q = data[f"{body.name}/modal_coordinates"][sample]
    elastic = nodal_displacement(reduction, q)
    position = place(body.reference_m + elastic, data[f"{body.name}/frame_position"][sample],
                     data[f"{body.name}/frame_angle"][sample])
    stress = nodal_stress(reduction, q) if body.has_stress else None
    return BodyState(position, elastic, stress)


def _nodal_body(link: str, scene: Any, data: CaseData, attrs: dict[str, Any], where: str,
                cache_dir: Path | None) -> tuple[Body, Any]:
    from flex.bodies.nonlinear import nonlinear_plate_for_scene
    from flex.bodies.plate import tet10_cells

    key = f"{link}/nodal/position"
    if key not in data:
        raise FlexError(f"{where}: the nonlinear FE {link} has no nodal field "
                        f"({key}: written before flex stored it): rerun the case")
    plate = nonlinear_plate_for_scene(scene)
    if data[key].shape[1] != plate.n_nodes:
        raise FlexError(f"{where}: the stored nodal field has {data[key].shape[1]} nodes, the "
                        f"plate's mesh {plate.n_nodes} (another netgen version?): rerun the "
                        f"case")
    corners = np.array([[v.nr - 1 for v in element.vertices]
                        for element in plate.mesh.ngmesh.Elements3D()], dtype=np.int64)
    positions = plate.node_positions_m
    return Body(link, "", positions, tet10_cells(corners, positions), corners,
                kind="nodal"), plate


def _nodal_state(body: Body, plate: Any, data: CaseData, sample: int, index: int,
                 frame: RigidFrame) -> BodyState:
    """Every node of the mesh, at the nodal snapshot ``index``; the elastic part in the chord
    frame (origin at the joint face ``end_a``'s centre, x toward ``end_b``'s)."""
    position = np.asarray(data[f"{body.name}/nodal/position"][index], dtype=float)
    b = plate.weights_end_a @ position[plate.nodes_end_a]
    c = plate.weights_end_b @ position[plate.nodes_end_b]
    angle = math.atan2(c[1] - b[1], c[0] - b[0])
    local = place(position - b, np.zeros(2), -angle)  # turned back into the chord frame
    return BodyState(position, local - body.reference_m, None)


#: the rigid model's: the link's angle and joint positions, a box of its plate moved with them
RIGID_MOTION = MotionReader("rigid", _rigid_body, _rigid_state)
def modal_motion(reduction_for_scene: Callable[..., Any]) -> MotionReader:
    """The reader of ``<link>/modal_coordinates`` and the floating frame's pose
    ``<link>/frame_position``, ``frame_angle``, on the basis of the link's reduction,
    rebuilt from the case's scene by ``reduction_for_scene(scene, link, cache_dir=...)``
    (:func:`flex.dynamics.link_models.reduction_for_scene`; passed in: the reduction is the
    registry's, a layer this module's callers stand on)."""
    return MotionReader("modal", functools.partial(
        _modal_body, reduction_for_scene=reduction_for_scene), _modal_state)


#: every node's position, ``<link>/nodal/position`` at ``<link>/nodal/time``, on the link's
#: plate mesh
NODAL_MOTION = MotionReader("nodal", _nodal_body, _nodal_state)
#: not read back: export and animate refuse it, naming the model
NO_MOTION = MotionReader("none", None, None)
