"""A reduction as an Exudyn FFRF body (:func:`add_ffrf_link`, its joint markers) and the
elastic quantities of its output (:func:`midpoint_deflection`, :func:`bending_stress_history`)."""


from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from flex.base.errors import SceneError
from flex.bodies.reduction.build import END_A, END_B, Reduction, is_number


class MidpointDeflection(NamedTuple):
    """Elastic midpoint response relative to the chord B-C, both zero at the first sample [m]."""

    transverse_m: np.ndarray  #: along the in-plane chord normal e_z x (C - B)/|C - B|
    chord_change_m: np.ndarray  #: |C - B| minus its first value (axial stretch of the link)


# ------------------------------------------------------------------------------------------
# Exudyn body
# ------------------------------------------------------------------------------------------
def as_vector3(value: Sequence[float], name: str) -> np.ndarray:
    vector = np.asarray(value, dtype=float)
    if vector.shape != (3,) or not np.all(np.isfinite(vector)):
        raise SceneError(f"{name} = {value!r}: must be 3 finite numbers (metres, global frame)")
    return vector


def add_ffrf_link(mbs, reduction: Reduction, position_B: Sequence[float], angle_rad: float,
                  damping_ratio: float = 0.0, damping_model: str = "stiffness_proportional",
                  initial_velocity_B_m_per_s: Sequence[float] = (0.0, 0.0, 0.0),
                  initial_angular_velocity_rad_per_s: float = 0.0, name: str = "coupler",
                  joint_markers: str = "fewest", end_b_rotation: bool = True,
                  end_a_rotation: bool = True) -> dict[str, Any]:
    """Add the reduced plate to ``mbs`` as an ``ObjectFFRFreducedOrder`` between B and C.

    Written for the coupler (``end_a`` at B, ``end_b`` at C); the crank uses it with
    ``position_B`` = A and its markers ``marker_B`` at A and ``marker_C`` at B.

    Contract:
      - placement: the floating frame's origin is the centre of ``end_a`` and is put at
        ``position_B`` [m, global]; its x axis (the link axis) is turned by ``angle_rad`` about
        global z. C's reference position is ``position_B + length * (cos, sin, 0)``.
      - markers: ``marker_B`` / ``marker_C`` for joints B and C, at the end-face centres
        with the frame's orientation; ``joint_markers = "fewest"`` (default) makes them as
        cheap as the basis allows (:func:`_ffrf_joint_markers`: the frame node at ``end_a``,
        four corner nodes of a rigid ``end_b``), ``"all_face_nodes"`` puts a
        ``MarkerSuperElementRigid`` on every face node (area weights; the same results to
        the Newton tolerance, several times the cost: kept to measure that);
        ``end_a_rotation = False`` (a joint at B free about z, a revolute pin) lets ``marker_B``
        be the frame node itself (its turn about z is then the chord's, not the face's);
        ``end_b_rotation = False`` (a joint at C that constrains only the position, the
        coupler's pin at C) makes ``marker_C`` a position marker, cheaper still; ``marker_mid``
        is a ``MarkerSuperElementPosition`` on the mid-length slab
        (reference point (L/2, 0, 0) in body coordinates).
      - damping (0 allowed, must be in [0, 1)): stiffness-proportional Rayleigh damping
        ``beta = 2 * damping_ratio / omega_pp`` on the elastic coordinates, with omega_pp the
        reduced body's first pinned-pinned bending frequency [rad/s]. That mode then has
        exactly ``damping_ratio`` of critical damping, higher modes proportionally more;
        rigid-body motion is never damped. ``damping_model = "modal_bands"`` (with
        ``damping_ratio`` 0) damps every mode of the reduced body by its frequency band
        instead (:mod:`flex.bodies.reduction.damping`: 1 % / 10 % / 100 %, the commercial
        codes' default).
      - initial state: frame origin (point B) velocity [m/s] and angular velocity about z
        [rad/s], elastic coordinates at rest. Give the coupler's rigid-body velocities of
        the starting configuration (e.g. a crank turning at constant speed); default rest.
      - the body is added at the reference configuration; call ``mbs.Assemble()`` afterwards.

    Returns a dict: ``object`` (ObjectIndex of the ObjectFFRFreducedOrder), ``node_frame``
    (NodeIndex of the floating frame, Euler parameters), ``node_modal`` (NodeIndex of the modal
    elastic coordinates: sensor ``OutputVariableType.Coordinates`` feeds
    :func:`bending_stress_history`), ``marker_B``, ``marker_C``, ``marker_mid`` (MarkerIndex),
    ``position_B``, ``position_C``, ``position_mid`` (reference positions [m], global),
    ``rotation_matrix`` (3x3, body to global), ``mass_kg``, ``stiffness_proportional_damping_s``
    (beta [s]), ``modal_damping`` (None, or the bands' ``(frequencies [Hz], damping ratios)``
    per mode of the reduced body).
    """
    position_B, velocity_B = _checked_placement(position_B, angle_rad, initial_velocity_B_m_per_s,
                                                initial_angular_velocity_rad_per_s, joint_markers)
    beta = _stiffness_proportional_damping_s(reduction, damping_ratio)
    rotation, link = _add_ffrf_object(mbs, reduction, position_B, angle_rad, velocity_B,
                                      initial_angular_velocity_rad_per_s, beta, name)
    modal_damping = _band_damping(mbs, link["object"], reduction, damping_model, damping_ratio)
    joints = None if joint_markers == "all_face_nodes" else _ffrf_joint_markers(
        mbs, link["object"], link["node_frame"], reduction, name, end_b_rotation, end_a_rotation)
    return {**link, **add_plate_markers(mbs, link["object"], reduction, position_B, rotation,
                                        name, joint_markers=joints),
            "stiffness_proportional_damping_s": beta, "modal_damping": modal_damping}


