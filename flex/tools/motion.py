"""The motion of a stored case, body by body and node by node: what ``flex export`` writes
and ``flex animate`` draws.

:func:`case_motion` reads one case of a result file and rebuilds what its bodies need:

- an FFRF link (coupler or crank): its plate mesh from the reduction (from the cache, rebuilt
  if missing: :func:`flex.dynamics.solver.reduction_for_scene` with the case's stored
  scene), refused unless it is the basis the run's modal coordinates were computed with
  (:func:`flex.bodies.stress.check_basis_identity`); per sample the nodal elastic
  displacement in the link's (floating) frame ``Phi q``, the nodes placed in the mechanism
  by the stored frame pose (``<link>/frame_position``, ``frame_angle``) and the nodal stress
  from the stress modes (body axes);
- the nonlinear FE coupler: its mesh (:func:`flex.bodies.nonlinear.nonlinear_plate_for_scene`)
  and the stored nodal positions (``coupler/nodal/position`` at ``coupler/nodal/time``); its
  link frame is the chord frame (origin at the joint-B face centre, x toward the joint-C
  face centre); no stress is recovered for it;
- rigid links and the slider: boxes (a rigid link's plate sizes; the slider a nominal block
  0.25 x 0.12 coupler lengths) moved with the stored angles and joint positions: A at the
  origin, B = A + |AB| (cos, sin)(crank angle), C = B + |BC| (cos, sin)(coupler angle).

Coordinates: mechanism frame x, y in the plane, z normal to it [m]; body coordinates of a
plate as in :mod:`flex.bodies.reduction` (x from the joint-B face along the link, y across
the thickness, z across the width).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError
from flex.data.results import case_names, reading
from flex.data.scene import LINKS, Scene, default_scene, merge
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, FFRF, NONLINEAR_FE, RIGID, LinkModel

#: VTK/XDMF order of a quadratic tetrahedron's mid-edge nodes (corner pairs)
TET10_EDGES = ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))
#: the slider block's length and height as fractions of the coupler length (drawing only)
SLIDER_BLOCK = (0.25, 0.12)


@dataclass
class Body:
    """One body of the mechanism as a tetrahedral mesh: ``reference_m`` (nodes, 3) in body
    coordinates [m], ``cells`` (cells, 10) quadratic tetrahedra (node indices, VTK order),
    ``corners`` (cells, 4) their corner nodes."""

    name: str
    model: str  #: the name of its link model (the slider: the rigid model's)
    reference_m: np.ndarray
    cells: np.ndarray
    corners: np.ndarray
    has_stress: bool = False
    facts: dict[str, Any] = field(default_factory=dict)  #: provenance (reduction key, ...)
    #: how its motion is stored (its model's ``stored_motion``: rigid, modal, nodal)
    kind: str = "rigid"


@dataclass
class BodyState:
    """A body at one sample: global node positions [m] (nodes, 3), elastic displacement in
    its link frame [m] (nodes, 3; zero for a rigid body) and, for an FFRF link, the nodal
    stress [Pa] (nodes, 6; body axes; None otherwise)."""

    position_m: np.ndarray
    elastic_m: np.ndarray
    stress_Pa: np.ndarray | None


class CaseMotion:
    """The bodies of one stored case and their state at its samples (see the module doc)."""

    def __init__(self, source: Path, case: str, scene: Scene, data: dict[str, np.ndarray],
                 attrs: dict[str, Any], bodies: list[Body], extra: dict[str, Any]) -> None:
        self.source, self.case, self.scene = source, case, scene
        self._data, self.attrs, self.bodies, self._extra = data, attrs, bodies, extra
        nodal = data.get("coupler/nodal/time")
        case_time = data["time"]
        if nodal is not None:  # the nonlinear FE coupler's snapshots govern
            self.time_s = np.asarray(nodal, dtype=float)
            spacing = float(np.min(np.diff(case_time))) if len(case_time) > 1 else 1.0
            self.sample = np.clip(np.searchsorted(case_time, self.time_s - 1e-6 * spacing),
                                  0, len(case_time) - 1)
        else:
            self.time_s = np.asarray(case_time, dtype=float)
            self.sample = np.arange(len(case_time))

    def link_model(self, link: str) -> Any:
        """The reduction (FFRF) or the meshed plate (nonlinear FE) of a flexible ``link``."""
        return self._extra[link]

    @property
    def flexible(self) -> list[Body]:
        """The flexible bodies."""
        return [body for body in self.bodies if body.kind != "rigid"]

    def crank_angle_rad(self, index: int) -> float:
        """The crank angle (chord A-B for a flexible crank) at motion sample ``index``."""
        return float(self._data["crank/angle"][self.sample[index]])

    def joints(self, index: int) -> dict[str, np.ndarray]:
        """Joint centres A, B, C at motion sample ``index`` [m] (x, y)."""
        d, s = self._data, self.sample[index]

        def chord(link: str) -> float:  # |AB| or |BC|: the length plus its stretch
            stretch = d.get(f"{link}/chord_change")
            return self.scene[link]["length_m"] + (0.0 if stretch is None else float(stretch[s]))

        b = _along(d["crank/angle"][s], chord("crank"))
        c = b + _along(d["coupler/angle"][s], chord("coupler"))
        return {"A": np.zeros(2), "B": b, "C": c}

    def states(self, index: int) -> dict[str, BodyState]:
        """Every body's :class:`BodyState` at motion sample ``index``."""
        return {body.name: self._state(body, index) for body in self.bodies}

    def _state(self, body: Body, index: int) -> BodyState:
        d, s = self._data, self.sample[index]
        if body.kind == "modal":  # a reduction's modal coordinates in its floating frame
            reduction = self._extra[body.name]
            from flex.bodies.stress import nodal_displacement, nodal_stress

            q = d[f"{body.name}/modal_coordinates"][s]
            elastic = nodal_displacement(reduction, q)
            position = _place(body.reference_m + elastic, d[f"{body.name}/frame_position"][s],
                              d[f"{body.name}/frame_angle"][s])
            stress = nodal_stress(reduction, q) if body.has_stress else None
            return BodyState(position, elastic, stress)
        if body.kind == "nodal":  # every node of the mesh (the nonlinear FE coupler)
            position = np.asarray(d[f"{body.name}/nodal/position"][index], dtype=float)
            plate = self._extra[body.name]
            b = plate.weights_end_a @ position[plate.nodes_end_a]
            c = plate.weights_end_b @ position[plate.nodes_end_b]
            angle = math.atan2(c[1] - b[1], c[0] - b[0])
            local = _place(position - b, np.zeros(2), -angle)  # turned back into the chord frame
            return BodyState(position, local - body.reference_m, None)
        joints = self.joints(index)
        if body.name == "slider":
            origin, angle = joints["C"], 0.0
        elif body.name == "crank":
            origin, angle = joints["A"], d["crank/angle"][s]
        else:
            origin, angle = joints["B"], d["coupler/angle"][s]
        return BodyState(_place(body.reference_m, origin, angle),
                         np.zeros_like(body.reference_m), None)


