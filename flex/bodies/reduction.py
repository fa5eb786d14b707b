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

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import numbers
import os
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from flex.base.errors import SceneError
from flex.bodies.plate import PlateLink, plate_mesh
from flex.data.cache import (
    REDUCTION_CACHE,
    content_digest,
    entry_problem,
    number_text,
    say,
    store,
)

#: Bump when the content or layout of a cache file changes; old entries are then rebuilt.
CACHE_FORMAT_VERSION = 2  # 2: the chord frame (end_a rotation static modes)

END_A = "end_a"  #: mesh boundary name of the joint-B face (x = 0)
END_B = "end_b"  #: mesh boundary name of the joint-C face (x = length)
MID = "mid"  #: node-set name of the mid-length cross-section

_MESH_ORDER = 2  # linear tets lock in bending (notes: first frequency 69-90 % too high)
_STATIC_MODES = 6  # of end_b: 3 translations + 3 rotations of the rigid face
#: which modes a reduction keeps (:func:`build_reduction`)
MODE_SELECTIONS = ("in_plane", "all")


# ------------------------------------------------------------------------------------------
# result type
# ------------------------------------------------------------------------------------------
@dataclass
class Reduction(PlateLink):
    """A reduced flexible plate link, ready for :func:`add_ffrf_link`.

    Node index arrays refer to ``fem``'s mesh nodes; weights sum to 1. ``centre_*`` are the
    weighted reference positions of the node sets in body coordinates [m]: the points the
    markers of :func:`add_ffrf_link` report.
    """

    fem: Any  #: exudyn.FEM.FEMinterface holding mesh, M, K, mode basis, stress modes
    modes: int  #: number of fixed-interface eigenmodes kept (the static modes come on top)
    mode_selection: str  #: "in_plane" or "all" (:data:`MODE_SELECTIONS`)
    fixed_interface_frequencies_Hz: np.ndarray  #: both end faces clamped
    pinned_pinned_frequency_Hz: float  #: first in-plane bending mode, ends pinned about z
    mass_kg: float  #: [kg]
    n_nodes: int
    n_elements: int  #: second-order tetrahedra
    n_dof: int  #: 3 * n_nodes, unreduced
    cold_build_time_s: float  #: time of the original (uncached) build
    build_time_s: float  #: time spent by this call: the build, or the cache load
    from_cache: bool
    cache_file: Path | None
    key: str  #: hash of everything the reduction depends on
    _ffrf_interface: Any = field(default=None, repr=False, compare=False)

    @property
    def n_modal_coordinates(self) -> int:
        """Number of elastic coordinates of the reduced body: the static modes of ``end_b``
        (6, or its 3 in-plane ones) + ``modes``."""
        return int(self.fem.modeBasis["matrix"].shape[1])

    @property
    def has_stress_modes(self) -> bool:
        """True if the FEMinterface carries stress post-processing modes."""
        return "matrix" in (self.fem.postProcessingModes or {})

    def ffrf_interface(self):
        """The ``ObjectFFRFreducedOrderInterface`` of this reduction, made once and reused.

        Its constructor projects the full mass matrix on the basis (the costly part of adding
        a body), so several systems built from one reduction share it.
        """
        if self._ffrf_interface is None:
            from exudyn.FEM import ObjectFFRFreducedOrderInterface

            self._ffrf_interface = ObjectFFRFreducedOrderInterface(self.fem)
        return self._ffrf_interface


class MidpointDeflection(NamedTuple):
    """Elastic midpoint response relative to the chord B-C, both zero at the first sample [m]."""

    transverse_m: np.ndarray  #: along the in-plane chord normal e_z x (C - B)/|C - B|
    chord_change_m: np.ndarray  #: |C - B| minus its first value (axial stretch of the link)


# ------------------------------------------------------------------------------------------
# input checks
# ------------------------------------------------------------------------------------------
def _is_number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _check_inputs(sizes: dict[str, float], poisson_ratio: float, modes: int) -> None:
    for name, value in sizes.items():
        if not (_is_number(value) and math.isfinite(value) and value > 0):
            raise SceneError(f"reduction {name} = {value!r}: must be a finite number > 0")
    if not (_is_number(poisson_ratio) and 0.0 < poisson_ratio < 0.5):
        raise SceneError(
            f"reduction poisson_ratio = {poisson_ratio!r}: must lie in the open range (0, 0.5)")
    if isinstance(modes, bool) or not isinstance(modes, int | np.integer) or modes < 1:
        raise SceneError(f"reduction modes = {modes!r}: must be an integer >= 1")
    if sizes["mesh_size_m"] > sizes["length_m"]:
        raise SceneError(
            f"reduction mesh_size_m = {sizes['mesh_size_m']!r}: must be <= length_m "
            f"({sizes['length_m']!r}); the notes recommend about 1-2 x thickness")


# ------------------------------------------------------------------------------------------
# cache
# ------------------------------------------------------------------------------------------
def reduction_cache_dir(environ: Mapping[str, str]) -> Path:
    """The reduction cache folder named by ``environ`` (a mapping of environment variables,
    e.g. ``os.environ`` read by a command line; this function reads nothing else):
    ``$FLEX_CACHE_DIR/reductions`` if set, else ``$XDG_CACHE_HOME/flex/reductions``, else
    ``~/.cache/flex/reductions`` (``~``: ``$HOME``, or the user's entry in the password
    database when ``environ`` has none), whatever folder the command runs from."""
    home = _home(environ)
    configured = environ.get("FLEX_CACHE_DIR")
    if configured:
        if configured == "~" or configured.startswith("~/"):
            return home / configured[2:] / "reductions"
        return Path(configured).expanduser() / "reductions"  # "~user/..." or a plain path
    base = environ.get("XDG_CACHE_HOME") or home / ".cache"
    return Path(base) / "flex" / "reductions"


