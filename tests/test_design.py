"""The design study and ``flex design``: closed forms, the reference DAE, the optimiser.

- mechanism checks against closed forms (Gruebler/Kutzbach counts of known linkages, the
  rank of a known Jacobian, dead centres and transmission angles of an in-line linkage);
- a tiny sweep on the sweep engine: its measures against the independent reference DAE
  (scipy) and the rest angle of the attached spring in closed form;
- the optimiser against a question answered in closed form (the preload that brings the
  crank to rest at a given angle: half the slider travel between the two angles), and the
  refusal of an unreachable target.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from flex.base.errors import EXIT_BAD_INPUT, FlexError
from flex.base.mechanism_checks import (
    Joint,
    counted_mobility,
    dead_centre_angles_rad,
    gruebler_mobility,
    jacobian_mobility,
    kutzbach_mobility,
    transmission_angle_rad,
)
from flex.base.physics import plate_thickness_for_mass_m
from flex.data.scene import load_scene
from flex.experiments.design import cases as design_cases
from flex.experiments.design import mechanism as design_mechanism
from flex.experiments.design import question as design_question
from flex.experiments.design import summary as design_summary
from flex.experiments.design.report import draw_figures, report_text
from flex.sweep import run_sweep

TINY = design_cases.Grid(angles_deg=(5.0, 60.0), preload_factors=(1.0,), energy_rate_factors=(4.0,),
                   thicknesses_m=(), thickness_rate_factors=(1.0,), final_angle_step_deg=45.0)


@pytest.fixture(scope="module")
def scene():
    return load_scene(None, design_cases.BASE_OVERRIDES)


@pytest.fixture(scope="module")
def sweep(scene, tmp_path_factory):
    scenes, _ = design_cases.plan(scene, TINY)
    outcome = run_sweep(scenes, tmp_path_factory.mktemp("design"), design_cases.design_case,
                        scheduler="serial", progress=False, study="design")
    return outcome.results


# --- mechanism checks: closed forms --------------------------------------------------------

def test_mobility_counts_of_known_linkages():
    assert gruebler_mobility(4, 4) == 1  # the thesis's slider-crank, Eq. 1
    assert kutzbach_mobility(4, [1, 1, 1, 1]) == 1  # Eq. 2
    assert gruebler_mobility(5, 5) == 2  # a five-bar
    assert gruebler_mobility(5, 6) == 0  # two triangles sharing a side: a structure
    assert kutzbach_mobility(3, [1, 1, 1]) == 0  # a triangle
    crank_and_wing = counted_mobility(
        ["frame", "crank", "coupler", "slider", "wing"],
        [Joint("A", ("frame", "crank"), "revolute"), Joint("B", ("crank", "coupler"), "revolute"),
         Joint("C", ("coupler", "slider"), "revolute"), Joint("P", ("slider", "frame"),
                                                             "prismatic"),
         Joint("W", ("crank", "wing"), "weld")])
    assert crank_and_wing == {"gruebler": 1, "kutzbach": 1}
    with pytest.raises(ValueError, match="not a body"):
        counted_mobility(["frame"], [Joint("A", ("frame", "crank"), "revolute")])


def test_jacobian_rank_finds_a_redundant_constraint():
    free = jacobian_mobility(np.eye(3)[:2])  # two constraints on three coordinates
    assert (free["rank"], free["mobility"], free["redundant"]) == (2, 1, 0)
    doubled = jacobian_mobility(np.array([[1.0, 0, 0], [0, 1, 0], [2, 0, 0]]))
    assert (doubled["rank"], doubled["mobility"], doubled["redundant"]) == (2, 1, 1)


def test_dead_centres_and_transmission_angle_in_closed_form():
    assert dead_centre_angles_rad(0.04, 0.08) == pytest.approx((0.0, math.pi))
    extended, folded = dead_centre_angles_rad(0.04, 0.08, 0.01)
    # collinear: C = (L1 + L2) (cos, sin) of the extended angle, C = -(L2 - L1) (cos, sin)
    # of the folded one; C on the slide line y = 0.01 either way
    assert 0.12 * math.sin(extended) == pytest.approx(0.01)
    assert -0.04 * math.sin(folded) == pytest.approx(0.01)
    assert math.cos(folded) < 0 < math.cos(extended)
    # in line at 90 deg: phi = -asin(L1 / L2) = -30 deg, so mu = 180 - 120 = 60 deg
    mu = transmission_angle_rad(math.pi / 2, -math.asin(0.5))
    assert math.degrees(float(mu)) == pytest.approx(60.0)
    assert float(transmission_angle_rad(0.0, 0.0)) == 0.0


def test_the_thesis_mechanism_has_one_freedom_and_no_redundant_constraint(scene):
    checks = design_mechanism.mechanism_checks(scene, np.radians([34.19, 60.0, 95.0]))
    assert checks["mechanism/gruebler_mobility"].data == 1
    assert checks["mechanism/kutzbach_mobility"].data == 1
    assert checks["mechanism/jacobian_mobility"].data == 1
    assert checks["mechanism/redundant_constraints"].data == 0
    # the slider-input Jacobian is singular exactly at the dead centres (0 and 180 deg)
    turn = checks["mechanism/turn_slider_input_singular_value"].data
    assert turn[0] < 1e-12 and turn[180] < 1e-12 and turn[90] > 1e-3


# --- the sweep against the reference DAE and closed forms ----------------------------------

def test_the_design_point_is_the_thesis_mechanism(scene):
    thickness = plate_thickness_for_mass_m(0.07767, 0.08, 0.01, 7850.0)
    assert scene["coupler"]["thickness_m"] == pytest.approx(thickness, rel=1e-3)


def test_sweep_measures_match_the_reference_dae(scene, sweep):
    names = design_cases.reference_names(scene, TINY, (5.0, 60.0))
    checks = design_cases.run_references(sweep, names)
    assert set(checks) == set(names)  # every point rigid, so every one checked
    for values in checks.values():
        assert values["crank_angle"][0] < 1e-5  # rad
        assert values["slider_position"][0] < 1e-6  # m
        assert abs(values["peak_crank_speed_flex"][0]
                   - values["peak_crank_speed_reference"][0]) < 1e-3  # rad/s


def test_rest_angle_and_travel_follow_the_attached_spring(scene, sweep):
    rows = design_summary.table(sweep)
    rest = math.degrees(design_cases.rest_angle_rad(scene))
    design_row = list(rows["case"]).index(design_cases.design_case_name(scene))
    assert math.degrees(rows["final_crank_angle"][design_row]) == pytest.approx(rest, abs=0.01)
    simulated = rows["outcome"] == "simulated"
    np.testing.assert_allclose(rows["slider_travel"][simulated],
                               2 * rows["preload_m"][simulated], rtol=1e-4)


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_report_and_figures_come_from_the_datasets(scene, sweep, tmp_path):
    datasets = design_summary.summary_datasets(scene, TINY, sweep, {})
    text = report_text(datasets)
    assert "Does 34.19 deg maximise the peak crank speed?" in text
    assert "Gruebler (Eq. 1) 1" in text
    paths = draw_figures(datasets, tmp_path)
    assert all(path.stat().st_size > 0 for path in paths)


# --- the optimiser ---------------------------------------------------------------------------

@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_optimiser_finds_the_closed_form_preload(scene):
    """The smallest preload that brings the crank (from 34.19 deg) to rest at 80 deg or
    beyond: half the slider travel between the two angles, x(theta0) - x(theta_f)."""
    expected = design_cases.preload_for_rest_angle_m(scene, math.radians(34.19), math.radians(80.0))
    found = design_question.answer(scene, design_question.Question("preload", "final_angle",
                                                                   80.0))
    assert found.value == pytest.approx(expected, rel=2e-3)
    assert found.best.target_margin >= 0
    assert len(found.evidence) >= design_question.SCAN_POINTS


def _stand_in(name, case_scene, cache_dir=None):
    """A stand-in simulation: peak speed 0.1 / t [rad/s], peak stress 100 MPa (1 mm / t)^2."""
    from flex.data.results import CaseResult, Dataset

    t = case_scene["coupler"]["thickness_m"]
    values = {"peak_crank_speed": 0.1 / t, "deployment_time": 0.02,
              "peak_coupler_stress": 100e6 * (1e-3 / t) ** 2}
    return CaseResult(name, "", {f"measures/{k}": Dataset(v, "") for k, v in values.items()},
                      attrs={"design_model": "rigid"})


def test_optimiser_finds_a_known_root_and_refuses_the_unreachable(scene):
    """Lightest coupler with peak speed >= 40 rad/s (t <= 2.5 mm) and 1.5 x stress <= 250
    MPa: t = 1 mm x sqrt(1.5 x 100 / 250), where the stress constraint binds."""
    question = design_question.Question("thickness", "peak_speed", 40.0)
    found = design_question.answer(scene, question, simulate=_stand_in)
    xtol = design_question.RELATIVE_XTOL * (12.37e-3 - 0.5e-3)  # brentq's, on the range
    assert 1e-3 * math.sqrt(0.6) <= found.value <= 1e-3 * math.sqrt(0.6) + 2 * xtol
    assert "limited by the stress" in found.note
    question = design_question.Question("thickness", "peak_speed", 40.0, bounds=(3e-3, 12e-3))
    with pytest.raises(FlexError, match="unreachable.*33.33 rad/s at 0.003"):
        design_question.answer(scene, question, simulate=_stand_in)


def test_cli_refuses_an_unreachable_target_in_one_line(capsys, tmp_path):
    from flex.cli import main

    status = main(["design", "--vary", "angle", "--peak-speed", "1000", "--range", "30", "40",
                   "--out", str(tmp_path / "q.h5")])
    err = capsys.readouterr().err
    assert status == EXIT_BAD_INPUT
    errors = [line for line in err.splitlines() if line.startswith("flex: error:")]
    assert len(errors) == 1 and "unreachable" in errors[0] and "Traceback" not in err
    assert all(line.startswith("flex: ") for line in err.splitlines())  # progress: one line each
    assert not (tmp_path / "q.h5").exists()
