"""The reduction cache: its folder, keys, and entries that prove their content."""


from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flex.data.cache import (
    REDUCTION_CACHE,
    content_digest,
    entry_problem,
    number_text,
    say,
)

#: Bump when the content or layout of a cache file changes; old entries are then rebuilt.
CACHE_FORMAT_VERSION = 3  # 2: the chord frame (end_a rotation static modes); 3: the mid-span
# marker reads the section mean (flex.bodies.section_mean)


def reduction_cache_dir(environ: Mapping[str, str]) -> Path:
    """The reduction cache folder named by ``environ`` (a mapping of environment variables,
    e.g. ``os.environ`` read by a command line; this function reads nothing else):
    ``$FLEX_CACHE_DIR/reductions`` if set, else ``$XDG_CACHE_HOME/flex/reductions``, else
    ``~/.cache/flex/reductions`` (``~``: ``$HOME``, or the user's entry in the password
    database when ``environ`` has none), whatever folder the command runs from."""
    home = _home(environ)
    configured = environ.get("FLEX_CACHE_DIR")
    if configured:
        if configured == "~" or configured.startswith("~/"):
            return home / configured[2:] / "reductions"
        return Path(configured).expanduser() / "reductions"  # "~user/..." or a plain path
    base = environ.get("XDG_CACHE_HOME") or home / ".cache"
    return Path(base) / "flex" / "reductions"


def _home(environ: Mapping[str, str]) -> Path:
    """``$HOME`` of ``environ``, else the user's home from the password database."""
    if environ.get("HOME"):
        return Path(environ["HOME"])
    try:
        import pwd

        return Path(pwd.getpwuid(os.getuid()).pw_dir)
    except (ImportError, KeyError):  # no password database (Windows): the platform's rule
        return Path.home()


def _engine_versions() -> dict[str, str]:
    # installed distribution versions: no need to import ngsolve (0.5 s) for a cache hit
    from importlib.metadata import version

    return {"exudyn": version("exudyn"), "ngsolve": version("ngsolve")}


def cache_key(parameters: dict[str, Any]) -> str:
    """A reduction's cache key: its parameters, the cache format and the engines' versions."""
    # repr(float) is exact and canonical, so 0.003 and 3e-3 hash alike, 0.0030000001 not
    canonical = {k: (repr(float(v)) if isinstance(v, float) else v)
                 for k, v in parameters.items()}
    canonical["format_version"] = CACHE_FORMAT_VERSION
    canonical.update(_engine_versions())
    text = json.dumps(canonical, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def fem_content_digest(fem) -> str:
    """SHA-256 over the arrays a simulation uses: detects a damaged file that still opens."""
    digest = hashlib.sha256()
    parts = [fem.GetNodePositionsAsArray(), fem.modeBasis["matrix"], np.asarray(fem.eigenValues)]
    for matrix in (fem.massMatrix, fem.stiffnessMatrix):
        parts += [matrix.data, matrix.indices, matrix.indptr]
    if "matrix" in (fem.postProcessingModes or {}):
        parts.append(fem.postProcessingModes["matrix"])
    for node_set in fem.nodeSets:
        parts += [node_set["NodeNumbers"], node_set["NodeWeights"]]
    for part in parts:
        array = np.ascontiguousarray(part)
        digest.update(str(array.dtype).encode() + str(array.shape).encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def load_cached(path: Path, key: str):
    """Return the FEMinterface stored under ``path`` if it is whole and made for ``key``.

    Returns None for a missing, truncated, foreign or damaged file (the caller rebuilds).
    """
    if not path.is_file():
        return None
    import h5py

    # check with h5py first: FEMinterface.LoadFromFile prints a banner before re-raising
    try:
        with h5py.File(path, "r") as h5:
            stored_key = h5["metaData"]["flex"]["key"][()]
    except Exception:
        return None
    if isinstance(stored_key, bytes):
        stored_key = stored_key.decode()
    if stored_key != key:
        return None
    from exudyn.FEM import FEMinterface

    fem = FEMinterface()
    try:
        fem.LoadFromFile(str(path), mode="HDF5")
        meta = fem.metaData["flex"]
        if (meta["digest"] != fem_content_digest(fem)
                or meta.get("meta_digest") != meta_digest(meta)):
            return None
        n_nodes = fem.NumberOfNodes()
        if fem.modeBasis["matrix"].shape[0] != 3 * n_nodes:
            return None
    except Exception:
        return None
    return fem


def meta_digest(meta: Mapping[str, Any]) -> str:
    """Digest of the entry's own numbers (mass, frequency, ...: read by
    :class:`~flex.bodies.reduction.build.Reduction` as they are stored), beside
    :func:`fem_content_digest` of its arrays."""
    return content_digest((name, number_text(meta[name])) for name in sorted(meta)
                          if name not in ("digest", "meta_digest"))


def say_unproven(path: Path | None) -> None:
    """One line when an existing entry is about to be rebuilt (it did not prove its
    content: damaged, edited, foreign, an older format, or not a file)."""
    if path is None or not path.is_file() or entry_problem(path):
        return  # missing, or not a file: store() says why it cannot be kept
    say(REDUCTION_CACHE, f"entry '{path}' did not prove its content (its key or content "
                         f"digest does not match: damaged, edited, foreign or of an older "
                         f"format); building the reduction again")


#: the old private names, still used by tests/test_hostile_caches.py (to go with that use)

