"""Flexible links: NGsolve plate mesh -> Hurty-Craig-Bampton reduction -> Exudyn FFRF body.

The building block of the flexible slider-crank (coupler between B and C, crank between A
and B: the same plate reduction, ``end_a`` at the link's first joint). :func:`build_reduction`
meshes a steel plate (:func:`flex.bodies.plate.plate_mesh`, second-order tetrahedra), reduces it
with Hurty-Craig-Bampton modes whose two interfaces are the joint faces ``end_a`` (joint B)
and ``end_b`` (joint C), adds stress post-processing modes and caches the result in one HDF5
file.
:func:`add_ffrf_link` puts the reduced body into an Exudyn ``MainSystem`` with markers at
B, C and the midpoint. :func:`midpoint_deflection` and :func:`bending_stress_history` turn
simulation output into the elastic quantities the study reports.

Body coordinates (metres) are the mesh's: x along the link from the centre of ``end_a``
(x = 0, joint B) to the centre of ``end_b`` (x = length, joint C), y across the thickness
(in the mechanism plane, the bending height), z across the width (out of plane).

Mode basis (a chord frame): static modes and ``modes`` fixed-interface eigenmodes (both end
faces clamped). The static modes are ``end_b``'s axial translation and rotations and
``end_a``'s rotations about the transverse axes, each a rigid motion of its face carried into
the plate by static condensation; no mode moves the centre of ``end_a`` or moves the centre
of ``end_b`` off the x axis. The floating frame therefore has its origin at joint B and its x
axis on the chord B-C, whatever the link's bending: a rigid-body motion of the frame *is*
the chord's. Both end faces stay rigid (RBE2-like), as a pin through a stiff eye would keep
them. By default only the in-plane modes are kept (3 static: ``end_b`` along x, ``end_a`` and
``end_b`` turned about z; the lowest ``modes`` eigenmodes symmetric about the mechanism
plane): a planar mechanism loads its links in plane, and torsion and out-of-plane bending
are decoupled from that load by symmetry.

Why the chord frame and not Exudyn's default (the frame on the ``end_a`` face, ``end_b``
translating across it): the axial force of a pinned link acts along its chord. With the frame
on the face, a bent link's chord is turned against the frame and the linear body puts the
axial force through that turn: compression *stiffens* it (the wrong sign), and the
geometric stiffness that corrects it must cancel large frame-rotation terms, which made it
fail Newton with more than one mode. In the chord frame the axial force is along the frame's
x axis: the linear body is blind to it (no stiffening, no softening) and
:mod:`flex.bodies.geometric_stiffness` adds exactly the missing softening
(docs/geometric-stiffness.md).
"""

from flex.bodies.reduction.body import (
    JOINT_MARKERS,
    RIGID_FACE_TOLERANCE,
    MidpointDeflection,
    add_ffrf_link,
    add_plate_markers,
    as_vector3,
    bending_stress_history,
    midpoint_deflection,
)
from flex.bodies.reduction.build import (
    END_A,
    END_B,
    MESH_ORDER,
    MID,
    MODE_SELECTIONS,
    Reduction,
    build_reduction,
    unit_sum,
)
from flex.bodies.reduction.cache import CACHE_FORMAT_VERSION, reduction_cache_dir

__all__ = ["CACHE_FORMAT_VERSION", "END_A", "END_B", "JOINT_MARKERS", "MESH_ORDER", "MID",
           "MODE_SELECTIONS", "RIGID_FACE_TOLERANCE", "MidpointDeflection", "Reduction",
           "add_ffrf_link", "add_plate_markers", "as_vector3", "bending_stress_history",
           "build_reduction", "midpoint_deflection", "reduction_cache_dir", "unit_sum"]
