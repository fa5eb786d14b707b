"""Fully nonlinear FE coupler: the accuracy reference for the FFRF reduction.

The same plate mesh as :mod:`flex.bodies.reduction` (:func:`flex.bodies.plate.plate_mesh`,
second-order
tetrahedra, end faces ``end_a`` at joint B and ``end_b`` at joint C, the same node numbering)
becomes an Exudyn ``ObjectGenericODE2``: every mesh node is a ``NodePoint`` (3 displacement
coordinates), the mass matrix is the mesh's consistent one, and the elastic forces and their
Jacobian come from NGsolve with the Green-Lagrange strain and a St. Venant-Kirchhoff material
-- the formulation of Exudyn's ``FEMinterface.CreateNonlinearFEMObjectGenericODE2NGsolve``.
Large rotations and geometric stiffening (the link's axial force changing its bending
stiffness) are exact; the FFRF body (linear elasticity in a floating frame) leaves them out.
About 50 times slower per step than the FFRF body (1 mm plate, 9627 coordinates: 0.11 s
against 2.2 ms; Python callbacks, a sparse LU per Jacobian): the accuracy reference for the
reduction, not a production model.

Why not Exudyn's function itself: with ``meshOrder=2`` (needed: linear tets lock) Exudyn
1.13.6 makes the mesh second order twice (once itself, once in ``ImportMeshFromNGsolve``),
and the second pass adds unconnected nodes (1 mm plate: 3209 -> 4092 nodes, 883 of them
without mass or stiffness), which leaves the system singular. This module imports once.

Body coordinates (metres) are the mesh's, as in :mod:`flex.bodies.reduction`: x along the link from
the centre of ``end_a`` (joint B) to the centre of ``end_b`` (joint C), y across the thickness
(in the mechanism plane), z across the width.

Placement: the Exudyn nodes' reference positions are the *placed* ones (end_a's centre at
joint B, link axis turned by the coupler angle about z), with zero initial displacement; the
elastic forces are evaluated on the mesh with the constant offset (placed - mesh position)
added to the displacements. The Green-Lagrange strain of a rigid motion is zero, so the body
starts unstrained, and the face markers start with the identity rotation (below).

Joints: ``marker_B`` and ``marker_C`` are ``MarkerSuperElementRigid`` markers on the end-face
nodes (surface-area weights; RBE3-like: the faces stay deformable, where the FFRF body's are
rigid). On a GenericODE2 such a marker's position is the weighted mean of the face nodes
(exact), but its rotation is the exponential map of a rotation vector that Exudyn computes
*linearly* from the face-node displacements relative to their reference positions: for a
face turned by phi about z it reports an angle sin(phi), and on a face whose weights are not
symmetric (any unstructured mesh) its z axis tilts by about (1 - cos phi) x (asymmetry) --
measured 1.8e-3 rad at phi = 0.3 on a coarse 5 mm face. The revolute joint at B holds exactly
that z axis (it constrains the face's out-of-plane tilt; it is free about z, so the sin(phi)
error does not enter), and would force the spurious tilt onto the face: hence the placed
reference, which keeps phi at the coupler's rotation since t = 0 (small over the first
deflection peaks, ~0.25 rad over the whole deployment). Joint C constrains only x and y and
uses the marker's position alone.

Progress: an integration of this body takes minutes (the flexible study's reference: ~5 min).
The elastic-force callback, which Exudyn calls with the simulated time, prints a line on
stderr every :data:`PROGRESS_INTERVAL_S` of wall time (simulated time of the end time, steps,
elapsed and estimated remaining time, callback counts); it only reads clocks and counters,
so no computed number changes.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import Plate, lame_first_parameter_Pa, shear_modulus_Pa
from flex.bodies.plate import PlateLink, plate_mesh
from flex.bodies.reduction.body import add_plate_markers, as_vector3
from flex.bodies.reduction.build import END_A, END_B, ngsolve_thread_count
from flex.bodies.section_mean import fem_tetrahedra, section_mean_weights
from flex.data.results import Dataset

_MESH_ORDER = 2  # as the reduction: linear tets lock in bending
#: wall-time seconds between two progress lines of an integration (see the module doc)
PROGRESS_INTERVAL_S = 10.0


@dataclass
class NonlinearPlate(PlateLink):
    """A meshed plate ready for :func:`add_nonlinear_fe_coupler` (sizes in metres).

    Node index arrays refer to the mesh nodes (the order of ``FEMinterface`` and of the
    GenericODE2 nodes); weights sum to 1. ``centre_*`` are the weighted reference positions of
    the node sets in body coordinates [m]. The node sets are built exactly as the reduction's
    (sorted face nodes with surface-area weights; the same mid-length slab), so on the same
    mesh the markers of both models report the same material points.
    """

    mesh: Any  #: ngsolve.Mesh, made second order by the import (do not import it again)
    node_positions_m: np.ndarray  #: (n_nodes, 3) reference positions, body coordinates
    mass_matrix: Any  #: scipy CSR, consistent mass [kg], Exudyn order (x, y, z per node)
    mass_kg: float  #: from the consistent mass matrix
    n_elements: int  #: second-order tetrahedra
    build_time_s: float  #: meshing and node sets
    end_time_s: float | None = None  #: the scene's end time [s], for progress lines only

    @property
    def n_nodes(self) -> int:
        """Number of mesh nodes (vertices and edge midpoints)."""
        return len(self.node_positions_m)

    @property
    def n_dof(self) -> int:
        """Coordinates of the GenericODE2 body: 3 per mesh node."""
        return 3 * self.n_nodes


def build_nonlinear_plate(plate: Plate, mesh_size_m: float, *,
                          ngsolve_threads: int | None = 1,
                          mesh_order: int = _MESH_ORDER) -> NonlinearPlate:
    """Mesh the plate and find its joint and midpoint node sets.

    Contract: ``plate`` its sizes in metres, E in Pa, density in kg/m^3, Poisson's ratio
    (:class:`flex.base.physics.Plate`), ``mesh_size_m`` is netgen's maxh [m];
    the same arguments as :func:`flex.bodies.reduction.build_reduction` (without ``modes``) give the
    same mesh, node numbering and node sets (``mesh_order``: the tetrahedra's order, 2 as the
    reduction's default, 1 for a linear-tetrahedra reduction's). Bad values raise
    :class:`flex.base.errors.SceneError`. ``ngsolve_threads`` as in ``build_reduction`` (1: the
    import's assembly took 0.85 s with NGsolve's default threads on the shared 2-core
    machine, 0.05 s with one). Nothing is cached: meshing takes one to a few seconds; the
    bodies are made per system by :func:`add_nonlinear_fe_coupler`.
    """
    start = time.perf_counter()
    length_m, thickness_m, width_m = plate.sizes_m
    density_kg_per_m3, poisson_ratio = plate.density_kg_per_m3, plate.poisson_ratio
    youngs_modulus_Pa = plate.youngs_modulus_Pa
    sizes = {"length_m": length_m, "thickness_m": thickness_m, "width_m": width_m,
             "youngs_modulus_Pa": youngs_modulus_Pa, "density_kg_per_m3": density_kg_per_m3,
             "mesh_size_m": mesh_size_m}
    _check_plate_inputs(sizes, poisson_ratio)
    from exudyn.FEM import FEMinterface

    with ngsolve_thread_count(ngsolve_threads):
        mesh = plate_mesh(length_m, thickness_m, width_m, mesh_size_m)
        fem = FEMinterface()
        # the reduction's import: it makes the mesh second order in place (once only: a
        # second call adds unconnected nodes) and numbers the nodes as the reduction does
        fem.ImportMeshFromNGsolve(mesh, density=density_kg_per_m3,
                                  youngsModulus=youngs_modulus_Pa,
                                  poissonsRatio=poisson_ratio, meshOrder=mesh_order,
                                  boundaryNamesList=[END_A, END_B])
    positions = fem.GetNodePositionsAsArray()
    face_sets = _face_sets(fem)
    mid_nodes, mid_weights = section_mean_weights(positions, fem_tetrahedra(fem), length_m / 2)

    def centre(nodes: np.ndarray, weights: np.ndarray) -> np.ndarray:
        return np.asarray(weights) @ positions[nodes]

    # total mass = 1^T M 1 for one translation direction (every x coordinate moved by 1 m)
    ones_x = np.zeros(fem.NumberOfCoordinates())
    ones_x[0::3] = 1.0
    mass_matrix = fem.GetMassMatrix()
    mass_kg = float(ones_x @ (mass_matrix @ ones_x))
    (nodes_a, weights_a), (nodes_b, weights_b) = face_sets[END_A], face_sets[END_B]
    return NonlinearPlate(
        mesh=mesh, **{k: float(v) for k, v in sizes.items()},
        poisson_ratio=float(poisson_ratio), node_positions_m=positions,
        nodes_end_a=nodes_a, weights_end_a=np.asarray(weights_a),
        nodes_end_b=nodes_b, weights_end_b=np.asarray(weights_b),
        nodes_mid=mid_nodes, weights_mid=mid_weights,
        centre_end_a=centre(nodes_a, weights_a), centre_end_b=centre(nodes_b, weights_b),
        centre_mid=centre(mid_nodes, mid_weights), mass_matrix=mass_matrix, mass_kg=mass_kg,
        n_elements=int(mesh.ne), build_time_s=time.perf_counter() - start)


def _check_plate_inputs(sizes: dict[str, float], poisson_ratio: float) -> None:
    """Raise :class:`flex.base.errors.SceneError` unless every size (and E, density) is a
    finite number > 0, Poisson's ratio lies in (0, 0.5) and the mesh size is at most the
    length (:func:`build_nonlinear_plate`)."""
    for name, value in sizes.items():
        if isinstance(value, bool) or not (isinstance(value, int | float)
                                           and math.isfinite(value) and value > 0):
            raise SceneError(f"nonlinear FE plate {name} = {value!r}: must be a finite "
                             f"number > 0")
    if isinstance(poisson_ratio, bool) or not (isinstance(poisson_ratio, int | float)
                                               and 0.0 < poisson_ratio < 0.5):
        raise SceneError(f"nonlinear FE plate poisson_ratio = {poisson_ratio!r}: must lie in "
                         f"the open range (0, 0.5)")
    if sizes["mesh_size_m"] > sizes["length_m"]:
        raise SceneError(f"nonlinear FE plate mesh_size_m = {sizes['mesh_size_m']!r}: must be "
                         f"<= length_m ({sizes['length_m']!r})")


def _face_sets(fem) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The joint faces' node sets (``end_a``, ``end_b``): sorted node numbers and area
    weights, as the reduction numbers and weighs them."""
    face_sets = {}
    for node_set in fem.nodeSets:
        if node_set["Name"] in (END_A, END_B):
            nodes = np.sort(np.asarray(node_set["NodeNumbers"], dtype=np.int64))
            face_sets[node_set["Name"]] = (nodes, fem.GetNodeWeightsFromSurfaceAreas(nodes))
    return face_sets


