"""``flex report``: Markdown reports generated from a result file, checked against that file.

Each check reads the HDF5 file independently (h5py) and asserts that what it holds appears
in the report as :func:`flex.tools.report.format_value` formats it.
"""

from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import unquote

import h5py
import numpy as np
import pytest
from hostile import check_refused, run_cli

from flex.base.errors import EXIT_OK, OutputError, ResultFileError
from flex.data.results import CaseResult, Dataset, attribute_value, write_results
from flex.tools.report import LARGE, default_report_path, format_value, render_report, write_report

REPO = Path(__file__).resolve().parent.parent
REPORT_TEXT = "demo: flex against the thesis\n  quantity  thesis  flex\n  stroke    0.08    0.0800"


def result_file(path: Path, with_report: bool = True) -> Path:
    """A result file with an ok case (counters, validity warning, "auto" choices), a failed
    case, and summary scalars, same-length arrays (numbers and text), a lone array, a small
    2-D array and a large array."""
    time_s = np.linspace(0.0, 0.03, 31)
    ok = CaseResult(
        "preload_22mm", "[crank]\n", {"time": Dataset(time_s, "s", "time"),
                                      "crank/angle": Dataset(np.sin(time_s), "rad", "angle")},
        counters={"steps": 3001, "newton_iterations": 6123, "wall_time_s": 0.0756123},
        attrs={"validity_warning": "coupler deflection 12% of its thickness",
               "fidelity_coupler_model": "ffrf", "fidelity_coupler_modes": 4,
               "fidelity_coupler_reason": "n_physical 0.96 < 108",
               "solver_defaults_entry": "ffrf", "solver_defaults_reason": "flexible links",
               "source": "unit test"})
    failed = CaseResult("diverged", "[crank]\n", status="failed",
                        message="solver diverged at step 10 (t = 0.009 s)")
    summary = {
        "errors/max_position": Dataset(2.721434189112415e-14, "m", "vs closed form"),
        "errors/relative_drift": Dataset(0.123456789, "1", "energy balance"),
        "errors/dof": Dataset(np.int64(26673), "1", "FE model size"),
        "errors/converged": Dataset(np.bool_(True), "1", "reference converged"),
        "errors/knobs": Dataset("step_s=1e-05 | newton=full", "1", "setting"),
        "thesis_comparison/quantity": Dataset(np.array(["stroke", "speed max", "acc min"]),
                                              "1", "reported quantity"),
        "thesis_comparison/thesis": Dataset(np.array([0.08, 0.28, -2.3]), "m", "thesis"),
        "thesis_comparison/flex": Dataset(np.array([0.0800001, 0.28229295, -2.36870537]),
                                          "m", "this run"),
        "thesis_comparison/frequencies": Dataset(np.array([59.5677, 29.78385]), "Hz",
                                                 "surge"),
        "thesis_comparison/mode_shape": Dataset(np.arange(6.0).reshape(3, 2) / 7, "1",
                                                "two modes"),
        "reference/crank_angle": Dataset(np.linspace(0.5967, 1.659, LARGE + 50), "rad",
                                         "reference DAE crank angle"),
    }
    attrs = {"wall_time_s": 0.3742890189996615, "failed_cases": 1}
    if with_report:
        attrs["summary_report"] = REPORT_TEXT
    write_results(path, "demo", [ok, failed], "[crank]\nlength_m = 0.04\n", summary, attrs)
    (path.parent / "figures").mkdir(exist_ok=True)
    (path.parent / "figures" / f"{path.stem}-crank-angle.png").write_bytes(b"png")
    return path


def sections(report: str) -> dict[str, str]:
    """The report's ``### `/group``` subsections by group path."""
    parts = re.split(r"^### `([^`]+)`$", report, flags=re.M)
    return {parts[i]: parts[i + 1].split("\n## ")[0] for i in range(1, len(parts), 2)}


def cells(text: str) -> set[str]:
    return {cell.strip() for line in text.splitlines() if line.startswith("|")
            for cell in line.strip("|").split(" | ")}


def test_every_summary_value_appears_as_the_report_formats_it(tmp_path):
    path = result_file(tmp_path / "demo.h5")
    report = render_report(path)
    groups = sections(report)
    with h5py.File(path) as h5:
        items = []
        h5["summary"].visititems(lambda name, obj: items.append((name, obj[()], dict(
            obj.attrs))) if hasattr(obj, "shape") else None)
    assert items
    for name, value, attrs in items:
        group, leaf = f"/summary/{name.rsplit('/', 1)[0]}", name.rsplit("/", 1)[1]
        units, description = (str(attribute_value(attrs[k])) for k in ("units", "description"))
        text = groups[group]
        value = np.asarray(value)
        if value.ndim == 0:  # scalar: one row name | value | unit | description
            shown = format_value(value).replace("|", "\\|")
            assert f"| `{leaf}` | {shown} | {units} | {description} |" in text, (name, text)
        elif value.size > LARGE:  # summarised: shape, min, max
            row = f"| `{leaf}` | {value.shape} | {format_value(value.min())} | " \
                  f"{format_value(value.max())} | {units} | {description} |"
            assert row in text, (name, text)
        else:  # every element as a cell (columns table, list or 2-D table)
            found = cells(text) | {part.strip() for line in text.splitlines()
                                   if line.startswith(f"- `{leaf}`")
                                   for part in line.split(": ", 1)[1].split(", ")}
            for element in value.ravel():
                assert format_value(element) in found, (name, element, text)
    assert "| 0.1235 |" in report and "0.123456789" not in report  # 4 significant digits
    assert "| 26673 |" in report and "| true |" in report  # integers and booleans as they are
    assert "| thesis [m] |" in report or "thesis [m]" in report  # units in column headers


