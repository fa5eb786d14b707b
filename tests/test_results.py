"""Result files: units everywhere, provenance, atomic replacement, clear errors."""

import h5py
import numpy as np
import pytest

from flex.base.errors import ResultFileError
from flex.data.results import CaseResult, Dataset, open_results, read_case, write_results
from flex.study import run_study


@pytest.fixture(scope="module")
def kinematics_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("res") / "kinematics.h5"
    run_study("kinematics", overrides=["simulation.end_time_s=0.1"], out=path, figures=False,
              quiet=True)
    return path


def test_every_dataset_has_units_and_root_has_provenance(kinematics_file):
    with open_results(kinematics_file) as h5:
        missing = []
        h5.visititems(lambda name, obj: missing.append(name)
                      if isinstance(obj, h5py.Dataset) and "units" not in obj.attrs else None)
        assert missing == []
        for key in ("flex_version", "git_commit", "git_dirty", "exudyn_version",
                    "ngsolve_version", "scene_toml", "created_utc"):
            assert h5.attrs[key], key
        assert "end_time_s = 0.1" in h5.attrs["scene_toml"]
        case = h5["cases/constant_speed"]
        assert case.attrs["status"] == "ok"
        assert "spectral_radius" in case.attrs["solver_settings_toml"]
        assert case["time"].attrs["units"] == "s"


def test_read_case(kinematics_file):
    data = read_case(kinematics_file, "constant_speed")
    assert data["time"][-1] == pytest.approx(0.1)
    with pytest.raises(ResultFileError, match="no case 'nope'"):
        read_case(kinematics_file, "nope")


def test_missing_foreign_and_broken_files_are_named(tmp_path):
    with pytest.raises(ResultFileError, match="does not exist"):
        open_results(tmp_path / "none.h5")
    text = tmp_path / "text.h5"
    text.write_text("not hdf5")
    with pytest.raises(ResultFileError, match="is not an HDF5 file"):
        open_results(text)
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as h5:
        h5["x"] = np.arange(3)
    with pytest.raises(ResultFileError, match="not written by flex"):
        open_results(foreign)


def test_truncated_file_is_refused(kinematics_file, tmp_path):
    cut = tmp_path / "cut.h5"
    cut.write_bytes(kinematics_file.read_bytes()[:4000])
    with pytest.raises(ResultFileError, match=str(cut.name)):
        open_results(cut)


def test_failed_write_leaves_previous_file_intact(tmp_path):
    path = tmp_path / "r.h5"
    good = CaseResult("a", "", {"time": Dataset(np.arange(3.0), "s")})
    write_results(path, "demo", [good])
    before = path.read_bytes()
    bad = CaseResult("b", "", {"time": Dataset(object(), "s")})  # cannot be stored
    with pytest.raises(TypeError):
        write_results(path, "demo", [good, bad])
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["r.h5"]  # no temporary left behind


def test_a_declared_table_becomes_one_dataset_per_column_and_reads_back(tmp_path):
    from flex.data.tables import table_datasets

    rows = [{"name": "a", "time": 0.5, "steps": 3, "ok": True},
            {"name": "b", "time": 1.5, "steps": 4, "ok": False}]
    columns = {"name": ("1", "case"), "time": ("s", "wall time"),
               "steps": ("1", "time steps", float), "ok": ("1", "within tolerance")}
    datasets = table_datasets(rows, columns, "runs")
    assert list(datasets) == ["runs/name", "runs/time", "runs/steps", "runs/ok"]
    assert datasets["runs/time"].units == "s" and datasets["runs/time"].description == "wall time"
    assert datasets["runs/name"].data.dtype == object  # text stays Python strings
    assert datasets["runs/steps"].data.dtype == float  # the declared dtype wins
    assert datasets["runs/ok"].data.dtype == bool
    empty = table_datasets([], columns)
    assert list(empty) == list(columns) and empty["name"].data.shape == (0,)
    with pytest.raises(KeyError):
        table_datasets([{"name": "c"}], columns)  # a row without a declared column
    path = tmp_path / "table.h5"
    write_results(path, "demo", [CaseResult("c", "", datasets)])
    with h5py.File(path) as h5:
        assert [v.decode() for v in h5["cases/c/runs/name"][()]] == ["a", "b"]
        np.testing.assert_array_equal(h5["cases/c/runs/time"][()], [0.5, 1.5])
        assert h5["cases/c/runs/time"].attrs["units"] == "s"


def test_an_empty_text_column_is_written(tmp_path):
    # a study summary whose cases all failed has empty object-dtype text columns: h5py cannot
    # guess their type ("Object dtype dtype('O') has no native HDF5 equivalent", an internal
    # error of make calibrate); they are written as (empty) string datasets
    summary = {"names": Dataset(np.array([], dtype=object), "1", "case names"),
               "labels": Dataset(np.array(["a", "b"], dtype=object), "1", "labels")}
    path = write_results(tmp_path / "empty.h5", "demo", [], "", summary)
    with h5py.File(path) as f:
        assert f["summary/names"].shape == (0,)
        assert [v.decode() for v in f["summary/labels"][()]] == ["a", "b"]