def _along(angle_rad: float, length_m: float) -> np.ndarray:
    return length_m * np.array([math.cos(angle_rad), math.sin(angle_rad)])


def _place(points_m: np.ndarray, origin_m: np.ndarray, angle_rad: float) -> np.ndarray:
    """Body points turned by ``angle_rad`` about z and moved to ``origin_m`` (x, y) [m]."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    out = np.array(points_m, dtype=float)
    out[:, 0] = c * points_m[:, 0] - s * points_m[:, 1] + origin_m[0]
    out[:, 1] = s * points_m[:, 0] + c * points_m[:, 1] + origin_m[1]
    return out


# ------------------------------------------------------------------------------------------
# meshes
# ------------------------------------------------------------------------------------------
def tet10_cells(corners: np.ndarray, positions_m: np.ndarray) -> np.ndarray:
    """Quadratic tetrahedra (VTK node order) from corner tetrahedra of a second-order mesh
    whose mid-edge nodes lie at the edge midpoints (straight edges: a plate box), oriented
    positively; raises ValueError when a midpoint has no node."""
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
    """A box x in [0, length] (or centred on 0), y and z centred, as 5 tetrahedra: node
    positions (8 corners) and the corner cells (5, 4)."""
    x0 = -length_m / 2 if centred else 0.0
    corners = np.array([[x0 + i * length_m, (j - 0.5) * height_m, (k - 0.5) * width_m]
                        for k in (0, 1) for j in (0, 1) for i in (0, 1)])
    # corner i + 2 j + 4 k at (x_i, y_j, z_k): four corner tetrahedra and the middle one
    cells = np.array([[0, 1, 2, 4], [3, 1, 2, 7], [5, 1, 4, 7], [6, 2, 4, 7], [1, 2, 4, 7]])
    return corners, cells


def _quadratic_box(length_m: float, height_m: float, width_m: float, centred: bool
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`box_mesh` with mid-edge nodes: positions, Tet10 cells, corner cells."""
    points, corners = box_mesh(length_m, height_m, width_m, centred)
    edges = sorted({tuple(sorted((int(c[a]), int(c[b])))) for c in corners
                    for a, b in TET10_EDGES})
    points = np.vstack([points, [(points[a] + points[b]) / 2 for a, b in edges]])
    return points, tet10_cells(corners, points), corners


