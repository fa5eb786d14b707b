"""Reliability of result files and scene input, tested with real processes.

- a run killed at any point (SIGKILL, SIGINT, a full disk) leaves the previous file intact
  and no half-written file under the final name; a killed writer's temporary part is removed
  by the next write;
- two processes writing the same path at once: the last complete writer wins, readers never
  see a partial file;
- the same scene and code give bit-identical datasets (timings and timestamps aside);
- random and hostile scene files and --set values are refused with one clear line.
"""

from __future__ import annotations

import os
import random
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from flex.base.errors import ResultFileError, SceneError
from flex.data.results import (
    CaseResult,
    Dataset,
    open_results,
    read_case,
    remove_stale_parts,
    write_results,
)
from flex.data.scene import SCHEMA, load_scene
from flex.study import run_study
from flex.tools.inspect import describe

REPO = Path(__file__).resolve().parent.parent
# 10001 samples (~3 MB): the write phase (create, fsync, rename) lasts a few tenths of a second
SLOW_RUN = ["run", "kinematics", "--no-figures", "--quiet", "--set", "simulation.end_time_s=1.0",
            "--set", "simulation.output_step_s=1e-4"]


def flex_command(*args: str) -> list[str]:
    return [sys.executable, "-m", "flex", *args]


def environment() -> dict[str, str]:
    return dict(os.environ, EXUDYN_NO_USER_SETTINGS="1", MPLBACKEND="Agg")


def parts_of(path: Path, pid: int | str = "*") -> list[Path]:
    return sorted(path.parent.glob(f".{path.name}.{pid}.*.part"))


def write_previous(path: Path) -> bytes:
    """A small, complete result file standing for yesterday's run; returns its bytes."""
    case = CaseResult("constant_speed", "", {
        "time": Dataset(np.linspace(0.0, 1.0, 11), "s", "simulation time"),
        "slider/position": Dataset(np.full(11, 0.12), "m", "previous run")})
    write_results(path, "kinematics", [case])
    return path.read_bytes()


def kill_run(out: Path, sig: signal.Signals, when: str | float
             ) -> tuple[subprocess.CompletedProcess, int]:
    """Start ``flex run`` writing ``out``; send ``sig`` while it writes (``"writing"``: as
    soon as its temporary part exists) or ``when`` seconds after the start. Returns the
    finished process and its pid."""
    proc = subprocess.Popen(flex_command(*SLOW_RUN, "--out", str(out)), cwd=REPO,
                            env=environment(), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    start = time.perf_counter()
    sent = False
    while proc.poll() is None and time.perf_counter() - start < 120:
        due = (parts_of(out, proc.pid) if when == "writing"
               else time.perf_counter() - start >= when)
        if due:
            proc.send_signal(sig)
            sent = True
            break
        time.sleep(0.0005)
    stdout, stderr = proc.communicate(timeout=120)
    assert sent or when != "writing", "the run finished before its write phase was seen"
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout.decode(),
                                       stderr.decode()), proc.pid


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_killed_runs_leave_the_previous_file_intact(tmp_path):
    out = tmp_path / "kinematics.h5"
    previous = write_previous(out)
    rng = random.Random(1234)
    # mid-write (as soon as the temporary part exists) and at a random moment of the run
    # the random moment gets SIGKILL: whatever the moment (still importing, integrating,
    # writing, done), the file must be whole; a SIGINT while importing would test Python's
    # default handler, not flex's
    attempts = [(signal.SIGKILL, "writing"), (signal.SIGINT, "writing"),
                (signal.SIGKILL, rng.uniform(0.3, 2.0))]
    for sig, when in attempts:
        result, pid = kill_run(out, sig, when)
        what = f"{sig.name} at {when}: rc {result.returncode}, stderr {result.stderr[-300:]!r}"
        with open_results(out) as h5:  # never half-written: always a complete flex file
            assert "cases/constant_speed/slider/position" in h5, what
        late = out.read_bytes() != previous
        if late:
            # the signal landed after the atomic rename (the write phase lasts only tenths of
            # a second, so this race is real): then the new file must be complete
            assert len(read_case(out, "constant_speed")["time"]) == 10001, what
            previous = out.read_bytes()
        if when == "writing" and sig == signal.SIGINT and not late:
            assert result.returncode == 130, what
            assert result.stderr.strip() == "flex: interrupted; no result file was changed"
        others = {p.name for p in tmp_path.iterdir()} - {out.name, "reports"}
        # SIGKILL cannot clean up: at most its own hidden part, never a *.h5 file
        assert all(name.startswith(f".{out.name}.") and name.endswith(".part")
                   for name in others), what
        if sig == signal.SIGINT:  # Ctrl-C: the run removes its own part
            assert parts_of(out, pid) == [], what
    # the next write of the same path removes the parts the killed runs left
    write_previous(out)
    assert [p.name for p in tmp_path.iterdir() if p.name != "reports"] == [out.name]


