"""No error exit after a result file was replaced: every output of a run is checked before
anything runs, written under a private name, and moved into place only when all are written.

A rerun onto an existing ``--out`` whose report path is a folder, whose figures or report
cannot be written (a full disk), or that is interrupted while writing them, exits with the
documented status and one line that tells the truth, and leaves the earlier result file, its
figures and its report exactly as they were, with no private file left behind.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest
from hostile import check_refused, earlier_run, fingerprint, run_cli

from flex.base.errors import EXIT_BAD_INPUT, EXIT_OK, EXIT_SIGINT

SHORT = ["--set", "simulation.end_time_s=0.004", "--set", "simulation.error_estimate=false"]
STUDIES = ["simulate", "kinematics", "dynamics"]


@pytest.fixture
def earlier(tmp_path) -> Path:
    """An earlier run's result file, figure and report (all watched)."""
    return earlier_run(tmp_path)


def _argv(study: str, out: Path, *extra: str) -> list[str]:
    sets = SHORT if study != "kinematics" else ["--set", "simulation.end_time_s=0.05"]
    return ["run", study, "--out", str(out), *sets, *extra]


def _leftovers(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.name.endswith((".part", ".figures"))]


@pytest.mark.parametrize("study", STUDIES)
def test_a_report_path_that_is_a_folder_is_refused_before_anything_runs(earlier, study):
    report = earlier.parent / "reports" / "run.md"
    report.unlink()
    report.mkdir()
    outcome = check_refused(_argv(study, earlier), ["reports/run.md", "folder"],
                            watch=[earlier.parent])
    assert "[0/" not in outcome.stderr  # no case ran


@pytest.mark.parametrize("study", STUDIES)
def test_the_failed_runs_report_path_is_checked_too(earlier, study):
    (earlier.parent / "reports" / "run.failed.md").mkdir()
    check_refused(_argv(study, earlier), ["run.failed.md", "folder"], watch=[earlier.parent])


@pytest.mark.parametrize("study", STUDIES)
def test_a_full_disk_while_drawing_figures_changes_nothing(earlier, study, monkeypatch):
    import matplotlib.figure

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(args[0]) if args else "")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", full)
    outcome = check_refused(_argv(study, earlier), ["No space left"], watch=[earlier.parent])
    assert "wrote" not in outcome.stdout
    assert _leftovers(earlier.parent) == []


@pytest.mark.parametrize("study", STUDIES)
def test_a_full_disk_while_writing_the_report_changes_nothing(earlier, study, monkeypatch):
    import flex.study

    def full(path, text, target):
        raise flex.study.OutputError(f"cannot write report '{target}': "
                                     f"{os.strerror(errno.ENOSPC)}; nothing was changed")

    monkeypatch.setattr(flex.study, "_write_text", full)
    outcome = check_refused(_argv(study, earlier, "--no-figures"),
                            ["run.md", "nothing was changed"],
                            watch=[earlier.parent])
    assert "wrote" not in outcome.stdout
    assert _leftovers(earlier.parent) == []


@pytest.mark.parametrize("study", STUDIES)
def test_a_full_disk_while_writing_the_result_names_it_not_a_temporary(earlier, study,
                                                                      monkeypatch):
    import flex.data.results as results

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(results, "_write_file", full)
    outcome = check_refused(_argv(study, earlier, "--no-figures"),
                            [str(earlier), "No space left", "unchanged"],
                            watch=[earlier.parent])
    assert ".part" not in outcome.stderr
    assert _leftovers(earlier.parent) == []


def test_a_figure_target_that_is_a_folder_changes_nothing(earlier):
    figure = earlier.parent / "figures" / "run-crank-angle.png"
    figure.unlink()
    figure.mkdir()
    check_refused(_argv("simulate", earlier), ["run-crank-angle.png", "folder",
                                               "nothing was changed"], watch=[earlier.parent])
    assert _leftovers(earlier.parent) == []


@pytest.mark.parametrize("study", STUDIES)
def test_an_interrupt_while_drawing_leaves_every_earlier_file(earlier, study, monkeypatch):
    import matplotlib.figure

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", interrupted)
    before = fingerprint([earlier.parent])
    outcome = run_cli(_argv(study, earlier))
    assert outcome.status == EXIT_SIGINT and "Traceback" not in outcome.stderr
    assert outcome.stderr.strip().splitlines()[-1] == (
        "flex: interrupted; no result file was changed")
    assert fingerprint([earlier.parent]) == before and _leftovers(earlier.parent) == []


def test_a_good_rerun_replaces_all_three_together(earlier):
    before = fingerprint([earlier.parent])
    outcome = run_cli(_argv("simulate", earlier))
    assert outcome.status == EXIT_OK, outcome.stderr
    after = fingerprint([earlier.parent])
    for name in ("run.h5", "figures/run-crank-angle.png", "reports/run.md"):
        assert after[earlier.parent / name] != before[earlier.parent / name], name
    report = (earlier.parent / "reports" / "run.md").read_text()
    assert "(../run.h5)" in report and "(../figures/run-crank-angle.png)" in report
    assert ".part" not in report and _leftovers(earlier.parent) == []


def test_hostile_case_count():
    """This file's share of issue 26's hostile cases."""
    assert 6 * len(STUDIES) + 1 >= 19 and EXIT_BAD_INPUT == 2
