"""Geometric stiffness of an FFRF plate link: the softening of its bending modes under its own
axial force, and the shortening of its chord by its bending.

A floating-frame body is linear elastic in its own frame: a compressed link keeps its bending
stiffness, so a thin coupler near its Euler load bends far less in the linear FFRF model than
in the fully nonlinear FE one (docs/geometric-stiffness.md). The missing part of the Green
strain is the transverse rotations' ``1/2 (du_y/dx)^2 + 1/2 (du_z/dx)^2``. Projected on the
reduction's mode basis Phi once per reduction::

    K_G = Phi^T [ (1/A) integral (du_y/dx dv_y/dx + du_z/dx dv_z/dx) dV ] Phi     [1/m]

(A = t w): ``b(q) = q^T K_G q / 2`` is the shortening of the chord that the bending q makes
[m], and a uniform axial tension N stores ``-N b``. The link's axial force comes from its
stretch including that shortening, ``N(q) = k_N . q + k_a b(q)`` (``k_N``: the ``end_b``
axial static mode's row of the reduced stiffness matrix, ``k_a`` its diagonal, E A / L), so the
energy added to the linear body's is::

    U_G(q) = (k_N . q) b(q) + k_a b(q)^2 / 2         (= k_a (u + b)^2 / 2 - k_a u^2 / 2)

and the generalized force on the modal coordinates (:class:`_GeometricForce`) is
``f = -grad U_G = -[N(q) K_G q + b(q) k_N]``: the bending softened (or stiffened, in tension)
by the axial force, and the axial coordinate pulled by the bending's shortening. f depends
on q alone and derives from an energy, so its Jacobian is exact and symmetric,
``N K_G + K_G q k_N^T + k_N q^T K_G + k_a K_G q q^T K_G``, and the body stays conservative:
Newton converges as for the linear body, whatever the modes and the step.

Why this is the whole correction: the reduction's floating frame is the chord B-C
(:mod:`flex.bodies.reduction`), so the joint forces' axial part acts along the frame's x
axis, the linear FFRF body is blind to it, and the second-order potential of the axial force
is exactly -N/2 integral(w'^2) over the elastic field w measured from the chord.
:func:`pinned_pinned_eigen` checks it against the Euler load and f(P) = f0 sqrt(1 - P / P_E).

What was measured and dropped (docs/geometric-stiffness.md): with the frame on the joint-B
face (Exudyn's default) the chord turns against the frame, compression stiffens the linear
body, and its correction needed the tension at C read from a joint's Lagrange multiplier,
outside the Jacobian (Newton failed with 2-24 modes on loaded scenes); in the chord frame,
the force -N K_G q without the shortening's pull (not conservative) went unstable on a crank
bent to 3 % of its length; K_G with the axial gradient's square (du_x/dx)^2 as well made the
reduced coupler resonate in a band of thickness where the nonlinear FE one does not.

Validity: the axial force is uniform along the link; below the Euler load the softening is
that of the beam; beyond it the bending's shortening is all that holds the buckled plate,
and the run carries a validity warning (only the nonlinear FE coupler is valid there).

Cached beside the reduction (``<key>.geometric.hdf5`` in the reduction's cache folder, keyed
by the reduction's key and a digest of its mode basis, its content checked on load by a
digest of its arrays); a reduction without a cache file computes it afresh (a mesh and one
bilinear form: about as long as meshing the plate).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from flex.data.cache import REDUCTION_CACHE, content_digest, say, store

#: bump when the content or layout of a cache entry changes (old entries are then rebuilt)
GEOMETRIC_FORMAT_VERSION = 4  # 4: transverse gradients only
_SUFFIX = ".geometric.hdf5"


@dataclass(frozen=True)
class GeometricStiffness:
    """The reduced geometric stiffness of one :class:`flex.bodies.reduction.Reduction`.

    ``matrix_per_N`` (K_G, m x m over the modal coordinates, [1/m]: generalized stiffness
    per newton of uniform axial tension; q^T K_G q / 2 is the bending's shortening of the
    chord [m]); ``axial_force_row_N_per_m`` (k_N: the linear part of the link's axial force,
    k_N . q [N], tension positive); ``axial_mode`` (column of the ``end_b`` axial static
    mode); ``from_cache``.
    """

    matrix_per_N: np.ndarray
    axial_force_row_N_per_m: np.ndarray
    axial_mode: int
    from_cache: bool = False

    def axial_force_N(self, modal_coordinates: np.ndarray) -> np.ndarray:
        """The link's axial force [N] (tension > 0) at modal coordinates of shape (m,) or
        (n, m): its stretch, the bending's shortening of the chord included."""
        q = np.asarray(modal_coordinates, dtype=float)
        shortening = 0.5 * np.einsum("...i,ij,...j->...", q, self.matrix_per_N, q)
        row = self.axial_force_row_N_per_m
        return q @ row + row[self.axial_mode] * shortening

    def energy_J(self, modal_coordinates: np.ndarray) -> np.ndarray:
        """U_G = (k_N . q) b + k_a b^2 / 2 [J] (module doc) at modal coordinates of shape
        (m,) or (n, m): what the geometric stiffness adds to the linear strain energy."""
        q = np.asarray(modal_coordinates, dtype=float)
        shortening = 0.5 * np.einsum("...i,ij,...j->...", q, self.matrix_per_N, q)
        row = self.axial_force_row_N_per_m
        return (q @ row) * shortening + 0.5 * row[self.axial_mode] * shortening**2


