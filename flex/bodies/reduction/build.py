"""Plate mesh -> Craig-Bampton reduction (cached): :func:`build_reduction` and its
:class:`Reduction`."""


from __future__ import annotations

import contextlib
import json
import math
import numbers
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import Plate
from flex.bodies.plate import PlateLink, plate_mesh
from flex.bodies.reduction.basis import (
    EIGENSOLVER_ITERATIONS,
    craig_bampton_basis,
    fix_eigenmode_signs,
)
from flex.bodies.reduction.cache import (
    CACHE_FORMAT_VERSION,
    cache_key,
    fem_content_digest,
    load_cached,
    meta_digest,
    say_unproven,
)
from flex.bodies.reduction.interface_cache import ffrf_interface, interface_path
from flex.bodies.section_mean import fem_tetrahedra, section_mean_weights
from flex.data.cache import (
    REDUCTION_CACHE,
    store,
)

END_A = "end_a"  #: mesh boundary name of the joint-B face (x = 0)
END_B = "end_b"  #: mesh boundary name of the joint-C face (x = length)
MID = "mid"  #: node-set name of the mid-length cross-section

#: tetrahedra of a reduction's mesh (:func:`build_reduction`): linear tets lock in bending
#: (notes: first frequency 69-90 % too high)
MESH_ORDER = 2
#: which modes a reduction keeps (:func:`build_reduction`)
MODE_SELECTIONS = ("in_plane", "all")