def test_full_disk_keeps_the_previous_file_and_says_so(tmp_path):
    out = tmp_path / "kinematics.h5"
    previous = write_previous(out)

    def small_disk() -> None:  # the child may write at most 256 kB per file ("disk full")
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (256 * 1024, 256 * 1024))

    run = ["run", "kinematics", "--no-figures", "--quiet", "--set", "simulation.end_time_s=0.2",
           "--set", "simulation.output_step_s=1e-4", "--out", str(out)]  # ~600 kB to write
    result = subprocess.run(flex_command(*run), cwd=REPO, env=environment(),
                            capture_output=True, text=True, timeout=120, preexec_fn=small_disk)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        f"flex: error: cannot write result file '{out}': File too large; the previous file "
        f"(if any) is unchanged"]
    assert out.read_bytes() == previous
    assert [p.name for p in tmp_path.iterdir() if p.name != "reports"] == [out.name]


def test_stale_parts_of_dead_writers_are_removed_live_ones_kept(tmp_path):
    out = tmp_path / "r.h5"
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                              capture_output=True, text=True).stdout.strip()
        stale = tmp_path / f".r.h5.{dead}.abcd1234.part"
        live = tmp_path / f".r.h5.{sleeper.pid}.efgh5678.part"
        unrelated = tmp_path / ".r.h5.5.x.h5.1.abc.part"  # belongs to a file "r.h5.5.x.h5"
        for part in (stale, live, unrelated):
            part.write_bytes(b"half")
        write_previous(out)
        assert not stale.exists()
        assert live.exists() and unrelated.exists()
        assert remove_stale_parts(out) == []
    finally:
        sleeper.kill()
        sleeper.wait()


WRITER = """
import sys, numpy as np
from flex.data.results import CaseResult, Dataset, write_results
writer, path, rounds = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
for round_ in range(rounds):
    values = np.full(100_000, writer * 1000.0 + round_)
    case = CaseResult("c", "", {"time": Dataset(np.arange(values.size, dtype=float), "s"),
                                "value": Dataset(values, "1", "writer*1000 + round")})
    write_results(path, "stress", [case], attrs={"writer": writer, "round": round_})
"""


def test_two_writers_at_once_last_complete_writer_wins(tmp_path):
    out = tmp_path / "shared.h5"
    rounds = 8
    writers = [subprocess.Popen([sys.executable, "-c", WRITER, str(w), str(out), str(rounds)],
                                env=environment(), stderr=subprocess.PIPE) for w in (1, 2)]
    reads = 0
    while any(w.poll() is None for w in writers):
        if out.exists():
            try:
                data = read_case(out, "c")
            except ResultFileError as exc:  # pragma: no cover - the failure this guards
                pytest.fail(f"a reader saw a broken file while two writers ran: {exc}")
            value = data["value"]
            assert value.size == 100_000 and np.all(value == value[0])  # one writer's, whole
            reads += 1
        time.sleep(0.005)
    for writer in writers:
        assert writer.wait() == 0, writer.stderr.read().decode()
    with open_results(out) as h5:
        writer, round_ = int(h5.attrs["writer"]), int(h5.attrs["round"])
        assert round_ == rounds - 1  # the final file is some writer's last, complete round
        assert np.all(h5["cases/c/value"][()] == writer * 1000.0 + round_)
    assert [p.name for p in tmp_path.iterdir() if p.name != "reports"] == [out.name]
    assert reads > 0


