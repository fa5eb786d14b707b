"""The Makefile's dependency graph, and progress that reads well in a log.

The graph is checked on a temporary tree holding the repository's Makefile and an empty file
for every input it names (the library, the bundled data files, the study modules,
pyproject.toml), with time stamps set by ``os.utime``: no study runs. Where a recipe must
run (failed runs, FORCE, the criterion targets), ``RUN`` is replaced by a small shell script
that writes the result files as ``flex run`` does; ``PYTHON=false`` makes sure no .venv is
ever built here.
"""

import io
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from flex.data.results import CaseResult, Dataset
from flex.data.scene import load_scene, to_toml

ROOT = Path(__file__).resolve().parent.parent
MAKEFILE = ROOT / "Makefile"
T0 = 1_700_000_000.0  # inputs; the .venv stamp at T0 + 10; results at T0 + 20

pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="needs make")


def _variable(name: str) -> list[str]:
    match = re.search(rf"^{name} := (.*)$", MAKEFILE.read_text(), re.MULTILINE)
    assert match, f"{name} not found in the Makefile"
    return match.group(1).split()


STUDIES = _variable("STUDIES")
ALL_ORDER = _variable("ALL_ORDER")
LONG = _variable("LONG")


def _inputs() -> list[str]:
    """What the Makefile should track: flex/**/*.py, flex/**/*.toml, the study modules and
    their scene lists, the reference store, pyproject.toml (relative paths)."""
    files = [p for pattern in ("flex/**/*.py", "flex/**/*.toml", "studies/*.py",
                               "studies/*.toml", "flex/data/references.h5")
             for p in ROOT.glob(pattern) if "__pycache__" not in p.parts]
    return sorted({str(p.relative_to(ROOT)) for p in files} | {"pyproject.toml"})


#: the bundled reference store: the studies that judge against it depend on it
STORE = "flex/data/references.h5"


def _set_time(path: Path, when: float) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.touch()
    os.utime(path, (when, when))


FAKE_RUN = """#!/bin/sh
# stands in for `flex run STUDY`: FAKE_MODE says how the run ends
study=$1
mkdir -p results
case "$FAKE_MODE" in
  ok) echo "run $study" > results/$study.h5
      # a law as the studies write it (the bundled one: install checks every value)
      [ "$study" = kfit ] && { echo "# fitted"; cat "$LAWS/criteria_fit.toml"; } \
          > results/kfit-criterion.toml
      [ "$study" = crank ] && { echo "# fitted"; cat "$LAWS/crank_criteria_fit.toml"; } \
          > results/crank-criterion.toml
      exit 0 ;;
  failed) # flex: a failed run is written beside an earlier result, else in its place
      if [ -e results/$study.h5 ]; then echo failed > results/$study.failed.h5
      else echo failed > results/$study.h5; fi
      exit 1 ;;
  late) echo "new" > results/$study.h5; exit 130 ;;  # interrupted while drawing figures
esac
exit 2
"""


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    """A copy of the Makefile, every input empty at T0, the stamp at T0 + 10, every study's
    result (and the fitted laws) at T0 + 20: up to date."""
    shutil.copy(MAKEFILE, tmp_path / "Makefile")
    for name in _inputs():
        _set_time(tmp_path / name, T0)
    _set_time(tmp_path / STORE, T0)
    _set_time(tmp_path / ".venv" / ".installed", T0 + 10)
    for study in STUDIES:
        _set_time(tmp_path / "results" / f"{study}.h5", T0 + 20)
    for law in ("kfit-criterion.toml", "crank-criterion.toml"):
        _set_time(tmp_path / "results" / law, T0 + 19)  # written before the result file
    (tmp_path / "fake_run.sh").write_text(FAKE_RUN)
    return tmp_path


