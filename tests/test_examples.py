"""Each study, run as users run it, checked by one regression number (scikit-fem style)."""

import re

import pytest

from flex.experiments.thesis import dynamics
from flex.study import execute, load_study, study_scene


def run(name, overrides=()):
    module = load_study(name)
    return module, execute(module, study_scene(module, overrides=list(overrides)))


def test_kinematics_stroke():
    _, output = run("kinematics")
    stroke = output.summary.datasets["thesis_comparison/flex"].data[0]
    assert stroke == pytest.approx(0.080, abs=1e-9)  # closed form: 2 L1


def test_dynamics_against_the_datasheet_checks():
    _, output = run("dynamics")
    peak = output.summary.datasets["thesis_comparison/preload_22mm"].data[2]
    assert peak == pytest.approx(60.686, abs=0.01)  # data sheet check: 60.7 rad/s
    table = {name: dynamics.measures({k: v.data for k, v in case.datasets.items()})
             for name, case in output.results.items()}
    # independent checks of ../shared/thesis-datasheet.md (rigid model, both preloads), to
    # the digits the data sheet quotes
    for name, speed, speed_time, angle, angle_time in (
            ("preload_22mm", 60.7, 0.01275, 1.659, 0.02645),
            ("preload_11mm", 32.4, 0.0125, 1.142, 0.0262)):
        measured = table[name]
        assert measured["speed_max"] == pytest.approx(speed, abs=0.05)
        assert measured["speed_max_time"] == pytest.approx(speed_time, abs=2.5e-4)
        assert measured["angle_max"] == pytest.approx(angle, abs=5e-4)
        assert measured["angle_max_time"] == pytest.approx(angle_time, abs=2.5e-4)
        # exact joints: the constraint norm stays at round-off, compared by order only
        assert measured["constraint_norm_max"] < 1e-12
    rendered = dynamics.comparison_table(table)
    assert rendered.count("\n") == len(dynamics.THESIS_ROWS) + 1  # head, rule, one row each


def test_simulate_runs_the_given_scene():
    _, output = run("simulate", ["crank.initial_angle_deg=50", "simulation.end_time_s=0.005"])
    angle = output.results["case"].datasets["crank/angle"].data
    assert angle[0] == pytest.approx(0.872664626, abs=1e-9)
    assert re.search(r"crank angle 0\.8727", output.summary.report)


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_spring_fe_agrees_with_wahl():
    _, output = run("spring")
    ratio = output.summary.datasets["fe/over_wahl"].data
    assert ratio == pytest.approx(1.0, abs=0.02)  # Wahl's curved-beam correction
    assert output.summary.datasets["design/rate"].data == pytest.approx(1500.0, rel=1e-9)


@pytest.mark.slow
def test_modal_table5_thinnest_plate():
    _, output = run("modal")
    omega = output.summary.datasets["table5/fe_omega_rad_per_s"].data[0]
    assert omega == pytest.approx(2247.04282, rel=2e-3)  # thesis Table 5, model 0