# ------------------------------------------------------------------------------------------
# assembly
# ------------------------------------------------------------------------------------------
def face_mean_displacement(reduction: Any, face: str) -> np.ndarray:
    """Weighted mean displacement of the face ``"end_a"`` or ``"end_b"`` per mode, shape
    (3, m) [m per unit modal coordinate] (x, y, z in body coordinates)."""
    basis = reduction.fem.modeBasis["matrix"]
    fields = basis.reshape(-1, 3, basis.shape[1])
    nodes = np.asarray(getattr(reduction, f"nodes_{face}"))
    weights = np.asarray(getattr(reduction, f"weights_{face}"))
    return np.einsum("n,ncm->cm", weights, fields[nodes])


def _axial_mode(reduction: Any) -> int:
    """The column of the ``end_b`` axial static mode: the one moving that face by 1 m in x."""
    axial = face_mean_displacement(reduction, "end_b")[0]
    mode = int(np.argmax(np.abs(axial)))
    if not abs(axial[mode] - 1.0) < 1e-6:
        raise ValueError(f"no end_b axial static mode in the basis (largest face x motion "
                         f"{axial[mode]:.3g} m per unit coordinate)")
    return mode


def unit_axial_stress_matrices(reduction: Any, rising: bool = False) -> Any:
    """K_sigma for 1 N of axial tension over the plate's mesh, Exudyn coordinate order
    (x, y, z per node), scipy CSR [1/m]: (1 / A) integral (du_y/dx dv_y/dx + du_z/dx dv_z/dx)
    dV, the transverse rotations only (the axial gradient's square, (du_x/dx)^2, is a
    strain's square, not a rotation's: near the rigid faces it made the reduced coupler
    resonate, docs/geometric-stiffness.md); with ``rising`` the same weighted by x / L (a
    tension of 1 N at ``end_b`` falling linearly to zero at ``end_a``: a distributed axial
    load).

    The mesh is the reduction's own when it was built in this process, else remade with the
    reduction's arguments (the same mesh and node numbering, as :mod:`flex.bodies.nonlinear`
    relies on; the node positions are checked against the reduction's).
    """
    import ngsolve as ngs
    from scipy.sparse import csr_matrix

    r = reduction
    mesh = getattr(r, "_mesh", None)
    if mesh is None:
        mesh = _remade_mesh(r)
    space = ngs.NodalFESpace(mesh, order=r.mesh_order) ** 3
    u, v = space.TnT()
    n_nodes = r.fem.NumberOfNodes()
    coordinate = np.arange(3 * n_nodes)
    ngsolve_index = (coordinate % 3) * n_nodes + coordinate // 3  # of Exudyn 3 i + c
    weight = ngs.x / r.length_m if rising else 1.0
    form = ngs.BilinearForm(space)
    gradient_u, gradient_v = ngs.Grad(u), ngs.Grad(v)  # [i, j] = d u_i / d x_j
    form += (weight / (r.thickness_m * r.width_m)) * (
        gradient_u[1, 0] * gradient_v[1, 0] + gradient_u[2, 0] * gradient_v[2, 0]) * ngs.dx
    form.Assemble()
    values, columns, pointers = form.mat.CSR()
    matrix = csr_matrix((np.asarray(values), np.asarray(columns).astype(np.int64),
                         np.asarray(pointers).astype(np.int64)), shape=(space.ndof, space.ndof))
    return matrix[ngsolve_index][:, ngsolve_index]