@pytest.mark.slow  # two real `flex run` processes; the writers' contract is in the test above
def test_two_flex_runs_on_one_path(tmp_path):
    out = tmp_path / "kinematics.h5"
    speeds = {"slow": 3.0, "fast": 6.0}
    base = ["run", "kinematics", "--no-figures", "--quiet", "--set",
            "simulation.end_time_s=0.2", "--set", "simulation.output_step_s=1e-4",
            "--out", str(out)]
    runs = [subprocess.Popen(flex_command(*base, "--set",
                                          f"drive.crank_speed_rad_per_s={speed}"),
                             cwd=REPO, env=environment(), stderr=subprocess.PIPE)
            for speed in speeds.values()]
    for run in runs:
        assert run.wait(timeout=120) == 0, run.stderr.read().decode()
    assert [p.name for p in tmp_path.iterdir() if p.name != "reports"] == [out.name]
    with open_results(out) as h5:
        scene = h5.attrs["scene_toml"]
    winner = next(name for name, speed in speeds.items()
                  if f"crank_speed_rad_per_s = {speed}" in scene)
    # the file is exactly that run: same datasets, bit for bit, as the same scene run here
    expected = tmp_path / "expected" / "kinematics.h5"
    run_study("kinematics", overrides=["simulation.end_time_s=0.2",
                                       "simulation.output_step_s=1e-4",
                                       f"drive.crank_speed_rad_per_s={speeds[winner]}"],
              out=expected, figures=False, quiet=True)
    assert_same_datasets(out, expected)


# --- reproducibility --------------------------------------------------------------------

TIMINGS = ("created_utc", "command", "wall_time_s", "counter_wall_time_s")


def is_timing(name: str) -> bool:
    """Provenance timestamps and wall-clock timings: the only things allowed to differ."""
    return name.split("/")[-1] in TIMINGS or name.endswith("wall_time_s")


def assert_same_datasets(path_a: Path, path_b: Path) -> None:
    """Every dataset and attribute bit-identical, timings and timestamps aside."""
    with h5py.File(path_a, "r") as a, h5py.File(path_b, "r") as b:
        items_a, items_b = {}, {}
        a.visititems(lambda n, o: items_a.__setitem__(n, o))
        b.visititems(lambda n, o: items_b.__setitem__(n, o))
        assert sorted(items_a) == sorted(items_b)
        for name in ["", *items_a]:
            obj_a, obj_b = (a[name], b[name]) if name else (a, b)
            attrs = {k for k in obj_a.attrs if not is_timing(k)}
            assert attrs == {k for k in obj_b.attrs if not is_timing(k)}, name
            for key in attrs:
                assert np.array_equal(obj_a.attrs[key], obj_b.attrs[key]), f"{name} @{key}"
            if isinstance(obj_a, h5py.Dataset) and not is_timing(name):
                assert obj_a.dtype == obj_b.dtype, name
                same = (np.array_equal(obj_a[()], obj_b[()], equal_nan=True)
                        if obj_a.dtype.kind == "f" else np.array_equal(obj_a[()], obj_b[()]))
                assert same, f"{name} differs"  # NaN: a quantity the run did not reach


@pytest.mark.parametrize("study, overrides", [
    ("kinematics", ["simulation.end_time_s=0.2"]),
    ("dynamics", ["simulation.end_time_s=0.01"]),
])
def test_same_scene_gives_bit_identical_datasets(tmp_path, study, overrides):
    first, second = tmp_path / "first.h5", tmp_path / "second.h5"
    for path in (first, second):
        run_study(study, overrides=overrides, out=path, figures=False, quiet=True)
    assert_same_datasets(first, second)


# --- hostile scene input ----------------------------------------------------------------

NUMERIC = [(s, k, f) for s, fields in SCHEMA.items() for k, f in fields.items()
           if not isinstance(f.kind, tuple) and f.kind is not bool]  # "=true" is a bool's value
CHOICES = [(s, k, f) for s, fields in SCHEMA.items() for k, f in fields.items()
           if isinstance(f.kind, tuple)]
# keys where a huge (finite) value is out of range or breaks the linkage or the step count
HUGE_REFUSED = [(s, k) for s, k, f in NUMERIC if f.maximum is not None or f.below is not None] \
    + [("crank", "length_m"), ("slider", "offset_m"), ("simulation", "end_time_s")]
POSITIVE_OR_MINIMUM = [(s, k) for s, k, f in NUMERIC
                       if f.positive or (f.minimum is not None and f.minimum >= 0)]


