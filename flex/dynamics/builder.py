"""The slider-crank's parts in Exudyn: its initial configuration, the :class:`Mechanism` a
build returns, and the 3D builder (:class:`Builder`) that :func:`flex.dynamics.mechanism.
build_mechanism` drives (:mod:`flex.dynamics.planar` extends it with 2D items for rigid
scenes). The sketch of the mechanism and the choice of build are in
:mod:`flex.dynamics.mechanism`; the crank's and the coupler's bodies are added by their link
models (:mod:`flex.dynamics.link_models`, point 5 of its contract).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.kinematics import crank_pin, slider_crank
from flex.base.physics import cuboid_inertia_kgm2, cuboid_mass_kg
from flex.data.fields import AUTO
from flex.data.plates import plate_mass_properties
from flex.data.scene import Scene
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel, entries

os.environ.setdefault("EXUDYN_NO_USER_SETTINGS", "1")


@dataclass
class InitialConfiguration:
    """Assembled configuration at t = 0 (metres, radians, per second)."""

    crank_angle_rad: float
    coupler_angle_rad: float
    joint_B_m: np.ndarray
    joint_C_m: np.ndarray
    crank_speed_rad_per_s: float
    coupler_speed_rad_per_s: float
    joint_B_velocity_m_per_s: np.ndarray
    joint_C_velocity_m_per_s: np.ndarray


def initial_configuration(scene: Scene) -> InitialConfiguration:
    """Positions and consistent velocities of the joints at t = 0 (closed form)."""
    l1, l2 = scene["crank"]["length_m"], scene["coupler"]["length_m"]
    offset_m = scene["slider"]["offset_m"]
    theta = np.radians(scene["crank"]["initial_angle_deg"])
    drive = scene["drive"]
    omega = drive["crank_speed_rad_per_s"] if drive["kind"] == "constant_speed" else 0.0
    state = slider_crank(l1, l2, theta, omega, 0.0, offset_m)
    pin, pin_velocity = crank_pin(l1, theta, omega)
    joint_b = np.array([*pin, 0.0])
    joint_c = np.array([float(state.slider_position_m), offset_m, 0.0])
    vel_b = np.array([*pin_velocity, 0.0])
    vel_c = np.array([float(state.slider_velocity_m_per_s), 0.0, 0.0])
    return InitialConfiguration(float(theta), float(state.coupler_angle_rad), joint_b, joint_c,
                                float(omega), float(state.coupler_angular_velocity_rad_per_s),
                                vel_b, vel_c)


@dataclass
class Mechanism:
    """A built, assembled Exudyn system and the handles the solver reads.

    ``sensors`` maps a name to ``(sensor index, columns)``: the columns of the stored sensor
    data (after the time column) that hold the quantity. ``joint_frames`` tells how each
    joint's local force output maps to global axes.
    """

    system_container: Any
    mbs: Any
    scene: Scene
    initial: InitialConfiguration
    sensors: dict[str, int] = field(default_factory=dict)
    joint_frames: dict[str, str | None] = field(default_factory=dict)
    constraint_points: list[tuple[str, str]] = field(default_factory=list)
    rigid_bodies: dict[str, tuple[float, np.ndarray]] = field(default_factory=dict)
    coupler: dict[str, Any] = field(default_factory=dict)
    crank: dict[str, Any] = field(default_factory=dict)
    #: flexible links whose energy Exudyn reports: name -> (kinetic sensor, strain sensor),
    #: or lists of them to sum (a beam link's elements)
    flexible_energy: dict[str, tuple[Any, Any]] = field(default_factory=dict)
    wing: dict[str, Any] = field(default_factory=dict)
    #: built by :mod:`flex.dynamics.planar` (2D bodies; joint loads read by its own rules)
    planar: bool = False
    #: ``drive.spring_model = "chain"``: ``{"chain": SpringChain, "nodes": [inner nodes,
    #: slider side first]}`` (collect reads their sensors ``spring_chain.<i>.<output>``)
    spring_chain: dict[str, Any] = field(default_factory=dict)
    #: the entry of each link's model, by link (:mod:`flex.dynamics.link_models`), and the
    #: registry they come from
    models: dict[str, Any] = field(default_factory=dict)
    link_models: Any = None
    #: the headline channel's cut-off [Hz] (:func:`flex.dynamics.advice.channel_cutoff_Hz`;
    #: None: no channel): a link's datasets read their stress peaks on their low-passed field
    #: with it (:mod:`flex.base.channel`)
    channel_cutoff_Hz: float | None = None


@dataclass(frozen=True)
class SpringChain:
    """The drive spring with its mass (``drive.spring_model = "chain"``): ``segments`` equal
    springs in series on the slide line between the slider and the frame, each of rate
    ``segments`` x k [N/m] (and damping ``segments`` x d [N s/m]), compressed by
    preload / ``segments`` [m] at t = 0, so the chain's rate, damping and preload force are
    the massless spring's. The coil's mass m_s [kg] is lumped at the segment ends: each
    segment's half to each end, i.e. ``segments`` - 1 inner masses of m_s / segments and
    m_s / (2 segments) moving with the slider (the frame's half-segment does not move).
    Converges to the continuous coil as segments^-2 (docs/spring-mass.md).
    """

    segments: int
    segment_stiffness_N_per_m: float
    segment_damping_Ns_per_m: float
    segment_preload_m: float
    inner_mass_kg: float
    slider_share_kg: float


def spring_chain(scene: Scene) -> SpringChain | None:
    """The scene's :class:`SpringChain`, or None for a massless spring or no spring."""
    drive = scene["drive"]
    if drive["kind"] == "spring" and drive["spring_model"] == AUTO:
        raise SceneError('drive.spring_model = "auto" must be resolved before building '
                         "(flex.fidelity.simulation.simulate does it with "
                         "flex.fidelity.auto.resolve)")
    if drive["kind"] != "spring" or drive["spring_model"] != "chain":
        return None
    segments, mass_kg = int(drive["spring_segments"]), drive["spring_mass_kg"]
    return SpringChain(segments, segments * drive["spring_stiffness_N_per_m"],
                       segments * drive["spring_damping_Ns_per_m"],
                       drive["spring_preload_m"] / segments, mass_kg / segments,
                       mass_kg / (2 * segments))


def slider_mass_kg(scene: Scene) -> float:
    """The slider's mass [kg] in the mechanism: its own, plus the spring's end share when the
    spring is a chain (:class:`SpringChain`)."""
    chain = spring_chain(scene)
    return scene["slider"]["mass_kg"] + (chain.slider_share_kg if chain else 0.0)


def rotation_z(angle_rad: float) -> np.ndarray:
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _turned_marker(mbs: Any, marker: int, rotation: np.ndarray) -> int:
    """A copy of ``marker`` with its frame turned by ``rotation`` (3x3, in the marker's frame)
    through its ``localHT``: a joint's frame as Exudyn takes it since 1.12.244 deprecated the
    joints' ``rotationMarker0/1``. A copy, so that the marker's own sensors (the frame of B's
    force in collect among them) read as before. Rigid markers only (``BodyRigid``,
    ``NodeRigid``, ``SuperElementRigid``: each has a ``localHT``)."""
    data = mbs.GetMarker(marker)
    if "localHT" not in data:
        raise TypeError(f"marker {marker} ({data['markerType']}) has no frame (localHT) to turn")
    turn = np.eye(4)
    turn[:3, :3] = rotation
    # names are unique (Exudyn names the copy); localPosition / offset is the localHT's
    # translation, which the copy keeps
    copy = {key: value for key, value in data.items()
            if key not in ("name", "localPosition", "offset")}
    copy["localHT"] = np.asarray(data["localHT"]) @ turn
    return mbs.AddMarker(copy)


#: damping of the penalty joints, as a fraction of critical for the lightest link's mass
PENALTY_DAMPING_RATIO = 0.2


def _add_penalty_joints(mbs: Any, stiffness_N_per_m: float, lightest_mass_kg: float,
                        joint_markers: list[tuple[int, int]], nodes: list[int]) -> list[int]:
    """Joints A, B, C and the slide line as stiff springs, for Exudyn's explicit solvers.

    ``joint_markers``: (marker 0, marker 1) of A, B, C and of the slide line (ground, slider);
    ``nodes``: the rigid-body nodes (Tait-Bryan, coordinates x y z rx ry rz) of crank,
    coupler and slider. A, B, C become ``CartesianSpringDamper``s of stiffness
    ``stiffness_N_per_m`` in x and y, the slide line one in y only, damped with
    :data:`PENALTY_DAMPING_RATIO` of critical for ``lightest_mass_kg`` (undamped, the
    joint forces ring at the penalty frequency about their true values: measured +-20 N on
    ~25 N at 1e8 N/m; damped, 1e-2 N, with the same crank angle). The out-of-plane
    coordinates (z, rx, ry of every body) and the slider's angle are held by
    ``CoordinateConstraint``s to ground, which the explicit solvers eliminate
    (``timeIntegration.explicit.eliminateConstraints``). The joints then open by about
    force / stiffness: the crank-angle error falls as 1 / stiffness, while the explicit
    stability limit of the step falls as 1 / sqrt(stiffness). Returns the four connector
    indices (their ``Force`` output is in global axes, acting on marker 0's body).
    """
    import exudyn.itemInterface as eii

    ground_node = mbs.AddNode(eii.NodePointGround())
    ground_coordinate = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground_node,
                                                               coordinate=0))
    held = {node: [2, 3, 4] for node in nodes}
    held[nodes[-1]].append(5)  # the slider does not turn
    for node, coordinates in held.items():
        for coordinate in coordinates:
            marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=node,
                                                            coordinate=coordinate))
            mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[ground_coordinate,
                                                                       marker]))
    k = stiffness_N_per_m
    d = 2.0 * PENALTY_DAMPING_RATIO * np.sqrt(k * lightest_mass_kg)
    springs = []
    for index, markers in enumerate(joint_markers):
        axes = np.array([1.0, 1.0, 0.0] if index < 3 else [0.0, 1.0, 0.0])
        springs.append(mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(
            markerNumbers=list(markers), stiffness=list(k * axes), damping=list(d * axes))))
    return springs


