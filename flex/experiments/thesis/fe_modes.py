"""Elastic modes of a plate link from 3D finite elements (NGsolve), classified by symmetry.

:func:`plate_modes` meshes a box link (:func:`flex.bodies.plate.plate_mesh`: x along the link,
y across the thickness t, in the mechanism plane; z across the width) with tetrahedra of
order 2, assembles stiffness K and consistent mass M of linear elasticity, and returns the
lowest elastic modes as :class:`PlateModes`. All quantities are SI (m, kg, Pa, s); circular
frequencies in rad/s, cyclic ones in Hz. Kinds and link boundary conditions are those of
:mod:`flex.experiments.thesis.beams` (:data:`~flex.experiments.thesis.beams.MODE_KINDS`,
:data:`~flex.experiments.thesis.beams.LINK_BOUNDARY_CONDITIONS`).

Method: the generalized eigenproblem K phi = omega^2 M phi is solved by Lanczos (ARPACK,
``scipy.sparse.linalg.eigsh``) in shift-invert mode about a negative shift
sigma = -(omega_est/2)^2 (omega_est the Euler-Bernoulli pinned-pinned frequency of the weak
plane): K - sigma M is then positive definite even for a free body, so NGsolve's sparse
Cholesky factorises it, and the eigenvalues nearest sigma are the lowest ones. Free-free: the
six lowest (rigid-body, ~0 Hz) modes are skipped; they are returned in
``rigid_body_frequencies_Hz`` so their smallness can be checked.

Pinned-pinned (the coupler between its revolute joints): ten linear constraints C u = 0 on the
two end faces (:func:`_end_face_constraints`): over each end face the integrals of u_x, u_y,
u_z vanish (no mean translation of the joint), and so do the mean rotations about x (integral
of y u_z - z u_y) and about y (integral of z u_x); the mean rotation about z stays free. This
is a distributing ("RBE3") coupling of the face to a joint at its centre, like Exudyn's
``MarkerSuperElementRigid`` on the face nodes, not a rigid face: its reaction is the
constraint row times a multiplier, i.e. a uniform traction over the face for each force
component and a linearly varying traction for the moments about x and y. So the pinned end of
in-plane bending carries a transverse force (uniform shear traction) but no moment about z,
with the face's mean deflection zero: exactly the simply supported end of beam theory (w = 0,
M = 0). Out-of-plane bending is clamped and torsion fixed, as a revolute joint about z
requires. Pinning instead the line of nodes along z through each face centre puts a line load
into a 3D continuum, whose displacement is logarithmically singular, so the frequency keeps
falling under refinement (measured, t = 10 mm: 3489.0, 3484.9, 3480.1, 3478.0 Hz at maxh 10,
5, 2.5, 1.77 mm, while the face coupling gives 3503.0, 3490.2, 3488.4, 3488.3 Hz, Timoshenko
3486.0). Pinned-roller drops the mean u_x constraint of ``end_b`` (nine constraints). The
constraints are imposed exactly inside the shift-invert operator with a Schur complement of
the multipliers: x = A^-1 y - Z S^-1 C A^-1 y, Z = A^-1 C^T, S = C Z, A = K - sigma M.

Classification: parity shares (:func:`parity_kind_shares`) from the mode evaluated at the
vertices and at their mirror images. Exactly degenerate eigenvalues (a square section has
equal in-plane and out-of-plane bending) come out of any solver as an arbitrary basis of the
eigenspace (and a coarse mesh splits them slightly, still mixed); clusters of mixed modes
closer than 1 % in frequency are rotated to parity-pure shapes first
(:func:`_align_degenerate_modes`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import check_positive, lame_first_parameter_Pa, shear_modulus_Pa
from flex.experiments.thesis.beams import (
    LINK_BOUNDARY_CONDITIONS,
    MODE_KINDS,
    THESIS_STEEL,
    Material,
    check_choice,
    check_count,
    weak_plane_bending_rad_per_s,
)

# ---------------------------------------------------------------------------------------------
# Mode classification
# ---------------------------------------------------------------------------------------------


def _parity_parts(u: np.ndarray, u_y: np.ndarray, u_z: np.ndarray,
                  u_yz: np.ndarray) -> list[np.ndarray]:
    """Four times the projections of a sampled field onto the four symmetry classes, in
    :data:`MODE_KINDS` order (inputs as :func:`parity_kind_shares`)."""
    flip_y = np.array([1.0, -1.0, 1.0])
    flip_z = np.array([1.0, 1.0, -1.0])
    reflected_y = u_y * flip_y          # R_y u(R_y p)
    reflected_z = u_z * flip_z          # R_z u(R_z p)
    reflected_yz = u_yz * flip_y * flip_z
    # Projector onto the class with characters (s_y, s_z): (u + s_y Ry + s_z Rz + s_y s_z Ryz)/4
    return [u + reflected_y + reflected_z + reflected_yz,   # axial
            u - reflected_y + reflected_z - reflected_yz,   # in-plane bending
            u + reflected_y - reflected_z - reflected_yz,   # out-of-plane bending
            u - reflected_y - reflected_z + reflected_yz]   # torsion


def parity_kind_shares(displacement: np.ndarray, displacement_at_mirror_y: np.ndarray,
                       displacement_at_mirror_z: np.ndarray,
                       displacement_at_mirror_yz: np.ndarray) -> np.ndarray:
    """Shares of a displacement field in the four symmetry classes of a rectangular link.

    Inputs are (n_points, 3) arrays of displacement (any unit) sampled at points p_i, at
    their mirror images (x, -y, z), (x, y, -z) and (x, -y, -z) respectively, in the same
    order. The link's symmetry group {1, R_y, R_z, R_y R_z} (R_y flips the y component)
    splits any field into four orthogonal parts with u(R p) = +-R u(p) under each
    reflection:

    - even in y and z: axial (and extensional/breathing) motion;
    - odd in y, even in z: in-plane bending (u_y(x), with u_x = -y w');
    - even in y, odd in z: out-of-plane bending;
    - odd in y and z: torsion (u_y = -theta z, u_z = theta y).

    Returns the four shares (sum 1) of the squared sampled norm, ordered as
    :data:`MODE_KINDS`. For the shares to be energy-like the sample points should be spread
    evenly over the body (e.g. mesh vertices).
    """
    arrays = [np.asarray(a, dtype=float) for a in (
        displacement, displacement_at_mirror_y, displacement_at_mirror_z,
        displacement_at_mirror_yz)]
    if any(a.shape != arrays[0].shape or a.ndim != 2 or a.shape[1] != 3 for a in arrays):
        raise SceneError("parity_kind_shares: all four arrays must have the same shape (n, 3)")
    norms = np.array([np.sum(part ** 2) for part in _parity_parts(*arrays)])
    total = norms.sum()
    if total == 0.0:
        raise SceneError("parity_kind_shares: the displacement field is zero everywhere")
    return norms / total


def classify_kind_shares(kind_shares: np.ndarray, minimum_share: float = 0.8) -> str:
    """Name of the dominant kind of :data:`MODE_KINDS`, or ``"mixed"`` below minimum_share.

    ``kind_shares``: four shares in :data:`MODE_KINDS` order (e.g. from
    :func:`parity_kind_shares`); ``minimum_share`` dimensionless in (0.25, 1].
    """
    shares = np.asarray(kind_shares, dtype=float)
    if shares.shape != (len(MODE_KINDS),):
        raise SceneError(f"kind_shares must have {len(MODE_KINDS)} entries, got {shares.shape}")
    if not 0.25 < minimum_share <= 1.0:
        raise SceneError(f"minimum_share = {minimum_share!r}: must lie in (0.25, 1]")
    best = int(np.argmax(shares))
    return MODE_KINDS[best] if shares[best] >= minimum_share else "mixed"


# ---------------------------------------------------------------------------------------------
# 3D finite elements
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlateModes:
    """Modes of a plate link from 3D second-order tetrahedra (see :func:`plate_modes`).

    Attributes:

    - ``length_m``, ``thickness_m``, ``width_m``, ``mesh_size_m``: the plate and netgen maxh, m.
    - ``boundary_condition``: one of :data:`LINK_BOUNDARY_CONDITIONS`.
    - ``frequencies_Hz``, ``frequencies_rad_per_s``: (n_modes,) ascending, rigid modes removed.
    - ``mode_kinds``: (n_modes,) names from :data:`MODE_KINDS` or ``"mixed"``.
    - ``kind_shares``: (n_modes, 4) symmetry-class shares in :data:`MODE_KINDS` order
      (:func:`parity_kind_shares` at the mesh vertices).
    - ``kinetic_energy_shares_xyz``: (n_modes, 3) share of the modal kinetic energy carried by
      the x, y and z displacement components (exact, from the consistent mass matrix).
    - ``node_coordinates_m``: (n_nodes, 3) mesh vertex positions, m.
    - ``mode_shapes``: (n_modes, n_nodes, 3) vertex displacements, dimensionless, each mode
      scaled to a largest vertex displacement magnitude of 1 (sign: largest component > 0).
    - ``surface_triangles``: (n_triangles, 3) vertex indices of the boundary triangles.
    - ``element_count`` (tetrahedra), ``node_count`` (vertices), ``dof_count`` (unknowns of
      the vector H1 space of the element order), ``constraint_count`` (linear constraints
      imposed).
    - ``max_relative_residual``: max over modes of |K phi - lambda M phi - C^T mu| / |K phi|,
      the check that the eigensolver converged.
    - ``rigid_body_frequencies_Hz``: the skipped free-free rigid-body frequencies, Hz (should be
      ~0; empty for the supported links).
    - ``wall_time_s``: mesh + assembly + eigensolution time, s.
    """

    length_m: float
    thickness_m: float
    width_m: float
    mesh_size_m: float
    boundary_condition: str
    frequencies_Hz: np.ndarray
    frequencies_rad_per_s: np.ndarray
    mode_kinds: tuple[str, ...]
    kind_shares: np.ndarray
    kinetic_energy_shares_xyz: np.ndarray
    node_coordinates_m: np.ndarray
    mode_shapes: np.ndarray
    surface_triangles: np.ndarray
    element_count: int
    node_count: int
    dof_count: int
    constraint_count: int
    max_relative_residual: float
    rigid_body_frequencies_Hz: np.ndarray = field(default_factory=lambda: np.zeros(0))
    wall_time_s: float = 0.0

    def first_of_kind(self, kind: str) -> int:
        """Index of the lowest mode of ``kind`` (one of :data:`MODE_KINDS`).

        Raises :class:`SceneError` if none of the computed modes is of that kind.
        """
        check_choice("kind", kind, MODE_KINDS)
        for index, name in enumerate(self.mode_kinds):
            if name == kind:
                return index
        raise SceneError(f"none of the {len(self.mode_kinds)} computed modes is {kind!r} "
                         f"(kinds: {', '.join(self.mode_kinds)}); compute more modes")


def _end_face_constraints(mesh, fes, boundary_condition: str) -> np.ndarray:
    """Rows of the joint constraints C u = 0, shape (10, ndof) or (9, ndof) for a roller.

    Per end face (centre on the x axis): the integrals over the face of u_x, u_y, u_z,
    (y u_z - z u_y) and z u_x. The first three fix the mean displacement; the last two the
    mean rotation about x and about y (u_x = theta_y z on the face). Rotation about z
    (integral of y u_x) stays free; a roller at ``end_b`` also leaves its mean u_x free.
    """
    import ngsolve as ngs

    rows = []
    test = fes.TestFunction()
    for face in ("end_a", "end_b"):
        on_face = ngs.ds(definedon=mesh.Boundaries(face))
        integrands = [test[0], test[1], test[2], ngs.y * test[2] - ngs.z * test[1],
                      ngs.z * test[0]]
        if face == "end_b" and boundary_condition == "pinned-roller":
            integrands = integrands[1:]
        for integrand in integrands:
            form = ngs.LinearForm(fes)
            form += integrand * on_face
            form.Assemble()
            rows.append(form.vec.FV().NumPy().copy())
    return np.array(rows)


def _assemble(fes, material: Material, shift: float
              ) -> tuple[Any, Any, Callable[[np.ndarray], np.ndarray]]:
    """Stiffness K [N/m] and consistent mass M [kg] (scipy CSR) of linear elasticity on
    ``fes``, and a solver of (K + shift M) x = y (NGsolve sparse Cholesky), shift in 1/s^2."""
    import ngsolve as ngs
    import scipy.sparse as sp

    trial, test = fes.TnT()
    youngs_Pa, nu = material.youngs_modulus_Pa, material.poissons_ratio
    shear_Pa, lame_Pa = shear_modulus_Pa(youngs_Pa, nu), lame_first_parameter_Pa(youngs_Pa, nu)

    def strain(w):
        return ngs.Sym(ngs.Grad(w))

    def stress(w):
        return 2.0 * shear_Pa * strain(w) + lame_Pa * ngs.Trace(strain(w)) * ngs.Id(3)

    # No ngs.TaskManager: on a shared 2-core machine its spinning worker threads made assembly
    # and solves 2x slower than sequential code (measured).
    stiffness = ngs.BilinearForm(fes, symmetric=True)
    stiffness += ngs.InnerProduct(stress(trial), strain(test)) * ngs.dx
    stiffness.Assemble()
    mass = ngs.BilinearForm(fes, symmetric=True)
    mass += material.density_kg_per_m3 * trial * test * ngs.dx
    mass.Assemble()
    shifted = stiffness.mat.CreateMatrix()
    shifted.AsVector().data = stiffness.mat.AsVector() + shift * mass.mat.AsVector()
    shifted_inverse = shifted.Inverse(inverse="sparsecholesky")
    # ngsolve's CSR export of a symmetric-storage matrix is the full matrix (checked).
    stiffness_csr = sp.csr_matrix(stiffness.mat.CSR())
    mass_csr = sp.csr_matrix(mass.mat.CSR())
    rhs_vector = shifted_inverse.CreateRowVector()
    sol_vector = shifted_inverse.CreateColVector()
    # the NGsolve objects the factorisation refers to live as long as the solver
    alive = (stiffness, mass, shifted)

    def solve_shifted(right_hand_side: np.ndarray) -> np.ndarray:
        assert alive
        rhs_vector.FV().NumPy()[:] = right_hand_side
        sol_vector.data = shifted_inverse * rhs_vector
        return sol_vector.FV().NumPy().copy()

    return stiffness_csr, mass_csr, solve_shifted


def _constrained_inverse(mesh, fes, boundary_condition: str,
                         solve_shifted: Callable[[np.ndarray], np.ndarray]
                         ) -> tuple[np.ndarray, Callable[[np.ndarray], np.ndarray], int]:
    """The joint constraints C (rows), the shift-invert operator restricted to C u = 0 (Schur
    complement of the multipliers) and the number of rigid-body modes left (6 free-free)."""
    if boundary_condition == "free-free":
        return np.zeros((0, fes.ndof)), solve_shifted, 6
    constraints = _end_face_constraints(mesh, fes, boundary_condition)
    constrained_solutions = np.column_stack([solve_shifted(row) for row in constraints])
    schur = constraints @ constrained_solutions

    def apply_inverse(right_hand_side: np.ndarray) -> np.ndarray:
        unconstrained = solve_shifted(np.ravel(right_hand_side))
        multipliers = np.linalg.solve(schur, constraints @ unconstrained)
        return unconstrained - constrained_solutions @ multipliers

    return constraints, apply_inverse, 0


def _max_relative_residual(stiffness_csr, mass_csr, constraints: np.ndarray,
                           eigenvalues: np.ndarray, eigenvectors: np.ndarray) -> float:
    """max over modes of |K phi - lambda M phi - C^T mu| / |K phi| (mu: least squares)."""
    residuals = []
    for index in range(eigenvectors.shape[1]):
        vector = eigenvectors[:, index]
        stiffness_times = stiffness_csr @ vector
        residual = stiffness_times - eigenvalues[index] * (mass_csr @ vector)
        if constraints.shape[0]:
            multipliers = np.linalg.lstsq(constraints.T, residual, rcond=None)[0]
            residual = residual - constraints.T @ multipliers
        residuals.append(np.linalg.norm(residual) / np.linalg.norm(stiffness_times))
    return float(max(residuals))


def _vertex_samples(mesh, fes, eigenvectors: np.ndarray
                    ) -> tuple[np.ndarray, list[list[np.ndarray]]]:
    """Vertex coordinates [m] and, per mode, its (n_vertices, 3) values at the vertices and
    at their mirror images (x, -y, z), (x, y, -z), (x, -y, -z)."""
    import ngsolve as ngs

    coordinates_m = np.array(mesh.ngmesh.Coordinates(), dtype=float)
    node_count = coordinates_m.shape[0]
    scalar_dofs = fes.ndof // 3
    grid_function = ngs.GridFunction(fes)
    mirrors = [np.array([1.0, -1.0, 1.0]), np.array([1.0, 1.0, -1.0]),
               np.array([1.0, -1.0, -1.0])]
    mirror_points = [mesh(*(coordinates_m * flip).T) for flip in mirrors]

    def sampled(vector: np.ndarray) -> list[np.ndarray]:
        # The vertex unknowns of the hierarchical H1 basis are the vertex values; the vector
        # space stores the components as three consecutive blocks.
        at_vertices = np.column_stack([vector[c * scalar_dofs:c * scalar_dofs + node_count]
                                       for c in range(3)])
        grid_function.vec.FV().NumPy()[:] = vector
        return [at_vertices] + [np.asarray(grid_function(points)) for points in mirror_points]

    return coordinates_m, [sampled(eigenvectors[:, i]) for i in range(eigenvectors.shape[1])]


def _kinetic_energy_shares(eigenvectors: np.ndarray, mass_csr) -> np.ndarray:
    """(n_modes, 3) shares of each mode's kinetic energy in the x, y, z components."""
    scalar_dofs = eigenvectors.shape[0] // 3
    energy_shares = np.zeros((eigenvectors.shape[1], 3))
    for index in range(eigenvectors.shape[1]):
        vector = eigenvectors[:, index]
        mass_times = mass_csr @ vector  # the mass matrix has no coupling between components
        for component in range(3):
            block = slice(component * scalar_dofs, (component + 1) * scalar_dofs)
            energy_shares[index, component] = vector[block] @ mass_times[block]
        energy_shares[index] /= energy_shares[index].sum()
    return energy_shares


def _normalised_shapes(samples: list[list[np.ndarray]]) -> np.ndarray:
    """(n_modes, n_vertices, 3) vertex displacements scaled to a largest magnitude of 1, the
    largest component of the largest displacement positive."""
    shapes = np.array([sample[0] for sample in samples])
    for index in range(shapes.shape[0]):
        magnitudes = np.linalg.norm(shapes[index], axis=1)
        peak = int(np.argmax(magnitudes))
        component = int(np.argmax(np.abs(shapes[index, peak])))
        sign = 1.0 if shapes[index, peak, component] >= 0.0 else -1.0
        shapes[index] *= sign / magnitudes[peak]
    return shapes


def _lowest_eigenpairs(stiffness_csr, mass_csr, apply_inverse, shift: float, count: int,
                       rigid_count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``count`` lowest elastic eigenvalues [1/s^2] and M-orthonormal eigenvectors by
    shift-invert Lanczos about -shift, and the skipped rigid-body frequencies [Hz]."""
    import scipy.sparse.linalg as spla

    dof_count = stiffness_csr.shape[0]
    operator = spla.LinearOperator((dof_count, dof_count), matvec=apply_inverse, dtype=float)
    # Deterministic start vector, mapped into the constrained space by one operator step.
    start_vector = apply_inverse(
        mass_csr @ np.random.default_rng(12345).standard_normal(dof_count))
    eigenvalues, eigenvectors = spla.eigsh(
        stiffness_csr, k=count + rigid_count, M=mass_csr, sigma=-shift,
        OPinv=operator, which="LM", v0=start_vector)
    order = np.argsort(eigenvalues)
    eigenvalues, eigenvectors = eigenvalues[order], eigenvectors[:, order]
    rigid_Hz = np.sqrt(np.abs(eigenvalues[:rigid_count])) / (2.0 * math.pi)
    return eigenvalues[rigid_count:], eigenvectors[:, rigid_count:], rigid_Hz


def plate_modes(length_m: float, thickness_m: float, width_m: float, mesh_size_m: float,
                boundary_condition: str = "free-free", mode_count: int = 5,
                material: Material = THESIS_STEEL, element_order: int = 2,
                minimum_share: float = 0.8, mesh=None) -> PlateModes:
    """First ``mode_count`` elastic modes of a box link from 3D linear elasticity.

    Inputs: plate ``length_m`` (x), ``thickness_m`` (y, in the mechanism plane), ``width_m``
    (z), netgen ``mesh_size_m`` (maxh), all in m; ``boundary_condition`` from
    :data:`LINK_BOUNDARY_CONDITIONS`; ``mode_count`` elastic modes wanted (1..200);
    ``material``; ``element_order`` of the vector H1 space (2 = second-order tetrahedra; 1 is
    allowed to show shear locking; 3 and 4 give a converged reference on a coarse mesh,
    :mod:`flex.experiments.thesis.mesh_convergence`); ``minimum_share`` for
    :func:`classify_kind_shares`;
    ``mesh`` an already built ``ngsolve.Mesh`` of the same plate (from
    :func:`flex.bodies.plate.plate_mesh`) to skip meshing. Returns :class:`PlateModes`. Method,
    joint constraints and classification: see the module doc.

    Raises :class:`SceneError` for non-positive sizes, an unknown boundary condition or a
    failed convergence check (relative residual above 1e-6).
    """
    _check_plate_inputs(length_m, thickness_m, width_m, mesh_size_m, boundary_condition,
                        mode_count, element_order, material)
    start_s = time.perf_counter()

    import ngsolve as ngs

    from flex.bodies.plate import plate_mesh

    if mesh is None:
        mesh = plate_mesh(length_m, thickness_m, width_m, mesh_size_m)
    fes = ngs.VectorH1(mesh, order=element_order)
    omega_est = weak_plane_bending_rad_per_s(length_m, thickness_m, width_m, material)
    shift = (0.5 * omega_est) ** 2  # sigma = -shift
    stiffness_csr, mass_csr, solve_shifted = _assemble(fes, material, shift)
    constraints, apply_inverse, rigid_count = _constrained_inverse(
        mesh, fes, boundary_condition, solve_shifted)
    eigenvalues, eigenvectors, rigid_Hz = _lowest_eigenpairs(
        stiffness_csr, mass_csr, apply_inverse, shift, mode_count, rigid_count)
    max_relative_residual = _converged_residual(
        stiffness_csr, mass_csr, constraints, eigenvalues, eigenvectors,
        f"plate {length_m} x {thickness_m} x {width_m} m, maxh {mesh_size_m} m, "
        f"{boundary_condition}")
    coordinates_m, samples = _vertex_samples(mesh, fes, eigenvectors)
    eigenvalues, eigenvectors, samples = _align_degenerate_modes(
        eigenvalues, eigenvectors, samples, stiffness_csr)
    kind_shares = np.array([parity_kind_shares(*sample) for sample in samples])
    triangles = _surface_triangles(mesh)
    omegas = np.sqrt(np.maximum(eigenvalues, 0.0))
    return PlateModes(
        length_m=float(length_m), thickness_m=float(thickness_m), width_m=float(width_m),
        mesh_size_m=float(mesh_size_m), boundary_condition=boundary_condition,
        frequencies_Hz=omegas / (2.0 * math.pi), frequencies_rad_per_s=omegas,
        mode_kinds=tuple(classify_kind_shares(shares, minimum_share) for shares in kind_shares),
        kind_shares=kind_shares,
        kinetic_energy_shares_xyz=_kinetic_energy_shares(eigenvectors, mass_csr),
        node_coordinates_m=coordinates_m, mode_shapes=_normalised_shapes(samples),
        surface_triangles=triangles, element_count=int(mesh.ne),
        node_count=int(coordinates_m.shape[0]), dof_count=int(fes.ndof),
        constraint_count=int(constraints.shape[0]),
        max_relative_residual=max_relative_residual, rigid_body_frequencies_Hz=rigid_Hz,
        wall_time_s=time.perf_counter() - start_s)


def _check_plate_inputs(length_m: float, thickness_m: float, width_m: float,
                        mesh_size_m: float, boundary_condition: str, mode_count: int,
                        element_order: int, material: Material) -> None:
    """Raise :class:`SceneError` for :func:`plate_modes`'s bad inputs (the first one found):
    a size not > 0, an unknown boundary condition, a bad mode count, element order or
    material."""
    check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m,
                   mesh_size_m=mesh_size_m)
    check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    check_count("mode_count", mode_count)
    if element_order not in (1, 2, 3, 4):
        raise SceneError(f"element_order = {element_order!r}: must be 1, 2, 3 or 4")
    material.check()


def _converged_residual(stiffness_csr, mass_csr, constraints, eigenvalues: np.ndarray,
                        eigenvectors: np.ndarray, plate: str) -> float:
    """The eigenpairs' largest relative residual (:func:`_max_relative_residual`); above 1e-6 a
    :class:`SceneError` says the eigensolver did not converge on ``plate``."""
    max_relative_residual = _max_relative_residual(stiffness_csr, mass_csr, constraints,
                                                   eigenvalues, eigenvectors)
    if max_relative_residual > 1e-6:
        raise SceneError(f"eigensolver did not converge: relative residual "
                         f"{max_relative_residual:.1e} > 1e-6 ({plate})")
    return max_relative_residual


def _surface_triangles(mesh) -> np.ndarray:
    """The mesh's surface triangles as 0-based vertex numbers, one row each."""
    return np.array([[vertex.nr - 1 for vertex in element.vertices]
                     for element in mesh.ngmesh.Elements2D()], dtype=np.int64)


def _align_degenerate_modes(eigenvalues: np.ndarray, eigenvectors: np.ndarray,
                            samples: list[list[np.ndarray]], stiffness_csr,
                            relative_gap: float = 2e-2, pure_share: float = 0.99):
    """Rotate clusters of nearly equal eigenvalues to symmetry-pure modes.

    A cluster: consecutive eigenvalues omega^2 closer than ``relative_gap`` (2 %, i.e. 1 % in
    frequency) that contain a mode with no kind share above ``pure_share``. A square section
    has equal in-plane and out-of-plane bending frequencies; a mesh that is not symmetric
    splits them by up to ~0.7 % (coarse meshes) and returns diagonal, mixed bending modes.
    The cluster's M-orthonormal eigenvectors Phi are replaced by Phi Q, Q orthogonal from the
    eigenvectors of sum_k k P_k (P_k the Gram matrices of the sampled parity projections), so
    each new mode lies in one symmetry class; its eigenvalue becomes its Rayleigh quotient.
    """
    eigenvalues = eigenvalues.copy()
    eigenvectors = eigenvectors.copy()
    samples = [list(sample) for sample in samples]
    start = 0
    count = len(eigenvalues)
    while start < count:
        stop = start + 1
        while stop < count and (eigenvalues[stop] - eigenvalues[stop - 1]
                                <= relative_gap * abs(eigenvalues[stop])):
            stop += 1
        impure = any(parity_kind_shares(*samples[index]).max() < pure_share
                     for index in range(start, stop))
        if stop - start > 1 and impure:
            _rotate_cluster(eigenvalues, eigenvectors, samples, stiffness_csr, start, stop)
        start = stop
    return eigenvalues, eigenvectors, samples


def _rotate_cluster(eigenvalues: np.ndarray, eigenvectors: np.ndarray,
                    samples: list[list[np.ndarray]], stiffness_csr, start: int,
                    stop: int) -> None:
    """Rotate the modes ``start:stop`` (in place) to parity-pure shapes, re-sorted by their
    Rayleigh quotients (see :func:`_align_degenerate_modes`)."""
    projections = [_parity_parts(*samples[index]) for index in range(start, stop)]
    size = stop - start
    weighted = np.zeros((size, size))
    for kind_index in range(len(MODE_KINDS)):
        for i in range(size):
            for j in range(size):
                weighted[i, j] += kind_index * np.sum(
                    projections[i][kind_index] * projections[j][kind_index])
    _, rotation = np.linalg.eigh(weighted)
    block = slice(start, stop)
    eigenvectors[:, block] = eigenvectors[:, block] @ rotation
    old_samples = samples[start:stop]
    for new_index in range(size):
        samples[start + new_index] = [
            sum(rotation[old, new_index] * old_samples[old][part] for old in range(size))
            for part in range(4)]
        vector = eigenvectors[:, start + new_index]
        eigenvalues[start + new_index] = vector @ (stiffness_csr @ vector)
    order = np.argsort(eigenvalues[block]) + start
    eigenvalues[block] = eigenvalues[order]
    eigenvectors[:, block] = eigenvectors[:, order]
    samples[start:stop] = [samples[i] for i in order]