# ------------------------------------------------------------------------------------------
# result type
# ------------------------------------------------------------------------------------------
@dataclass
class Reduction(PlateLink):
    """A reduced flexible plate link, ready for :func:`~flex.bodies.reduction.body.add_ffrf_link`.

    Node index arrays refer to ``fem``'s mesh nodes; weights sum to 1. ``centre_*`` are the
    weighted reference positions of the node sets in body coordinates [m]: the points the
    markers of :func:`~flex.bodies.reduction.body.add_ffrf_link` report.
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
    #: the tetrahedra's order: 2 (quadratic, the default) or 1 (linear)
    mesh_order: int = MESH_ORDER
    #: the eigen-solve's mode count when the reduction keeps the first ``modes`` of a larger
    #: solve (:func:`build_reduction`'s ``solve_modes``), None for a solve of ``modes`` itself
    solve_modes: int | None = None
    _ffrf_interface: Any = field(default=None, repr=False, compare=False)
    #: the ``ngsolve.Mesh`` of a build made in this process (second order after the import),
    #: None when loaded from the cache: what is assembled on the mesh later (the geometric
    #: stiffness) uses it instead of meshing the plate again (about as long as a build)
    _mesh: Any = field(default=None, repr=False, compare=False)

    @property
    def n_modal_coordinates(self) -> int:
        """Number of elastic coordinates of the reduced body: the static modes of ``end_b``
        (6, or its 3 in-plane ones) + ``modes``."""
        return int(self.fem.modeBasis["matrix"].shape[1])

    @property
    def highest_body_frequency_Hz(self) -> float:
        """The highest natural frequency [Hz] the reduced body carries with end A held: its
        static modes of end B included (the axial one, near the rod's fixed-free frequency,
        lies far above the retained bending modes and sets the joint forces' ringing)."""
        interface = self.ffrf_interface()
        # K x = w^2 M x through M's Cholesky factor (numpy: scipy.linalg costs 75 ms to
        # import on a command line that needs nothing else of it)
        inverse = np.linalg.inv(np.linalg.cholesky(interface.massMatrixReduced))
        eigenvalues = np.linalg.eigvalsh(inverse @ interface.stiffnessMatrixReduced
                                         @ inverse.T)
        return float(np.sqrt(np.max(np.abs(eigenvalues))) / (2.0 * np.pi))

    @property
    def has_stress_modes(self) -> bool:
        """True if the FEMinterface carries stress post-processing modes."""
        return "matrix" in (self.fem.postProcessingModes or {})

    def ffrf_interface(self):
        """The ``ObjectFFRFreducedOrderInterface`` of this reduction, made once and reused.

        Its constructor projects the full mass matrix on the basis (the costly part of adding
        a body), so several systems built from one reduction share it, and its arrays are
        kept beside the reduction's cache entry (:mod:`flex.bodies.reduction.interface_cache`).
        """
        if self._ffrf_interface is None:
            self._ffrf_interface = ffrf_interface(self.fem,
                                                  interface_path(self.cache_file, self.key))
        return self._ffrf_interface



# ------------------------------------------------------------------------------------------
# input checks
# ------------------------------------------------------------------------------------------
def is_number(value: Any) -> bool:
    """A real number, not a bool (``True`` is an ``int`` to Python, never a size to flex)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _check_inputs(sizes: dict[str, float], poisson_ratio: float, modes: int) -> None:
    for name, value in sizes.items():
        if not (is_number(value) and math.isfinite(value) and value > 0):
            raise SceneError(f"reduction {name} = {value!r}: must be a finite number > 0")
    if not (is_number(poisson_ratio) and 0.0 < poisson_ratio < 0.5):
        raise SceneError(
            f"reduction poisson_ratio = {poisson_ratio!r}: must lie in the open range (0, 0.5)")
    if isinstance(modes, bool) or not isinstance(modes, int | np.integer) or modes < 1:
        raise SceneError(f"reduction modes = {modes!r}: must be an integer >= 1")
    if sizes["mesh_size_m"] > sizes["length_m"]:
        raise SceneError(
            f"reduction mesh_size_m = {sizes['mesh_size_m']!r}: must be <= length_m "
            f"({sizes['length_m']!r}); the notes recommend about 1-2 x thickness")


# ------------------------------------------------------------------------------------------
# building
# ------------------------------------------------------------------------------------------
def _node_set(fem, name: str) -> dict:
    for node_set in fem.nodeSets:
        if node_set["Name"] == name:
            return node_set
    raise KeyError(name)


def unit_sum(weights: np.ndarray) -> np.ndarray:
    """Marker weights scaled to sum to 1 (Exudyn warns, once per marker and run, when a
    solve left their sum off 1 by round-off)."""
    weights = np.asarray(weights, dtype=float)
    return weights / math.fsum(weights)


def _pinned_pinned_frequency_Hz(interface, reduction_length_m: float,
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
    body = interface.AddObjectFFRFreducedOrder(mbs, positionRef=[0.0, 0.0, 0.0])
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
def ngsolve_thread_count(threads: int | None) -> Iterator[None]:
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


def build_reduction(plate: Plate, mesh_size_m: float, modes: int,
                    cache_dir: str | os.PathLike | None, *,
                    mode_selection: str = "in_plane",
                    ngsolve_threads: int | None = 1,
                    mesh_order: int = MESH_ORDER,
                    solve_modes: int | None = None) -> Reduction:
    """Mesh, reduce and cache a plate link; return the :class:`Reduction`.

    Contract:
      - ``plate``: its sizes in metres, E in Pa, density in kg/m^3, Poisson's ratio
        (:class:`flex.base.physics.Plate`); ``mesh_size_m`` is netgen's maxh
        (recommendation: about the thickness, at most 2 x thickness); ``modes`` >= 1 is the
        number of fixed-interface (both faces clamped) eigenmodes added to the static modes
        of ``end_b``. Bad values raise :class:`flex.base.errors.SceneError`.
      - ``mode_selection``: ``"in_plane"`` (default) keeps only modes symmetric about the
        mechanism plane z = 0 -- the 3 in-plane static modes of ``end_b`` (x, y, rotation
        about z) and the lowest ``modes`` in-plane eigenmodes -- since a planar mechanism
        loads its links in plane and the out-of-plane bending and torsion modes carry
        nothing (decoupled by symmetry,
        :func:`~flex.bodies.reduction.basis._in_plane_eigenmodes`); ``"all"`` keeps the 6
        static modes and the lowest ``modes`` eigenmodes of any kind.
      - the mesh uses second-order tetrahedra; stress post-processing modes (local stress,
        Pa per unit modal coordinate) are always computed.
      - ``cache_dir``: directory of the cache (created if missing) or None for no caching. The
        entry is ``<key>.hdf5``, ``key`` hashing every argument except ``cache_dir``, the
        cache format version and the exudyn and ngsolve versions. A whole entry for the same
        key is loaded (``from_cache`` True); a missing, truncated, damaged or foreign entry is
        rebuilt and replaced by an atomic rename.
      - ``mesh_order``: the tetrahedra's order, 2 (default, :data:`MESH_ORDER`) or 1 (linear:
        what the work-precision study measures them to cost in accuracy); part of the key.
      - ``ngsolve_threads``: threads of NGsolve's task manager during a build (restored
        afterwards; None leaves NGsolve's setting). 1 by default: the task manager spins,
        and on a shared 2-core machine 2 threads made a 0.6 s build take 12-20 s.
      - a rebuild reproduces the same reduction up to round-off (threaded assembly and
        eigensolver); eigenmode signs are normalised so modal coordinates keep their sign.
      - ``solve_modes``: None (or ``modes``): the eigenmodes are solved for ``modes``. A
        larger count: the reduction keeps the first ``modes`` eigenmodes (and their stress
        modes) of the ``solve_modes`` reduction, which is built or loaded as itself (so one
        mesh and one eigen-solve serve every smaller count). Such a truncation is its own
        cache entry (the key holds ``solve_modes``, the entry's metaData the solve's key): it
        is never taken for a solve of ``modes``. It equals that solve to ~2e-8 (1 mm plate,
        2 mm mesh); where the mesh's in-plane and out-of-plane modes mix, the in-plane modes
        are a Rayleigh-Ritz pick from the vectors computed, and the two differ by up to ~2e-5
        in frequency (coarse 3 mm plate; its pinned-pinned frequency 2e-7; measured,
        tests/test_reduction.py).
    """
    start = time.perf_counter()
    sizes = {"length_m": plate.length_m, "thickness_m": plate.thickness_m,
             "width_m": plate.width_m, "youngs_modulus_Pa": plate.youngs_modulus_Pa,
             "density_kg_per_m3": plate.density_kg_per_m3, "mesh_size_m": mesh_size_m}
    poisson_ratio = plate.poisson_ratio
    parameters = _reduction_parameters(sizes, poisson_ratio, modes, mode_selection, mesh_order)
    solve = _solve_count(modes, solve_modes)
    if solve is not None:
        parameters["solve_modes"] = solve
    key = cache_key(parameters)
    cache_file = None if cache_dir is None else Path(cache_dir) / f"{key}.hdf5"

    def make() -> tuple[Any, Any, Any]:
        if solve is None:
            with ngsolve_thread_count(ngsolve_threads):
                return _build_fem(parameters, key)
        solved = build_reduction(plate, mesh_size_m, solve, cache_dir,
                                 mode_selection=mode_selection,
                                 ngsolve_threads=ngsolve_threads, mesh_order=mesh_order)
        return (*_truncated_fem(solved, parameters, key), solved._mesh)

    fem, made, mesh, from_cache, cache_file = _cached_or_built(key, cache_file, make)
    meta = fem.metaData["flex"]
    return Reduction(
        fem=fem, **sizes, poisson_ratio=float(poisson_ratio), modes=int(modes),
        mode_selection=mode_selection, **_node_set_fields(fem),
        fixed_interface_frequencies_Hz=np.sqrt(np.abs(np.asarray(fem.eigenValues))) / (2 * np.pi),
        pinned_pinned_frequency_Hz=float(meta["pinned_pinned_frequency_Hz"]),
        mass_kg=float(meta["mass_kg"]), n_nodes=int(fem.NumberOfNodes()),
        n_elements=int(meta["n_elements"]), n_dof=3 * int(fem.NumberOfNodes()),
        cold_build_time_s=float(meta["cold_build_time_s"]),
        build_time_s=time.perf_counter() - start, from_cache=from_cache,
        cache_file=cache_file, key=key, mesh_order=int(mesh_order),
        solve_modes=solve, _ffrf_interface=made, _mesh=mesh,
    )


def _solve_count(modes: int, solve_modes: int | None) -> int | None:
    """The eigen-solve's count of a truncated reduction, None for a solve of ``modes``."""
    if solve_modes is None or solve_modes == modes:
        return None
    if isinstance(solve_modes, bool) or not isinstance(solve_modes, int | np.integer) \
            or solve_modes < modes:
        raise SceneError(f"reduction solve_modes = {solve_modes!r}: must be an integer >= "
                         f"modes ({modes!r})")
    return int(solve_modes)


