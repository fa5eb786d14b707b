"""Hostile input to the command line itself: arguments, outputs, failed runs, signals.

Every case asserts the contract of README "When something goes wrong" (see tests/hostile.py):
no traceback, the documented exit status, one ``flex: error:`` line naming the problem, and
no existing result, scene or figure file changed.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hostile import check_refused, fingerprint, run_cli

from flex.base.errors import EXIT_FAILED, EXIT_OK, EXIT_SIGINT, EXIT_SIGTERM, EXIT_STATUSES
from flex.data.results import CaseResult, Dataset, open_results, write_results

REPO = Path(__file__).resolve().parent.parent
SHORT = ["--set", "simulation.end_time_s=0.005"]
# a 1000x stiffer spring at h = 2 ms: Newton fails in the first steps (a failed case)
FAILING = ["--set", "simulation.end_time_s=0.02", "--set", "simulation.step_s=0.002",
           "--set", "drive.spring_stiffness_N_per_m=1.5e6"]


def previous_result(path: Path) -> Path:
    """A small complete result file standing for the last good run."""
    case = CaseResult("case", "", {"time": Dataset(np.linspace(0.0, 1.0, 11), "s", "time"),
                                   "crank/angle": Dataset(np.zeros(11), "rad", "last run")})
    write_results(path, "simulate", [case])
    return path


@pytest.fixture
def workspace(tmp_path):
    """A folder with a good result file, its figure and a scene file (all watched)."""
    good = previous_result(tmp_path / "good.h5")
    (tmp_path / "figures").mkdir()
    (tmp_path / "figures" / "good-crank-angle.png").write_bytes(b"yesterday's figure")
    scene = tmp_path / "scene.toml"
    scene.write_text("[crank]\ninitial_angle_deg = 40.0\n")
    (tmp_path / "notes.txt").write_text("a plain file\n")
    return tmp_path, good, scene


ARGUMENT_ERRORS = [
    ([], ["command"]),
    (["frobnicate"], ["frobnicate"]),
    (["run"], ["study"]),
    (["run", "nosuch"], ["nosuch"]),
    (["run", "Simulate"], ["simulate"]),
    (["run", ""], ["study"]),
    (["run", "simulate", "--bogus"], ["--bogus"]),
    (["run", "simulate", "extra"], ["extra"]),
    (["run", "simulate", "--workers"], ["--workers"]),
    (["run", "simulate", "--workers", "x"], ["--workers"]),
    (["run", "simulate", "--workers", "0"], ["--workers"]),
    (["run", "simulate", "--workers", "-3"], ["--workers"]),
    (["run", "simulate", "--workers", "2"], ["--workers", "kfit"]),
    (["run", "dynamics", "--scheduler", "local"], ["--scheduler", "kfit"]),
    (["run", "dynamics", "--folder", "cases"], ["--folder", "kfit"]),
    (["run", "simulate", "--retry-failed"], ["--retry-failed", "kfit"]),
    (["run", "kfit", "--scheduler", "bogus"], ["--scheduler"]),
    (["run", "kfit", "--scheduler", "http://x:1"], ["--scheduler"]),
    (["run", "kfit", "--scheduler", ""], ["--scheduler"]),
    (["run", "simulate", "--set"], ["--set"]),
    (["run", "simulate", "--set", "nodot=1"], ["nodot"]),
    (["run", "simulate", "--set", "crank.length_m"], ["crank.length_m"]),
    (["run", "simulate", "--scene"], ["--scene"]),
    (["run", "simulate", "--scene", "nosuch"], ["nosuch"]),
    (["run", "simulate", "--scene", "/nonexistent/x.toml"], ["x.toml"]),
    (["run", "simulate", "--out"], ["--out"]),
    (["scene"], ["study"]),
    (["scene", "nosuch"], ["nosuch"]),
    (["scene", "simulate", "--out", "x.h5"], ["--out"]),
    (["scene", "simulate", "--set", "crank.bogus_m=1"], ["crank.bogus_m"]),
    (["scene", "simulate", "--set", "bogus.key=1"], ["bogus"]),
    (["inspect"], ["file"]),
    (["inspect", "a.h5", "b", "c"], ["c"]),
    (["inspect", "--bogus", "a.h5"], ["--bogus"]),
    (["plot"], ["file"]),
    (["plot", "a.h5"], ["path"]),
    (["plot", "a.h5", "x", "--vs"], ["--vs"]),
    (["compare"], ["a.h5"]),
    (["compare", "a.h5"], ["b.h5"]),
    (["compare", "a.h5", "b.h5", "--rtol", "x"], ["--rtol"]),
    (["compare", "a.h5", "b.h5", "--atol", "one"], ["--atol"]),
    (["compare", "a.h5", "b.h5", "--limit", "1.5"], ["--limit"]),
    (["compare", "a.h5", "b.h5", "--interp", "spline"], ["--interp"]),
    (["compare", "a.h5", "b.h5", "--json", "--bogus"], ["--bogus"]),
    (["--bogus"], ["--bogus"]),
]


@pytest.mark.parametrize("argv, names", ARGUMENT_ERRORS, ids=lambda v: " ".join(v) or "none"
                         if isinstance(v, list) else None)
def test_bad_arguments_are_refused_in_one_line(workspace, argv, names):
    folder, good, scene = workspace
    os.chdir(folder)
    check_refused(argv, names, watch=[folder])


def output_errors(folder: Path, good: Path, scene: Path) -> list[tuple[list[str], list[str]]]:
    (folder / "taken.h5").mkdir(exist_ok=True)
    (folder / "link-to-scene.h5").unlink(missing_ok=True)
    (folder / "link-to-scene.h5").symlink_to(scene)
    return [
        (["--out", ""], ["--out"]),
        (["--out", "   "], ["--out"]),
        (["--out", "result.txt"], [".h5"]),
        (["--out", "result"], [".h5"]),
        (["--out", str(scene)], [".h5"]),
        (["--out", str(folder / "taken.h5")], ["folder"]),
        (["--out", str(folder / "notes.txt" / "x.h5")], ["notes.txt", "not a folder"]),
        (["--out", str(folder / "notes.txt" / "deeper" / "x.h5")], ["notes.txt"]),
        (["--out", str(folder / "link-to-scene.h5"), "--scene", str(scene)], ["input"]),
        (["--out", str(good), "--scene", str(good)], ["good.h5"]),
        (["--out", str(folder / "x.h5"), "--scene", str(folder / "notes.txt")], ["notes.txt"]),
    ]


@pytest.mark.parametrize("index", range(11))
def test_bad_outputs_are_refused_before_anything_runs(workspace, index):
    folder, good, scene = workspace
    os.chdir(folder)
    extra, names = output_errors(folder, good, scene)[index]
    check_refused(["run", "simulate", "--no-figures", *SHORT, *extra], names,
                  watch=[good, scene, folder / "figures"])


@pytest.mark.parametrize("study", ["simulate", "kinematics", "dynamics"])
def test_an_unwritable_figures_folder_is_refused_up_front(workspace, study):
    folder, good, scene = workspace
    out = folder / "runs" / "new.h5"
    out.parent.mkdir()
    (out.parent / "figures").write_text("a file where the figures folder would go")
    check_refused(["run", study, *SHORT, "--out", str(out)], ["figures"],
                  watch=[out.parent, good])
    assert not out.exists()


def test_a_failed_run_keeps_the_last_good_file_and_says_so(workspace):
    folder, good, scene = workspace
    before = fingerprint([folder])
    outcome = run_cli(["run", "simulate", "--out", str(good), *FAILING])
    assert outcome.status == EXIT_FAILED and "Traceback" not in outcome.stderr
    assert "FAILED case case" in outcome.stderr
    assert f"'{good}' was kept as it was" in outcome.stderr
    after = fingerprint([folder])
    failed = folder / "good.failed.h5"
    assert {path: after[path] for path in before} == before  # nothing existing changed
    assert set(after) - set(before) == {failed, folder / "reports" / "good.failed.md"}
    with open_results(failed) as h5:
        assert h5["cases/case"].attrs["status"] == "failed"


def test_quiet_still_reports_failed_cases(workspace):
    folder, good, scene = workspace
    outcome = run_cli(["run", "simulate", "--quiet", "--out", str(good), *FAILING])
    assert outcome.status == EXIT_FAILED and outcome.stdout == ""
    assert "FAILED case case" in outcome.stderr and "kept as it was" in outcome.stderr


def test_a_failed_run_without_an_earlier_file_is_written_with_status_1(tmp_path):
    out = tmp_path / "first.h5"
    outcome = run_cli(["run", "simulate", "--quiet", "--out", str(out), *FAILING])
    assert outcome.status == EXIT_FAILED and out.exists()
    assert not (tmp_path / "figures").exists()  # no figures of a failed run


def test_figures_are_named_after_the_result_file(tmp_path):
    for name in ("a", "b"):
        assert run_cli(["run", "simulate", "--quiet", "--out", str(tmp_path / f"{name}.h5"),
                        *SHORT]).status == EXIT_OK
    names = sorted(p.name for p in (tmp_path / "figures").iterdir())
    assert names == ["a-crank-angle.png", "b-crank-angle.png"]


def test_version_and_help_state_the_exit_statuses():
    version = run_cli(["--version"])
    assert version.status == 0 and version.stdout.startswith("flex ")
    for argv in (["--help"], ["run", "--help"]):
        helped = run_cli(argv)
        assert helped.status == 0
        for code in EXIT_STATUSES:
            assert f"  {code} " in helped.stdout


# --- signals: real processes ------------------------------------------------------------
def flex_process(args: list[str], cache: Path) -> subprocess.Popen:
    env = dict(os.environ, EXUDYN_NO_USER_SETTINGS="1", MPLBACKEND="Agg",
               FLEX_CACHE_DIR=str(cache))
    return subprocess.Popen([sys.executable, "-m", "flex", *args], cwd=REPO, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def signal_when(proc: subprocess.Popen, sig: signal.Signals, ready, limit_s: float = 300
                ) -> tuple[bool, str]:
    """Send ``sig`` once ``ready()`` is true; return (sent, stderr)."""
    start, sent = time.perf_counter(), False
    while proc.poll() is None and time.perf_counter() - start < limit_s:
        if ready():
            proc.send_signal(sig)
            sent = True
            break
        time.sleep(0.001)
    _, err = proc.communicate(timeout=limit_s)
    return sent, err


PHASES = {
    # integration: a long constant-speed run, signalled after the imports
    "integration": (["run", "kinematics", "--set", "simulation.end_time_s=20.0",
                     "--set", "simulation.step_s=1e-5", "--set", "simulation.output_step_s=1e-2"],
                    "time", 4.0),
    # meshing and reduction of an FFRF coupler into an empty cache
    "meshing": (["run", "simulate", "--set", 'coupler.model="ffrf"',
                 "--set", 'coupler.geometry="plate"',
                 "--set", "coupler.mesh_size_m=0.0015", "--set", "simulation.end_time_s=0.002",
                 "--set", "simulation.step_s=1e-5"], "time", 3.0),
    # writing: as soon as the temporary part of the result file exists
    "writing": (["run", "kinematics", "--set", "simulation.end_time_s=1.0",
                 "--set", "simulation.output_step_s=1e-4"], "part", None),
    # figures: as soon as the private figures folder exists
    "figures": (["run", "simulate", "--set", "simulation.end_time_s=0.01"], "figures", None),
}


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=lambda s: s.name)
@pytest.mark.parametrize("phase", list(PHASES))
def test_signals_at_each_phase_leave_nothing_half_done(tmp_path, phase, sig):
    out = previous_result(tmp_path / "run.h5")
    figures = tmp_path / "figures"
    figures.mkdir()
    (figures / "run-crank-angle.png").write_bytes(b"last good figure")
    before = fingerprint([tmp_path])
    args, trigger, delay = PHASES[phase]
    proc = flex_process([*args, "--out", str(out)], tmp_path / "cache")
    start = time.perf_counter()
    ready = {
        "time": lambda: time.perf_counter() - start >= delay,
        "part": lambda: any(tmp_path.glob(".run.h5.*.part")),
        "figures": lambda: any(figures.glob(".run.*.figures")),
    }[trigger]
    sent, err = signal_when(proc, sig, ready)
    assert sent, f"the run ended before the {phase} phase was seen: {err[-300:]}"
    assert "Traceback" not in err, err
    expected = EXIT_SIGINT if sig == signal.SIGINT else EXIT_SIGTERM
    assert proc.returncode == expected, err
    word = "interrupted" if sig == signal.SIGINT else "terminated"
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"flex: {word};"), err
    after = fingerprint([tmp_path])
    leftovers = [p for p in tmp_path.rglob("*") if p.name.endswith((".part", ".figures"))]
    assert leftovers == []
    if "already written" in last:  # the signal came after the result was complete
        assert phase == "figures" and after[out] != before[out]
        assert after[figures / "run-crank-angle.png"] == before[figures / "run-crank-angle.png"]
    else:
        assert last == f"flex: {word}; no result file was changed"
        assert {path: after.get(path) for path in before} == before


def test_the_old_python_m_flex_sweep_says_where_it_went(workspace):
    """``python -m flex.sweep`` became part of ``flex run``: one line saying so, status 2,
    nothing run or written."""
    folder, good, scene = workspace
    before = fingerprint([folder])
    done = subprocess.run([sys.executable, "-m", "flex.sweep", "kfit", "--retry-failed"],
                          cwd=folder, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "flex run" in lines[0], done.stderr
    assert fingerprint([folder]) == before
