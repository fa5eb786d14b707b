"""Fields recovered from an FFRF link's modal coordinates: nodal stress and displacement,
their peaks, and the identity of the mode basis they only make sense with.

An FFRF body's elastic state is its modal coordinates q (the ``node_modal`` of
:func:`flex.bodies.reduction.add_ffrf_link`, stored as ``<link>/modal_coordinates``). Fields
are linear in q (small strains, as the FFRF model assumes):

- displacement in the link's frame ``u = Phi q`` (``fem.modeBasis["matrix"]``, 3 rows per
  node, body coordinates [m]);
- stress ``sigma = S q`` from the stress post-processing modes
  (``fem.postProcessingModes["matrix"]``: per node 6 columns per mode, Exudyn's order xx, yy,
  zz, yz, xz, xy, body axes; Pa per unit modal coordinate). NGsolve projects the element
  stresses on the second-order nodal space, so these are nodal values of a continuous field.

Peaks (:func:`von_mises_history`, :func:`stress_peak`): the largest von Mises stress over
the mesh nodes at each stored sample, in two regions -- ``away`` from the joint faces (nodes
with reference x in [t, L - t], one thickness left out at each end as
:func:`flex.bodies.reduction.bending_stress_history` does: the rigid end faces concentrate
stress where the pin of a real eye would not, Saint-Venant) and ``at the joints`` (the
rest). What they miss: stress between stored samples and between nodes.

Identity (:func:`basis_identity`, :func:`check_basis_identity`): modal coordinates mean
nothing without their exact basis. A run stores the reduction's cache key, the SHA-256 of its
mode basis and a *fingerprint* (low moments of every mode over the mesh): a rebuilt
reduction of the same key differs from the stored one by threaded round-off (the cache tests
allow 1e-7), which changes the digest but not the fingerprint beyond
:data:`FINGERPRINT_RTOL`; another basis (another floating frame, other modes) changes it by
far more.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from flex.data.results import Dataset

#: stress components per node and mode in ``postProcessingModes["matrix"]`` (Exudyn order)
COMPONENTS = ("xx", "yy", "zz", "yz", "xz", "xy")
#: largest difference of two fingerprints, relative to the largest entry of each mode's
#: row, that still counts as the same basis (round-off of a rebuild: ~1e-12 .. 1e-8)
FINGERPRINT_RTOL = 1e-6
#: the regions of the peaks: name -> description
REGIONS = {"away": "away from the joint faces (one thickness from each end left out)",
           "at_joints": "within one thickness of a joint face (end faces held rigid)"}
_CHUNK_VALUES = 4_000_000  # bound (samples x nodes) temporaries


# ------------------------------------------------------------------------------------------
# nodal fields
# ------------------------------------------------------------------------------------------
def von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress [Pa] of stress tensors given as their 6 components
    [Pa] in the last axis (order xx, yy, zz, yz, xz, xy)."""
    s = np.asarray(stress, dtype=float)
    xx, yy, zz, yz, xz, xy = (s[..., k] for k in range(6))
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2)
                   + 3.0 * (yz**2 + xz**2 + xy**2))


def _as_coordinates(reduction: Any, modal_coordinates: np.ndarray) -> np.ndarray:
    coordinates = np.atleast_2d(np.asarray(modal_coordinates, dtype=float))
    if coordinates.shape[1] != reduction.n_modal_coordinates:
        raise ValueError(f"modal_coordinates: expected {reduction.n_modal_coordinates} "
                         f"columns, got shape {coordinates.shape}")
    return coordinates


def stress_modes(reduction: Any) -> np.ndarray:
    """The stress modes as an array (nodes, modes, 6) [Pa per unit modal coordinate]."""
    if not reduction.has_stress_modes:
        raise ValueError("this reduction has no stress post-processing modes")
    matrix = np.asarray(reduction.fem.postProcessingModes["matrix"], dtype=float)
    return matrix.reshape(matrix.shape[0], -1, len(COMPONENTS))


