"""``flex export``: a stored case's bodies and nodal fields as XDMF + HDF5 (ParaView, meshio).

:func:`export_case` writes ``<out>/<stem>-<case>.xdmf`` and its data ``<stem>-<case>.h5``
(``stem``: the result file's). One unstructured mesh holds every body of the mechanism
(:mod:`flex.tools.motion`): each flexible link's plate mesh (quadratic tetrahedra, the
reduction's or the nonlinear FE body's nodes first, in mesh order) followed by the rigid
links and the slider as boxes. Its geometry is the mechanism at the case's first sample
(mechanism frame, metres). One XDMF grid per exported time (every stored sample, or every
``every``-th and the last one) holds the point fields, units in their names, in the HDF5
datasets' ``units`` attributes and in the XDMF ``Information`` element ``units``:

- ``displacement_m``: from the first sample's position, mechanism frame (ParaView's "Warp
  By Vector" with it shows the motion);
- ``elastic_displacement_link_m``: elastic displacement in the link's frame (FFRF: the
  floating frame, ``Phi q``; nonlinear FE: the chord frame B-C); zero on rigid bodies;
- ``von_mises_stress_Pa``, ``sigma_xx_Pa``: recovered nodal stress of an FFRF link (axial
  component along the link, body axes); NaN where none is recovered (rigid bodies, the
  nonlinear FE coupler);
- ``body_id`` (see the ``bodies`` Information) and ``reference_position_link_m`` (body
  coordinates of each node), the same at every time.

Field datasets are written per time (``/fields/<name>/<index>``), gzip-compressed. Before
writing, the export says what it will write (times, nodes, :func:`estimate_bytes`, the free
space) and refuses when the estimate exceeds the free space; an existing output that flex did
not write is refused (unless ``force``). The HDF5 file is built in memory and both files are
written under temporary names beside their targets and renamed when complete: a full disk
mid-write is one line, with no partial file left.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from flex import __version__
from flex.base.errors import OutputError
from flex.base.progress import REPORT_INTERVAL_S
from flex.data.outputs import check_replaceable, check_writable_folder, free_bytes, has_marker
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel
from flex.tools.motion import CaseMotion, case_motion, pick_case, sample_indices

#: point fields written at every time: name -> (units, description)
FIELDS = {
    "displacement_m": ("m", "displacement from the case's first sample, mechanism frame"),
    "elastic_displacement_link_m": ("m", "elastic displacement in the link's frame (FFRF: "
                                         "floating frame; nonlinear FE: chord frame B-C; "
                                         "rigid: 0)"),
    "von_mises_stress_Pa": ("Pa", "nodal von Mises stress (FFRF links; NaN: not recovered)"),
    "sigma_xx_Pa": ("Pa", "nodal axial stress along the link, body axes (FFRF links; NaN: "
                          "not recovered)"),
}
#: point fields that do not change with time, written once: name -> (units, description)
CONSTANT_FIELDS = {
    "body_id": ("1", "body of each node (XDMF Information 'bodies')"),
    "reference_position_link_m": ("m", "node position in its body's coordinates"),
}
#: storage type of the per-time fields: 7 significant digits (a viewer's precision; the
#: result file keeps the run's own numbers), half the size of float64
FIELD_DTYPE = np.float32
#: seconds between two progress lines
PROGRESS_INTERVAL_S = REPORT_INTERVAL_S
#: HDF5 bookkeeping of one compressed dataset with its attributes [bytes], measured ~1.9 kB
DATASET_OVERHEAD_BYTES = 2500


@dataclass
class ExportOutput:
    """What :func:`export_case` wrote."""

    xdmf: Path
    hdf5: Path
    times: int
    nodes: int
    cells: int
    bytes_written: int
    motion: CaseMotion


def output_paths(source: str | Path, case: str, out_dir: str | Path) -> tuple[Path, Path]:
    """``<out_dir>/<stem>-<case>.xdmf`` and ``.h5`` for result file ``source``."""
    stem = f"{Path(source).stem}-{case}"
    return Path(out_dir) / f"{stem}.xdmf", Path(out_dir) / f"{stem}.h5"


def _stderr(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def export_case(source: str | Path, case: str | None, out_dir: str | Path, every: int = 1,
                *, cache_dir: Path | None = None,
                progress: Callable[[str], None] | None = _stderr,
                force: bool = False,
                link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> ExportOutput:
    """Export ``case`` of result file ``source`` to ``out_dir`` (created if missing); see the
    module doc. ``every``: export every n-th stored time (and the last). ``cache_dir``: the
    reduction cache folder. Refusals (:class:`FlexError`, one line, nothing changed): those
    of :func:`flex.tools.motion.case_motion`, a bad ``every``, an output folder that cannot
    be made, an existing output file flex did not write (unless ``force``), less free space
    than :func:`estimate_bytes`, and a write that fails (a full disk: the partial files are
    removed). ``progress``: where the size estimate and progress lines go (None: nowhere).
    The HDF5 file is assembled in memory (about its compressed size) and then written.
    ``link_models``: the registry the case's models are read from."""
    sample_indices(1, every)  # a bad --every is refused before anything is read
    if not str(out_dir).strip():  # '' was the current folder
        raise OutputError(f"--out {str(out_dir)!r}: an empty folder name; give the output "
                          f"folder (e.g. exported/, or . for the current one)")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {out}: is a file, not a folder")
    xdmf, hdf5 = output_paths(source, pick_case(source, case), out)
    check_replaceable(hdf5, _ours_hdf5, "flex export: output", force)
    check_replaceable(xdmf, _ours_xdmf, "flex export: output", force)
    check_writable_folder(out, f"--out {out}")
    motion = case_motion(source, case, cache_dir=cache_dir, link_models=link_models)
    indices = sample_indices(len(motion.time_s), every)
    nodes = sum(len(body.reference_m) for body in motion.bodies)
    estimate = estimate_bytes(len(indices), nodes, sum(len(b.cells) for b in motion.bodies))
    free = free_bytes(out)
    if estimate > free:
        raise OutputError(f"--out {out}: the export needs up to {size_text(estimate)} "
                          f"({len(indices)} times x {nodes} nodes, before compression) but "
                          f"{size_text(free)} is free there: free space, choose another "
                          f"--out, or export fewer times (--every N); nothing was written")
    if progress:
        progress(f"flex export: {motion.case}: {len(indices)} times x {nodes} nodes, up to "
                 f"{size_text(estimate)} ({size_text(free)} free) -> {xdmf} and {hdf5.name}")
    _place(out, (hdf5, xdmf), lambda parts: _write_both(parts, hdf5.name, motion, indices,
                                                        nodes, progress))
    return ExportOutput(xdmf, hdf5, len(indices), nodes, sum(len(b.cells) for b in motion.bodies),
                        hdf5.stat().st_size + xdmf.stat().st_size, motion)