def _checked_placement(position_B: Sequence[float], angle_rad: float,
                       velocity_B: Sequence[float], angular_velocity_rad_per_s: float,
                       joint_markers: str) -> tuple[np.ndarray, np.ndarray]:
    """:func:`add_ffrf_link`'s placement and initial velocity checked (a
    :class:`flex.base.errors.SceneError` names the first bad one): position and velocity of B
    as 3-vectors."""
    position_B = as_vector3(position_B, "position_B")
    velocity_B = as_vector3(velocity_B, "initial_velocity_B_m_per_s")
    for label, value in (("angle_rad", angle_rad),
                         ("initial_angular_velocity_rad_per_s", angular_velocity_rad_per_s)):
        if not (is_number(value) and math.isfinite(value)):
            raise SceneError(f"{label} = {value!r}: must be a finite number")
    if joint_markers not in JOINT_MARKERS:
        raise SceneError(f"joint_markers = {joint_markers!r}: must be one of "
                         f"{', '.join(JOINT_MARKERS)}")
    return position_B, velocity_B


def _add_ffrf_object(mbs, reduction: Reduction, position_B: np.ndarray, angle_rad: float,
                     velocity_B: np.ndarray, angular_velocity_rad_per_s: float, beta: float,
                     name: str) -> tuple[np.ndarray, dict[str, Any]]:
    """The reduction's ``ObjectFFRFreducedOrder`` added at B turned by ``angle_rad`` about z,
    with its initial velocity and stiffness-proportional damping ``beta`` [s]. Returns the
    rotation matrix (body to global) and the ``object``, ``node_frame`` and ``node_modal``
    entries of :func:`add_ffrf_link`'s result."""
    from exudyn.rigidBodyUtilities import RotationMatrixZ

    rotation = np.asarray(RotationMatrixZ(float(angle_rad)))
    added = reduction.ffrf_interface().AddObjectFFRFreducedOrder(
        mbs, positionRef=list(position_B), rotationMatrixRef=rotation,
        initialVelocity=list(velocity_B),
        initialAngularVelocity=[0.0, 0.0, float(angular_velocity_rad_per_s)],
        stiffnessProportionalDamping=beta, name=name)
    return rotation, {"object": added["oFFRFreducedOrder"], "node_frame": added["nRigidBody"],
                      "node_modal": added["nGenericODE2"]}