class _HyperelasticForces:
    """Elastic forces and tangent stiffness of the plate for Exudyn's GenericODE2 callbacks.

    St. Venant-Kirchhoff material on the Green-Lagrange strain E = sym(grad u) + grad u^T
    grad u / 2, energy S : E / 2 with S = 2 mu E + lambda tr(E) I, integrated by NGsolve on the
    second-order mesh (the formulation of Exudyn's CreateNonlinearFEMObjectGenericODE2NGsolve).
    NGsolve orders the coordinates by component (x of every node, then y, then z), Exudyn by
    node; fixed permutations map between the two, and the Jacobian's sparsity pattern is
    permuted once and reused. ``offset_m`` (Exudyn order, metres) is added to the Exudyn
    displacements to give the displacements from the mesh positions (the placement). Counts
    calls and the time spent in them.
    """

    def __init__(self, plate: NonlinearPlate, offset_m: np.ndarray) -> None:
        import ngsolve as ngs

        mu = shear_modulus_Pa(plate.youngs_modulus_Pa, plate.poisson_ratio)
        lam = lame_first_parameter_Pa(plate.youngs_modulus_Pa, plate.poisson_ratio)
        space = ngs.NodalFESpace(plate.mesh, order=_MESH_ORDER) ** 3
        if space.ndof != plate.n_dof:
            raise RuntimeError(f"NGsolve space has {space.ndof} coordinates, the plate "
                               f"{plate.n_dof}: the mesh was made second order twice")
        displacement = space.TrialFunction()
        gradient = ngs.Grad(displacement)
        strain = ngs.Sym(gradient) + 0.5 * gradient.trans * gradient
        stress = 2 * mu * strain + lam * ngs.Trace(strain) * ngs.Id(3)
        self._form = ngs.BilinearForm(space)
        self._form += ngs.Variation((0.5 * ngs.InnerProduct(stress, strain)).Compile()
                                    * ngs.dx)
        self._state = ngs.GridFunction(space)
        self._residual = self._state.vec.CreateVector()
        n_nodes = plate.n_nodes
        coordinate = np.arange(3 * n_nodes)
        # NGsolve index of Exudyn coordinate 3 i + c (node i, component c) is c n + i
        self._ngsolve_index = (coordinate % 3) * n_nodes + coordinate // 3
        self._exudyn_index = np.argsort(self._ngsolve_index)
        self._offset_m = np.asarray(offset_m, dtype=float).ravel()  # Exudyn order
        self._jacobian_layout: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self.force_calls = 0
        self.jacobian_calls = 0
        self.time_s = 0.0
        self._progress = _IntegrationProgress(plate.end_time_s)

    def _set_state(self, q) -> None:
        self._state.vec.FV().NumPy()[self._ngsolve_index] = np.asarray(q) + self._offset_m

    def force(self, mbs, t, item_index, q, q_t) -> np.ndarray:
        """Minus the internal elastic forces [N] at Exudyn displacements ``q`` [m]."""
        start = time.perf_counter()
        self._set_state(q)
        self._form.Apply(self._state.vec, self._residual)
        force = -self._residual.FV().NumPy()[self._ngsolve_index]
        self.force_calls += 1
        self.time_s += time.perf_counter() - start
        self._progress.update(float(t), self.force_calls, self.jacobian_calls)
        return force

    def jacobian(self, mbs, t, item_index, q, q_t, f_ode2, f_ode2_t):
        """``f_ode2`` x tangent stiffness [N/m] at ``q`` (Exudyn order, MatrixContainer)."""
        import exudyn as exu
        from scipy.sparse import coo_matrix, csr_matrix

        start = time.perf_counter()
        self._set_state(q)
        self._form.AssembleLinearization(self._state.vec)
        values, columns, row_pointers = self._form.mat.CSR()
        values = np.asarray(values)
        size = len(self._ngsolve_index)
        if self._jacobian_layout is None:
            row_pointers = np.asarray(row_pointers).astype(np.int64)  # NGsolve: uint64
            rows = np.repeat(np.arange(size), np.diff(row_pointers))
            columns = np.asarray(columns).astype(np.int64)
            # tag each entry by its position (1-based: no tag is a droppable zero)
            tags = coo_matrix((np.arange(1, len(values) + 1, dtype=float),
                               (self._exudyn_index[rows], self._exudyn_index[columns])),
                              shape=(size, size)).tocsr()
            self._jacobian_layout = (tags.data.astype(np.int64) - 1, tags.indices.copy(),
                                     tags.indptr.copy())
        order, indices, pointers = self._jacobian_layout
        stiffness = csr_matrix((values[order], indices, pointers), shape=(size, size))
        container = exu.MatrixContainer()
        container.SetWithSparseMatrix(stiffness, factor=float(f_ode2))
        self.jacobian_calls += 1
        self.time_s += time.perf_counter() - start
        return container


