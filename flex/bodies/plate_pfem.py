"""One order of the linear 3D plate reference (:mod:`flex.bodies.plate_reference`): a plate
between flex's joint supports as hexahedral p-version finite elements in NGSolve.

The plate (x along the length L, y across the thickness t: the in-plane bending direction, z
across the width w; the section's centroid on the x axis) is meshed with the hexahedra of a
:class:`HexMesh` (default 8 x 1 x 2, the end elements split once geometrically towards the end
faces) of ``VectorH1`` order p, their element interiors condensed statically (what makes high
order cheap). Supports as flex's joint markers
(RBE3-like, no point constraint): Lagrange multipliers (``NumberSpace`` factors of the product
space) hold the *mean* displacement of end face A (x = 0) in x, y, z and its mean twist about
x, and the mean y and z displacement of end face B (x = L; axially free). Load: the plate's own
weight at standard gravity as a uniform body force in -y (:func:`line_load_N_per_m`).
:func:`solve_order` returns, deflections positive along the load:

- the area-weighted section mean of u_y at x = L/2 (Gauss-Legendre points, order + 1 per
  element side, over the section): what a beam's transverse displacement is;
- u_y at the mid-span centroid, which lags the mean by the anticlastic curl of the section
  (:func:`flex.base.physics.anticlastic_centroid_offset`);
- the first in-plane bending frequency by inverse iteration with the static factorization
  (started from the static deflection, Rayleigh quotient to 1e-9).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from flex.base.physics import Plate, lame_first_parameter_Pa, shear_modulus_Pa

#: the size of a graded layer over the one before it, towards an end face (the classical
#: geometric grading of hp refinement towards a singularity)
GRADING_RATIO = 0.15
#: ``ngsolve.meshes.MakeStructured3DMesh``'s names of the faces x = 0 and x = L
END_A, END_B = "back", "front"
STANDARD_GRAVITY_M_PER_S2 = 9.80665
#: inverse iteration: relative change of the Rayleigh quotient, and the most iterations
RAYLEIGH_TOLERANCE, MAX_ITERATIONS = 1e-9, 60


@dataclass(frozen=True)
class HexMesh:
    """Hexahedra of a plate: ``along`` equal elements along the length (before grading),
    ``across_thickness``, ``across_width``; ``graded_layers`` geometric layers (each
    :data:`GRADING_RATIO` of the one before) cut off the first and last element towards the
    end faces, where the supports' uniform tractions meet the free faces (a weak edge
    singularity). Measured, 80 x 3 x 10 mm: orders 5 -> 6 -> 7 changed the deflection by
    5.4e-13 and 4.0e-13 m on 8 x 1 x 2 equal elements (slowing: the singularity), by 1.0e-13 and
    4.1e-14 m with one graded layer; 80 x 1 x 10 mm is smooth enough either way."""

    along: int = 8
    across_thickness: int = 1
    across_width: int = 2
    graded_layers: int = 1

    def x_nodes_m(self, length_m: float) -> np.ndarray:
        """The element boundaries along the length [m], 0 .. L."""
        step = length_m / self.along
        layers = [step * GRADING_RATIO**k for k in range(self.graded_layers, 0, -1)]
        inner = [step * i for i in range(1, self.along)]
        return np.array([0.0, *layers, *inner, *(length_m - v for v in reversed(layers)),
                         length_m])

    def as_array(self) -> np.ndarray:
        """``(along, across_thickness, across_width, graded_layers)``."""
        return np.array([self.along, self.across_thickness, self.across_width,
                         self.graded_layers])


DEFAULT_MESH = HexMesh()


class OrderSolution(NamedTuple):
    """One order's solve: unknowns (before condensation), deflections [m] along the load,
    first bending frequency [Hz]."""

    dof_count: int
    section_mean_deflection_m: float
    centroid_deflection_m: float
    first_bending_Hz: float


def line_load_N_per_m(plate: Plate) -> float:
    """The reference's uniform transverse load [N/m]: the plate's weight per length at
    standard gravity, ``rho t w g_n``."""
    return plate.density_kg_per_m3 * plate.thickness_m * plate.width_m * STANDARD_GRAVITY_M_PER_S2


def solve_order(plate: Plate, order: int, hex_mesh: HexMesh = DEFAULT_MESH) -> OrderSolution:
    """One order's static and modal solve (module doc)."""
    import ngsolve as ngs

    mesh = _mesh(plate, hex_mesh)
    space = ngs.FESpace([ngs.VectorH1(mesh, order=order)] + [ngs.NumberSpace(mesh)] * 6)
    (trial, *_), (test, *_) = space.TnT()
    solve = _condensed_solver(_stiffness(space, mesh, plate), space)
    load = ngs.LinearForm(space)
    load += -plate.density_kg_per_m3 * STANDARD_GRAVITY_M_PER_S2 * test[1] * ngs.dx
    load.Assemble()
    static = ngs.GridFunction(space)
    static.vec.data = solve(load.vec)
    mean, centroid = _midspan_deflections_m(static.components[0], mesh, plate, hex_mesh, order)
    mass = ngs.BilinearForm(space, symmetric=True)
    mass += plate.density_kg_per_m3 * ngs.InnerProduct(trial, test) * ngs.dx
    mass.Assemble()
    frequency = _first_frequency_Hz(solve, mass.mat, static.vec)
    return OrderSolution(space.ndof, mean, centroid, frequency)


