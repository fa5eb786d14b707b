"""What fidelity.tolerance applies to (flex.config.tolerance, fidelity.quantities), and every
run's statement of what it covered (issue 47: one tolerance had two meanings, and a missed
tolerance went unsaid)."""

from __future__ import annotations

import pytest

from flex.config.tolerance import Tolerance
from flex.data.scene import load_scene

MOTION = ("crank_angle_end_rad", "slider_position_end_m", "deployment_time_s")


def test_the_default_asks_the_motion_and_the_flexible_links_deflections():
    tolerance = Tolerance.of(load_scene())
    assert tolerance.asked([]) == MOTION
    assert tolerance.asked(["coupler"]) == (*MOTION, "coupler_deployment_peak_deflection_m")
    assert not tolerance.wants_flexible("coupler") and not tolerance.wants_flexible("crank")


def test_asking_a_links_deflection_makes_it_wanted_flexible_and_nothing_else():
    scene = load_scene(overrides=['fidelity.quantities=["coupler_deployment_peak_deflection_m"]'])
    tolerance = Tolerance.of(scene)
    assert tolerance.asked([]) == ("coupler_deployment_peak_deflection_m",)
    assert tolerance.wants_flexible("coupler") and not tolerance.wants_flexible("crank")
    grouped = Tolerance.of(load_scene(overrides=['fidelity.quantities=["deflections"]']))
    assert grouped.wants_flexible("coupler") and grouped.wants_flexible("crank")


@pytest.mark.parametrize("value", ['["nope"]', "[]", '["motion", "motion"]', '"motion"'])
def test_a_quantity_list_that_names_nothing_known_is_refused(value):
    from flex.base.errors import SceneError

    with pytest.raises(SceneError, match="fidelity.quantities"):
        load_scene(overrides=[f"fidelity.quantities={value}"])


def test_auto_never_gives_an_asked_deflection_as_a_rigid_prediction():
    """At 0.001 the 2 mm plate's predicted deflection is 4.4e-4 of its length: rigid for the
    motion, but its deflection asked of itself needs a flexible rung."""
    from flex.fidelity.auto import resolve

    plate = ['coupler.geometry="plate"', 'coupler.model="auto"', "coupler.thickness_m=0.002",
             "fidelity.tolerance=0.001"]
    motion = resolve(load_scene(overrides=plate))
    assert motion.scene["coupler"]["model"] == "rigid"
    assert "of the coupler's length" in motion.decisions[0].reason
    asked = resolve(load_scene(overrides=[*plate, 'fidelity.quantities=["deflections"]']))
    assert asked.scene["coupler"]["model"] != "rigid"


def test_a_missed_tolerance_without_refine_is_a_warning_naming_the_quantity(capsys,
                                                                          reduction_cache):
    from flex.api import simulate

    result = simulate(load_scene(overrides=[
        'coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.003",
        "simulation.end_time_s=0.01", "fidelity.tolerance=1e-5"]), cache_dir=reduction_cache)
    err = capsys.readouterr().err
    line = next(line for line in err.splitlines() if "tolerance 0.001 %" in line)
    assert line.startswith("flex: warning:") and "missed: " in line
    assert "coupler_deployment_peak_deflection_m" in line.split("missed: ")[1]
    assert "fidelity.refine = true" in line
    assert result.attrs["tolerance_met"] is False or not result.attrs["tolerance_met"]
    assert "coupler_deployment_peak_deflection_m\tmissed" in result.attrs["tolerance_covered"]


def test_compare_allows_the_stated_history_errors_when_no_rtol_is_given(tmp_path):
    """Two runs of a rigid 2 mm plate, the second at half the step: their crank-angle curves
    differ by the first's step error, which its stated history error covers; with a tight
    --rtol the same difference fails."""
    from hostile import run_cli

    from flex.tools.compare import compare_files

    files = []
    for name, step in (("coarse", "2e-5"), ("fine", "1e-5")):
        out = tmp_path / f"{name}.h5"
        outcome = run_cli(["run", "simulate", "--no-figures", "--quiet", "--out", str(out),
                           "--set", 'coupler.geometry="plate"', "--set",
                           "coupler.thickness_m=0.002", "--set", "simulation.end_time_s=0.005",
                           "--set", f"simulation.step_s={step}"])
        assert outcome.status == 0, outcome.stderr
        files.append(out)
    stated = compare_files(*files, ["cases/case/crank/angle"])
    (row,) = stated.deviations
    assert row.passed and "stated history errors" in row.note and row.max_abs_deviation > 0
    assert not compare_files(*files, ["cases/case/crank/angle"], rtol=1e-12).passed