def _remade_mesh(reduction: Any) -> Any:
    """The reduction's mesh made again from its arguments, its node positions checked
    against the reduction's."""
    from flex.bodies.nonlinear import build_nonlinear_plate

    r = reduction
    plate = build_nonlinear_plate(r.plate, r.mesh_size_m, mesh_order=r.mesh_order)
    positions = r.fem.GetNodePositionsAsArray()
    if plate.node_positions_m.shape != positions.shape or not np.allclose(
            plate.node_positions_m, positions, rtol=0, atol=1e-9 * r.length_m):
        raise RuntimeError("the remade mesh differs from the reduction's: cannot project")
    return plate.mesh


def projected(reduction: Any, matrix: Any) -> np.ndarray:
    """``Phi^T matrix Phi`` on the reduction's mode basis, symmetrized."""
    basis = reduction.fem.modeBasis["matrix"]
    reduced = basis.T @ (matrix @ basis)
    return 0.5 * (reduced + reduced.T)


def compute_geometric_stiffness(reduction: Any) -> GeometricStiffness:
    """K_G and k_N of ``reduction`` (see the module doc), computed on its mesh."""
    basis = reduction.fem.modeBasis["matrix"]
    stiffness = basis.T @ (reduction.fem.stiffnessMatrix @ basis)
    mode = _axial_mode(reduction)
    return GeometricStiffness(
        matrix_per_N=projected(reduction, unit_axial_stress_matrices(reduction)),
        axial_force_row_N_per_m=np.asarray(stiffness[mode]).ravel(), axial_mode=mode)


# ------------------------------------------------------------------------------------------
# cache
# ------------------------------------------------------------------------------------------
def _digest(*arrays: np.ndarray) -> str:
    return content_digest((f"array{index}", array) for index, array in enumerate(arrays))


def _cache_path(reduction: Any) -> Path | None:
    cache_file = getattr(reduction, "cache_file", None)
    if cache_file is None:
        return None
    return Path(cache_file).with_name(f"{reduction.key}{_SUFFIX}")


def _load(path: Path, basis_digest: str) -> GeometricStiffness | None:
    """The entry at ``path`` if whole, made for this basis and unchanged since it was
    written (its content digest, :func:`flex.data.cache.content_digest`), else None (one
    line says why when the entry was there but did not prove its content)."""
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            if (h5.attrs["format_version"] != GEOMETRIC_FORMAT_VERSION
                    or h5.attrs["basis_digest"] != basis_digest):
                return None
            matrix = h5["matrix_per_N"][()]
            row = h5["axial_force_row_N_per_m"][()]
            stored = h5.attrs.get("content_digest")
            mode = int(h5.attrs["axial_mode"])
    except Exception:  # missing, truncated or foreign: rebuilt by the caller
        say(REDUCTION_CACHE, f"geometric-stiffness entry '{path}' cannot be read; rebuilding it")
        return None
    if stored != _digest(matrix, row, np.array([mode])):
        say(REDUCTION_CACHE, f"geometric-stiffness entry '{path}' did not prove its content "
                             f"(damaged or edited); rebuilding it")
        return None
    return GeometricStiffness(matrix_per_N=matrix, axial_force_row_N_per_m=row,
                              axial_mode=mode, from_cache=True)


def _save(path: Path, stiffness: GeometricStiffness, basis_digest: str) -> None:
    """Write atomically (:func:`flex.data.cache.store`: a temporary file renamed; a location
    that cannot be used is said in one line and the entry is not kept)."""
    import h5py

    def write(temporary: Path) -> None:
        with h5py.File(temporary, "w") as h5:
            h5["matrix_per_N"] = stiffness.matrix_per_N
            h5["axial_force_row_N_per_m"] = stiffness.axial_force_row_N_per_m
            h5.attrs.update(format_version=GEOMETRIC_FORMAT_VERSION, basis_digest=basis_digest,
                            axial_mode=stiffness.axial_mode,
                            content_digest=_digest(stiffness.matrix_per_N,
                                                   stiffness.axial_force_row_N_per_m,
                                                   np.array([stiffness.axial_mode])))

    store(path, write, REDUCTION_CACHE)


def geometric_stiffness(reduction: Any) -> GeometricStiffness:
    """The reduction's :class:`GeometricStiffness`: loaded from beside its cache file when
    there is a whole, unchanged entry for its basis, else computed (and stored there, if it
    has one)."""
    path = _cache_path(reduction)
    basis_digest = _digest(reduction.fem.modeBasis["matrix"])
    if path is not None and path.is_file():
        cached = _load(path, basis_digest)
        if cached is not None:
            return cached
    stiffness = compute_geometric_stiffness(reduction)
    if path is not None:
        _save(path, stiffness, basis_digest)
    return stiffness