def _band_damping(mbs, body, reduction: Reduction, damping_model: str,
                  damping_ratio: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Set the body's band damping matrix for ``damping_model = "modal_bands"`` (and return
    the modes' frequencies [Hz] and ratios); None for stiffness-proportional damping."""
    from flex.bodies.reduction.damping import DAMPING_MODELS, modal_band_damping_matrix

    if damping_model not in DAMPING_MODELS:
        raise SceneError(f"damping_model = {damping_model!r}: must be one of "
                         f"{', '.join(DAMPING_MODELS)}")
    if damping_model != "modal_bands":
        return None
    if damping_ratio != 0:
        raise SceneError(f"damping_ratio = {damping_ratio!r} with damping_model = "
                         '"modal_bands": the bands set every ratio; accepted: 0')
    interface = reduction.ffrf_interface()
    matrix, frequencies_Hz, ratios = modal_band_damping_matrix(
        interface.massMatrixReduced, interface.stiffnessMatrixReduced)
    mbs.SetObjectParameter(body, "dampingMatrixReduced", matrix)
    return frequencies_Hz, ratios


def _stiffness_proportional_damping_s(reduction: Reduction, damping_ratio: float) -> float:
    """Rayleigh ``beta`` [s] that gives the first pinned-pinned mode ``damping_ratio`` of
    critical damping (0 for none); SceneError outside [0, 1) or without that mode."""
    if not (is_number(damping_ratio) and 0.0 <= damping_ratio < 1.0):
        raise SceneError(f"damping_ratio = {damping_ratio!r}: must lie in [0, 1)")
    if damping_ratio == 0:
        return 0.0
    omega = 2 * np.pi * reduction.pinned_pinned_frequency_Hz
    if not math.isfinite(omega):
        raise SceneError("damping_ratio > 0 needs the pinned-pinned frequency, which is "
                         "undefined for thickness > 2 x width: use damping_ratio = 0")
    return 2.0 * damping_ratio / omega


#: how an FFRF body's joint markers are made (:func:`add_ffrf_link`)
JOINT_MARKERS = ("fewest", "all_face_nodes")
#: largest relative non-rigid part of a mode's displacement over a joint face for the face to
#: count as rigid in the reduced basis (round-off measures ~4e-14)
RIGID_FACE_TOLERANCE = 1e-9


def _ffrf_joint_markers(mbs, body, frame_node, reduction: Reduction, name: str,
                        end_b_rotation: bool = True, end_a_rotation: bool = True
                        ) -> dict[str, Any]:
    """The joint markers at ``end_a`` (B) and ``end_b`` (C) of an FFRF body, as cheap as the
    reduced basis allows.

    Why: a ``MarkerSuperElementRigid`` costs time per face node and mode at every residual
    and Jacobian evaluation (Exudyn's CMarkerSuperElementRigid), and the joints were most of
    an FFRF step, growing with the mesh (33, 39, 63 face nodes for 4, 2, 1 mm meshes). In
    the chord-frame basis both end faces move rigidly in every mode, and no mode moves the
    centre of ``end_a`` (the frame's origin), so:

    - ``end_a`` without ``end_a_rotation`` (its joint ignores the face's turn about z, as a
      revolute pin about z does) gets a ``MarkerNodeRigid`` on the frame node, when no mode
      turns the face about x or y (the in-plane basis): the frame node then has the face's
      position and its orientation but for that turn;
    - a face every mode moves rigidly gets a ``MarkerSuperElementRigid`` on its four corner
      nodes, equal weights (any three or more non-collinear nodes centred on the face centre
      give the same position and rotation of a rigid face);
    - any other face keeps all its nodes and their area weights;
    - without ``end_b_rotation`` the ``end_b`` marker is a ``MarkerSuperElementPosition``
      on those nodes (no rotation to compute: a quarter less per step on a 6-mode coupler).

    Results agree with all-node markers to the Newton tolerance; a step on a 2 mm mesh is 4x
    cheaper. Returns ``marker_B``, ``marker_C`` (MarkerIndex).
    """
    import exudyn.itemInterface as eii

    positions = reduction.fem.GetNodePositionsAsArray()
    basis = reduction.fem.modeBasis["matrix"]
    basis = basis.reshape(-1, 3, basis.shape[1])
    markers = {}
    for face, label, rotation in ((END_A, "B", end_a_rotation), (END_B, "C", end_b_rotation)):
        nodes = np.asarray(getattr(reduction, f"nodes_{face}"))
        weights = getattr(reduction, f"weights_{face}")
        centre = getattr(reduction, f"centre_{face}")
        motions = _rigid_face_motions(positions[nodes], basis[nodes], centre)
        if (face == END_A and not rotation and motions is not None
                and not np.any(motions[:, :5])
                and np.allclose(centre, 0.0, rtol=0, atol=1e-9 * reduction.length_m)):
            markers[f"marker_{label}"] = mbs.AddMarker(eii.MarkerNodeRigid(
                name=f"{name}:{label}", nodeNumber=frame_node))
            continue
        corners = _face_corners(positions, nodes)
        if (len(corners) == 4 and motions is not None
                and np.allclose(positions[corners].mean(axis=0), centre, rtol=0,
                                atol=1e-9 * reduction.length_m)):
            nodes, weights = corners, np.full(4, 0.25)
        kind = (eii.MarkerSuperElementPosition if face == END_B and not rotation
                else eii.MarkerSuperElementRigid)
        markers[f"marker_{label}"] = mbs.AddMarker(kind(
            name=f"{name}:{label}", bodyNumber=body, meshNodeNumbers=nodes,
            weightingFactors=weights))
    return markers


def _face_corners(positions: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The nodes of a face normal to x at its four (y, z) corners (extremes of +-y +- z,
    each coordinate scaled by the face's extent)."""
    yz = positions[nodes][:, 1:]
    scaled = (yz - yz.mean(axis=0)) / np.maximum(np.ptp(yz, axis=0), 1e-300)
    picks = {int(nodes[np.argmax(scaled @ np.array([sign_y, sign_z]))])
             for sign_y in (-1.0, 1.0) for sign_z in (-1.0, 1.0)}
    return np.array(sorted(picks))


def _rigid_face_motions(face_positions: np.ndarray, face_modes: np.ndarray,
                        origin: np.ndarray | None = None) -> np.ndarray | None:
    """Per mode, the face's (linearized) rigid motion u = t + w x r about ``origin`` [m]
    (None: the face nodes' centroid),
    rows (t_x, t_y, t_z, w_x, w_y, w_z) with entries below :data:`RIGID_FACE_TOLERANCE` of
    the mode's face displacement set to 0; None if some mode does not move the face rigidly
    to that tolerance (least squares over the face nodes)."""
    r = face_positions - (face_positions.mean(axis=0) if origin is None else origin)
    fit = np.zeros((3 * len(r), 6))
    for i, (x, y, z) in enumerate(r):
        fit[3 * i:3 * i + 3, :3] = np.eye(3)
        fit[3 * i:3 * i + 3, 3:] = [[0.0, z, -y], [-z, 0.0, x], [y, -x, 0.0]]  # -[r]x
    motions = []
    for mode in np.moveaxis(face_modes, 2, 0):
        u = mode.ravel()
        size = np.linalg.norm(u)
        parameters = np.zeros(6)
        if size > 0:
            parameters, *_ = np.linalg.lstsq(fit, u, rcond=None)
            if np.linalg.norm(fit @ parameters - u) > RIGID_FACE_TOLERANCE * size:
                return None
            scale = np.concatenate([np.ones(3), np.full(3, np.abs(r).max())])
            parameters[np.abs(parameters) * scale < RIGID_FACE_TOLERANCE * size] = 0.0
        motions.append(parameters)
    return np.array(motions).reshape(-1, 6)


def add_plate_markers(mbs, body, plate, position_B: np.ndarray, rotation: np.ndarray,
                      name: str = "coupler",
                      joint_markers: dict[str, Any] | None = None) -> dict[str, Any]:
    """Joint and midpoint markers on a meshed plate body (FFRF or nonlinear FE).

    ``plate`` carries the node sets ``nodes_end_a/_b/_mid``, their weights and the reference
    centres ``centre_end_a/_b/_mid`` [m, body frame] (a :class:`Reduction` or a
    ``flex.bodies.nonlinear.NonlinearPlate``). Returns ``marker_B`` and ``marker_C``
    (``MarkerSuperElementRigid`` on the end faces), ``marker_mid``
    (``MarkerSuperElementPosition``), their global reference positions ``position_B/_C/_mid``
    [m], ``rotation_matrix`` (body to global) and ``mass_kg``. ``joint_markers``: markers
    ``marker_B`` / ``marker_C`` already made for the end faces (FFRF bodies), used instead.
    """
    import exudyn.itemInterface as eii

    def marker(kind, label: str, nodes, weights):
        return mbs.AddMarker(kind(name=f"{name}:{label}", bodyNumber=body,
                                  meshNodeNumbers=nodes, weightingFactors=weights))

    joints = joint_markers or {
        "marker_B": marker(eii.MarkerSuperElementRigid, "B", plate.nodes_end_a,
                           plate.weights_end_a),
        "marker_C": marker(eii.MarkerSuperElementRigid, "C", plate.nodes_end_b,
                           plate.weights_end_b)}
    return {
        **joints,
        "marker_mid": marker(eii.MarkerSuperElementPosition, "mid", plate.nodes_mid,
                             plate.weights_mid),
        "position_B": position_B + rotation @ plate.centre_end_a,
        "position_C": position_B + rotation @ plate.centre_end_b,
        "position_mid": position_B + rotation @ plate.centre_mid,
        "rotation_matrix": rotation,
        "mass_kg": plate.mass_kg,
    }


# ------------------------------------------------------------------------------------------
# post-processing
# ------------------------------------------------------------------------------------------
def _as_track(positions: np.ndarray, name: str) -> np.ndarray:
    track = np.asarray(positions, dtype=float)
    if track.ndim != 2 or track.shape[1] != 3 or len(track) == 0:
        raise ValueError(f"{name}: expected an array of shape (n, 3), got {track.shape}")
    return track


def midpoint_deflection(position_B: np.ndarray, position_C: np.ndarray,
                        position_mid: np.ndarray) -> MidpointDeflection:
    """Elastic midpoint deflection and chord stretch from global point tracks.

    Contract: the three arguments are time series of global positions [m], shape (n, 3),
    of the joint-B centre, the joint-C centre and the midpoint marker, motion in the x-y
    plane. Returns :class:`MidpointDeflection` with, per sample,

    - ``transverse_m``: (mid - B) . n with n = e_z x (C - B)/|C - B| (the chord turned by
      +90 deg in the x-y plane, i.e. the body's +y for an undeformed link), minus its first
      value;
    - ``chord_change_m``: |C - B| minus its first value.

    Rigid motion of the link gives zeros; the first sample is the reference (zero by
    definition), so start the series in the undeformed state. Pure numpy; raises ValueError
    for mismatched shapes or a zero-length chord.
    """
    b = _as_track(position_B, "position_B")
    c = _as_track(position_C, "position_C")
    m = _as_track(position_mid, "position_mid")
    if not (b.shape == c.shape == m.shape):
        raise ValueError(f"shapes differ: B {b.shape}, C {c.shape}, mid {m.shape}")
    chord = c - b
    chord_length = np.linalg.norm(chord, axis=1)
    if np.any(chord_length == 0):
        raise ValueError("B and C coincide in some sample: the chord has no direction")
    in_plane = chord[:, :2] / np.linalg.norm(chord[:, :2], axis=1)[:, None]
    normal = np.column_stack([-in_plane[:, 1], in_plane[:, 0]])  # e_z x chord
    transverse = np.einsum("ij,ij->i", (m - b)[:, :2], normal)
    return MidpointDeflection(transverse_m=transverse - transverse[0],
                              chord_change_m=chord_length - chord_length[0])


def bending_stress_history(reduction: Reduction, modal_coordinates: np.ndarray,
                           x_range_m: tuple[float, float] | None = None) -> np.ndarray:
    """Peak |sigma_xx| (axial stress along the link, body frame) per sample [Pa].

    Contract: ``modal_coordinates`` has shape (n, 6 + modes) or (6 + modes,): the elastic
    coordinates of the body (the ``node_modal`` of :func:`add_ffrf_link`, output
    ``Coordinates``). Stress is linear in them (small strains, as the FFRF model assumes),
    taken from the stress post-processing modes at the mesh nodes whose reference x lies in
    ``x_range_m``; the default (thickness, length - thickness) leaves out one thickness at
    each end, where the rigid end faces cause a local stress concentration that the pin of
    a real eye would not (Saint-Venant). Bending dominates sigma_xx in a slender link; the
    membrane part from the axial force is included. Returns an array of shape (n,).
    """
    if not reduction.has_stress_modes:
        raise ValueError("this reduction has no stress post-processing modes")
    coordinates = np.atleast_2d(np.asarray(modal_coordinates, dtype=float))
    if coordinates.shape[1] != reduction.n_modal_coordinates:
        raise ValueError(f"modal_coordinates: expected {reduction.n_modal_coordinates} columns, "
                         f"got shape {coordinates.shape}")
    if x_range_m is None:
        x_range_m = (reduction.thickness_m, reduction.length_m - reduction.thickness_m)
    x = reduction.fem.GetNodePositionsAsArray()[:, 0]
    nodes = np.flatnonzero((x >= x_range_m[0]) & (x <= x_range_m[1]))
    if len(nodes) == 0:
        raise ValueError(f"x_range_m = {x_range_m!r} holds no mesh node")
    # columns 6k + 0 hold sigma_xx of mode k (Exudyn order xx, yy, zz, yz, xz, xy)
    stress_xx_modes = reduction.fem.postProcessingModes["matrix"][nodes, 0::6]
    peaks = np.empty(len(coordinates))
    chunk = max(1, 2_000_000 // len(nodes))  # bound the (samples x nodes) temporary
    for start in range(0, len(coordinates), chunk):
        stress = coordinates[start:start + chunk] @ stress_xx_modes.T
        peaks[start:start + chunk] = np.abs(stress).max(axis=1)
    return peaks