def make(tree: Path, *args: str, mode: str = "ok") -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if not k.startswith("MAKE")}
    env.update(FAKE_MODE=mode, LC_ALL="C",  # make's own messages in English
               LAWS=str(ROOT / "flex" / "config"))  # the fake run's laws: the bundled ones
    return subprocess.run(["make", "--no-print-directory", "-C", str(tree), "PYTHON=false",
                           f"RUN=sh {tree / 'fake_run.sh'}", *args], capture_output=True,
                          text=True, env=env, timeout=60)


def runs(tree: Path, *targets: str) -> list[str]:
    """The studies ``make -n`` would run for ``targets``."""
    done = make(tree, "-n", *targets)
    assert done.returncode == 0, done.stderr
    return re.findall(r"fake_run\.sh (\w+)\";", done.stdout)


def database(tree: Path) -> dict[str, tuple[list[str], list[str]]]:
    """``make -p``'s rules: target -> (prerequisites, order-only prerequisites)."""
    done = make(tree, "-n", "-p", "all")
    assert done.returncode == 0, done.stderr
    rules = {}
    for line in done.stdout.splitlines():
        match = re.match(r"^([^#\s:=][^:=]*?):(?!=)\s*(.*)$", line)
        if match and not line.startswith("\t"):
            normal, _, order = match.group(2).partition("|")
            rules[match.group(1).strip()] = (normal.split(), order.split())
    return rules


def test_each_result_file_depends_on_its_module_the_library_data_and_pyproject(tree):
    rules = database(tree)
    library = [name for name in _inputs() if name.startswith("flex/")
               and not name.endswith(".h5")]  # the store: the judging studies' input
    assert any(name.startswith("flex/data/scenes/") and name.endswith(".toml") for name in library)
    assert "flex/config/criteria_fit.toml" in library
    assert "flex/config/solver_defaults.toml" in library
    for study in STUDIES + LONG:
        normal, order = rules[f"results/{study}.h5"]
        assert f"studies/{study}.py" in normal
        assert set(library) <= set(normal), set(library) - set(normal)
        assert "pyproject.toml" in normal
        others = {f"studies/{s}.py" for s in STUDIES + LONG if s != study}
        assert not others & set(normal)  # no other study's module
        assert order == [".venv/.installed"]  # (re)making the .venv reruns nothing
        assert rules[study][0] == [f"results/{study}.h5"]  # the phony alias
        if (ROOT / "studies" / f"{study}.toml").exists():  # its scene list
            assert f"studies/{study}.toml" in normal
    for judging in ("estimates", "calibrate"):  # they read the reference store
        assert "flex/data/references.h5" in rules[f"results/{judging}.h5"][0]


def test_all_builds_every_study_file_and_none_of_the_long_ones(tree):
    normal, _ = database(tree)["all"]
    assert normal == [f"results/{study}.h5" for study in ALL_ORDER]
    assert not {"tradeoff", "stability", "bench"} & set(STUDIES)
    for study in LONG:
        _set_time(tree / "results" / f"{study}.h5", T0 + 20)
    _set_time(tree / "flex" / "solver.py", T0 + 30)
    assert sorted(runs(tree, "all")) == sorted(STUDIES)


def test_an_up_to_date_tree_has_nothing_to_do(tree):
    assert make(tree, "-q", "all").returncode == 0
    assert runs(tree, "all") == []
    assert "Nothing to be done" in make(tree, "all").stdout


@pytest.mark.parametrize("study", ["spring", "kfit", "flexible"])
def test_touching_a_study_module_makes_only_that_study_out_of_date(tree, study):
    _set_time(tree / "studies" / f"{study}.py", T0 + 30)
    assert runs(tree, "all") == [study]
    assert runs(tree, study) == [study]  # the phony alias
    for other in STUDIES:
        status = make(tree, "-q", f"results/{other}.h5").returncode
        assert status == (1 if other == study else 0), other


def test_a_new_reference_store_reruns_the_studies_that_judge_against_it(tree):
    _set_time(tree / STORE, T0 + 30)
    assert runs(tree, "all") == ["flexible"]
    assert runs(tree, "estimates") == ["estimates"]
    assert runs(tree, "calibrate") == ["calibrate"]


