"""Mesh convergence of a plate link's FE frequency and the choice of the production mesh.

:func:`select_production_mesh` (pure: no FE) estimates the converged frequency by Richardson
extrapolation (or takes a given reference) and picks the coarsest mesh within a relative
tolerance; :func:`mesh_convergence` refines a plate's mesh
(:func:`flex.experiments.thesis.fe_modes.plate_modes`) and applies it. Optionally the
reference comes from raising the element order on one of the levels' meshes (p-refinement,
:class:`OrderConvergence`) instead of from the finest meshes: on these plates the order
converges far faster than the mesh (1 mm plate: order 4 on a 4 mm mesh, 20k DOF, within
3e-6 of order 4 on a 1 mm mesh, 233k DOF, where order 2 on the 1 mm mesh, 36k DOF, is 6e-5
off; measured). Sizes in m, frequencies in Hz (or any one unit), times in s.
"""

from __future__ import annotations

import math
import time
from collections.abc import MutableMapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import check_positive
from flex.experiments.thesis.beams import (
    LINK_BOUNDARY_CONDITIONS,
    MODE_KINDS,
    THESIS_STEEL,
    Material,
    brent_root,
    check_choice,
)
from flex.experiments.thesis.fe_modes import plate_modes


@dataclass(frozen=True)
class MeshSelection:
    """Outcome of :func:`select_production_mesh`.

    ``reference_frequency`` (unit of the input frequencies) is the given reference (its
    ``reference_method`` as given, ``observed_order`` NaN), else the Richardson extrapolation
    of the three finest levels when they converge monotonically with an observed order in
    [0.5, 12] (``reference_method`` "richardson", ``observed_order`` set), else the finest
    value ("finest", order NaN). ``relative_errors`` (n_levels,) = |f - f_ref| / f_ref.
    ``selected_index`` is the coarsest level whose error and every finer level's error are
    within ``relative_tolerance``, or None if even the finest is not.
    """

    reference_frequency: float
    reference_method: str
    observed_order: float
    relative_errors: np.ndarray
    relative_tolerance: float
    selected_index: int | None


def select_production_mesh(mesh_sizes_m: Sequence[float], frequencies: Sequence[float],
                           relative_tolerance: float = 0.005,
                           reference: tuple[float, str] | None = None) -> MeshSelection:
    """Pick the coarsest mesh whose frequency lies within ``relative_tolerance`` of converged.

    ``mesh_sizes_m`` strictly decreasing (m), ``frequencies`` (any one unit) per level,
    ``relative_tolerance`` dimensionless in (0, 1). The converged value is ``reference``
    (frequency in the same unit, method name) when given, else estimated by Richardson
    extrapolation f(h) = f_ref + C h^p through the three finest levels (p solved
    for, so the sizes need not form a geometric sequence); if those levels are not monotone
    with shrinking steps, the finest value is the reference. Pure function (no FE), so the
    selection logic can be tested on synthetic data.
    """
    sizes = np.asarray(mesh_sizes_m, dtype=float)
    values = np.asarray(frequencies, dtype=float)
    if sizes.ndim != 1 or sizes.shape != values.shape or sizes.size < 1:
        raise SceneError("mesh_sizes_m and frequencies must be 1D sequences of equal length")
    if np.any(sizes <= 0) or np.any(np.diff(sizes) >= 0):
        raise SceneError("mesh_sizes_m must be positive and strictly decreasing (coarse first)")
    if np.any(~np.isfinite(values)) or np.any(values <= 0):
        raise SceneError("frequencies must be positive finite numbers")
    if not 0.0 < relative_tolerance < 1.0:
        raise SceneError(f"relative_tolerance = {relative_tolerance!r}: must lie in (0, 1)")
    given = reference
    reference, method, order = float(values[-1]), "finest", float("nan")
    if given is not None:
        reference, method = float(given[0]), str(given[1])
        if not (math.isfinite(reference) and reference > 0):
            raise SceneError(f"reference frequency {reference!r}: must be positive and finite")
    elif sizes.size >= 3:
        (h1, h2, h3), (f1, f2, f3) = sizes[-3:], values[-3:]
        step_coarse, step_fine = f1 - f2, f2 - f3
        if step_coarse * step_fine > 0 and abs(step_fine) < abs(step_coarse):
            ratio = step_coarse / step_fine

            def mismatch(p: float) -> float:
                return (h1**p - h2**p) / (h2**p - h3**p) - ratio

            low, high = 0.5, 12.0
            if mismatch(low) * mismatch(high) < 0:
                order = brent_root(mismatch, low, high)
                coefficient = step_fine / (h2**order - h3**order)
                reference, method = float(f3 - coefficient * h3**order), "richardson"
    errors = np.abs(values - reference) / reference
    within = errors <= relative_tolerance
    selected: int | None = None
    for index in range(sizes.size):
        if np.all(within[index:]):
            selected = index
            break
    return MeshSelection(reference_frequency=reference, reference_method=method,
                         observed_order=order, relative_errors=errors,
                         relative_tolerance=relative_tolerance, selected_index=selected)


