"""Rectangular plate links meshed with NGsolve/netgen (OCC geometry).

Coordinates of the mesh (metres): x along the link from joint end ``end_a`` (x = 0) to
``end_b`` (x = length), y across the thickness (in the mechanism plane, the bending height),
z across the width (out of the mechanism plane). The origin is the centre of ``end_a``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import Plate


def plate_mesh(length_m: float, thickness_m: float, width_m: float, mesh_size_m: float):
    """Return an ``ngsolve.Mesh`` of the plate with end faces named ``end_a`` and ``end_b``.

    All sizes in metres; ``mesh_size_m`` is netgen's ``maxh``. The faces are flat, so
    the mesh needs no curving even for second-order elements. Meshed serially
    (``parallel_meshing=False``): the same mesh, node for node, as netgen's default parallel
    meshing, whose threads spun for up to ~2 s of CPU in its 3D optimisation whatever the
    mesh's size (measured on 9 plates 0.5-10 mm thick, maxh 1-5 mm: 0.04-0.8 s serial against
    0.6-2.3 s; a bimodal 0.1 or ~2 s for the same 439 tetrahedra).
    """
    for name, value in (("length_m", length_m), ("thickness_m", thickness_m),
                        ("width_m", width_m), ("mesh_size_m", mesh_size_m)):
        if not value > 0:
            raise SceneError(f"plate {name} = {value!r}: must be a positive number of metres")
    import ngsolve as ngs
    from netgen.occ import Box, OCCGeometry, Pnt, X

    box = Box(Pnt(0.0, -thickness_m / 2, -width_m / 2),
              Pnt(length_m, thickness_m / 2, width_m / 2))
    box.faces.Min(X).name = "end_a"
    box.faces.Max(X).name = "end_b"
    mesh = ngs.Mesh(OCCGeometry(box).GenerateMesh(maxh=mesh_size_m, parallel_meshing=False))
    return mesh


@dataclass
class PlateLink:
    """A meshed plate link: its sizes [m] and material, and the node sets of its two joint
    faces (``end_a``, ``end_b``) and its mid-length slab (``mid``): mesh node indices and
    weights summing to 1, ``centre_*`` their weighted reference positions in body
    coordinates [m]. The FFRF reduction and the nonlinear FE plate extend it."""

    length_m: float
    thickness_m: float
    width_m: float
    youngs_modulus_Pa: float
    density_kg_per_m3: float
    poisson_ratio: float
    mesh_size_m: float
    nodes_end_a: np.ndarray
    weights_end_a: np.ndarray
    nodes_end_b: np.ndarray
    weights_end_b: np.ndarray
    nodes_mid: np.ndarray
    weights_mid: np.ndarray
    centre_end_a: np.ndarray
    centre_end_b: np.ndarray
    centre_mid: np.ndarray

    @property
    def plate(self) -> Plate:
        """Its geometry and material as one :class:`~flex.base.physics.Plate`."""
        return Plate(self.length_m, self.thickness_m, self.width_m, self.youngs_modulus_Pa,
                     self.density_kg_per_m3, self.poisson_ratio)


# ------------------------------------------------------------------------------------------
# quadratic tetrahedra of a plate (what export and animate draw)
# ------------------------------------------------------------------------------------------
#: VTK/XDMF order of a quadratic tetrahedron's mid-edge nodes (corner pairs)
TET10_EDGES = ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))


def tet10_cells(corners: np.ndarray, positions_m: np.ndarray) -> np.ndarray:
    """Quadratic tetrahedra (VTK node order) from corner tetrahedra of a second-order mesh
    whose mid-edge nodes lie at the edge midpoints (straight edges: a plate box), oriented
    positively; ``positions_m`` the node positions [m]; raises ValueError when a midpoint has
    no node."""
    from scipy.spatial import cKDTree

    corners = np.array(corners, dtype=np.int64)
    p = positions_m[corners]
    volume = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                       p[:, 3] - p[:, 0])
    corners[volume < 0] = corners[volume < 0][:, [0, 2, 1, 3]]
    midpoints = np.stack([(positions_m[corners[:, a]] + positions_m[corners[:, b]]) / 2
                          for a, b in TET10_EDGES], axis=1)
    distance, nodes = cKDTree(positions_m).query(midpoints.reshape(-1, 3))
    if np.max(distance) > 1e-9 * np.ptp(positions_m, axis=0).max():
        raise ValueError("the mesh has a curved or missing mid-edge node")
    return np.hstack([corners, nodes.reshape(-1, 6)])


def box_mesh(length_m: float, height_m: float, width_m: float, centred: bool = False
             ) -> tuple[np.ndarray, np.ndarray]:
    """A box x in [0, length] (or centred on 0), y and z centred (sizes [m]), as 5
    tetrahedra: node positions [m] (8 corners) and the corner cells (5, 4)."""
    x0 = -length_m / 2 if centred else 0.0
    corners = np.array([[x0 + i * length_m, (j - 0.5) * height_m, (k - 0.5) * width_m]
                        for k in (0, 1) for j in (0, 1) for i in (0, 1)])
    # corner i + 2 j + 4 k at (x_i, y_j, z_k): four corner tetrahedra and the middle one
    cells = np.array([[0, 1, 2, 4], [3, 1, 2, 7], [5, 1, 4, 7], [6, 2, 4, 7], [1, 2, 4, 7]])
    return corners, cells


def quadratic_box(length_m: float, height_m: float, width_m: float, centred: bool
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`box_mesh` with mid-edge nodes: positions [m], Tet10 cells, corner cells."""
    points, corners = box_mesh(length_m, height_m, width_m, centred)
    edges = sorted({tuple(sorted((int(c[a]), int(c[b])))) for c in corners
                    for a, b in TET10_EDGES})
    points = np.vstack([points, [(points[a] + points[b]) / 2 for a, b in edges]])
    return points, tet10_cells(corners, points), corners
