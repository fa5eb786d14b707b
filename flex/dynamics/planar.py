"""Planar build of the rigid slider-crank: 2D items, the 3D model's datasets.

A rigid scene moves in the x-y plane only, so half of the 3D model
(:mod:`flex.dynamics.mechanism`: 18 coordinates, 17 constraints, a 35 x 35 Newton system)
only holds coordinates that never move. Here crank and coupler are ``NodeRigidBody2D`` +
``ObjectRigidBody2D`` (x, y, angle), A, B and C are ``RevoluteJoint2D`` s, and the slider
is a point mass on the slide line (``Node1D`` + ``ObjectMass1D``: its x only; its y and
angle are no coordinates, so the slide line needs no constraint): 7 coordinates, 6
constraints (one degree of freedom), a 13 x 13 Newton system. Measured on the thesis
deployment at h = 1e-5 s (one Newton iteration per step): 6.5 us per step with collect's 25
sensors (5 us without) against 24.6 us in 3D, where the factorization and the numerically
differentiated Jacobian of the rotation coordinates took 60 %; the datasets equal the 3D
ones to the Newton tolerance (tests/test_planar.py). Exudyn's cost here goes by item more
than by coordinate: a 2D slider held by two coordinate constraints (y, angle) costs 2 us
more per step than the 1D one.

Used automatically (:func:`flex.dynamics.mechanism.build_mechanism`) where the scene needs
nothing 3D (:func:`is_planar`). The drive (spring or constant speed), the welded wing and
the sensor names are those of the 3D builder, which this one extends; the joint loads are
read by their own rules (:func:`joint_forces`, :func:`weld_loads`), so that
:func:`flex.dynamics.collect.collect` gives the same datasets (names, units, signs, frames).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from flex.data.fields import AUTO
from flex.data.scene import LINKS, Scene, link_model
from flex.dynamics.builder import Builder, Mechanism, slider_mass_kg
from flex.dynamics.link_models import BUILTIN_LINK_MODELS


def is_planar(scene: Scene, link_models: Mapping[str, Any] = BUILTIN_LINK_MODELS) -> bool:
    """Whether ``scene`` can be built with 2D items and give the 3D model's results.

    Needs rigid crank and coupler (the FFRF and nonlinear FE bodies are 3D meshes) and an
    implicit integrator (``explicit_penalty`` keeps its 3D penalty joints, whose out-of-plane
    coordinate constraints the explicit solvers eliminate).
    """
    return (all(scene[link]["model"] != AUTO
                and link_model(link, scene[link], link_models).rigid for link in LINKS)
            and scene["simulation"]["integrator"] != "explicit_penalty")


class PlanarBuilder(Builder):
    """The 3D builder's order and sensor names with 2D bodies and joints and a 1D slider."""

    #: index of the angle among a 2D rigid-body node's coordinates (x y angle)
    rotation_coordinate = 2

    def __init__(self, scene: Scene, *,
                 link_models: Mapping[str, Any] = BUILTIN_LINK_MODELS) -> None:
        super().__init__(scene, link_models=link_models)
        self.mech.planar = True
        self.wing_angle_joint: int | None = None

    def rigid_body(self, name: str, mass_kg: float, inertia_kgm2: float, position,
                   angle_rad: float, velocity, angular_velocity_rad_per_s: float) -> dict:
        """A 2D rigid body [kg, kg m^2, m, rad, m/s, rad/s] with its node at the centre of
        mass; returns ``{"bodyNumber", "nodeNumber"}`` as the 3D builder's does."""
        node = self.mbs.AddNode(self.eii.NodeRigidBody2D(
            referenceCoordinates=[position[0], position[1], angle_rad],
            initialVelocities=[velocity[0], velocity[1], angular_velocity_rad_per_s]))
        body = self.mbs.AddObject(self.eii.ObjectRigidBody2D(
            name=name, mass=mass_kg, inertia=inertia_kgm2, nodeNumber=node))
        # the energy in collect takes a 3 x 3 inertia; only its z entry meets a planar
        # angular velocity (0, 0, omega)
        self.mech.rigid_bodies[name] = (mass_kg, np.eye(3) * inertia_kgm2)
        return {"bodyNumber": body, "nodeNumber": node}

    def add_slider(self) -> dict:
        """The slider as a mass moving along x from joint C (its one coordinate: the x
        displacement, as the 3D slider node's first one, which the spring acts on)."""
        slider, init = self.scene["slider"], self.init
        mass_kg = slider_mass_kg(self.scene)  # with a chain spring's end share
        node = self.mbs.AddNode(self.eii.Node1D(
            referenceCoordinates=[0.0], initialVelocities=[init.joint_C_velocity_m_per_s[0]]))
        body = self.mbs.AddObject(self.eii.ObjectMass1D(
            name="slider", mass=mass_kg, nodeNumber=node,
            referencePosition=list(init.joint_C_m)))
        self.mech.rigid_bodies["slider"] = (mass_kg, np.eye(3) * slider["inertia_kgm2"])
        return {"bodyNumber": body, "nodeNumber": node, "sliding": True}

    def body_marker(self, body: dict, global_point) -> int:
        """A marker on ``body`` at ``global_point`` [m] (reference configuration): a rigid
        marker on a 2D body, a position marker on the slider (which does not turn)."""
        if body.get("sliding"):
            return self.mbs.AddMarker(self.eii.MarkerBodyPosition(
                bodyNumber=body["bodyNumber"],
                localPosition=list(np.asarray(global_point) - self.init.joint_C_m)))
        x, y, angle = self.mbs.GetNode(body["nodeNumber"])["referenceCoordinates"]
        c, s = np.cos(angle), np.sin(angle)
        dx, dy = np.asarray(global_point)[:2] - np.array([x, y])
        return self.mbs.AddMarker(self.eii.MarkerBodyRigid(
            bodyNumber=body["bodyNumber"], localPosition=[c * dx + s * dy, -s * dx + c * dy,
                                                          0.0]))

    def add_joints(self) -> None:
        """Revolute A, B and C, with the 3D joints' marker order (so each force keeps its
        side); the slide line is the slider's own (1D) kinematics."""
        m = self.markers
        revolute = {"A": (m["ground_A"], m["crank_A"]), "B": (m["crank_B"], m["coupler_B"]),
                    "C": (m["slider_C"], m["coupler_C"])}
        self.joints = {name: self.mbs.AddObject(self.eii.ObjectJointRevolute2D(
            markerNumbers=list(markers))) for name, markers in revolute.items()}
        self.mech.joint_frames = {"A": None, "B": None, "C": None, "P": None}

    def weld(self, crank_root: int, wing_root: int) -> int:
        """The wing welded to the crank at A: a revolute joint (the root force) and the
        wing's angle held to the crank's (the root moment); returns the revolute joint."""
        crank, wing = self.crank_body["nodeNumber"], self.mech.wing["node"]
        self.wing_angle_joint = self.mbs.AddObject(self.eii.ObjectConnectorCoordinate(
            markerNumbers=[self._angle_marker(crank), self._angle_marker(wing)]))
        return self.mbs.AddObject(self.eii.ObjectJointRevolute2D(
            markerNumbers=[crank_root, wing_root]))

    def _angle_marker(self, node: int) -> int:
        return self.mbs.AddMarker(self.eii.MarkerNodeCoordinate(
            nodeNumber=node, coordinate=self.rotation_coordinate))

    def _add_body_sensors(self, name: str, body: dict) -> None:
        """As the 3D builder's, but the slider's from its body (a 1D node has coordinates
        only): position, velocity, rotation (0) and angular velocity (0) as 3-vectors;
        acceleration as the node's x acceleration (collect reads only that column)."""
        if not body.get("sliding"):
            super()._add_body_sensors(name, body)
            return
        for output in ("Position", "Velocity", "Rotation", "AngularVelocity"):
            self.add(f"{name}.{output}", self.eii.SensorBody(
                bodyNumber=body["bodyNumber"], storeInternal=True,
                outputVariableType=getattr(self.exu.OutputVariableType, output)))
        self.add(f"{name}.Acceleration",
                 self.sensor("Node", "Coordinates_tt", nodeNumber=body["nodeNumber"]))

    def _add_weld_sensors(self) -> None:
        self.add("joint_W.Force", self.sensor("Object", "Force", objectNumber=self.wing_joint))
        self.add("joint_W.Torque",
                 self.sensor("Object", "Force", objectNumber=self.wing_angle_joint))

    def _add_joint_sensors(self) -> None:
        """Forces of A, B and C (global axes); P follows from C (:func:`joint_forces`)."""
        for name, joint in self.joints.items():
            self.add(f"joint_{name}.Force", self.sensor("Object", "Force", objectNumber=joint))


