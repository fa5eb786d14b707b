"""A plate link as a planar geometrically exact beam (Simo and Reissner, with shear).

The link is the rectangular plate of :mod:`flex.experiments.thesis.beams` (length L along x,
thickness t
in the mechanism plane, the height of its in-plane bending, width w out of it), modelled as
``elements`` two-node ``ObjectBeamGeometricallyExact2D`` elements of Exudyn (Simo and Vu-Quoc:
axial, shear and bending strain of large displacements and rotations, one integration point;
``NodeRigidBody2D`` nodes: x, y and the cross-section's rotation, in the plane z = 0). Its
section (:func:`exact_beam_section`) is that of the plate: axial stiffness E A, bending
stiffness E I (I = w t^3 / 12), shear stiffness kappa G A (kappa: the rectangle's Timoshenko
shear correction :data:`flex.base.physics.SHEAR_CORRECTION_RECTANGLE`), mass rho A and rotary
inertia rho I per length.

:func:`add_exact_beam_link` adds the beam to an Exudyn system between two joint points with
the initial motion of the link as a rigid body and returns an :class:`ExactBeamLink`: its
nodes, elements and the position markers of its ends and midpoint. The 2D nodes have no z
coordinate: a joint on them may constrain x and y only (e.g. ``ObjectJointSpherical`` with
``constrainedAxes = [1, 1, 0]``, or ``ObjectJointRevolute2D``).

Stresses (:func:`section_stress_peaks`): from each element's axial force N, shear force Q
and bending moment M (constant along a two-node element), the outer fibre's normal stress
|N| / A + |M| c / I (c = t / 2) and the largest von Mises stress over the section's height
with the parabolic shear stress of a rectangle, 3 Q / (2 A) (1 - (y / c)^2).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from flex.base import physics
from flex.base.channel import ChannelFilter
from flex.base.physics import SHEAR_CORRECTION_RECTANGLE, check_positive, rectangle_section
from flex.data.results import Dataset

#: fibres across the section's height at which the von Mises stress is evaluated (odd: the
#: neutral axis, where the shear stress peaks, is one of them)
VON_MISES_FIBRES = 21


@dataclass(frozen=True)
class ExactBeamSection:
    """The section of a rectangular plate link as a beam, SI units."""

    length_m: float
    thickness_m: float
    width_m: float
    area_m2: float
    second_moment_m4: float
    axial_stiffness_N: float
    bending_stiffness_Nm2: float
    shear_stiffness_N: float
    mass_per_length_kg_per_m: float
    rotary_inertia_kg_m: float
    #: its calibration against the 3-D plate (:meth:`flex.bodies.beam_calibration.
    #: BeamCalibration.attrs`; empty: the uncalibrated section)
    calibration: Mapping[str, float] = field(default_factory=dict)

    @property
    def outer_fibre_m(self) -> float:
        """Distance c of the outer fibre from the neutral axis [m]: t / 2."""
        return 0.5 * self.thickness_m


def exact_beam_section(plate: physics.Plate,
                       shear_correction: float = SHEAR_CORRECTION_RECTANGLE
                       ) -> ExactBeamSection:
    """The beam section of a ``length_m`` x ``thickness_m`` x ``width_m`` plate [m] of its
    material: E A, E I, kappa G A, rho A, rho I (see the module doc)."""
    length_m, thickness_m, width_m = plate.sizes_m
    youngs_modulus_Pa, density_kg_per_m3 = plate.youngs_modulus_Pa, plate.density_kg_per_m3
    check_positive(length_m=length_m, youngs_modulus_Pa=youngs_modulus_Pa,
                   density_kg_per_m3=density_kg_per_m3)
    section = rectangle_section(thickness_m, width_m)
    area, inertia = section.area_m2, section.second_moment_m4
    shear_modulus = physics.shear_modulus_Pa(youngs_modulus_Pa, plate.poisson_ratio)
    return ExactBeamSection(
        length_m, thickness_m, width_m, area, inertia, youngs_modulus_Pa * area,
        youngs_modulus_Pa * inertia, shear_correction * shear_modulus * area,
        density_kg_per_m3 * area, density_kg_per_m3 * inertia)


@dataclass(frozen=True)
class ExactBeamLink:
    """What :func:`add_exact_beam_link` added: node and element (object) numbers, from the
    first end to the second, and the position markers of the ends and the midpoint (a node
    marker for an even number of elements, else a body marker at the middle element's
    centre). ``midpoint_node``: the middle node, or None for an odd number of elements."""

    nodes: tuple[int, ...]
    elements: tuple[int, ...]
    marker_start: int
    marker_end: int
    marker_mid: int
    midpoint_node: int | None
    element_length_m: float

    def handles(self) -> dict[str, Any]:
        """The link as a builder's coupler takes it: ``marker_B``, ``marker_C`` (its ends),
        ``marker_mid``, ``nodes``, ``elements``, ``planar_pins`` (its end markers carry
        x, y only)."""
        return {"marker_B": self.marker_start, "marker_C": self.marker_end,
                "marker_mid": self.marker_mid, "nodes": list(self.nodes),
                "elements": list(self.elements), "planar_pins": True}


def add_exact_beam_link(mbs: Any, section: ExactBeamSection, elements: int, start_m: Any,
                        angle_rad: float, velocity_start_m_per_s: Any = (0.0, 0.0),
                        angular_velocity_rad_per_s: float = 0.0) -> ExactBeamLink:
    """Add the link as ``elements`` beam elements from ``start_m`` (x, y [m]; a z component
    is ignored) along ``angle_rad`` from +x, its length ``section.length_m``, moving as a
    rigid body: the start point at ``velocity_start_m_per_s`` (x, y), turning at
    ``angular_velocity_rad_per_s`` about z. Undeformed at t = 0."""
    import exudyn.itemInterface as eii

    if not (isinstance(elements, int | np.integer) and elements >= 1):
        raise ValueError(f"elements = {elements!r}: must be an integer >= 1")
    direction = np.array([np.cos(angle_rad), np.sin(angle_rad)])
    normal = np.array([-direction[1], direction[0]])
    start, velocity = np.asarray(start_m, float)[:2], np.asarray(velocity_start_m_per_s,
                                                                 float)[:2]
    length_m = section.length_m / elements
    nodes = []
    for index in range(elements + 1):
        arm = index * length_m
        point = start + arm * direction
        node_velocity = velocity + angular_velocity_rad_per_s * arm * normal
        nodes.append(mbs.AddNode(eii.NodeRigidBody2D(
            referenceCoordinates=[point[0], point[1], 0.0],
            initialVelocities=[node_velocity[0], node_velocity[1],
                               angular_velocity_rad_per_s])))
    objects = tuple(mbs.AddObject(eii.ObjectBeamGeometricallyExact2D(
        nodeNumbers=[first, second], length=length_m,
        massPerLength=section.mass_per_length_kg_per_m,
        crossSectionInertia=section.rotary_inertia_kg_m,
        bendingStiffness=section.bending_stiffness_Nm2,
        axialStiffness=section.axial_stiffness_N, shearStiffness=section.shear_stiffness_N))
        for first, second in zip(nodes[:-1], nodes[1:], strict=True))
    markers = [mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=node))
               for node in (nodes[0], nodes[-1])]
    if elements % 2 == 0:
        middle = nodes[elements // 2]
        marker_mid = mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=middle))
    else:
        middle = None
        marker_mid = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=objects[elements // 2],
                                                          localPosition=[0.0, 0.0, 0.0]))
    return ExactBeamLink(tuple(nodes), objects, markers[0], markers[1], marker_mid, middle,
                         length_m)


def element_centres_m(section: ExactBeamSection, elements: int) -> np.ndarray:
    """Distance of each element's centre from the link's first end [m]."""
    return (np.arange(elements) + 0.5) * section.length_m / elements


def section_stress_peaks(section: ExactBeamSection, axial_N: np.ndarray, shear_N: np.ndarray,
                         moment_Nm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per sample and element (arrays of shape (samples, elements)): the outer fibre's
    normal stress |N| / A + |M| c / I [Pa] and the section's largest von Mises stress [Pa]
    (normal N / A + M y / I and shear 3 Q / (2 A) (1 - (y / c)^2) at
    :data:`VON_MISES_FIBRES` heights y)."""
    area, inertia, c = section.area_m2, section.second_moment_m4, section.outer_fibre_m
    axial, shear, moment = (np.asarray(a, float) for a in (axial_N, shear_N, moment_Nm))
    normal = np.abs(axial) / area + np.abs(moment) * c / inertia
    heights = np.linspace(-c, c, VON_MISES_FIBRES)
    sigma = axial[..., None] / area + moment[..., None] * heights / inertia
    tau = 1.5 * shear[..., None] / area * (1.0 - (heights / c) ** 2)
    von_mises = np.sqrt(sigma**2 + 3.0 * tau**2).max(axis=-1)
    return normal, von_mises


