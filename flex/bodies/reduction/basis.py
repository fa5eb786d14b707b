"""The chord-frame Craig-Bampton basis of a plate link: static modes, in-plane eigenmodes,
mode signs (module doc of :mod:`flex.bodies.reduction`: why the chord frame)."""


from __future__ import annotations

import numpy as np

_STATIC_MODES = 6  # of end_b: 3 translations + 3 rotations of the rigid face
#: PINVIT iterations of an in-plane basis. Preconditioned with the exact inverse of the
#: interior stiffness, and with about twice the vectors it keeps, it converges in a few
#: iterations: against Exudyn's default 40, 10 iterations changed the fixed-interface
#: frequencies by at most 6e-8 (relative) and the basis's span by 8e-8 (3 mm plate, 12 modes,
#: 1.5 mm mesh; 1e-10 on the 0.5, 1 and 10 mm plates), at a third of the build time; the
#: eigensolve was ~75 % of a build. PINVIT has no stopping test, so the count is fixed.
EIGENSOLVER_ITERATIONS = 12
#: ``"all"`` keeps every vector it computes, the last converging slowest: Exudyn's default
EIGENSOLVER_ITERATIONS_ALL = 40



def craig_bampton_basis(fem, mass_form, stiffness_form, interfaces: list[np.ndarray],
                        modes: int, selection: str) -> int:
    """Put the chord-frame Craig-Bampton basis in ``fem`` (``modeBasis``, ``eigenValues``):
    static modes and ``modes`` fixed-interface eigenmodes, all of them or the in-plane ones
    (``selection``, see :func:`~flex.bodies.reduction.build.build_reduction`). Returns the
    number of static modes.

    Exudyn's Hurty-Craig-Bampton modes make ``end_a`` the floating frame (it gets no static
    modes) and give ``end_b`` its six rigid-face modes; :func:`_chord_frame` then trades
    ``end_b``'s transverse translations for rotations of ``end_a``, so the frame's x axis runs
    through both face centres (see the module doc for why).

    In-plane eigenmodes: more eigenmodes are computed than asked (about half of a thin
    plate's lowest modes are torsion and out-of-plane bending), their in-plane subspace is
    found (:func:`_in_plane_eigenmodes`), and the count grows until it holds ``modes``.
    """
    computed = modes if selection == "all" else 2 * modes + 4
    iterations = (EIGENSOLVER_ITERATIONS_ALL if selection == "all"
                  else EIGENSOLVER_ITERATIONS)
    while True:
        _seed_eigensolver()
        fem.ComputeHurtyCraigBamptonModesNGsolve(mass_form, stiffness_form, interfaces,
                                                 computed, maxEigensolveIterations=iterations)
        basis = fem.modeBasis["matrix"]
        if selection == "all":
            static = np.arange(_STATIC_MODES)
            eigenmodes, eigenvalues = basis[:, _STATIC_MODES:], np.asarray(fem.eigenValues)
            break
        positions = fem.GetNodePositionsAsArray()
        found = _in_plane_eigenmodes(fem, positions, basis[:, _STATIC_MODES:], modes)
        if found is not None:
            static = np.flatnonzero(
                _mirror_antisymmetry(positions, basis[:, :_STATIC_MODES]) < 0.5)
            eigenmodes, eigenvalues = found
            break
        computed = int(1.5 * computed) + 4
    static_modes = _chord_frame(fem, basis[:, static], interfaces)
    fem.modeBasis["matrix"] = np.ascontiguousarray(np.column_stack([static_modes, eigenmodes]))
    fem.eigenValues = eigenvalues
    return static_modes.shape[1]


