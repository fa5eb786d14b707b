"""A meshed plate's mid-span output: the area-weighted mean over the cross-section.

A beam's transverse displacement *is* its section's mean; a 3-D body's section does not stay
straight across the width (anticlastic curl: the centroid deflects ~0.4 nu (w/L)^2 of the
deflection less than the section mean, 0.17-0.18 % on the 80 x t x 10 mm thesis plates), and a
slab of mesh nodes near mid-span is neither (0.01-0.06 % off the mean, moving with the mesh;
docs/references.md). So every body reads its midpoint as the section mean, the quantity a beam
carries and the plate reference (:mod:`flex.bodies.plate_reference`) converges.

:func:`section_mean_weights` gives the mesh nodes and weights whose weighted sum of a nodal
field is that mean, exactly, for the field the tetrahedra interpolate (quadratic where their
mid-edge nodes exist, linear otherwise): each tetrahedron crossing the plane is cut into its
polygon, the polygon into triangles, and each triangle integrated with the three-point
edge-midpoint rule (exact for quadratics, which the shape functions are on a plane). The
weights sum to 1 and put the weighted reference position at the section's centroid; an
Exudyn ``MarkerSuperElementPosition`` with them reads the section mean of the displacement.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

#: a plane through a node within this fraction of the plate's size counts as through it
PLANE_TOLERANCE = 1e-9
_EDGES = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


def _midpoint_nodes(positions: np.ndarray, tets: np.ndarray, scale: float
                    ) -> dict[tuple[int, int], int]:
    """Each edge's mid-edge node of the tetrahedra ``tets`` (quadratic tetrahedra; none for
    linear ones), found by position."""
    x = positions[tets, 0]  # a mid-edge node lies within its tetrahedra's span
    nearby = np.flatnonzero((positions[:, 0] >= x.min() - 1e-9 * scale)
                            & (positions[:, 0] <= x.max() + 1e-9 * scale))
    keys = np.round(positions[nearby] / scale, 7)
    index = {tuple(key): int(node) for node, key in zip(nearby, keys, strict=True)}
    out = {}
    for tet in tets:
        for i, j in _EDGES:
            a, b = sorted((int(tet[i]), int(tet[j])))
            found = index.get(tuple(np.round(0.5 * (positions[a] + positions[b]) / scale, 7)))
            if found is not None and found not in (a, b):
                out[(a, b)] = found
    return out


def _polygon(corners: np.ndarray, x_m: float, tolerance: float) -> np.ndarray | None:
    """The tetrahedron's section with the plane x = ``x_m`` as ordered points (None: none,
    or a face in the plane owned by the tetrahedron on the other side)."""
    side = corners[:, 0] - x_m
    on = np.abs(side) <= tolerance
    if on.sum() == 3:  # a face in the plane: the tetrahedron behind it (x > x_m) owns it
        return corners[on] if side[~on][0] > 0 else None
    if not (side.min() < -tolerance and side.max() > tolerance):
        return None
    points = [corners[k] for k in np.flatnonzero(on)]
    for i, j in _EDGES:
        if (side[i] < -tolerance and side[j] > tolerance) or \
                (side[i] > tolerance and side[j] < -tolerance):
            points.append(corners[i] + side[i] / (side[i] - side[j]) * (corners[j] - corners[i]))
    points = np.asarray(points)
    centre = points.mean(axis=0)
    order = np.argsort(np.arctan2(points[:, 2] - centre[2], points[:, 1] - centre[1]))
    return points[order]


def _shape(corners: np.ndarray, point: np.ndarray, quadratic: bool) -> np.ndarray:
    """The tetrahedron's shape functions at ``point``: the four vertices', then the six
    edges' (quadratic: ``L_i (2 L_i - 1)`` and ``4 L_i L_j``; linear: the ``L_i``)."""
    matrix = np.vstack([corners.T, np.ones(4)])
    barycentric = np.linalg.solve(matrix, np.append(point, 1.0))
    if not quadratic:
        return barycentric
    vertex = barycentric * (2.0 * barycentric - 1.0)
    edge = [4.0 * barycentric[i] * barycentric[j] for i, j in _EDGES]
    return np.concatenate([vertex, edge])


def section_mean_weights(positions: np.ndarray, tets: Iterable[Iterable[int]], x_m: float
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights (summing to 1) of the area-weighted mean over the cross-section
    x = ``x_m`` [m] of a field the tetrahedra ``tets`` (corner node numbers) interpolate on
    the nodes at ``positions`` [m] (see the module doc). ValueError when the plane cuts no
    element."""
    positions = np.asarray(positions, dtype=float)
    tets = np.asarray(list(map(list, tets)), dtype=np.int64)
    scale = float(np.max(np.ptp(positions, axis=0)))
    x = positions[tets, 0]  # only the tetrahedra the plane may cut
    near = PLANE_TOLERANCE * scale
    tets = tets[(x.min(axis=1) <= x_m + near) & (x.max(axis=1) >= x_m - near)]
    midpoints = _midpoint_nodes(positions, tets, scale)
    weights: dict[int, float] = {}
    area = 0.0
    for tet in tets:
        corners = positions[tet]
        polygon = _polygon(corners, x_m, PLANE_TOLERANCE * scale)
        if polygon is None:
            continue
        edge_nodes = [midpoints.get(tuple(sorted((int(tet[i]), int(tet[j]))))) for i, j in _EDGES]
        quadratic = all(node is not None for node in edge_nodes)
        nodes = [*map(int, tet), *(edge_nodes if quadratic else [])]
        for k in range(1, len(polygon) - 1):
            triangle = polygon[[0, k, k + 1]]
            part = 0.5 * np.linalg.norm(np.cross(triangle[1] - triangle[0],
                                                 triangle[2] - triangle[0]))
            area += part
            for a, b in ((0, 1), (1, 2), (2, 0)):
                shape = _shape(corners, 0.5 * (triangle[a] + triangle[b]), quadratic)
                for node, value in zip(nodes, shape, strict=True):
                    weights[node] = weights.get(node, 0.0) + part / 3.0 * value
    if area <= 0.0:
        raise ValueError(f"the plane x = {x_m:g} m cuts no element of the mesh")
    nodes = np.array(sorted(weights), dtype=np.int64)
    values = np.array([weights[node] for node in nodes]) / area
    keep = np.abs(values) > 1e-14  # nodes whose shape functions vanish on the section
    return nodes[keep], values[keep] / values[keep].sum()


def fem_tetrahedra(fem) -> np.ndarray:
    """The corner node numbers of an Exudyn ``FEMinterface``'s tetrahedra (its ``Tet4``
    blocks; a ``Tet10`` block's first four columns)."""
    blocks = [np.asarray(block[kind])[:, :4] for block in fem.elements
              for kind in ("Tet4", "Tet10") if kind in block]
    if not blocks:
        raise ValueError("the mesh holds no tetrahedra")
    return np.vstack(blocks)


__all__ = ["fem_tetrahedra", "section_mean_weights"]
