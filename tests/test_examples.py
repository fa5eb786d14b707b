"""Each study, run as users run it, checked by one regression number (scikit-fem style)."""

import re
from pathlib import Path

import pytest

from flex.study import execute, load_study, study_scene

README = Path(__file__).resolve().parent.parent / "README.md"


def run(name, overrides=()):
    module = load_study(name)
    return module, execute(module, study_scene(module, overrides=list(overrides)))


def test_kinematics_stroke():
    _, output = run("kinematics")
    stroke = output.summary.datasets["thesis_comparison/flex"].data[0]
    assert stroke == pytest.approx(0.080, abs=1e-9)  # closed form: 2 L1


def test_dynamics_speed_peak_and_readme_table():
    module, output = run("dynamics")
    peak = output.summary.datasets["thesis_comparison/preload_22mm"].data[2]
    assert peak == pytest.approx(60.686, abs=0.01)  # data sheet check: 60.7 rad/s
    # the README's comparison table is the one this run computes
    table = module.comparison_table({
        name: module.measures({k: v.data for k, v in case.datasets.items()})
        for name, case in output.results.items()})
    assert table in README.read_text(), "README thesis table is stale: re-paste it"


def test_simulate_runs_the_given_scene():
    _, output = run("simulate", ["crank.initial_angle_deg=50", "simulation.end_time_s=0.005"])
    angle = output.results["case"].datasets["crank/angle"].data
    assert angle[0] == pytest.approx(0.872664626, abs=1e-9)
    assert re.search(r"crank angle 0\.8727", output.summary.report)


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