class _IntegrationProgress:
    """Progress lines of one integration on stderr, from the force callback's time ``t``:
    one per :data:`PROGRESS_INTERVAL_S` of wall time since the first call (none for a run
    shorter than that). Steps are counted as the increasing values of ``t`` after the
    first (each step's Newton iterations share its time)."""

    def __init__(self, end_time_s: float | None) -> None:
        self.end_time_s = end_time_s
        self.start: float | None = None
        self.last_line = 0.0
        self.first_t = self.last_t = 0.0
        self.steps = 0

    def update(self, t: float, force_calls: int, jacobian_calls: int) -> None:
        now = time.monotonic()
        if self.start is None:
            self.start = self.last_line = now
            self.first_t = self.last_t = t
            return
        if t > self.last_t:
            self.steps += 1
            self.last_t = t
        if now - self.last_line < PROGRESS_INTERVAL_S:
            return
        self.last_line = now
        elapsed = now - self.start
        done = t - self.first_t
        span = f"t = {t * 1e3:.3g} ms"
        left = ""
        if self.end_time_s and self.end_time_s > self.first_t:
            total = self.end_time_s - self.first_t
            span += f" of {self.end_time_s * 1e3:.3g} ms ({100 * done / total:.0f} %)"
            if done > 0:
                left = f", ~{_duration(elapsed * max(total - done, 0.0) / done)} left"
        print(f"nonlinear FE coupler: {span}, step {self.steps}, {_duration(elapsed)} "
              f"elapsed{left} ({force_calls} force, {jacobian_calls} Jacobian evaluations)",
              file=sys.stderr, flush=True)