def estimate_bytes(times: int, nodes: int, cells: int) -> int:
    """Upper estimate of an export's size [bytes], as if nothing compressed: 8 float32
    values a node and time, HDF5's bookkeeping of the 4 datasets a time (about
    :data:`DATASET_OVERHEAD_BYTES` each), the mesh (geometry, Tet10 topology), the constant
    fields and the XDMF file (about 500 bytes a time)."""
    return (times * (nodes * 8 * np.dtype(FIELD_DTYPE).itemsize
                     + len(FIELDS) * DATASET_OVERHEAD_BYTES + 500)
            + nodes * (24 + 4 + 24) + cells * 10 * 8 + 16 * DATASET_OVERHEAD_BYTES)


def size_text(count: float) -> str:
    """A byte count for a person: ``12 kB``, ``3.4 MB``, ``291 MB``, ``1.2 GB``."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if count >= scale:
            return f"{count / scale:.3g} {unit}"
    return f"{count:.0f} bytes"


def _write_both(parts: tuple[Path, Path], h5name: str, motion: CaseMotion,
                indices: np.ndarray, nodes: int,
                progress: Callable[[str], None] | None) -> None:
    image, cells = _hdf5_image(motion, indices, progress)
    with parts[0].open("wb") as file:
        file.write(image)
    del image
    _write_xdmf(parts[1], h5name, motion, indices, nodes, cells)


def _place(out: Path, targets: tuple[Path, ...],
           write: Callable[[tuple[Path, ...]], None]) -> None:
    """Call ``write`` with private names beside ``targets`` and move each into place when
    all are written; an OSError (a full disk) or an interrupt leaves no private file and no
    target changed (one line, :class:`OutputError`)."""
    parts = tuple(_part(target) for target in targets)
    made = not out.exists()
    try:
        out.mkdir(parents=True, exist_ok=True)
        write(parts)
        for part, target in zip(parts, targets, strict=True):
            os.replace(part, target)
    except OSError as exc:
        for part in parts:
            part.unlink(missing_ok=True)
        if made:
            with contextlib.suppress(OSError):
                out.rmdir()  # the folder this export made, empty again
        raise OutputError(f"cannot write {' and '.join(str(t) for t in targets)}: "
                          f"{exc.strerror or exc}; the partial files were removed and no "
                          f"existing file was changed") from None
    finally:
        for part in parts:
            part.unlink(missing_ok=True)


def _ours_hdf5(path: Path) -> bool:
    """Whether ``path`` is an HDF5 file flex export wrote (its root provenance)."""
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            return "flex_version" in h5.attrs and "mesh/topology" in h5
    except (OSError, ValueError):
        return False


def _ours_xdmf(path: Path) -> bool:
    """Whether ``path`` is an XDMF file flex export wrote (its ``source`` Information)."""
    return has_marker(path, b'Name="source" Value=') and has_marker(path, b"(flex ")


def _part(path: Path) -> Path:
    return path.with_name(f".{path.name}.{os.getpid()}.part")


def _mesh(motion: CaseMotion) -> dict[str, np.ndarray]:
    """Geometry (the first sample), Tet10 topology and the constant fields of all bodies."""
    states = motion.states(0)
    geometry, topology, body_id, reference = [], [], [], []
    offset = 0
    for number, body in enumerate(motion.bodies):
        geometry.append(states[body.name].position_m)
        topology.append(body.cells + offset)
        body_id.append(np.full(len(body.reference_m), number, dtype=np.int32))
        reference.append(body.reference_m)
        offset += len(body.reference_m)
    return {"geometry": np.vstack(geometry), "topology": np.vstack(topology),
            "body_id": np.concatenate(body_id), "reference_position_link_m": np.vstack(reference)}


def _fields(motion: CaseMotion, index: int, geometry: np.ndarray) -> dict[str, np.ndarray]:
    """The time-dependent point fields at motion sample ``index``."""
    from flex.bodies.stress import von_mises

    states = motion.states(index)
    position, elastic, mises, axial = [], [], [], []
    for body in motion.bodies:
        state = states[body.name]
        position.append(state.position_m)
        elastic.append(state.elastic_m)
        if state.stress_Pa is None:
            mises.append(np.full(len(state.position_m), np.nan))
            axial.append(np.full(len(state.position_m), np.nan))
        else:
            mises.append(von_mises(state.stress_Pa))
            axial.append(state.stress_Pa[:, 0])
    return {"displacement_m": np.vstack(position) - geometry,
            "elastic_displacement_link_m": np.vstack(elastic),
            "von_mises_stress_Pa": np.concatenate(mises),
            "sigma_xx_Pa": np.concatenate(axial)}


def _dataset(group, name: str, data: np.ndarray, units: str, description: str) -> None:
    compress = {"compression": "gzip", "compression_opts": 4, "shuffle": True} \
        if np.size(data) > 64 else {}
    created = group.create_dataset(name, data=data, **compress)
    created.attrs["units"] = units
    created.attrs["description"] = description


def _hdf5_image(motion: CaseMotion, indices: np.ndarray,
                progress: Callable[[str], None] | None) -> tuple[bytes, int]:
    """The HDF5 file's bytes (built in memory: HDF5 writing to a disk that fills leaves the
    library in a state that crashes the interpreter) and the number of cells."""
    import h5py

    with h5py.File(f"flex-export-{id(motion)}.h5", "w", driver="core",
                   backing_store=False) as h5:
        cells = _fill_hdf5(h5, motion, indices, progress)
        h5.flush()
        return h5.id.get_file_image(), cells


def _fill_hdf5(h5, motion: CaseMotion, indices: np.ndarray,
               progress: Callable[[str], None] | None) -> int:
    """Fill the HDF5 file ``h5``: mesh, constant fields, times and per-time fields; returns
    the number of cells."""
    mesh = _mesh(motion)
    start = last = time.monotonic()
    h5.attrs.update(_provenance(motion))
    _dataset(h5, "mesh/geometry", mesh["geometry"], "m",
             "node positions at the case's first sample, mechanism frame")
    _dataset(h5, "mesh/topology", mesh["topology"], "1",
             "quadratic tetrahedra (VTK node order), node indices")
    for name, (units, description) in CONSTANT_FIELDS.items():
        _dataset(h5, f"constant/{name}", mesh[name], units, description)
    _dataset(h5, "time", motion.time_s[indices], "s", "exported times")
    _dataset(h5, "sample", motion.sample[indices], "1",
             "index of each exported time in the case's time")
    for count, index in enumerate(indices):
        for name, values in _fields(motion, int(index), mesh["geometry"]).items():
            _dataset(h5, f"fields/{name}/{count:06d}", values.astype(FIELD_DTYPE),
                     *FIELDS[name])
        now = time.monotonic()
        if progress and now - last >= PROGRESS_INTERVAL_S:
            last = now
            progress(f"flex export: time {count + 1} of {len(indices)} "
                     f"({now - start:.0f} s)")
    return len(mesh["topology"])


def _provenance(motion: CaseMotion) -> dict[str, Any]:
    """Root attributes of the HDF5 file: where it came from."""
    out: dict[str, Any] = {"flex_version": __version__, "source": str(motion.source),
                           "case": motion.case, "time_units": "s",
                           "bodies": json.dumps(_bodies(motion))}
    for link in ("crank", "coupler"):
        for key in ("reduction_key", "reduction_basis_sha256"):
            if f"{link}_{key}" in motion.attrs:
                out[f"{link}_{key}"] = str(motion.attrs[f"{link}_{key}"])
    return out


def _bodies(motion: CaseMotion) -> dict[str, str]:
    return {str(number): f"{body.name} ({body.model})"
            for number, body in enumerate(motion.bodies)}


def _data_item(parent, file: str, h5path: str, shape: tuple[int, ...], dtype: np.dtype):
    kind = {"f": "Float", "i": "Int", "u": "UInt"}[np.dtype(dtype).kind]
    item = ET.SubElement(parent, "DataItem", DataType=kind,
                         Dimensions=" ".join(str(n) for n in shape), Format="HDF",
                         Precision=str(np.dtype(dtype).itemsize))
    item.text = f"{file}:{h5path}"
    return item


def _write_xdmf(path: Path, h5name: str, motion: CaseMotion, indices: np.ndarray,
                nodes: int, cells: int) -> None:
    """The XDMF 3 file: one temporal collection, one uniform grid per time, every grid on
    the same geometry and topology datasets."""
    root = ET.Element("Xdmf", Version="3.0")
    domain = ET.SubElement(root, "Domain")
    units = {"time": "s", **{name: units for name, (units, _) in FIELDS.items()},
             **{name: units for name, (units, _) in CONSTANT_FIELDS.items()}}
    ET.SubElement(domain, "Information", Name="units", Value=json.dumps(units))
    ET.SubElement(domain, "Information", Name="bodies", Value=json.dumps(_bodies(motion)))
    ET.SubElement(domain, "Information", Name="source",
                  Value=f"{motion.source} case {motion.case} (flex {__version__})")
    series = ET.SubElement(domain, "Grid", Name=motion.case, GridType="Collection",
                           CollectionType="Temporal")
    for count, index in enumerate(indices):
        grid = ET.SubElement(series, "Grid", Name=f"t{count:06d}", GridType="Uniform")
        topology = ET.SubElement(grid, "Topology", TopologyType="Tetrahedron_10",
                                 NumberOfElements=str(cells))
        _data_item(topology, h5name, "/mesh/topology", (cells, 10), np.int64)
        geometry = ET.SubElement(grid, "Geometry", GeometryType="XYZ")
        _data_item(geometry, h5name, "/mesh/geometry", (nodes, 3), np.float64)
        ET.SubElement(grid, "Time", Value=repr(float(motion.time_s[index])))
        for name, folder, width, dtype in (
                *((n, f"fields/{n}/{count:06d}", 3 if "displacement" in n else 1, FIELD_DTYPE)
                  for n in FIELDS),
                ("body_id", "constant/body_id", 1, np.int32),
                ("reference_position_link_m", "constant/reference_position_link_m", 3,
                 np.float64)):
            attribute = ET.SubElement(grid, "Attribute", Name=name, Center="Node",
                                      AttributeType="Vector" if width == 3 else "Scalar")
            _data_item(attribute, h5name, f"/{folder}",
                       (nodes, 3) if width == 3 else (nodes,), dtype)
    ET.indent(root)
    path.write_text('<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n")


__all__ = ["CONSTANT_FIELDS", "FIELDS", "ExportOutput", "estimate_bytes", "export_case",
           "output_paths", "size_text"]
