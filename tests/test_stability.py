"""Divergence detection and dead-centre handling, against the independent reference DAE.

Dead centres (crank angle 0 or 180 deg, spring drive): the spring pushes along the slide line,
which gives no crank torque there. flex's full-coordinate model stays regular (the constraint
Jacobian keeps full rank, smallest singular value ~0.045 at every angle; only the one-DOF
slider-to-crank map is singular), so flex runs these starts: at the dead centre the answer is
to stay put (0 deg: unstable equilibrium, 180 deg: stable), near it the crank creeps away
(0 deg) or oscillates about it (180 deg). Both are checked against the reference DAE.
"""

from __future__ import annotations

import math

import h5py
import numpy as np
import pytest

from flex.base.errors import FlexError, SimulationError
from flex.data.results import CaseResult, Dataset, write_results
from flex.data.scene import load_scene
from flex.dynamics.advice import check_finite
from flex.dynamics.reference import SliderCrankDAE, solve_reference
from flex.fidelity.simulation import simulate, simulate_case

SHORT = ["simulation.end_time_s=0.01"]
#: largest energy range over E0 (the spring's energy at the start) of the long FFRF run, per
#: spectral radius (measured: 7.8e-5 and 2.8e-4; drift -4.7e-5 and -2.4e-4)
LOSS = {0.9: 2e-4, 0.5: 1e-3}


def _failed_case_is_stored_without_data(case, tmp_path) -> None:
    path = write_results(tmp_path / "diverged.h5", "test", [case])
    with h5py.File(path) as h5:
        group = h5[f"cases/{case.name}"]
        assert group.attrs["status"] == "failed"
        assert group.attrs["message"] == case.message
        assert len(group) == 0  # no datasets: a failed case is not data


def test_explicit_step_above_the_stability_limit_is_caught(tmp_path):
    # RK44 with 1e8 N/m penalty joints is stable up to ~1.6e-5 s; 3e-5 s explodes
    scene = load_scene(overrides=SHORT + ['simulation.integrator="explicit_penalty"',
                                          "simulation.step_s=3e-5"])
    case = simulate_case(scene, "explicit")
    assert case.status == "failed" and not case.datasets
    assert "diverged at step" in case.message and "t = " in case.message
    step = int(case.message.split("diverged at step ")[1].split()[0])
    time_s = float(case.message.split("t = ")[1].split()[0])
    assert step == round(time_s / 3e-5) and 0 < time_s < 0.01
    _failed_case_is_stored_without_data(case, tmp_path)


def test_newton_failure_is_reported_with_step_and_time(tmp_path):
    # a 1000x stiffer spring with a 2 ms step: the crank snaps through faster than the step
    # resolves and Newton does not converge in step 6 (at any tolerance 1e-6 ... 1e-10)
    scene = load_scene(overrides=["drive.spring_stiffness_N_per_m=1.5e6",
                                  "simulation.step_s=2e-3",
                                  "simulation.newton_relative_tolerance=1e-8"])
    case = simulate_case(scene, "newton")
    assert case.status == "failed" and not case.datasets
    assert "Newton failed" in case.message
    assert "step 6 (t = 0.01 s" in case.message
    _failed_case_is_stored_without_data(case, tmp_path)


def test_nan_input_is_caught_not_returned():
    scene = load_scene(overrides=SHORT)
    scene["drive"]["spring_preload_m"] = math.nan  # bypasses validation on purpose
    case = simulate_case(scene, "nan")
    assert case.status == "failed" and not case.datasets
    assert "step" in case.message and "t = " in case.message


def test_check_finite_reports_the_earliest_problem_with_step_and_time():
    time_s = np.arange(11) * 2e-5
    angle = np.zeros(11)
    angle[7] = np.nan
    norm = np.zeros(11)
    norm[4:] = 1.0  # the constraint norm explodes first
    data = {"time": Dataset(time_s, "s"), "crank/angle": Dataset(angle, "rad"),
            "constraint_norm": Dataset(norm, "m")}
    with pytest.raises(SimulationError) as error:
        check_finite(data, {"step_s": 1e-5})
    assert "step 8 (t = 8e-05 s" in str(error.value)
    assert "constraint norm" in str(error.value)


def test_constraint_jacobian_keeps_full_rank_at_the_dead_centres():
    for angle in (0.0, 180.0, 34.19):
        dae = SliderCrankDAE(load_scene(overrides=[f"crank.initial_angle_deg={angle}"]))
        singular_values = np.linalg.svd(dae.jacobian(dae.q0), compute_uv=False)
        assert singular_values.min() > 0.04


