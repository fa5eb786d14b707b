"""The layout every reader of a flex result file relies on (:func:`check_layout`): what
:func:`flex.data.results.open_results` checks before handing a file over."""


from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import ResultFileError

CASE_STATUSES = ("ok", "failed")
ROOT_TEXT_ATTRIBUTES = ("flex_format", "study", "scene_toml", "flex_version", "git_commit",
                        "git_dirty", "created_utc", "command")
CASE_TEXT_ATTRIBUTES = ("status", "message", "scene_toml", "solver_settings_toml")
DATASET_TEXT_ATTRIBUTES = ("units", "description")


def describe_value(value: Any) -> str:
    """A short description of an unexpected attribute value: its type and (short) value."""
    import h5py

    if isinstance(value, h5py.Empty):
        return "an empty (null) attribute"
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} ({value.dtype})"
    if isinstance(value, bytes):
        try:
            value.decode("utf-8")
        except UnicodeDecodeError:
            return f"bytes that are not UTF-8 ({value[:20]!r})"
    text = repr(value.item() if isinstance(value, np.generic) else value)
    text = text if len(text) <= 40 else text[:37] + "..."
    return text if isinstance(value, str) else f"{type(value).__name__} {text}"


def _text_attribute(obj, key: str, where: str, label) -> str | None:
    """Attribute ``key`` of ``obj`` as a string (``None`` if absent); anything else but a
    string (or UTF-8 bytes) raises :class:`ResultFileError` naming file, object and key."""
    if key not in obj.attrs:
        return None
    return _as_text(obj.attrs[key], key, where, label)


def _as_text(value: Any, key: str, where: str, label) -> str:
    """An attribute's value read as a string (see :func:`_text_attribute`)."""
    if isinstance(value, np.ndarray) and value.shape == () and value.dtype.kind in "OSU":
        value = value[()]
    if isinstance(value, bytes):
        try:
            return value.decode("utf-8")
        except UnicodeDecodeError:
            pass
    elif isinstance(value, str):
        return str(value)
    raise ResultFileError(f"result file '{label}': attribute {key!r} of {where} is "
                          f"{describe_value(value)}; expected a text string")


def _number_attribute(obj, key: str, where: str, label) -> None:
    value = obj.attrs[key]
    if isinstance(value, bool | int | float | np.bool_ | np.integer | np.floating):
        return
    raise ResultFileError(f"result file '{label}': attribute {key!r} of {where} is "
                          f"{describe_value(value)}; expected a number")


def _link_kind(group, name: str) -> str | None:
    """``"soft link to '/x'"`` / ``"external link to ..."`` for a link, else ``None``."""
    import h5py

    link = group.get(name, getlink=True)
    if isinstance(link, h5py.SoftLink):
        return f"a soft link (to '{link.path}')"
    if isinstance(link, h5py.ExternalLink):
        return f"an external link (to '{link.path}' in file '{link.filename}')"
    return None


def check_layout(h5, label: str | Path = "") -> None:
    """Check that an open result file has the layout every reader relies on.

    Raises :class:`ResultFileError` naming the file, the HDF5 path and what was expected:

    - no links (soft or external) anywhere; every object readable;
    - root attributes ``flex_format``, ``study``, ``scene_toml`` (and the provenance
      strings) are text when present;
    - ``/cases`` is a group and holds only groups (one per case);
    - each case has a text ``status`` of ``"ok"`` or ``"failed"``; ``message``,
      ``scene_toml``, ``solver_settings_toml`` are text; ``counter_*`` are numbers;
    - a ``time`` dataset (at a case's root or in a group of it) is a 1-D float array of at
      least one finite, non-decreasing sample [s], and every array dataset it governs (in
      its group and the groups below, up to the next ``time``) has one row per sample;
      scalars and cases without ``time`` (summary-like cases, failed cases) carry no such
      constraint;
    - every dataset holds numbers or text (no compound, complex, reference or empty
      dataset); its ``units`` and ``description`` attributes are text when present.

    Valid files written by :func:`~flex.data.results.write_results` always pass. ``/summary``
    and other top-level groups are checked for links, dataset types and attribute types only.
    """
    label = label or h5.filename
    where = "/"
    try:
        _check_attributes(h5, "/", ROOT_TEXT_ATTRIBUTES, label)
        for name in h5:
            where = f"/{name}"
            _check_tree(h5, name, label)
        where = "/cases"
        if "cases" not in h5:
            raise ResultFileError(f"result file '{label}' has no /cases group; expected one "
                                  f"(a flex result file always has it, maybe empty)")
        cases = h5["cases"]
        if not hasattr(cases, "keys"):
            raise ResultFileError(f"result file '{label}': /cases is {_kind(cases)}; "
                                  f"expected a group holding one group per case")
        for case in cases:
            where = f"/cases/{case}"
            group = cases[case]
            if not hasattr(group, "keys"):
                raise ResultFileError(f"result file '{label}': /cases/{case} is "
                                      f"{_kind(group)}; expected a case group (every "
                                      f"object directly under /cases is a case)")
            _check_case(group, case, label)
    except (OSError, RuntimeError, KeyError, ValueError, TypeError, UnicodeError) as exc:
        reason = " ".join(str(exc).split())[:160]
        raise ResultFileError(f"result file '{label}' is damaged: cannot read {where} "
                              f"({type(exc).__name__}: {reason})") from None