def _home(environ: Mapping[str, str]) -> Path:
    """``$HOME`` of ``environ``, else the user's home from the password database."""
    if environ.get("HOME"):
        return Path(environ["HOME"])
    try:
        import pwd

        return Path(pwd.getpwuid(os.getuid()).pw_dir)
    except (ImportError, KeyError):  # no password database (Windows): the platform's rule
        return Path.home()


def _engine_versions() -> dict[str, str]:
    # installed distribution versions: no need to import ngsolve (0.5 s) for a cache hit
    from importlib.metadata import version

    return {"exudyn": version("exudyn"), "ngsolve": version("ngsolve")}


def _cache_key(parameters: dict[str, Any]) -> str:
    # repr(float) is exact and canonical, so 0.003 and 3e-3 hash alike, 0.0030000001 not
    canonical = {k: (repr(float(v)) if isinstance(v, float) else v)
                 for k, v in parameters.items()}
    canonical["format_version"] = CACHE_FORMAT_VERSION
    canonical.update(_engine_versions())
    text = json.dumps(canonical, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def _content_digest(fem) -> str:
    """SHA-256 over the arrays a simulation uses: detects a damaged file that still opens."""
    digest = hashlib.sha256()
    parts = [fem.GetNodePositionsAsArray(), fem.modeBasis["matrix"], np.asarray(fem.eigenValues)]
    for matrix in (fem.massMatrix, fem.stiffnessMatrix):
        parts += [matrix.data, matrix.indices, matrix.indptr]
    if "matrix" in (fem.postProcessingModes or {}):
        parts.append(fem.postProcessingModes["matrix"])
    for node_set in fem.nodeSets:
        parts += [node_set["NodeNumbers"], node_set["NodeWeights"]]
    for part in parts:
        array = np.ascontiguousarray(part)
        digest.update(str(array.dtype).encode() + str(array.shape).encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def _load_cached(path: Path, key: str):
    """Return the FEMinterface stored under ``path`` if it is whole and made for ``key``.

    Returns None for a missing, truncated, foreign or damaged file (the caller rebuilds).
    """
    if not path.is_file():
        return None
    import h5py

    # check with h5py first: FEMinterface.LoadFromFile prints a banner before re-raising
    try:
        with h5py.File(path, "r") as h5:
            stored_key = h5["metaData"]["flex"]["key"][()]
    except Exception:
        return None
    if isinstance(stored_key, bytes):
        stored_key = stored_key.decode()
    if stored_key != key:
        return None
    from exudyn.FEM import FEMinterface

    fem = FEMinterface()
    try:
        fem.LoadFromFile(str(path), mode="HDF5")
        meta = fem.metaData["flex"]
        if (meta["digest"] != _content_digest(fem)
                or meta.get("meta_digest") != _meta_digest(meta)):
            return None
        n_nodes = fem.NumberOfNodes()
        if fem.modeBasis["matrix"].shape[0] != 3 * n_nodes:
            return None
    except Exception:
        return None
    return fem


def _meta_digest(meta: Mapping[str, Any]) -> str:
    """Digest of the entry's own numbers (mass, frequency, ...: read by :class:`Reduction`
    as they are stored), beside :func:`_content_digest` of its arrays."""
    return content_digest((name, number_text(meta[name])) for name in sorted(meta)
                          if name not in ("digest", "meta_digest"))


def _say_unproven(path: Path | None) -> None:
    """One line when an existing entry is about to be rebuilt (it did not prove its
    content: damaged, edited, foreign, an older format, or not a file)."""
    if path is None or not path.is_file() or entry_problem(path):
        return  # missing, or not a file: store() says why it cannot be kept
    say(REDUCTION_CACHE, f"entry '{path}' did not prove its content (its key or content "
                         f"digest does not match: damaged, edited, foreign or of an older "
                         f"format); building the reduction again")


# ------------------------------------------------------------------------------------------
# building
# ------------------------------------------------------------------------------------------
def _node_set(fem, name: str) -> dict:
    for node_set in fem.nodeSets:
        if node_set["Name"] == name:
            return node_set
    raise KeyError(name)


def _mid_set(positions: np.ndarray, length_m: float, mesh_size_m: float,
             ) -> tuple[np.ndarray, np.ndarray]:
    """Nodes of a thin slab around x = length/2 and weights placing their centre there.

    A tetrahedral mesh has no node plane at mid-length, so the marker averages a slab of
    half-width mesh_size/4 (widened until it holds >= 8 nodes). Equal weights are corrected by
    the smallest change that puts the weighted reference centre exactly at (L/2, 0, 0); if that
    would make a weight non-positive the equal weights are kept (centre then off by << h).
    The slab average differs from the mid-section value by O((h/L)^2) in the deflection.
    """
    distance = np.abs(positions[:, 0] - length_m / 2)
    half_width = 0.25 * mesh_size_m
    nodes = np.flatnonzero(distance <= half_width)
    while len(nodes) < 8:
        half_width *= 1.5
        nodes = np.flatnonzero(distance <= half_width)
    weights = np.full(len(nodes), 1.0 / len(nodes))
    constraint = np.vstack([np.ones(len(nodes)), positions[nodes].T])  # sum, x, y, z
    target = np.array([1.0, length_m / 2, 0.0, 0.0])
    try:
        correction = constraint.T @ np.linalg.solve(constraint @ constraint.T,
                                                    target - constraint @ weights)
        if np.all(weights + correction > 0):
            weights = weights + correction
    except np.linalg.LinAlgError:
        pass
    return nodes, unit_sum(weights)


def unit_sum(weights: np.ndarray) -> np.ndarray:
    """Marker weights scaled to sum to 1 (Exudyn warns, once per marker and run, when a
    solve left their sum off 1 by round-off)."""
    weights = np.asarray(weights, dtype=float)
    return weights / math.fsum(weights)


def _pinned_pinned_frequency_Hz(ffrf_interface, reduction_length_m: float,
                                thickness_m: float, width_m: float,
                                nodes_end_a, weights_end_a, nodes_end_b, weights_end_b,
                                ) -> float:
    """First bending frequency of the reduced body with both end faces pinned about z.

    Exudyn's constrained eigenvalue solver on the body alone: each end face is held in all
    translations and in rotation about x and y, rotation about z free (a revolute pin). With
    the out-of-plane rotations held at both ends, the lowest mode is the in-plane one while
    thickness < ~2.2 x width (pinned-pinned 9.87 t vs clamped-clamped 22.4 w); beyond that
    NaN is returned instead of a wrong mode.
    """
    if thickness_m > 2.0 * width_m:
        return float("nan")
    import exudyn as exu
    import exudyn.itemInterface as eii

    system_container = exu.SystemContainer()
    mbs = system_container.AddSystem()
    body = ffrf_interface.AddObjectFFRFreducedOrder(mbs, positionRef=[0.0, 0.0, 0.0])
    ground = mbs.AddObject(eii.ObjectGround())
    for nodes, weights, x in ((nodes_end_a, weights_end_a, 0.0),
                              (nodes_end_b, weights_end_b, reduction_length_m)):
        face = mbs.AddMarker(eii.MarkerSuperElementRigid(
            bodyNumber=body["oFFRFreducedOrder"], meshNodeNumbers=nodes,
            weightingFactors=weights))
        support = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=ground,
                                                    localPosition=[x, 0.0, 0.0]))
        mbs.AddObject(eii.GenericJoint(markerNumbers=[support, face],
                                       constrainedAxes=[1, 1, 1, 1, 1, 0]))
    mbs.Assemble()
    eigenvalues, _ = mbs.ComputeODE2Eigenvalues(useAbsoluteValues=True)
    eigenvalues = np.sort(np.abs(np.asarray(eigenvalues)))
    # the constraint projection leaves no rigid-body modes; skip round-off zeros anyway
    eigenvalues = eigenvalues[eigenvalues > 1e-6 * eigenvalues[-1]]
    return float(np.sqrt(eigenvalues[0]) / (2 * np.pi))


