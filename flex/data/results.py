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
reader sees the previous complete file or the new complete file, never a partial one. Every
reader opens files through :func:`open_results`, which checks this layout
(:func:`flex.data.result_layout.check_layout`) and refuses a file that breaks it with one
message naming the file, the HDF5 path and what was expected.
"""

from __future__ import annotations

import datetime as _dt
import glob
import os
import platform
import re
import secrets
import shlex
import subprocess
import sys
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flex import __version__
from flex.base.errors import ResultFileError
from flex.data.result_layout import check_layout, describe_value

FORMAT = "flex-results/1"


@dataclass
class Dataset:
    """An array with its unit (``"1"`` for dimensionless) and a one-line description."""

    data: Any
    units: str
    description: str = ""
    compress: bool = False  #: gzip (with shuffle) in the file: large fields (nodal snapshots)
    #: further attributes written on the dataset (small scalars or text: a report table's
    #: title and column position, :func:`flex.data.tables.findings_table`)
    attrs: dict[str, Any] = field(default_factory=dict)


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
    root = Path(__file__).resolve().parents[2]
    try:
        return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True,
                              timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def provenance() -> dict[str, str]:
    """Code and engine versions, git commit and dirtiness, time, host and command line."""
    from importlib.metadata import PackageNotFoundError, version

    versions = {}
    for module in ("exudyn", "ngsolve", "h5py", "numpy", "scipy"):
        # the installed distribution's version: no import (ngsolve's costs 0.2 s a run)
        try:
            versions[f"{module}_version"] = version(module)
        except PackageNotFoundError:  # an engine not installed is recorded, not fatal
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


PART_SUFFIX = ".part"
_PART_TAIL = re.compile(r"^(\d+)\.[^.]+\.part$")  # <pid>.<random hex>.part


def _part_prefix(path: Path) -> str:
    return f".{path.name}."


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_stale_parts(path: str | Path) -> list[Path]:
    """Delete temporary files ``.<name>.<pid>.*.part`` beside ``path`` left by dead writers.

    A writer killed with SIGKILL (or by a power cut) cannot remove its temporary file; the
    next write of the same path removes it. Parts whose writer process is still alive (a
    concurrent run) are kept. Returns the removed paths.
    """
    path = Path(path)
    removed = []
    prefix = _part_prefix(path)
    try:
        candidates = list(path.parent.glob(f"{glob.escape(prefix)}*{PART_SUFFIX}"))
    except OSError:
        return removed
    for part in candidates:
        match = _PART_TAIL.match(part.name[len(prefix):])
        if not match or int(match[1]) == os.getpid() or _process_alive(int(match[1])):
            continue
        try:
            part.unlink()
            removed.append(part)
        except OSError:
            pass
    return removed


@contextmanager
def atomic_path(path: str | Path):
    """Yield a temporary path beside ``path``; rename it to ``path`` only on success.

    The temporary file is ``.<name>.<pid>.<random>.part`` in the same folder, created with
    the usual permissions (0666 minus the umask). On any exception (including
    ``KeyboardInterrupt``) it is deleted and ``path`` is untouched; on success it is flushed
    to disk and renamed over ``path`` in one atomic step, so readers and concurrent writers
    see a complete old or a complete new file (the last writer to finish wins). Parts left
    by killed writers are removed here (:func:`remove_stale_parts`).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_parts(path)
    # named before it exists, so an interrupt at any point after creation still removes it
    tmp = path.parent / f"{_part_prefix(path)}{os.getpid()}.{secrets.token_hex(8)}{PART_SUFFIX}"
    try:
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        yield tmp
        with open(tmp, "rb+") as stream:
            os.fsync(stream.fileno())
        os.replace(tmp, path)
        _fsync_folder(path.parent)
    finally:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass


def _fsync_folder(folder: Path) -> None:
    try:
        handle = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(handle)
    except OSError:
        pass
    finally:
        os.close(handle)


def _write_dataset(group, path: str, dataset: Dataset) -> None:
    data = np.asarray(dataset.data)
    # text columns: numpy strings, or objects that are all str (an empty column included:
    # h5py cannot guess the type of an empty object array)
    if data.dtype.kind in "US" or (data.dtype.kind == "O"
                                   and all(isinstance(v, str) for v in data.ravel())):
        data = data.astype(object)
        created = group.create_dataset(path, data=data, dtype=_string_dtype())
    elif dataset.compress:
        created = group.create_dataset(path, data=data, compression="gzip",
                                       compression_opts=4, shuffle=True)
    else:
        created = group.create_dataset(path, data=data)
    created.attrs["units"] = dataset.units
    created.attrs["description"] = dataset.description
    for key, value in dataset.attrs.items():
        created.attrs[key] = value