def nodal_stress(reduction: Any, modal_coordinates: np.ndarray,
                 nodes: np.ndarray | None = None) -> np.ndarray:
    """Stress components at the mesh nodes [Pa], body axes: shape (samples, nodes, 6) for
    ``modal_coordinates`` of shape (samples, modal coordinates) (or (nodes, 6) for one
    sample). ``nodes``: a subset of node indices (default all)."""
    coordinates = _as_coordinates(reduction, modal_coordinates)
    modes = stress_modes(reduction)
    if nodes is not None:
        modes = modes[nodes]
    stress = np.einsum("sm,nmc->snc", coordinates, modes)
    return stress[0] if np.ndim(modal_coordinates) == 1 else stress


def nodal_displacement(reduction: Any, modal_coordinates: np.ndarray) -> np.ndarray:
    """Elastic displacement of the mesh nodes in the link's frame, ``Phi q`` [m]: shape
    (samples, nodes, 3) (or (nodes, 3) for one sample)."""
    coordinates = _as_coordinates(reduction, modal_coordinates)
    basis = np.asarray(reduction.fem.modeBasis["matrix"], dtype=float)
    displacement = (coordinates @ basis.T).reshape(len(coordinates), -1, 3)
    return displacement[0] if np.ndim(modal_coordinates) == 1 else displacement


def region_nodes(reduction: Any) -> dict[str, np.ndarray]:
    """Node indices of each region of :data:`REGIONS` (by reference x, body coordinates)."""
    x = reduction.fem.GetNodePositionsAsArray()[:, 0]
    away = (x >= reduction.thickness_m) & (x <= reduction.length_m - reduction.thickness_m)
    return {"away": np.flatnonzero(away), "at_joints": np.flatnonzero(~away)}


# ------------------------------------------------------------------------------------------
# peaks
# ------------------------------------------------------------------------------------------
#: the von Mises form: sigma_vm^2 = s^T P s for the stress components s (order xx, yy, zz,
#: yz, xz, xy)
VON_MISES_FORM = np.array([[1.0, -0.5, -0.5, 0.0, 0.0, 0.0], [-0.5, 1.0, -0.5, 0.0, 0.0, 0.0],
                           [-0.5, -0.5, 1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 3.0, 0.0, 0.0],
                           [0.0, 0.0, 0.0, 0.0, 3.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 3.0]])


