"""Interrupts that are never swallowed, final messages that tell the truth, and a command
line that is never silent for long.

- A Ctrl-C or SIGTERM that lands inside a weakref callback, a ``weakref.finalize`` or a
  ``__del__`` (Python can only print "Exception ignored" there) still ends the run with 130
  or 143 and one line; each real process is signalled once it printed a readiness line from
  inside the callback (no timer), and without :mod:`flex.base.interrupts` it would hang.
- An interrupt while ``flex run --animate`` animates names the result file, figures, report
  and animations already written (it used to say "no result file was changed").
- stderr gets a line at least every 10 s (:func:`flex.base.progress.silence_watch`);
  ``flex export`` says what it will write before writing; the README's output folders are
  ignored by git; ``flex inspect`` of a refined run shows the settings the run used.
"""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from hostile import assert_no_traceback, fingerprint, run_cli

from flex.base.errors import EXIT_OK, EXIT_SIGINT, EXIT_SIGTERM, Terminated

REPO = Path(__file__).resolve().parents[1]
SIGNALS = [signal.SIGINT, signal.SIGTERM]
EXPECTED = {signal.SIGINT: (EXIT_SIGINT, "interrupted"),
            signal.SIGTERM: (EXIT_SIGTERM, "terminated")}

SWALLOWING = """
import gc, sys, threading, weakref
import flex.cli as cli

class Thing:
    def __del__(self):
        if KIND == "__del__":
            wait_inside()

def wait_inside():
    print("ready", flush=True)
    threading.Event().wait()  # the signal arrives here, inside the callback

def dispatch(argv):
    thing = Thing()
    if KIND == "weakref":
        keep = weakref.ref(thing, lambda ref: wait_inside())
    elif KIND == "finalize":
        weakref.finalize(thing, wait_inside)
    del thing  # runs the callback; the interrupt raised in it is "ignored" by Python
    threading.Event().wait()  # so without flex.base.interrupts: forever
    return 0

KIND = sys.argv[1]
cli._dispatch = dispatch
sys.exit(cli.main([]))
"""


def _environment() -> dict[str, str]:
    return dict(os.environ, PYTHONPATH=str(REPO), EXUDYN_NO_USER_SETTINGS="1", MPLBACKEND="Agg")