@contextlib.contextmanager
def _ngsolve_thread_count(threads: int | None) -> Iterator[None]:
    """Run NGsolve's task manager with ``threads`` threads inside the block, then restore."""
    if threads is None:
        yield
        return
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise SceneError(f"ngsolve_threads = {threads!r}: must be an integer >= 1 or None")
    import ngsolve

    with ngsolve.TaskManager():  # the count in force is only visible inside a task manager
        previous = ngsolve.GetNumThreads()
    ngsolve.SetNumThreads(threads)
    try:
        yield
    finally:
        ngsolve.SetNumThreads(previous)


def _craig_bampton_basis(fem, mass_form, stiffness_form, interfaces: list[np.ndarray],
                         modes: int, selection: str) -> int:
    """Put the chord-frame Craig-Bampton basis in ``fem`` (``modeBasis``, ``eigenValues``):
    static modes and ``modes`` fixed-interface eigenmodes, all of them or the in-plane ones
    (``selection``, see :func:`build_reduction`). Returns the number of static modes.

    Exudyn's Hurty-Craig-Bampton modes make ``end_a`` the floating frame (it gets no static
    modes) and give ``end_b`` its six rigid-face modes; :func:`_chord_frame` then trades
    ``end_b``'s transverse translations for rotations of ``end_a``, so the frame's x axis runs
    through both face centres (see the module doc for why).

    In-plane eigenmodes: more eigenmodes are computed than asked (about half of a thin
    plate's lowest modes are torsion and out-of-plane bending), their in-plane subspace is
    found (:func:`_in_plane_eigenmodes`), and the count grows until it holds ``modes``.
    """
    computed = modes if selection == "all" else 2 * modes + 4
    while True:
        fem.ComputeHurtyCraigBamptonModesNGsolve(mass_form, stiffness_form, interfaces,
                                                 computed)
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


def _fix_eigenmode_signs(basis: np.ndarray, static_modes: int = _STATIC_MODES) -> None:
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