def von_mises_history(reduction: Any, modal_coordinates: np.ndarray, nodes: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Per sample, the largest von Mises stress over ``nodes`` [Pa] and the node where it
    occurs (a mesh node index): two arrays of shape (samples,).

    The stress is linear in the modal coordinates q, so sigma_vm^2 = q^T A_n q at node n with
    A_n = S_n P S_n^T (S_n: the node's stress modes, P: :data:`VON_MISES_FORM`): one matrix
    product of the samples' q_i q_j (i <= j) with the nodes' A_n entries gives every
    sample's squares at every node (measured 4-5x faster than forming the six components
    and combining them)."""
    coordinates = _as_coordinates(reduction, modal_coordinates)
    nodes = np.asarray(nodes)
    if nodes.size == 0:
        return np.full(len(coordinates), np.nan), np.full(len(coordinates), -1)
    modes = stress_modes(reduction)[nodes]  # (nodes, m, 6)
    forms = np.einsum("nic,cd,njd->nij", modes, VON_MISES_FORM, modes, optimize=True)
    upper_i, upper_j = np.triu_indices(modes.shape[1])
    weights = forms[:, upper_i, upper_j] * np.where(upper_i == upper_j, 1.0, 2.0)
    columns = np.ascontiguousarray(weights.T)  # (pairs, nodes)
    peaks = np.empty(len(coordinates))
    where = np.empty(len(coordinates), dtype=np.int64)
    chunk = max(1, _CHUNK_VALUES // len(nodes))
    for start in range(0, len(coordinates), chunk):
        part = coordinates[start:start + chunk]
        squares = (part[:, upper_i] * part[:, upper_j]) @ columns
        best = np.argmax(squares, axis=1)
        peaks[start:start + chunk] = np.sqrt(np.maximum(squares[np.arange(len(best)), best],
                                                        0.0))
        where[start:start + chunk] = nodes[best]
    return peaks, where


@dataclass
class StressPeak:
    """The largest von Mises stress of a run in one region: value [Pa], time [s], where on
    the plate (reference position of the node, body coordinates [m]) and the node."""

    region: str
    von_mises_Pa: float
    time_s: float
    position_m: np.ndarray
    node: int


def stress_peak(reduction: Any, modal_coordinates: np.ndarray, time_s: np.ndarray,
                region: str) -> StressPeak:
    """The peak of :func:`von_mises_history` over the run in ``region`` (:data:`REGIONS`)."""
    peaks, where = von_mises_history(reduction, modal_coordinates,
                                     region_nodes(reduction)[region])
    sample = int(np.nanargmax(peaks)) if np.any(np.isfinite(peaks)) else 0
    node = int(where[sample])
    position = reduction.fem.GetNodePositionsAsArray()[node] if node >= 0 else np.full(3, np.nan)
    return StressPeak(region, float(peaks[sample]), float(np.asarray(time_s)[sample]),
                      np.asarray(position, dtype=float), node)


def _stored_peak(reduction: Any, modal_coordinates: np.ndarray, time_s: np.ndarray,
                 region: str, peaks: np.ndarray) -> StressPeak:
    """:func:`stress_peak` from the region's stored peak series ``peaks`` [Pa]: the largest
    sample's node found by evaluating that sample alone."""
    peaks = np.asarray(peaks, dtype=float)
    sample = int(np.nanargmax(peaks)) if np.any(np.isfinite(peaks)) else 0
    coordinates = _as_coordinates(reduction, modal_coordinates)[sample:sample + 1]
    _, where = von_mises_history(reduction, coordinates, region_nodes(reduction)[region])
    node = int(where[0])
    position = reduction.fem.GetNodePositionsAsArray()[node] if node >= 0 else np.full(3, np.nan)
    return StressPeak(region, float(peaks[sample]), float(np.asarray(time_s)[sample]),
                      np.asarray(position, dtype=float), node)


def peak_datasets(link: str, reduction: Any, modal_coordinates: np.ndarray
                  ) -> dict[str, Dataset]:
    """The stored peak series of a flexible ``link``: ``<link>/peak_von_mises_stress`` (away
    from the joint faces) and ``<link>/peak_von_mises_stress_at_joints`` [Pa]."""
    nodes = region_nodes(reduction)
    out = {}
    for region, suffix in (("away", ""), ("at_joints", "_at_joints")):
        if nodes[region].size == 0:  # a plate thicker than L/2 has no node away from both
            continue
        peaks, _ = von_mises_history(reduction, modal_coordinates, nodes[region])
        out[f"{link}/peak_von_mises_stress{suffix}"] = Dataset(
            peaks, "Pa", f"largest nodal von Mises stress {REGIONS[region]}")
    return out


def peak_attrs(link: str, reduction: Any, modal_coordinates: np.ndarray,
               time_s: np.ndarray, stored: Mapping[str, Any] | None = None
               ) -> dict[str, Any]:
    """Case attributes of the run's peaks, units in the names: ``<link>_peak_von_mises_Pa``,
    ``_time_s``, ``_position_m`` (x, y, z on the plate, body coordinates) and the same with
    ``_at_joints`` (:data:`REGIONS`). ``stored``: the run's datasets; where they hold a
    region's peak series (:func:`peak_datasets`), only its largest sample is evaluated again
    (for the node), not the whole run."""
    out: dict[str, Any] = {}
    nodes = region_nodes(reduction)
    for region, suffix in (("away", ""), ("at_joints", "_at_joints")):
        if nodes[region].size == 0:
            continue
        series = (stored or {}).get(f"{link}/peak_von_mises_stress{suffix}")
        peak = (stress_peak(reduction, modal_coordinates, time_s, region) if series is None
                else _stored_peak(reduction, modal_coordinates, time_s, region, series.data))
        name = f"{link}_peak_von_mises{suffix}"
        out.update({f"{name}_Pa": peak.von_mises_Pa, f"{name}_time_s": peak.time_s,
                    f"{name}_position_m": peak.position_m})
    return out


# ------------------------------------------------------------------------------------------
# identity of the mode basis
# ------------------------------------------------------------------------------------------
def basis_fingerprint(reduction: Any) -> np.ndarray:
    """Low moments of each mode over the mesh: shape (modes, 16). Per mode: the mean over
    the nodes of each displacement component times 1, x/L, (x/L)^2, y/t, z/w (15 numbers),
    and the mode's root-mean-square size. Insensitive to round-off, sensitive to any other
    change of a mode."""
    positions = reduction.fem.GetNodePositionsAsArray()
    basis = np.asarray(reduction.fem.modeBasis["matrix"], dtype=float)
    fields = basis.reshape(len(positions), 3, -1)  # node, component, mode
    x = positions[:, 0] / reduction.length_m
    weights = np.column_stack([np.ones_like(x), x, x**2,
                               positions[:, 1] / reduction.thickness_m,
                               positions[:, 2] / reduction.width_m])  # node, moment
    moments = np.einsum("ncm,nj->mcj", fields, weights) / len(positions)
    size = np.sqrt(np.mean(fields**2, axis=(0, 1)))
    return np.column_stack([moments.reshape(basis.shape[1], -1), size])


def basis_digest(reduction: Any) -> str:
    """SHA-256 of the mode basis (shape, dtype and bytes): equal for a cache hit."""
    array = np.ascontiguousarray(reduction.fem.modeBasis["matrix"])
    digest = hashlib.sha256(str(array.dtype).encode() + str(array.shape).encode())
    digest.update(array.tobytes())
    return digest.hexdigest()


def basis_identity(link: str, reduction: Any) -> dict[str, Any]:
    """Case attributes naming the reduction a run's ``<link>/modal_coordinates`` belong to:
    ``<link>_reduction_key`` (its cache key), ``_basis_sha256`` and ``_basis_fingerprint``
    (:func:`basis_fingerprint`, shape (modes, 16))."""
    return {f"{link}_reduction_key": reduction.key,
            f"{link}_reduction_basis_sha256": basis_digest(reduction),
            f"{link}_reduction_basis_fingerprint": basis_fingerprint(reduction)}


def check_basis_identity(link: str, reduction: Any, stored: dict[str, Any]) -> str | None:
    """Why ``reduction`` is not the basis of a stored run (``stored``: its case attributes),
    in one sentence; None if it is. An exact digest match, or a fingerprint within
    :data:`FINGERPRINT_RTOL` of the stored one under the same key (a rebuild), is the same
    basis."""
    key = stored.get(f"{link}_reduction_key")
    if key is None:
        return (f"the result stores no identity of the {link}'s mode basis (written before "
                f"flex stored it): its modal coordinates cannot be tied to a basis; rerun "
                f"the case")
    if str(key) != reduction.key:
        return (f"the {link}'s reduction differs from the one the result was computed with "
                f"(cache key {reduction.key}, result {key}: another flex or engine version, "
                f"or other plate, mesh or mode settings); rerun the case with this flex")
    if str(stored.get(f"{link}_reduction_basis_sha256", "")) == basis_digest(reduction):
        return None
    fingerprint = np.asarray(stored.get(f"{link}_reduction_basis_fingerprint", []), float)
    current = basis_fingerprint(reduction)
    if fingerprint.shape == current.shape:
        scale = np.maximum(np.abs(fingerprint).max(axis=1, keepdims=True), 1e-300)
        if np.all(np.abs(current - fingerprint) <= FINGERPRINT_RTOL * scale):
            return None
    return (f"the {link}'s mode basis differs from the one the result was computed with "
            f"(same cache key {key}, but the basis's fingerprint does not match: the basis "
            f"construction changed); rerun the case with this flex")


__all__ = ["COMPONENTS", "FINGERPRINT_RTOL", "REGIONS", "StressPeak", "basis_digest",
           "basis_fingerprint", "basis_identity", "check_basis_identity",
           "nodal_displacement", "nodal_stress", "peak_attrs", "peak_datasets",
           "region_nodes", "stress_modes", "stress_peak", "von_mises", "von_mises_history"]