def _signal_when_ready(argv: list[str], sig: signal.Signals, ready: str = "ready",
                       cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Start ``argv``, read its stdout until the line ``ready``, send ``sig`` and wait; the
    timeout only guards against a hang (the failure it would show)."""
    proc = subprocess.Popen(argv, env=_environment(), cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    seen = []
    for line in proc.stdout:
        seen.append(line)
        if line.strip() == ready:
            proc.send_signal(sig)
            break
    try:
        out, err = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        pytest.fail(f"{sig.name} was swallowed: still running 120 s after it; {err[-500:]}")
    assert seen and seen[-1].strip() == ready, (seen, err)
    return subprocess.CompletedProcess(argv, proc.returncode, "".join(seen) + out, err)


@pytest.mark.parametrize("kind", ["weakref", "finalize", "__del__"])
@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: s.name)
def test_an_interrupt_inside_a_callback_is_not_swallowed(kind, sig):
    done = _signal_when_ready([sys.executable, "-c", SWALLOWING, kind], sig)
    status, word = EXPECTED[sig]
    assert done.returncode == status, done.stderr
    assert done.stderr.strip().splitlines() == [f"flex: {word}; no result file was changed"]


# --- flex run --animate, interrupted while animating ---------------------------------------
SHORT = ["--set", "simulation.end_time_s=0.004", "--set", "simulation.error_estimate=false"]


def _animate_argv(out: Path) -> list[str]:
    return ["run", "simulate", "--out", str(out), "--animate", *SHORT]


@pytest.mark.parametrize("before", [0, 1], ids=["first-animation", "second-animation"])
@pytest.mark.parametrize("kind", [KeyboardInterrupt, Terminated], ids=["SIGINT", "SIGTERM"])
def test_an_interrupt_while_animating_names_what_was_written(tmp_path, monkeypatch, kind,
                                                             before):
    import flex.cli as cli
    import flex.tools.animate as animate

    made = tmp_path / "figures" / "run-case.gif"

    def animations(result, **kwargs):
        for _ in range(before):
            made.write_bytes(b"GIF89a")
            yield animate.Animation(made, 2, 960, 540, 25, 1.0)
        raise kind

    monkeypatch.setattr(animate, "animate_results", animations)
    monkeypatch.setattr(cli, "_check_animate", lambda *args: None)  # a rigid, quick run
    outcome = run_cli(_animate_argv(tmp_path / "run.h5"))
    assert_no_traceback(outcome)
    status, word = EXPECTED[signal.SIGINT if kind is KeyboardInterrupt else signal.SIGTERM]
    assert outcome.status == status
    last = outcome.stderr.strip().splitlines()[-1]
    assert last.startswith(f"flex: {word}; already written: "), last
    written = [Path(p) for p in last.split("already written: ")[1].split(";")[0].split(", ")]
    assert tmp_path / "run.h5" in written and tmp_path / "reports" / "run.md" in written
    assert any(p.parent.name == "figures" and p.suffix == ".png" for p in written)
    assert (made in written) is bool(before) and all(p.exists() for p in written)


ANIMATE_BLOCKS = """
import sys, threading
import flex.cli as cli
import flex.tools.animate as animate
from flex.cli import main

def animations(result, **kwargs):
    print("ready", flush=True)  # the result, figures and report are in place
    threading.Event().wait()
    yield

animate.animate_results = animations
cli._check_animate = lambda *args: None  # a rigid, quick run
sys.exit(main(sys.argv[1:]))
"""


def test_sigterm_while_animating_in_a_real_process(tmp_path):
    """The reported case: SIGTERM during ``--animate`` said "no result file was changed"."""
    done = _signal_when_ready([sys.executable, "-c", ANIMATE_BLOCKS,
                               *_animate_argv(tmp_path / "run.h5"), "--no-figures"],
                              signal.SIGTERM)
    assert done.returncode == EXIT_SIGTERM, done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("flex: terminated; already written: ") and "run.h5" in last, last
    assert "no result file was changed" not in done.stderr and "Traceback" not in done.stderr


# --- never silent for long -------------------------------------------------------------------
class _Lines(io.StringIO):
    """A stream that says when a line containing ``wanted`` was written."""

    def __init__(self, wanted: str) -> None:
        super().__init__()
        self.wanted, self.seen = wanted, threading.Event()

    def write(self, text: str) -> int:
        written = super().write(text)
        if self.wanted in self.getvalue():
            self.seen.set()
        return written


def test_silence_watch_speaks_when_nothing_else_does():
    from flex.base.progress import silence_watch

    stream = _Lines("still working")
    with silence_watch(stream, interval_s=0.01) as watched:
        print("flex: reducing the coupler", file=watched)
        while "(last line" not in stream.getvalue():  # a loaded machine may speak first
            assert stream.seen.wait(timeout=60)  # the timeout only guards against a hang
            threading.Event().wait(0.005)
    text = stream.getvalue()
    line = text[text.index("flex: reducing the coupler"):].splitlines()[1]
    assert line.startswith("flex: still working after ")
    assert line.endswith("ago: flex: reducing the coupler)")


def test_silence_watch_names_the_work_s_line_not_its_own():
    """A long silence (the cases on worker processes) gives one plain line per interval, each
    naming the work's last line: never the watch's previous line nested inside."""
    from flex.base.progress import silence_watch

    stream = _Lines("still working")
    with silence_watch(stream, interval_s=0.01) as watched:
        print("flex: reducing the coupler", file=watched)
        while stream.getvalue().count("(last line") < 3:
            threading.Event().wait(0.005)
    text = stream.getvalue()
    lines = text[text.index("flex: reducing the coupler"):].splitlines()[1:]
    assert len(lines) >= 2 and all(line.count("still working") == 1 and
               line.endswith("ago: flex: reducing the coupler)") for line in lines)


def test_the_command_line_is_never_silent_for_its_interval(monkeypatch):
    import flex.cli as cli

    def quiet_work(argv):  # many short steps, none of which says anything
        while "still working" not in sys.stderr.getvalue():
            threading.Event().wait(0.001)
        return EXIT_OK

    monkeypatch.setattr(cli, "PROGRESS_INTERVAL_S", 0.01)
    monkeypatch.setattr(cli, "_dispatch", quiet_work)
    outcome = run_cli([])
    assert outcome.status == EXIT_OK and "flex: still working after" in outcome.stderr


def test_jobs_report_before_the_silence_watch_would():
    """A job's own progress lines (heartbeats, integrations, sweeps, exports) come a little
    more often than the silence watch speaks, so a log does not get both."""
    import inspect

    from flex.base.progress import PROGRESS_INTERVAL_S, Progress, heartbeat
    from flex.sweep import PROGRESS_MAX_SILENCE_S
    from flex.tools.export import PROGRESS_INTERVAL_S as EXPORT_INTERVAL_S

    reporters = [inspect.signature(heartbeat).parameters["interval_s"].default,
                 inspect.signature(Progress).parameters["interval_s"].default,
                 PROGRESS_MAX_SILENCE_S, EXPORT_INTERVAL_S]
    assert PROGRESS_INTERVAL_S <= 10 and all(r < PROGRESS_INTERVAL_S for r in reporters)


def test_export_says_what_it_will_write_before_writing(tiny_ffrf_file, tmp_path):
    out = tmp_path / "out"
    outcome = run_cli(["export", str(tiny_ffrf_file), "--out", str(out)])
    assert outcome.status == EXIT_OK, outcome.stderr
    (line,) = [x for x in outcome.stderr.splitlines() if x.startswith("flex export: case:")]
    assert "times x" in line and "up to" in line and "free" in line
    assert str(out / "plate-case.xdmf") in line


@pytest.mark.parametrize("path", ["exported/plate-case.h5", "runs/soft.h5"])
def test_the_readmes_output_folders_are_ignored_by_git(path):
    if not (REPO / ".git").exists():
        pytest.skip("not a git checkout")
    done = subprocess.run(["git", "check-ignore", "-q", "--no-index", path], cwd=REPO)
    assert done.returncode == 0, f"{path} would show as untracked"


# --- inspect: a refined run, a selection ------------------------------------------------------
@pytest.fixture
def refined_file(tmp_path) -> Path:
    from flex.data.results import CaseResult, Dataset, write_results
    from flex.data.scene import load_scene, to_toml

    guess = "coupler.modes = 2, coupler.mesh_size_m = 0.002, step_s = 8e-05, newton = 'full'"
    ran = load_scene(overrides=['coupler.geometry="plate"', 'coupler.model="ffrf"',
                                "coupler.modes=4", "coupler.mesh_size_m=0.002",
                                "simulation.step_s=4e-05", 'simulation.newton="full"',
                                "simulation.spectral_radius=0.9",
                                "simulation.newton_relative_tolerance=1e-08"])
    cases = [CaseResult(name, to_toml(ran), {"time": Dataset(np.linspace(0, 1, 3), "s"),
                                             "crank/angle": Dataset(np.zeros(3), "rad")},
                        attrs={"solver_defaults_keys": guess, "solver_defaults_entry": "rule",
                               "refine_status": "met", "refine_attempts": "1: ...\n2: met"})
             for name in ("a", "b")]
    return write_results(tmp_path / "refined.h5", "simulate", cases[:1]), write_results(
        tmp_path / "two.h5", "simulate", cases)


def test_inspect_of_a_refined_run_shows_the_settings_it_ran_with(refined_file):
    one, _ = refined_file
    outcome = run_cli(["inspect", str(one)])
    assert outcome.status == EXIT_OK, outcome.stderr
    text = outcome.stdout
    assert 'solver: "auto" -> first guess coupler.modes = 2' in text
    assert ("refined (fidelity.refine: met): the stored run used coupler.modes = 4, "
            "coupler.mesh_size_m = 0.002, step_s = 4e-05, newton = 'full'") in text
    scene = text.split("scene of case a (resolved: the settings it ran with, after "
                       "refinement)")[1]
    assert '"auto"' not in scene and "modes = 4" in scene and "step_s = 4e-05" in scene


@pytest.mark.parametrize("spec, shown", [("a/crank/angle", "the 1 of the file's 2 cases"),
                                         ("cases/b/time", "the 1 of the file's 2 cases"),
                                         (None, None)])
def test_inspect_path_says_how_many_of_the_files_cases_it_shows(refined_file, spec, shown):
    _, two = refined_file
    before = fingerprint([two])
    outcome = run_cli(["inspect", str(two), *([spec] if spec else [])])
    assert outcome.status == EXIT_OK, outcome.stderr
    head = outcome.stdout.splitlines()[1]
    assert (shown in head) if shown else ("cases: a ok, b ok" in head and "of the" not in head)
    assert fingerprint([two]) == before
