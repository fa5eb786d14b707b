"""Modal band damping (``<link>.damping_model = "modal_bands"``, flex.bodies.reduction.damping).

The band matrix is checked against an independent computation: the damped reduced system's
own eigenvalues (the quadratic eigenproblem M s^2 + D s + K, solved in state space), whose
damping ratios -Re(s)/|s| must be the bands' for each mode's undamped frequency. A run
through Exudyn is checked against its undamped twin (the bands take energy out).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from flex.api import load_scene
from flex.base.errors import SceneError
from flex.bodies.reduction.damping import band_damping_ratio, modal_band_damping_matrix

PLATE = ['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.modes=4",
         "coupler.mesh_size_m=0.004", "simulation.end_time_s=0.01"]


def test_band_ratios_follow_the_commercial_default():
    assert [band_damping_ratio(f) for f in (5.0, 99.9, 100.0, 999.0, 1000.0, 1000.1, 5e4)] \
        == [0.01, 0.01, 0.10, 0.10, 0.10, 1.0, 1.0]


def _state_roots(mass, damping, stiffness):
    """The roots s of det(M s^2 + D s + K) = 0, from the first-order (state-space) form."""
    n = len(mass)
    inverse = np.linalg.inv(mass)
    state = np.block([[np.zeros((n, n)), np.eye(n)],
                      [-inverse @ stiffness, -inverse @ damping]])
    return scipy.linalg.eigvals(state)


def _damping_ratios_of_the_damped_system(mass, damping, stiffness):
    """-Re(s)/|s| of each eigenvalue pair of M s^2 + D s + K (state space), by |s|."""
    roots = _state_roots(mass, damping, stiffness)
    # one of each underdamped pair (a critically damped mode's double real root comes out
    # with an imaginary part of round-off's square root)
    roots = roots[roots.imag > 1e-3 * np.abs(roots)]
    order = np.argsort(np.abs(roots))
    return np.abs(roots[order]) / (2 * np.pi), -roots[order].real / np.abs(roots[order])


def test_each_mode_of_a_reduced_body_gets_its_bands_ratio(reduction_cache):
    """On the 1 mm coupler's reduction (FE matrices of NGsolve, projected by Exudyn): every
    underdamped mode of M s^2 + D s + K has the ratio of its band; D is symmetric and
    positive semidefinite."""
    from flex.dynamics.link_models import reduction_for_scene
    from flex.fidelity.auto import resolve

    scene = resolve(load_scene(overrides=PLATE), quiet=True).scene
    interface = reduction_for_scene(scene, cache_dir=reduction_cache).ffrf_interface()
    mass, stiffness = interface.massMatrixReduced, interface.stiffnessMatrixReduced
    damping, frequencies_Hz, ratios = modal_band_damping_matrix(mass, stiffness)
    assert np.allclose(damping, damping.T, rtol=0, atol=1e-12 * np.abs(damping).max())
    assert np.linalg.eigvalsh(damping).min() > -1e-9 * np.abs(damping).max()
    measured_Hz, measured_ratios = _damping_ratios_of_the_damped_system(mass, damping,
                                                                        stiffness)
    underdamped = ratios < 1.0
    assert underdamped.sum() == len(measured_Hz) >= 1  # critically damped modes: no pair
    state_roots = _state_roots(mass, damping, stiffness)
    for omega in 2 * np.pi * frequencies_Hz[~underdamped]:  # a double root at -omega
        assert np.min(np.abs(state_roots + omega)) < 1e-3 * omega
    # a damped mode's |s| is its undamped frequency (s = omega (-zeta +- i sqrt(1 - zeta^2)))
    assert measured_Hz == pytest.approx(frequencies_Hz[underdamped], rel=1e-6)
    assert measured_ratios == pytest.approx(ratios[underdamped], rel=1e-6)


def test_a_banded_coupler_runs_and_loses_energy_its_undamped_twin_keeps(reduction_cache):
    """Without the integrator's numerical damping (spectral radius 1), the undamped run keeps
    its energy to a small drift and the banded one loses it."""
    from flex.fidelity.simulation import simulate

    runs = {}
    for model in ("stiffness_proportional", "modal_bands"):
        scene = load_scene(overrides=[*PLATE, f'coupler.damping_model="{model}"',
                                      "simulation.error_estimate=false",
                                      "simulation.spectral_radius=1.0"])
        runs[model] = simulate(scene, cache_dir=reduction_cache)
    total = {model: run.datasets["energy/total"].data for model, run in runs.items()}
    undamped_drift = abs(total["stiffness_proportional"][-1] - total["stiffness_proportional"][0])
    damped_loss = total["modal_bands"][0] - total["modal_bands"][-1]
    assert damped_loss > 10 * undamped_drift  # measured: 21x on this scene


@pytest.mark.parametrize(("overrides", "needle"), [
    (['coupler.damping_model="modal_bands"'], 'coupler.model = "rigid" has none'),
    ([*PLATE[:1], 'coupler.model="auto"', 'coupler.damping_model="modal_bands"'],
     "laws fitted per damping ratio"),
    ([*PLATE, 'coupler.damping_model="modal_bands"', "coupler.damping_ratio=0.02"],
     "would be ignored; accepted: 0"),
    ([*PLATE[:1], 'coupler.model="nonlinear_fe"', 'coupler.damping_model="modal_bands"'],
     'coupler.model = "nonlinear_fe" has none'),
    ([*PLATE, 'coupler.damping_model="bands"'], '"stiffness_proportional", "modal_bands"'),
])
def test_band_damping_where_it_would_mean_nothing_is_refused(overrides, needle):
    with pytest.raises(SceneError) as refused:
        load_scene(overrides=overrides)
    assert needle in str(refused.value)
