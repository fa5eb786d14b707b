"""Rectangular plate links meshed with NGsolve/netgen (OCC geometry).

Coordinates of the mesh (metres): x along the link from joint end ``end_a`` (x = 0) to
``end_b`` (x = length), y across the thickness (in the mechanism plane, the bending height),
z across the width (out of the mechanism plane). The origin is the centre of ``end_a``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flex.base.errors import SceneError


def plate_mesh(length_m: float, thickness_m: float, width_m: float, mesh_size_m: float):
    """Return an ``ngsolve.Mesh`` of the plate with end faces named ``end_a`` and ``end_b``.

    All sizes in metres; ``mesh_size_m`` is netgen's ``maxh``. The faces are flat, so
    the mesh needs no curving even for second-order elements.
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
    mesh = ngs.Mesh(OCCGeometry(box).GenerateMesh(maxh=mesh_size_m))
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