def build_reduction(length_m: float, thickness_m: float, width_m: float,
                    youngs_modulus_Pa: float, density_kg_per_m3: float, poisson_ratio: float,
                    mesh_size_m: float, modes: int,
                    cache_dir: str | os.PathLike | None, *,
                    mode_selection: str = "in_plane",
                    ngsolve_threads: int | None = 1) -> Reduction:
    """Mesh, reduce and cache a plate link; return the :class:`Reduction`.

    Contract:
      - sizes in metres, E in Pa, density in kg/m^3; ``mesh_size_m`` is netgen's maxh
        (recommendation: about the thickness, at most 2 x thickness); ``modes`` >= 1 is the
        number of fixed-interface (both faces clamped) eigenmodes added to the static modes
        of ``end_b``. Bad values raise :class:`flex.base.errors.SceneError`.
      - ``mode_selection``: ``"in_plane"`` (default) keeps only modes symmetric about the
        mechanism plane z = 0 -- the 3 in-plane static modes of ``end_b`` (x, y, rotation
        about z) and the lowest ``modes`` in-plane eigenmodes -- since a planar mechanism
        loads its links in plane and the out-of-plane bending and torsion modes carry
        nothing (decoupled by symmetry, :func:`_in_plane_eigenmodes`); ``"all"`` keeps the 6
        static modes and the lowest ``modes`` eigenmodes of any kind.
      - the mesh uses second-order tetrahedra; stress post-processing modes (local stress,
        Pa per unit modal coordinate) are always computed.
      - ``cache_dir``: directory of the cache (created if missing) or None for no caching. The
        entry is ``<key>.hdf5``, ``key`` hashing every argument except ``cache_dir``, the
        cache format version and the exudyn and ngsolve versions. A whole entry for the same
        key is loaded (``from_cache`` True); a missing, truncated, damaged or foreign entry is
        rebuilt and replaced by an atomic rename.
      - ``ngsolve_threads``: threads of NGsolve's task manager during a build (restored
        afterwards; None leaves NGsolve's setting). 1 by default: the task manager spins,
        and on a shared 2-core machine 2 threads made a 0.6 s build take 12-20 s.
      - a rebuild reproduces the same reduction up to round-off (threaded assembly and
        eigensolver); eigenmode signs are normalised so modal coordinates keep their sign.
    """
    start = time.perf_counter()
    sizes = {"length_m": length_m, "thickness_m": thickness_m, "width_m": width_m,
             "youngs_modulus_Pa": youngs_modulus_Pa, "density_kg_per_m3": density_kg_per_m3,
             "mesh_size_m": mesh_size_m}
    _check_inputs(sizes, poisson_ratio, modes)
    if mode_selection not in MODE_SELECTIONS:
        raise SceneError(f"reduction mode_selection = {mode_selection!r}: must be one of "
                         f"{', '.join(MODE_SELECTIONS)}")
    parameters = {name: float(value) for name, value in sizes.items()}
    parameters.update(poisson_ratio=float(poisson_ratio), modes=int(modes),
                      mesh_order=_MESH_ORDER, stress_modes=True)
    if mode_selection != "all":  # "all" keeps the keys (and cache entries) it always had
        parameters["mode_selection"] = mode_selection
    key = _cache_key(parameters)
    cache_file = None if cache_dir is None else Path(cache_dir) / f"{key}.hdf5"

    fem = _load_cached(cache_file, key) if cache_file is not None else None
    from_cache = fem is not None
    ffrf_interface = None
    if fem is None:
        _say_unproven(cache_file)
        with _ngsolve_thread_count(ngsolve_threads):
            fem, ffrf_interface = _build_fem(parameters, key)
        if cache_file is not None and not store(
                cache_file, lambda temporary: fem.SaveToFile(str(temporary), mode="HDF5"),
                REDUCTION_CACHE):
            cache_file = None  # not kept (said): nothing is cached beside it either

    meta = fem.metaData["flex"]
    end_a, end_b, mid = (_node_set(fem, name) for name in (END_A, END_B, MID))
    positions = fem.GetNodePositionsAsArray()

    def centre(node_set: dict) -> np.ndarray:
        return np.asarray(node_set["NodeWeights"]) @ positions[node_set["NodeNumbers"]]

    return Reduction(
        fem=fem, **sizes, poisson_ratio=float(poisson_ratio), modes=int(modes),
        mode_selection=mode_selection,
        nodes_end_a=np.asarray(end_a["NodeNumbers"]),
        weights_end_a=unit_sum(end_a["NodeWeights"]),
        nodes_end_b=np.asarray(end_b["NodeNumbers"]),
        weights_end_b=unit_sum(end_b["NodeWeights"]),
        nodes_mid=np.asarray(mid["NodeNumbers"]), weights_mid=unit_sum(mid["NodeWeights"]),
        centre_end_a=centre(end_a), centre_end_b=centre(end_b), centre_mid=centre(mid),
        fixed_interface_frequencies_Hz=np.sqrt(np.abs(np.asarray(fem.eigenValues))) / (2 * np.pi),
        pinned_pinned_frequency_Hz=float(meta["pinned_pinned_frequency_Hz"]),
        mass_kg=float(meta["mass_kg"]), n_nodes=int(fem.NumberOfNodes()),
        n_elements=int(meta["n_elements"]), n_dof=3 * int(fem.NumberOfNodes()),
        cold_build_time_s=float(meta["cold_build_time_s"]),
        build_time_s=time.perf_counter() - start, from_cache=from_cache,
        cache_file=cache_file, key=key,
        _ffrf_interface=ffrf_interface,
    )


