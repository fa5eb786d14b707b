"""Wing application (sec. 6.4): the welded wing against the independent DAE, and formulas."""

import numpy as np
import pytest

from flex.base.thesis import THESIS_WING_PEAK_RATE_DEG_PER_S, THESIS_WING_PEAK_TIME_S
from flex.data.scene import load_scene
from flex.dynamics.reference import crank_mass_properties, solve_reference
from flex.experiments.thesis import wing
from flex.fidelity.simulation import simulate
from studies.wing import OVERRIDES


def test_wing_scene_matches_the_reference_dae():
    # rigid limit: crank + welded wing is one rigid body; the reference DAE models it as
    # such (combined mass, centre and inertia), sharing no code with the Exudyn weld
    scene = load_scene(overrides=["wing.enabled=true", "drive.spring_stiffness_N_per_m=9000",
                                  "simulation.end_time_s=0.02"])
    data = {k: v.data for k, v in simulate(scene).datasets.items()}
    reference = solve_reference(scene, data["time"])
    assert np.abs(data["crank/angle"] - reference.q[:, 2]).max() < 1e-6
    assert np.abs(data["wing/angular_velocity"] - reference.q_dot[:, 2]).max() < 1e-3
    assert np.ptp(data["energy/total"]) / data["energy/total"][0] < 1e-6


def test_vanishing_wing_recovers_the_plain_mechanism():
    plain = simulate(load_scene()).datasets["crank/angle"].data
    tiny = load_scene(overrides=["wing.enabled=true", "wing.thickness_m=1e-12",  # no density
                                  "wing.density_kg_per_m3=1.0"])
    # below a solid's is accepted (flex.data.scene._DENSITY): a wing of no thickness instead
    assert np.abs(simulate(tiny).datasets["crank/angle"].data - plain).max() < 1e-8


def test_combined_crank_properties_parallel_axis():
    scene = load_scene(overrides=["wing.enabled=true", "wing.span_m=0.1", "wing.chord_m=0.02",
                                  "wing.thickness_m=0.002", "wing.density_kg_per_m3=2500"])
    mass_kg, inertia_kgm2, centre_m = crank_mass_properties(scene)
    wing_kg = 2500 * 0.1 * 0.02 * 0.002
    assert mass_kg == pytest.approx(0.01432 + wing_kg)
    # inertia about A is additive: I_A = I_c + m_c (L1/2)^2 + m_w (s^2 + c^2)/12 + m_w (s/2)^2
    about_a = 2.7e-6 + 0.01432 * 0.02**2 + wing_kg * (0.1**2 + 0.02**2) / 12 + wing_kg * 0.05**2
    assert inertia_kgm2 + mass_kg * centre_m**2 == pytest.approx(about_a, rel=1e-12)


def test_cantilever_formulas():
    scene = load_scene(overrides=["wing.enabled=true"])
    result = wing.wing_flexibility(scene, peak_angular_acceleration_rad_per_s2=1e4,
                                   deployment_time_s=0.016)
    w = scene["wing"]
    # Roark: cantilever, load rising linearly to q0 at the free end: 11 q0 L^4 / (120 E I)
    q0 = w["density_kg_per_m3"] * w["chord_m"] * w["thickness_m"] * 1e4 * w["span_m"]
    inertia_m4 = w["thickness_m"] * w["chord_m"] ** 3 / 12
    expected = 11 * q0 * w["span_m"] ** 4 / (120 * w["youngs_modulus_Pa"] * inertia_m4)
    assert result["quasi_static_tip_deflection_m"] == pytest.approx(expected, rel=1e-12)
    # out of plane, slender: Euler-Bernoulli cantilever (1.8751^2 / 2 pi) sqrt(EI / (rho A L^4))
    eb = 1.87510407**2 / (2 * np.pi) * np.sqrt(
        w["youngs_modulus_Pa"] * w["chord_m"] * w["thickness_m"] ** 3 / 12
        / (w["density_kg_per_m3"] * w["chord_m"] * w["thickness_m"] * w["span_m"] ** 4))
    assert result["out_of_plane_frequency_Hz"] == pytest.approx(eb, rel=2e-3)


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_spring_fit_reaches_the_thesis_outcome():
    scene = load_scene(overrides=OVERRIDES)
    fitted, values = wing.fit_spring(scene)
    rate, time_s = wing.peak_rate(fitted)
    assert rate == pytest.approx(THESIS_WING_PEAK_RATE_DEG_PER_S, rel=2e-3)
    assert time_s == pytest.approx(THESIS_WING_PEAK_TIME_S, abs=2e-4)