@pytest.mark.parametrize("angle_deg", [0.0, 180.0])
def test_start_at_a_dead_centre_stays_put_as_the_reference(angle_deg):
    scene = load_scene(overrides=["simulation.end_time_s=0.03",
                                  f"crank.initial_angle_deg={angle_deg}"])
    data = simulate(scene).datasets
    angle = data["crank/angle"].data
    reference = solve_reference(scene, data["time"].data)
    assert np.abs(angle - math.radians(angle_deg)).max() < 1e-12
    assert np.abs(reference.q[:, 2] - math.radians(angle_deg)).max() < 1e-12
    assert np.abs(data["slider/velocity"].data).max() < 1e-10


@pytest.mark.parametrize("angle_deg, bound_rad", [
    (1e-3, 5e-9), (1.0, 1e-6), (179.0, 1e-7),
    *(pytest.param(*case, marks=pytest.mark.slow)  # the same contract, in make test-slow
      for case in [(0.1, 1e-6), (181.0, 1e-7), (-1.0, 1e-6)])])
def test_start_near_a_dead_centre_matches_the_reference(angle_deg, bound_rad):
    scene = load_scene(overrides=["simulation.end_time_s=0.03",
                                  f"crank.initial_angle_deg={angle_deg}"])
    data = simulate(scene).datasets
    angle = data["crank/angle"].data
    reference = solve_reference(scene, data["time"].data)
    assert angle[0] == pytest.approx(math.radians(angle_deg), abs=1e-12)  # same branch
    assert np.abs(angle - reference.q[:, 2]).max() < bound_rad
    swing = np.ptp(reference.q[:, 2])
    if angle_deg in (179.0, 181.0):  # stable: oscillates about 180 deg
        assert reference.q[:, 2].min() < math.pi < reference.q[:, 2].max()
    else:  # unstable: the crank leaves the dead centre
        assert swing > 10 * abs(math.radians(angle_deg))


@pytest.mark.slow  # make test-slow: 13 s, the default suite stays within 3 min
def test_a_coupler_beyond_its_euler_load_runs_and_says_the_result_is_not_valid(
        reduction_cache):
    # a 0.3 mm plate (Euler load 6.9 N) pushed by the ~33 N spring: the chord-frame FFRF body
    # runs at 0.1 ms and 0.01 ms steps alike (the linear body in the end_a face frame failed
    # Newton within 6 steps at 0.1 ms), but its geometric stiffness is linear in the load:
    # the buckled plate grows without bound, and the result says it is not valid
    plate = ['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.0003",
             "coupler.mesh_size_m=0.006", "coupler.modes=6", "simulation.end_time_s=0.001",
             "simulation.newton_relative_tolerance=1e-8"]
    peaks = []
    for step_s in (1e-4, 1e-5):
        case = simulate_case(load_scene(overrides=plate + [f"simulation.step_s={step_s}"]),
                             "thin", cache_dir=reduction_cache)
        assert case.status == "ok"
        assert "x its Euler load" in case.attrs["validity_warning"]
        peaks.append(np.abs(case.datasets["coupler/midpoint_deflection"].data).max())
    assert peaks[0] == pytest.approx(peaks[1], rel=0.02)  # measured 0.7 %


@pytest.mark.slow
def test_ffrf_coupler_keeps_its_energy_over_a_long_horizon(reduction_cache):
    # undamped plate and spring: kinetic + strain + spring energy is constant in the physics;
    # generalized-alpha with rho < 1 may only dissipate it (the high modes first). Over
    # 0.2 s of free motion (~70 periods of the first bending mode) at the tradeoff study's
    # 1 % setting the energy stays within LOSS of its start, and more numerical damping
    # (rho 0.5) removes more of it: the check sees dissipation where there is some
    plate = ['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.001",
             "coupler.mesh_size_m=0.004", "coupler.modes=2", "simulation.end_time_s=0.2",
             "simulation.step_s=2e-4", "simulation.output_step_s=2e-4",
             'simulation.newton="modified"', "simulation.newton_relative_tolerance=1e-8"]
    drift = {}
    for rho in (0.9, 0.5):
        data = simulate(load_scene(overrides=plate + [f"simulation.spectral_radius={rho}"]),
                        cache_dir=reduction_cache).datasets
        energy = data["energy/total"].data
        assert data["energy/strain"].data.max() > 1e-4 * energy[0]  # the plate's share counts
        drift[rho] = (energy[-1] - energy[0]) / energy[0]
        assert np.ptp(energy) / energy[0] < LOSS[rho]
    assert -LOSS[0.9] < drift[0.9] <= 1e-6  # never gains energy
    assert drift[0.5] < drift[0.9]


