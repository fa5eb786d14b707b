"""HDF5 result files: units on every dataset, provenance at the root, atomic writes.

Layout of a study's file (``results/<study>.h5``)::

    /                      attrs: flex_format, study, flex_version, git_commit, git_dirty,
                                  exudyn_version, ngsolve_version, h5py_version,
                                  numpy_version, python_version, created_utc, command,
                                  scene_toml (the study's base scene)
    /cases/<case>/         attrs: status ("ok" | "failed"), message, scene_toml,
                                  solver_settings_toml, counters (steps, newton_iterations,
                                  jacobian_updates, wall_time_s)
    /cases/<case>/time     [s]
    /cases/<case>/crank/angle, ...   every dataset: attrs units, description
    /summary/...           study-level tables (e.g. thesis comparison)

Files are written to a temporary name in the same folder and renamed when complete, so a
reader sees the previous complete file or the new complete file, never a partial one.
"""

from __future__ import annotations

import datetime as _dt
import os
import platform
import shlex
import subprocess
import sys
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import __version__
from .errors import ResultFileError

FORMAT = "flex-results/1"


@dataclass
class Dataset:
    """An array with its unit (``"1"`` for dimensionless) and a one-line description."""

    data: Any
    units: str
    description: str = ""


@dataclass
class CaseResult:
    """One simulated case: datasets keyed by path relative to ``/cases/<name>``.

    ``status`` is ``"ok"`` or ``"failed"`` (then ``message`` says why and ``datasets`` may be
    empty); ``counters`` hold steps, Newton iterations, Jacobian updates and wall time [s].
    """

    name: str
    scene_toml: str
    datasets: dict[str, Dataset] = field(default_factory=dict)
    status: str = "ok"
    message: str = ""
    counters: dict[str, float] = field(default_factory=dict)
    solver_settings_toml: str = ""
    attrs: dict[str, Any] = field(default_factory=dict)


def _git(*args: str) -> str:
    root = Path(__file__).resolve().parent.parent
    try:
        return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True,
                              timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def provenance() -> dict[str, str]:
    """Code and engine versions, git commit and dirtiness, time, host and command line."""
    versions = {}
    for module in ("exudyn", "ngsolve", "h5py", "numpy", "scipy"):
        try:
            versions[f"{module}_version"] = __import__(module).__version__
        except Exception:  # an engine that fails to import is recorded, not fatal
            versions[f"{module}_version"] = "unavailable"
    commit = _git("rev-parse", "HEAD") or "unknown"
    dirty = _git("status", "--porcelain", "--untracked-files=no")
    return {
        "flex_format": FORMAT,
        "flex_version": __version__,
        "git_commit": commit,
        "git_dirty": "yes" if dirty else ("no" if commit != "unknown" else "unknown"),
        **versions,
        "python_version": platform.python_version(),
        "platform": platform.platform(),
        "created_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "command": shlex.join(sys.argv),
    }


@contextmanager
def atomic_path(path: str | Path):
    """Yield a temporary path beside ``path``; rename it to ``path`` only on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(handle)
    try:
        yield Path(tmp)
        with open(tmp, "rb+") as stream:
            os.fsync(stream.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _write_dataset(group, path: str, dataset: Dataset) -> None:
    data = np.asarray(dataset.data)
    if data.dtype.kind in "US":
        data = data.astype(object)
        created = group.create_dataset(path, data=data, dtype=_string_dtype())
    else:
        created = group.create_dataset(path, data=data)
    created.attrs["units"] = dataset.units
    created.attrs["description"] = dataset.description


def _string_dtype():
    import h5py

    return h5py.string_dtype()


def write_results(path: str | Path, study: str, cases: list[CaseResult],
                  scene_toml: str = "", summary: dict[str, Dataset] | None = None,
                  attrs: dict[str, Any] | None = None) -> Path:
    """Write a whole result file atomically and return its path.

    ``summary`` datasets go under ``/summary``; ``attrs`` are extra root attributes.
    """
    import h5py

    path = Path(path)
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as h5:
            for key, value in provenance().items():
                h5.attrs[key] = value
            h5.attrs["study"] = study
            h5.attrs["scene_toml"] = scene_toml
            for key, value in (attrs or {}).items():
                h5.attrs[key] = value
            group = h5.create_group("cases")
            for case in cases:
                write_case(group, case)
            if summary:
                summary_group = h5.create_group("summary")
                for name, dataset in summary.items():
                    _write_dataset(summary_group, name, dataset)
    return path


def write_case(parent, case: CaseResult) -> None:
    """Write one case group under ``parent`` (an open h5py group)."""
    group = parent.create_group(case.name)
    group.attrs["status"] = case.status
    group.attrs["message"] = case.message
    group.attrs["scene_toml"] = case.scene_toml
    group.attrs["solver_settings_toml"] = case.solver_settings_toml
    for key, value in case.counters.items():
        group.attrs[f"counter_{key}"] = value
    for key, value in case.attrs.items():
        group.attrs[key] = value
    for name, dataset in case.datasets.items():
        _write_dataset(group, name, dataset)


def open_results(path: str | Path):
    """Open a flex result file read-only (``h5py.File``), or raise :class:`ResultFileError`.

    The message names the file and what is wrong: missing, not HDF5 (or truncated), or HDF5
    not written by flex (no ``flex_format`` attribute).
    """
    import h5py

    path = Path(path)
    if not path.exists():
        raise ResultFileError(f"result file '{path}' does not exist")
    if path.is_dir():
        raise ResultFileError(f"result file '{path}' is a directory, not an HDF5 file")
    try:
        h5 = h5py.File(path, "r")
    except OSError:
        if not h5py.is_hdf5(path):
            raise ResultFileError(f"result file '{path}' is not an HDF5 file "
                                  f"(or is truncated)") from None
        raise ResultFileError(f"result file '{path}' is damaged or truncated HDF5") from None
    fmt = h5.attrs.get("flex_format")
    if isinstance(fmt, bytes):
        fmt = fmt.decode()
    if fmt != FORMAT:
        h5.close()
        found = f"flex_format = {fmt!r}" if fmt is not None else "no flex_format attribute"
        raise ResultFileError(f"result file '{path}' was not written by flex ({found}; "
                              f"expected {FORMAT!r})")
    return h5


def read_case(path: str | Path, case: str) -> dict[str, np.ndarray]:
    """All datasets of one case as ``{relative path: array}`` (for tests and scripts)."""
    with open_results(path) as h5:
        if f"cases/{case}" not in h5:
            raise ResultFileError(f"result file '{path}' has no case '{case}' (cases: "
                                  f"{', '.join(h5['cases'])})")
        out: dict[str, np.ndarray] = {}
        h5[f"cases/{case}"].visititems(
            lambda name, obj: out.__setitem__(name, obj[()]) if hasattr(obj, "shape") else None)
        return out
