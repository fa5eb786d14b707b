"""``drive.spring_model = "auto"`` (flex.fidelity.spring_choice): the closed forms of the coil
against independent computations (the chain's own mass and stiffness matrices), the prediction
of the massless spring's error against measured chains, and the choice auto makes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh

from flex.base import spring_waves
from flex.base.errors import SceneError
from flex.bodies.spring import surge_frequency_fixed_free_Hz
from flex.config.settings import pinned_overrides
from flex.config.usage import unused_keys
from flex.data.scene import load_scene
from flex.dynamics.solver import integrate
from flex.experiments.models.spring_mass import chain_matrices, governing_error
from flex.fidelity.auto import resolve
from flex.fidelity.probe import deployment_probe
from flex.fidelity.simulation import simulate
from flex.fidelity.spring_choice import (
    CHAIN_ERROR_CONSTANT,
    SPRING_PREDICTION_MARGIN,
    chain_segments,
    predict_massless_spring_error,
    rayleigh_warp,
)

RATE_N_PER_M, COIL_KG = 1500.0, 0.1057  # the bundled (consistent thesis) spring
QUICK = ["simulation.error_estimate=false", "simulation.step_s=1e-5"]


def _arrays(case) -> dict[str, np.ndarray]:
    return {key: np.asarray(value.data) for key, value in case.datasets.items()}


def _run(*sets: str, end_s: float = 0.035) -> dict[str, np.ndarray]:
    return _arrays(integrate(resolve(load_scene(
        overrides=[*QUICK, f"simulation.end_time_s={end_s}", *sets]), quiet=True).scene))


def _chain(segments: int) -> list[str]:
    return ['drive.spring_model="chain"', f"drive.spring_segments={segments}"]


# --- closed forms against the chain ---------------------------------------------------------

@pytest.mark.parametrize("segments", [1, 4, 16, 256])
def test_rayleigh_mass_is_the_chain_kinetic_energy_in_the_limit(segments):
    # the chain's own lumped masses (flex.experiments.models.spring_mass.chain_matrices, no end
    # mass beyond a negligible one) moving with the linear profile of a quasi-static coil:
    # sum m_i (x_i / L)^2 = m_s / 3 + m_s / (6 N^2), the second-order convergence
    mass, _ = chain_matrices(COIL_KG, RATE_N_PER_M, 1e-300, segments)
    profile = np.arange(1, segments + 1) / segments
    effective_kg = float(profile @ mass @ profile)
    exact = spring_waves.spring_effective_mass_kg(COIL_KG)
    assert exact == pytest.approx(COIL_KG / 3, rel=1e-15)
    assert effective_kg - exact == pytest.approx(COIL_KG / (6 * segments**2), rel=1e-9)


@pytest.mark.parametrize("mass_ratio", [0.3, 1.0, 4.0])
def test_wave_numbers_against_the_chain_eigenvalues(mass_ratio):
    # 128 segments: the chain's frequencies are within ~1e-4 (second order, 0.09 j^2 / N^2)
    mass, stiffness = chain_matrices(COIL_KG, RATE_N_PER_M, COIL_KG / mass_ratio, 128)
    chain = np.sqrt(eigh(stiffness, mass, eigvals_only=True)[:3])
    exact = spring_waves.spring_end_mass_wave_numbers(mass_ratio, 3) * math.sqrt(
        RATE_N_PER_M / COIL_KG)
    np.testing.assert_allclose(chain, exact, rtol=3e-4)


def test_fixed_free_surge_period_is_four_root_m_over_k():
    # the slider end without mass: the chain's first period -> 4 sqrt(m_s / k)
    mass, stiffness = chain_matrices(COIL_KG, RATE_N_PER_M, 1e-12, 128)
    period_s = 2 * math.pi / math.sqrt(eigh(stiffness, mass, eigvals_only=True)[0])
    four_root_s = 4 * math.sqrt(COIL_KG / RATE_N_PER_M)
    assert period_s == pytest.approx(four_root_s, rel=3e-5)
    beta = spring_waves.spring_end_mass_wave_numbers(1e12, 1)[0]
    assert 2 * math.pi / beta * math.sqrt(COIL_KG / RATE_N_PER_M) == pytest.approx(
        four_root_s, rel=1e-9)
    assert 1 / surge_frequency_fixed_free_Hz(RATE_N_PER_M, COIL_KG) == pytest.approx(
        four_root_s, rel=1e-12)


@pytest.mark.parametrize("mass_ratio", [0.3, 1.0, 3.0])
def test_released_coil_against_the_chain_released_from_rest(mass_ratio):
    # the chain (128 segments) released at rest from a uniform compression, solved exactly
    # by its own modes; its end against the modal series of the continuous coil
    mass, stiffness = chain_matrices(1.0, 1.0, 1.0 / mass_ratio, 128)
    values, vectors = eigh(stiffness, mass)
    start = np.arange(1, 129) / 128.0  # uniform compression: linear in the position
    amplitudes = vectors.T @ mass @ start  # mass-normalised modes
    tau = np.linspace(0.0, 12.0, 400)
    chain_end = np.cos(np.outer(tau, np.sqrt(values))) @ (amplitudes * vectors[-1])
    series = spring_waves.released_spring_end_displacement(mass_ratio, tau)
    assert np.max(np.abs(series - chain_end)) < 1e-3
    # and the deviation from Rayleigh's model that the prediction adds, on the chain
    beta_1 = spring_waves.spring_end_mass_wave_numbers(mass_ratio, 1)[0]
    tau = np.linspace(0.0, math.pi / beta_1, 2001)
    chain_end = np.cos(np.outer(tau, np.sqrt(values))) @ (amplitudes * vectors[-1])
    rayleigh = np.cos(tau / math.sqrt(1 / mass_ratio + 1 / 3))
    assert spring_waves.released_spring_rayleigh_deviation(mass_ratio) == pytest.approx(
        np.max(np.abs(chain_end - rayleigh)) / 2, rel=3e-3)


def test_rayleigh_warp_of_a_linear_oscillator_is_its_frequency_change():
    # one mass M on a spring, released from rest: x = 1 - cos(w t); with m_a more, w' =
    # w sqrt(M / (M + m_a)); the warp of the probe must give the closed-form deviation
    mass_kg, added_kg, omega = 0.1, 0.05, 100.0
    time = np.linspace(0.0, math.pi / omega, 4001)
    position = 1.0 - np.cos(omega * time)
    speed = omega * np.sin(omega * time)
    probe = {"time": time, "crank/angle": position, "slider/position": position,
             "slider/velocity": speed, "energy/kinetic": 0.5 * mass_kg * speed**2}
    error, stop_s = rayleigh_warp(probe, added_kg)
    slower = omega * math.sqrt(mass_kg / (mass_kg + added_kg))
    fine = np.linspace(0.0, math.pi / slower, 20001)
    exact = np.max(np.abs(np.cos(slower * fine) - np.cos(omega * fine))) / 2
    assert stop_s == pytest.approx(math.pi / slower, rel=1e-6)
    assert error == pytest.approx(exact, rel=1e-4)


# --- the prediction against measured chains -------------------------------------------------

@pytest.mark.parametrize("coil_kg, slider_kg", [(COIL_KG, 0.0264), (0.03, 0.1)])
def test_predicted_massless_error_bounds_the_measured_one(coil_kg, slider_kg):
    # make spring_mass measured 1.001-1.17 over 14 runs; here two of them again, against a
    # 48-segment chain (its own error ~1e-4)
    sets = [f"drive.spring_mass_kg={coil_kg}", f"slider.mass_kg={slider_kg}"]
    scene = load_scene(overrides=[*QUICK, "simulation.end_time_s=0.045", *sets])
    _, _, probe = deployment_probe(scene)
    predicted = predict_massless_spring_error(probe, coil_kg).error
    measured = governing_error(_run(*sets, end_s=0.045), _run(*sets, *_chain(48), end_s=0.045))
    assert 1.0 <= predicted / measured <= 1.25


def test_auto_picks_massless_at_a_loose_tolerance_and_a_chain_at_a_tight_one():
    def decided(tolerance: float):
        resolution = resolve(load_scene(overrides=['drive.spring_model="auto"',
                                                   f"fidelity.tolerance={tolerance}"]))
        return resolution.scene, resolution.decisions

    loose, (decision,) = decided(0.5)
    assert loose["drive"]["spring_model"] == "massless" and decision.segments == 0
    tight, (decision,) = decided(0.01)
    segments = tight["drive"]["spring_segments"]
    assert tight["drive"]["spring_model"] == "chain" and decision.segments == segments
    assert 2 <= segments <= 16
    # the chosen chain's measured error (against a fine chain) is within its predicted
    # discretization error, which is within half the tolerance
    error = governing_error(_run(*_chain(segments)), _run(*_chain(64)))
    bound = decision.predicted_error * SPRING_PREDICTION_MARGIN
    assert error <= CHAIN_ERROR_CONSTANT * bound / segments**2 <= 0.01 * 0.5


def test_simulate_stores_the_spring_decision():
    result = simulate(load_scene(overrides=['drive.spring_model="auto"', *QUICK,
                                            "simulation.end_time_s=0.035"]))
    attrs = result.attrs
    assert attrs["fidelity_spring_model"] == "chain"
    assert attrs["fidelity_spring_segments"] >= 2
    assert attrs["fidelity_spring_predicted_massless_error"] > 0.01
    assert "chain of" in attrs["fidelity_spring_reason"]
    assert 'spring_model = "chain"' in result.scene_toml
    assert f"spring_segments = {attrs['fidelity_spring_segments']}" in result.scene_toml
    assert "energy/spring_potential" in result.datasets


# --- refusals and unused keys ---------------------------------------------------------------

def test_auto_spring_with_a_constant_speed_drive_is_refused():
    with pytest.raises(SceneError, match='drive.spring_model = "auto" needs drive.kind = '
                                         '"spring"'):
        load_scene(overrides=['drive.spring_model="auto"', 'drive.kind="constant_speed"'])


def test_an_unresolved_auto_spring_is_not_built_as_massless():
    # below flex.fidelity.auto.resolve every scene is concrete: integrate refuses "auto"
    with pytest.raises(ValueError, match="resolve"):
        integrate(load_scene(overrides=['drive.spring_model="auto"', *QUICK,
                                        *pinned_overrides()]))


def test_more_segments_than_a_chain_may_have_are_refused():
    with pytest.raises(SceneError, match="more than the 256"):
        chain_segments(0.15, 1e-7)


def test_auto_spring_reads_the_tolerance_and_chooses_the_segments():
    keys = unused_keys(load_scene(overrides=['drive.spring_model="auto"']))
    assert "drive.spring_segments" in keys and "auto" in keys["drive.spring_segments"]
    assert "drive.spring_mass_kg" not in keys and "fidelity.tolerance" not in keys