def _reduction_parameters(sizes: dict[str, float], poisson_ratio: float, modes: int,
                          mode_selection: str, mesh_order: int) -> dict[str, Any]:
    """The checked arguments of :func:`build_reduction` as the parameters its cache key
    hashes (bad values raise :class:`flex.base.errors.SceneError`)."""
    _check_inputs(sizes, poisson_ratio, modes)
    if mode_selection not in MODE_SELECTIONS:
        raise SceneError(f"reduction mode_selection = {mode_selection!r}: must be one of "
                         f"{', '.join(MODE_SELECTIONS)}")
    if mesh_order not in (1, 2) or isinstance(mesh_order, bool):
        raise SceneError(f"reduction mesh_order = {mesh_order!r}: must be 1 or 2")
    parameters = {name: float(value) for name, value in sizes.items()}
    parameters.update(poisson_ratio=float(poisson_ratio), modes=int(modes),
                      mesh_order=int(mesh_order), stress_modes=True)
    if mode_selection != "all":  # "all" keeps the keys (and cache entries) it always had
        parameters.update(mode_selection=mode_selection,
                          eigensolver_iterations=EIGENSOLVER_ITERATIONS)
    return parameters


def _cached_or_built(key: str, cache_file: Path | None,
                     make: Callable[[], tuple[Any, Any, Any]]
                     ) -> tuple[Any, Any, Any, bool, Path | None]:
    """The FEMinterface of ``key``: the cache entry that proves its content, or a new one
    from ``make()`` (FEMinterface, its ObjectFFRFreducedOrderInterface, its mesh) stored in
    its place. Returns the FEMinterface, its ObjectFFRFreducedOrderInterface and its mesh
    (both None when loaded from the cache), whether it was loaded, and the cache file (None
    when nothing is kept)."""
    fem = load_cached(cache_file, key) if cache_file is not None else None
    from_cache = fem is not None
    made = mesh = None
    if fem is None:
        say_unproven(cache_file)
        fem, made, mesh = make()
        if cache_file is not None and not store(
                cache_file, lambda temporary: fem.SaveToFile(str(temporary), mode="HDF5"),
                REDUCTION_CACHE):
            cache_file = None  # not kept (said): nothing is cached beside it either
        elif cache_file is not None:
            ffrf_interface(fem, interface_path(cache_file, key), made=made)
    return fem, made, mesh, from_cache, cache_file