def _duration(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 90 else f"{seconds / 60:.1f} min"


def add_nonlinear_fe_coupler(mbs, plate: NonlinearPlate, position_B: Sequence[float],
                             angle_rad: float,
                             initial_velocity_B_m_per_s: Sequence[float] = (0.0, 0.0, 0.0),
                             initial_angular_velocity_rad_per_s: float = 0.0,
                             ) -> dict[str, Any]:
    """Add the plate to ``mbs`` as a fully nonlinear FE body between joints B and C.

    Contract:
      - placement as :func:`flex.bodies.reduction.add_ffrf_link`: the centre of ``end_a`` is put at
        ``position_B`` [m, global], the link axis (body x) turned by ``angle_rad`` about global
        z; C's reference position is ``position_B + length * (cos, sin, 0)``. The nodes'
        reference positions are the placed ones (see the module doc); the body starts
        unstrained.
      - initial velocity: the rigid-body field of point B's velocity [m/s] and the angular
        velocity about z [rad/s]; default rest.
      - markers: ``marker_B`` / ``marker_C`` are ``MarkerSuperElementRigid`` on the end faces
        (area weights); ``marker_mid`` a ``MarkerSuperElementPosition`` on the mid-length
        slab. Position sensors of the three give :func:`flex.bodies.reduction.midpoint_deflection`.
      - no damping (the nonlinear body has no damping model); no stress output.
      - call ``mbs.Assemble()`` afterwards, and integrate with a sparse linear solver
        (``LinearSolverType.EigenSparse``): the body has ``plate.n_dof`` coordinates.

    Returns a dict: ``object`` (ObjectIndex of the ObjectGenericODE2), ``nodes`` (its
    NodeIndex list, mesh node order), ``marker_B``, ``marker_C``, ``marker_mid``
    (MarkerIndex), ``position_B``, ``position_C``, ``position_mid`` (reference positions [m],
    global), ``rotation_matrix`` (3x3, body to global at t = 0), ``mass_kg``, ``n_dof``,
    ``elastic_forces`` (the callbacks' owner: ``force_calls``, ``jacobian_calls``, ``time_s``).
    """
    import exudyn as exu
    import exudyn.itemInterface as eii
    from exudyn.rigidBodyUtilities import RotationMatrixZ

    position_B, velocity_B = _checked_placement(position_B, angle_rad,
                                                initial_velocity_B_m_per_s,
                                                initial_angular_velocity_rad_per_s)
    rotation = np.asarray(RotationMatrixZ(float(angle_rad)))
    reference = plate.node_positions_m
    placed = position_B + reference @ rotation.T
    omega = np.array([0.0, 0.0, float(initial_angular_velocity_rad_per_s)])
    velocities = velocity_B + np.cross(omega, placed - position_B)
    nodes = [mbs.AddNode(eii.NodePoint(referenceCoordinates=list(position),
                                       initialVelocities=list(velocity)))
             for position, velocity in zip(placed, velocities, strict=True)]
    elastic = _HyperelasticForces(plate, placed - reference)
    mass = exu.MatrixContainer()
    mass.SetWithSparseMatrix(plate.mass_matrix)
    body = mbs.AddObject(eii.ObjectGenericODE2(
        name="coupler", nodeNumbers=nodes, massMatrix=mass,
        forceUserFunction=elastic.force, jacobianUserFunction=elastic.jacobian))

    return {
        "object": body,
        "nodes": nodes,
        **add_plate_markers(mbs, body, plate, position_B, rotation),
        "n_dof": plate.n_dof,
        "elastic_forces": elastic,
    }


def _checked_placement(position_B: Sequence[float], angle_rad: float,
                       velocity_B: Sequence[float], angular_velocity_rad_per_s: float
                       ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`add_nonlinear_fe_coupler`'s placement and initial velocity checked (a
    :class:`flex.base.errors.SceneError` names the first bad one): position and velocity of B
    as 3-vectors."""
    position_B = as_vector3(position_B, "position_B")
    velocity_B = as_vector3(velocity_B, "initial_velocity_B_m_per_s")
    for label, value in (("angle_rad", angle_rad),
                         ("initial_angular_velocity_rad_per_s", angular_velocity_rad_per_s)):
        if isinstance(value, bool) or not (isinstance(value, int | float)
                                           and math.isfinite(value)):
            raise SceneError(f"{label} = {value!r}: must be a finite number")
    return position_B, velocity_B


#: the nonlinear FE coupler's nodal positions are stored at most this many times plus one
#: (:class:`NodalRecorder`)
NODAL_SNAPSHOTS = 300


class NodalRecorder:
    """The nonlinear FE body's global nodal positions [m] during an integration, for
    ``flex export`` and ``flex animate`` (its nodes carry the whole field; no modes).

    Recorded at t = 0 and then every ``k``-th output sample, ``k`` the smallest integer that
    keeps the count within :data:`NODAL_SNAPSHOTS` + 1 (the flexible study's 3000 samples:
    every 10th, 1e-4 s apart, ~28 per first bending period of the 1 mm plate), by an Exudyn
    post-step function that copies the body's coordinates (an array copy per recorded step;
    nothing else is computed). Stored as ``coupler/nodal/time`` [s] and
    ``coupler/nodal/position`` [m] (snapshots, nodes, 3), gzip-compressed. Make it after
    ``mbs.Assemble()`` (it reads the coordinates' indices).
    """

    def __init__(self, mbs, nodes: Sequence[int], step_s: float, output_step_s: float,
                 end_time_s: float) -> None:
        import exudyn as exu

        samples = max(1, round(end_time_s / output_step_s))
        self.step_s = float(step_s)
        self.steps_between = round(output_step_s / step_s) * math.ceil(samples / NODAL_SNAPSHOTS)
        self.reference = np.array([mbs.GetNode(n)["referenceCoordinates"] for n in nodes],
                                  dtype=float)
        first = np.array([mbs.GetNodeODE2Index(n) for n in nodes], dtype=np.int64)
        self.indices = (first[:, None] + np.arange(3)).ravel()
        self.times = [0.0]
        self.positions = [self._positions(mbs.systemData.GetODE2Coordinates(
            configuration=exu.ConfigurationType.Initial))]
        mbs.SetPostStepUserFunction(self)

    def _positions(self, coordinates) -> np.ndarray:
        return self.reference + np.asarray(coordinates)[self.indices].reshape(-1, 3)

    def __call__(self, mbs, t: float) -> bool:
        step = round(t / self.step_s)  # Exudyn also calls it once at t = 0: skip that
        if step % self.steps_between == 0 and t > self.times[-1] + 0.5 * self.step_s:
            self.times.append(float(t))
            self.positions.append(self._positions(mbs.systemData.GetODE2Coordinates()))
        return True

    def datasets(self, link: str = "coupler") -> dict[str, Dataset]:
        """``<link>/nodal/time`` and ``<link>/nodal/position``."""
        return {f"{link}/nodal/time": Dataset(np.array(self.times), "s",
                                              "times of the nodal snapshots"),
                f"{link}/nodal/position": Dataset(
                    np.array(self.positions), "m", "node positions, mechanism frame (mesh "
                    "node order)", compress=True)}


def nonlinear_plate_for_scene(scene: dict[str, dict[str, Any]]) -> NonlinearPlate:
    """The meshed plate of the scene's coupler (``coupler.geometry = "plate"``)."""
    c = scene["coupler"]
    plate = build_nonlinear_plate(Plate.of(c), c["mesh_size_m"])
    end = scene.get("simulation", {}).get("end_time_s")
    if isinstance(end, int | float) and not isinstance(end, bool):
        plate.end_time_s = float(end)  # for progress lines only
    return plate
