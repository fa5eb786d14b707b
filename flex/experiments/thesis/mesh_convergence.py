"""Mesh convergence of a plate link's FE frequency and the choice of the production mesh.

:func:`select_production_mesh` (pure: no FE) estimates the converged frequency by Richardson
extrapolation and picks the coarsest mesh within a relative tolerance;
:func:`mesh_convergence` refines a plate's mesh
(:func:`flex.experiments.thesis.fe_modes.plate_modes`) and
applies it. Sizes in m, frequencies in Hz (or any one unit), times in s.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

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

    ``reference_frequency`` (unit of the input frequencies) is the Richardson extrapolation
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
                           relative_tolerance: float = 0.005) -> MeshSelection:
    """Pick the coarsest mesh whose frequency lies within ``relative_tolerance`` of converged.

    ``mesh_sizes_m`` strictly decreasing (m), ``frequencies`` (any one unit) per level,
    ``relative_tolerance`` dimensionless in (0, 1). The converged value is estimated by
    Richardson extrapolation f(h) = f_ref + C h^p through the three finest levels (p solved
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
    reference, method, order = float(values[-1]), "finest", float("nan")
    if sizes.size >= 3:
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
class MeshConvergence:
    """Per-level results of :func:`mesh_convergence` and the production-mesh choice.

    Arrays (n_levels,): ``mesh_sizes_m`` (m), ``element_counts``, ``dof_counts``,
    ``frequencies_Hz`` (Hz, first mode of ``mode_kind``), ``wall_times_s`` (s, whole
    :func:`flex.experiments.thesis.fe_modes.plate_modes` call), ``cpu_times_s`` (s, process CPU
    time of the
    call).
    ``selection``: :class:`MeshSelection`. ``production_mesh_size_m``: the selected size (m),
    or None. ``mode_kind`` and ``boundary_condition`` as requested.
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
                     mode_count: int = 5, material: Material = THESIS_STEEL
                     ) -> MeshConvergence:
    """Refine ``mesh_size_m`` and track the first mode of ``mode_kind``; pick the production mesh.

    Sizes in m; ``mesh_sizes_m`` strictly decreasing, default :func:`default_mesh_sizes_m`
    (from 4 t down by sqrt(2) per level). Refinement stops at the first level whose
    DOF count, estimated from the previous level as DOF * (h_prev / h)^3, would exceed
    ``max_dof_count`` (memory and time of the sparse Cholesky factorisation grow fast with
    3D meshes). ``mode_count`` modes are computed per level; raise it if ``mode_kind`` is not
    among them. Selection: :func:`select_production_mesh` with ``relative_tolerance``
    (default 0.5 %). Returns :class:`MeshConvergence`.
    """
    check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m)
    check_choice("mode_kind", mode_kind, MODE_KINDS)
    check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    sizes = (default_mesh_sizes_m(thickness_m, width_m) if mesh_sizes_m is None
             else np.asarray(mesh_sizes_m, dtype=float))
    if sizes.ndim != 1 or sizes.size < 1 or np.any(np.diff(sizes) >= 0):
        raise SceneError("mesh_sizes_m must be a non-empty, strictly decreasing sequence")
    check_positive(**{f"mesh_sizes_m[{i}]": float(h) for i, h in enumerate(sizes)})
    rows: list[tuple[float, int, int, float, float, float]] = []
    for size_m in sizes:
        if rows:
            previous_size_m, previous_dofs = rows[-1][0], rows[-1][2]
            if previous_dofs * (previous_size_m / size_m) ** 3 > max_dof_count:
                break
        wall_start, cpu_start = time.perf_counter(), time.process_time()
        modes = plate_modes(length_m, thickness_m, width_m, float(size_m), boundary_condition,
                            mode_count, material)
        wall_s, cpu_s = time.perf_counter() - wall_start, time.process_time() - cpu_start
        frequency_Hz = float(modes.frequencies_Hz[modes.first_of_kind(mode_kind)])
        rows.append((float(size_m), modes.element_count, modes.dof_count, frequency_Hz,
                     wall_s, cpu_s))
    table = np.array(rows)
    selection = select_production_mesh(table[:, 0], table[:, 3], relative_tolerance)
    production = (None if selection.selected_index is None
                  else float(table[selection.selected_index, 0]))
    return MeshConvergence(
        length_m=float(length_m), thickness_m=float(thickness_m), width_m=float(width_m),
        boundary_condition=boundary_condition, mode_kind=mode_kind, mesh_sizes_m=table[:, 0],
        element_counts=table[:, 1].astype(int), dof_counts=table[:, 2].astype(int),
        frequencies_Hz=table[:, 3], wall_times_s=table[:, 4], cpu_times_s=table[:, 5],
        selection=selection, production_mesh_size_m=production)