def hostile_scene(rng: random.Random) -> bytes:
    """One random scene file that must be refused (each kind below is invalid)."""
    section, key, _ = rng.choice(NUMERIC)
    kind = rng.choice(["type", "huge", "huge_int", "negative", "nan", "unknown_section",
                       "unknown_key", "bytes", "syntax", "nesting", "not_table", "choice",
                       "control", "long_list"])
    if kind == "type":
        value = rng.choice(['"0.04"', "[0.04]", "{a = 1}", "true", "1979-05-27T07:32:00Z",
                            "07:32:00", '""', "[]"])
    elif kind == "huge":
        section, key = rng.choice(HUGE_REFUSED)
        value = rng.choice(["1e308", "1.7976931348623157e308", "9e307", "1e400", "-1e400"])
    elif kind == "huge_int":
        value = ("-" if rng.random() < 0.3 else "") + "9" * rng.choice([310, 400, 4000])
        if value.startswith("-"):
            section, key = rng.choice(POSITIVE_OR_MINIMUM)
    elif kind == "negative":
        section, key = rng.choice(POSITIVE_OR_MINIMUM)
        value = rng.choice(["-1", "-1e-300", "-0.04", "-1e308", "-0.0"
                            if SCHEMA[section][key].positive else "-1e-9"])
    elif kind == "nan":
        value = rng.choice(["nan", "+nan", "-nan", "inf", "-inf", "+inf"])
    elif kind == "unknown_section":
        name = rng.choice(["wheels", "Crank", "crank2", '"a\\nb"', '"\\u00e9t\\u00e9"', '""'])
        return f"[{name}]\nradius_m = 1.0\n".encode()
    elif kind == "unknown_key":
        name = rng.choice(["length", "length_mm", '"length_m "', '"a\\tb"', "x" * 5000])
        return f"[{section}]\n{name} = 1.0\n".encode()
    elif kind == "bytes":
        valid = f"[{section}]\n{key} = 0.5\n".encode()
        cut = rng.randrange(len(valid) + 1)
        junk = rng.choice([b"\xff", b"\xfe\xff", b"\xc3\x28", b"\x80abc", b"\xed\xa0\x80"])
        return valid[:cut] + junk + valid[cut:]
    elif kind == "syntax":
        return rng.choice([f"[{section}\n{key} = 1", f"[{section}]\n{key} = ",
                           f"[{section}]\n{key} = 1\n{key} = 2", f"[{section}]\n{key} 1",
                           f"[{section}]\n{key} = 0.04\x00", "= 1", "[[[", f"[{section}]]",
                           f"[{section}]\n{key} = 1 2", f'[{section}]\n{key} = "unterminated',
                           ]).encode()
    elif kind == "nesting":
        depth = rng.choice([200, 2000, 20000])
        return (f"[{section}]\n{key} = " + "[" * depth + "]" * depth).encode()
    elif kind == "not_table":
        return rng.choice([f"{section} = 1", f"[[{section}]]\n{key} = 1", f"{section} = [1]",
                           "title = 'x'"]).encode()
    elif kind == "choice":
        section, key, field = rng.choice(CHOICES)
        value = rng.choice(["1", '"Rigid"', '"rigid "', "true", '["rigid"]', '""'])
    elif kind == "control":
        value = rng.choice(['"\\u0000"', '"a\\nb"', '"\\u001b[31m"'])
    else:  # long_list
        value = "[" + ", ".join(["1.0"] * rng.choice([100, 10000])) + "]"
    return f"[{section}]\n{key} = {value}\n".encode()


def hostile_override(rng: random.Random) -> str:
    section, key, _ = rng.choice(NUMERIC)
    return rng.choice([
        f"{section}.{key}=", f"{section}.{key}=nan", f"{section}.{key}=-inf",
        f"{section}.{key}=1e999", f"{section}.{key}=" + "9" * 5000, f"{section}.{key}=[",
        f"{section}.{key}=" + "[" * 3000, f"{section}.{key}=\udcff", f"{section}.{key}=[1, 2]",
        f"{section}.{key}={{a=1}}", f"{section}.{key}=true", f"{section}.{key}=0x7fffffff"
        if (section, key) in HUGE_REFUSED else f"{section}.{key}=-1e9999",
        f"{section}{key}=1", f"={key}", f".{key}=1", f"{section}.=1", "crank", "",
        f"wheels.{key}=1", f"{section}.{key}\n=nan", f"{section}.x\ny=1", "a.b.c=1",
    ])