def _build_fem(parameters: dict[str, Any], key: str) -> tuple[Any, Any]:
    """Mesh + Craig-Bampton + stress modes.

    Returns the FEMinterface (flex's own data in ``metaData['flex']``, the mid-length node set
    in ``nodeSets``) and its ObjectFFRFreducedOrderInterface.
    """
    import exudyn as exu
    from exudyn.FEM import FEMinterface, KirchhoffMaterial

    start = time.perf_counter()
    length_m = parameters["length_m"]
    mesh = plate_mesh(length_m, parameters["thickness_m"], parameters["width_m"],
                      parameters["mesh_size_m"])
    fem = FEMinterface()
    mass_form, stiffness_form, space = fem.ImportMeshFromNGsolve(
        mesh, density=parameters["density_kg_per_m3"],
        youngsModulus=parameters["youngs_modulus_Pa"],
        poissonsRatio=parameters["poisson_ratio"], meshOrder=_MESH_ORDER,
        boundaryNamesList=[END_A, END_B])
    # sorted node numbers and area weights: reproducible files, weighted centre = face centre
    interfaces = []
    for name in (END_A, END_B):
        node_set = _node_set(fem, name)
        nodes = np.sort(np.asarray(node_set["NodeNumbers"], dtype=np.int64))
        node_set["NodeNumbers"] = nodes
        node_set["NodeWeights"] = fem.GetNodeWeightsFromSurfaceAreas(nodes)
        interfaces.append(nodes)
    static_modes = _craig_bampton_basis(fem, mass_form, stiffness_form, interfaces,
                                        parameters["modes"],
                                        parameters.get("mode_selection", "all"))
    _fix_eigenmode_signs(fem.modeBasis["matrix"], static_modes)
    material = KirchhoffMaterial(parameters["youngs_modulus_Pa"], parameters["poisson_ratio"],
                                 parameters["density_kg_per_m3"])
    fem.ComputePostProcessingModesNGsolve(space, material=material,
                                          outputVariableType=exu.OutputVariableType.StressLocal)
    positions = fem.GetNodePositionsAsArray()
    mid_nodes, mid_weights = _mid_set(positions, length_m, parameters["mesh_size_m"])
    fem.nodeSets.append({"Name": MID, "NodeNumbers": mid_nodes, "NodeWeights": mid_weights})

    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    ffrf_interface = ObjectFFRFreducedOrderInterface(fem)
    end_a, end_b = _node_set(fem, END_A), _node_set(fem, END_B)
    pinned_pinned = _pinned_pinned_frequency_Hz(
        ffrf_interface, length_m, parameters["thickness_m"], parameters["width_m"],
        end_a["NodeNumbers"], end_a["NodeWeights"], end_b["NodeNumbers"], end_b["NodeWeights"])
    fem.metaData["flex"] = {
        "key": key,
        "format_version": CACHE_FORMAT_VERSION,
        "parameters": json.dumps(parameters, sort_keys=True),
        "pinned_pinned_frequency_Hz": pinned_pinned,
        "mass_kg": float(ffrf_interface.totalMass),
        "n_elements": int(mesh.ne),
        "cold_build_time_s": time.perf_counter() - start,
        "digest": _content_digest(fem),
    }
    fem.metaData["flex"]["meta_digest"] = _meta_digest(fem.metaData["flex"])
    # handed to the Reduction (not stored): saves re-projecting on the first add
    return fem, ffrf_interface


# ------------------------------------------------------------------------------------------
# Exudyn body
# ------------------------------------------------------------------------------------------
def as_vector3(value: Sequence[float], name: str) -> np.ndarray:
    vector = np.asarray(value, dtype=float)
    if vector.shape != (3,) or not np.all(np.isfinite(vector)):
        raise SceneError(f"{name} = {value!r}: must be 3 finite numbers (metres, global frame)")
    return vector


