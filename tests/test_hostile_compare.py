"""``flex compare`` on curves that do not cover the reference: partial, shifted, one-sample.

A comparison must cover the reference's (B's) time span with at least two common samples;
otherwise each such curve fails (exit status 1), its row and the time-base line saying
exactly which span was compared and what fraction of B's span that is. ``--partial``
accepts the overlap (exit 0 when within tolerance) and still says so. Every case runs the
command line in process (tests/hostile.py): no traceback, the documented status, and the
input files unchanged; and the same through :func:`flex.tools.compare.compare_files`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hostile import check_refused, run_cli

from flex.data.results import CaseResult, Dataset, write_results
from flex.tools.compare import compare_files

REPO = Path(__file__).resolve().parent.parent
REFERENCE = REPO / "tests" / "reference_curves" / "deployment_preload_22mm.h5"


def curve(time_s: np.ndarray) -> dict[str, Dataset]:
    """The same smooth curves at any samples: a run that agrees wherever it has data."""
    return {"time": Dataset(time_s, "s", "time"),
            "crank/angle": Dataset(np.sin(40 * time_s), "rad", "angle"),
            "crank/midpoint_position": Dataset(np.stack([np.cos(40 * time_s),
                                                         np.sin(40 * time_s)], axis=1), "m")}


#: name -> sample times [s] of a one-case file (case "run"); the reference is "full"
GRIDS = {
    "full": np.linspace(0.0, 0.03, 31),
    "short": np.linspace(0.0, 0.005, 6),          # stops early: 17 % of the reference
    "late": np.linspace(0.01, 0.03, 21),          # starts late
    "shifted": np.linspace(0.01, 0.04, 31),       # shifted by 0.01 s
    "longer": np.linspace(0.0, 0.06, 61),         # covers the reference and more
    "one_at_start": np.array([0.0]),              # one sample, t = 0
    "one_at_end": np.array([0.03]),               # one sample, t = end
    "touching": np.linspace(0.03, 0.05, 3),       # meets the reference at its last instant
    "finer": np.linspace(0.0, 0.03, 301),         # covers it on a finer grid
}


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("compare")
    return {name: write_results(folder / f"{name}.h5", "demo",
                                [CaseResult("run", "", curve(times))])
            for name, times in GRIDS.items()}


#: (A, B, passes without --partial, words of the failing note)
PAIRS = [
    ("full", "full", True, []),
    ("finer", "full", True, []),
    ("longer", "full", True, []),
    ("full", "finer", True, []),
    ("short", "full", False, ["not the whole reference", "0 .. 0.005 s of B's 0 .. 0.03 s"]),
    ("late", "full", False, ["not the whole reference", "0.01 .. 0.03 s of B's 0 .. 0.03 s"]),
    ("shifted", "full", False, ["not the whole reference", "0.01 .. 0.03 s of B's"]),
    ("full", "longer", False, ["0 .. 0.03 s of B's 0 .. 0.06 s", "50 %"]),
    ("full", "shifted", False, ["0.01 .. 0.03 s of B's 0.01 .. 0.04 s"]),
    ("one_at_start", "full", False, ["one common sample", "single instant"]),
    ("full", "one_at_start", False, ["one sample", "t = 0 s", "single instant"]),
    ("one_at_end", "full", False, ["single instant"]),
    ("full", "one_at_end", False, ["one sample", "t = 0.03 s"]),
    ("one_at_start", "one_at_start", False, ["one sample", "single instant"]),
    ("touching", "full", False, ["one common sample", "t = 0.03 s"]),
    ("short", "longer", False, ["0 .. 0.005 s of B's 0 .. 0.06 s"]),
]
PAIR_IDS = [f"{a}-vs-{b}" for a, b, _, _ in PAIRS]


@pytest.mark.parametrize("a, b, passes, words", PAIRS, ids=PAIR_IDS)
def test_compare_fails_a_curve_that_does_not_cover_the_reference(files, a, b, passes, words):
    outcome = check_refused(["compare", str(files[a]), str(files[b]), "crank/angle"],
                            watch=[files[a], files[b]], status=0 if passes else 1)
    if passes:
        assert "covers B's whole span" in outcome.stdout and "-> PASS" in outcome.stdout
        return
    assert "-> FAIL" in outcome.stdout and "NOT the whole reference" in outcome.stdout
    for word in words:
        assert word in outcome.stdout, (word, outcome.stdout)


@pytest.mark.parametrize("a, b, passes, words", PAIRS, ids=PAIR_IDS)
def test_partial_accepts_the_overlap_and_says_which(files, a, b, passes, words):
    outcome = check_refused(["compare", str(files[a]), str(files[b]), "crank/angle",
                             "--partial"], watch=[files[a], files[b]], status=0)
    assert "-> PASS" in outcome.stdout
    if not passes:  # said on the row, on the time base and on the verdict line
        assert "partial:" in outcome.stdout and "accepted by --partial" in outcome.stdout
        for word in words[1:]:
            assert word in outcome.stdout, (word, outcome.stdout)


@pytest.mark.parametrize("a, b, passes, words", PAIRS, ids=PAIR_IDS)
def test_json_states_the_coverage(files, a, b, passes, words):
    outcome = check_refused(["compare", str(files[a]), str(files[b]), "--json"],
                            watch=[files[a], files[b]], status=0 if passes else 1)
    report = json.loads(outcome.stdout)
    (base,) = report["time_bases"]
    assert report["passed"] is passes and (base["shortfall"] == "") is passes
    assert 0.0 <= base["coverage"] <= 1.0
    assert [base["b_start_s"], base["b_end_s"]] == [GRIDS[b][0], GRIDS[b][-1]]
    if not passes:  # every curve of the case failed: columns are not compared one by one
        assert all(not d["passed"] and "not the whole reference" in d["note"]
                   for d in report["deviations"])


@pytest.mark.parametrize("a, b, passes, words", PAIRS, ids=PAIR_IDS)
def test_the_library_function_keeps_the_same_rule(files, a, b, passes, words):
    strict = compare_files(files[a], files[b], ["crank/midpoint_position"])
    assert strict.passed is passes
    loose = compare_files(files[a], files[b], ["crank/midpoint_position"], partial=True)
    assert loose.passed and len(loose.deviations) == 2  # both columns compared
    assert ("--partial" in loose.command()) and ("--partial" not in strict.command())


def test_the_readme_example_on_a_short_run_fails_and_says_why(tmp_path):
    short = tmp_path / "short.h5"
    assert run_cli(["run", "simulate", "--quiet", "--no-figures", "--out", str(short),
                    "--set", "simulation.end_time_s=0.005", "--set",
                    "simulation.error_estimate=false"]).status == 0
    outcome = check_refused(["compare", str(short), str(REFERENCE), "crank/angle"],
                            watch=[short, REFERENCE], status=1)
    assert "0 .. 0.005 s of B's 0 .. 0.03 s (16.7 %" in outcome.stdout
    assert check_refused(["compare", str(short), str(REFERENCE), "crank/angle", "--partial"],
                         watch=[short, REFERENCE], status=0).stdout.count("partial") >= 2


def test_hostile_case_count():
    """This file's share of issue 26's hostile cases."""
    assert 4 * len(PAIRS) + 1 >= 60