def _mesh(plate: Plate, hex_mesh: HexMesh) -> Any:
    """The plate's hexahedra, x in [0, L], y in [-t/2, t/2], z in [-w/2, w/2]: a structured
    mesh mapped piecewise linearly along x (the elements stay boxes)."""
    from ngsolve.meshes import MakeStructured3DMesh

    length_m, thickness_m, width_m = plate.sizes_m
    x_nodes = hex_mesh.x_nodes_m(length_m)
    unit = np.linspace(0.0, 1.0, x_nodes.size)
    return MakeStructured3DMesh(
        hexes=True, nx=x_nodes.size - 1, ny=hex_mesh.across_thickness,
        nz=hex_mesh.across_width,
        mapping=lambda x, y, z: (float(np.interp(x, unit, x_nodes)), thickness_m * (y - 0.5),
                                 width_m * (z - 0.5)))


def _stiffness(space: Any, mesh: Any, plate: Plate) -> Any:
    """Linear elasticity plus the six support constraints (each the mean of a displacement,
    or of the twist, over an end face, scaled by E t to the elastic entries), condensed."""
    import ngsolve as ngs

    (u, *multiplier), (v, *test_multiplier) = space.TnT()
    youngs_Pa, nu = plate.youngs_modulus_Pa, plate.poisson_ratio
    shear_Pa, lame_Pa = shear_modulus_Pa(youngs_Pa, nu), lame_first_parameter_Pa(youngs_Pa, nu)

    def strain(w: Any) -> Any:
        return ngs.Sym(ngs.Grad(w))

    form = ngs.BilinearForm(space, symmetric=True, condense=True)
    form += ngs.InnerProduct(2.0 * shear_Pa * strain(u)
                             + lame_Pa * ngs.Trace(strain(u)) * ngs.Id(3), strain(v)) * ngs.dx
    _, thickness_m, width_m = plate.sizes_m
    area_m2 = thickness_m * width_m
    gyration_m = math.sqrt((thickness_m**2 + width_m**2) / 12.0)
    scale = youngs_Pa * thickness_m / area_m2

    def means(w: Any) -> list[tuple[Any, str]]:
        twist = (ngs.y * w[2] - ngs.z * w[1]) / gyration_m
        return [(w[0], END_A), (w[1], END_A), (w[2], END_A), (twist, END_A),
                (w[1], END_B), (w[2], END_B)]

    for (held, face), (tested, _), lam, mu in zip(means(u), means(v), multiplier,
                                                  test_multiplier, strict=True):
        form += scale * (lam * tested + mu * held) * ngs.ds(definedon=mesh.Boundaries(face))
    form.Assemble()
    return form


