"""Stress recovery, ``flex export`` and ``flex animate``, read back by independent readers.

- The stored peak von Mises series of an FFRF coupler against a recomputation from the
  principal stresses (``numpy.linalg.eigvalsh`` of each nodal tensor), and ``von_mises``
  against closed forms (uniaxial, pure shear, hydrostatic).
- The exported files read back with **meshio's XDMF time-series reader**
  (``meshio.xdmf.TimeSeriesReader``; and, where the ``vtk`` wheel is installed, with
  ParaView's "XDMF Reader", VTK's ``vtkXdmfReader``: passed here with vtk 9.7 installed by
  hand, skipped without it):
  the reduction's mesh (nodes at the placed reference positions, quadratic tetrahedra), the
  number of times, the units. The exported midpoint deflection equals the stored
  ``coupler/midpoint_deflection`` when rebuilt by its definition (the mid-span section mean of
  the exported quadratic tetrahedra, :func:`flex.bodies.section_mean.section_mean_weights`,
  minus the chord between the joint-face centres,
  :func:`flex.bodies.reduction.midpoint_deflection`) from the exported
  nodes: within 1e-4 of its peak from the mechanism-frame field (float32 storage of
  positions ~0.1 m), 1e-5 from the link-frame field. The exported peak von Mises away from
  the joint faces equals the stored series within 1e-6 (float32).
- Refusals: a result whose stored basis identity does not match the reduction (another
  key, another basis under the same key, none stored) exits 2 with one line; a reduction
  rebuilt from scratch (round-off apart) is accepted.
- The nonlinear FE coupler's nodal field: exported and checked the same way (its markers'
  area weights on the end faces).
- Animations decoded with imageio-ffmpeg (mp4) and Pillow (gif): frame count and size.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest

from flex.api import simulate
from flex.bodies.reduction import midpoint_deflection
from flex.bodies.section_mean import section_mean_weights
from flex.bodies.stress import check_basis_identity, von_mises
from flex.cli import main
from flex.config.settings import pinned_overrides
from flex.data.results import read_case, write_results
from flex.data.scene import load_scene, to_toml
from flex.dynamics.link_models import reduction_for_scene

# a coarse 5 mm plate (maxh 5 mm, 4 modes), 2 ms at the rigid 1e-5 s step, a sample per
# 1e-4 s: 21 samples
PLATE = [*pinned_overrides(), 'coupler.geometry="plate"', "coupler.thickness_m=0.005",
         "coupler.mesh_size_m=0.005", "coupler.modes=4", "simulation.end_time_s=0.002",
         "simulation.output_step_s=1e-4"]
SAMPLES = 21


@pytest.fixture(scope="module")
def ffrf_file(tmp_path_factory, reduction_cache) -> Path:
    scene = load_scene(overrides=[*PLATE, 'coupler.model="ffrf"'])
    path = tmp_path_factory.mktemp("ffrf") / "plate.h5"
    return write_results(path, "simulate", [simulate(scene, "case", cache_dir=reduction_cache)],
                         to_toml(scene))


@pytest.fixture(scope="module")
def nonlinear_file(tmp_path_factory) -> Path:
    plate = [item for item in PLATE if not item.startswith("coupler.modes")]  # no modes
    scene = load_scene(overrides=[*plate, 'coupler.model="nonlinear_fe"',
                                  "simulation.error_estimate=false",
                                  "simulation.end_time_s=0.0004"])
    path = tmp_path_factory.mktemp("nl") / "nl.h5"
    return write_results(path, "simulate", [simulate(scene, "case")], to_toml(scene))


@pytest.fixture(scope="module")
def reduction(ffrf_file, reduction_cache):
    """The reduction of the FFRF case (from the cache its run filled)."""
    scene = load_scene(overrides=[*PLATE, 'coupler.model="ffrf"'])
    return reduction_for_scene(scene, cache_dir=reduction_cache)


def run_cli(capsys, *args: str) -> tuple[int, str, str]:
    status = main([str(arg) for arg in args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


# ------------------------------------------------------------------------------------------
# stress recovery
# ------------------------------------------------------------------------------------------
def test_von_mises_closed_forms():
    sigma, tau, p = 120e6, 50e6, -30e6
    tensors = np.array([[sigma, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, tau], [p, p, p, 0, 0, 0]])
    np.testing.assert_allclose(von_mises(tensors), [sigma, np.sqrt(3) * tau, 0.0],
                               atol=1e-6)


def test_stored_peak_von_mises_matches_principal_stress_recomputation(ffrf_file, reduction):
    data = read_case(ffrf_file, "case")
    q = data["coupler/modal_coordinates"]
    modes = reduction.fem.postProcessingModes["matrix"]
    x = reduction.fem.GetNodePositionsAsArray()[:, 0]
    away = (x >= reduction.thickness_m) & (x <= reduction.length_m - reduction.thickness_m)
    expected, expected_joints = [], []
    for sample in q:
        s = np.stack([modes[:, c::6] @ sample for c in range(6)], axis=1)  # xx yy zz yz xz xy
        tensor = np.stack([s[:, [0, 5, 4]], s[:, [5, 1, 3]], s[:, [4, 3, 2]]], axis=1)
        p = np.linalg.eigvalsh(tensor)
        mises = np.sqrt(((p[:, 0] - p[:, 1]) ** 2 + (p[:, 1] - p[:, 2]) ** 2
                         + (p[:, 2] - p[:, 0]) ** 2) / 2)
        expected.append(mises[away].max())
        expected_joints.append(mises[~away].max())
    stored = data["coupler/peak_von_mises_stress"]
    np.testing.assert_allclose(stored, expected, rtol=1e-9, atol=1e-9 * max(expected))
    np.testing.assert_allclose(data["coupler/peak_von_mises_stress_at_joints"],
                               expected_joints, rtol=1e-9, atol=1e-9 * max(expected_joints))


def test_peak_where_and_when_with_estimate(ffrf_file, reduction, capsys):
    data = read_case(ffrf_file, "case")
    with h5py.File(ffrf_file) as h5:
        attrs = dict(h5["cases/case"].attrs)
    series = data["coupler/peak_von_mises_stress"]
    assert attrs["coupler_peak_von_mises_Pa"] == pytest.approx(series.max(), rel=1e-12)
    assert attrs["coupler_peak_von_mises_time_s"] == data["time"][np.argmax(series)]
    x, _, _ = attrs["coupler_peak_von_mises_position_m"]
    assert reduction.thickness_m <= x <= reduction.length_m - reduction.thickness_m
    x_joint = attrs["coupler_peak_von_mises_at_joints_position_m"][0]
    assert min(x_joint, reduction.length_m - x_joint) <= reduction.thickness_m
    # the attributes come from the stored series (its largest sample evaluated again):
    # the same as a search of the whole run
    from flex.bodies.stress import peak_attrs

    whole_run = peak_attrs("coupler", reduction, data["coupler/modal_coordinates"],
                           data["time"])
    for key, value in whole_run.items():
        np.testing.assert_allclose(attrs[key], value, rtol=1e-12)
    # the headline's error: the whole-run peak on the headline channel, an estimate, the
    # root sum of squares of its terms
    error = attrs["estimated_error_coupler_peak_von_mises_Pa"]
    terms = np.array([attrs[f"estimated_error_coupler_peak_von_mises_Pa_{term}"]
                      for term in ("step", "modes", "mesh", "model")])
    assert 0 < error < np.inf and error == pytest.approx(np.sqrt(np.sum(terms ** 2)), rel=1e-12)
    status, out, _ = run_cli(capsys, "inspect", ffrf_file)
    assert status == 0 and "peak von Mises stress, coupler:" in out and "mm on the plate" in out


# ------------------------------------------------------------------------------------------
# export, read back with meshio
# ------------------------------------------------------------------------------------------
def _read_series(xdmf: Path):
    with meshio.xdmf.TimeSeriesReader(xdmf) as reader:
        points, cells = reader.read_points_cells()
        steps = [reader.read_data(k) for k in range(reader.num_steps)]
    return points, cells, steps


def _deflections(points, steps, body, plate, nodes_a, weights_a, nodes_b, weights_b, mid):
    """The midpoint deflection rebuilt from the exported mechanism-frame and link-frame
    fields of body ``body``."""
    glob, link = {"B": [], "C": [], "M": []}, {"B": [], "C": [], "M": []}
    for _, point_data, _ in steps:
        selected = point_data["body_id"] == body
        reference = point_data["reference_position_link_m"][selected]
        moved = points[selected] + point_data["displacement_m"][selected]
        local = reference + point_data["elastic_displacement_link_m"][selected]
        for out, p in ((glob, moved), (link, local)):
            out["B"].append(weights_a @ p[nodes_a])
            out["C"].append(weights_b @ p[nodes_b])
            out["M"].append(mid[1] @ p[mid[0]])
    return [midpoint_deflection(*(np.array(d[k]) for k in "BCM")).transverse_m
            for d in (glob, link)]


def test_export_reads_back_with_meshio(ffrf_file, reduction, capsys, tmp_path):
    status, out, _ = run_cli(capsys, "export", ffrf_file, "--out", tmp_path, "--every", "3")
    assert status == 0, out
    xdmf = tmp_path / "plate-case.xdmf"
    assert "wrote" in out and xdmf.exists() and (tmp_path / "plate-case.h5").exists()
    points, cells, steps = _read_series(xdmf)
    data = read_case(ffrf_file, "case")
    exported = list(range(0, SAMPLES, 3)) + [SAMPLES - 1]
    assert [t for t, _, _ in steps] == pytest.approx(data["time"][exported], abs=1e-15)
    # the mesh: the reduction's nodes (placed by the first frame pose), then the rigid boxes
    n = reduction.n_nodes
    body = steps[0][1]["body_id"]
    names = json.loads(ET_info(xdmf, "bodies"))
    coupler = int(next(k for k, v in names.items() if v.startswith("coupler")))
    assert np.count_nonzero(body == coupler) == n
    reference = reduction.fem.GetNodePositionsAsArray()
    np.testing.assert_allclose(steps[0][1]["reference_position_link_m"][body == coupler],
                               reference)
    angle, origin = data["coupler/frame_angle"][0], data["coupler/frame_position"][0]
    rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    np.testing.assert_allclose(points[body == coupler][:, :2],
                               origin + reference[:, :2] @ rotation.T, atol=1e-12)
    assert [block.type for block in cells] == ["tetra10"]
    assert len(cells[0].data) == reduction.n_elements + 2 * 5  # + crank and slider boxes
    # units: in the names, the XDMF Information and the HDF5 attributes
    units = json.loads(ET_info(xdmf, "units"))
    assert units["displacement_m"] == "m" and units["von_mises_stress_Pa"] == "Pa"
    assert units["time"] == "s"
    with h5py.File(tmp_path / "plate-case.h5") as h5:
        assert h5["fields/von_mises_stress_Pa/000000"].attrs["units"] == "Pa"
        assert h5["mesh/geometry"].attrs["units"] == "m"
    # the midpoint deflection by its definition, from the exported nodes
    own = np.flatnonzero(body == coupler)  # the coupler's nodes, in the reduction's order
    local = np.full(len(points), -1)
    local[own] = np.arange(len(own))
    corners = local[cells[0].data[np.all(np.isin(cells[0].data, own), axis=1)][:, :4]]
    mid = section_mean_weights(reference, corners, reduction.length_m / 2)
    from_global, from_link = _deflections(
        points, steps, coupler, reduction, reduction.nodes_end_a, reduction.weights_end_a,
        reduction.nodes_end_b, reduction.weights_end_b, mid)
    stored = data["coupler/midpoint_deflection"][exported]
    peak = np.abs(data["coupler/midpoint_deflection"]).max()
    assert peak > 1e-7  # the plate bends: the comparison means something
    np.testing.assert_allclose(from_global, stored, rtol=0, atol=1e-4 * peak)
    np.testing.assert_allclose(from_link, stored, rtol=0, atol=1e-5 * peak)
    # the exported peak stress away from the joint faces equals the stored one
    x = reference[:, 0]
    away = (x >= reduction.thickness_m) & (x <= reduction.length_m - reduction.thickness_m)
    peaks = [point_data["von_mises_stress_Pa"][body == coupler][away].max()
             for _, point_data, _ in steps]
    np.testing.assert_allclose(peaks, data["coupler/peak_von_mises_stress"][exported],
                               rtol=1e-6)
    assert np.all(np.isnan(steps[0][1]["von_mises_stress_Pa"][body != coupler]))


def ET_info(xdmf: Path, name: str) -> str:  # noqa: N802 - reads an XDMF Information value
    import xml.etree.ElementTree as ET

    for item in ET.parse(xdmf).getroot().iter("Information"):
        if item.get("Name") == name:
            return item.get("Value")
    raise KeyError(name)


def _tampered(source: Path, folder: Path, change) -> Path:
    target = folder / "tampered.h5"
    shutil.copyfile(source, target)
    with h5py.File(target, "r+") as h5:
        change(h5["cases/case"].attrs)
    return target


@pytest.mark.parametrize(("change", "words"), [
    (lambda a: a.__setitem__("coupler_reduction_key", "0" * 24), "cache key"),
    (lambda a: (a.__setitem__("coupler_reduction_basis_sha256", "x"),
                a.__setitem__("coupler_reduction_basis_fingerprint",
                              a["coupler_reduction_basis_fingerprint"] * 1.001)),
     "fingerprint does not match"),
    (lambda a: a.__delitem__("coupler_reduction_key"), "stores no identity"),
])
def test_export_refuses_a_basis_that_does_not_match(ffrf_file, tmp_path, capsys, change, words):
    tampered = _tampered(ffrf_file, tmp_path, change)
    status, out, err = run_cli(capsys, "export", tampered, "--out", tmp_path / "out")
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("flex: error:") and words in err
    assert not (tmp_path / "out" / "tampered-case.xdmf").exists()


def test_a_rebuilt_reduction_is_the_same_basis(ffrf_file, reduction):
    from flex.bodies.reduction import build_reduction

    rebuilt = build_reduction(reduction.plate, reduction.mesh_size_m, reduction.modes, None,
                              mode_selection=reduction.mode_selection)
    with h5py.File(ffrf_file) as h5:
        attrs = dict(h5["cases/case"].attrs)
    assert check_basis_identity("coupler", rebuilt, attrs) is None
    # while a basis of one mode more is refused, and so is a reordered one
    attrs_reordered = dict(attrs, coupler_reduction_basis_sha256="",
                           coupler_reduction_basis_fingerprint=attrs[
                               "coupler_reduction_basis_fingerprint"][::-1])
    assert "fingerprint" in check_basis_identity("coupler", rebuilt, attrs_reordered)


def test_nonlinear_fe_nodal_field_exports(nonlinear_file, tmp_path):
    from flex.tools.export import export_case

    data = read_case(nonlinear_file, "case")
    assert data["coupler/nodal/position"].shape[0] == len(data["coupler/nodal/time"]) == 5
    done = export_case(nonlinear_file, None, tmp_path, progress=None)
    points, cells, steps = _read_series(done.xdmf)
    names = json.loads(ET_info(done.xdmf, "bodies"))
    coupler = int(next(k for k, v in names.items() if v == "coupler (nonlinear_fe)"))
    plate = done.motion.link_model("coupler")  # its markers' node sets and area weights
    from_global, from_link = _deflections(
        points, steps, coupler, plate, plate.nodes_end_a, plate.weights_end_a,
        plate.nodes_end_b, plate.weights_end_b, (plate.nodes_mid, plate.weights_mid))
    sample = np.searchsorted(data["time"], data["coupler/nodal/time"] - 1e-9)
    stored = data["coupler/midpoint_deflection"][sample]
    peak = np.abs(stored).max()
    assert peak > 1e-8
    np.testing.assert_allclose(from_global, stored, rtol=0, atol=1e-4 * peak)
    np.testing.assert_allclose(from_link, stored, rtol=0, atol=1e-4 * peak)


def test_export_of_a_rigid_case_is_refused(tmp_path, capsys):
    scene = load_scene(overrides=["simulation.end_time_s=0.001",
                                  "simulation.error_estimate=false"])
    path = write_results(tmp_path / "rigid.h5", "simulate", [simulate(scene, "case")],
                         to_toml(scene))
    status, _, err = run_cli(capsys, "export", path, "--out", tmp_path)
    assert status == 2 and "no flexible link" in err


# ------------------------------------------------------------------------------------------
# animation, decoded
# ------------------------------------------------------------------------------------------
def test_mp4_animation_decodes_to_its_frames(ffrf_file, tmp_path, capsys):
    import imageio_ffmpeg

    status, out, _ = run_cli(capsys, "animate", ffrf_file, "--out", tmp_path / "a.mp4",
                             "--frames", "12")
    assert status == 0 and "12 frames" in out
    reader = imageio_ffmpeg.read_frames(str(tmp_path / "a.mp4"))
    meta = next(reader)
    frames = [frame for frame in reader]
    assert meta["size"] == (960, 540) and len(frames) == 12
    assert len(frames[0]) == 960 * 540 * 3
    pixels = np.frombuffer(frames[6], np.uint8).reshape(540, 960, 3)
    assert pixels.std() > 10  # a drawing, not a blank frame


def test_gif_animation_decodes_to_its_frames(ffrf_file, tmp_path, capsys):
    from PIL import Image

    status, _, _ = run_cli(capsys, "animate", ffrf_file, "--out", tmp_path / "a.gif",
                           "--frames", "8", "--magnification", "100")
    assert status == 0
    with Image.open(tmp_path / "a.gif") as image:
        assert image.size == (960, 540) and image.n_frames == 8


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_run_simulate_animate_writes_beside_the_figures(tmp_path, capsys):
    status, out, _ = run_cli(capsys, "run", "simulate", *[x for o in PLATE for x in ("--set", o)],
                             "--set", 'coupler.model="ffrf"', "--set",
                             "simulation.error_estimate=false", "--out", tmp_path / "s.h5",
                             "--no-figures", "--animate")
    assert status == 0
    animation = tmp_path / "figures" / "s-case.mp4"
    assert animation.exists() and f"wrote {animation}" in out


def test_vtk_xdmf_reader_reads_the_export(ffrf_file, reduction, tmp_path, capsys):
    """ParaView's "XDMF Reader" is VTK's vtkXdmfReader: run only where the vtk wheel is
    installed (not a dependency; ``pip install vtk``)."""
    xdmf2 = pytest.importorskip("vtkmodules.vtkIOXdmf2")
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline

    assert run_cli(capsys, "export", ffrf_file, "--out", tmp_path, "--every", "5")[0] == 0
    reader = xdmf2.vtkXdmfReader()
    reader.SetFileName(str(tmp_path / "plate-case.xdmf"))
    reader.UpdateInformation()
    times = reader.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS())
    assert len(times) == len(range(0, SAMPLES, 5))
    reader.UpdateTimeStep(times[2])
    grid = reader.GetOutputDataObject(0)
    assert grid.GetCellType(0) == 24  # VTK_QUADRATIC_TETRA
    assert grid.GetNumberOfCells() == reduction.n_elements + 2 * 5
    stress = vtk_to_numpy(grid.GetPointData().GetArray("von_mises_stress_Pa"))
    assert np.nanmax(stress) > 0