@pytest.mark.parametrize("name", ["flex/dynamics/solver.py", "flex/data/scenes/cavezza2012.toml",
                                  "flex/config/criteria_fit.toml",
                                  "flex/config/solver_defaults.toml",
                                  "pyproject.toml"])
def test_touching_the_library_or_its_data_reruns_every_study(tree, name):
    assert (tree / name).exists()
    _set_time(tree / name, T0 + 30)
    _set_time(tree / ".venv" / ".installed", T0 + 40)  # what the .venv rule would do
    assert runs(tree, "all") == ALL_ORDER


def test_a_new_venv_alone_reruns_nothing(tree):
    _set_time(tree / ".venv" / ".installed", T0 + 50)
    assert runs(tree, "all") == []


def test_a_successful_run_brings_its_target_up_to_date(tree):
    _set_time(tree / "studies" / "spring.py", T0 + 30)
    done = make(tree, "spring")
    assert done.returncode == 0, done.stderr
    assert (tree / "results" / "spring.h5").read_text() == "run spring\n"
    assert make(tree, "-q", "all").returncode == 0


def test_a_failed_first_run_leaves_no_target(tree):
    (tree / "results" / "spring.h5").unlink()
    done = make(tree, "all", mode="failed")
    assert done.returncode != 0
    assert not (tree / "results" / "spring.h5").exists()
    assert (tree / "results" / "spring.failed.h5").read_text() == "failed\n"
    assert "moved to results/spring.failed.h5" in done.stderr
    assert runs(tree, "all") == ["spring"]  # still to do
    assert not list((tree / "results").glob(".*.before"))


def test_a_failed_rerun_keeps_the_earlier_result_and_its_time_stamp(tree):
    _set_time(tree / "studies" / "wing.py", T0 + 30)
    done = make(tree, "all", mode="failed")
    assert done.returncode != 0
    result = tree / "results" / "wing.h5"
    assert result.stat().st_mtime == T0 + 20
    assert (tree / "results" / "wing.failed.h5").exists()
    assert runs(tree, "all") == ["wing"]


def test_a_run_that_changes_its_target_and_then_fails_leaves_it_out_of_date(tree):
    _set_time(tree / "studies" / "modal.py", T0 + 30)
    assert make(tree, "modal", mode="late").returncode != 0
    assert (tree / "results" / "modal.h5").read_text() == "new\n"
    assert (tree / "results" / "modal.h5").stat().st_mtime == T0 + 20
    assert runs(tree, "all") == ["modal"]


def test_force_reruns_what_is_asked_for(tree):
    assert runs(tree, "all", "FORCE=1") == ALL_ORDER
    assert runs(tree, "dynamics", "FORCE=1") == ["dynamics"]
    assert runs(tree, "bench") == ["bench"]  # no result yet


def install(tree: Path, *args: str, mode: str = "ok") -> subprocess.CompletedProcess:
    """``make calibration-install`` with this interpreter as the .venv's python."""
    # -P: the installed flex, not the empty module files of the tree
    return make(tree, f"PY={sys.executable} -P", "calibration-install", *args, mode=mode)


def test_calibration_install_installs_the_fitted_laws_after_their_study(tree):
    config = tree / "flex" / "config"
    for study, installed in (("kfit", "criteria_fit.toml"), ("crank", "crank_criteria_fit.toml")):
        _set_time(tree / "studies" / f"{study}.py", T0 + 30)
        done = install(tree, f"FITS={study}")
        assert done.returncode == 0, done.stderr
        assert (config / installed).read_text() == (tree / "results" /
                                                    f"{study}-criterion.toml").read_text()
        assert (tree / "results" / f"{study}.h5").read_text() == f"run {study}\n"
    stamp = (config / "criteria_fit.toml").stat().st_mtime
    again = install(tree, "FITS=kfit crank")
    assert again.returncode == 0 and "is already" in again.stdout
    # same law: no copy
    assert (config / "criteria_fit.toml").stat().st_mtime == stamp