def section_datasets(link: str, section: ExactBeamSection, force_N: np.ndarray,
                     moment_Nm: np.ndarray, low_pass: ChannelFilter | None = None,
                     channel: str = "") -> dict[str, Dataset]:
    """The stored series of a beam ``link`` from its elements' section forces ``force_N``
    (samples, elements, 2: axial N, shear Q) and moments ``moment_Nm`` (samples, elements):
    ``<link>/axial_force`` at the midpoint, ``peak_bending_stress`` and
    ``peak_von_mises_stress`` away from the end faces (elements whose centre lies one
    thickness or more from both, as the FFRF link's window; the middle element of a plate
    too stubby for it), where that peak is (``peak_von_mises_position``, from the first
    end) and ``peak_von_mises_stress_at_joints`` (the other elements). With the headline
    channel's filter ``low_pass`` (:func:`flex.base.channel.channel_filter`; ``channel``: how
    its series say so) also ``channel/<link>/peak_bending_stress`` and
    ``channel/<link>/peak_von_mises_stress``: the same peaks of the low-passed section forces
    (a peak series low-passed would rectify the field's ringing, :mod:`flex.base.channel`)."""
    out = _section_peaks(link, section, force_N, moment_Nm)
    if low_pass is not None:
        smooth = _section_peaks(link, section, low_pass(force_N), low_pass(moment_Nm))
        out.update({f"channel/{path}": Dataset(smooth[path].data, "Pa",
                                               f"{smooth[path].description}, {channel}")
                    for path in (f"{link}/peak_bending_stress", f"{link}/peak_von_mises_stress")})
    return out