def test_cases_statuses_provenance_and_study_report(tmp_path):
    path = result_file(tmp_path / "demo.h5")
    report = render_report(path)
    with h5py.File(path) as h5:
        commit = str(attribute_value(h5.attrs["git_commit"]))
        for case in h5["cases"]:
            status = str(attribute_value(h5["cases"][case].attrs["status"]))
            row = next(line for line in report.splitlines() if line.startswith(f"| `{case}` |"))
            assert status in row, row
    assert commit in report
    assert report.startswith("# demo\n")
    assert "| preload_22mm" not in report  # case names as code
    ok_row = next(line for line in report.splitlines() if line.startswith("| `preload_22mm`"))
    for fragment in ("| ok |", "| 31 |", "| 0 .. 0.03 |", "| 3001 |", "| 6123 |",
                     "| 0.07561 |", "coupler deflection 12%", "fidelity coupler: ffrf, 4 modes",
                     "solver defaults: ffrf (flexible links)"):
        assert fragment in ok_row, fragment
    failed_row = next(line for line in report.splitlines() if line.startswith("| `diverged`"))
    assert "**failed**" in failed_row and "solver diverged at step 10" in failed_row
    assert "| `preload_22mm` | unit test |" in report  # other case attributes
    assert f"```text\n{REPORT_TEXT}\n```" in report
    assert "| wall_time_s | 0.3743 |" in report and "| failed_cases | 1 |" in report


def test_older_file_without_study_report_says_so(tmp_path):
    report = render_report(result_file(tmp_path / "old.h5", with_report=False))
    assert "This file has no study report (root attribute `summary_report`)" in report


def test_figures_linked_relative_to_the_report(tmp_path):
    path = result_file(tmp_path / "demo.h5")
    write_results(tmp_path / "demo-long.h5", "demo", [])  # its figures are not demo's
    (tmp_path / "figures" / "demo-long-x.png").write_bytes(b"png")
    for out in (None, tmp_path / "elsewhere" / "deep" / "r.md"):
        written = write_report(path, out)
        assert written == (default_report_path(path) if out is None else out)
        links = re.findall(r"!\[[^]]*\]\(([^)]+)\)", written.read_text())
        assert len(links) == 1 and links[0].endswith("demo-crank-angle.png"), links
        assert not Path(links[0]).is_absolute()
        assert (written.parent / unquote(links[0])).resolve() == (
            tmp_path / "figures" / "demo-crank-angle.png").resolve()
    assert default_report_path(path) == tmp_path / "reports" / "demo.md"
    assert "](../figures/demo-crank-angle.png)" in default_report_path(path).read_text()


def test_cli_report_writes_the_file_and_exits_0(tmp_path):
    path = result_file(tmp_path / "demo.h5")
    outcome = run_cli(["report", str(path)])
    target = tmp_path / "reports" / "demo.md"
    assert outcome.status == EXIT_OK, outcome
    assert outcome.stdout.strip() == f"wrote {target}"
    assert target.read_text() == render_report(path)
    assert [p.name for p in target.parent.iterdir()] == ["demo.md"]  # no temporary left
    other = tmp_path / "out" / "demo-report.md"
    assert run_cli(["report", str(path), "--out", str(other)]).status == EXIT_OK
    assert other.read_text().startswith("# demo\n")


def test_cli_report_refuses_bad_files_and_outputs(tmp_path):
    path = result_file(tmp_path / "demo.h5")
    (tmp_path / "text.h5").write_text("not HDF5\n")
    watch = [tmp_path]
    check_refused(["report", str(tmp_path / "missing.h5")], ["missing.h5"], watch)
    check_refused(["report", str(tmp_path / "text.h5")], ["text.h5", "HDF5"], watch)
    check_refused(["report", str(path), "--out", str(path)], ["demo.h5", "result file"], watch)
    check_refused(["report", str(path), "--out", str(tmp_path / "r.txt")], [".md"], watch)
    check_refused(["report", str(path), "--out", str(tmp_path)], ["folder"], watch)
    assert not (tmp_path / "reports").exists()
    with pytest.raises(OutputError):
        write_report(path, tmp_path / "demo.h5")
    with pytest.raises(ResultFileError):
        write_report(tmp_path / "text.h5")


def test_reference_curve_files_without_summary(tmp_path):
    for path in sorted((REPO / "tests" / "reference_curves").glob("*.h5")):
        report = render_report(path, tmp_path)
        assert "This file has no `/summary` tables." in report
        assert "| compare_rtol |" in report or "`compare_rtol`" in report


def test_report_of_a_real_run(tmp_path):
    out = tmp_path / "x.h5"
    status = run_cli(["run", "simulate", "--set", "simulation.end_time_s=0.005",
                      "--no-figures", "--quiet", "--out", str(out)]).status
    assert status == EXIT_OK
    outcome = run_cli(["report", str(out)])
    assert outcome.status == EXIT_OK, outcome
    report = (tmp_path / "reports" / "x.md").read_text()
    with h5py.File(out) as h5:
        samples = h5["cases/case/time"].shape[0]
        study_report = str(attribute_value(h5.attrs["summary_report"]))
    assert report.startswith("# simulate\n")
    assert f"| `case` | ok | {samples} | 0 .. 0.005 |" in report
    assert study_report.strip().splitlines()[0] in report
