"""Hostile result files and arguments for ``inspect``, ``plot`` and ``compare``.

Issue "Nothing lost, nothing silent": every command that reads a result file checks its
layout (:func:`flex.data.result_layout.check_layout`) and names what is wrong and where (file, HDF5
path, what was expected); no traceback, one ``flex: error:`` line, exit status 2, and no
input file changed (tests/hostile.py). Each malformed file starts as a valid file written by
:func:`flex.data.results.write_results` with one thing damaged.
"""

from __future__ import annotations

import os
import random
import shutil
from collections.abc import Callable
from pathlib import Path

import h5py
import numpy as np
import pytest
from hostile import check_refused, run_cli

from flex.base.errors import ResultFileError
from flex.data.result_layout import check_layout
from flex.data.results import CaseResult, Dataset, open_results, write_results
from flex.tools.compare import compare_files

REPO = Path(__file__).resolve().parent.parent
REFERENCE_FILES = sorted((REPO / "tests" / "reference_curves").glob("*.h5"))
FAILURE = "solution diverged at step 7 (t = 0.007 s): crank/angle is not finite"


def _case(name: str, samples: int, end_s: float = 1.0) -> CaseResult:
    time_s = np.linspace(0.0, end_s, samples)
    return CaseResult(name, f"[drive]\nspring_preload_m = {samples / 1000}\n", {
        "time": Dataset(time_s, "s", "simulation time"),
        "crank/angle": Dataset(np.sin(time_s), "rad", "crank angle"),
        "slider/position": Dataset(np.cos(time_s), "m", "slider position"),
        "crank/midpoint_position": Dataset(np.stack([time_s, time_s ** 2], axis=1), "m",
                                           "midpoint x y"),
        "joints/B/force": Dataset(np.ones((samples, 2)), "N", "force x y"),
        "peak": Dataset(1.5, "rad", "a scalar in a case"),
    }, counters={"steps": samples - 1, "newton_iterations": 3 * samples, "wall_time_s": 0.25})


def valid_cases() -> list[CaseResult]:
    """Two curves cases with different sample counts and one failed case."""
    return [_case("alpha", 21), _case("beta", 31),
            CaseResult("gamma", "[drive]\n", status="failed", message=FAILURE)]


SUMMARY = {"table/quantity": Dataset(np.array(["angle", "travel"]), "1", "what"),
           "table/value": Dataset(np.array([0.5, 0.1]), "m", "how much"),
           "relative_drift": Dataset(1e-7, "1", "energy drift")}


def write_valid(path: Path, cases: list[CaseResult] | None = None) -> Path:
    return write_results(path, "demo", valid_cases() if cases is None else cases,
                         "[drive]\nspring_preload_m = 0.02\n", SUMMARY, {"wall_time_s": 1.0})


# --- the damages: (name, function of the open file, words the refusal names) --------------

def _replace(path: str, data, attrs: dict | None = None, **kwargs) -> Callable:
    def damage(h5: h5py.File) -> None:
        old = dict(h5[path].attrs) if path in h5 and attrs is None else (attrs or {})
        if path in h5:
            del h5[path]
        h5.create_dataset(path, data=data, **kwargs)
        for key, value in old.items():
            h5[path].attrs[key] = value
    return damage


def _attr(path: str, key: str, value) -> Callable:
    def damage(h5: h5py.File) -> None:
        h5[path].attrs[key] = value
    return damage


def _del_attr(path: str, key: str) -> Callable:
    def damage(h5: h5py.File) -> None:
        del h5[path].attrs[key]
    return damage


def _delete(path: str) -> Callable:
    def damage(h5: h5py.File) -> None:
        del h5[path]
    return damage


def _set(path: str, thing) -> Callable:
    def damage(h5: h5py.File) -> None:
        if path in h5 or h5.get(path, getlink=True) is not None:
            del h5[path]
        h5[path] = thing
    return damage


def _decreasing(h5: h5py.File) -> None:
    time_s = h5["cases/alpha/time"][()]
    time_s[10] = time_s[8]
    h5["cases/alpha/time"][...] = time_s


def _cases_dataset(h5: h5py.File) -> None:
    del h5["cases"]
    h5["cases"] = np.arange(3.0)


def _named_type(h5: h5py.File) -> None:
    h5["cases/stray_type"] = np.dtype("f8")


def _references(h5: h5py.File) -> None:
    data = h5.create_dataset("cases/alpha/refs", (21,), dtype=h5py.ref_dtype)
    data[0] = h5["cases/alpha/time"].ref
    data.attrs["units"] = "1"


def _compound(h5: h5py.File) -> None:
    records = np.zeros(21, dtype=[("a", "f8"), ("b", "i4")])
    h5["cases/alpha/records"] = records


NON_UTF8 = np.bytes_(b"\xff\xfe bad")