# ------------------------------------------------------------------------------------------
# Exudyn
# ------------------------------------------------------------------------------------------
class _GeometricForce:
    """f(q) = -[N(q) K_G q + b(q) k_N] with b = q^T K_G q / 2 and N = k_N . q + k_a b, the
    gradient of U_G (module doc), and its exact Jacobian, as the user functions of an Exudyn
    ``ObjectGenericODE2`` on the modal node."""

    def __init__(self, stiffness: GeometricStiffness) -> None:
        self.matrix = np.asarray(stiffness.matrix_per_N, dtype=float)
        self.row = np.asarray(stiffness.axial_force_row_N_per_m, dtype=float)
        self.axial = float(self.row[stiffness.axial_mode])

    def _parts(self, q: np.ndarray) -> tuple[np.ndarray, float, float]:
        bent = self.matrix @ q
        shortening = 0.5 * float(q @ bent)
        return bent, shortening, float(self.row @ q) + self.axial * shortening

    def force(self, mbs, t, item_index, q, q_t) -> np.ndarray:
        """-[N K_G q + b k_N] [N per modal coordinate]."""
        bent, shortening, axial_force = self._parts(np.asarray(q))
        return -(axial_force * bent + shortening * self.row)

    def jacobian(self, mbs, t, item_index, q, q_t, f_ode2, f_ode2_t):
        """``f_ode2`` times the Hessian of U_G (the derivative of minus :meth:`force`)."""
        import exudyn as exu

        bent, _, axial_force = self._parts(np.asarray(q))
        cross = np.outer(bent, self.row)
        tangent = (axial_force * self.matrix + cross + cross.T
                   + self.axial * np.outer(bent, bent))
        container = exu.MatrixContainer()
        container.SetWithDenseMatrix(float(f_ode2) * tangent, useDenseMatrix=True)
        return container


def add_geometric_stiffness(mbs, node_modal: int, stiffness: GeometricStiffness,
                            name: str = "coupler") -> int:
    """Add the geometric stiffness force to the FFRF body whose modal coordinates are the
    node ``node_modal`` (``add_ffrf_link``'s ``node_modal``): an ``ObjectGenericODE2`` with
    no mass acting on that node alone (:class:`_GeometricForce`). Returns its ObjectIndex;
    call ``mbs.Assemble()`` afterwards."""
    import exudyn.itemInterface as eii

    force = _GeometricForce(stiffness)
    size = len(force.row)
    zero = np.zeros((size, size))
    return mbs.AddObject(eii.ObjectGenericODE2(
        name=f"{name}:geometric_stiffness", nodeNumbers=[node_modal],
        massMatrix=zero, stiffnessMatrix=zero,
        forceUserFunction=force.force, jacobianUserFunction=force.jacobian))


# ------------------------------------------------------------------------------------------
# the pinned-pinned link under axial load (the closed-form check)
# ------------------------------------------------------------------------------------------
def pinned_pinned_eigen(reduction: Any, stiffness: GeometricStiffness, compression_N: float,
                        rising: bool = False) -> tuple[float, float]:
    """First in-plane bending frequency [Hz] of the reduced link pinned at both end-face
    centres under an axial compression, and its lowest buckling load [N] in that pattern.

    ``rising`` False: ``compression_N`` [N] uniform along the link (end loads along the
    chord); True: growing linearly from 0 at ``end_a`` to ``compression_N`` at ``end_b``
    (a distributed axial load, e.g. the link's own axial inertia). In the chord frame the
    pinned link is the modal coordinates alone (the frame is held by the two pins, ``end_b``
    free along x): (K - P K_G) v = omega^2 M v. Undamped.
    """
    from scipy.linalg import eigh

    fem = reduction.fem
    basis = fem.modeBasis["matrix"]
    mass = basis.T @ (fem.massMatrix @ basis)
    elastic = basis.T @ (fem.stiffnessMatrix @ basis)
    geometric = (projected(reduction, unit_axial_stress_matrices(reduction, rising=True))
                 if rising else stiffness.matrix_per_N)
    omega2 = eigh(elastic - compression_N * geometric, mass, eigvals_only=True)
    # buckling: the largest mu of G v = mu K v gives the lowest positive load 1 / mu
    mu = eigh(geometric, elastic, eigvals_only=True)
    buckling_N = 1.0 / mu[-1] if mu[-1] > 0 else float("inf")
    frequency = float(np.sqrt(omega2[0]) / (2 * np.pi)) if omega2[0] > 0 else 0.0
    return frequency, float(buckling_N)
