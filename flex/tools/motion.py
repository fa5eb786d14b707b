"""The motion of a stored case, body by body and node by node: what ``flex export`` writes
and ``flex animate`` draws.

:func:`case_motion` reads one case of a result file and rebuilds what its bodies need, each
link through its model's reader of stored motion (the registry entry's ``stored_motion``,
:class:`flex.dynamics.link_outputs.MotionReader`; the built-in readers there):

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
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError
from flex.bodies.plate import quadratic_box
from flex.data.results import case_names, reading
from flex.data.scene import LINKS, Scene, default_scene, merge
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, RIGID, LinkModel
from flex.dynamics.link_outputs import RIGID_MOTION, Body, BodyState, MotionReader

__all__ = ["Body", "BodyState", "CaseMotion", "case_motion", "case_scene", "model_entry",
           "motion_problem",
           "pick_case", "sample_indices", "top_faces", "SLIDER_BLOCK"]

#: the slider block's length and height as fractions of the coupler length (drawing only)
SLIDER_BLOCK = (0.25, 0.12)


class CaseMotion:
    """The bodies of one stored case and their state at its samples (see the module doc)."""

    def __init__(self, source: Path, case: str, scene: Scene, data: dict[str, np.ndarray],
                 attrs: dict[str, Any], bodies: list[Body], extra: dict[str, Any],
                 readers: Mapping[str, MotionReader] | None = None) -> None:
        self.source, self.case, self.scene = source, case, scene
        self._data, self.attrs, self.bodies, self._extra = data, attrs, bodies, extra
        #: each body's reader of stored motion, by body name (absent: the rigid one's)
        self._readers = dict(readers or {})
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
        """The body's state through its link model's reader of stored motion (the slider:
        the rigid one's)."""
        d, s = self._data, self.sample[index]

        def frame() -> tuple[np.ndarray, float]:  # the rigid frame: origin at its first joint
            joints = self.joints(index)
            if body.name == "slider":
                return joints["C"], 0.0
            if body.name == "crank":
                return joints["A"], float(d["crank/angle"][s])
            return joints["B"], float(d["coupler/angle"][s])

        reader = self._readers.get(body.name, RIGID_MOTION)
        return reader.state(body, self._extra.get(body.name), d, s, index, frame)


def _along(angle_rad: float, length_m: float) -> np.ndarray:
    return length_m * np.array([math.cos(angle_rad), math.sin(angle_rad)])


# ------------------------------------------------------------------------------------------
# meshes
# ------------------------------------------------------------------------------------------
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
    _check_motion(data, where)
    scene = case_scene(attrs, where)
    models = {link: model_entry(scene[link]["model"], where, link_models)
              for link in LINKS}
    readers = {link: model.stored_motion for link, model in models.items()}
    problem = motion_problem(scene, link_models)
    if problem:
        raise FlexError(f"{where}: {problem}")
    bodies, extra = [], {}
    for link, reader in readers.items():
        body, extra[link] = reader.body(link, scene, data, attrs, where, cache_dir)
        bodies.append(replace(body, model=models[link].name))
    bodies.append(_slider_body(scene))
    return CaseMotion(path, case, scene, data, attrs, bodies, extra, readers)


def motion_problem(scene: Scene,
                   link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> str:
    """Why a case of ``scene`` cannot be exported or animated ("" when it can, or may: a
    link whose model ``auto`` decides at run time, or one not in ``link_models``): both
    links rigid, or a flexible link whose model stores no motion that export and animate
    read back (an exact beam)."""
    models = [scene[link]["model"] for link in LINKS]
    if any(model not in link_models for model in models):
        return ""
    entries = {link: link_models[model] for link, model in zip(LINKS, models, strict=True)}
    readers = {link: entry.stored_motion for link, entry in entries.items()}
    if all(reader.kind == RIGID_MOTION.kind for reader in readers.values()):
        return ("no flexible link (crank and coupler rigid): flex export and animate show "
                "FFRF and nonlinear FE links")
    unread = [f"the {entries[link].label} {link}" for link, reader in readers.items()
              if reader.body is None or reader.state is None]
    if unread:
        return (f"{' and '.join(unread)} stores no motion that flex export and animate read "
                f"back (they show FFRF and nonlinear FE links)")
    return ""


#: the stored series every case's motion is drawn from (a link model's own are checked by
#: the dimensions of :data:`MOTION_SHAPES` when present; its reader says which it needs)
MOTION_SERIES = ("time", "crank/angle", "coupler/angle")
#: series a motion is drawn from, by the end of their name: their dimensions, samples first
#: (0: any; the reader checks the columns against the reduction)
MOTION_SHAPES = {"time": 1, "/angle": 1, "/chord_change": 1, "/frame_angle": 1,
                 "/frame_position": 2, "/modal_coordinates": 0, "/nodal/time": 1,
                 "/nodal/position": 3}


def _check_motion(data: dict[str, np.ndarray], where: str) -> None:
    """Refuse (FlexError, one line) a case whose :data:`MOTION_SERIES` are missing, or whose
    series of :data:`MOTION_SHAPES` are not finite numbers, one row per stored time (per
    nodal snapshot under ``nodal/``), of their dimensions: a file edited or damaged stopped
    export and animate on ``KeyError: 'time'`` or a broadcasting error, as internal errors."""
    for name in MOTION_SERIES:
        if name not in data:
            raise FlexError(f"{where} has no dataset '{name}' (every flex run stores it: the "
                            f"file was edited or damaged): rerun the case")
    for name, values in data.items():
        ndim = next((n for end, n in MOTION_SHAPES.items() if name.endswith(end)), -1)
        if ndim < 0:
            continue
        rows = np.shape(data.get(name.split("nodal/")[0] + "nodal/time" if "nodal/" in name
                                 else "time"))[:1]
        values = np.asarray(values)
        if (values.ndim != (ndim or max(values.ndim, 1)) or values.shape[:1] != rows
                or values.size == 0 or values.dtype.kind not in "iuf"
                or not np.isfinite(values).all()):
            raise FlexError(f"{where}: dataset '{name}' is not {ndim or 'an array of'}"
                            f"{'-dimensional' if ndim else ''} finite "
                            f"numbers with one row per stored time (shape {values.shape}, "
                            f"{values.dtype}; rows expected: {rows[0] if rows else '?'}): the "
                            f"file was edited or damaged, rerun the case")
    if np.any(np.diff(data["time"]) < 0):
        raise FlexError(f"{where}: its time is not in order (the file was edited or damaged): "
                        f"rerun the case")


def _slider_body(scene: Scene) -> Body:
    length = scene["coupler"]["length_m"]
    points, cells, corners = quadratic_box(SLIDER_BLOCK[0] * length, SLIDER_BLOCK[1] * length,
                                           scene["coupler"]["width_m"], centred=True)
    return Body("slider", RIGID, points, cells, corners)


def sample_indices(count: int, every: int) -> np.ndarray:
    """Every ``every``-th of ``count`` samples, the last one always included."""
    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise FlexError(f"--every {every!r}: must be an integer >= 1")
    indices = np.arange(0, count, every)
    return indices if indices[-1] == count - 1 else np.append(indices, count - 1)