DAMAGES: list[tuple[str, Callable, list[str]]] = [
    # time: 1-D float, finite, non-decreasing, at least one sample
    ("time_scalar", _replace("cases/alpha/time", 0.5), ["cases/alpha/time", "scalar"]),
    ("time_2d", _replace("cases/alpha/time", np.linspace(0, 1, 21).reshape(21, 1)),
     ["cases/alpha/time", "2 dimensions"]),
    ("time_3d", _replace("cases/alpha/time", np.zeros((21, 1, 1))),
     ["cases/alpha/time", "3 dimensions"]),
    ("time_int", _replace("cases/alpha/time", np.arange(21)), ["cases/alpha/time", "int"]),
    ("time_text", _replace("cases/alpha/time", np.array([str(i) for i in range(21)],
                                                        dtype=object),
                           dtype=h5py.string_dtype()), ["cases/alpha/time", "text"]),
]


def _time_group(h5: h5py.File) -> None:
    del h5["cases/alpha/time"]
    h5.create_group("cases/alpha/time")


def _time_with(value: float, index: int = 5) -> Callable:
    def damage(h5: h5py.File) -> None:
        time_s = h5["cases/alpha/time"][()]
        time_s[index] = value
        h5["cases/alpha/time"][...] = time_s
    return damage


DAMAGES += [
    ("time_nan", _time_with(np.nan), ["cases/alpha/time", "non-finite", "index 5"]),
    ("time_inf", _time_with(np.inf, 20), ["cases/alpha/time", "non-finite"]),
    ("time_first_nan", _time_with(np.nan, 0), ["cases/alpha/time", "index 0"]),
    ("time_decreasing", _decreasing, ["cases/alpha/time", "decreases"]),
    ("time_empty", _replace("cases/alpha/time", np.zeros(0)), ["cases/alpha/time", "no samples"]),
    ("time_null", _set("cases/alpha/time", h5py.Empty("f8")), ["cases/alpha/time", "empty"]),
    ("time_group", _time_group, ["cases/alpha/time", "group"]),
    ("time_beta_reversed", _replace("cases/beta/time", np.linspace(1, 0, 31)),
     ["cases/beta/time", "decreases"]),
    # one row per sample of the case's time
    ("short_curve", _replace("cases/alpha/crank/angle", np.zeros(20)),
     ["cases/alpha/crank/angle", "21 samples"]),
    ("long_curve", _replace("cases/beta/slider/position", np.zeros(40)),
     ["cases/beta/slider/position", "31 samples"]),
    ("short_two_column", _replace("cases/alpha/crank/midpoint_position", np.zeros((20, 2))),
     ["cases/alpha/crank/midpoint_position", "(20, 2)"]),
    ("transposed", _replace("cases/alpha/joints/B/force", np.zeros((2, 21))),
     ["cases/alpha/joints/B/force", "(2, 21)"]),
    ("extra_curve", _replace("cases/alpha/extra", np.zeros(7), attrs={"units": "m"}),
     ["cases/alpha/extra", "21 samples"]),
    # root attributes
    ("format_int", _attr("/", "flex_format", 1), ["flex_format", "not written by flex"]),
    ("format_array", _attr("/", "flex_format", np.array(["flex-results/1"], dtype=object)),
     ["flex_format", "array"]),
    ("format_newer", _attr("/", "flex_format", "flex-results/2"), ["flex-results/2"]),
    ("format_missing", _del_attr("/", "flex_format"), ["no flex_format attribute"]),
    ("format_bytes", _attr("/", "flex_format", NON_UTF8), ["flex_format", "UTF-8"]),
    ("study_int", _attr("/", "study", 7), ["'study'", "/", "text"]),
    ("study_array", _attr("/", "study", np.array([1.0, 2.0])), ["'study'", "array"]),
    ("study_empty_attr", _attr("/", "study", h5py.Empty("f8")), ["'study'", "empty"]),
    ("scene_int", _attr("/", "scene_toml", 3), ["'scene_toml'", "text"]),
    ("scene_not_utf8", _attr("/", "scene_toml", NON_UTF8), ["'scene_toml'", "UTF-8"]),
    ("scene_list", _attr("/", "scene_toml", np.array(["[a]", "[b]"], dtype=object)),
     ["'scene_toml'", "array"]),
    ("command_float", _attr("/", "command", 2.5), ["'command'", "text"]),
    ("created_bool", _attr("/", "created_utc", True), ["'created_utc'"]),
    # case attributes
    ("status_int", _attr("cases/alpha", "status", 1), ["'status'", "/cases/alpha"]),
    ("status_other", _attr("cases/alpha", "status", "maybe"), ["'maybe'", "/cases/alpha"]),
    ("status_empty_text", _attr("cases/beta", "status", ""), ["/cases/beta", "status"]),
    ("status_case", _attr("cases/alpha", "status", "OK"), ["'OK'", "ok"]),
    ("status_missing", _del_attr("cases/alpha", "status"), ["'status'", "/cases/alpha"]),
    ("status_array", _attr("cases/alpha", "status", np.array(["ok"], dtype=object)),
     ["'status'", "array"]),
    ("status_not_utf8", _attr("cases/gamma", "status", NON_UTF8), ["'status'", "UTF-8"]),
    ("message_int", _attr("cases/gamma", "message", 42), ["'message'", "/cases/gamma"]),
    ("message_array", _attr("cases/gamma", "message", np.arange(3)), ["'message'", "array"]),
    ("case_scene_float", _attr("cases/alpha", "scene_toml", 1.0), ["'scene_toml'",
                                                                  "/cases/alpha"]),
    ("solver_settings_int", _attr("cases/beta", "solver_settings_toml", 5),
     ["'solver_settings_toml'", "/cases/beta"]),
    ("counter_text", _attr("cases/alpha", "counter_steps", "many"), ["'counter_steps'",
                                                                    "number"]),
    ("counter_array", _attr("cases/alpha", "counter_wall_time_s", np.array([0.1, 0.2])),
     ["'counter_wall_time_s'", "array"]),
    # dataset attributes
    ("units_int", _attr("cases/alpha/crank/angle", "units", 3), ["'units'",
                                                                 "/cases/alpha/crank/angle"]),
    ("units_array", _attr("cases/alpha/crank/angle", "units", np.array(["rad", "deg"],
                                                                        dtype=object)),
     ["'units'", "array"]),
    ("units_not_utf8", _attr("cases/beta/time", "units", NON_UTF8), ["'units'", "UTF-8"]),
    ("description_float", _attr("cases/alpha/slider/position", "description", 0.5),
     ["'description'", "/cases/alpha/slider/position"]),
    ("summary_units_int", _attr("summary/table/value", "units", 1), ["'units'",
                                                                     "/summary/table/value"]),
    # the tree: /cases a group of groups, no links, numbers or text only
    ("dataset_in_cases", _set("cases/stray", np.arange(3.0)), ["/cases/stray", "dataset"]),
    ("scalar_in_cases", _set("cases/stray", 1.0), ["/cases/stray", "case group"]),
    ("type_in_cases", _named_type, ["/cases/stray_type"]),
    ("cases_dataset", _cases_dataset, ["/cases", "dataset"]),
    ("cases_missing", _delete("cases"), ["/cases"]),
    ("dangling_link", _set("cases/alpha/crank/speed", h5py.SoftLink("/nowhere")),
     ["/cases/alpha/crank/speed", "soft link"]),
    ("case_link", _set("cases/delta", h5py.SoftLink("/cases/alpha")),
     ["/cases/delta", "soft link"]),
    ("external_link", _set("cases/alpha/outside", h5py.ExternalLink("other.h5", "/x")),
     ["/cases/alpha/outside", "external link"]),
    ("summary_link", _set("summary/again", h5py.SoftLink("/summary/table")),
     ["/summary/again", "link"]),
    ("compound", _compound, ["/cases/alpha/records", "compound"]),
    ("complex", _replace("cases/alpha/crank/angle", np.ones(21) * (1 + 1j)),
     ["/cases/alpha/crank/angle", "complex"]),
    ("null_dataset", _set("cases/alpha/nothing", h5py.Empty("f8")), ["/cases/alpha/nothing",
                                                                     "empty"]),
    ("references", _references, ["/cases/alpha/refs", "references"]),
]

