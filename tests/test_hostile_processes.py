"""Processes that outlive their run: none.

- A run's worker processes end with it however it ends: SIGKILL of the run (no clean-up
  can run: the kernel's parent-death signal, :func:`flex.sweep.executors.die_with_parent`),
  Ctrl-C or SIGTERM (:meth:`~flex.sweep.executors.ProcessExecutor.abort`, which kills a
  worker that does not end on SIGTERM: one in an eigen-solve, or in an Exudyn solve that
  turns SIGTERM into an exception and asks for the next case).
- ``kill <make pid>`` reaches only make's shells: each passes it on to its ``flex run`` and
  waits for it; no ``results/.<study>.h5.before`` stays behind.
- An interrupted sweep's last progress line says "interrupted", not "finished".

Each real process is signalled once it said it is ready (a line, or its workers seen in
/proc); the 15 s deadlines are the issue's ("no process of a killed run alive 15 s later")
and only bound a poll.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DEADLINE_S = 15.0


def _environment() -> dict[str, str]:
    return dict(os.environ, PYTHONPATH=str(REPO), EXUDYN_NO_USER_SETTINGS="1", MPLBACKEND="Agg")


def _session(sid: int) -> list[tuple[int, str]]:
    """Live processes (pid, command line) of session ``sid``, from /proc (zombies left out:
    they have ended)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        if int(fields[3]) == sid and fields[0] not in "ZX":
            found.append((int(entry.name), command))
    return found


def _children(pid: int) -> list[int]:
    return [p for p, _ in _session(pid) if p != pid]


def _gone_within(sid: int, seconds: float = DEADLINE_S) -> list[tuple[int, str]]:
    """Poll until session ``sid`` has no live process or ``seconds`` passed; what is left."""
    end = time.monotonic() + seconds
    while (left := _session(sid)) and time.monotonic() < end:
        time.sleep(0.2)
    return left


def _reap_leftovers(left: list[tuple[int, str]]) -> None:
    for pid, _ in left:  # only processes of the session this test started
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")

# a parent with a pool of two workers, each in a long case that ignores SIGTERM
POOL = """
import signal, sys, time
from flex.sweep import make_executor

executor = make_executor(workers=int(sys.argv[1]))
futures = [executor.submit(signal.signal, signal.SIGTERM, signal.SIG_IGN)
           for _ in range(executor.workers)]
[f.result() for f in futures]
for _ in range(executor.workers):
    executor.submit(time.sleep, 600)
print("ready", flush=True)
if sys.argv[2] == "abort":
    time.sleep(1.0)  # the sleeps have started
    executor.abort()
    print("aborted", flush=True)
    time.sleep(600)
time.sleep(600)
"""


def _start_pool(mode: str, workers: int = 2) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-c", POOL, str(workers), mode],
                            env=_environment(), stdout=subprocess.PIPE, text=True,
                            start_new_session=True)
    assert proc.stdout.readline().strip() == "ready"
    return proc


def test_the_workers_of_a_killed_run_end_with_it():
    proc = _start_pool("wait")
    assert len(_children(proc.pid)) >= 2  # the workers (and the resource tracker)
    proc.kill()
    proc.wait()
    left = _gone_within(proc.pid)
    _reap_leftovers(left)
    assert not left, f"still alive {DEADLINE_S:g} s after SIGKILL of their run: {left}"


LAUNCHER = """
import subprocess, sys, time
from flex.base.lifetime import dying_with_this_process

child = subprocess.Popen(dying_with_this_process(["sleep", "600"]))
print(child.pid, flush=True)
time.sleep(600)
"""


def test_a_command_a_run_starts_ends_with_it():
    """The ``make all`` that ``make bench`` times: SIGTERM when its run is killed."""
    proc = subprocess.Popen([sys.executable, "-c", LAUNCHER], env=_environment(),
                            stdout=subprocess.PIPE, text=True, start_new_session=True)
    child = int(proc.stdout.readline())
    while not any(pid == child and command.startswith("sleep")  # exec'd: armed
                  for pid, command in _session(proc.pid)):
        time.sleep(0.05)
    proc.kill()
    proc.wait()
    left = _gone_within(proc.pid)
    _reap_leftovers(left)
    assert not left, left


def test_an_abort_ends_workers_that_do_not_end_on_sigterm():
    proc = _start_pool("abort", workers=1)
    workers = [pid for pid, command in _session(proc.pid) if "spawn_main" in command]
    assert workers
    assert proc.stdout.readline().strip() == "aborted"  # returned: nothing joined forever
    alive = [pid for pid, _ in _session(proc.pid) if pid in workers]
    proc.kill()
    proc.wait()
    _reap_leftovers(_gone_within(proc.pid))
    assert not alive, f"workers alive after abort(): {alive}"


