"""The bench study's step-cost part runs both joint-marker kinds on the plan's meshes and modes
(its timings are measured by ``make bench``, never asserted here)."""

from __future__ import annotations

import math

import pytest

from flex.data.scene import apply_overrides, default_scene
from flex.experiments.workprecision.benchmark import StepCostPlan, bench_step_cost
from flex.experiments.workprecision.measurement import ReductionPool


def test_step_cost_measures_both_joint_marker_kinds(reduction_cache):
    scene = apply_overrides(default_scene(), [
        'coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.001"])
    notes: dict = {}
    said: list[str] = []
    bench_step_cost(scene, StepCostPlan((0.004,), (2,), 1e-5, 5e-4), 1,
                    ReductionPool(reduction_cache), said.append, notes)
    (row,) = notes["step_cost"]
    assert (row["mesh_size_m"], row["modes"]) == (0.004, 2) and row["mesh_nodes"] > 100
    for kind in ("fewest", "all_face_nodes"):
        assert math.isfinite(row[f"{kind}_ms_per_step"]) and row[f"{kind}_ms_per_step"] > 0
    # the same equations to the Newton tolerance: the same iteration counts, give or take one
    assert abs(row["fewest_newton_per_step"] - row["all_face_nodes_newton_per_step"]) <= 1
    assert said and "mesh 4 mm, 2 modes" in said[0]


def test_newton_variants_report_their_iterations_per_step(reduction_cache):
    """Full Newton at a looser tolerance takes fewer iterations per step than modified Newton
    at flex's (a Jacobian every iteration against one kept while converging)."""
    scene = apply_overrides(default_scene(), [
        'coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.001"])
    notes: dict = {}
    plan = StepCostPlan((0.004,), (2,), 1e-5, 5e-4, {"modified 1e-8": ("modified", 1e-8),
                                                     "full 1e-6": ("full", 1e-6)})
    bench_step_cost(scene, plan, 1, ReductionPool(reduction_cache), lambda _: None, notes)
    modified, full = notes["newton"]
    assert (modified["label"], full["label"]) == ("modified 1e-8", "full 1e-6")
    assert full["newton_per_step"] < modified["newton_per_step"]
    assert all(math.isfinite(row["ms_per_step"]) and row["ms_per_step"] > 0
               for row in (modified, full))


def test_make_all_is_timed_in_the_clone_that_holds_flex():
    # make bench once ran "make all" inside flex/ (a fixed parents[2] gone stale when the
    # module moved a folder deeper): "No rule to make target 'all'", nothing timed
    from pathlib import Path

    import flex
    from flex.experiments.workprecision.benchmark import repository_root

    root = repository_root()
    assert root == Path(flex.__file__).resolve().parents[1]
    assert "\nall: " in (root / "Makefile").read_text()


def test_the_budget_part_reports_its_ratios_from_its_own_medians():
    """The table rows and datasets of the ``budget`` part come from the notes' medians: a
    ratio is the run with its budget over the run alone, the command line over in process."""
    from flex.experiments.workprecision.benchmark_report import _budget_rows  # noqa: PLC2701

    notes = {"budget": [{"plate": "1mm", "run_s": 0.2, "budget_s": 0.9, "ratio": 4.5}],
             "command_line": {"plate": "1mm", "command_s": 1.9, "in_process_s": 0.9,
                              "ratio": 1.9 / 0.9}}
    datasets: dict = {}
    rows = _budget_rows(notes, datasets)
    assert rows[0][:2] == ("budget at 1 %: 1mm", "4.5x")
    assert rows[1][:2] == ("command line: 1mm", "1.90 s") and "(2.1x)" in rows[1][2]
    assert datasets["budget/1mm/ratio"].data == 4.5
    assert datasets["command_line/command_s"].units == "s"


@pytest.mark.slow
def test_the_budget_part_times_the_run_its_budget_and_the_command_line(reduction_cache):
    from flex.experiments.workprecision.budget_cost import BudgetPlan, bench_budget

    plate = ['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.003",
             "simulation.end_time_s=0.003"]
    notes: dict = {}
    bench_budget(BudgetPlan({"3mm": plate}, 0.01, "3mm"), 1, reduction_cache, lambda _: None,
                 notes)
    (row,) = notes["budget"]
    assert row["budget_s"] > row["run_s"] > 0 and row["ratio"] == pytest.approx(
        row["budget_s"] / row["run_s"])
    line = notes["command_line"]
    assert line["command_s"] > line["in_process_s"] > 0
