"""The FFRF body's constant matrices, cached beside their reduction.

Exudyn's ``ObjectFFRFreducedOrderInterface`` projects the full mass matrix on the mode basis
and its skew companions when it is made (``ComputeSkewMatrix`` loops over the nodes in Python:
measured 0.19 s for a 1 mm plate's 2-mode reduction, as long as the run it serves). The
result depends on the reduction alone, so it is kept as ``<key>.ffrf.hdf5`` beside the
reduction's entry (the rules of :mod:`flex.data.cache`: a content digest, an atomic write)
and read back with the library's own ``SetWithDictionary``. The arrays the reduction already
holds (mode basis, nodes, surface, stress modes) are not stored twice.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from flex.data.cache import REDUCTION_CACHE, content_digest, say, store

#: bump when the stored arrays change
INTERFACE_FORMAT_VERSION = 1
_SUFFIX = ".ffrf.hdf5"
#: the interface's derived arrays (``GetDictionary`` keys computed from the reduction)
DERIVED = ("massMatrixReduced", "stiffnessMatrixReduced", "infoList", "inertiaLocal", "Mtt",
           "totalMass", "chiU", "chiUtilde", "mPsiTildePsi", "mPsiTildePsiTilde",
           "mPhitTPsi", "mPhitTPsiTilde", "mXRefTildePsi", "mXRefTildePsiTilde")
_NODE_TYPE = "NodeType.RotationEulerParameters"


def _digest(arrays: dict[str, np.ndarray]) -> str:
    return content_digest((name, np.asarray(arrays[name])) for name in DERIVED)


def _basis_digest(fem: Any) -> str:
    return content_digest([("basis", np.asarray(fem.modeBasis["matrix"])),
                           ("nodes", fem.GetNodePositionsAsArray())])


def interface_path(cache_file: Path | None, key: str) -> Path | None:
    """Where the interface of the reduction cached at ``cache_file`` is kept (None: the
    reduction is not cached, neither is its interface)."""
    return None if cache_file is None else Path(cache_file).with_name(f"{key}{_SUFFIX}")


def ffrf_interface(fem: Any, path: Path | None, made: Any = None) -> Any:
    """The ``ObjectFFRFreducedOrderInterface`` of ``fem`` (an Exudyn FEMinterface): ``made``
    if given (one just made for it, then stored at ``path``), else read from ``path`` when
    that entry is whole and made for this basis, else made by Exudyn (and stored at
    ``path``, if given)."""
    basis = _basis_digest(fem)
    if made is None and path is not None and path.is_file():
        arrays = _load(path, basis)
        if arrays is not None:
            return _restored(fem, arrays)
    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    interface = made or ObjectFFRFreducedOrderInterface(fem, rigidBodyNodeType=_NODE_TYPE)
    if path is not None:
        data = interface.GetDictionary()
        _save(path, {name: np.asarray(data[name]) for name in DERIVED}, basis)
    return interface


def _restored(fem: Any, arrays: dict[str, np.ndarray]) -> Any:
    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    interface = ObjectFFRFreducedOrderInterface()
    data = dict(arrays, modeBasis=np.asarray(fem.modeBasis["matrix"]),
                trigList=fem.GetSurfaceTriangles6() or fem.GetSurfaceTriangles(),
                postProcessingModes=fem.postProcessingModes,
                xRef=fem.GetNodePositionsAsArray().flatten(), rigidBodyNodeType=_NODE_TYPE)
    data["totalMass"] = float(arrays["totalMass"])
    interface.SetWithDictionary(data)
    # what Exudyn's LoadFromFile adds after SetWithDictionary: the FFRF mass matrix's
    # constant blocks
    size = int(interface.nODE2FFRFreduced)
    interface.massMatrixFFRFreduced = np.zeros((size, size))
    interface.massMatrixFFRFreduced[0:3, 0:3] = interface.Mtt
    rigid = int(interface.nODE2rigid)
    interface.massMatrixFFRFreduced[rigid:, rigid:] = interface.massMatrixReduced
    return interface


def _load(path: Path, basis: str) -> dict[str, np.ndarray] | None:
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            if (h5.attrs["format_version"] != INTERFACE_FORMAT_VERSION
                    or h5.attrs["basis_digest"] != basis):
                return None
            arrays = {name: h5[name][()] for name in DERIVED}
            stored = h5.attrs.get("content_digest")
    except Exception:  # missing, truncated or foreign: made again by the caller
        say(REDUCTION_CACHE, f"FFRF interface entry '{path}' cannot be read; making it again")
        return None
    if stored != _digest(arrays):
        say(REDUCTION_CACHE, f"FFRF interface entry '{path}' did not prove its content "
                             f"(damaged or edited); making it again")
        return None
    return arrays


def _save(path: Path, arrays: dict[str, np.ndarray], basis: str) -> None:
    import h5py

    def write(temporary: Path) -> None:
        with h5py.File(temporary, "w") as h5:
            for name in DERIVED:
                h5[name] = arrays[name]
            h5.attrs.update(format_version=INTERFACE_FORMAT_VERSION, basis_digest=basis,
                            content_digest=_digest(arrays))

    store(path, write, REDUCTION_CACHE)


__all__ = ["DERIVED", "INTERFACE_FORMAT_VERSION", "ffrf_interface", "interface_path"]