def _top_faces(corners: np.ndarray, reference_m: np.ndarray) -> np.ndarray:
    """Boundary triangles (corner nodes) of a tetrahedral mesh that lie in its top face
    (z = max z): what a view from +z sees of a plate."""
    faces = np.sort(corners[:, [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]].reshape(-1, 3),
                    axis=1)
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    boundary = unique[counts == 1]
    z = reference_m[:, 2]
    top = np.all(np.abs(z[boundary] - z.max()) <= 1e-9 * np.ptp(reference_m, axis=0).max(),
                 axis=1)
    return boundary[top]


def top_faces(body: Body) -> np.ndarray:
    """:func:`_top_faces` of a body (triangles of corner nodes)."""
    return _top_faces(body.corners, body.reference_m)


# ------------------------------------------------------------------------------------------
# reading a case
# ------------------------------------------------------------------------------------------
def pick_case(path: str | Path, case: str | None) -> str:
    """``case``, checked against the file; None picks the file's only case (else refused,
    naming the cases)."""
    with reading(path) as h5:
        names = case_names(h5)
    if case is None:
        if len(names) == 1:
            return names[0]
        raise FlexError(f"result file '{path}' has {len(names)} cases: name one "
                        f"({', '.join(names) or 'none'})")
    if case not in names:
        raise FlexError(f"result file '{path}' has no case '{case}' (cases: "
                        f"{', '.join(names) or 'none'})")
    return case


def _read_case(path: Path, case: str) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    from flex.data.results import attribute_value

    with reading(path) as h5:
        group = h5[f"cases/{case}"]
        attrs = {key: attribute_value(value) for key, value in group.attrs.items()}
        data: dict[str, np.ndarray] = {}
        group.visititems(lambda name, obj: data.__setitem__(name, obj[()])
                         if hasattr(obj, "shape") else None)
    return data, attrs


def case_scene(attrs: dict[str, Any], where: str) -> Scene:
    """The resolved scene a case ran (its ``scene_toml`` attribute, over the defaults)."""
    try:
        return merge(default_scene(), tomllib.loads(str(attrs.get("scene_toml", ""))))
    except (tomllib.TOMLDecodeError, ValueError) as exc:
        raise FlexError(f"{where}: its scene_toml is not a readable scene ({exc})") from None


