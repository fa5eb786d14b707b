"""Reports a reviewer reads (issue 50): a study's findings as short Markdown and tables of
data, long cells as notes, wide tables split, long prose wrapped, the printed report folded.

- the mechanism (flex.tools.report_findings, flex.tools.markdown) on a hand-made file: each
  findings table where its placeholder puts it (the others after, in their order), units in
  the numeric headers, one row per item, every value as the report formats it, the findings
  columns not repeated in the summary section, the printed report folded;
- the three studies' summaries on synthetic runs (estimates, tradeoff) and a design-like file
  (refused cases with auto's long reason): no line outside the folded printed report longer
  than :data:`LINE`, the expected tables with a row per item, the long reasons as notes.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from flex.data.results import CaseResult, Dataset
from flex.data.scene import load_scene
from flex.data.tables import findings_table
from flex.study import StudyOutput, Summary, _write_output
from flex.tools.markdown import LONG_CELL, format_value, table, wrap_markdown
from flex.tools.report import render_report

#: the longest line a reviewer scrolls for [characters]
LINE = 200
REASON = ("coupler: n_physical 3.1 from the probe's loads (omega 2262 rad/s, delta_t 1.4 ms); "
          "compressive load {load} x Euler load; beyond 0.5 x the Euler load the fitted laws do "
          "not hold and the rigid model is not offered (near buckling the error depends on the "
          "load, not on n); the ladder climbs: FFRF with 6 modes misses the tolerance 0.001 by "
          "its own error bound 0.0034 (mesh 2 mm, step 1e-05 s), the nonlinear FE coupler "
          "is refused: its Newton iterations do not converge near the buckling load of the "
          "plate, 0.6 mm thick, whose first in-plane bending mode at 358 Hz sets the step; "
          "choose a thicker coupler, a smaller preload or coupler.model = \"ffrf\" explicitly, "
          "or a larger fidelity.tolerance (the design sweep records the case as refused)")


def outside_folds(report: str) -> list[str]:
    """The report's lines outside ``<details>`` folds."""
    return re.sub(r"<details>.*?</details>", "", report, flags=re.S).splitlines()


def table_rows(report: str, header: str) -> list[list[str]]:
    """The cells of the rows of the table whose header line is ``header``."""
    lines = report.splitlines()
    start = lines.index(header) + 2
    rows = []
    for line in lines[start:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip("|").split(" | ")])
    return rows


def written(tmp_path: Path, name: str, summary: Summary, cases=()) -> str:
    """The report of ``summary`` written as a study run writes it (flex.study)."""
    path = tmp_path / f"{name}.h5"
    output = StudyOutput(name, load_scene(), {case.name: case for case in cases}, summary, 1.0)
    _write_output(output, path, load_scene())
    return render_report(path)


# --- the mechanism ------------------------------------------------------------------------
COLUMNS = {"setting": ("1", "the setting"), "wall_time": ("s", "median wall time"),
           "error": ("1", "relative error"), "steps": ("1", "time steps", int)}
ROWS = [{"setting": "h=1e-3", "wall_time": 0.0123456, "error": 2.5e-3, "steps": 30},
        {"setting": "h=1e-4", "wall_time": 0.1, "error": 2.5e-5, "steps": 300}]


def test_findings_tables_are_shown_from_the_data_where_the_findings_place_them(tmp_path):
    datasets = {**findings_table("front", "Pareto front", ROWS, COLUMNS, 1,
                                 {"wall_time": "wall time"}),
                **findings_table("late", "Shown after the findings", ROWS[:1], COLUMNS, 2),
                **findings_table("early", "Shown first of the rest", ROWS[1:], COLUMNS, 0),
                **findings_table("none", "An empty table", [], COLUMNS, 3),
                "other/x": Dataset(np.arange(3.0), "m", "a plain column")}
    long_report = "the printed report: " + "x " * 200
    findings = "Two findings.\n\n- one bullet\n\n[[table:front]]\n\nAfter the front."
    report = written(tmp_path, "demo", Summary(datasets, long_report, findings=findings))
    study = report.split("## Study report")[1].split("## Provenance")[0]
    header = "| setting | wall time [s] | error [1] | steps |"
    assert study.index("- one bullet") < study.index(header) < study.index("After the front.")
    assert study.index("After the front.") < study.index("Shown first of the rest") < study.index(
        "Shown after the findings")
    assert "**An empty table**\n\n(no rows)" in study
    rows = table_rows(report, header)
    assert rows == [[row["setting"], format_value(row["wall_time"]), format_value(row["error"]),
                     str(row["steps"])] for row in ROWS]
    assert "| 0.01235 |" in report and "0.0123456" not in report  # read back, 4 digits
    # the printed report folded, the findings columns not repeated in the summary section
    fold = study[study.index("<details><summary>The study's full printed report"):]
    assert long_report.strip() in fold and long_report.strip() not in study[:study.index(
        "<details><summary>The study's full printed report")]
    summary = report.split("## Summary")[1]
    assert "/summary/findings" not in summary.replace("(`/summary/findings/...`)", "")
    assert "### `/summary/other`" in summary