def _node_set_fields(fem) -> dict[str, np.ndarray]:
    """The :class:`Reduction` fields of the node sets ``end_a``, ``end_b`` and ``mid``: node
    numbers, weights (summing to 1) and weighted reference centres [m]."""
    positions = fem.GetNodePositionsAsArray()
    fields = {}
    for field_name, set_name in (("end_a", END_A), ("end_b", END_B), ("mid", MID)):
        node_set = _node_set(fem, set_name)
        fields[f"nodes_{field_name}"] = np.asarray(node_set["NodeNumbers"])
        fields[f"weights_{field_name}"] = unit_sum(node_set["NodeWeights"])
        fields[f"centre_{field_name}"] = (np.asarray(node_set["NodeWeights"])
                                          @ positions[node_set["NodeNumbers"]])
    return fields


def _truncated_fem(solved: Reduction, parameters: dict[str, Any], key: str
                   ) -> tuple[Any, Any]:
    """The FEMinterface keeping the static modes and the first ``parameters["modes"]``
    eigenmodes of ``solved`` (a reduction of more), their eigenvalues and stress modes, and
    its ObjectFFRFreducedOrderInterface; mesh, matrices and node sets are ``solved``'s."""
    import copy

    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    start = time.perf_counter()
    source, modes = solved.fem, parameters["modes"]
    kept = solved.n_modal_coordinates - solved.modes + modes  # static modes first
    fem = copy.copy(source)  # shares what the truncation keeps whole (read only)
    fem.modeBasis = {**source.modeBasis,
                     "matrix": np.ascontiguousarray(source.modeBasis["matrix"][:, :kept])}
    fem.eigenValues = np.asarray(source.eigenValues)[:modes].copy()
    stress = source.postProcessingModes  # six stress components per mode, mode by mode
    fem.postProcessingModes = {**stress,
                               "matrix": np.ascontiguousarray(stress["matrix"][:, :6 * kept])}
    interface = ObjectFFRFreducedOrderInterface(fem)
    end_a, end_b = _node_set(fem, END_A), _node_set(fem, END_B)
    pinned_pinned = _pinned_pinned_frequency_Hz(
        interface, parameters["length_m"], parameters["thickness_m"], parameters["width_m"],
        end_a["NodeNumbers"], end_a["NodeWeights"], end_b["NodeNumbers"], end_b["NodeWeights"])
    solved_meta = source.metaData["flex"]
    fem.metaData = {**source.metaData, "flex": {
        "key": key,
        "format_version": CACHE_FORMAT_VERSION,
        "parameters": json.dumps(parameters, sort_keys=True),
        "pinned_pinned_frequency_Hz": pinned_pinned,
        "mass_kg": float(interface.totalMass),
        "n_elements": int(solved_meta["n_elements"]),
        "cold_build_time_s": float(solved_meta["cold_build_time_s"])
        + time.perf_counter() - start,
        "solve_key": solved.key,
        "digest": fem_content_digest(fem),
    }}
    fem.metaData["flex"]["meta_digest"] = meta_digest(fem.metaData["flex"])
    return fem, interface


