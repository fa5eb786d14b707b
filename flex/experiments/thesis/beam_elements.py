"""Beam finite elements: an emulation of the thesis's ANSYS BEAM188 link models (Tables 7, 9).

:func:`beam_element_modes` builds a link from 3D two-node linear Timoshenko beam elements, as
ANSYS documents BEAM188 with its default KEYOPT(3) = 0 (ANSYS Theory Reference, BEAM188):
linear interpolation of the three displacements and three rotations, stiffness integrated with
one point along the length (reduced integration: no shear locking), consistent mass with
rotary (rho I) and torsional (rho I_p) inertia. Axes as :mod:`flex.experiments.thesis.beams` (x
along the link,
thickness along y, width along z); SI units throughout, frequencies in rad/s and Hz.
"""

from __future__ import annotations

import math

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import SHEAR_CORRECTION_RECTANGLE, check_positive, rectangle_section
from flex.experiments.thesis.beams import (
    LINK_BOUNDARY_CONDITIONS,
    THESIS_STEEL,
    BeamLinkModes,
    Material,
    check_choice,
    check_count,
    weak_plane_bending_rad_per_s,
)

# Per boundary condition: local DOFs [ux, uy, uz, rot_x, rot_y, rot_z] fixed at the first node
# (x = 0) and at the last node (x = L). Rotation about z (the joint axis) is always free.
_BEAM_FIXED_DOFS = {
    "free-free": ((), ()),
    "pinned-pinned": ((0, 1, 2, 3, 4), (0, 1, 2, 3, 4)),
    "pinned-roller": ((0, 1, 2, 3, 4), (1, 2, 3, 4)),
}
_KIND_OF_COMPONENT = {0: "axial", 1: "in-plane bending", 2: "out-of-plane bending",
                      3: "torsion"}


def _assemble_beam(length_m: float, thickness_m: float, width_m: float, element_count: int,
                   material: Material, shear_correction: float, torsion_constant_m4: float):
    """Global stiffness [N/m, N m/rad] and consistent mass [kg, kg m^2] (scipy CSR, 6 DOFs
    per node: ux, uy, uz, rot_x, rot_y, rot_z) of ``element_count`` equal elements."""
    import scipy.sparse as sp

    section = rectangle_section(thickness_m, width_m)
    youngs_Pa, shear_Pa = material.youngs_modulus_Pa, material.shear_modulus_Pa
    density = material.density_kg_per_m3
    area = section.area_m2
    inertia_y_bending = section.second_moment_m4        # uy deflection, rotation about z
    inertia_z_bending = section.second_moment_other_m4  # uz deflection, rotation about y
    element_length = length_m / element_count
    dof_count = 6 * (element_count + 1)
    # Element matrices are collected as (rows, cols, values) and summed by the sparse
    # constructor: long converged models (hundreds of elements) stay cheap.
    triplets: dict[str, list[np.ndarray]] = {"rows": [], "cols": [], "stiffness": [],
                                              "mass": []}

    def scatter(dofs: list[int], element_stiffness: np.ndarray,
                element_mass: np.ndarray) -> None:
        rows, cols = np.meshgrid(dofs, dofs, indexing="ij")
        triplets["rows"].append(rows.ravel())
        triplets["cols"].append(cols.ravel())
        triplets["stiffness"].append(element_stiffness.ravel())
        triplets["mass"].append(element_mass.ravel())

    rod_stiffness = np.array([[1.0, -1.0], [-1.0, 1.0]]) / element_length
    rod_mass = np.array([[2.0, 1.0], [1.0, 2.0]]) * element_length / 6.0
    for element in range(element_count):
        first = 6 * element
        for component, axial_rigidity, inertia_per_length in (
                (0, youngs_Pa * area, density * area),
                (3, shear_Pa * torsion_constant_m4, density * section.polar_moment_m4)):
            scatter([first + component, first + 6 + component],
                    axial_rigidity * rod_stiffness, inertia_per_length * rod_mass)
        # In-plane bending: w = uy, psi = rot_z. Out-of-plane: w = uz, psi = -rot_y (a
        # positive rotation about y tilts the section against +z).
        for deflection, rotation, sign, inertia in ((1, 5, 1.0, inertia_y_bending),
                                                    (2, 4, -1.0, inertia_z_bending)):
            dofs = [first + deflection, first + rotation, first + 6 + deflection,
                    first + 6 + rotation]
            signs = np.diag([1.0, sign, 1.0, sign])
            element_stiffness, element_mass = _bending_element(
                element_length, material, area, inertia, shear_correction, rod_mass)
            scatter(dofs, signs @ element_stiffness @ signs, signs @ element_mass @ signs)
    rows, cols = np.concatenate(triplets["rows"]), np.concatenate(triplets["cols"])
    stiffness = sp.csr_matrix((np.concatenate(triplets["stiffness"]), (rows, cols)),
                              shape=(dof_count, dof_count))
    mass = sp.csr_matrix((np.concatenate(triplets["mass"]), (rows, cols)),
                         shape=(dof_count, dof_count))
    return stiffness, mass