def wing_mass_properties(scene: Scene) -> tuple[float, float, float]:
    """Wing plate mass [kg], inertia about its centre [kg m^2] and centre distance from A [m].

    The wing is a flat plate in the mechanism plane (switchblade wing): root at the crank
    pivot A, span along the crank direction, chord across it, thickness out of plane.
    """
    wing = scene["wing"]
    mass_kg = cuboid_mass_kg(wing["span_m"], wing["chord_m"], wing["thickness_m"],
                             wing["density_kg_per_m3"])
    return mass_kg, cuboid_inertia_kgm2(mass_kg, wing["span_m"], wing["chord_m"]), \
        wing["span_m"] / 2.0


def _add_wing(mech: Mechanism, rigid_body, body_marker) -> int:
    """Add the wing as a rigid body with its root at A; return its marker at the root (the
    builder welds it to the crank: :meth:`Builder.weld`)."""
    init = mech.initial
    mass_kg, inertia_kgm2, centre_m = wing_mass_properties(mech.scene)
    direction = np.array([np.cos(init.crank_angle_rad), np.sin(init.crank_angle_rad), 0.0])
    normal = np.array([-direction[1], direction[0], 0.0])
    wing_body = rigid_body("wing", mass_kg, inertia_kgm2, direction * centre_m,
                           init.crank_angle_rad,
                           normal * centre_m * init.crank_speed_rad_per_s,
                           init.crank_speed_rad_per_s)
    mech.wing = {"body": wing_body["bodyNumber"], "node": wing_body["nodeNumber"]}
    return body_marker(wing_body, [0.0, 0.0, 0.0])