def add_ffrf_link(mbs, reduction: Reduction, position_B: Sequence[float], angle_rad: float,
                  damping_ratio: float = 0.0,
                  initial_velocity_B_m_per_s: Sequence[float] = (0.0, 0.0, 0.0),
                  initial_angular_velocity_rad_per_s: float = 0.0,
                  name: str = "coupler", joint_markers: str = "fewest",
                  end_b_rotation: bool = True, end_a_rotation: bool = True
                  ) -> dict[str, Any]:
    """Add the reduced plate to ``mbs`` as an ``ObjectFFRFreducedOrder`` between B and C.

    Written for the coupler (``end_a`` at B, ``end_b`` at C); the crank uses it with
    ``position_B`` = A and its markers ``marker_B`` at A and ``marker_C`` at B.

    Contract:
      - placement: the floating frame's origin is the centre of ``end_a`` and is put at
        ``position_B`` [m, global]; its x axis (the link axis) is turned by ``angle_rad`` about
        global z. C's reference position is ``position_B + length * (cos, sin, 0)``.
      - markers: ``marker_B`` / ``marker_C`` for joints B and C, at the end-face centres
        with the frame's orientation; ``joint_markers = "fewest"`` (default) makes them as
        cheap as the basis allows (:func:`_ffrf_joint_markers`: the frame node at ``end_a``,
        four corner nodes of a rigid ``end_b``), ``"all_face_nodes"`` puts a
        ``MarkerSuperElementRigid`` on every face node (area weights; the same results to
        the Newton tolerance, several times the cost: kept to measure that);
        ``end_a_rotation = False`` (a joint at B free about z, a revolute pin) lets ``marker_B``
        be the frame node itself (its turn about z is then the chord's, not the face's);
        ``end_b_rotation = False`` (a joint at C that constrains only the position, the
        coupler's pin at C) makes ``marker_C`` a position marker, cheaper still; ``marker_mid``
        is a ``MarkerSuperElementPosition`` on the mid-length slab
        (reference point (L/2, 0, 0) in body coordinates).
      - damping (0 allowed, must be in [0, 1)): stiffness-proportional Rayleigh damping
        ``beta = 2 * damping_ratio / omega_pp`` on the elastic coordinates, with omega_pp the
        reduced body's first pinned-pinned bending frequency [rad/s]. That mode then has
        exactly ``damping_ratio`` of critical damping, higher modes proportionally more;
        rigid-body motion is never damped.
      - initial state: frame origin (point B) velocity [m/s] and angular velocity about z
        [rad/s], elastic coordinates at rest. Give the coupler's rigid-body velocities of
        the starting configuration (e.g. a crank turning at constant speed); default rest.
      - the body is added at the reference configuration; call ``mbs.Assemble()`` afterwards.

    Returns a dict:
      ``object`` (ObjectIndex of the ObjectFFRFreducedOrder), ``node_frame`` (NodeIndex of the
      floating frame, Euler parameters), ``node_modal`` (NodeIndex of the modal elastic
      coordinates: sensor ``OutputVariableType.Coordinates`` feeds
      :func:`bending_stress_history`), ``marker_B``, ``marker_C``, ``marker_mid``
      (MarkerIndex), ``position_B``, ``position_C``, ``position_mid`` (reference positions
      [m], global), ``rotation_matrix`` (3x3, body to global), ``mass_kg``,
      ``stiffness_proportional_damping_s`` (beta [s]).
    """
    from exudyn.rigidBodyUtilities import RotationMatrixZ

    position_B = as_vector3(position_B, "position_B")
    velocity_B = as_vector3(initial_velocity_B_m_per_s, "initial_velocity_B_m_per_s")
    for label, value in (("angle_rad", angle_rad),
                         ("initial_angular_velocity_rad_per_s",
                          initial_angular_velocity_rad_per_s)):
        if not (_is_number(value) and math.isfinite(value)):
            raise SceneError(f"{label} = {value!r}: must be a finite number")
    if joint_markers not in JOINT_MARKERS:
        raise SceneError(f"joint_markers = {joint_markers!r}: must be one of "
                         f"{', '.join(JOINT_MARKERS)}")
    beta = _stiffness_proportional_damping_s(reduction, damping_ratio)
    rotation = np.asarray(RotationMatrixZ(float(angle_rad)))
    added = reduction.ffrf_interface().AddObjectFFRFreducedOrder(
        mbs, positionRef=list(position_B), rotationMatrixRef=rotation,
        initialVelocity=list(velocity_B),
        initialAngularVelocity=[0.0, 0.0, float(initial_angular_velocity_rad_per_s)],
        stiffnessProportionalDamping=beta, name=name)
    body = added["oFFRFreducedOrder"]
    return {
        "object": body,
        "node_frame": added["nRigidBody"],
        "node_modal": added["nGenericODE2"],
        **add_plate_markers(mbs, body, reduction, position_B, rotation, name,
                            joint_markers=None if joint_markers == "all_face_nodes" else
                            _ffrf_joint_markers(mbs, body, added["nRigidBody"], reduction,
                                                name, end_b_rotation, end_a_rotation)),
        "stiffness_proportional_damping_s": beta,
    }


def _stiffness_proportional_damping_s(reduction: Reduction, damping_ratio: float) -> float:
    """Rayleigh ``beta`` [s] that gives the first pinned-pinned mode ``damping_ratio`` of
    critical damping (0 for none); SceneError outside [0, 1) or without that mode."""
    if not (_is_number(damping_ratio) and 0.0 <= damping_ratio < 1.0):
        raise SceneError(f"damping_ratio = {damping_ratio!r}: must lie in [0, 1)")
    if damping_ratio == 0:
        return 0.0
    omega = 2 * np.pi * reduction.pinned_pinned_frequency_Hz
    if not math.isfinite(omega):
        raise SceneError("damping_ratio > 0 needs the pinned-pinned frequency, which is "
                         "undefined for thickness > 2 x width: use damping_ratio = 0")
    return 2.0 * damping_ratio / omega


#: how an FFRF body's joint markers are made (:func:`add_ffrf_link`)
JOINT_MARKERS = ("fewest", "all_face_nodes")
#: largest relative non-rigid part of a mode's displacement over a joint face for the face to
#: count as rigid in the reduced basis (round-off measures ~4e-14)
RIGID_FACE_TOLERANCE = 1e-9