def _string_dtype():
    import h5py

    return h5py.string_dtype()


def write_results(path: str | Path, study: str, cases: list[CaseResult],
                  scene_toml: str = "", summary: dict[str, Dataset] | None = None,
                  attrs: dict[str, Any] | None = None) -> Path:
    """Write a whole result file atomically and return its path.

    ``summary`` datasets go under ``/summary``; ``attrs`` are extra root attributes. An
    operating-system failure while writing (full disk, no permission) raises
    :class:`ResultFileError` naming the file; the previous file is then unchanged.
    """
    path = Path(path)
    try:
        _write_file(path, study, cases, scene_toml, summary, attrs)
    except (OSError, RuntimeError) as exc:  # full disk, no permission: the old file stays
        cause = _os_error_in(exc)
        if cause is None:
            raise
        raise ResultFileError(f"cannot write result file '{path}': {os_reason(cause)}; "
                              f"the previous file (if any) is unchanged") from None
    return path


def _os_error_in(exc: BaseException) -> OSError | None:
    """The ``OSError`` behind ``exc`` (h5py reports a failed write again as a RuntimeError
    when it closes the file), or ``None``."""
    seen = 0
    current: BaseException | None = exc
    while current is not None and seen < 10:
        if isinstance(current, OSError):
            return current
        current = current.__context__
        seen += 1
    return None


def os_reason(exc: OSError) -> str:
    """A one-line reason: ``No space left on device`` rather than HDF5's multi-line text."""
    if exc.errno:
        return os.strerror(exc.errno)
    return " ".join(str(exc).split())[:200]


#: the old private name, still imported by flex/tools/plotcurves.py (to go with that import)


def _write_file(path: Path, study: str, cases: list[CaseResult], scene_toml: str,
                summary: dict[str, Dataset] | None, attrs: dict[str, Any] | None) -> None:
    import h5py

    # The file is built in memory and written with one plain write: a full disk then fails
    # in Python with a clean OSError (HDF5 itself can crash when its own write fails).
    with atomic_path(path) as tmp:
        with h5py.File(tmp.name, "w", driver="core", backing_store=False) as h5:
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
            h5.flush()
            image = h5.id.get_file_image()
        with open(tmp, "wb") as stream:
            stream.write(image)


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


def open_results(path: str | Path, check: bool = True):
    """Open a flex result file read-only (``h5py.File``), or raise :class:`ResultFileError`.

    The message names the file and what is wrong: missing (or a symbolic link to nothing),
    a folder, empty, not HDF5 (or truncated), HDF5 not written by flex (no ``flex_format``
    attribute), or (``check``, the default) a layout :func:`check_layout` refuses.
    """
    path = Path(path)
    _check_readable_file(path)
    h5 = _open_hdf5(path)
    try:
        _check_format(h5, path)
        if check:
            check_layout(h5, path)
    except BaseException:
        h5.close()
        raise
    return h5


def _check_readable_file(path: Path) -> None:
    """Raise :class:`ResultFileError` unless ``path`` is a regular, readable, non-empty file
    (missing, a link to nothing, a folder, a device, unreadable, empty: each said so)."""
    if not path.exists():
        if path.is_symlink():
            raise ResultFileError(f"result file '{path}' is a symbolic link to nothing "
                                  f"('{os.readlink(path)}' does not exist)")
        raise ResultFileError(f"result file '{path}' does not exist")
    if path.is_dir():
        raise ResultFileError(f"result file '{path}' is a directory, not an HDF5 file")
    if not path.is_file():
        raise ResultFileError(f"result file '{path}' is not a regular file (a device, pipe or "
                              f"socket), not an HDF5 file")
    try:
        size = path.stat().st_size
        with open(path, "rb") as stream:
            stream.read(1)
    except OSError as exc:
        raise ResultFileError(f"result file '{path}' cannot be read: "
                              f"{os_reason(exc)}") from None
    if size == 0:
        raise ResultFileError(f"result file '{path}' is empty (0 bytes), not an HDF5 file")


def _open_hdf5(path: Path):
    """``path`` opened read-only by h5py, or :class:`ResultFileError` saying why it cannot be
    (not HDF5, truncated, locked by another process, damaged)."""
    import h5py

    try:
        return h5py.File(path, "r")
    except (OSError, RuntimeError, ValueError) as exc:
        try:
            hdf5 = h5py.is_hdf5(path)
        except (OSError, RuntimeError, ValueError):
            hdf5 = False
        if not hdf5:
            raise ResultFileError(f"result file '{path}' is not an HDF5 file "
                                  f"(or is truncated)") from None
        reason = str(exc)
        sizes = re.search(r"truncated file: eof = (\d+).*stored_eof = (\d+)", reason)
        if sizes:
            raise ResultFileError(f"result file '{path}' is truncated HDF5 ({sizes[1]} of "
                                  f"the {sizes[2]} bytes it declares)") from None
        if "unable to lock file" in reason.lower():
            raise ResultFileError(f"result file '{path}' is locked by another process "
                                  f"(HDF5 file locking)") from None
        raise ResultFileError(f"result file '{path}' is damaged or truncated HDF5") from None