def _condensed_solver(form: Any, space: Any) -> Any:
    """x = A^-1 f through the condensed system: the coupling unknowns and multipliers by a
    sparse LDL^T, then the element interiors. The LDL^T does not pivot; where it meets a
    zero pivot (a multiplier ordered before its face, e.g. one element across the width) it
    gives no finite solution, and UMFPACK (pivoting, ~2x slower) factorizes instead."""
    free = space.FreeDofs(coupling=True)
    inverse = form.mat.Inverse(free, inverse="sparsecholesky")
    if not _solves(form.mat, inverse, free):
        inverse = form.mat.Inverse(free, inverse="umfpack")

    def solve(rhs: Any) -> Any:
        right = rhs.CreateVector()
        right.data = rhs
        right.data += form.harmonic_extension_trans * right
        solution = rhs.CreateVector()
        solution.data = inverse * right
        solution.data += form.harmonic_extension * solution
        solution.data += form.inner_solve * right
        return solution

    return solve


def _solves(matrix: Any, inverse: Any, free: Any) -> bool:
    """Whether ``inverse`` solves ``matrix`` x = b on the ``free`` unknowns: finite, with a
    relative residual below 1e-6 (a direct solve of these systems leaves ~1e-9) for b = A 1."""
    mask = np.array(list(free), dtype=bool)
    ones = matrix.CreateColVector()
    ones.FV().NumPy()[:] = mask
    right = matrix.CreateColVector()
    right.data = matrix * ones
    right.FV().NumPy()[~mask] = 0.0
    solution = matrix.CreateColVector()
    solution.data = inverse * right
    residual = matrix.CreateColVector()
    residual.data = right - matrix * solution
    values = residual.FV().NumPy()[mask]
    return bool(np.all(np.isfinite(solution.FV().NumPy()))
                and np.linalg.norm(values) <= 1e-6 * np.linalg.norm(right.FV().NumPy()))


def _midspan_deflections_m(displacement: Any, mesh: Any, plate: Plate,
                           hex_mesh: HexMesh, order: int) -> tuple[float, float]:
    """``(section mean, centroid)`` of -u_y at x = L/2 [m]: Gauss-Legendre points, order + 1
    per element side (exact for the polynomials there), weighted by area."""
    length_m, thickness_m, width_m = plate.sizes_m
    nodes, weights = np.polynomial.legendre.leggauss(order + 1)

    def points(size_m: float, count: int) -> tuple[np.ndarray, np.ndarray]:
        edges = np.linspace(-size_m / 2, size_m / 2, count + 1)
        half = np.diff(edges)[:, None] / 2
        where = (edges[:-1, None] + half * (1 + nodes)).ravel()
        return where, (half * weights).ravel()

    ys, y_weights = points(thickness_m, hex_mesh.across_thickness)
    zs, z_weights = points(width_m, hex_mesh.across_width)
    y_grid, z_grid = (a.ravel() for a in np.meshgrid(ys, zs, indexing="ij"))
    area_weights = np.outer(y_weights, z_weights).ravel()
    transverse = displacement[1]
    values = np.asarray(transverse(mesh(np.full(y_grid.size, length_m / 2), y_grid, z_grid)))
    mean = float(np.dot(area_weights, values.ravel()) / area_weights.sum())
    centroid = float(transverse(mesh(length_m / 2, 0.0, 0.0)))
    return -mean, -centroid


def _first_frequency_Hz(solve: Any, mass_matrix: Any, start: Any) -> float:
    """Lowest eigenfrequency [Hz] of the constrained K x = omega^2 M x by inverse iteration
    from ``start``: omega^2 is the Rayleigh quotient of each new iterate y = A^-1 M x,
    (y . M x) / (y . M y) (the multipliers drop out: C y = 0)."""
    from ngsolve import InnerProduct

    iterate = start.CreateVector()
    iterate.data = start
    mass_iterate, mass_new = start.CreateVector(), start.CreateVector()
    previous = math.inf
    for _ in range(MAX_ITERATIONS):
        mass_iterate.data = mass_matrix * iterate
        new = solve(mass_iterate)
        mass_new.data = mass_matrix * new
        norm = InnerProduct(new, mass_new)
        omega_sq = InnerProduct(new, mass_iterate) / norm
        iterate.data = (1.0 / math.sqrt(norm)) * new
        if abs(omega_sq - previous) <= RAYLEIGH_TOLERANCE * omega_sq:
            return math.sqrt(omega_sq) / (2.0 * math.pi)
        previous = omega_sq
    raise RuntimeError(f"inverse iteration: no convergence in {MAX_ITERATIONS} steps "
                       f"(last omega^2 = {omega_sq!r} 1/s^2)")