def _stored(mech: Mechanism, name: str) -> np.ndarray:
    return np.asarray(mech.mbs.GetSensorStoredData(mech.sensors[name]))


def joint_forces(mech: Mechanism) -> dict[str, np.ndarray]:
    """Force on each joint's second body [N], (n, 2) in global x, y: ``A`` (frame on crank),
    ``B`` (crank on coupler), ``C`` (slider on coupler), ``P`` (frame on slider).

    A 2D joint reports its Lagrange multipliers, the force on its first body (marker 0) in
    global axes, as the 3D joints do. The slide line is no joint here: its force on the
    slider is what holds the slider on the line, -(C's force on the slider) across it (the
    slider never accelerates across the line, and nothing else pushes it across), and none
    along it (no friction); the 3D prismatic joint's multipliers agree to the Newton
    tolerance.
    """
    forces = {name: -_stored(mech, f"joint_{name}.Force")[:, 1:3] for name in "ABC"}
    across = forces["C"][:, 1]  # -(coupler on slider) = slider on coupler, y
    forces["P"] = np.column_stack([np.zeros_like(across), across])
    return forces


def weld_loads(mech: Mechanism) -> tuple[np.ndarray, np.ndarray]:
    """The weld's loads with the 3D weld's signs: the crank's force on the wing (n, 2) [N]
    in global x, y, and the in-plane root moment (n,) [N m] about z.

    The force is minus the revolute joint's multipliers (they act on the crank, marker 0).
    The moment is the angle constraint's multiplier (wing angle minus crank angle), the
    moment on the crank: the 3D weld's ``-TorqueLocal`` is that one too, i.e. the wing's
    moment on the crank, -J_A alpha (measured), not the crank's on the wing.
    """
    return -_stored(mech, "joint_W.Force")[:, 1:3], _stored(mech, "joint_W.Torque")[:, 1]


__all__ = ["is_planar", "PlanarBuilder", "joint_forces", "weld_loads"]