def _check_format(h5, path: Path) -> None:
    """Raise :class:`ResultFileError` unless the open file's root attribute ``flex_format``
    is :data:`FORMAT` (unreadable, missing or another value: not written by flex)."""
    try:
        fmt = h5.attrs.get("flex_format")
    except (OSError, RuntimeError, KeyError, ValueError, TypeError):
        raise ResultFileError(f"result file '{path}' is damaged: its root attribute "
                              f"flex_format cannot be read") from None
    if isinstance(fmt, bytes):
        try:
            fmt = fmt.decode("utf-8")
        except UnicodeDecodeError:
            pass
    if not isinstance(fmt, str) or fmt != FORMAT:
        found = (f"flex_format = {describe_value(fmt)}" if fmt is not None
                 else "no flex_format attribute")
        raise ResultFileError(f"result file '{path}' was not written by flex ({found}; "
                              f"expected {FORMAT!r})")


def read_case(path: str | Path, case: str) -> dict[str, np.ndarray]:
    """All datasets of one case as ``{relative path: array}`` (for tests and scripts)."""
    with reading(path) as h5:
        if case not in case_names(h5):
            raise ResultPathError(f"result file '{path}' has no case '{case}' (cases: "
                                  f"{', '.join(case_names(h5)) or 'none'})")
        out: dict[str, np.ndarray] = {}
        h5[f"cases/{case}"].visititems(
            lambda name, obj: out.__setitem__(name, obj[()]) if hasattr(obj, "shape") else None)
        return out


class ResultPathError(ResultFileError):
    """A path asked for (``cases/<case>/crank/angle``, a case, a group) is not in the file."""


@contextmanager
def reading(path: str | Path):
    """Open a result file like :func:`open_results` and close it after the block.

    Low-level read errors inside the block (a damaged file whose header opened but whose
    data cannot be read) become one :class:`ResultFileError` naming the file.
    """
    h5 = open_results(path)
    try:
        yield h5
    except (OSError, RuntimeError) as exc:
        raise ResultFileError(f"result file '{path}' is damaged: cannot read its data "
                              f"({exc})") from None
    finally:
        h5.close()


def list_datasets(group) -> list[str]:
    """Paths of every dataset below ``group`` (an open h5py file or group), relative to it,
    in the file's order."""
    names: list[str] = []
    group.visititems(lambda name, obj: names.append(name) if hasattr(obj, "shape") else None)
    return names


def case_names(h5) -> list[str]:
    """Names of the cases of an open result file (``/cases/<case>``), in the file's order."""
    cases = h5.get("cases")
    return list(cases) if cases is not None and hasattr(cases, "keys") else []


def split_case_path(path: str) -> tuple[str | None, str]:
    """``"cases/a/crank/angle"`` -> ``("a", "crank/angle")``; other paths -> ``(None, path)``."""
    parts = path.strip("/").split("/", 2)
    if len(parts) == 3 and parts[0] == "cases":
        return parts[1], parts[2]
    return None, path.strip("/")


_COLUMN = re.compile(r"^(.*)\[(\d+)\]$")


def parse_spec(spec: str) -> tuple[str, int | None]:
    """``"crank/midpoint_position[1]"`` -> ``("crank/midpoint_position", 1)``."""
    match = _COLUMN.match(spec.strip())
    if match:
        return match[1].strip("/"), int(match[2])
    return spec.strip().strip("/"), None