DAMAGE_NAMES = [name for name, _, _ in DAMAGES]
assert len(set(DAMAGE_NAMES)) == len(DAMAGE_NAMES)


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """A valid file, one damaged copy per :data:`DAMAGES`, broken files of every kind."""
    folder = tmp_path_factory.mktemp("hostile")
    good = write_valid(folder / "good.h5")
    out = {"good": good, "folder": folder}
    out["one"] = write_results(folder / "one.h5", "demo", [_case("solo", 11)], "")
    out["failed_only"] = write_results(folder / "failed_only.h5", "demo", [
        CaseResult("alpha", "", status="failed", message=FAILURE)], "")
    for name, damage, _ in DAMAGES:
        path = folder / f"{name}.h5"
        shutil.copy(good, path)
        with h5py.File(path, "r+") as h5:
            damage(h5)
        out[name] = path
    data = good.read_bytes()
    for length in (8, 100, 512, 2048, len(data) // 2, len(data) - 100, len(data) - 1):
        path = folder / f"cut_{length}.h5"
        path.write_bytes(data[:length])
        out[f"cut_{length}"] = path
    (folder / "zero.h5").write_bytes(b"")
    (folder / "random.h5").write_bytes(random.Random(7).randbytes(5000))
    (folder / "text.h5").write_text("time,angle\n0,0\n")
    (folder / "dir.h5").mkdir()
    os.symlink(folder / "gone.h5", folder / "dangling.h5")
    with h5py.File(folder / "other_program.h5", "w") as h5:  # HDF5 of another program
        h5.attrs["creator"] = "some other tool"
        h5["data/time"] = np.linspace(0, 1, 5)
        h5["data/values"] = np.arange(5.0)
    for name in ("zero", "random", "text", "dir", "dangling", "other_program"):
        out[name] = folder / f"{name}.h5"
    out["missing"] = folder / "missing.h5"
    return out


def watched(files: dict[str, Path]) -> dict:
    """What a command on these files must leave as it was: the valid files byte for byte,
    every other file of the folder (the damaged ones) as a bystander."""
    return {"watch": [path for key, path in files.items()
                      if key in ("good", "one", "failed_only")],
            "bystanders": [files["folder"]]}


# --- every damage, every verb -------------------------------------------------------------

VERBS = ("inspect", "inspect_json", "inspect_path", "plot", "plot_vs", "compare_a",
         "compare_b")


def argv_for(verb: str, bad: Path, good: Path, folder: Path) -> list[str]:
    figure = str(folder / f"never-{bad.stem}-{verb}.png")
    return {"inspect": ["inspect", str(bad)],
            "inspect_json": ["inspect", str(bad), "--json"],
            "inspect_path": ["inspect", str(bad), "alpha/crank/angle"],
            "plot": ["plot", str(bad), "alpha/crank/angle", "--out", figure],
            "plot_vs": ["plot", str(good), "alpha/crank/angle", "--vs", str(bad), "--out",
                        figure],
            "compare_a": ["compare", str(bad), str(good)],
            "compare_b": ["compare", str(good), str(bad), "alpha/crank/angle"]}[verb]


@pytest.mark.parametrize("name", DAMAGE_NAMES)
def test_a_damaged_layout_is_refused_by_every_verb(files, name):
    words = dict((n, w) for n, _, w in DAMAGES)[name]
    bad = files[name]
    for verb in VERBS:
        argv = argv_for(verb, bad, files["good"], files["folder"])
        figure = files["folder"] / f"never-{bad.stem}-{verb}.png"
        seen = watched(files)
        check_refused(argv, names=[bad.name, *words], watch=[*seen["watch"], bad, figure],
                      bystanders=seen["bystanders"])


BROKEN = {"zero": ["empty", "0 bytes"], "random": ["not an HDF5 file"],
          "text": ["not an HDF5 file"], "dir": ["directory"],
          "dangling": ["symbolic link to nothing", "gone.h5"], "missing": ["does not exist"],
          "other_program": ["not written by flex", "no flex_format"],
          "cut_8": ["truncated"], "cut_100": ["truncated", "100 of the"],
          "cut_512": ["truncated"], "cut_2048": ["truncated"]}


@pytest.mark.parametrize("name", sorted(BROKEN) + ["cut_half", "cut_end_100", "cut_end_1"])
@pytest.mark.parametrize("verb", ["inspect_json", "plot", "compare_a", "compare_b"])
def test_a_broken_file_gives_one_message(files, name, verb):
    if name.startswith("cut_") and name not in BROKEN:
        size = files["good"].stat().st_size
        length = {"cut_half": size // 2, "cut_end_100": size - 100, "cut_end_1": size - 1}[name]
        bad, words = files[f"cut_{length}"], ["truncated", f"{length} of the {size} bytes"]
    else:
        bad, words = files[name], BROKEN[name]
    argv = argv_for(verb, bad, files["good"], files["folder"])
    seen = watched(files)
    check_refused(argv, names=[bad.name, *words], bystanders=seen["bystanders"],
                  watch=[*seen["watch"], bad, files["folder"] / f"never-{bad.stem}-{verb}.png"])


def test_every_damage_is_refused_by_the_checker_itself(files):
    for name, _, words in DAMAGES:
        with pytest.raises(ResultFileError) as error:
            open_results(files[name]).close()
        for word in words:
            assert word.lower() in str(error.value).lower(), (name, word, str(error.value))


# --- valid files pass ---------------------------------------------------------------------

@pytest.mark.parametrize("reference", REFERENCE_FILES, ids=lambda p: p.name)
def test_reference_curve_files_pass_the_checker(reference):
    with open_results(reference) as h5:
        check_layout(h5, reference)
    outcome = check_refused(["inspect", str(reference)], watch=[reference], status=0)
    assert "cases/" in outcome.stdout


def test_write_results_output_passes_the_checker(files, tmp_path):
    layouts = {
        "study": valid_cases(),
        "empty": [],
        "failed": [CaseResult("f", "", status="failed", message="x")],
        # a sweep case: scalars and a downsampled curve group with its own time, no case time
        "fit": [CaseResult("fit", "", {
            "measures/error": Dataset(0.5, "1", "an error"),
            "curves/time": Dataset(np.linspace(0, 1, 7), "s", "time"),
            "curves/angle": Dataset(np.zeros(7), "rad", "angle"),
            "wall_times": Dataset(np.array([0.1, 0.2, 0.3]), "s", "repeats")})],
        "text": [CaseResult("t", "not = valid = toml", {
            "time": Dataset(np.array([0.0]), "s"), "label": Dataset(np.array(["a"]), "1"),
            "note": Dataset("scalar text", "1")}, attrs={"extra": np.array([1, 2])})],
        "repeated_time": [CaseResult("r", "", {"time": Dataset(np.array([0.0, 0.5, 0.5]), "s"),
                                               "x": Dataset(np.zeros(3), "m")})],
    }
    for name, cases in layouts.items():
        path = write_valid(tmp_path / f"{name}.h5", cases)
        with open_results(path) as h5:
            check_layout(h5, path)
        check_refused(["inspect", str(path)], watch=[path], status=0)
        check_refused(["inspect", str(path), "--json"], watch=[path], status=0)


# --- valid but unusual content: no refusal, no traceback ----------------------------------

def _unusual(folder: Path) -> dict[str, Path]:
    out = {}
    time_s = np.linspace(0.0, 1.0, 5)
    out["unicode"] = write_valid(folder / "ünïcødé α.h5", [CaseResult("débit_α β", "", {
        "time": Dataset(time_s, "s"), "größe/wert": Dataset(time_s * 2, "m²", "ünïcødé"),
        "cost$x$": Dataset(time_s, "$", "dollars")})])
    out["bad_toml"] = write_valid(folder / "bad_toml.h5", [CaseResult("c", "[[[ not toml", {
        "time": Dataset(time_s, "s"), "x": Dataset(time_s, "m")})])
    with h5py.File(out["bad_toml"], "r+") as h5:
        h5.attrs["scene_toml"] = "= = ="
        h5.attrs["complex_extra"] = 1 + 2j
        h5.attrs["empty_extra"] = h5py.Empty("f8")
        h5["cases/c"].attrs["records"] = np.zeros(2, dtype=[("a", "f8"), ("b", "i4")])
    out["text_curve"] = write_valid(folder / "text_curve.h5", [CaseResult("alpha", "", {
        "time": Dataset(np.linspace(0, 1, 21), "s"),
        "crank/angle": Dataset(np.array([f"v{i}" for i in range(21)]), "rad", "text")})])
    out["no_time"] = write_valid(folder / "no_time.h5", [CaseResult("alpha", "", {
        "crank/angle": Dataset(np.sin(np.linspace(0, 1, 21)), "rad", "no time")})])
    out["huge"] = write_valid(folder / "huge.h5", [CaseResult("alpha", "", {
        "time": Dataset(np.linspace(0, 1, 21), "s"),
        "crank/angle": Dataset(np.linspace(-1.0, 1.0, 21) * 1e308, "rad", "huge")})])
    out["nan_curve"] = write_valid(folder / "nan_curve.h5", [CaseResult("alpha", "", {
        "time": Dataset(np.linspace(0, 1, 21), "s"),
        "crank/angle": Dataset(np.full(21, np.nan), "rad", "all NaN"),
        "cube": Dataset(np.zeros((21, 2, 2)), "m", "3-D"),
        "flags": Dataset(np.arange(21) % 2 == 0, "1", "booleans")})])
    out["empty_cases"] = write_valid(folder / "empty_cases.h5", [])
    return out


@pytest.fixture(scope="module")
def unusual(files) -> dict[str, Path]:
    return _unusual(files["folder"] / "unusual")


def _figure(files, name: str) -> str:
    return str(files["folder"] / "figures_ok" / f"{name}.png")


UNUSUAL_OK = [
    ("inspect_unicode", lambda u, f: ["inspect", str(u["unicode"])]),
    ("inspect_unicode_json", lambda u, f: ["inspect", str(u["unicode"]), "--json"]),
    ("inspect_unicode_path", lambda u, f: ["inspect", str(u["unicode"]), "größe/wert"]),
    ("plot_unicode", lambda u, f: ["plot", str(u["unicode"]), "größe/wert", "cost$x$",
                                   "--out", _figure(f, "unicode"), "--title", "$\\frac{"]),
    ("inspect_bad_toml", lambda u, f: ["inspect", str(u["bad_toml"])]),
    ("inspect_bad_toml_json", lambda u, f: ["inspect", str(u["bad_toml"]), "--json"]),
    ("inspect_bad_toml_path", lambda u, f: ["inspect", str(u["bad_toml"]), "x"]),
    ("inspect_text_curve", lambda u, f: ["inspect", str(u["text_curve"]), "crank/angle"]),
    ("inspect_text_curve_json", lambda u, f: ["inspect", str(u["text_curve"]), "crank/angle",
                                              "--json"]),
    ("inspect_no_time", lambda u, f: ["inspect", str(u["no_time"]), "crank/angle"]),
    ("plot_no_time", lambda u, f: ["plot", str(u["no_time"]), "crank/angle", "--out",
                                   _figure(f, "no_time")]),
    ("inspect_huge", lambda u, f: ["inspect", str(u["huge"]), "crank/angle", "--json"]),
    ("inspect_nan", lambda u, f: ["inspect", str(u["nan_curve"]), "crank/angle"]),
    ("inspect_cube", lambda u, f: ["inspect", str(u["nan_curve"]), "cube"]),
    ("inspect_flags", lambda u, f: ["inspect", str(u["nan_curve"]), "flags"]),
    ("plot_nan", lambda u, f: ["plot", str(u["nan_curve"]), "crank/angle", "--out",
                               _figure(f, "nan")]),
    ("inspect_empty_cases", lambda u, f: ["inspect", str(u["empty_cases"]), "--json"]),
    ("inspect_summary_text", lambda u, f: ["inspect", str(f["good"]), "summary/table/quantity"]),
    ("inspect_failed_case", lambda u, f: ["inspect", str(f["failed_only"])]),
    ("plot_x_same_case_wildcard", lambda u, f: ["plot", str(f["good"]), "alpha/crank/angle",
                                                "--x", "*/slider/position", "--out",
                                                _figure(f, "x_wild")]),
]


@pytest.mark.parametrize("name", [name for name, _ in UNUSUAL_OK])
def test_unusual_but_valid_content_works(files, unusual, name):
    argv = dict(UNUSUAL_OK)[name](unusual, files)
    seen = watched(files)
    check_refused(argv, watch=[*seen["watch"], *unusual.values()], status=0,
                  bystanders=seen["bystanders"])


# --- refusals of what cannot be done with a valid file ------------------------------------

def _refusals(u: dict[str, Path], f: dict[str, Path]) -> list[tuple[str, list[str], list[str]]]:
    good, folder = str(f["good"]), f["folder"]
    fig = str(folder / "never.png")
    return [
        # arguments
        ("plot_no_path", ["plot", good], ["PATH"]),
        ("inspect_no_file", ["inspect"], ["FILE.h5"]),
        ("compare_one_file", ["compare", good], ["B.h5"]),
        ("inspect_wildcard_nothing", ["inspect", good, "*/nothing"], ["*/nothing"]),
        ("plot_wildcard_nothing", ["plot", good, "*/nothing", "--out", fig], ["*/nothing"]),
        ("compare_wildcard_nothing", ["compare", good, good, "*/nothing"], ["*/nothing"]),
        ("inspect_no_such_case", ["inspect", good, "delta/crank/angle"], ["delta/crank/angle"]),
        ("plot_column_too_big", ["plot", good, "alpha/crank/midpoint_position[5]", "--out",
                                 fig], ["[5]", "no such column"]),
        ("plot_column_of_1d", ["plot", good, "alpha/crank/angle[0]", "--out", fig],
         ["[0]", "no such column"]),
        ("plot_column_unclosed", ["plot", good, "alpha/crank/angle[1", "--out", fig],
         ["angle[1"]),
        ("plot_column_negative", ["plot", good, "alpha/crank/midpoint_position[-1]", "--out",
                                  fig], ["[-1]"]),
        ("compare_column_too_big", ["compare", good, good, "alpha/crank/midpoint_position[7]"],
         ["[7]", "no such column"]),
        ("compare_limit_negative", ["compare", good, good, "--limit", "-1"], ["--limit"]),
        ("compare_limit_text", ["compare", good, good, "--limit", "all"], ["--limit"]),
        ("compare_rtol_nan", ["compare", good, good, "--rtol", "nan"], ["--rtol"]),
        ("compare_rtol_negative", ["compare", good, good, "--rtol", "-1e-6"], ["--rtol"]),
        ("compare_rtol_inf", ["compare", good, good, "--rtol", "inf"], ["--rtol"]),
        ("compare_atol_negative", ["compare", good, good, "--atol", "-1"], ["--atol"]),
        ("compare_atol_text", ["compare", good, good, "--atol", "tiny"], ["--atol"]),
        ("compare_interp_unknown", ["compare", good, good, "--interp", "quadratic"],
         ["--interp"]),
        ("compare_nothing_in_common", ["compare", str(f["one"]), str(u["empty_cases"])],
         ["nothing to compare", "one.h5"]),
        ("compare_empty_cases", ["compare", str(u["empty_cases"]), str(u["empty_cases"])],
         ["nothing to compare"]),
        # plot: what cannot be drawn
        ("plot_x_other_case", ["plot", good, "alpha/crank/angle", "--x",
                               "beta/slider/position", "--out", fig], ["alpha", "beta"]),
        ("plot_x_other_case_full", ["plot", good, "cases/beta/crank/angle", "--x",
                                    "cases/alpha/crank/angle", "--out", fig],
         ["case alpha", "case beta"]),
        ("plot_x_summary", ["plot", good, "alpha/crank/angle", "--x", "summary/table/value",
                            "--out", fig], ["outside the cases", "alpha"]),
        ("plot_x_text", ["plot", good, "alpha/crank/angle", "--x", "summary/table/quantity",
                         "--out", fig], ["--x"]),
        ("plot_x_missing", ["plot", good, "alpha/crank/angle", "--x", "alpha/nothing",
                            "--out", fig], ["alpha/nothing"]),
        ("plot_x_column", ["plot", good, "alpha/crank/angle", "--x",
                           "alpha/crank/midpoint_position[4]", "--out", fig], ["column 4"]),
        ("plot_text_curve", ["plot", str(u["text_curve"]), "crank/angle", "--out", fig],
         ["is text"]),
        ("plot_scalar", ["plot", good, "alpha/peak", "--out", fig], ["scalar"]),
        ("plot_cube", ["plot", str(u["nan_curve"]), "cube", "--out", fig], ["(21, 2, 2)"]),
        ("plot_only_time", ["plot", good, "alpha/time", "beta/time", "--out", fig],
         ["nothing to plot"]),
        ("plot_huge", ["plot", str(u["huge"]), "crank/angle", "--out", fig],
         ["cannot draw", "huge.h5"]),
        ("plot_empty_cases", ["plot", str(u["empty_cases"]), "crank/angle", "--out", fig],
         ["no cases"]),
        ("plot_failed_case", ["plot", str(f["failed_only"]), "crank/angle", "--out", fig],
         ["crank/angle"]),
    ]


@pytest.fixture(scope="module")
def refusals(files, unusual):
    return {name: (argv, words) for name, argv, words in _refusals(unusual, files)}


REFUSAL_NAMES = [name for name, _, _ in _refusals({k: Path(k) for k in (
    "empty_cases", "text_curve", "huge", "nan_curve")}, {k: Path(k) for k in (
        "good", "one", "failed_only", "folder")})]


@pytest.mark.parametrize("name", REFUSAL_NAMES)
def test_what_cannot_be_done_is_refused(files, unusual, refusals, name):
    argv, words = refusals[name]
    seen = watched(files)
    check_refused(argv, names=words, bystanders=seen["bystanders"],
                  watch=[*seen["watch"], *unusual.values(), files["folder"] / "never.png"])


# --- plot outputs: never clobber an input, never a traceback, always atomic ---------------

@pytest.fixture
def workspace(files, tmp_path):
    """A good result file, one named like a figure, a plain file and an existing figure."""
    good = shutil.copy(files["good"], tmp_path / "good.h5")
    disguised = shutil.copy(files["good"], tmp_path / "run.png")  # HDF5 named .png
    (tmp_path / "notes.txt").write_text("a plain file\n")
    (tmp_path / "old.png").write_bytes(b"yesterday's figure")
    (tmp_path / "folder.png").mkdir()
    return tmp_path, Path(good), Path(disguised)


OUTPUTS = [
    ("out_is_the_file", lambda t, g, d: ["plot", str(d), "alpha/crank/angle", "--out", str(d)],
     ["run.png", "being read"]),
    ("out_is_the_vs_file", lambda t, g, d: ["plot", str(g), "alpha/crank/angle", "--vs", str(d),
                                            "--out", str(d)], ["run.png", "overwritten"]),
    ("out_is_the_h5", lambda t, g, d: ["plot", str(g), "alpha/crank/angle", "--out", str(g)],
     ["good.h5", "being read"]),
    ("out_via_other_spelling", lambda t, g, d: ["plot", str(d), "alpha/crank/angle", "--out",
                                                str(t / "." / "sub" / ".." / "run.png")],
     ["being read"]),
    ("out_is_a_directory", lambda t, g, d: ["plot", str(g), "alpha/crank/angle", "--out",
                                            str(t / "folder.png")], ["folder.png", "directory"]),
    ("out_under_a_file", lambda t, g, d: ["plot", str(g), "alpha/crank/angle", "--out",
                                          str(t / "notes.txt" / "fig.png")], ["notes.txt"]),
    ("out_deep_under_a_file", lambda t, g, d: ["plot", str(g), "alpha/crank/angle", "--out",
                                               str(t / "notes.txt" / "a" / "b" / "fig.png")],
     ["notes.txt", "not a folder"]),
    ("out_bad_suffix", lambda t, g, d: ["plot", str(g), "alpha/crank/angle", "--out",
                                        str(t / "fig.txt")], ["figures end in"]),
    ("out_no_suffix", lambda t, g, d: ["plot", str(g), "alpha/crank/angle", "--out",
                                       str(t / "fig")], ["figures end in"]),
]


@pytest.mark.parametrize("name", [name for name, _, _ in OUTPUTS])
def test_plot_output_that_cannot_be_written_or_clobbers_an_input(workspace, name):
    folder, good, disguised = workspace
    make, words = {n: (m, w) for n, m, w in OUTPUTS}[name]
    check_refused(make(folder, good, disguised), names=words,
                  watch=[folder / "good.h5", folder / "run.png", folder / "notes.txt",
                         folder / "old.png", folder / "fig.png"])
    assert sorted(p.name for p in folder.iterdir()) == ["folder.png", "good.h5", "notes.txt",
                                                        "old.png", "run.png"]


def test_default_output_beside_a_figures_file_is_refused(workspace):
    folder, good, _ = workspace
    (folder / "figures").write_text("not a folder")
    check_refused(["plot", str(good), "alpha/crank/angle"], names=["figures", "not a folder"],
                  watch=[good, folder / "figures"])


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_plot_into_a_read_only_folder_is_refused(workspace):
    folder, good, _ = workspace
    locked = folder / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        check_refused(["plot", str(good), "alpha/crank/angle", "--out", str(locked / "f.png")],
                      names=["locked", "not writable"], watch=[good])
    finally:
        locked.chmod(0o700)


def test_a_failed_draw_leaves_the_previous_figure_intact(workspace, files):
    folder, good, _ = workspace
    unusual = _unusual(folder / "u")
    before = (folder / "old.png").read_bytes()
    check_refused(["plot", str(unusual["huge"]), "crank/angle", "--out", str(folder / "old.png")],
                  names=["cannot draw"], watch=[folder / "old.png", good])
    assert (folder / "old.png").read_bytes() == before
    assert not [p for p in folder.iterdir() if p.name.endswith(".part")]
    outcome = run_cli(["plot", str(good), "alpha/crank/angle", "--out", str(folder / "old.png")])
    assert outcome.status == 0 and (folder / "old.png").read_bytes()[:4] == b"\x89PNG"
    assert not [p for p in folder.iterdir() if p.name.endswith(".part")]


# --- compare: a failed case is named with its message --------------------------------------

def test_compare_names_a_case_that_failed(files):
    good, failed_only = str(files["good"]), str(files["failed_only"])
    for argv, side in ((["compare", failed_only, failed_only], "A"),
                       (["compare", failed_only, good], "A"),
                       (["compare", good, failed_only, "alpha/crank/angle"], "B"),
                       (["compare", failed_only, good, "alpha/crank/angle"], "A"),
                       (["compare", good, good], "A"),
                       (["compare", good, good, "gamma"], "A"),
                       (["compare", good, good, "gamma/crank/angle"], "A"),
                       (["compare", good, good, "--json"], "A")):
        # failed in both files (a file compared with itself): the same outcome, status 0
        both = argv[1] == argv[2]
        outcome = check_refused(argv, **watched(files), status=0 if both else 1)
        case = "gamma" if "failed_only" not in " ".join(argv) else "alpha"
        assert f"case {case} failed in {side}: {FAILURE}" in outcome.stdout, (argv, outcome)
        assert "no dataset in common" not in outcome.stdout + outcome.stderr
    report = compare_files(files["good"], files["good"], ["alpha", "beta"])
    assert report.passed  # the failed case is not named: not compared


def test_compare_text_and_missing_time_are_differences_not_crashes(files, unusual):
    good = str(files["good"])
    for other in ("text_curve", "no_time"):
        outcome = check_refused(["compare", str(unusual[other]), good, "alpha/crank/angle"],
                                **watched(files), status=1)
        assert "FAIL" in outcome.stdout


def test_compare_interpolates_nan_and_huge_curves_without_crashing(files, unusual, tmp_path):
    grid = write_valid(tmp_path / "grid.h5", [_case("alpha", 33)])
    wide = write_valid(tmp_path / "wide.h5", [CaseResult("alpha", "", {
        "time": Dataset(np.linspace(-1.0, 1.0, 21) * 1e308, "s"),
        "crank/angle": Dataset(np.linspace(-1.0, 1.0, 21) * 1e308, "rad")})])
    for a, b in ((unusual["nan_curve"], grid), (grid, unusual["nan_curve"]),
                 (unusual["huge"], grid), (grid, unusual["huge"]), (wide, grid), (grid, wide)):
        for interp in ("cubic", "linear"):
            outcome = check_refused(["compare", str(a), str(b), "alpha/crank/angle", "--interp",
                                     interp], watch=[a, b], status=1)
            assert "FAIL" in outcome.stdout


def test_hostile_case_count():
    """The issue asks for at least 120 hostile cases."""
    count = (len(DAMAGES) * len(VERBS) + (len(BROKEN) + 3) * 4 + len(UNUSUAL_OK)
             + len(REFUSAL_NAMES) + len(OUTPUTS) + 2 + 12)
    assert count >= 120, count