def test_calibration_install_is_one_command_for_every_fit(tree):
    done = make(tree, "-n", "calibration-install")
    assert done.returncode == 0, done.stderr
    installs = [line for line in done.stdout.splitlines() if "flex.config.calibration" in line]
    assert len(installs) == 1, done.stdout
    for fit in ("kfit-criterion", "crank-criterion", "calibrate-rule"):
        assert f"results/{fit}.toml" in installs[0]


def test_no_law_is_installed_from_a_run_that_failed(tree):
    installed = tree / "flex" / "config" / "criteria_fit.toml"
    assert make(tree, "kfit", "FORCE=1", mode="failed").returncode != 0  # earlier kfit.h5 kept
    before = installed.stat().st_mtime
    done = install(tree, "FITS=kfit")
    assert done.returncode != 0 and "the last kfit run failed" in done.stderr
    assert installed.stat().st_mtime == before
    assert make(tree, "kfit", "FORCE=1").returncode == 0  # a good run: installed again
    assert install(tree, "FITS=kfit").returncode == 0
    assert installed.read_text() == (tree / "results" / "kfit-criterion.toml").read_text()


def test_clean_removes_results_figures_and_reports(tree):
    for name in ("figures/a.png", "reports/r.md", "kfit-cases/cases/x.h5", "spring.failed.h5"):
        _set_time(tree / "results" / name, T0)
    (tree / "results" / "README.md").write_text("kept")
    assert make(tree, "clean").returncode == 0
    assert sorted(p.name for p in (tree / "results").iterdir()) == ["README.md"]


# ------------------------------------------------------------------------------------------
# progress in a log (stderr not a terminal)
# ------------------------------------------------------------------------------------------
def _quick_case(name, scene):
    return CaseResult(name, to_toml(scene), {"x": Dataset(np.zeros(2), "1", "x")},
                      status="failed" if name == "bad" else "ok")


def _prepare(scene):
    return {"ok": True}


def _key(scene):
    return "one"


def test_sweep_progress_in_a_log_is_plain_lines(tmp_path, capsys, monkeypatch):
    import flex.sweep as sweep

    monkeypatch.setattr(sweep, "PROGRESS_MIN_INTERVAL_S", 0.0)
    scene = load_scene(None)
    scenes = {"a": scene, "b": scene, "bad": scene}
    sweep.run_sweep(scenes, tmp_path, _quick_case, prepare=_prepare, prepare_key=_key,
                    scheduler="serial", study="demo")
    err = capsys.readouterr().err
    assert "\r" not in err and "\x1b" not in err
    lines = err.splitlines()  # (serial cases finish in any order)
    assert lines[0] == "demo: 3 cases to run"
    assert any(re.match(r"demo: 1/3 cases \(done=[01] failed=[01] remaining=2 prepared=1/1\), "
                        r"\d+ s elapsed, ~\d+ s left$", line) for line in lines)
    assert re.match(r"demo: 3/3 cases \(done=2 failed=1 remaining=0 prepared=1/1\), \d+ s "
                    r"elapsed, finished$", lines[-1])
    sweep.run_sweep(scenes, tmp_path, _quick_case, scheduler="serial", study="demo")
    assert capsys.readouterr().err.splitlines()[0] == "demo: 0 cases to run, 3 resumed from " \
                                                      "their files"


