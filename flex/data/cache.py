"""Caches on disk: an entry proves its content when loaded, is written atomically, and every
problem names the cache and how to move it.

flex keeps three kinds of cache: the reduction cache (Craig-Bampton reductions of plate
links, :mod:`flex.bodies.reduction`, and the geometric stiffness beside them), the plate
references (converged 3D solves, :mod:`flex.bodies.plate_reference`) and a sweep's case
files (:mod:`flex.sweep`, where a rerun resumes). The rules, shared by all:

- **content digest** (:func:`content_digest`): an entry stores a SHA-256 of everything a
  run reads from it, computed when it is built; a loader recomputes it and uses the entry
  only if both agree. An entry that does not prove its content (damaged, edited, foreign,
  of an older format) is rebuilt, with one line on stderr saying so (:func:`say`).
- **atomic write** (:func:`store`): an entry is written under a temporary name in its
  folder and renamed into place, so a reader never sees half an entry.
- **clear errors**: a cache location that cannot be used (a file where the folder should
  be, a read-only folder, a full disk, a folder at an entry's path) is reported in one line
  naming the cache, the folder and how to move it (:class:`Cache`); writing an entry is
  never worth losing a run for, so :func:`store` reports and goes on (the entry is simply
  not kept).

Adopting it for another entry kind (as the geometric-stiffness entries beside a reduction,
``<key>.geometric.hdf5``, do): write the arrays with ``store(path, writer,
REDUCTION_CACHE)``, store ``content_digest([(name, array), ...])`` of them as an attribute,
and on load recompute it from what was read; when it differs (or is absent),
``say(REDUCTION_CACHE, f"entry '{path}' did not prove its content ...")`` and rebuild.

Pure helpers: nothing here reads the environment; what to say goes to the ``stream`` given
(stderr by default).
"""

from __future__ import annotations

import hashlib
import math
import os
import sys
import tempfile
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from flex.base.errors import CacheError


@dataclass(frozen=True)
class Cache:
    """A cache's name in messages and how a user moves it (``hint``)."""

    label: str
    hint: str

    def error(self, folder: Path, reason: str) -> CacheError:
        """A :class:`CacheError` naming this cache, ``folder``, ``reason`` and the hint."""
        return CacheError(f"{self.label} '{folder}': {reason}; {self.hint}")


#: the reduction cache (and the geometric-stiffness entries beside its reductions)
REDUCTION_CACHE = Cache("reduction cache", "the reduction cache is safe to delete; "
                                           "FLEX_CACHE_DIR=/other/folder moves it (library "
                                           "calls: cache_dir=)")
#: the converged 3D plate references (:mod:`flex.bodies.plate_reference`)
PLATE_REFERENCE_CACHE = Cache("plate reference cache",
                              "the plate reference cache is safe to delete (its entries are "
                              "computed again, seconds each); library calls: cache_dir=")
#: a sweep's case files
SWEEP_CASES = Cache("sweep case folder", "the case folder is safe to delete (its cases run "
                                         "again); --folder DIR (FLEX_SWEEP_DIR) moves it")


def content_digest(parts: Iterable[tuple[str, Any]]) -> str:
    """SHA-256 (hex) over named parts, in their order: arrays by dtype kind, shape and
    values (numbers as float64, so an int written and read back as a float digests alike),
    text as UTF-8, None as nothing. Two values digest alike exactly when a loader would
    read the same numbers and text from them."""
    digest = hashlib.sha256()
    for name, value in parts:
        digest.update(name.encode("utf-8", "replace") + b"\0")
        digest.update(_canonical(value))
    return digest.hexdigest()


def _canonical(value: Any) -> bytes:
    if value is None:
        return b"none\0"
    if isinstance(value, bytes):
        value = value.decode("utf-8", "replace")
    if isinstance(value, str):
        return b"text\0" + value.encode("utf-8", "replace") + b"\0"
    array = np.asarray(value)
    if array.dtype.kind in "biuf":
        array = np.ascontiguousarray(array, dtype=np.float64)
        return b"num" + str(array.shape).encode() + b"\0" + array.tobytes()
    if array.dtype.kind == "c":
        array = np.ascontiguousarray(array, dtype=np.complex128)
        return b"complex" + str(array.shape).encode() + b"\0" + array.tobytes()
    texts = [item.decode("utf-8", "replace") if isinstance(item, bytes) else str(item)
             for item in array.reshape(-1)]
    return (b"texts" + str(array.shape).encode() + b"\0"
            + "\0".join(texts).encode("utf-8", "replace") + b"\0")