def check_refusal(message: str) -> None:
    assert message and "\n" not in message and len(message) < 400, repr(message[:500])
    assert "Traceback" not in message


def test_fuzzed_scene_files_are_refused_in_process(tmp_path):
    rng = random.Random(20121123)
    for index in range(100):
        path = tmp_path / f"hostile-{index}.toml"
        path.write_bytes(hostile_scene(rng))
        with pytest.raises(SceneError) as info:
            load_scene(path)
        check_refusal(str(info.value))


def test_fuzzed_overrides_are_refused_in_process():
    rng = random.Random(5)
    for _ in range(60):
        override = hostile_override(rng)
        with pytest.raises(SceneError) as info:
            load_scene(overrides=[override])
        check_refusal(str(info.value))


def test_fuzzed_scenes_on_the_command_line(tmp_path):
    rng = random.Random(77)
    hostile = tmp_path / "hostile.toml"
    hostile.write_bytes(hostile_scene(rng))
    deep = tmp_path / "deep.toml"
    deep.write_bytes(b"[crank]\nlength_m = " + b"[" * 5000 + b"]" * 5000)
    commands = [
        [b"run", b"simulate", b"--scene", os.fsencode(hostile), b"--out",
         os.fsencode(tmp_path / "never.h5")],
        [b"scene", b"simulate", b"--scene", os.fsencode(deep), b"--set",
         b"crank.length_m=" + b"9" * 400],
        [b"scene", b"simulate", b"--set", b"crank.length_m=\xff\xfe"],  # not UTF-8
    ]
    for args in commands:
        result = subprocess.run([os.fsencode(sys.executable), b"-m", b"flex", *args],
                                cwd=REPO, env=environment(), capture_output=True, timeout=120)
        stderr = result.stderr.decode("utf-8", "replace")
        assert result.returncode == 2, (args[:3], stderr[-500:])
        lines = stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("flex: error: "), stderr[-500:]
        assert "Traceback" not in stderr and result.stdout == b""
    assert not (tmp_path / "never.h5").exists()


# --- damaged result files ---------------------------------------------------------------

def test_truncated_result_files_give_one_clear_message(tmp_path):
    good = tmp_path / "good.h5"
    case = CaseResult("c", "", {"time": Dataset(np.linspace(0, 1, 2000), "s"),
                                "x": Dataset(np.sin(np.linspace(0, 1, 2000)), "m", "x")})
    write_results(good, "demo", [case])
    data = good.read_bytes()
    for fraction in (0.0, 0.001, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.999):
        cut = tmp_path / f"cut-{fraction}.h5"
        cut.write_bytes(data[:int(len(data) * fraction)])
        with pytest.raises(ResultFileError) as info:
            describe(cut)
            read_case(cut, "c")  # if the header survived, reading the data must fail clearly
        message = str(info.value)
        assert str(cut) in message and "\n" not in message, message


def test_ctrl_c_inside_the_solver_is_an_interrupt_not_a_failed_case():
    import threading

    from flex.data.scene import load_scene
    from flex.fidelity.simulation import simulate_case

    scene = load_scene(overrides=['drive.kind="constant_speed"', "simulation.end_time_s=20.0",
                                  "simulation.step_s=1e-4", "simulation.output_step_s=1e-2"])
    from flex.dynamics import runtime

    # Ctrl-C once Exudyn is integrating (its first step line), not after a time: a timer
    # could fire before the solve (or, without flex.base.interrupts, inside a weakref
    # callback, where it used to be swallowed and the 20 s run went on for minutes)
    write = runtime.SolverOutput.write
    sent = threading.Event()

    def first_line_interrupts(self, text: str) -> int:
        if "STEP" in text and not sent.is_set():
            sent.set()
            os.kill(os.getpid(), signal.SIGINT)
        return write(self, text)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(runtime.SolverOutput, "write", first_line_interrupts)
        with pytest.raises(KeyboardInterrupt):
            simulate_case(scene)
    assert sent.is_set()