def test_long_cells_become_notes_and_wide_tables_are_split():
    rows = [[f"case_{i}", REASON.format(load=0.6), *range(12)] for i in range(3)]
    rows.append(["case_3", REASON.format(load=0.7), *range(12)])
    lines = table(["case", "reason", *(f"column number {i}" for i in range(12))], rows,
                  [False, False, *[True] * 12])
    assert max(map(len, lines)) <= LINE
    text = "\n".join(lines)
    first = text.split("\n\n")[0]
    assert first.count("| note 1 |") == 3 and first.count("| note 2 |") == 1  # one per text
    assert text.count("- note 1: ") == 1 and text.count("- note 2: ") == 1
    notes = " ".join(" ".join(text.split("- note 1: ")[1].split("- note 2: ")[0].split()).split())
    assert notes == REASON.format(load=0.6)
    headers = [line for line in lines if line.startswith("| case | reason |")]
    assert len(headers) >= 2  # split, each part naming the rows (the leading text columns)
    shown = {cell for line in headers for cell in line.strip("|").split(" | ")}
    assert {f"column number {i}" for i in range(12)} <= {cell.strip() for cell in shown}
    assert all(len(cell) <= LONG_CELL for line in lines if line.startswith("|")
               for cell in line.strip("|").split(" | "))


def test_prose_is_wrapped_tables_and_code_are_not():
    text = ("- " + "word " * 60 + "\n| a | " + "b " * 120 + "|\n```\n" + "c" * 300 + "\n```\n"
            + "plain " * 40)
    lines = wrap_markdown(text)
    assert [line[:3] for line in lines if len(line) > 100] == ["| a", "ccc"]
    assert lines[lines.index("```") + 1] == "c" * 300  # code as it is
    assert " ".join(lines[lines.index("```", lines.index("```") + 1) + 1:]) == (
        "plain " * 40).strip()
    item = [line for line in lines if "word" in line]
    assert item[0].startswith("- word") and all(line.startswith("  word") for line in item[1:])
    assert " ".join(" ".join(item).split()) == "- " + " ".join(["word"] * 60)


# --- the studies on synthetic runs ----------------------------------------------------------
def test_estimates_report_tables_and_short_lines(tmp_path):
    from flex.study import StudyRun
    from studies import estimates

    quantities = ["crank_angle_end_rad", "coupler_deployment_peak_von_mises_Pa",
                  "joint_A_deployment_peak_force_N"]  # in the headlines' order
    results = {}
    for index, ratio in enumerate([0.95, 1.2, 0.01, 3.0]):
        attrs = {"reference": REASON[:110]}
        for k, quantity in enumerate(quantities):
            true = 10.0 ** -(5 + index) * (k + 1)
            attrs |= {f"estimated_error_{quantity}": ratio * true,
                      f"true_error_{quantity}": true,
                      f"reference_accuracy_{quantity}": true / 100}
        results[f"scene_{index}"] = CaseResult(f"scene_{index}", "", attrs=attrs)
    summary = estimates.summarize({}, results, StudyRun())
    report = written(tmp_path, "estimates", summary)
    assert max(map(len, outside_folds(report))) <= LINE
    pairs = table_rows(report, "| case | quantity | estimated [quantity's unit] | true "
                       "[quantity's unit] | true / estimated [1] | largest term | note |")
    assert [(row[0], row[1]) for row in pairs] == [(scene, q) for scene in results
                                                   for q in quantities]
    assert [row[6] for row in pairs if row[0] == "scene_2"] == ["**outside**"] * 3
    assert {row[4] for row in pairs if row[0] == "scene_2"} == {"100"}  # true / estimated
    per_quantity = table_rows(report, "| quantity | pairs | judged | within | lowest true / "
                              "estimated [1] | highest true / estimated [1] |")
    assert [row[0] for row in per_quantity] == quantities
    assert all(row[1:4] == ["4", "4", "2"] for row in per_quantity)  # 0.95, 1.2 within
    assert "judged pairs within the target: 6 of 12" in report
    assert len(table_rows(report, "| case | reference |")) == 4


