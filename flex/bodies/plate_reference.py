"""A p-converged linear 3D reference of a plate link: its static deflection and first bending
frequency between flex's joint supports, with an error from the order sequence (cached).

For each order p of ``orders`` (default 3, 4, 5) one solve of :mod:`flex.bodies.plate_pfem`
(hexahedra of order p, default 8 x 1 x 2 with the end elements graded towards the end faces,
static condensation; the ends held as flex's joint markers hold them, on their mean
displacement; the plate's own weight as a uniform transverse load) gives the section-mean and
the centroid deflection at mid-span and the first in-plane bending frequency. At least two
elements across the width: one element there is symmetric about z = 0, so the solution (even
in z) gains only from every second order; measured on 80 x 1 x 10 mm, orders 4 and 5 then
agreed to 3e-10 while both were 6.6e-5 off, a false certificate.

Each output's limit is Aitken's extrapolation over the last three orders (:func:`aitken_limit`);
its error is the larger of the extrapolated tail and the last change, a bound that held for
every plate measured against order 7 (``docs/references.md``).
Method and measurements: ``docs/references.md``. Entries are cached (one HDF5 file per plate,
orders and mesh, keyed also by NGSolve's version; content digest, atomic write:
:mod:`flex.data.cache`); ``cache_dir`` is the caller's (a command line reads it from the
environment, this module reads none).
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from importlib.metadata import version
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from flex.base.physics import Plate
from flex.bodies.plate_pfem import (
    DEFAULT_MESH,
    GRADING_RATIO,
    HexMesh,
    OrderSolution,
    line_load_N_per_m,
    solve_order,
)
from flex.data.cache import PLATE_REFERENCE_CACHE, content_digest, say, store

#: Bump when the method or the layout of a cache entry changes; old entries are then ignored.
FORMAT_VERSION = 1
DEFAULT_ORDERS: tuple[int, ...] = (3, 4, 5)
_PER_ORDER = ("dof_counts", "section_mean_deflections_m", "centroid_deflections_m",
              "first_bending_frequencies_Hz")


def aitken_limit(values: Sequence[float]) -> tuple[float, float, float]:
    """``(limit, error, ratio)`` of a sequence from its last three values a, b, c.

    ``ratio`` = (c - b) / (b - a), the observed contraction per step. For 0 <= ratio < 1 (a
    monotone, converging sequence) the limit is Aitken's delta-squared extrapolation ``c + (c -
    b) r / (1 - r)`` and the error the larger of the extrapolated tail ``|c - b| r / (1 - r)``
    and the last change ``|c - b|``: the tail alone assumes the contraction goes on, and
    p-convergence towards the supports' edge singularity slows down (measured, 80 x 3 x 10 mm
    on equal elements: ratios 0.25, 0.53, 0.74 over orders 3 to 7; the tail of orders 3-5 then
    was half the limit's distance to order 7, the last change more than it). Otherwise no
    convergence is seen: the limit is c and the error the larger of the two last changes.
    """
    a, b, c = (float(v) for v in values[-3:])
    first, second = b - a, c - b
    if first == 0.0:
        return c, abs(second), (0.0 if second == 0.0 else math.inf)
    ratio = second / first
    if 0.0 <= ratio < 1.0:
        tail = second * ratio / (1.0 - ratio)
        return c + tail, max(abs(tail), abs(second)), ratio
    return c, max(abs(first), abs(second)), ratio


@dataclass(frozen=True)
class PlateReference:
    """The converged linear 3D response of a plate between flex's joint supports (module doc).

    Per order (tuples in ``orders``' order): ``dof_counts``, ``section_mean_deflections_m``,
    ``centroid_deflections_m`` [m] (along the load), ``first_bending_frequencies_Hz``. The
    limits (Aitken over the last three orders, :func:`aitken_limit`) with their errors [same
    unit] and convergence ratios (last change / the one before). ``line_load_N_per_m``: the
    uniform load [N/m] the deflections answer. ``from_cache``: read, not computed (not part
    of the value)."""

    plate: Plate
    orders: tuple[int, ...]
    mesh: HexMesh
    line_load_N_per_m: float
    dof_counts: tuple[int, ...]
    section_mean_deflections_m: tuple[float, ...]
    centroid_deflections_m: tuple[float, ...]
    first_bending_frequencies_Hz: tuple[float, ...]
    section_mean_deflection_m: float
    section_mean_deflection_error_m: float
    section_mean_convergence_ratio: float
    centroid_deflection_m: float
    centroid_deflection_error_m: float
    first_bending_Hz: float
    first_bending_error_Hz: float
    first_bending_convergence_ratio: float
    from_cache: bool = field(default=False, compare=False)

    @classmethod
    def of_orders(cls, plate: Plate, orders: Sequence[int], mesh: HexMesh,
                  solutions: Sequence[OrderSolution], from_cache: bool = False
                  ) -> PlateReference:
        """The reference of per-order ``solutions`` (one per order), limits extrapolated."""
        columns = [tuple(column) for column in zip(*solutions, strict=True)]
        mean = aitken_limit(columns[1])
        centroid = aitken_limit(columns[2])
        frequency = aitken_limit(columns[3])
        return cls(plate, tuple(int(p) for p in orders), mesh,
                   line_load_N_per_m(plate), tuple(int(n) for n in columns[0]),
                   *(tuple(float(v) for v in column) for column in columns[1:]),
                   mean[0], mean[1], mean[2], centroid[0], centroid[1],
                   frequency[0], frequency[1], frequency[2], from_cache)

    @property
    def section_mean_relative_error(self) -> float:
        """Error of the section-mean deflection relative to it [-]."""
        return self.section_mean_deflection_error_m / self.section_mean_deflection_m

    @property
    def first_bending_relative_error(self) -> float:
        """Error of the first bending frequency relative to it [-]."""
        return self.first_bending_error_Hz / self.first_bending_Hz

    @property
    def centroid_offset(self) -> float:
        """``1 - centroid / section mean`` deflection [-]: the anticlastic lag of the centroid."""
        return 1.0 - self.centroid_deflection_m / self.section_mean_deflection_m

    def attrs(self) -> dict[str, Any]:
        """The reference as HDF5 attributes: ``plate_<field>``, ``mesh_<field>``, the
        per-order arrays, the limits, errors and ratios (units in the names) and the format
        version."""
        values = {f"plate_{name}": value for name, value in asdict(self.plate).items()}
        values.update({f"mesh_{name}": value for name, value in asdict(self.mesh).items()})
        values["mesh_grading_ratio"] = GRADING_RATIO
        for name, value in asdict(self).items():
            if name in ("plate", "mesh", "from_cache"):
                continue
            values[name] = np.asarray(value) if isinstance(value, tuple) else value
        values.update(section_mean_relative_error=self.section_mean_relative_error,
                      first_bending_relative_error=self.first_bending_relative_error,
                      centroid_offset=self.centroid_offset,
                      reference_format_version=FORMAT_VERSION)
        return values


def plate_reference(plate: Plate, *, orders: Sequence[int] = DEFAULT_ORDERS,
                    cache_dir: Path | None = None,
                    mesh: HexMesh = DEFAULT_MESH,
                    stream: TextIO | None = None) -> PlateReference:
    """The :class:`PlateReference` of ``plate``: read from ``cache_dir`` when an entry for
    the plate, ``orders`` (at least three, increasing) and ``mesh`` proves its content,
    else computed (seconds) and stored there. ``cache_dir`` None: computed, not stored. An
    entry that does not prove its content is computed again with one line on ``stream``
    (stderr by default)."""
    orders = _checked(plate, orders, mesh)
    path = None
    if cache_dir is not None:
        path = Path(cache_dir) / f"plate-reference-{reference_key(plate, orders, mesh)}.h5"
        cached = _load(path, plate, orders, mesh, stream)
        if cached is not None:
            return cached
    solutions = [solve_order(plate, order, mesh) for order in orders]
    reference = PlateReference.of_orders(plate, orders, mesh, solutions)
    if path is not None:
        _save(path, reference, stream)
    return reference


def _checked(plate: Plate, orders: Sequence[int], mesh: HexMesh) -> tuple[int, ...]:
    orders = tuple(orders)
    if (len(orders) < 3 or any(not isinstance(p, int) or p < 1 for p in orders)
            or list(orders) != sorted(set(orders))):
        raise ValueError(f"orders = {orders!r}: need at least three increasing integers >= 1")
    counts = (mesh.along, mesh.across_thickness, mesh.across_width)
    if (any(not isinstance(n, int) or n < 1 for n in counts) or mesh.across_width < 2
            or not isinstance(mesh.graded_layers, int) or mesh.graded_layers < 0):
        raise ValueError(f"mesh = {mesh!r}: need element counts >= 1, >= 2 across the width "
                         f"(one element there, symmetric about z = 0, gains only from every "
                         f"second order: a false plateau), graded layers >= 0")
    sizes = (*plate.sizes_m, plate.youngs_modulus_Pa, plate.density_kg_per_m3)
    if not all(math.isfinite(v) and v > 0 for v in sizes):
        raise ValueError(f"plate = {plate!r}: sizes, modulus and density must be finite, > 0")
    if not -1.0 < plate.poisson_ratio < 0.5:
        raise ValueError(f"poisson_ratio = {plate.poisson_ratio!r}: must lie in (-1, 0.5)")
    return orders


# --- the cache ---------------------------------------------------------------------------

def reference_key(plate: Plate, orders: Sequence[int], mesh: HexMesh) -> str:
    """A reference's cache key: the plate, orders, mesh, format version and NGSolve's
    version (``repr(float)``: exact and canonical, 0.003 and 3e-3 hash alike)."""
    parameters = {name: repr(float(value)) for name, value in asdict(plate).items()}
    parameters.update(orders=list(orders), mesh=mesh.as_array().tolist(),
                      format_version=FORMAT_VERSION, ngsolve=version("ngsolve"))
    text = json.dumps(parameters, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def _digest(key: str, arrays: dict[str, np.ndarray]) -> str:
    return content_digest([("key", key), *((name, arrays[name]) for name in
                                           ("orders", "mesh", *_PER_ORDER))])


def _load(path: Path, plate: Plate, orders: tuple[int, ...], mesh: HexMesh,
          stream: TextIO | None) -> PlateReference | None:
    """The entry at ``path`` if it proves its content (key and digest), else None: missing
    silently, otherwise with one line saying it is computed again."""
    if not path.is_file():
        return None
    import h5py

    key = reference_key(plate, orders, mesh)
    try:
        with h5py.File(path, "r") as h5:
            arrays = {name: h5[name][()] for name in ("orders", "mesh", *_PER_ORDER)}
            stored = (str(h5.attrs["key"]), str(h5.attrs["content_digest"]))
    except Exception:  # truncated, foreign, not HDF5: computed again
        stored = None
    if stored != (key, _digest(key, arrays) if stored else None):
        say(PLATE_REFERENCE_CACHE, f"entry '{path}' did not prove its content (unreadable, "
                                   f"or its key or content digest does not match: damaged, "
                                   f"edited or foreign); computing the reference again",
            stream)
        return None
    solutions = [OrderSolution(int(n), *(float(v) for v in rest)) for n, *rest in
                 zip(*(arrays[name] for name in _PER_ORDER), strict=True)]
    return PlateReference.of_orders(plate, orders, mesh, solutions, from_cache=True)


def _save(path: Path, reference: PlateReference, stream: TextIO | None) -> None:
    """Write the entry atomically (:func:`flex.data.cache.store`; a location that cannot be
    used is said in one line and the entry is not kept)."""
    import h5py

    key = reference_key(reference.plate, reference.orders, reference.mesh)
    arrays = {"mesh": reference.mesh.as_array(),
              **{name: np.asarray(getattr(reference, name)) for name in ("orders", *_PER_ORDER)}}

    def write(temporary: Path) -> None:
        with h5py.File(temporary, "w") as h5:
            for name, array in arrays.items():
                h5[name] = array
            h5.attrs.update(reference.attrs())
            h5.attrs.update(key=key, content_digest=_digest(key, arrays))

    store(path, write, PLATE_REFERENCE_CACHE, stream)