def model_entry(name: str, where: str = "",
                link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> LinkModel:
    """The entry of link model ``name`` in ``link_models`` (its ``stored_motion`` says how
    its stored motion is read): a model not in the registry is refused (FlexError)."""
    if name not in link_models:
        raise FlexError(f"{where or 'a body'}: link model {name!r} is not in the registry of "
                        f"link models; accepted: {', '.join(link_models)}")
    return link_models[name]


def case_motion(path: str | Path, case: str | None = None, *,
                cache_dir: Path | None = None,
                link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> CaseMotion:
    """The :class:`CaseMotion` of ``case`` (None: the file's only case) of result file
    ``path``. ``cache_dir``: the reduction cache folder (None: built in memory);
    ``link_models``: the registry the case's link models are read from (each entry's
    ``stored_motion`` says how its motion is read back). Refused
    (:class:`FlexError`, one line) for a failed case, a case without a flexible link, a
    reduction that is not the run's basis, or a nonlinear FE case without its nodal field."""
    path = Path(path)
    case = pick_case(path, case)
    where = f"result file '{path}', case '{case}'"
    data, attrs = _read_case(path, case)
    if attrs.get("status") != "ok":
        raise FlexError(f"{where} failed ({attrs.get('message', '')}): nothing to export")
    scene = case_scene(attrs, where)
    models = {link: model_entry(scene[link]["model"], where, link_models)
              for link in LINKS}
    if all(model.stored_motion == "rigid" for model in models.values()):
        raise FlexError(f"{where} has no flexible link (crank and coupler rigid): flex export "
                        f"and animate show FFRF and nonlinear FE links")
    unread = [f"the {model.label} {link}" for link, model in models.items()
              if model.stored_motion == "none"]
    if unread:
        raise FlexError(f"{where}: {' and '.join(unread)} stores no motion that flex export "
                        f"and animate read back (they show FFRF and nonlinear FE links)")
    bodies, extra = [], {}
    for link, model in models.items():
        if model.stored_motion == "modal":
            body, extra[link] = _ffrf_body(link, scene, data, attrs, where, cache_dir)
        elif model.stored_motion == "nodal":
            body, extra[link] = _nonlinear_body(scene, data, where)
        else:
            body = _rigid_body(link, scene)
        bodies.append(replace(body, model=model.name))
    bodies.append(_slider_body(scene))
    return CaseMotion(path, case, scene, data, attrs, bodies, extra)


def _ffrf_body(link: str, scene: Scene, data: dict[str, np.ndarray], attrs: dict[str, Any],
               where: str, cache_dir: Path | None) -> tuple[Body, Any]:
    from flex.bodies.stress import check_basis_identity
    from flex.dynamics.solver import reduction_for_scene

    missing = [name for name in ("modal_coordinates", "frame_position", "frame_angle")
               if f"{link}/{name}" not in data]
    if missing:
        raise FlexError(f"{where}: the FFRF {link} has no {', '.join(missing)} (written "
                        f"before flex stored them): rerun the case")
    reduction = reduction_for_scene(scene, link, cache_dir=cache_dir)
    problem = check_basis_identity(link, reduction, attrs)
    if problem:
        raise FlexError(f"{where}: {problem}")
    found = np.shape(data[f"{link}/modal_coordinates"])
    if len(found) != 2 or found[1] != reduction.n_modal_coordinates:
        raise FlexError(f"{where}: {link}/modal_coordinates has shape {found}, expected "
                        f"(samples, {reduction.n_modal_coordinates}): one column per mode of "
                        f"the reduction; the file was changed after flex wrote it: rerun the "
                        f"case")
    positions = reduction.fem.GetNodePositionsAsArray()
    corners = np.asarray(reduction.fem.elements[0]["Tet4"], dtype=np.int64)
    body = Body(link, FFRF, positions, tet10_cells(corners, positions), corners,
                has_stress=reduction.has_stress_modes,
                facts={"reduction_key": reduction.key, "from_cache": reduction.from_cache},
                kind="modal")
    return body, reduction


def _nonlinear_body(scene: Scene, data: dict[str, np.ndarray], where: str
                    ) -> tuple[Body, Any]:
    from flex.bodies.nonlinear import nonlinear_plate_for_scene

    if "coupler/nodal/position" not in data:
        raise FlexError(f"{where}: the nonlinear FE coupler has no nodal field "
                        f"(coupler/nodal/position: written before flex stored it): rerun "
                        f"the case")
    plate = nonlinear_plate_for_scene(scene)
    if data["coupler/nodal/position"].shape[1] != plate.n_nodes:
        raise FlexError(f"{where}: the stored nodal field has "
                        f"{data['coupler/nodal/position'].shape[1]} nodes, the plate's mesh "
                        f"{plate.n_nodes} (another netgen version?): rerun the case")
    corners = np.array([[v.nr - 1 for v in element.vertices]
                        for element in plate.mesh.ngmesh.Elements3D()], dtype=np.int64)
    positions = plate.node_positions_m
    return Body("coupler", NONLINEAR_FE, positions, tet10_cells(corners, positions),
                corners, kind="nodal"), plate


def _rigid_body(link: str, scene: Scene) -> Body:
    values = scene[link]
    points, cells, corners = _quadratic_box(values["length_m"], values["thickness_m"],
                                            values["width_m"], centred=False)
    return Body(link, RIGID, points, cells, corners)


def _slider_body(scene: Scene) -> Body:
    length = scene["coupler"]["length_m"]
    points, cells, corners = _quadratic_box(SLIDER_BLOCK[0] * length, SLIDER_BLOCK[1] * length,
                                            scene["coupler"]["width_m"], centred=True)
    return Body("slider", RIGID, points, cells, corners)


def sample_indices(count: int, every: int) -> np.ndarray:
    """Every ``every``-th of ``count`` samples, the last one always included."""
    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise FlexError(f"--every {every!r}: must be an integer >= 1")
    indices = np.arange(0, count, every)
    return indices if indices[-1] == count - 1 else np.append(indices, count - 1)