class Builder:
    """Adds the items of one slider-crank to a new Exudyn system, in a fixed order (the
    order numbers the coordinates, so it is kept the same for every scene of a kind)."""

    #: index of the rotation about z among a rigid-body node's coordinates (x y z rx ry rz)
    rotation_coordinate = 5

    def __init__(self, scene: Scene, ffrf_joint_markers: str = "fewest", *,
                 link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> None:
        import exudyn as exu
        import exudyn.itemInterface as eii

        self.exu, self.eii = exu, eii
        self.scene = scene
        self.ffrf_joint_markers = ffrf_joint_markers
        self.init = initial_configuration(scene)
        system_container = exu.SystemContainer()
        self.mbs = system_container.AddSystem()
        #: the entry of each link's model (:mod:`flex.dynamics.link_models`)
        self.models = entries(scene, link_models)
        self.mech = Mechanism(system_container, self.mbs, scene, self.init,
                              models=self.models, link_models=link_models)
        self.ground = self.mbs.CreateGround()
        self.markers: dict[str, int] = {}
        self.crank_body: dict | None = None
        self.slider_body: dict = {}
        self.wing_joint: int | None = None
        self.joints: dict[str, int] = {}

    def rigid_body(self, name: str, mass_kg: float, inertia_kgm2: float, position,
                   angle_rad: float, velocity, angular_velocity_rad_per_s: float) -> dict:
        """A planar rigid body [kg, kg m^2, m, rad, m/s, rad/s]."""
        from exudyn.utilities import RigidBodyInertia

        # out-of-plane inertias do not enter planar motion; any positive, physically
        # admissible values will do, so take the in-plane one
        inertia = RigidBodyInertia(mass=mass_kg, inertiaTensor=np.eye(3) * inertia_kgm2)
        body = self.mbs.CreateRigidBody(
            name=name, inertia=inertia, referencePosition=list(position),
            referenceRotationMatrix=rotation_z(angle_rad), initialVelocity=list(velocity),
            initialAngularVelocity=[0.0, 0.0, angular_velocity_rad_per_s],
            nodeType=self.exu.NodeType.RotationRxyz, returnDict=True)
        self.mech.rigid_bodies[name] = (mass_kg, np.eye(3) * inertia_kgm2)
        return body

    def body_marker(self, body: dict, global_point) -> int:
        """A marker on ``body`` at ``global_point`` [m] (reference configuration)."""
        node = self.mbs.GetNode(body["nodeNumber"])
        reference = np.asarray(node["referenceCoordinates"][:3])
        rotation = rotation_z(node["referenceCoordinates"][5])
        local = rotation.T @ (np.asarray(global_point) - reference)
        return self.mbs.AddMarker(self.eii.MarkerBodyRigid(bodyNumber=body["bodyNumber"],
                                                           localPosition=list(local)))

    def add_crank_and_slider(self, crank_prepared: Any) -> None:
        """The crank (its model's: a rigid body before the slider, any other after the
        ground markers), the slider, the ground markers at A and C, and the wing welded at A
        when enabled."""
        scene, init, mbs, eii = self.scene, self.init, self.mbs, self.eii
        rigid = self.models["crank"].rigid
        if rigid:  # the order numbers the coordinates: kept as it always was
            self.crank_body = self.add_link("crank", crank_prepared)["rigid_body"]
        self.slider_body = self.add_slider()
        m = self.markers
        m["ground_A"] = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=self.ground,
                                                          localPosition=[0, 0, 0]))
        m["ground_C"] = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=self.ground,
                                                          localPosition=list(init.joint_C_m)))
        if not rigid:
            self.add_link("crank", crank_prepared)
        m["slider_C"] = self.body_marker(self.slider_body, init.joint_C_m)
        if scene["wing"]["enabled"]:
            wing_root = _add_wing(self.mech, self.rigid_body, self.body_marker)
            self.wing_joint = self.weld(m["crank_A"], wing_root)

    def weld(self, crank_root: int, wing_root: int) -> int:
        """Weld the wing's root marker to the crank's marker at A (a rigid-body marker, or
        the joint face of a flexible crank); return the joint. Its reaction torque is the
        wing root bending moment in the mechanism plane."""
        if "localHT" not in self.mbs.GetMarker(crank_root):  # a scene no check has seen:
            # a budget's companion one rung up (an exact-beam crank) was an internal error
            raise SceneError(f'crank.model = "{self.scene["crank"]["model"]}" carries no wing '
                             "(the weld at A needs a frame its nodes do not have); accepted: "
                             "wing.enabled = false")
        # both markers turned back by the crank angle: the weld frame is global at t = 0
        crank_rotation = rotation_z(self.init.crank_angle_rad)
        markers = [_turned_marker(self.mbs, marker, crank_rotation.T)
                   for marker in (crank_root, wing_root)]
        return self.mbs.AddObject(self.eii.ObjectJointGeneric(
            markerNumbers=markers, constrainedAxes=[1, 1, 1, 1, 1, 1]))

    def add_slider(self) -> dict:
        """The slider: a rigid body at joint C, not turned (its prismatic joint holds it)."""
        slider, init = self.scene["slider"], self.init
        return self.rigid_body("slider", slider_mass_kg(self.scene), slider["inertia_kgm2"],
                               init.joint_C_m, 0.0, init.joint_C_velocity_m_per_s, 0.0)

    def add_link(self, link: str, prepared: Any) -> dict[str, Any]:
        """Add ``link`` as its model adds it (:mod:`flex.dynamics.link_models`, point 5) and
        keep the handles it returns: its joint markers (``<link>_A``/``_B`` of the crank,
        ``_B``/``_C`` of the coupler) and, as ``mech.crank`` / ``mech.coupler``, the rest."""
        handles = self.models[link].add(self, link, prepared)
        first, second = ("A", "B") if link == "crank" else ("B", "C")
        self.markers[f"{link}_{first}"], self.markers[f"{link}_{second}"] = \
            handles["joint_markers"]
        setattr(self.mech, link, handles)
        return handles

    def add_coupler(self, prepared: Any) -> None:
        """The coupler B-C, as its model adds it (:meth:`add_link`)."""
        self.add_link("coupler", prepared)

    def _add_geometric_stiffness(self) -> None:
        """The softening of each FFRF link's bending modes under its own axial force
        (``<link>.geometric_stiffness``, true by default;
        :mod:`flex.bodies.geometric_stiffness`)."""
        from flex.bodies.geometric_stiffness import (
            add_geometric_stiffness,
            geometric_stiffness,
        )

        for name, link in (("coupler", self.mech.coupler), ("crank", self.mech.crank)):
            values = self.scene[name]
            if link.get("reduction") is not None and values["geometric_stiffness"]:
                link["geometric_data"] = geometric_stiffness(link["reduction"])
                link["geometric_stiffness"] = add_geometric_stiffness(
                    self.mbs, link["node_modal"], link["geometric_data"], name)

    def add_joints(self) -> None:
        """Revolute A and B, the in-plane pin C, the prismatic slide (or penalty springs for
        the explicit integrator)."""
        scene, mbs, eii, m = self.scene, self.mbs, self.eii, self.markers
        if scene["simulation"]["integrator"] == "explicit_penalty":
            # explicit solvers take no joint constraints (validate: rigid coupler only)
            joints = _add_penalty_joints(
                mbs, scene["simulation"]["penalty_stiffness_N_per_m"],
                min(plate_mass_properties(scene, "crank")[0], scene["slider"]["mass_kg"],
                    plate_mass_properties(scene)[0]),
                [(m["ground_A"], m["crank_A"]), (m["crank_B"], m["coupler_B"]),
                 (m["slider_C"], m["coupler_C"]), (m["ground_C"], m["slider_C"])],
                [self.crank_body["nodeNumber"], self.mech.coupler["node"],
                 self.slider_body["nodeNumber"]])
            self.joints = dict(zip("ABCP", joints, strict=True))
            self.mech.joint_frames = {"A": None, "B": None, "C": None, "P": None}
            return
        crank_ref = rotation_z(self.init.crank_angle_rad)
        # joint frames coincide with the global axes at t = 0; force outputs are in the frame
        # of marker 0, so marker 0 sits on a body that does not rotate (ground, slider) where
        # it can; the links' markers are turned by copies (_turned_marker)
        self.joints = {
            "A": mbs.AddObject(eii.ObjectJointSpherical(
                markerNumbers=[m["ground_A"], m["crank_A"]], constrainedAxes=[1, 1, 0]))
            if self.planar("crank") else mbs.AddObject(eii.ObjectJointRevoluteZ(
                markerNumbers=[m["ground_A"], _turned_marker(mbs, m["crank_A"], crank_ref.T)])),
            "B": self._joint_B(crank_ref),
            "C": mbs.AddObject(eii.ObjectJointSpherical(
                markerNumbers=[m["slider_C"], m["coupler_C"]], constrainedAxes=[1, 1, 0])),
            "P": mbs.AddObject(eii.ObjectJointPrismaticX(
                markerNumbers=[m["ground_C"], m["slider_C"]]))}
        # B's force is reported in the frame of the crank's marker at B (its joint face when
        # the crank is flexible), turned back by the initial crank angle: collect turns it
        # with that marker's rotation since t = 0 (a planar pin's in global axes)
        self.mech.joint_frames = {"A": None, "B": None if self.planar_B else
                                  "marker_crank_B", "C": None, "P": None}
        self._add_geometric_stiffness()

    def planar(self, link: str) -> bool:
        """Whether ``link``'s joint markers carry x and y only (a planar beam's nodes, its
        handles' ``planar_pins``): its pins then hold x and y (a 3D coupler's z and tilts are
        held by its revolute joint at B, a 3D crank's by the one at A)."""
        handles = self.mech.coupler if link == "coupler" else self.mech.crank
        return bool(handles.get("planar_pins", False))

    @property
    def planar_B(self) -> bool:
        """Whether the pin at B holds x and y only: a planar coupler or crank (a planar crank
        has a planar coupler: :func:`flex.data.plates.check_beam_plate`)."""
        return self.planar("coupler") or self.planar("crank")

    def _joint_B(self, crank_ref: np.ndarray) -> int:
        """The revolute joint at B (a pin in x and y on a planar link)."""
        mbs, eii, m = self.mbs, self.eii, self.markers
        if self.planar_B:
            return mbs.AddObject(eii.ObjectJointSpherical(
                markerNumbers=[m["crank_B"], m["coupler_B"]], constrainedAxes=[1, 1, 0]))
        coupler_ref = rotation_z(self.init.coupler_angle_rad)
        return mbs.AddObject(eii.ObjectJointRevoluteZ(
            markerNumbers=[_turned_marker(mbs, m["crank_B"], crank_ref.T),
                           _turned_marker(mbs, m["coupler_B"], coupler_ref.T)]))

    def add_drive(self) -> None:
        """The preloaded spring on the slider, or the crank held at constant speed."""
        drive, mbs, eii = self.scene["drive"], self.mbs, self.eii
        ground_node = mbs.AddNode(eii.NodePointGround())
        ground_coordinate = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground_node,
                                                                   coordinate=0))
        if drive["kind"] == "spring":
            slider_x = mbs.AddMarker(eii.MarkerNodeCoordinate(
                nodeNumber=self.slider_body["nodeNumber"], coordinate=0))
            chain = spring_chain(self.scene)
            if chain is not None:
                self._add_spring_chain(chain, ground_coordinate, slider_x)
                return
            # slider coordinate = displacement from t = 0; spring force k (q + preload) pushes -x
            mbs.AddObject(eii.ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[ground_coordinate, slider_x],
                stiffness=drive["spring_stiffness_N_per_m"],
                damping=drive["spring_damping_Ns_per_m"], offset=-drive["spring_preload_m"]))
            return
        crank_rotation = mbs.AddMarker(eii.MarkerNodeCoordinate(  # rigid crank (validate)
            nodeNumber=self.crank_body["nodeNumber"], coordinate=self.rotation_coordinate))
        # velocity-level constraint: no Python callback per step, crank speed held exactly
        mbs.AddObject(eii.ObjectConnectorCoordinate(
            markerNumbers=[ground_coordinate, crank_rotation], velocityLevel=True,
            offset=drive["crank_speed_rad_per_s"]))

    def _add_spring_chain(self, chain: SpringChain, ground_coordinate: int,
                          slider_x: int) -> None:
        """The spring as a chain (:class:`SpringChain`) from the slider's x coordinate
        (marker ``slider_x``) to the frame's (``ground_coordinate``): inner point masses on
        the slide line (1D nodes: their x displacement from t = 0, at rest) joined by
        coordinate springs; each spring's frame side is its marker 0, as the massless one's."""
        mbs, eii = self.mbs, self.eii
        nodes = [mbs.AddNode(eii.Node1D(referenceCoordinates=[0.0]))
                 for _ in range(chain.segments - 1)]
        for node in nodes:
            mbs.AddObject(eii.ObjectMass1D(mass=chain.inner_mass_kg, nodeNumber=node,
                                           referencePosition=list(self.init.joint_C_m)))
        ends = [slider_x, *(mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=node,
                                                                   coordinate=0))
                            for node in nodes), ground_coordinate]
        for slider_side, frame_side in zip(ends[:-1], ends[1:], strict=True):
            mbs.AddObject(eii.ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[frame_side, slider_side],
                stiffness=chain.segment_stiffness_N_per_m,
                damping=chain.segment_damping_Ns_per_m, offset=-chain.segment_preload_m))
        for index, node in enumerate(nodes):
            for output in ("Coordinates", "Coordinates_t"):
                self.add(f"spring_chain.{index}.{output}",
                         self.sensor("Node", output, nodeNumber=node))
        self.mech.spring_chain = {"chain": chain, "nodes": nodes}

    def add(self, name: str, sensor) -> None:
        self.mech.sensors[name] = self.mbs.AddSensor(sensor)

    def sensor(self, kind: str, output: str, **item: int):
        """An Exudyn sensor (``kind``: Node, Object, Marker, Body) stored internally."""
        return getattr(self.eii, f"Sensor{kind}")(
            storeInternal=True, outputVariableType=getattr(self.exu.OutputVariableType,
                                                           output), **item)

    def add_sensors(self) -> None:
        """What :func:`flex.dynamics.collect.collect` reads: bodies, joints, markers, energies."""
        if self.wing_joint is not None:
            for output in ("Velocity", "Rotation", "AngularVelocity", "AngularAcceleration"):
                self.add(f"wing.{output}",
                         self.sensor("Node", output, nodeNumber=self.mech.wing["node"]))
            self._add_weld_sensors()
        for name, body in (("crank", self.crank_body), ("slider", self.slider_body)):
            if body is not None:  # None: a flexible crank, its markers below
                self._add_body_sensors(name, body)
        for link, model in self.models.items():  # the link model's own (point 6)
            model.sensors(self, link, getattr(self.mech, link))
        self._add_joint_sensors()
        self._add_marker_sensors()

    def _add_body_sensors(self, name: str, body: dict) -> None:
        """Motion of a rigid body's node (its centre of mass), as ``<name>.<output>``."""
        for output in ("Position", "Velocity", "Acceleration", "Rotation",
                       "AngularVelocity", "AngularAcceleration"):
            self.add(f"{name}.{output}",
                     self.sensor("Node", output, nodeNumber=body["nodeNumber"]))

    def _add_weld_sensors(self) -> None:
        """The wing weld's force and torque, in the weld frame (read by collect)."""
        for output in ("ForceLocal", "TorqueLocal"):
            self.add(f"joint_W.{output}",
                     self.sensor("Object", output, objectNumber=self.wing_joint))

    def _add_joint_sensors(self) -> None:
        """The forces of joints A, B, C and P, and the frame B's force is reported in."""
        penalty = self.scene["simulation"]["integrator"] == "explicit_penalty"
        for name, joint in self.joints.items():
            # the spherical joint reports its force in global axes ("Force"), the others in
            # the frame of marker 0 ("ForceLocal")
            global_axes = (name == "C" or (name == "B" and self.planar_B)
                           or (name == "A" and self.planar("crank")))
            output = "Force" if global_axes or penalty else "ForceLocal"
            self.add(f"joint_{name}.Force", self.sensor("Object", output, objectNumber=joint))
        if not (penalty or self.planar("crank")):  # a planar crank's marker has no frame
            self.add("marker_crank_B.Rotation",
                     self.sensor("Marker", "Rotation", markerNumber=self.markers["crank_B"]))

    def _add_marker_sensors(self) -> None:
        """Joint-marker positions (the constraint norm in collect)."""
        for name in ("ground_A", "crank_A", "crank_B", "coupler_B", "coupler_C", "slider_C"):
            self.add(f"marker_{name}.Position",
                     self.sensor("Marker", "Position", markerNumber=self.markers[name]))
        self.mech.constraint_points = [("ground_A", "crank_A"), ("crank_B", "coupler_B"),
                                       ("coupler_C", "slider_C")]