def _ffrf_joint_markers(mbs, body, frame_node, reduction: Reduction, name: str,
                        end_b_rotation: bool = True, end_a_rotation: bool = True
                        ) -> dict[str, Any]:
    """The joint markers at ``end_a`` (B) and ``end_b`` (C) of an FFRF body, as cheap as the
    reduced basis allows.

    Why: a ``MarkerSuperElementRigid`` costs time per face node and mode at every residual
    and Jacobian evaluation (Exudyn's CMarkerSuperElementRigid), and the joints were most of
    an FFRF step, growing with the mesh (33, 39, 63 face nodes for 4, 2, 1 mm meshes). In
    the chord-frame basis both end faces move rigidly in every mode, and no mode moves the
    centre of ``end_a`` (the frame's origin), so:

    - ``end_a`` without ``end_a_rotation`` (its joint ignores the face's turn about z, as a
      revolute pin about z does) gets a ``MarkerNodeRigid`` on the frame node, when no mode
      turns the face about x or y (the in-plane basis): the frame node then has the face's
      position and its orientation but for that turn;
    - a face every mode moves rigidly gets a ``MarkerSuperElementRigid`` on its four corner
      nodes, equal weights (any three or more non-collinear nodes centred on the face centre
      give the same position and rotation of a rigid face);
    - any other face keeps all its nodes and their area weights;
    - without ``end_b_rotation`` the ``end_b`` marker is a ``MarkerSuperElementPosition``
      on those nodes (no rotation to compute: a quarter less per step on a 6-mode coupler).

    Results agree with all-node markers to the Newton tolerance; a step on a 2 mm mesh is 4x
    cheaper. Returns ``marker_B``, ``marker_C`` (MarkerIndex).
    """
    import exudyn.itemInterface as eii

    positions = reduction.fem.GetNodePositionsAsArray()
    basis = reduction.fem.modeBasis["matrix"]
    basis = basis.reshape(-1, 3, basis.shape[1])
    markers = {}
    for face, label, rotation in ((END_A, "B", end_a_rotation), (END_B, "C", end_b_rotation)):
        nodes = np.asarray(getattr(reduction, f"nodes_{face}"))
        weights = getattr(reduction, f"weights_{face}")
        centre = getattr(reduction, f"centre_{face}")
        motions = _rigid_face_motions(positions[nodes], basis[nodes], centre)
        if (face == END_A and not rotation and motions is not None
                and not np.any(motions[:, :5])
                and np.allclose(centre, 0.0, rtol=0, atol=1e-9 * reduction.length_m)):
            markers[f"marker_{label}"] = mbs.AddMarker(eii.MarkerNodeRigid(
                name=f"{name}:{label}", nodeNumber=frame_node))
            continue
        corners = _face_corners(positions, nodes)
        if (len(corners) == 4 and motions is not None
                and np.allclose(positions[corners].mean(axis=0), centre, rtol=0,
                                atol=1e-9 * reduction.length_m)):
            nodes, weights = corners, np.full(4, 0.25)
        kind = (eii.MarkerSuperElementPosition if face == END_B and not rotation
                else eii.MarkerSuperElementRigid)
        markers[f"marker_{label}"] = mbs.AddMarker(kind(
            name=f"{name}:{label}", bodyNumber=body, meshNodeNumbers=nodes,
            weightingFactors=weights))
    return markers