def test_sweep_progress_lines_are_spaced_with_a_heartbeat(monkeypatch):
    import flex.sweep as sweep

    clock = [0.0]
    monkeypatch.setattr(sweep.time, "monotonic", lambda: clock[0])
    stream = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    bar = sweep._Progress(10, 0, "demo", True)
    for second in range(1, 31):  # a case every second: a line every 5 s at most
        clock[0] = float(second)
        if second <= 10:
            bar.case(True)
        else:  # then 20 s of waiting
            bar.tick()
    bar.close()
    lines = stream.getvalue().splitlines()
    assert lines[0] == "demo: 10 cases to run"
    silence = sweep.PROGRESS_MAX_SILENCE_S  # 9 s: below the command line's 10 s watch
    assert [line.split(",")[0] for line in lines[1:]] == [
        "demo: 5/10 cases (done=5 failed=0 remaining=5)",   # 5 s
        "demo: 10/10 cases (done=10 failed=0 remaining=0)",  # heartbeat at 5 s + silence
        "demo: 10/10 cases (done=10 failed=0 remaining=0)",  # heartbeat at 5 s + 2 silence
        "demo: 10/10 cases (done=10 failed=0 remaining=0)"]  # finished (the last case: once)
    assert "~5 s left" in lines[1] and f"{5 + silence:.0f} s elapsed" in lines[2]
    assert lines[-1].endswith("30 s elapsed, finished")


def test_sweep_progress_on_a_terminal_is_the_tqdm_bar(monkeypatch):
    import flex.sweep as sweep

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    stream = Terminal()
    monkeypatch.setattr(sys, "stderr", stream)
    bar = sweep._Progress(2, 0, "demo", True)
    assert bar.bar is not None
    bar.case(True)
    bar.case(False)
    bar.close()
    assert "\r" in stream.getvalue() and "done=1 failed=1 remaining=0" in stream.getvalue()


def test_no_progress_when_disabled(capsys):
    import flex.sweep as sweep

    bar = sweep._Progress(2, 0, "demo", False)
    bar.case(True)
    bar.tick()
    bar.close()
    assert capsys.readouterr().err == ""


def test_nonlinear_fe_progress_reports_time_steps_and_remaining(monkeypatch, capsys):
    import flex.bodies.nonlinear as nonlinear

    clock = [100.0]
    monkeypatch.setattr(nonlinear.time, "monotonic", lambda: clock[0])
    progress = nonlinear._IntegrationProgress(0.03)
    for step in range(0, 301):  # two force calls per step of 0.1 ms, 0.1 s per step
        clock[0] = 100.0 + step / 10
        progress.update(step * 1e-4, 2 * step, 1)
        progress.update(step * 1e-4, 2 * step + 1, 1)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 3  # at 10, 20, 30 s
    assert lines[0] == ("nonlinear FE coupler: t = 10 ms of 30 ms (33 %), step 100, 10 s "
                        "elapsed, ~20 s left (200 force, 1 Jacobian evaluations)")
    assert "\r" not in "".join(lines)


def test_one_registry_of_studies_ties_the_makefile_the_cli_and_the_readme():
    """flex.study's registry is the one list: make all runs MAKE_ALL_STUDIES in order, the
    long ones are LONG_STUDIES, every study has its module, the command line offers exactly
    them, and the README's study table has one row per study."""
    import argparse

    from flex.cli import _parser
    from flex.study import LONG_STUDIES, MAKE_ALL_STUDIES, STUDIES

    assert set(STUDIES) == {"simulate", *MAKE_ALL_STUDIES, *LONG_STUDIES}
    assert len(STUDIES) == 1 + len(MAKE_ALL_STUDIES) + len(LONG_STUDIES)
    assert globals()["STUDIES"] == list(MAKE_ALL_STUDIES)  # the Makefile's, in its order
    assert sorted(ALL_ORDER) == sorted(MAKE_ALL_STUDIES)  # what `make all` starts, reordered
    assert LONG == list(LONG_STUDIES)
    for study in STUDIES:
        assert (ROOT / "studies" / f"{study}.py").is_file()
    commands = next(action for action in _parser()._actions
                    if isinstance(action, argparse._SubParsersAction))
    for verb in ("run", "scene"):
        (study,) = [action for action in commands.choices[verb]._actions
                    if action.dest == "study"]
        assert tuple(study.choices) == STUDIES
    rows = re.findall(r"^\| `(?:make|flex run) (\w+)`", (ROOT / "README.md").read_text(),
                      re.MULTILINE)
    assert sorted(rows) == sorted(STUDIES)
