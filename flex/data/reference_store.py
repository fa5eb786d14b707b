"""Stored references: converged headline values and curves of a scene's physics, made once.

``make references`` (:mod:`studies.references`) computes each reference scene once, converged
in its knobs, and ``make references-install`` writes them to the bundled store
(:func:`bundled_store`, ``flex/data/references.h5``, committed): the studies that judge flex's
error estimates read their truths here instead of computing a reference inside every run.

A reference is found by the *physics* of a scene (:func:`physics_identity`): every key of the
mechanism (links, slider, drive, wing) and the end time, without the keys that choose a model
or its discretization (:data:`MODEL_KEYS`), the step, the solver, the output and the fidelity.
A run of any model and settings of that physics is compared with the same reference.

Layout of a store file (``flex_format`` :data:`FORMAT`)::

    /                        attrs: flex_format, provenance (flex_version, git_commit, ...)
    /<name>/                 attrs: physics_toml, physics_digest, model, evidence
    /<name>/value/<quantity>     scalar [the quantity's unit]: the reference's value
    /<name>/accuracy/<quantity>  scalar [the quantity's unit]: its own error (module of
                                 :mod:`flex.experiments.workprecision.stored_references`)
    /<name>/curves/time          [s]; /<name>/curves/<series path> [its unit]: the series
                                 of the history quantities, every :data:`CURVE_STEP_S`

A file that breaks this layout, a foreign HDF5 file or one of another format is refused with
one message (:class:`flex.base.errors.ResultFileError`); a scene whose physics has no stored
reference is refused naming the stored ones and the command that makes them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError, ResultFileError
from flex.data.cache import content_digest

#: 2: a link's stress peaks read on its low-passed field; 3: a joint force's modulus on the
#: low-passed force vector (the headline channel's versions,
#: :data:`flex.base.channel.CHANNEL_FORMAT_VERSION`); 4: the whole-run peaks and the
#: histories on the channel (its curves kept, with ``channel/determined``); 5: a peak at its
#: crest between samples (:func:`flex.data.headlines.crest_value`); an older store
#: holds values a run of today does not read: it is refused, to be made again
FORMAT = "flex-references/5"
#: the sections of a scene that hold its mechanism's physics
PHYSICS_SECTIONS = ("crank", "coupler", "slider", "drive", "wing")
#: keys of a link that choose its model or discretize it, not its physics
MODEL_KEYS = frozenset({"model", "modes", "mode_selection", "mesh_size_m", "elements",
                        "geometric_stiffness"})
#: the stored curves' sample interval [s] (linear interpolation of a 1 kHz bending crest
#: sampled so: ~5e-5 of its amplitude)
CURVE_STEP_S = 1e-5
#: the bundled store's file name, beside this module
BUNDLED_STORE_NAME = "references.h5"


def bundled_store() -> Path:
    """The store shipped with flex (``flex/data/references.h5``), written by ``make
    references-install``."""
    return Path(str(resources.files("flex.data").joinpath(BUNDLED_STORE_NAME)))


class MissingReferenceError(FlexError):
    """A scene whose physics the store does not hold."""


@dataclass
class StoredReference:
    """One converged reference: its values and accuracies [each quantity's unit], curves
    (``time`` [s] and each series path -> values), the physics it stands for, the model and
    discretization that made it (``model``) and the evidence of its accuracy, in words."""

    name: str
    physics: dict[str, dict[str, Any]]
    model: str
    evidence: str
    values: dict[str, float]
    accuracies: dict[str, float]
    units: dict[str, str]
    curves: dict[str, np.ndarray] = field(default_factory=dict)
    curve_units: dict[str, str] = field(default_factory=dict)

    @property
    def digest(self) -> str:
        return physics_digest(self.physics)


def store_digest(references: Mapping[str, StoredReference]) -> str:
    """A content digest of a store's references (names, physics, values, accuracies and
    curves): what a sweep binds so that its cases rerun when the store changes."""
    parts: list[tuple[str, Any]] = []
    for name, ref in sorted(references.items()):
        parts += [(f"{name}/physics", ref.digest), (f"{name}/model", ref.model)]
        parts += [(f"{name}/value/{q}", v) for q, v in sorted(ref.values.items())]
        parts += [(f"{name}/accuracy/{q}", v) for q, v in sorted(ref.accuracies.items())]
        parts += [(f"{name}/curves/{c}", v) for c, v in sorted(ref.curves.items())]
    return content_digest(parts)


def physics_identity(scene: Mapping[str, Mapping[str, Any]]) -> dict[str, dict[str, Any]]:
    """The physics of a resolved scene (module doc): its mechanism sections without
    :data:`MODEL_KEYS`, and ``simulation.end_time_s`` [s]."""
    out = {section: {key: value for key, value in sorted(scene[section].items())
                     if key not in MODEL_KEYS}
           for section in PHYSICS_SECTIONS if section in scene}
    out["simulation"] = {"end_time_s": float(scene["simulation"]["end_time_s"])}
    return out


def physics_digest(physics: Mapping[str, Mapping[str, Any]]) -> str:
    """A content digest of :func:`physics_identity`'s result (numbers as written)."""
    return content_digest((f"{section}.{key}", value) for section, values in
                          sorted(physics.items()) for key, value in sorted(values.items()))


