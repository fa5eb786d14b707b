"""The rigid model's deflection predictor (flex.fidelity.predictor) and the closed forms it
rests on (flex.base.physics): each against an independent computation, and the prediction
against FFRF couplers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from flex.base.physics import (
    axial_load_amplification,
    pinned_beam_midpoint_deflection_m,
    ramp_load_factor,
)
from flex.fidelity.predictor import oscillator_response, predict_deflection

L, T, W, E = 0.08, 0.002, 0.01, 200e9
EI = E * W * T**3 / 12


def _midpoint_by_integration(load_N_per_m) -> float:
    """Midpoint deflection of a pinned-pinned beam by integrating M / EI twice (the moment
    from the load by statics), chord-relative: an independent route to the closed form."""
    x = np.linspace(0.0, L, 20001)
    q = load_N_per_m(x)
    shear = cumulative_trapezoid(q, x, initial=0.0)
    reaction_a = np.trapezoid(q * (L - x), x) / L  # moments about the far end
    moment = reaction_a * x - cumulative_trapezoid(shear, x, initial=0.0)
    slope = cumulative_trapezoid(moment / EI, x, initial=0.0)
    deflection = cumulative_trapezoid(slope, x, initial=0.0)
    deflection -= deflection[-1] * x / L  # pinned ends: zero at both
    return abs(float(deflection[len(x) // 2]))  # along the load (the closed form's sign)


def test_midpoint_deflection_of_a_uniform_load_against_integration():
    total = 3.7  # N
    expected = _midpoint_by_integration(lambda x: np.full_like(x, total / L))
    assert pinned_beam_midpoint_deflection_m(total, L, T, W, E) == pytest.approx(
        expected, rel=1e-6)


def test_a_linear_load_bends_the_midpoint_by_its_mean_only():
    # q from 1 to 5 N/m along the beam: total 0.24 N; its odd part leaves the middle alone
    expected = _midpoint_by_integration(lambda x: 1.0 + 4.0 * x / L)
    assert pinned_beam_midpoint_deflection_m(3.0 * L, L, T, W, E) == pytest.approx(
        expected, rel=1e-6)


def test_axial_amplification():
    euler = math.pi**2 * EI / L**2
    np.testing.assert_allclose(axial_load_amplification([0.0, euler / 2, -euler], euler),
                               [1.0, 2.0, 0.5])
    assert np.isinf(axial_load_amplification(euler, euler))


@pytest.mark.parametrize("ratio", [0.25, 0.5, 1.3, 3.0])
def test_the_ramp_load_factor_is_the_oscillator_peak_under_a_ramp(ratio):
    period = 1e-3
    time_s = np.linspace(0.0, 12 * period, 24001)
    static = np.minimum(time_s / (ratio * period), 1.0)
    response = oscillator_response(time_s, static, 2 * np.pi / period)
    assert np.max(response) == pytest.approx(float(ramp_load_factor(ratio * period, period)),
                                             rel=2e-3)


def test_a_step_doubles_the_static_deflection():
    assert float(ramp_load_factor(0.0, 1e-3)) == 2.0
    time_s = np.linspace(0.0, 5e-3, 5001)
    response = oscillator_response(time_s, np.ones_like(time_s), 2 * np.pi / 1e-3)
    assert np.max(response) == pytest.approx(2.0, rel=1e-4)


@pytest.mark.parametrize("extra", [[], ["drive.spring_stiffness_N_per_m=5000.0"]])
def test_the_prediction_from_a_rigid_run_meets_the_ffrf_coupler(reduction_cache, extra):
    """A 2 mm steel plate coupler, thesis spring and a 5000 N/m one: the prediction from the
    rigid run's loads alone is within [0.8, 1.25] of the FFRF peak deflection over the
    deployment (measured 0.99 and 0.97, nothing fitted)."""
    from flex.data.headlines import first_maximum_index
    from flex.data.scene import apply_overrides, default_scene
    from flex.fidelity.simulation import simulate

    scene = apply_overrides(default_scene(), [
        'coupler.geometry="plate"', "coupler.thickness_m=0.002", "coupler.mesh_size_m=0.004",
        "simulation.error_estimate=false", "simulation.step_s=1e-5",
        'simulation.newton="modified"', "simulation.spectral_radius=0.9",
        "simulation.newton_relative_tolerance=1e-8", *extra])
    rigid, ffrf = (simulate(apply_overrides(scene, [f'coupler.model="{model}"']),
                            cache_dir=reduction_cache) for model in ("rigid", "ffrf"))
    series = {key: value.data for key, value in rigid.datasets.items()}
    end = series["time"][first_maximum_index(series["crank/angle"])]
    prediction = predict_deflection(series, scene["coupler"], "coupler", end)
    window = np.asarray(ffrf.datasets["time"].data) <= end
    measured = np.max(np.abs(ffrf.datasets["coupler/midpoint_deflection"].data[window]))
    assert 0.8 <= prediction.peak_deflection_m / measured <= 1.25
    assert prediction.load_factor_peak_m < prediction.peak_deflection_m  # the bound misses


def test_auto_stores_the_rigid_model_s_predicted_error(reduction_cache):
    """Whatever auto picks, the coupler's decision carries the rigid model's deflection error
    predicted from the probe's loads (fidelity_coupler_predicted_rigid_error)."""
    from flex.data.scene import apply_overrides, default_scene
    from flex.fidelity.simulation import simulate

    scene = apply_overrides(default_scene(), [
        'coupler.geometry="plate"', 'coupler.model="auto"', "coupler.thickness_m=0.003",
        "simulation.error_estimate=false", "simulation.end_time_s=0.01"])
    result = simulate(scene, cache_dir=reduction_cache)
    predicted = result.attrs["fidelity_coupler_predicted_rigid_error"]
    # a 3 mm steel coupler deflects ~14 um over its 80 mm in this deployment (test above)
    assert 5e-5 < predicted < 5e-4
    # a crank left rigid by the scene gets no decision, so no prediction; an auto crank's:
    # tests/test_crank_predictor.py
    assert "fidelity_crank_predicted_rigid_error" not in result.attrs


def test_a_rigid_plate_coupler_states_the_bending_its_loads_predict(reduction_cache):
    """A rigid 2 mm plate coupler: the run states its predicted peak deflection over the
    deployment, named a prediction, +- its spread; the FFRF body on the same scene (an
    independent model) lies within that spread."""
    from flex.api import load_scene, simulate
    from flex.data.headlines import BUILTIN_HEADLINES
    from flex.fidelity.predictor import PREDICTION_SPREAD

    plate = {"coupler.geometry": "plate", "coupler.thickness_m": 0.002,
             "simulation.end_time_s": 0.02, "simulation.error_estimate": False}
    rigid = simulate(load_scene(overrides={**plate, "coupler.model": "rigid"}), cache_dir=None)
    predicted = rigid.attrs["predicted_coupler_peak_deflection_m"]
    assert rigid.attrs["predicted_coupler_peak_deflection_m_error"] == pytest.approx(
        PREDICTION_SPREAD * predicted)
    assert "a prediction, not a run" in rigid.attrs["predicted_method"]
    assert rigid.attrs["predicted_coupler_peak_bending_stress_Pa"] > 0
    ffrf = simulate(load_scene(overrides={**plate, "coupler.model": "ffrf"}),
                    cache_dir=reduction_cache)
    run = BUILTIN_HEADLINES["coupler_deployment_peak_deflection_m"].read(ffrf.datasets)
    assert abs(predicted - run) <= PREDICTION_SPREAD * predicted
    assert not any(key.startswith("predicted_") for key in ffrf.attrs)