def _face_corners(positions: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The nodes of a face normal to x at its four (y, z) corners (extremes of +-y +- z,
    each coordinate scaled by the face's extent)."""
    yz = positions[nodes][:, 1:]
    scaled = (yz - yz.mean(axis=0)) / np.maximum(np.ptp(yz, axis=0), 1e-300)
    picks = {int(nodes[np.argmax(scaled @ np.array([sign_y, sign_z]))])
             for sign_y in (-1.0, 1.0) for sign_z in (-1.0, 1.0)}
    return np.array(sorted(picks))


def _rigid_face_motions(face_positions: np.ndarray, face_modes: np.ndarray,
                        origin: np.ndarray | None = None) -> np.ndarray | None:
    """Per mode, the face's (linearized) rigid motion u = t + w x r about ``origin`` [m]
    (None: the face nodes' centroid),
    rows (t_x, t_y, t_z, w_x, w_y, w_z) with entries below :data:`RIGID_FACE_TOLERANCE` of
    the mode's face displacement set to 0; None if some mode does not move the face rigidly
    to that tolerance (least squares over the face nodes)."""
    r = face_positions - (face_positions.mean(axis=0) if origin is None else origin)
    fit = np.zeros((3 * len(r), 6))
    for i, (x, y, z) in enumerate(r):
        fit[3 * i:3 * i + 3, :3] = np.eye(3)
        fit[3 * i:3 * i + 3, 3:] = [[0.0, z, -y], [-z, 0.0, x], [y, -x, 0.0]]  # -[r]x
    motions = []
    for mode in np.moveaxis(face_modes, 2, 0):
        u = mode.ravel()
        size = np.linalg.norm(u)
        parameters = np.zeros(6)
        if size > 0:
            parameters, *_ = np.linalg.lstsq(fit, u, rcond=None)
            if np.linalg.norm(fit @ parameters - u) > RIGID_FACE_TOLERANCE * size:
                return None
            scale = np.concatenate([np.ones(3), np.full(3, np.abs(r).max())])
            parameters[np.abs(parameters) * scale < RIGID_FACE_TOLERANCE * size] = 0.0
        motions.append(parameters)
    return np.array(motions).reshape(-1, 6)


def add_plate_markers(mbs, body, plate, position_B: np.ndarray, rotation: np.ndarray,
                      name: str = "coupler",
                      joint_markers: dict[str, Any] | None = None) -> dict[str, Any]:
    """Joint and midpoint markers on a meshed plate body (FFRF or nonlinear FE).

    ``plate`` carries the node sets ``nodes_end_a/_b/_mid``, their weights and the reference
    centres ``centre_end_a/_b/_mid`` [m, body frame] (a :class:`Reduction` or a
    ``flex.bodies.nonlinear.NonlinearPlate``). Returns ``marker_B`` and ``marker_C``
    (``MarkerSuperElementRigid`` on the end faces), ``marker_mid``
    (``MarkerSuperElementPosition``), their global reference positions ``position_B/_C/_mid``
    [m], ``rotation_matrix`` (body to global) and ``mass_kg``. ``joint_markers``: markers
    ``marker_B`` / ``marker_C`` already made for the end faces (FFRF bodies), used instead.
    """
    import exudyn.itemInterface as eii

    def marker(kind, label: str, nodes, weights):
        return mbs.AddMarker(kind(name=f"{name}:{label}", bodyNumber=body,
                                  meshNodeNumbers=nodes, weightingFactors=weights))

    joints = joint_markers or {
        "marker_B": marker(eii.MarkerSuperElementRigid, "B", plate.nodes_end_a,
                           plate.weights_end_a),
        "marker_C": marker(eii.MarkerSuperElementRigid, "C", plate.nodes_end_b,
                           plate.weights_end_b)}
    return {
        **joints,
        "marker_mid": marker(eii.MarkerSuperElementPosition, "mid", plate.nodes_mid,
                             plate.weights_mid),
        "position_B": position_B + rotation @ plate.centre_end_a,
        "position_C": position_B + rotation @ plate.centre_end_b,
        "position_mid": position_B + rotation @ plate.centre_mid,
        "rotation_matrix": rotation,
        "mass_kg": plate.mass_kg,
    }


# ------------------------------------------------------------------------------------------
# post-processing
# ------------------------------------------------------------------------------------------
def _as_track(positions: np.ndarray, name: str) -> np.ndarray:
    track = np.asarray(positions, dtype=float)
    if track.ndim != 2 or track.shape[1] != 3 or len(track) == 0:
        raise ValueError(f"{name}: expected an array of shape (n, 3), got {track.shape}")
    return track


def midpoint_deflection(position_B: np.ndarray, position_C: np.ndarray,
                        position_mid: np.ndarray) -> MidpointDeflection:
    """Elastic midpoint deflection and chord stretch from global point tracks.

    Contract: the three arguments are time series of global positions [m], shape (n, 3),
    of the joint-B centre, the joint-C centre and the midpoint marker, motion in the x-y
    plane. Returns :class:`MidpointDeflection` with, per sample,

    - ``transverse_m``: (mid - B) . n with n = e_z x (C - B)/|C - B| (the chord turned by
      +90 deg in the x-y plane, i.e. the body's +y for an undeformed link), minus its first
      value;
    - ``chord_change_m``: |C - B| minus its first value.

    Rigid motion of the link gives zeros; the first sample is the reference (zero by
    definition), so start the series in the undeformed state. Pure numpy; raises ValueError
    for mismatched shapes or a zero-length chord.
    """
    b = _as_track(position_B, "position_B")
    c = _as_track(position_C, "position_C")
    m = _as_track(position_mid, "position_mid")
    if not (b.shape == c.shape == m.shape):
        raise ValueError(f"shapes differ: B {b.shape}, C {c.shape}, mid {m.shape}")
    chord = c - b
    chord_length = np.linalg.norm(chord, axis=1)
    if np.any(chord_length == 0):
        raise ValueError("B and C coincide in some sample: the chord has no direction")
    in_plane = chord[:, :2] / np.linalg.norm(chord[:, :2], axis=1)[:, None]
    normal = np.column_stack([-in_plane[:, 1], in_plane[:, 0]])  # e_z x chord
    transverse = np.einsum("ij,ij->i", (m - b)[:, :2], normal)
    return MidpointDeflection(transverse_m=transverse - transverse[0],
                              chord_change_m=chord_length - chord_length[0])


def bending_stress_history(reduction: Reduction, modal_coordinates: np.ndarray,
                           x_range_m: tuple[float, float] | None = None) -> np.ndarray:
    """Peak |sigma_xx| (axial stress along the link, body frame) per sample [Pa].

    Contract: ``modal_coordinates`` has shape (n, 6 + modes) or (6 + modes,): the elastic
    coordinates of the body (the ``node_modal`` of :func:`add_ffrf_link`, output
    ``Coordinates``). Stress is linear in them (small strains, as the FFRF model assumes),
    taken from the stress post-processing modes at the mesh nodes whose reference x lies in
    ``x_range_m``; the default (thickness, length - thickness) leaves out one thickness at
    each end, where the rigid end faces cause a local stress concentration that the pin of
    a real eye would not (Saint-Venant). Bending dominates sigma_xx in a slender link; the
    membrane part from the axial force is included. Returns an array of shape (n,).
    """
    if not reduction.has_stress_modes:
        raise ValueError("this reduction has no stress post-processing modes")
    coordinates = np.atleast_2d(np.asarray(modal_coordinates, dtype=float))
    if coordinates.shape[1] != reduction.n_modal_coordinates:
        raise ValueError(f"modal_coordinates: expected {reduction.n_modal_coordinates} columns, "
                         f"got shape {coordinates.shape}")
    if x_range_m is None:
        x_range_m = (reduction.thickness_m, reduction.length_m - reduction.thickness_m)
    x = reduction.fem.GetNodePositionsAsArray()[:, 0]
    nodes = np.flatnonzero((x >= x_range_m[0]) & (x <= x_range_m[1]))
    if len(nodes) == 0:
        raise ValueError(f"x_range_m = {x_range_m!r} holds no mesh node")
    # columns 6k + 0 hold sigma_xx of mode k (Exudyn order xx, yy, zz, yz, xz, xy)
    stress_xx_modes = reduction.fem.postProcessingModes["matrix"][nodes, 0::6]
    peaks = np.empty(len(coordinates))
    chunk = max(1, 2_000_000 // len(nodes))  # bound the (samples x nodes) temporary
    for start in range(0, len(coordinates), chunk):
        stress = coordinates[start:start + chunk] @ stress_xx_modes.T
        peaks[start:start + chunk] = np.abs(stress).max(axis=1)
    return peaks