def test_an_interrupted_sweep_does_not_say_finished(tmp_path, capsys):
    from flex.data.scene import load_scene
    from flex.sweep import SerialExecutor, run_sweep

    class Interrupted(SerialExecutor):
        def submit(self, function, *args):
            return object()  # a case that never finishes

        def wait_first(self, futures, timeout=None):
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep({"a": load_scene(None)}, tmp_path, executor=Interrupted(), study="demo")
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last.startswith("demo: 0/1 cases") and last.endswith(", interrupted"), last


# --- make: kill <make pid> ------------------------------------------------------------------
LONG_RUN = """#!/bin/sh
# stands in for a long `flex run STUDY`: says it is ready, ends 143 on SIGTERM
trap 'echo new > results/$1.h5; exit 143' TERM
echo $$ > "$PIDS/run"
while :; do sleep 0.05; done
"""


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make")
@pytest.mark.parametrize("earlier", [True, False], ids=["rerun", "first-run"])
def test_killing_make_ends_its_run_and_leaves_no_before_file(tmp_path, earlier):
    shutil.copy(REPO / "Makefile", tmp_path / "Makefile")
    for name in ("studies/spring.py", "studies/__init__.py", "pyproject.toml",
                 ".venv/.installed"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).touch()
    result = tmp_path / "results" / "spring.h5"
    if earlier:
        result.parent.mkdir()
        result.write_text("earlier\n")
        os.utime(result, (1e9, 1e9))  # older than the study module: out of date
    (tmp_path / "run.sh").write_text(LONG_RUN)
    env = {k: v for k, v in os.environ.items() if not k.startswith("MAKE")}
    env.update(PIDS=str(tmp_path), LC_ALL="C")
    make = subprocess.Popen(["make", "--no-print-directory", "-C", str(tmp_path),
                             "PYTHON=false", f"RUN=sh {tmp_path / 'run.sh'}", "spring"],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    pid_file = tmp_path / "run"
    while not (pid_file.exists() and pid_file.read_text().strip()):  # the run is ready
        assert make.poll() is None, make.communicate()
        time.sleep(0.05)
    make.terminate()  # make alone, as `kill <make pid>`
    try:
        _, err = make.communicate(timeout=60)  # guards against a hang only
    except subprocess.TimeoutExpired:
        err = "make did not end within 60 s"
    left = _gone_within(make.pid)
    _reap_leftovers(left)
    assert not left, f"the run outlived make: {left}; {err}"
    assert make.returncode not in (None, 0)
    assert not list(result.parent.glob(".*.before")), "a .before file stayed behind"
    if earlier:  # the interrupted run changed it: its old time stamp is back (out of date)
        assert result.stat().st_mtime == 1e9
    else:
        assert not result.exists() and (result.parent / "spring.failed.h5").exists()


# --- the real command line -----------------------------------------------------------------
def _flex_run_with_workers(tmp_path: Path) -> subprocess.Popen:
    """``flex run kfit --workers 2`` in its own session, returned once its two workers run."""
    proc = subprocess.Popen([sys.executable, "-m", "flex", "run", "kfit", "--workers", "2",
                             "--folder", str(tmp_path / "cases"), "--out",
                             str(tmp_path / "kfit.h5"), "--no-figures"],
                            env=dict(_environment(), FLEX_CACHE_DIR=str(tmp_path / "cache")),
                            cwd=tmp_path, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    while sum("spawn_main" in command for _, command in _session(proc.pid)) < 2:
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.2)
    time.sleep(2.0)  # the workers are computing cases
    return proc


def test_sigkill_of_a_real_sweep_leaves_no_process(tmp_path):
    proc = _flex_run_with_workers(tmp_path)
    proc.kill()
    proc.wait()
    left = _gone_within(proc.pid)
    _reap_leftovers(left)
    assert not left, f"alive {DEADLINE_S:g} s after SIGKILL of flex run kfit: {left}"


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=lambda s: s.name)
def test_one_signal_to_flex_alone_ends_a_real_sweep(tmp_path, sig):
    proc = _flex_run_with_workers(tmp_path)
    proc.send_signal(sig)  # to flex alone, not its process group
    try:
        _, err = proc.communicate(timeout=60)  # guards against a hang only
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
        pytest.fail(f"{sig.name} to flex alone not honoured within 60 s: {err[-500:]}")
    left = _gone_within(proc.pid)
    _reap_leftovers(left)
    assert proc.returncode == (130 if sig == signal.SIGINT else 143), err
    assert not left, left
    assert "Traceback" not in err and ", finished" not in err, err[-800:]