def select_datasets(h5, spec: str, label: str | Path = "") -> list[str]:
    """Full paths of the datasets that ``spec`` names in the open result file ``h5``.

    ``spec`` (without a ``[column]`` suffix, see :func:`parse_spec`) is tried as written,
    then under ``cases/``, then, when the file has exactly one case, under that case; so
    ``cases/preload_22mm/crank/angle``, ``preload_22mm/crank/angle`` and (one case)
    ``crank/angle`` name the same dataset. A group stands for every dataset below it;
    ``*`` and ``?`` are wildcards (``*/crank/angle``: that curve of every case). Raises
    :class:`ResultPathError` naming the file and suggesting close paths when nothing matches.
    """
    import fnmatch

    spec = "/".join(part for part in spec.strip().split("/") if part not in ("", "."))
    cases = case_names(h5)
    candidates = [spec, f"cases/{spec}"] if spec else [""]
    if len(cases) == 1 and spec:
        candidates.append(f"cases/{cases[0]}/{spec}")
    everything = list_datasets(h5)
    for candidate in candidates:
        if any(char in candidate for char in "*?"):
            matches = [name for name in everything if fnmatch.fnmatchcase(name, candidate)]
            if matches:
                return matches
            continue
        if candidate == "":
            return everything
        if candidate in h5:
            obj = h5[candidate]
            if hasattr(obj, "shape"):
                return [candidate]
            below = [f"{candidate}/{name}" for name in list_datasets(obj)]
            if below:
                return below
    import difflib

    close = difflib.get_close_matches(spec, everything, n=3, cutoff=0.5)
    close += [name for name in everything if name.endswith("/" + spec)][:3]
    hint = f"; did you mean {', '.join(dict.fromkeys(close))}?" if close else ""
    where = f"cases: {', '.join(cases)}" if cases else "no cases"
    raise ResultPathError(f"result file '{label or h5.filename}' has no dataset or group "
                          f"'{spec}' ({where}){hint}")


def to_xarray(path: str | Path, case: str | None = None):
    """One case of a result file as an ``xarray.Dataset`` with a ``time`` coordinate [s].

    Variables are named by their path inside the case (``ds["crank/angle"]``); each carries
    ``units``, ``description`` and ``long_name`` attributes (so ``ds["crank/angle"].plot()``
    labels its axes). Curves have dimension ``time``; two-column curves (x, y) add a
    dimension ``xy`` with coordinates ``["x", "y"]``; other arrays get their own dimensions
    ``<name>_dim<i>``. ``ds.attrs`` hold the case's attributes and the file's provenance
    (prefixed ``file_``). ``case`` may be omitted when the file has one case. The data are
    read into memory; the file is closed on return. Needs ``xarray`` (``pip install
    xarray``).
    """
    try:
        import xarray as xr
    except ImportError:
        raise ResultFileError("to_xarray needs xarray: pip install xarray") from None
    with reading(path) as h5:
        cases = case_names(h5)
        if case is None:
            if len(cases) != 1:
                raise ResultPathError(f"result file '{path}' has {len(cases)} cases "
                                      f"({', '.join(cases)}); name one")
            case = cases[0]
        if case not in cases:
            raise ResultPathError(f"result file '{path}' has no case '{case}' (cases: "
                                  f"{', '.join(cases)})")
        group = h5[f"cases/{case}"]
        time_s = group["time"][()] if "time" in group else None
        coords: dict[str, Any] = {}
        if time_s is not None:
            coords["time"] = ("time", time_s, _attrs_of(group["time"]))
        variables = {}
        for name in list_datasets(group):
            if name == "time":
                continue
            data = group[name][()]
            attrs = _attrs_of(group[name])
            if isinstance(data, bytes):
                data = data.decode("utf-8", "replace")
            elif data.dtype == object or data.dtype.kind == "S":
                data = np.vectorize(_as_str, otypes=[str])(data) if data.size else data
            shape = np.shape(data)
            if time_s is not None and shape[:1] == time_s.shape and len(shape) <= 2:
                dims = ("time",) if len(shape) == 1 else ("time", "xy" if shape[1] == 2
                                                           else f"{name}_dim1")
                if len(shape) == 2 and shape[1] == 2:
                    coords["xy"] = ("xy", ["x", "y"])
            else:
                dims = tuple(f"{name}_dim{i}" for i in range(len(shape)))
            variables[name] = (dims, data, attrs)
        attrs = {key: attribute_value(value) for key, value in group.attrs.items()}
        attrs.update({f"file_{key}": attribute_value(value) for key, value in h5.attrs.items()})
        attrs["case"] = case
        attrs["file"] = str(path)
        return xr.Dataset(variables, coords=coords, attrs=attrs)


def _as_str(value: Any) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def _attrs_of(dataset) -> dict[str, str]:
    units = str(attribute_value(dataset.attrs.get("units", "")))
    description = str(attribute_value(dataset.attrs.get("description", "")))
    return {"units": units, "description": description, "long_name": description or ""}


def attribute_value(value: Any) -> Any:
    """An HDF5 attribute (or small dataset) value as plain Python: str, int, float, bool,
    ``None`` (an empty attribute), or a list of them (bytes decoded as UTF-8; anything else,
    such as a complex number or a record, as its text)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "cV":
            return str(value.tolist())
        return [attribute_value(item) for item in value.tolist()]
    if isinstance(value, np.generic):
        value = value.item()
    if value is None or isinstance(value, str | bool | int | float):
        return value
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, list | tuple):
        return [attribute_value(item) for item in value]
    if type(value).__name__ == "Empty":  # h5py.Empty: an attribute without a value
        return None
    return str(value)
