"""Geometric stiffness of an FFRF plate link: the stress-stiffening of its reduced modes under
the link's axial force.

A floating-frame body is linear elastic in its own frame: a compressed link keeps its bending
stiffness, so a thin coupler near its Euler load bends far less in the linear FFRF model than
in the fully nonlinear FE one (docs/stability.md). The missing term is the initial-stress
(geometric) stiffness of the axial force N (tension positive) [N]::

    K_sigma(N) = N / A * integral over the plate of  du/dx . dv/dx  dV      (A = t w)

the second-order work of a uniform axial stress N / A through the rotations of the material
lines (the 1/2 (du_y/dx)^2 + 1/2 (du_z/dx)^2 part of the Green strain the linear body drops).
Projected on the reduction's mode basis Phi once per reduction, ``K_G = Phi^T K_sigma(1 N)
Phi`` [1/m], and its part weighted by x / L, ``K_b`` (a tension at ``end_b`` falling
linearly to zero at ``end_a``). The body gets the generalized force on its modal coordinates
q (:class:`_GeometricForce`)::

    f(q) = -[N K_G + (N_C - N) (2 K_b - K_G)] q

an axial force varying linearly along the link with mean N and value N_C at ``end_b``:

- N(q) = k_N . q, the link's mean axial force from its own stretch: the elastic force of the
  ``end_b`` axial static mode (``k_N`` its row of the reduced stiffness matrix), ringing
  included;
- N_C, the tension at joint C: its reaction along the body's x axis, read at each call
  (:func:`joint_tension`; None: uniform, N_C = N).

Why the variation matters: the coupler's own axial inertia makes its compression differ
between B and C (measured 14 against 18 N on the 0.5 mm plate, 20 %), and with the frame at
``end_a`` the elastic rotations w' of a pinned bending mode vanish at B and are largest at
C, so the end C compression weighs most. With the mean alone the 0.5 mm plate's peak was
7.5 % below the nonlinear FE one, with the linear variation 1.1 % (docs/geometric-stiffness.md).

Why the full K_G and nothing subtracted: the floating frame is the ``end_a`` face. A bent
pinned link's chord is turned against that frame by delta_C / L (delta_C: the frame-y
displacement of ``end_b``), and the FFRF model, whose frame rotation is exact, already puts
the axial force through that rigid turn (the chord's length grows by delta_C^2 / 2L). The
complete second-order potential of the axial force, -N/2 integral((theta + w')^2) with the
frame angle theta = -delta_C / L against the chord, splits into that rigid part
(+N delta_C^2 / 2L) and -N/2 integral(w'^2) over the elastic field w measured in the frame,
which is exactly q^T K_G q / 2 with K_G over the whole basis (static modes included).
:func:`pinned_pinned_eigen` checks the sum against the Euler load and against
f(P) = f0 sqrt(1 - P / P_E).

Validity (``make ladder``, docs/geometric-stiffness.md): within 1 % of the nonlinear FE
coupler's peak deflection from 0.7 mm up, 1.1 % at 0.5-0.6 mm (compression up to 0.56 of the
Euler load); at 0.5 mm only at a coarse step (1e-4 s: Newton fails at finer ones, the axial
ringing modulating every bending mode through the single axial static mode); beyond the
Euler load the body buckles without bound (linear in N) and the run fails.

Cached beside the reduction (``<key>.geometric.hdf5`` in the reduction's cache folder, keyed
by the reduction's key and a digest of its mode basis); a reduction without a cache file
computes it afresh (a mesh and one bilinear form: about as long as meshing the plate).
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

#: bump when the content or layout of a cache entry changes (old entries are then rebuilt)
GEOMETRIC_FORMAT_VERSION = 2
_SUFFIX = ".geometric.hdf5"


@dataclass(frozen=True)
class GeometricStiffness:
    """The reduced geometric stiffness of one :class:`flex.bodies.reduction.Reduction`.

    ``matrix_per_N`` (K_G, m x m over the modal coordinates, [1/m]: generalized stiffness
    per newton of uniform axial tension); ``matrix_end_b_per_N`` (K_b [1/m]: the same for a
    tension of 1 N at ``end_b`` falling linearly to 0 at ``end_a``); ``axial_force_row_N_per_m``
    (k_N: the link's mean axial force N = k_N . q [N], tension positive); ``axial_mode``
    (column of the ``end_b`` axial static mode); ``from_cache``.
    """

    matrix_per_N: np.ndarray
    matrix_end_b_per_N: np.ndarray
    axial_force_row_N_per_m: np.ndarray
    axial_mode: int
    from_cache: bool = False

    def axial_force_N(self, modal_coordinates: np.ndarray) -> np.ndarray:
        """The link's axial force [N] (tension > 0) at modal coordinates of shape (m,) or
        (n, m)."""
        return np.asarray(modal_coordinates, dtype=float) @ self.axial_force_row_N_per_m


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


def _unit_axial_stress_matrices(reduction: Any) -> tuple[Any, Any]:
    """K_sigma for 1 N of axial tension over the plate's mesh, Exudyn coordinate order
    (x, y, z per node), scipy CSR [1/m]: (1 / A) integral du/dx . dv/dx dV; and the same
    weighted by x / L (the share of a tension at ``end_b`` that falls linearly to zero at
    ``end_a``).

    The mesh is remade with the reduction's arguments (the same mesh and node numbering, as
    :mod:`flex.bodies.nonlinear` relies on); the node positions are checked against the
    reduction's.
    """
    import ngsolve as ngs
    from scipy.sparse import csr_matrix

    from flex.bodies.nonlinear import build_nonlinear_plate

    r = reduction
    plate = build_nonlinear_plate(r.length_m, r.thickness_m, r.width_m, r.youngs_modulus_Pa,
                                  r.density_kg_per_m3, r.poisson_ratio, r.mesh_size_m)
    positions = r.fem.GetNodePositionsAsArray()
    if plate.node_positions_m.shape != positions.shape or not np.allclose(
            plate.node_positions_m, positions, rtol=0, atol=1e-9 * r.length_m):
        raise RuntimeError("the remade mesh differs from the reduction's: cannot project")
    space = ngs.NodalFESpace(plate.mesh, order=2) ** 3
    u, v = space.TnT()
    along = ngs.CF((1.0, 0.0, 0.0))
    n_nodes = len(positions)
    coordinate = np.arange(3 * n_nodes)
    ngsolve_index = (coordinate % 3) * n_nodes + coordinate // 3  # of Exudyn 3 i + c
    matrices = []
    for weight in (1.0, ngs.x / r.length_m):
        form = ngs.BilinearForm(space)
        form += (weight / (r.thickness_m * r.width_m)) * ngs.InnerProduct(
            ngs.Grad(u) * along, ngs.Grad(v) * along) * ngs.dx
        form.Assemble()
        values, columns, pointers = form.mat.CSR()
        matrix = csr_matrix((np.asarray(values), np.asarray(columns).astype(np.int64),
                             np.asarray(pointers).astype(np.int64)),
                            shape=(space.ndof, space.ndof))
        matrices.append(matrix[ngsolve_index][:, ngsolve_index])
    return matrices[0], matrices[1]


def compute_geometric_stiffness(reduction: Any) -> GeometricStiffness:
    """K_G and k_N of ``reduction`` (see the module doc), computed on its mesh."""
    basis = reduction.fem.modeBasis["matrix"]
    uniform, rising = (basis.T @ (matrix @ basis)
                       for matrix in _unit_axial_stress_matrices(reduction))
    stiffness = basis.T @ (reduction.fem.stiffnessMatrix @ basis)
    mode = _axial_mode(reduction)
    return GeometricStiffness(matrix_per_N=0.5 * (uniform + uniform.T),
                              matrix_end_b_per_N=0.5 * (rising + rising.T),
                              axial_force_row_N_per_m=np.asarray(stiffness[mode]).ravel(),
                              axial_mode=mode)


# ------------------------------------------------------------------------------------------
# cache
# ------------------------------------------------------------------------------------------
def _basis_digest(reduction: Any) -> str:
    basis = np.ascontiguousarray(reduction.fem.modeBasis["matrix"])
    return hashlib.sha256(str(basis.shape).encode() + basis.tobytes()).hexdigest()[:24]


def _cache_path(reduction: Any) -> Path | None:
    cache_file = getattr(reduction, "cache_file", None)
    if cache_file is None:
        return None
    return Path(cache_file).with_name(f"{reduction.key}{_SUFFIX}")


def _load(path: Path, digest: str) -> GeometricStiffness | None:
    """The entry at ``path`` if whole and made for this basis, else None."""
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            if (h5.attrs["format_version"] != GEOMETRIC_FORMAT_VERSION
                    or h5.attrs["basis_digest"] != digest):
                return None
            return GeometricStiffness(matrix_per_N=h5["matrix_per_N"][()],
                                      matrix_end_b_per_N=h5["matrix_end_b_per_N"][()],
                                      axial_force_row_N_per_m=h5["axial_force_row_N_per_m"][()],
                                      axial_mode=int(h5.attrs["axial_mode"]), from_cache=True)
    except Exception:  # missing, truncated or foreign: rebuilt by the caller
        return None


def _save(path: Path, stiffness: GeometricStiffness, digest: str) -> None:
    """Write atomically (a temporary file renamed): readers never see half an entry."""
    import h5py

    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=path.stem + ".", suffix=".tmp",
                                         dir=path.parent)
    os.close(handle)
    try:
        with h5py.File(temporary, "w") as h5:
            h5["matrix_per_N"] = stiffness.matrix_per_N
            h5["matrix_end_b_per_N"] = stiffness.matrix_end_b_per_N
            h5["axial_force_row_N_per_m"] = stiffness.axial_force_row_N_per_m
            h5.attrs.update(format_version=GEOMETRIC_FORMAT_VERSION, basis_digest=digest,
                            axial_mode=stiffness.axial_mode)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def geometric_stiffness(reduction: Any) -> GeometricStiffness:
    """The reduction's :class:`GeometricStiffness`: loaded from beside its cache file when
    there is a whole entry for its basis, else computed (and stored there, if it has one)."""
    path = _cache_path(reduction)
    digest = _basis_digest(reduction)
    if path is not None and path.is_file():
        cached = _load(path, digest)
        if cached is not None:
            return cached
    stiffness = compute_geometric_stiffness(reduction)
    if path is not None:
        _save(path, stiffness, digest)
    return stiffness


# ------------------------------------------------------------------------------------------
# Exudyn
# ------------------------------------------------------------------------------------------
class _GeometricForce:
    """The generalized force on the modal coordinates and its Jacobian, as the user functions
    of an Exudyn ``ObjectGenericODE2`` on the modal node.

    Without ``end_b_tension``: f = -N(q) K_G q, N the link's mean axial force (its stretch).
    With it (a callable of ``mbs`` giving the tension at ``end_b`` [N], e.g. a joint's
    reaction, :func:`joint_tension`): the axial force falls linearly from N_b at ``end_b``
    to 2 N - N_b at ``end_a`` (the same mean), f = -[N K_G + (N_b - N) (2 K_b - K_G)] q with
    K_b the x / L weighted matrix. N_b is read at every call, in step with the state (the
    Newton iterate's Lagrange multiplier); its dependence on the multiplier is left out of
    the Jacobian. (Read once per step instead, it lags the axial ringing by a step and the
    0.5 mm plate diverged at every step tried.)
    """

    def __init__(self, stiffness: GeometricStiffness, end_b_tension=None) -> None:
        self.matrix = np.asarray(stiffness.matrix_per_N, dtype=float)
        self.gradient = 2.0 * np.asarray(stiffness.matrix_end_b_per_N) - self.matrix
        self.row = np.asarray(stiffness.axial_force_row_N_per_m, dtype=float)
        self.end_b_tension = end_b_tension

    def _parts(self, mbs, q: np.ndarray) -> tuple[float, float]:
        mean = float(self.row @ q)
        excess = 0.0 if self.end_b_tension is None else self.end_b_tension(mbs) - mean
        return mean, excess

    def force(self, mbs, t, item_index, q, q_t) -> np.ndarray:
        """-[N K_G + (N_b - N)(2 K_b - K_G)] q [N per modal coordinate]."""
        q = np.asarray(q)
        mean, excess = self._parts(mbs, q)
        return -(mean * (self.matrix @ q) + excess * (self.gradient @ q))

    def jacobian(self, mbs, t, item_index, q, q_t, f_ode2, f_ode2_t):
        """``f_ode2`` times the derivative of minus :meth:`force` in q (Exudyn's sign), N_b
        held."""
        import exudyn as exu

        q = np.asarray(q)
        mean, excess = self._parts(mbs, q)
        tangent = (mean * self.matrix + excess * self.gradient
                   + np.outer((self.matrix - self.gradient) @ q, self.row))
        container = exu.MatrixContainer()
        container.SetWithDenseMatrix(float(f_ode2) * tangent, useDenseMatrix=True)
        return container


def joint_tension(joint: int, frame_node: int):
    """A callable of ``mbs`` giving the tension [N] a joint puts on its second body along
    the x axis of the FFRF body whose floating frame is ``frame_node``: minus the joint's
    global ``Force`` output (Exudyn reports the force on the first body) dotted with that
    axis. For :func:`add_geometric_stiffness`'s ``end_b_tension`` (a joint at ``end_b``)."""
    import exudyn as exu

    def tension(mbs) -> float:
        force = np.asarray(mbs.GetObjectOutput(joint, exu.OutputVariableType.Force))
        rotation = np.asarray(mbs.GetNodeOutput(frame_node,
                                                exu.OutputVariableType.RotationMatrix))
        return float(-force @ rotation.reshape(3, 3)[:, 0])

    return tension


def add_geometric_stiffness(mbs, node_modal: int, stiffness: GeometricStiffness,
                            name: str = "coupler", end_b_tension=None) -> int:
    """Add the geometric stiffness force to the FFRF body whose modal coordinates are the
    node ``node_modal`` (``add_ffrf_link``'s ``node_modal``): an ``ObjectGenericODE2`` with
    no mass acting on that node alone (:class:`_GeometricForce`; ``end_b_tension``: None
    for a uniform axial force, or e.g. :func:`joint_tension` of the joint at ``end_b``).
    Returns its ObjectIndex; call ``mbs.Assemble()`` afterwards."""
    import exudyn.itemInterface as eii

    force = _GeometricForce(stiffness, end_b_tension)
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
    (a distributed axial load, e.g. the link's own axial inertia). The coordinates are the
    modal ones and a small rigid turn theta of the frame about z at ``end_a`` (the FFRF
    frame's rotation against the chord); ``end_b``'s y displacement is held
    (theta L + delta_C(q) = 0), its x free. The turn's mass terms come from the mesh's mass
    matrix, its geometric terms are closed-form (a rigid turn: du_y/dx = theta), the elastic
    ones K_G (or its x / L weighted part): together the whole second-order potential of the
    axial force, as the FFRF model's exact frame rotation plus :class:`_GeometricForce`
    make it. Undamped; solved on the constraint's null space.
    """
    from scipy.linalg import eigh, null_space

    fem = reduction.fem
    basis = fem.modeBasis["matrix"]
    positions = fem.GetNodePositionsAsArray()
    turn = np.zeros_like(positions)  # rigid turn about z at end_a: (-y, x, 0)
    turn[:, 0], turn[:, 1] = -positions[:, 1], positions[:, 0]
    full = np.column_stack([turn.ravel(), basis])
    mass = full.T @ (fem.massMatrix @ full)
    elastic = np.zeros_like(mass)
    elastic[1:, 1:] = basis.T @ (fem.stiffnessMatrix @ basis)
    end_b_y = face_mean_displacement(reduction, "end_b")[1]
    geometric = _turn_geometric(reduction, stiffness, end_b_y, rising)
    held = null_space(np.concatenate([[reduction.length_m], end_b_y])[None, :])
    mass_h, elastic_h, geometric_h = (held.T @ m @ held for m in (mass, elastic, geometric))
    omega2 = eigh(elastic_h - compression_N * geometric_h, mass_h, eigvals_only=True)
    # buckling: the largest mu of G v = mu K v gives the lowest positive load 1 / mu
    mu = eigh(geometric_h, elastic_h, eigvals_only=True)
    buckling_N = 1.0 / mu[-1] if mu[-1] > 0 else float("inf")
    frequency = float(np.sqrt(omega2[0]) / (2 * np.pi)) if omega2[0] > 0 else 0.0
    return frequency, float(buckling_N)


def _turn_geometric(reduction: Any, stiffness: GeometricStiffness, end_b_y: np.ndarray,
                    rising: bool) -> np.ndarray:
    """The geometric matrix per newton [1/m] over (turn, modes) for a uniform (``rising``
    False) or linearly rising (0 at ``end_a``, 1 N at ``end_b``) axial tension.

    Turn terms (1 / A) integral w(x) du_turn/dx . dv/dx dV with du_turn/dx = (0, 1, 0):
    turn-turn L mean(w); turn-mode integral(w phi_y') dx = phi_y(end_b) (w = 1) or
    phi_y(end_b) - mean of phi_y over the volume (w = x / L, by parts)."""
    size = len(end_b_y) + 1
    geometric = np.zeros((size, size))
    if not rising:
        geometric[0, 0] = reduction.length_m
        geometric[0, 1:] = geometric[1:, 0] = end_b_y
        geometric[1:, 1:] = stiffness.matrix_per_N
        return geometric
    fem = reduction.fem
    basis = fem.modeBasis["matrix"]
    along_y = np.zeros(basis.shape[0])
    along_y[1::3] = 1.0
    volume_m3 = reduction.length_m * reduction.thickness_m * reduction.width_m
    mean_y = (along_y @ (fem.massMatrix @ basis)) / (reduction.density_kg_per_m3 * volume_m3)
    geometric[0, 0] = reduction.length_m / 2
    geometric[0, 1:] = geometric[1:, 0] = end_b_y - mean_y
    geometric[1:, 1:] = stiffness.matrix_end_b_per_N
    return geometric