@dataclass(frozen=True)
class OrderConvergence:
    """The element order raised on one mesh (p-refinement), the reference of
    :func:`mesh_convergence` when it is asked for one.

    ``mesh_size_m`` (m): netgen maxh of the mesh; arrays (n_orders,): ``orders`` of the
    tetrahedra, ``dof_counts``, ``frequencies_Hz`` (Hz), ``cpu_times_s`` (s, process CPU time
    of each solve). ``reference_frequency_Hz``: the highest order's frequency;
    ``relative_error_estimate``: its difference to the next lower order's, relative to it (an
    upper estimate: the error falls by far more than that from one order to the next here).
    """

    mesh_size_m: float
    orders: np.ndarray
    dof_counts: np.ndarray
    frequencies_Hz: np.ndarray
    cpu_times_s: np.ndarray

    @property
    def reference_frequency_Hz(self) -> float:
        """The highest order's frequency [Hz]."""
        return float(self.frequencies_Hz[-1])

    @property
    def relative_error_estimate(self) -> float:
        """|f(p_max) - f(p_max - 1)| / f(p_max), dimensionless."""
        return float(abs(self.frequencies_Hz[-1] - self.frequencies_Hz[-2])
                     / self.frequencies_Hz[-1])

    @property
    def method(self) -> str:
        """How the reference was found, as the report and the figure name it."""
        return (f"order {int(self.orders[-1])} on the {self.mesh_size_m * 1e3:.3g} mm mesh, "
                f"estimated error {self.relative_error_estimate:.1e}")


@dataclass(frozen=True)
class MeshConvergence:
    """Per-level results of :func:`mesh_convergence` and the production-mesh choice.

    Arrays (n_levels,): ``mesh_sizes_m`` (m), ``element_counts``, ``dof_counts``,
    ``frequencies_Hz`` (Hz, first mode of ``mode_kind``), ``wall_times_s`` (s, whole
    :func:`flex.experiments.thesis.fe_modes.plate_modes` call), ``cpu_times_s`` (s, process CPU
    time of the
    call).
    ``selection``: :class:`MeshSelection`. ``production_mesh_size_m``: the selected size (m),
    or None. ``mode_kind`` and ``boundary_condition`` as requested. ``orders``: the
    p-refinement that gave the reference (:class:`OrderConvergence`), or None (Richardson).
    """

    length_m: float
    thickness_m: float
    width_m: float
    boundary_condition: str
    mode_kind: str
    mesh_sizes_m: np.ndarray
    element_counts: np.ndarray
    dof_counts: np.ndarray
    frequencies_Hz: np.ndarray
    wall_times_s: np.ndarray
    cpu_times_s: np.ndarray
    selection: MeshSelection
    production_mesh_size_m: float | None
    orders: OrderConvergence | None = None


def default_mesh_sizes_m(thickness_m: float, width_m: float) -> np.ndarray:
    """Default refinement levels, m: 4 s, 2.83 s, 2 s, 1.41 s, s, ..., s / 16, with s the
    smaller of thickness and width; ratio sqrt(2) per level. :func:`mesh_convergence` stops
    at its DOF budget long before the finest: a 1 mm plate stops at about s, a 10 mm plate
    (mesh limited by the 10 mm box, so its coarse levels are pre-asymptotic) near s / 4.
    """
    check_positive(thickness_m=thickness_m, width_m=width_m)
    smallest_m = min(thickness_m, width_m)
    return smallest_m * 2.0 ** (np.arange(4, -9, -1) / 2.0)


