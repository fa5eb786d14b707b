"""``python -m flex inspect | plot | compare`` and the xarray view, on real study output."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import matplotlib
import numpy as np
import pytest

from flex.base.errors import ResultFileError
from flex.cli import main
from flex.data.results import CaseResult, Dataset, select_datasets, to_xarray, write_results
from flex.study import run_study
from flex.tools.compare import common_time_base, compare_files, resample
from flex.tools.inspect import describe
from flex.tools.plotcurves import plot_curves

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def study_files(tmp_path_factory) -> dict[str, Path]:
    """Every study's output, short runs: kinematics (one case), dynamics (two cases),
    simulate (one case named ``case``)."""
    folder = tmp_path_factory.mktemp("results")
    files = {}
    for study, overrides in (("kinematics", ["simulation.end_time_s=0.2"]),
                             ("dynamics", []),
                             ("simulate", ["simulation.end_time_s=0.01"])):
        files[study] = folder / f"{study}.h5"
        run_study(study, overrides=overrides, out=files[study], figures=False, quiet=True)
    return files


def run_cli(capsys, *args: str) -> tuple[int, str, str]:
    status = main([str(a) for a in args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


# --- inspect ----------------------------------------------------------------------------

def test_inspect_lists_cases_datasets_units_provenance_and_scene(study_files, capsys):
    status, out, _ = run_cli(capsys, "inspect", study_files["dynamics"])
    assert status == 0
    # 6001 samples: the case reports its step's finest companion (h / 2) with its budget
    for fragment in ("study    dynamics", "cases/preload_22mm  ok; 6001 samples",
                     "scene: the file's scene with drive.spring_preload_m = 0.011",
                     "exudyn 1.13", "git ", "created  ", "[drive]", "spring_preload_m = 0.022"):
        assert fragment in out, fragment
    line = next(x for x in out.splitlines() if x.strip().startswith("crank/angle "))
    assert line.split()[1:4] == ["(6001,)", "rad", "crank"]
    assert "= 7.8" in out or "relative_drift" in out  # summary scalars show their value


def test_inspect_json_for_scripts(study_files, capsys):
    status, out, _ = run_cli(capsys, "inspect", study_files["dynamics"], "--json")
    info = json.loads(out)
    assert status == 0
    assert info["provenance"]["study"] == "dynamics"
    assert {"flex_version", "git_commit", "exudyn_version", "created_utc"} <= set(
        info["provenance"])
    case = info["cases"]["preload_11mm"]
    assert case["status"] == "ok" and case["scene_changes"] == {"drive.spring_preload_m": 0.011}
    angle = next(d for d in case["datasets"] if d["path"] == "crank/angle")
    assert angle["units"] == "rad" and angle["shape"] == [6001]  # the finest run (h / 2)


def test_inspect_one_dataset_with_the_case_shorthand(study_files, capsys):
    status, out, _ = run_cli(capsys, "inspect", study_files["kinematics"], "slider/position")
    assert status == 0
    assert "cases/constant_speed/slider/position" in out
    assert "max 0.12 at t = 0 s" in out  # slider at L1 + L2 when the crank starts at 0
    assert "scene of case constant_speed" in out
    info = describe(study_files["dynamics"], "preload_22mm/crank/midpoint_position")
    assert len(info["dataset"]["columns"]) == 2 and list(info["cases"]) == ["preload_22mm"]


def test_path_forms(study_files):
    with h5py.File(study_files["dynamics"], "r") as h5:
        full = ["cases/preload_22mm/crank/angle"]
        assert select_datasets(h5, "cases/preload_22mm/crank/angle") == full
        assert select_datasets(h5, "/preload_22mm/crank/angle") == full
        assert len(select_datasets(h5, "*/crank/angle")) == 2
        assert len(select_datasets(h5, "preload_22mm/joints/B")) == 3
        with pytest.raises(ResultFileError, match="did you mean cases/preload_22mm/crank/angle"):
            select_datasets(h5, "crank/angle")  # two cases: the case must be named


# --- compare ----------------------------------------------------------------------------

def test_compare_identical_runs_passes(study_files, capsys):
    for study, path in study_files.items():
        status, out, _ = run_cli(capsys, "compare", path, path)
        assert status == 0, (study, out)
        assert "0 fail -> PASS" in out


def test_compare_finds_the_largest_deviation_and_where(study_files, tmp_path, capsys):
    changed = tmp_path / "changed.h5"
    shutil.copy(study_files["dynamics"], changed)
    with h5py.File(changed, "r+") as h5:
        h5["cases/preload_22mm/crank/angle"][1234] += 1e-3
        h5["cases/preload_22mm/joints/B/force_on_coupler"][500, 1] += 1e-9
        time_s = h5["cases/preload_22mm/time"][1234]
    status, out, _ = run_cli(capsys, "compare", changed, study_files["dynamics"],
                             "--atol", "1e-6", "--rtol", "0")
    assert status == 1
    fail = [line for line in out.splitlines() if line.startswith("FAIL")]
    assert len(fail) == 1 and "cases/preload_22mm/crank/angle" in fail[0]
    assert f"t={time_s:.6g} s" in fail[0] and "0.001" in fail[0]
    report = compare_files(changed, study_files["dynamics"], ["preload_22mm/joints/B"],
                           rtol=0.0, atol=1e-10)
    failed = [(d.path, d.column) for d in report.failures]
    assert failed == [("cases/preload_22mm/joints/B/force_on_coupler", 1)]  # column-wise
    assert main(["compare", str(changed), str(study_files["dynamics"]),
                 "preload_22mm/crank/angle", "--atol", "2e-3", "--rtol", "0"]) == 0


def test_tolerance_is_atol_plus_rtol_times_max_b(tmp_path):
    time_s = np.linspace(0.0, 1.0, 11)
    b = write_results(tmp_path / "b.h5", "demo", [CaseResult("c", "", {
        "time": Dataset(time_s, "s"), "x": Dataset(np.full(11, -4.0), "m")})])

    def a_with(deviation: float) -> Path:
        return write_results(tmp_path / "a.h5", "demo", [CaseResult("c", "", {
            "time": Dataset(time_s, "s"), "x": Dataset(np.full(11, -4.0) + deviation, "m")})])

    # allowed = 0.5 + 0.25 * max|b| = 0.5 + 0.25 * 4 = 1.5 m
    assert compare_files(a_with(1.5), b, ["x"], rtol=0.25, atol=0.5).passed
    assert not compare_files(a_with(1.5001), b, ["x"], rtol=0.25, atol=0.5).passed
    assert compare_files(a_with(1.5), b, ["x"], rtol=0.25, atol=0.5).deviations[0].allowed == 1.5


def test_common_time_base_is_the_overlap_on_the_finer_grid(tmp_path):
    coarse = np.linspace(0.0, 1.0, 101)
    fine = np.linspace(0.2, 1.5, 1301)
    base, source, _, _ = common_time_base(coarse, fine)
    assert source == "B" and base[0] == pytest.approx(0.2) and base[-1] == pytest.approx(1.0)
    assert len(base) == 801
    curve = np.stack([np.sin(3 * coarse), np.cos(3 * coarse)], axis=1)
    assert np.abs(resample(coarse, curve, base)[:, 0] - np.sin(3 * base)).max() < 1e-6
    assert np.abs(resample(coarse, curve, base, "linear")[:, 1]
                  - np.cos(3 * base)).max() < 1e-3
    a = write_results(tmp_path / "a.h5", "demo", [CaseResult("one", "", {
        "time": Dataset(coarse, "s"), "p": Dataset(curve, "m", "x y")})])
    b = write_results(tmp_path / "b.h5", "demo", [CaseResult("other", "", {
        "time": Dataset(fine, "s"),
        "p": Dataset(np.stack([np.sin(3 * fine), np.cos(3 * fine) + 0.01], axis=1), "m")})])
    # one case each: paired; A (0 .. 1 s) covers 0.2 .. 1 s of B's 0.2 .. 1.5 s: compared
    # only on the overlap when asked (--partial), and said so
    report = compare_files(a, b, ["p"], rtol=0.0, atol=1e-5, partial=True)
    assert [(d.column, d.passed) for d in report.deviations] == [(0, True), (1, False)]
    assert report.time_bases[0].samples == 801
    assert report.time_bases[0].coverage == pytest.approx(0.8 / 1.3)
    assert all("partial: compared 0.2 .. 1 s of B's 0.2 .. 1.5 s" in d.note
               for d in report.deviations)
    strict = compare_files(a, b, ["p"], rtol=0.0, atol=1e-5)
    assert not strict.passed and "not the whole reference" in strict.deviations[0].note
    assert compare_files(a, b, rtol=0, atol=1e-5, partial=True).deviations  # cases pair up


def test_compare_bad_input_exits_2_with_one_line(study_files, tmp_path, capsys):
    kinematics, dynamics = study_files["kinematics"], study_files["dynamics"]
    for args, fragment in (
            ([dynamics, kinematics, "preload_22mm/crank/angle"], "has no dataset or group"),
            ([dynamics, dynamics, "preload_22mm/crank/angel"], "did you mean"),
            ([dynamics, tmp_path / "none.h5"], "does not exist"),
            ([dynamics, dynamics, "--rtol", "nan"], "--rtol = nan"),
            ([dynamics, dynamics, "--atol", "-1"], "--atol = -1.0")):
        status, out, err = run_cli(capsys, "compare", *args)
        assert status == 2 and out == "", args
        assert err.count("\n") == 1 and err.startswith("flex: error: ") and fragment in err


def test_compare_json(study_files, capsys):
    status, out, _ = run_cli(capsys, "compare", study_files["kinematics"],
                             study_files["kinematics"], "--json", "slider")
    report = json.loads(out)
    assert status == 0 and report["passed"] and len(report["deviations"]) == 4
    assert report["command"].startswith("python -m flex compare ")


# --- plot -------------------------------------------------------------------------------

def svg_text(path: Path) -> str:
    return path.read_text()


def test_plot_against_time_with_units_and_an_overlay(study_files, tmp_path, capsys):
    matplotlib.rcParams["svg.fonttype"] = "none"  # keep text as text in the SVG
    out = tmp_path / "angle.svg"
    status, printed, _ = run_cli(capsys, "plot", study_files["dynamics"],
                                 "*/crank/angle", "*/crank/angular_velocity",
                                 "--vs", study_files["dynamics"], "--out", out)
    assert status == 0 and printed.strip() == f"wrote {out}"
    text = svg_text(out)
    for fragment in ("time [s]", "crank/angle [rad]", "crank/angular_velocity [rad/s]",
                     "preload_11mm/crank/angle"):
        assert fragment in text, fragment


def test_plot_against_each_other_and_default_output(study_files, tmp_path):
    matplotlib.rcParams["svg.fonttype"] = "none"
    out = plot_curves(study_files["kinematics"], ["crank/midpoint_position[1]"],
                      x_spec="crank/midpoint_position[0]", out=tmp_path / "circle.svg")
    text = svg_text(out)
    assert "crank/midpoint_position[0] [m]" in text and "crank/midpoint_position[1] [m]" in text
    default = plot_curves(study_files["simulate"], ["crank/angle"])
    assert default == study_files["simulate"].parent / "figures" / "plot-simulate-crank-angle.png"
    assert default.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_refuses_what_it_cannot_draw(study_files, capsys):
    dynamics = study_files["dynamics"]
    for args, fragment in (
            (["preload_22mm/crank/angle", "preload_22mm/slider/position",
              "preload_22mm/energy/total"], "at most two"),
            (["summary/thesis_comparison/quantity"], "is text"),
            (["preload_22mm/crank/angle", "--out", "x.txt"], "figures end in"),
            (["preload_22mm/crank/angle", "--x", "preload_22mm/crank/midpoint_position"],
             "one column")):
        status, _, err = run_cli(capsys, "plot", dynamics, *args)
        assert status == 2 and err.count("\n") == 1 and fragment in err, (args, err)


def test_plot_overlays_a_reference_curve_file(study_files, tmp_path):
    reference = REPO / "tests" / "reference_curves" / "deployment_preload_22mm.h5"
    out = plot_curves(study_files["dynamics"], ["preload_22mm/crank/angle"], [reference],
                      out=tmp_path / "vs.png")
    assert out.stat().st_size > 10_000


# --- every command on bad files ---------------------------------------------------------

@pytest.fixture(scope="module")
def bad_files(study_files, tmp_path_factory) -> dict[str, tuple[Path, str]]:
    folder = tmp_path_factory.mktemp("bad")
    truncated = folder / "truncated.h5"
    truncated.write_bytes(study_files["kinematics"].read_bytes()[:50_000])
    text = folder / "notes.h5"
    text.write_text("these are not results\n")
    foreign = folder / "foreign.h5"
    with h5py.File(foreign, "w") as h5:
        h5["x"] = np.arange(3)
    newer = folder / "newer.h5"
    shutil.copy(study_files["kinematics"], newer)
    with h5py.File(newer, "r+") as h5:
        h5.attrs["flex_format"] = "flex-results/99"
    return {"missing": (folder / "missing.h5", "does not exist"),
            "truncated": (truncated, "truncated"),
            "not HDF5": (text, "is not an HDF5 file"),
            "foreign": (foreign, "not written by flex (no flex_format attribute"),
            "newer": (newer, "flex_format = 'flex-results/99'"),
            "folder": (folder, "is a directory")}


@pytest.mark.parametrize("kind", ["missing", "truncated", "not HDF5", "foreign", "newer",
                                  "folder"])
def test_bad_files_give_one_message_naming_file_and_problem(study_files, bad_files, kind,
                                                            capsys):
    path, fragment = bad_files[kind]
    good = study_files["kinematics"]
    for args in (["inspect", path], ["plot", path, "slider/position"],
                 ["plot", good, "slider/position", "--vs", path], ["compare", path, good],
                 ["compare", good, path]):
        status, out, err = run_cli(capsys, *args)
        assert status == 2 and out == "", (args, out)
        assert err.count("\n") == 1 and err.startswith(f"flex: error: result file '{path}'")
        assert fragment in err, (args, err)


def test_a_real_process_prints_no_traceback(bad_files):
    path, _ = bad_files["truncated"]
    result = subprocess.run([sys.executable, "-m", "flex", "inspect", str(path)], cwd=REPO,
                            env=dict(os.environ, EXUDYN_NO_USER_SETTINGS="1"),
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.startswith("flex: error: result file") and "Traceback" not in (
        result.stderr) and result.stderr.count("\n") == 1


# --- xarray -----------------------------------------------------------------------------

def test_to_xarray_gives_a_time_coordinate_and_units(study_files):
    ds = to_xarray(study_files["dynamics"], "preload_22mm")
    assert ds.sizes["time"] == 6001 and ds["time"].attrs["units"] == "s"  # h / 2 reported
    angle = ds["crank/angle"]
    assert angle.dims == ("time",) and angle.attrs["units"] == "rad"
    assert ds["joints/B/force_on_coupler"].dims == ("time", "xy")
    peak = float(angle.idxmax("time"))
    assert peak == pytest.approx(0.02645, abs=1e-5)  # the thesis's angle maximum time
    assert float(ds["crank/angle"].interp(time=0.01)) == pytest.approx(
        np.interp(0.01, ds["time"].values, angle.values), abs=1e-6)
    assert ds.attrs["file_study"] == "dynamics" and ds.attrs["status"] == "ok"
    assert to_xarray(study_files["kinematics"]).attrs["case"] == "constant_speed"  # one case
    with pytest.raises(ResultFileError, match="has 2 cases"):
        to_xarray(study_files["dynamics"])


def test_plain_xarray_opens_a_case_group(study_files):
    import xarray as xr

    group = "cases/preload_22mm/crank"
    with xr.open_dataset(study_files["dynamics"], group=group, engine="h5netcdf",
                         phony_dims="sort") as ds:
        assert ds["angle"].attrs["units"] == "rad" and ds["angle"].size == 6001
    with xr.open_dataset(study_files["dynamics"], group="cases/preload_22mm",
                         engine="h5netcdf", phony_dims="sort") as ds:
        assert ds["time"].attrs["units"] == "s"