def _section_peaks(link: str, section: ExactBeamSection, force_N: np.ndarray,
                   moment_Nm: np.ndarray) -> dict[str, Dataset]:
    """:func:`section_datasets` without the channel."""
    count = force_N.shape[1]
    normal, von_mises = section_stress_peaks(section, force_N[..., 0], force_N[..., 1],
                                             moment_Nm)
    centres = element_centres_m(section, count)
    half = 0.5 * section.length_m
    away = np.abs(centres - half) <= half - section.thickness_m
    middle = [count // 2] if count % 2 else [count // 2 - 1, count // 2]
    away[middle] = True  # a plate too stubby for the window (t >= L / 2: none was away)
    out = {
        f"{link}/axial_force": Dataset(force_N[:, middle, 0].mean(axis=1), "N",
                                       "axial force at the midpoint (tension > 0)"),
        f"{link}/peak_bending_stress": Dataset(
            normal[:, away].max(axis=1), "Pa", "largest |sigma_xx| at the outer fibres away "
            "from the end faces (|N| / A + |M| c / I)"),
        f"{link}/peak_von_mises_stress": Dataset(
            von_mises[:, away].max(axis=1), "Pa",
            "largest von Mises stress away from the end faces (beam section)"),
        f"{link}/peak_von_mises_position": Dataset(
            centres[away][np.argmax(von_mises[:, away], axis=1)], "m",
            "where the peak von Mises stress away from the end faces is, from the first end")}
    if not away.all():
        out[f"{link}/peak_von_mises_stress_at_joints"] = Dataset(
            von_mises[:, ~away].max(axis=1), "Pa",
            "largest von Mises stress within one thickness of the end faces (beam section)")
    return out