def mesh_convergence(length_m: float, thickness_m: float, width_m: float,
                     boundary_condition: str = "pinned-pinned",
                     mode_kind: str = "in-plane bending",
                     mesh_sizes_m: Sequence[float] | None = None,
                     relative_tolerance: float = 0.005, max_dof_count: int = 60_000,
                     mode_count: int = 5, material: Material = THESIS_STEEL,
                     reference_orders: Sequence[int] = (),
                     reference_max_dof_count: int = 25_000,
                     meshes: MutableMapping[float, Any] | None = None) -> MeshConvergence:
    """Refine ``mesh_size_m`` and track the first mode of ``mode_kind``; pick the production mesh.

    Sizes in m; ``mesh_sizes_m`` strictly decreasing, default :func:`default_mesh_sizes_m`
    (from 4 t down by sqrt(2) per level). Refinement stops at the first level whose
    DOF count, estimated from the previous level as DOF * (h_prev / h)^3, would exceed
    ``max_dof_count`` (memory and time of the sparse Cholesky factorisation grow fast with
    3D meshes). ``mode_count`` modes are computed per level; raise it if ``mode_kind`` is not
    among them. Selection: :func:`select_production_mesh` with ``relative_tolerance``
    (default 0.5 %). Its reference: with ``reference_orders`` (e.g. (3, 4), above the levels'
    order 2) the frequency at the highest order on the finest level's mesh where that order
    has at most ``reference_max_dof_count`` unknowns (the coarsest level's if none has), else
    Richardson extrapolation of the levels. ``meshes``: the plate's meshes by maxh [m], used
    and filled (a caller that meshes the same plate elsewhere shares them). Returns
    :class:`MeshConvergence`.
    """
    check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m)
    check_choice("mode_kind", mode_kind, MODE_KINDS)
    check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    sizes = (default_mesh_sizes_m(thickness_m, width_m) if mesh_sizes_m is None
             else np.asarray(mesh_sizes_m, dtype=float))
    if sizes.ndim != 1 or sizes.size < 1 or np.any(np.diff(sizes) >= 0):
        raise SceneError("mesh_sizes_m must be a non-empty, strictly decreasing sequence")
    check_positive(**{f"mesh_sizes_m[{i}]": float(h) for i, h in enumerate(sizes)})
    meshes = {} if meshes is None else meshes

    def solve(size_m: float, order: int) -> tuple[int, int, float, float, float]:
        """(elements, DOF, frequency [Hz], wall [s], CPU [s]) at maxh ``size_m``, ``order``."""
        wall_start, cpu_start = time.perf_counter(), time.process_time()
        if size_m not in meshes:
            from flex.bodies.plate import plate_mesh

            meshes[size_m] = plate_mesh(length_m, thickness_m, width_m, size_m)
        modes = plate_modes(length_m, thickness_m, width_m, size_m, boundary_condition,
                            mode_count, material, element_order=order, mesh=meshes[size_m])
        frequency_Hz = float(modes.frequencies_Hz[modes.first_of_kind(mode_kind)])
        return (modes.element_count, modes.dof_count, frequency_Hz,
                time.perf_counter() - wall_start, time.process_time() - cpu_start)

    rows: list[tuple[float, int, int, float, float, float]] = []
    for size_m in sizes:
        if rows:
            previous_size_m, previous_dofs = rows[-1][0], rows[-1][2]
            if previous_dofs * (previous_size_m / size_m) ** 3 > max_dof_count:
                break
        rows.append((float(size_m), *solve(float(size_m), 2)))
    table = np.array(rows)
    orders = None
    if reference_orders:
        orders = _order_convergence(table, reference_orders, reference_max_dof_count,
                                    meshes, solve)
    selection = select_production_mesh(
        table[:, 0], table[:, 3], relative_tolerance,
        None if orders is None else (orders.reference_frequency_Hz, orders.method))
    production = (None if selection.selected_index is None
                  else float(table[selection.selected_index, 0]))
    return MeshConvergence(
        length_m=float(length_m), thickness_m=float(thickness_m), width_m=float(width_m),
        boundary_condition=boundary_condition, mode_kind=mode_kind, mesh_sizes_m=table[:, 0],
        element_counts=table[:, 1].astype(int), dof_counts=table[:, 2].astype(int),
        frequencies_Hz=table[:, 3], wall_times_s=table[:, 4], cpu_times_s=table[:, 5],
        selection=selection, production_mesh_size_m=production, orders=orders)


def _order_convergence(table: np.ndarray, orders: Sequence[int], max_dof_count: int,
                       meshes: MutableMapping[float, Any], solve: Any) -> OrderConvergence:
    """Orders 2 (the level's own row of ``table``) and ``orders`` on the finest level's
    mesh where the highest order has at most ``max_dof_count`` unknowns (else the
    coarsest's); ``solve(size_m, order)`` as in :func:`mesh_convergence`."""
    import ngsolve as ngs

    orders = sorted(int(order) for order in orders)
    if len(orders) < 1 or orders[0] <= 2 or orders[-1] > 4:
        raise SceneError(f"reference_orders = {orders!r}: orders above 2, at most 4")
    index = 0
    for candidate in range(len(table)):
        mesh = meshes[float(table[candidate, 0])]
        if ngs.VectorH1(mesh, order=orders[-1]).ndof <= max_dof_count:
            index = candidate
    size_m = float(table[index, 0])
    rows = [(2, int(table[index, 2]), float(table[index, 3]), float(table[index, 5]))]
    for order in orders:
        _, dofs, frequency_Hz, _, cpu_s = solve(size_m, order)
        rows.append((order, dofs, frequency_Hz, cpu_s))
    columns = np.array(rows)
    return OrderConvergence(mesh_size_m=size_m, orders=columns[:, 0].astype(int),
                            dof_counts=columns[:, 1].astype(int), frequencies_Hz=columns[:, 2],
                            cpu_times_s=columns[:, 3])