def _bending_element(element_length: float, material: Material, area: float, inertia: float,
                     shear_correction: float, rod_mass: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and consistent mass of one linear Timoshenko bending element for
    [w1, psi1, w2, psi2] (length [m], area [m^2], second moment [m^4]; ``rod_mass`` the linear
    rod's unit mass matrix): bending plus shear at the midpoint (one-point rule)."""
    youngs_Pa, shear_Pa = material.youngs_modulus_Pa, material.shear_modulus_Pa
    density = material.density_kg_per_m3
    # Shear strain at the element midpoint (one-point rule) for [w1, psi1, w2, psi2], with
    # gamma = w' - psi.
    shear_strain = np.array([-1.0 / element_length, -0.5, 1.0 / element_length, -0.5])
    curvature = np.array([0.0, -1.0, 0.0, 1.0]) / element_length
    element_stiffness = (youngs_Pa * inertia * element_length
                         * np.outer(curvature, curvature)
                         + shear_correction * shear_Pa * area * element_length
                         * np.outer(shear_strain, shear_strain))
    element_mass = np.zeros((4, 4))
    element_mass[np.ix_([0, 2], [0, 2])] = density * area * rod_mass
    element_mass[np.ix_([1, 3], [1, 3])] = density * inertia * rod_mass
    return element_stiffness, element_mass


def _mode_kinds(vectors: np.ndarray, free: np.ndarray, mass, dof_count: int
                ) -> tuple[list[str], list[int]]:
    """Kinds (largest kinetic-energy share of ux, uy, uz, rot_x) and orders within each kind
    of the modes in the columns of ``vectors`` (free DOFs only)."""
    kinds: list[str] = []
    orders: list[int] = []
    for index in range(vectors.shape[1]):
        full = np.zeros(dof_count)
        full[free] = vectors[:, index]
        kinetic = full * (mass @ full)
        energy = [kinetic[component::6].sum() for component in range(4)]
        kind = _KIND_OF_COMPONENT[int(np.argmax(energy))]
        kinds.append(kind)
        orders.append(kinds.count(kind))
    return kinds, orders


def beam_element_modes(length_m: float, thickness_m: float, width_m: float,
                       boundary_condition: str, element_count: int = 8, mode_count: int = 5,
                       material: Material = THESIS_STEEL,
                       shear_correction: float = SHEAR_CORRECTION_RECTANGLE,
                       torsion_constant_m4: float | None = None) -> BeamLinkModes:
    """Modes of a link from 3D two-node linear Timoshenko beam elements (BEAM188-like).

    ``element_count`` equal elements along the link; thickness (m) along y, width (m) along z,
    length (m) along x. ``boundary_condition`` from :data:`LINK_BOUNDARY_CONDITIONS`: the end
    nodes have x, y, z translations and rotations about x and y fixed, rotation about z free;
    pinned-roller frees x at the last node. ``torsion_constant_m4`` overrides the series value
    of :func:`flex.experiments.thesis.beams.rectangle_torsion_constant_m4`. Free-free: the six
    rigid modes are
    skipped. Returns :class:`flex.experiments.thesis.beams.BeamLinkModes`; kinds from the
    kinetic-energy shares
    of ux (axial), uy (in-plane bending), uz (out-of-plane bending) and rot_x (torsion);
    ``mode_orders`` counts within each kind.
    """
    from scipy.linalg import eigh
    from scipy.sparse.linalg import eigsh

    check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m,
                   shear_correction=shear_correction)
    check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    check_count("element_count", element_count, 2000)
    check_count("mode_count", mode_count)
    material.check()
    torsion_constant = (rectangle_section(thickness_m, width_m).torsion_constant_m4
                        if torsion_constant_m4 is None else torsion_constant_m4)
    check_positive(torsion_constant_m4=torsion_constant)
    stiffness, mass = _assemble_beam(length_m, thickness_m, width_m, element_count, material,
                                     shear_correction, torsion_constant)
    dof_count = stiffness.shape[0]
    fixed_first, fixed_last = _BEAM_FIXED_DOFS[boundary_condition]
    fixed = list(fixed_first) + [6 * element_count + dof for dof in fixed_last]
    free = np.setdiff1d(np.arange(dof_count), fixed)
    stiffness_free = stiffness[free][:, free]
    mass_free = mass[free][:, free]
    rigid_count = 6 if boundary_condition == "free-free" else 0
    wanted = rigid_count + mode_count
    if free.size <= wanted:
        raise SceneError(f"element_count = {element_count}: too few elements for "
                         f"{mode_count} modes")
    if free.size <= 600:
        eigenvalues, vectors = eigh(stiffness_free.toarray(), mass_free.toarray())
    else:
        # Shift-invert about a negative shift (positive definite even when free), scaled by
        # the Euler-Bernoulli pinned-pinned frequency of the weak plane.
        shift = 0.25 * weak_plane_bending_rad_per_s(length_m, thickness_m, width_m,
                                                    material) ** 2
        eigenvalues, vectors = eigsh(stiffness_free.tocsc(), k=wanted, M=mass_free.tocsc(),
                                     sigma=-shift, which="LM")
        order = np.argsort(eigenvalues)
        eigenvalues, vectors = eigenvalues[order], vectors[:, order]
    eigenvalues = eigenvalues[rigid_count:rigid_count + mode_count]
    kinds, orders = _mode_kinds(vectors[:, rigid_count:rigid_count + mode_count], free, mass,
                                dof_count)
    omegas = np.sqrt(np.maximum(eigenvalues, 0.0))
    return BeamLinkModes(frequencies_rad_per_s=omegas, frequencies_Hz=omegas / (2 * math.pi),
                         mode_kinds=tuple(kinds), mode_orders=np.array(orders),
                         theory=f"linear Timoshenko beam elements, {element_count} elements")
