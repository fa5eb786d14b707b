"""Rectangular plate links meshed with NGsolve/netgen (OCC geometry).

Coordinates of the mesh (metres): x along the link from joint end ``end_a`` (x = 0) to
``end_b`` (x = length), y across the thickness (in the mechanism plane, the bending height),
z across the width (out of the mechanism plane). The origin is the centre of ``end_a``.
"""

from __future__ import annotations

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