def number_text(value: Any) -> str:
    """A number or text as stable text for a digest (``repr(float)`` for numbers)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, str):
        return value
    try:
        number = float(value)
    except (TypeError, ValueError):
        return str(value)
    return repr(number) if math.isfinite(number) or math.isnan(number) else str(number)


def say(cache: Cache, text: str, stream: TextIO | None = None) -> None:
    """One line ``flex: <cache>: <text>`` on ``stream`` (default stderr)."""
    print(f"flex: {cache.label}: {text}", file=stream or sys.stderr, flush=True)


def folder_problem(folder: Path) -> str:
    """Why ``folder`` cannot hold cache entries ("" if it can, or can be created): a file
    (or broken link) in its place or above it, or a folder that cannot be written."""
    existing = Path(folder)
    while not existing.exists():
        if existing.is_symlink():
            return f"'{existing}' is a broken link"
        if existing == existing.parent:
            break
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        return f"'{existing}' is a file, not a folder"
    if not os.access(existing, os.W_OK | os.X_OK):
        return f"folder '{existing}' is not writable"
    return ""


def entry_problem(path: Path) -> str:
    """Why an entry's path cannot hold an entry ("" if it can): a folder, or a non-file."""
    if path.is_dir():
        return f"'{path.name}' is a folder, not a cache entry"
    if path.exists() and not path.is_file():
        return f"'{path.name}' is not a regular file"
    return ""


def store(path: Path, write: Callable[[Path], None], cache: Cache,
          stream: TextIO | None = None) -> bool:
    """Write one entry atomically: ``write(temporary path)`` in ``path``'s folder, then
    rename onto ``path``. True when the entry is in place. When the location cannot be used
    (a file in the way, read-only, full disk, a folder at ``path``) nothing is left behind,
    one line says so (naming the cache, the reason and how to move it) and False is
    returned: a cache that cannot be written costs the next run a rebuild, not this run's
    result. An interrupt removes the temporary file and propagates."""
    path = Path(path)
    problem = entry_problem(path) or folder_problem(path.parent)
    temporary: Path | None = None
    if not problem:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            # the temporary name keeps the entry's suffix (a writer may choose its format by it)
            handle, name = tempfile.mkstemp(prefix=f".{path.stem}.",
                                            suffix=f".tmp{path.suffix}", dir=path.parent)
            os.close(handle)
            temporary = Path(name)
            write(temporary)
            os.replace(temporary, path)
            return True
        except OSError as exc:
            problem = _reason(exc)
        except RuntimeError as exc:  # a library's failed write (h5py, HDF5)
            cause = _os_error(exc)
            if cause is None:
                raise
            problem = _reason(cause)
        finally:
            if temporary is not None and temporary.exists():
                temporary.unlink(missing_ok=True)
    say(cache, f"cannot write '{path}' ({problem}): the entry is not kept, the run goes on; "
               f"{cache.hint}", stream)
    return False


def _os_error(exc: BaseException) -> OSError | None:
    current: BaseException | None = exc
    for _ in range(10):
        if current is None:
            return None
        if isinstance(current, OSError):
            return current
        current = current.__cause__ or current.__context__
    return None


def _reason(exc: OSError) -> str:
    return os.strerror(exc.errno) if exc.errno else " ".join(str(exc).split())[:200]


def check_folder(folder: Path, cache: Cache) -> None:
    """Refuse (:class:`CacheError`) a cache folder that is unusable in a way a user must
    fix before anything runs: a file (or broken link) where the folder or one above it
    should be. A read-only folder is not refused here: it costs rebuilds, not results
    (:func:`store` says so when an entry cannot be kept)."""
    problem = folder_problem(Path(folder))
    if problem and "not writable" not in problem:
        raise cache.error(Path(folder), problem)