@pytest.fixture(scope="module")
def tradeoff_summary():
    import studies.tradeoff as study
    from flex.experiments.workprecision.measurement import (
        Measurement,
        Observables,
        Reference,
        Setting,
    )
    from flex.experiments.workprecision.tradeoff import SceneRuns
    from flex.study import StudyRun

    def measured(label, wall, error, status="ok"):
        message = "" if status == "ok" else REASON
        errors = {} if status != "ok" else {"error": error, "crank_angle_rad": error,
                                            "slider_position_m": error / 10}
        return Measurement(Setting.of(label, "one knob: step", step_s=1e-4), wall_time_s=wall,
                           wall_times_s=[wall], errors=errors, status=status, message=message)

    zeros = np.zeros(3)
    reference = Reference("synthetic", Observables(np.arange(3.0), zeros, zeros,
                                                   np.array([0.0, 1e-4, 0.0])),
                          Setting("fine"), {"step": {"error": 1e-6}}, 1e-2, 0.0)
    runs = {"rigid": [measured("a", 0.01, 1e-2), measured("b", 0.02, 2e-2),  # b: beaten by a
                      measured("c", 0.03, 1e-3), measured("d", 0.5, 1e-5),
                      measured("e", np.nan, np.nan, "failed")]}
    scene = load_scene(overrides=study.OVERRIDES)
    notes = {"runs": {name: SceneRuns(reference, values, 1.0) for name, values in runs.items()}}
    return study.summarize(scene, {}, StudyRun(notes=notes))


def test_tradeoff_report_shows_each_scene_s_pareto_front_as_a_table(tmp_path,
                                                                     tradeoff_summary):
    report = written(tmp_path, "tradeoff", tradeoff_summary)
    assert max(map(len, outside_folds(report))) <= LINE
    front = table_rows(report.split("**Pareto front, scene rigid**")[1],
                       "| setting | wall time [s] | error [1] |")
    assert front == [["a", "0.01", "0.01"], ["c", "0.03", "0.001"], ["d", "0.5", "1e-05"]]
    levels = table_rows(report.split("**Fastest flex setting per accuracy level, scene rigid**")[1],
                        "| level [1] | setting | wall time [s] | error [1] |")
    assert [row[:2] for row in levels] == [["0.01", "c"], ["0.001", "d"], ["0.0001", "d"]]
    assert "- 5 settings, 1 failed; 3 on the Pareto front" in report
    study = report.split("## Provenance")[0]
    assert REASON not in " ".join(outside_folds(study))  # the failure: in the folded text


def test_design_like_refusals_are_notes_not_700_character_cells(tmp_path):
    cases = [CaseResult(f"angle_{a}", "", attrs={"design_outcome": "refused",
                                                 "design_reason": REASON.format(load=a / 100)})
             for a in (5, 10)]
    cases += [CaseResult("angle_10_again", "", attrs={"design_outcome": "refused",
                                                      "design_reason": REASON.format(load=0.1)}),
              CaseResult("angle_60", "", attrs={"design_outcome": "simulated",
                                                "design_model": "rigid",
                                                "validity_warning": REASON[:300]})]
    report = written(tmp_path, "design", Summary({}, "# Design\n\n| a | b |\n|---|---|\n"),
                     cases)
    assert len(REASON) > 700 and max(map(len, outside_folds(report))) <= LINE
    rows = table_rows(report, "| case | design_outcome | design_reason | design_model |")
    reason = {row[0].strip("`"): row[2] for row in rows}
    assert reason["angle_10"] == reason["angle_10_again"] != reason["angle_5"]  # one per text
    assert reason["angle_60"] == "-" and all(len(cell) <= LONG_CELL for row in rows
                                             for cell in row)
    attributes = report.split("Other case attributes:")[1]
    note = " ".join(attributes.split(f"- {reason['angle_10']}: ")[1].split("\n- ")[0].split())
    assert note == REASON.format(load=0.1)
    # a long note of the cases table: below it, the row pointing to it
    (row,) = [row for row in table_rows(report, report.split("## Cases")[1].split("\n")[2])
              if row[0] == "`angle_60`"]
    number = row[-1].split()[-1]
    assert row[-1] == f"note {number}"
    below = report.split("## Cases")[1].split(f"- note {number}: ")[1]
    below = below.split("\n\n")[0].split("\n- ")[0]
    assert " ".join(below.split()) == f"**validity warning**: {' '.join(REASON[:300].split())}"
