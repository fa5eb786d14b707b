"""Hostile outputs of ``flex export`` and ``flex animate``: a file of the same name someone
else wrote, a full disk (before and while writing), a result file whose modal coordinates
were changed; and the internal errors that became clear ones (a study name where a scene
is expected, a mechanism that does not deploy under ``model = "auto"``, a scheduler address
without a port).

Each case asserts the exit status, one ``flex: error:`` line naming the problem, no
traceback, no partial file left and no existing file changed (byte for byte).
"""

from __future__ import annotations

import errno
import os
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from hostile import check_refused, fingerprint, run_cli

from flex.base.errors import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, FlexError
from flex.tools.animate import MARKER, encoder_available

REPO = Path(__file__).resolve().parents[1]


def _leftovers(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if ".part" in p.name]


@pytest.fixture
def source(tiny_ffrf_file, tmp_path) -> Path:
    """A private copy of the tiny FFRF result file."""
    return Path(shutil.copy(tiny_ffrf_file, tmp_path / "plate.h5"))


@pytest.fixture(scope="module")
def motion(tiny_ffrf_file, reduction_cache):
    from flex.tools.motion import case_motion

    return case_motion(tiny_ffrf_file, None, cache_dir=reduction_cache)


@pytest.fixture
def fast(monkeypatch, motion):
    """Export and animate reuse the tiny file's motion (read once per module: these cases
    are about writing, not reading)."""
    import flex.tools.animate as animate
    import flex.tools.export as export

    for module in (export, animate):
        monkeypatch.setattr(module, "case_motion", lambda *args, **kwargs: motion)