def _build_fem(parameters: dict[str, Any], key: str) -> tuple[Any, Any, Any]:
    """Mesh + Craig-Bampton + stress modes.

    Returns the FEMinterface (flex's own data in ``metaData['flex']``, the mid-length node set
    in ``nodeSets``), its ObjectFFRFreducedOrderInterface and the mesh (second order after
    the import).
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
        poissonsRatio=parameters["poisson_ratio"], meshOrder=parameters["mesh_order"],
        boundaryNamesList=[END_A, END_B])
    # sorted node numbers and area weights: reproducible files, weighted centre = face centre
    interfaces = []
    for name in (END_A, END_B):
        node_set = _node_set(fem, name)
        nodes = np.sort(np.asarray(node_set["NodeNumbers"], dtype=np.int64))
        node_set["NodeNumbers"] = nodes
        node_set["NodeWeights"] = fem.GetNodeWeightsFromSurfaceAreas(nodes)
        interfaces.append(nodes)
    static_modes = craig_bampton_basis(fem, mass_form, stiffness_form, interfaces,
                                       parameters["modes"],
                                       parameters.get("mode_selection", "all"))
    fix_eigenmode_signs(fem.modeBasis["matrix"], static_modes)
    material = KirchhoffMaterial(parameters["youngs_modulus_Pa"], parameters["poisson_ratio"],
                                 parameters["density_kg_per_m3"])
    fem.ComputePostProcessingModesNGsolve(space, material=material,
                                          outputVariableType=exu.OutputVariableType.StressLocal)
    mid_nodes, mid_weights = section_mean_weights(fem.GetNodePositionsAsArray(),
                                                  fem_tetrahedra(fem), length_m / 2)
    fem.nodeSets.append({"Name": MID, "NodeNumbers": mid_nodes, "NodeWeights": mid_weights})

    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    interface = ObjectFFRFreducedOrderInterface(fem)
    end_a, end_b = _node_set(fem, END_A), _node_set(fem, END_B)
    pinned_pinned = _pinned_pinned_frequency_Hz(
        interface, length_m, parameters["thickness_m"], parameters["width_m"],
        end_a["NodeNumbers"], end_a["NodeWeights"], end_b["NodeNumbers"], end_b["NodeWeights"])
    fem.metaData["flex"] = {
        "key": key,
        "format_version": CACHE_FORMAT_VERSION,
        "parameters": json.dumps(parameters, sort_keys=True),
        "pinned_pinned_frequency_Hz": pinned_pinned,
        "mass_kg": float(interface.totalMass),
        "n_elements": int(mesh.ne),
        "cold_build_time_s": time.perf_counter() - start,
        "digest": fem_content_digest(fem),
    }
    fem.metaData["flex"]["meta_digest"] = meta_digest(fem.metaData["flex"])
    # handed to the Reduction (not stored): saves re-projecting on the first add, remeshing
    return fem, interface, mesh