def test_a_run_succeeds_when_exactly_the_expected_cases_fail():
    from flex.study import StudyOutput, Summary

    results = {"ok": CaseResult("ok", ""),
               "diverged": CaseResult("diverged", "", status="failed", message="NaN at step 3")}
    output = StudyOutput("s", {}, results, Summary({}, ""), 0.0,
                         expected_failures=frozenset({"diverged"}))
    assert output.as_expected and output.unexpected() == []
    output.expected_failures = frozenset()
    assert not output.as_expected and output.unexpected() == ["diverged"]
    output.expected_failures = frozenset({"ok", "diverged"})
    assert output.unexpected() == ["ok"]  # built to fail, but ran


def test_the_stability_study_declares_its_forced_divergences():
    from studies import stability

    assert stability.EXPECTED_FAILURES == {"diverge_explicit_above_limit",
                                           "diverge_thin_plate_h1e-3", "long_rigid_rho1"}


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_the_thin_plate_built_to_diverge_does_diverge_and_names_its_step():
    from studies import stability

    (extreme,) = [e for e in stability.extremes() if e.name == "diverge_thin_plate_h1e-3"]
    from flex.config.settings import pinned_overrides
    from flex.experiments.models.stability import extreme_cases

    (scene,) = extreme_cases(load_scene(None, pinned_overrides()), [extreme]).values()
    result = simulate_case(scene, extreme.name)
    assert result.status == "failed" and "diverged" in result.message
    assert "simulation.step_s" in result.message


# ------------------------------------------------------------------------------------------
# flex.experiments.models.stability: references, verdicts, trust boundary
# ------------------------------------------------------------------------------------------
def test_a_constant_speed_run_is_judged_against_the_closed_form():
    from flex.config.settings import pinned_overrides
    from flex.experiments.models.stability import Extreme, References, extreme_cases, judge
    from flex.experiments.workprecision.measurement import ReductionPool

    extreme = Extreme("crank_speed", "stiff_drive", (
        'drive.kind="constant_speed"', "simulation.end_time_s=0.01"), "closed_form", 1.0)
    (scene,) = extreme_cases(load_scene(None, pinned_overrides()), [extreme]).values()
    references = References(ReductionPool(), 1e-3)
    verdict = judge(extreme, scene, simulate_case(scene, extreme.name), references, 1e-3)
    assert verdict["verdict"] == "within tolerance" and verdict["within_tolerance"]
    assert verdict["error"] < 1e-6 and verdict["reference_accuracy"] == 0.0
    assert "energy_drift" not in verdict  # a prescribed crank speed has no spring energy
    failed = CaseResult(extreme.name, "", status="failed", message="Newton failed at step 3")
    diverging = Extreme("d", "divergence", (), "scipy", expect="diverges")
    assert judge(diverging, scene, failed, references, 1e-3)["verdict"] == (
        "diverged as expected, detected")
    with pytest.raises(FlexError, match="unknown reference kind"):
        references.get("fine", scene)  # a fine reference needs its step


def test_trust_boundary_interpolates_where_ffrf_comes_within_one_percent():
    from flex.experiments.models.stability import trust_boundary

    def verdicts(errors):
        return {f"nonlinear_{t:g}mm": {"group": "nonlinear", "parameter": t,
                                       "error_peak_deflection_relative": e,
                                       "axial_force_over_euler_load": 0.1}
                for t, e in errors}

    # log-interpolation: the error 4 % -> 0.25 % over t = 0.5 -> 1 mm is 1 % half-way
    boundary, text = trust_boundary(verdicts([(1.0, 2.5e-3), (0.5, 4e-2), (2.0, 1e-3)]))
    assert boundary == pytest.approx(0.5 * math.sqrt(2), rel=1e-12)
    assert "0.5 mm: 4 % (P/P_euler 0.1)" in text
    assert trust_boundary(verdicts([(0.5, 5e-3)]))[0] == 0.5
    assert trust_boundary(verdicts([(0.5, 5e-2), (1.0, 2e-2)]))[0] == math.inf
    assert math.isnan(trust_boundary({})[0])