def _face_mean(fem, nodes: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """Area-weighted mean displacement (3, m) of the face ``nodes`` in each column."""
    weights = np.asarray(fem.GetNodeWeightsFromSurfaceAreas(nodes))
    return np.einsum("n,ncm->cm", weights / weights.sum(),
                     columns.reshape(-1, 3, columns.shape[1])[nodes])


def _chord_frame(fem, static_modes: np.ndarray, interfaces: list[np.ndarray]) -> np.ndarray:
    """``end_b``'s static modes (columns) with each transverse translation (y, and z when
    kept) replaced by the static mode of a unit rotation of ``end_a`` about the other
    transverse axis (z, and y) through its centre, ``end_b`` clamped: no mode then moves the
    centre of ``end_b`` off the frame's x axis, nor the centre of ``end_a`` off its origin.

    Each new mode is the rigid turn of ``end_a`` [1 rad] carried into the interior by the
    static condensation (K_ii u_i = -K_ib u_b, one sparse factorization for both)."""
    from scipy.sparse.linalg import splu

    end_a, end_b = (np.asarray(nodes) for nodes in interfaces)
    translation = _face_mean(fem, end_b, static_modes)
    positions = fem.GetNodePositionsAsArray()
    centre_a = _face_mean(fem, end_a, positions.reshape(-1, 1))[:, 0]
    size = 3 * len(positions)
    fixed = np.zeros(size, dtype=bool)
    for nodes in (end_a, end_b):
        fixed[(3 * nodes[:, None] + np.arange(3)).ravel()] = True
    stiffness = fem.stiffnessMatrix.tocsc()
    interior = splu(stiffness[~fixed][:, ~fixed].tocsc())
    out = static_modes.copy()
    # (translation replaced, rotation axis of end_a): y <-> z axis, z <-> y axis
    for component, axis in ((1, np.array([0.0, 0.0, 1.0])), (2, np.array([0.0, 1.0, 0.0]))):
        column = np.flatnonzero(np.isclose(translation[component], 1.0, atol=1e-6))
        if len(column) == 0:
            continue
        boundary = np.zeros(size)
        turn = np.cross(axis, positions[end_a] - centre_a)  # small rigid turn, 1 rad
        boundary[(3 * end_a[:, None] + np.arange(3)).ravel()] = turn.ravel()
        mode = boundary.copy()
        mode[~fixed] = interior.solve(-(stiffness[~fixed][:, fixed] @ boundary[fixed]))
        out[:, column[0]] = mode
    return out


def _mirror_parts(positions: np.ndarray, basis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gram matrices of the columns' mirror differences (u minus its mirror image about the
    mechanism plane z = 0, u_z sign flipped) and of the columns with their mirror images.
    Compared at the moving nodes whose mirror point is a node too (netgen meshes the box's
    parallel edges alike: a third of a 3 mm plate's nodes), unless they miss a column (a
    mode still at those nodes), then at every moving node against the node nearest its
    mirror point."""
    from scipy.spatial import cKDTree

    distance, mirror = cKDTree(positions).query(positions * [1.0, 1.0, -1.0])
    fields = basis.reshape(len(positions), 3, -1)
    moving = np.any(fields != 0.0, axis=(1, 2))  # interface nodes are fixed in eigenmodes
    exact = (distance <= 1e-9 * np.ptp(positions, axis=0).max()) & moving
    for nodes in (np.flatnonzero(exact), np.flatnonzero(moving)):  # exact pairs first
        mirrored = fields[mirror[nodes]] * np.array([1.0, 1.0, -1.0])[None, :, None]
        difference = (fields[nodes] - mirrored).reshape(-1, basis.shape[1])
        both = np.concatenate([fields[nodes], mirrored]).reshape(-1, basis.shape[1])
        size = both.T @ both
        scales = np.linalg.eigvalsh(size)
        if len(nodes) >= 12 and scales[0] > 1e-10 * scales[-1]:  # every column seen
            break
    return difference.T @ difference, size


def _mirror_antisymmetry(positions: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """Per column: 0 for a mode symmetric about the mechanism plane (in plane: u_x, u_y even,
    u_z odd in z), 2 for an antisymmetric one (out of plane), between for a mixture."""
    difference, size = _mirror_parts(positions, basis)
    return np.diag(difference) / np.maximum(np.diag(size), 1e-300)


def _in_plane_eigenmodes(fem, positions: np.ndarray, eigenmodes: np.ndarray, modes: int
                         ) -> tuple[np.ndarray, np.ndarray] | None:
    """The lowest ``modes`` in-plane fixed-interface eigenmodes in the span of the computed
    ``eigenmodes`` (columns) and their eigenvalues [rad^2/s^2], or None if the span holds
    too few.

    Why a subspace: on a mesh that is not mirror-symmetric, an in-plane and an out-of-plane
    mode of nearly equal frequency come back mixed. The symmetric subspace (directions whose
    mirror difference is below 5 % of their size) is found first, then the stiffness and
    mass are projected on it and its eigenmodes solved (Rayleigh-Ritz, mass-normalised).
    Directions in between (a mixed pair cut by the computed count) are left out, and modes
    count only below the lowest such direction's Rayleigh frequency.
    """
    from scipy.linalg import eigh

    difference, size = _mirror_parts(positions, eigenmodes)
    share, directions = eigh(difference, size)  # 0: in plane ... 2: out of plane
    symmetric = eigenmodes @ directions[:, share < 0.1]
    stiffness = symmetric.T @ (fem.stiffnessMatrix @ symmetric)
    mass = symmetric.T @ (fem.massMatrix @ symmetric)
    eigenvalues, combination = eigh(stiffness, mass)
    mixed = eigenmodes @ directions[:, (share >= 0.1) & (share <= 1.9)]
    if mixed.shape[1]:
        quotients = (np.sum(mixed * (fem.stiffnessMatrix @ mixed), axis=0)
                     / np.sum(mixed * (fem.massMatrix @ mixed), axis=0))
        trusted = eigenvalues < quotients.min()
        eigenvalues, combination = eigenvalues[trusted], combination[:, trusted]
    if len(eigenvalues) < modes:
        return None
    return symmetric @ combination[:, :modes], eigenvalues[:modes]


#: the seed of NGsolve's random generator before each eigensolve (PINVIT starts from
#: random vectors drawn from one process-wide generator: without a seed, a reduction
#: depended on how many were built before it in the same process, ~1e-4 on the 5 and 10 mm
#: plates' stored values when a study's cases ran in another order)
EIGENSOLVER_SEED = 1


def _seed_eigensolver() -> None:
    """Reset NGsolve's random generator to :data:`EIGENSOLVER_SEED` (its only handle: a
    vector's ``SetRandom(seed=...)``), so that every build starts from the same vectors."""
    import ngsolve.la

    ngsolve.la.CreateVVector(1).SetRandom(seed=EIGENSOLVER_SEED)


def fix_eigenmode_signs(basis: np.ndarray, static_modes: int = _STATIC_MODES) -> None:
    """Turn each fixed-interface eigenmode so its largest entry is positive (in place).

    PINVIT returns modes of arbitrary sign (and threads change round-off), so two builds of
    one key could give modal coordinates of opposite sign; this makes them comparable. The
    first entry within 1e-6 of the largest is used, so round-off cannot change the pick.
    """
    for column in range(static_modes, basis.shape[1]):
        magnitude = np.abs(basis[:, column])
        pick = int(np.argmax(magnitude >= (1 - 1e-6) * magnitude.max()))
        if basis[pick, column] < 0:
            basis[:, column] *= -1