def distinct_physics(scenes: Mapping[str, Mapping[str, Any]]) -> dict[str, Any]:
    """``scenes`` without those whose physics (:func:`physics_identity`) an earlier one has:
    one stored reference per physics, named after its first scene."""
    seen: set[str] = set()
    out = {}
    for name, scene in scenes.items():
        digest = physics_digest(physics_identity(scene))
        if digest not in seen:
            seen.add(digest)
            out[name] = scene
    return out


def reference_for(store: Mapping[str, StoredReference], scene: Mapping[str, Any]
                  ) -> StoredReference:
    """The stored reference of ``scene``'s physics; :class:`MissingReferenceError` naming the
    stored ones when there is none."""
    digest = physics_digest(physics_identity(scene))
    for reference in store.values():
        if reference.digest == digest:
            return reference
    raise MissingReferenceError(
        f"no stored reference for this scene's physics (digest {digest[:12]}); the store holds "
        f"{', '.join(sorted(store)) or 'none'}: add the scene to studies/references.py, then "
        f"run `make references` and `make references-install`")


def write_store(path: str | Path, references: Mapping[str, StoredReference],
                attrs: Mapping[str, str]) -> None:
    """Write ``references`` to ``path`` atomically (:func:`flex.data.results.atomic_path`),
    with ``attrs`` (provenance) at the root."""
    import h5py
    import tomli_w

    from flex.data.results import atomic_path

    with atomic_path(path) as part, h5py.File(part, "w") as h5:
        for key, value in attrs.items():
            h5.attrs[key] = value
        h5.attrs["flex_format"] = FORMAT  # after the provenance, which names the results'
        for name, ref in references.items():
            group = h5.create_group(name)
            group.attrs.update(physics_toml=tomli_w.dumps(ref.physics), model=ref.model,
                               physics_digest=ref.digest, evidence=ref.evidence)
            for kind, numbers in (("value", ref.values), ("accuracy", ref.accuracies)):
                for quantity, number in numbers.items():
                    data = group.create_dataset(f"{kind}/{quantity}", data=float(number))
                    data.attrs["units"] = ref.units[quantity]
            for path_, values in ref.curves.items():
                data = group.create_dataset(f"curves/{path_}", data=np.asarray(values),
                                            compression="gzip", shuffle=True)
                data.attrs["units"] = ref.curve_units[path_]


def read_store(path: str | Path) -> dict[str, StoredReference]:
    """The references of a store file (module doc); :class:`ResultFileError` for a file that
    is missing, not HDF5, of another format or broken."""
    import tomllib

    import h5py

    path = Path(path)
    if not path.is_file():
        raise ResultFileError(f"{path}: no reference store (make it with `make references` "
                              f"and `make references-install`)")
    try:
        with h5py.File(path, "r") as h5:
            if h5.attrs.get("flex_format") != FORMAT:
                raise ResultFileError(f"{path}: not a flex reference store (flex_format "
                                      f"{h5.attrs.get('flex_format')!r}, expected {FORMAT!r})")
            return {name: _read_one(name, group, tomllib) for name, group in h5.items()}
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise ResultFileError(f"{path}: unreadable reference store ({exc})") from None


def _read_one(name: str, group: Any, tomllib: Any) -> StoredReference:
    def numbers(kind: str) -> dict[str, float]:
        return {q: float(d[()]) for q, d in group[kind].items()}

    units = {q: str(d.attrs["units"]) for q, d in group["value"].items()}
    curves: dict[str, np.ndarray] = {}
    curve_units: dict[str, str] = {}
    if "curves" in group:
        group["curves"].visititems(lambda p, d: _collect(p, d, curves, curve_units))
    return StoredReference(name, tomllib.loads(group.attrs["physics_toml"]),
                           str(group.attrs["model"]), str(group.attrs["evidence"]),
                           numbers("value"), numbers("accuracy"), units, curves, curve_units)


def _collect(path: str, item: Any, curves: dict[str, np.ndarray],
             units: dict[str, str]) -> None:
    import h5py

    if isinstance(item, h5py.Dataset):
        curves[path] = np.asarray(item[()])
        units[path] = str(item.attrs["units"])


__all__ = ["BUNDLED_STORE_NAME", "CURVE_STEP_S", "FORMAT", "MODEL_KEYS", "MissingReferenceError",
           "distinct_physics",
           "PHYSICS_SECTIONS", "StoredReference", "bundled_store", "physics_digest",
           "physics_identity", "read_store", "reference_for", "store_digest", "write_store"]