def _kind(obj) -> str:
    if hasattr(obj, "keys"):
        return "a group"
    if hasattr(obj, "shape"):
        return f"a dataset of shape {obj.shape}"
    return f"a {type(obj).__name__}"


def _check_attributes(obj, where: str, text_keys: Sequence[str], label) -> None:
    """Every attribute readable, those of ``text_keys`` text; each is read once (a result
    file holds tens of thousands, and an h5py attribute read costs ~0.1 ms)."""
    attrs = obj.attrs
    for key in attrs:
        try:
            value = attrs[key]
        except (OSError, RuntimeError, KeyError, ValueError, TypeError):
            raise ResultFileError(f"result file '{label}': attribute {key!r} of {where} "
                                  f"cannot be read (a type flex does not know)") from None
        if key in text_keys:
            _as_text(value, key, where, label)


def _check_tree(parent, name: str, label) -> None:
    """Check ``parent[name]`` and everything below it (links, datasets, attributes)."""
    path = f"{parent.name.rstrip('/')}/{name}"
    link = _link_kind(parent, name)
    if link:
        raise ResultFileError(f"result file '{label}': {path} is {link}; flex result "
                              f"files hold no links")
    obj = parent[name]
    if hasattr(obj, "keys"):
        _check_attributes(obj, path, (), label)
        for child in obj:
            _check_tree(obj, child, label)
        return
    if not hasattr(obj, "shape"):
        raise ResultFileError(f"result file '{label}': {path} is {_kind(obj)}; expected a "
                              f"group or a dataset")
    _check_attributes(obj, path, DATASET_TEXT_ATTRIBUTES, label)
    _check_dataset_type(obj, path, label)


def _check_dataset_type(dataset, path: str, label) -> None:
    import h5py

    if dataset.shape is None:
        raise ResultFileError(f"result file '{label}': {path} is an empty (null) dataset; "
                              f"expected numbers or text")
    dtype = dataset.dtype
    kind = dtype.kind
    if kind in "biuf" and dtype.names is None and dtype.shape == ():
        return
    if kind in "SU" or (kind == "O" and h5py.check_string_dtype(dtype) is not None):
        return
    what = {"c": "complex numbers", "V": "compound or opaque records",
            "O": "object references or variable-length sequences"}.get(kind, f"type {dtype}")
    if dtype.shape != ():
        what = f"array elements of shape {dtype.shape}"
    raise ResultFileError(f"result file '{label}': {path} holds {what}; expected numbers "
                          f"or text")


def _check_case(group, case: str, label) -> None:
    where = f"/cases/{case}"
    status = _text_attribute(group, "status", where, label)
    if status is None:
        raise ResultFileError(f"result file '{label}': case {where} has no 'status' "
                              f"attribute; expected \"ok\" or \"failed\"")
    if status not in CASE_STATUSES:
        raise ResultFileError(f"result file '{label}': case {where} has status "
                              f"{status!r}; expected \"ok\" or \"failed\"")
    _check_attributes(group, where, CASE_TEXT_ATTRIBUTES, label)
    for key in group.attrs:
        if key.startswith("counter_"):
            _number_attribute(group, key, where, label)
    _check_samples(group, where, label, None)


def _check_samples(group, where: str, label, governing: tuple[str, int] | None) -> None:
    """Every array dataset below ``group`` has one row per sample of the ``time`` that
    governs it (the nearest ``time`` in its group or above, inside the case)."""
    if "time" in group:
        governing = (f"{where}/time", _check_time(group["time"], f"{where}/time", label))
    for name in group:
        obj = group[name]
        path = f"{where}/{name}"
        if hasattr(obj, "keys"):
            _check_samples(obj, path, label, governing)
            continue
        if name == "time" or governing is None or obj.ndim == 0:
            continue
        time_path, samples = governing
        if obj.shape[0] != samples:
            raise ResultFileError(f"result file '{label}': {path} has shape {obj.shape} but "
                                  f"{time_path} has {samples} samples; expected one row "
                                  f"per sample ({samples}, ...)")


def _check_time(dataset, path: str, label) -> int:
    """Validate a ``time`` dataset; return its number of samples."""
    def refuse(problem: str) -> ResultFileError:
        return ResultFileError(f"result file '{label}': {path} {problem}; expected a 1-D "
                               f"float array of at least one finite, non-decreasing sample "
                               f"time [s]")

    if not hasattr(dataset, "shape"):
        raise refuse("is a group")
    if dataset.ndim != 1:
        raise refuse("is a scalar" if dataset.ndim == 0
                     else f"has {dataset.ndim} dimensions (shape {dataset.shape})")
    if dataset.dtype.kind != "f":
        raise refuse(f"holds {'text' if dataset.dtype.kind in 'OSU' else dataset.dtype}")
    if dataset.shape[0] == 0:
        raise refuse("has no samples")
    units = dataset.attrs.get("units", "s")
    units = units.decode("utf-8", "replace") if isinstance(units, bytes) else units
    if units != "s":  # relabelled (ms): compared, plotted and exported as seconds
        raise refuse(f"has units {str(units)[:20]!r}")
    values = dataset[()]
    finite = np.isfinite(values)
    if not finite.all():
        index = int(np.argmin(finite))
        raise refuse(f"has a non-finite value ({values[index]}) at index {index}")
    steps = np.diff(values)
    if (steps < 0).any():
        index = int(np.argmax(steps < 0))
        raise refuse(f"decreases at index {index + 1} ({values[index]:.9g} -> "
                     f"{values[index + 1]:.9g} s)")
    return int(dataset.shape[0])