@pytest.fixture(scope="module")
def earlier_template(tiny_ffrf_file, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("earlier") / "out"
    assert run_cli(["export", str(tiny_ffrf_file), "--out", str(out)]).status == EXIT_OK
    return out


# --- a file of the same name that flex did not write ---------------------------------------
@pytest.fixture(scope="module")
def foreign(tmp_path_factory) -> dict[str, bytes]:
    """Contents of files someone else wrote (made once)."""
    from flex.data.results import CaseResult, Dataset, write_results

    tmp_path = tmp_path_factory.mktemp("foreign")

    result = write_results(tmp_path / "a-result.h5", "simulate", [CaseResult("c", "", {
        "time": Dataset(np.linspace(0, 1, 3), "s")})])
    with h5py.File(tmp_path / "plain.h5", "w") as h5:
        h5["x"] = np.arange(3)
    return {"text": b"my notes, not an export\n", "empty": b"",
            "flex-result-file": result.read_bytes(), "plain-hdf5": (tmp_path / "plain.h5")
            .read_bytes(), "png-without-marker": b"\x89PNG\r\n\x1a\n" + b"\0" * 64}


TARGETS = {  # name -> (argv after FILE, the output file that is already there)
    "export-h5": (["--out", "{out}"], "plate-case.h5"),
    "export-xdmf": (["--out", "{out}"], "plate-case.xdmf"),
    "animate-png": (["--out", "{out}/a.png"], "a.png"),
    "animate-gif": (["--out", "{out}/a.gif", "--frames", "2"], "a.gif"),
    "animate-mp4": (["--out", "{out}/a.mp4", "--frames", "2"], "a.mp4"),
}
CONTENTS = ["text", "empty", "flex-result-file", "plain-hdf5", "png-without-marker"]


def _argv(target: str, source: Path, out: Path, *extra: str) -> list[str]:
    args, _ = TARGETS[target]
    if target == "animate-mp4" and not encoder_available():
        pytest.skip("no mp4 encoder (imageio-ffmpeg)")
    return [target.split("-")[0], str(source), *(a.format(out=out) for a in args), *extra]


@pytest.mark.parametrize("content", CONTENTS)
@pytest.mark.parametrize("target", TARGETS)
def test_a_file_flex_did_not_write_is_not_replaced(source, tmp_path, target, content,
                                                   foreign):
    out = tmp_path / "out"
    out.mkdir()
    there = out / TARGETS[target][1]
    there.write_bytes(foreign[content])
    outcome = check_refused(_argv(target, source, out), [str(there), "not written by flex",
                                                         "--force"], watch=[out, source])
    assert "wrote" not in outcome.stdout and _leftovers(tmp_path) == []


@pytest.mark.parametrize("target", ["export-h5", "export-xdmf", "animate-png"])
def test_a_folder_where_the_output_goes_is_refused(source, tmp_path, target):
    out = tmp_path / "out"
    (out / TARGETS[target][1]).mkdir(parents=True)
    check_refused(_argv(target, source, out), ["is a folder"], watch=[out, source])


@pytest.mark.parametrize("target", ["export-h5", "animate-png"])
def test_a_link_to_someone_elses_file_is_refused(source, tmp_path, target):
    out = tmp_path / "out"
    out.mkdir()
    theirs = tmp_path / "theirs.bin"
    theirs.write_bytes(b"someone else's data")
    (out / TARGETS[target][1]).symlink_to(theirs)
    check_refused(_argv(target, source, out), ["not written by flex"], watch=[theirs, source])
    assert theirs.read_bytes() == b"someone else's data"


@pytest.mark.parametrize("target", ["export-h5", "animate-png"])
def test_force_replaces_a_file_flex_did_not_write(source, tmp_path, target, fast):
    out = tmp_path / "out"
    out.mkdir()
    there = out / TARGETS[target][1]
    there.write_bytes(b"my notes")
    outcome = run_cli(_argv(target, source, out, "--force"))
    assert outcome.status == EXIT_OK, outcome.stderr
    assert there.read_bytes() != b"my notes" and _leftovers(tmp_path) == []


@pytest.mark.parametrize("target", ["export-h5", "animate-png"])
def test_flex_replaces_its_own_earlier_output_without_force(source, tmp_path, target, fast):
    out = tmp_path / "out"
    first = run_cli(_argv(target, source, out))
    assert first.status == EXIT_OK, first.stderr
    there = out / TARGETS[target][1]
    if target.startswith("animate"):
        assert MARKER in there.read_bytes()  # its provenance, in the image's metadata
    again = run_cli(_argv(target, source, out, *(["--every", "2"] if target == "export-h5"
                                                 else ["--time", "0"])))
    assert again.status == EXIT_OK, again.stderr


# --- a full disk -----------------------------------------------------------------------------
@pytest.fixture
def earlier_export(earlier_template, tmp_path) -> Path:
    """An earlier export of ``plate.h5`` in ``tmp_path/out`` (both files watched)."""
    return Path(shutil.copytree(earlier_template, tmp_path / "out"))


@pytest.mark.parametrize("free", [0, 1000, "estimate - 1"])
@pytest.mark.parametrize("earlier", [False, True], ids=["new-folder", "earlier-export"])
def test_too_little_free_space_is_refused_before_writing(source, tmp_path, monkeypatch,
                                                        free, earlier, earlier_template, fast):
    import flex.tools.export as export

    out = tmp_path / "out"
    if earlier:
        shutil.copytree(earlier_template, out)
    if free == "estimate - 1":
        monkeypatch.setattr(export, "estimate_bytes", lambda *args: 10**9)
        free = 10**9 - 1
    monkeypatch.setattr(export, "free_bytes", lambda folder: free)
    outcome = check_refused(["export", str(source), "--out", str(out)],
                            ["needs up to", "free", "--every"], watch=[tmp_path])
    assert out.exists() is earlier and _leftovers(tmp_path) == []
    assert "flex export: case:" not in outcome.stderr  # no "writing ..." line before


ERRNOS = [errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO]


def _fail(code: int):
    def fail(*args, **kwargs):
        raise OSError(code, os.strerror(code))
    return fail


@pytest.mark.parametrize("code", ERRNOS, ids=[errno.errorcode[c] for c in ERRNOS])
@pytest.mark.parametrize("where", ["building-hdf5", "writing-xdmf", "moving-into-place"])
def test_a_write_that_fails_midway_leaves_nothing(source, earlier_export, monkeypatch, where,
                                                  code, fast):
    import flex.tools.export as export

    if where == "building-hdf5":
        monkeypatch.setattr(export, "_fill_hdf5", _fail(code))
    elif where == "writing-xdmf":
        monkeypatch.setattr(export, "_write_xdmf", _fail(code))
    else:  # the first rename succeeds, the second fails
        real, calls = os.replace, []

        def replace(a, b):
            calls.append(b)
            if len(calls) == 2:
                raise OSError(code, os.strerror(code))
            return real(a, b)

        monkeypatch.setattr(export.os, "replace", replace)
    outcome = check_refused(["export", str(source), "--out", str(earlier_export), "--every", "3"],
                            [os.strerror(code), "partial files were removed"],
                            watch=[earlier_export, source] if where != "moving-into-place"
                            else [source])
    assert ".part" not in outcome.stderr and _leftovers(earlier_export) == []


@pytest.mark.parametrize("suffix", [".png", ".gif"])
def test_an_animation_that_cannot_be_written_leaves_nothing(source, tmp_path, monkeypatch,
                                                           suffix, fast):
    import flex.tools.animate as animate

    monkeypatch.setattr(animate, "_write", _fail(errno.ENOSPC))
    out = tmp_path / f"a{suffix}"
    check_refused(["animate", str(source), "--out", str(out), "--frames", "2"],
                  [str(out), "No space left"], watch=[tmp_path])
    assert not out.exists() and _leftovers(tmp_path) == []


FSIZE_CHILD = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
from flex.cli import main
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.parametrize("limit", [100_000])
def test_a_file_size_limit_in_a_real_process_is_one_line_and_no_crash(source, earlier_export,
                                                                     limit):
    """The disk that fills, for real: HDF5 writing into a file that cannot grow printed pages
    of h5py tracebacks and crashed the interpreter (exit 139); now one line, exit 2."""
    before = fingerprint([earlier_export, source])
    env = dict(os.environ, PYTHONPATH=str(REPO), EXUDYN_NO_USER_SETTINGS="1",
               MPLBACKEND="Agg")
    done = subprocess.run([sys.executable, "-c", FSIZE_CHILD, str(limit), "export",
                           str(source), "--out", str(earlier_export)], env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == EXIT_BAD_INPUT, done.stderr[-2000:]
    errors = [line for line in done.stderr.splitlines() if line.startswith("flex: error:")]
    assert len(errors) == 1 and "File too large" in errors[0], done.stderr
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr
    assert fingerprint([earlier_export, source]) == before and _leftovers(earlier_export) == []


# --- modal coordinates that do not fit the reduction ---------------------------------------
@pytest.mark.parametrize("columns", [3, 9, "1-D"])
@pytest.mark.parametrize("command", ["export", "animate"])
def test_modal_coordinates_of_the_wrong_width_are_named(source, tmp_path, command, columns):
    with h5py.File(source, "r+") as h5:
        stored = h5["cases/case/coupler/modal_coordinates"]
        rows, width = stored.shape
        attrs = dict(stored.attrs)
        del h5["cases/case/coupler/modal_coordinates"]
        data = np.zeros(rows) if columns == "1-D" else np.zeros((rows, columns))
        h5.create_dataset("cases/case/coupler/modal_coordinates", data=data).attrs.update(attrs)
    out = tmp_path / ("out" if command == "export" else "a.png")
    found = f"({rows},)" if columns == "1-D" else f"({rows}, {columns})"
    check_refused([command, str(source), "--out", str(out)],
                  ["coupler/modal_coordinates", found, f"(samples, {width})"],
                  watch=[tmp_path])
    assert not out.exists()


# --- internal errors that are clear errors now ---------------------------------------------
def test_flex_scene_ladder_prints_its_scene():
    outcome = run_cli(["scene", "ladder"])
    assert outcome.status == EXIT_OK and "[coupler]" in outcome.stdout, outcome.stderr


BAD_ADDRESSES = [("tcp://localhost", "needs a port"), ("tcp://10.0.0.1", "needs a port"),
                 ("tls://[::1]", "needs a port"), ("ws://host:", "needs a port"),
                 ("tcp://host:99999", "outside 1..65535"), ("tcp://host:0", "outside"),
                 ("tcp://", "needs a port"), ("host:8786", "expected processes"),
                 ("", "expected processes")]


@pytest.mark.parametrize("address, words", BAD_ADDRESSES,
                         ids=[a or "empty" for a, _ in BAD_ADDRESSES])
def test_a_scheduler_address_without_a_usable_port_is_refused(tmp_path, address, words):
    check_refused(["run", "kfit", "--scheduler", address, "--out", str(tmp_path / "k.h5")],
                  [repr(address), words], watch=[tmp_path])


@pytest.mark.parametrize("address", ["tcp://localhost", "tcp://h:70000"])
def test_flex_scheduler_in_the_environment_is_checked_too(address):
    from flex.sweep import settings_from_environment

    with pytest.raises(FlexError, match="FLEX_SCHEDULER"):
        settings_from_environment({"FLEX_SCHEDULER": address})


@pytest.mark.parametrize("address", ["serial", "local", "processes", "tcp://127.0.0.1:8786",
                                     "tls://[::1]:8786", "inproc://worker/1"])
def test_good_scheduler_addresses_pass_the_check(address):
    from flex.sweep.executors import check_scheduler

    check_scheduler(address)


def test_an_auto_link_on_a_constant_speed_crank_at_rest_is_refused_in_one_line(tmp_path):
    """drive.crank_speed_rad_per_s = 0 with an auto coupler: refused before anything runs
    (exit 2), naming the key and what is accepted (the probe refuses it too, for callers of
    the library that skip the scene's checks)."""
    check_refused(["run", "simulate", "--no-figures", "--out", str(tmp_path / "p.h5"),
                   "--set", 'drive.kind="constant_speed"', "--set",
                   "drive.crank_speed_rad_per_s=0", "--set", 'coupler.geometry="plate"',
                   "--set", 'coupler.model="auto"', "--set", "simulation.end_time_s=0.004"],
                  ["drive.crank_speed_rad_per_s", "!= 0"])


PRELOAD_ZERO = [
    ("crank-auto-with-wing", ["wing.enabled=true", 'crank.model="auto"'], "crank.model"),
    ("coupler-auto", ['coupler.geometry="plate"', 'coupler.model="auto"'], "coupler.model"),
]


@pytest.mark.parametrize("sets, link", [(s, k) for _, s, k in PRELOAD_ZERO],
                         ids=[n for n, _, _ in PRELOAD_ZERO])
def test_auto_links_of_a_mechanism_that_does_not_deploy_fail_clearly(tmp_path, sets, link):
    """Preload 0: the rigid probe never moves (delta_t = 0); this divided by zero (exit 3)."""
    argv = ["run", "simulate", "--no-figures", "--out", str(tmp_path / "p.h5"),
            "--set", "drive.spring_preload_m=0", "--set", "simulation.end_time_s=0.004"]
    for item in sets:
        argv += ["--set", item]
    outcome = check_refused(argv, status=EXIT_FAILED)
    failed = [line for line in outcome.stderr.splitlines() if "FAILED case" in line]
    assert len(failed) == 1 and f'{link} = "auto"' in failed[0], outcome.stderr
    assert "does not deploy" in failed[0] and "spring_preload_m = 0" in failed[0]


# --- a result file of the same name that flex did not write ----------------------------------
RESULT_WRITERS = {
    "run": ["run", "simulate", "--no-figures", "--set", "simulation.end_time_s=0.004"],
    "design": ["design", "--vary", "preload", "--peak-speed", "50"],
}


@pytest.mark.parametrize("content", ["text", "empty", "plain-hdf5", "png-without-marker"])
@pytest.mark.parametrize("command", RESULT_WRITERS)
def test_a_result_file_flex_did_not_write_is_not_replaced(tmp_path, foreign, command, content):
    there = tmp_path / "mine.h5"
    there.write_bytes(foreign[content])
    outcome = check_refused([*RESULT_WRITERS[command], "--out", str(there)],
                            [str(there), "not written by flex", "nothing was run"],
                            watch=[tmp_path])
    assert "[0/" not in outcome.stderr and "flex: design: case" not in outcome.stderr


# --- inspect: attributes a hand made strings or arrays ---------------------------------------
PEAK = {"coupler_peak_von_mises_Pa": 2.8e7, "coupler_peak_von_mises_time_s": 0.015,
        "coupler_peak_von_mises_position_m": np.array([0.04, 0.0005, -0.005]),
        "estimated_error_coupler_peak_von_mises_Pa": 2.1e6,
        "crest_gap_coupler_peak_deflection_m": 2.3e-5, "refine_status": "met",
        "refine_wall_time_s": 16.8, "refine_attempts": "1: met"}
#: inspect's own lines (estimated_error_* budget rows: flex.fidelity.stored_budget.budget_rows)
BROKEN = ["coupler_peak_von_mises_Pa", "coupler_peak_von_mises_time_s",
          "crest_gap_coupler_peak_deflection_m", "refine_wall_time_s"]


@pytest.mark.parametrize("value", ["28 MPa", np.array([1.5, 2.5])], ids=["string", "array"])
@pytest.mark.parametrize("name", BROKEN)
def test_inspect_shows_a_hand_made_attribute_as_stored(tmp_path, name, value):
    from flex.data.results import CaseResult, Dataset, write_results

    attrs = dict(PEAK, **{name: value})
    path = write_results(tmp_path / "hand.h5", "simulate", [CaseResult("c", "", {
        "time": Dataset(np.linspace(0, 1, 3), "s")}, attrs=attrs)])
    before = fingerprint([path])
    outcome = run_cli(["inspect", str(path)])
    assert outcome.status == EXIT_OK and "Traceback" not in outcome.stderr, outcome.stderr
    shown = "28 MPa" if isinstance(value, str) else "[1.5, 2.5]"
    assert shown in outcome.stdout, outcome.stdout  # as stored, not a number made up
    assert fingerprint([path]) == before
