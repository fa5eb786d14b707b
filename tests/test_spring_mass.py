"""The drive spring with its mass (``drive.spring_model = "chain"``): the chain against the
continuous coil's closed form, the Exudyn build against an independent eigenproblem, the
preload force at t = 0, energy, and the refusal of bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from flex.base.errors import SceneError
from flex.bodies.spring import CONSISTENT_THESIS_SPRING
from flex.config.usage import unused_keys
from flex.data.scene import load_scene
from flex.dynamics.planar import PlanarBuilder
from flex.dynamics.solver import integrate
from flex.experiments.models.spring_mass import (
    chain_convergence,
    chain_matrices,
    continuous_first_omega_rad_per_s,
    deployment_cases,
    wing_spring_mass_kg,
)
from flex.fidelity.auto import resolve

QUIET = ["simulation.error_estimate=false"]


def chain(segments: int, *extra: str) -> list[str]:
    return ['drive.spring_model="chain"', f"drive.spring_segments={segments}", *QUIET, *extra]


def run(overrides: list[str]) -> dict[str, np.ndarray]:
    case = integrate(resolve(load_scene(None, overrides), quiet=True).scene, "case")
    return {k: np.asarray(v.data) for k, v in case.datasets.items()}


@pytest.mark.parametrize("end_mass_kg", [1e-3, 0.0264, 0.5])
def test_chain_converges_to_the_continuous_coil_at_second_order(end_mass_kg):
    """beta tan beta = m_s / M: the lumped chain's first frequency converges as N^-2."""
    design = CONSISTENT_THESIS_SPRING
    rows = chain_convergence(design.active_mass_kg, design.rate_N_per_m, end_mass_kg,
                             (4, 8, 16, 32))
    assert rows[-1].relative_error < 2e-4
    for row in rows[1:]:
        assert row.observed_order == pytest.approx(2.0, abs=0.05)


def test_continuous_coil_limits():
    """Heavy end mass: sqrt(k / (M + m_s / 3)) (Rayleigh); light: the fixed-free surge."""
    k, m_s = 1500.0, 0.1
    heavy = continuous_first_omega_rad_per_s(m_s, k, 100.0)
    assert heavy == pytest.approx(math.sqrt(k / (100.0 + m_s / 3)), rel=1e-7)
    light = continuous_first_omega_rad_per_s(m_s, k, 1e-9)
    assert light == pytest.approx(0.5 * math.pi * math.sqrt(k / m_s), rel=1e-6)


def test_exudyn_chain_matches_the_independent_eigenproblem():
    """The builder's slider and chain alone (ComputeODE2Eigenvalues) against numpy's
    chain matrices: every frequency."""
    scene = load_scene(None, chain(6))
    builder = PlanarBuilder(scene)
    builder.slider_body = builder.add_slider()
    builder.add_drive()
    builder.mbs.Assemble()
    values, _ = builder.mbs.ComputeODE2Eigenvalues(useAbsoluteValues=True)
    exudyn_omega = np.sqrt(np.sort(np.abs(np.asarray(values))))
    from scipy.linalg import eigh

    mass, stiffness = chain_matrices(scene["drive"]["spring_mass_kg"],
                                     scene["drive"]["spring_stiffness_N_per_m"],
                                     scene["slider"]["mass_kg"], 6)
    np.testing.assert_allclose(exudyn_omega, np.sqrt(eigh(stiffness, mass, eigvals_only=True)),
                               rtol=1e-6)


def test_preload_force_at_release_is_the_massless_springs():
    """At t = 0 the chain is at rest in equilibrium: the slider feels k x preload, so the
    mechanism accelerates as the massless model with the slider carrying the end share."""
    segments, mass_kg = 8, 0.1057
    with_chain = run(chain(segments, f"drive.spring_mass_kg={mass_kg}",
                           "simulation.end_time_s=1e-4"))
    share = load_scene()["slider"]["mass_kg"] + mass_kg / (2 * segments)
    massless = run([*QUIET, f"slider.mass_kg={share}", "simulation.end_time_s=1e-4"])
    for key in ("crank/angular_acceleration", "joints/C/force_modulus"):
        assert with_chain[key][0] == pytest.approx(massless[key][0], rel=1e-6)
    scene = load_scene()
    force_N = scene["drive"]["spring_stiffness_N_per_m"] * scene["drive"]["spring_preload_m"]
    assert with_chain["energy/spring_potential"][0] == pytest.approx(
        force_N**2 / (2 * scene["drive"]["spring_stiffness_N_per_m"]), rel=1e-12)


def test_one_segment_is_half_the_coil_on_the_slider():
    """N = 1: no inner mass, m_s / 2 on the slider: the massless model with that slider."""
    with_chain = run(chain(1, "drive.spring_mass_kg=0.1", "simulation.end_time_s=0.01"))
    heavier = run([*QUIET, f"slider.mass_kg={load_scene()['slider']['mass_kg'] + 0.05}",
                   "simulation.end_time_s=0.01"])
    np.testing.assert_allclose(with_chain["crank/angle"], heavier["crank/angle"], atol=1e-9)


@pytest.mark.parametrize("planar", [True, False])
def test_chain_conserves_energy_in_both_builds(planar):
    """Undamped: kinetic (links and chain masses) + chain strain energy stays constant."""
    extra = [] if planar else ['simulation.integrator="explicit_penalty"',
                               "simulation.step_s=1e-6", "simulation.end_time_s=0.005"]
    data = run(chain(4, *(extra or ["simulation.end_time_s=0.02"])))
    total = data["energy/total"]
    assert np.ptp(total) < 1e-3 * total[0]
    assert data["energy/kinetic"].max() > 0.1 * total[0]


def test_three_dimensional_build_matches_planar():
    """The 3D build (rigid bodies, exact joints) gives the planar build's chain run."""
    from flex.dynamics.collect import collect
    from flex.dynamics.mechanism import build_mechanism
    from flex.dynamics.solver import run as solve

    scene = resolve(load_scene(None, chain(3, "simulation.end_time_s=0.01",
                                           "simulation.step_s=1e-5")), quiet=True).scene
    curves = []
    for planar in (True, False):
        mech = build_mechanism(scene, planar=planar)
        solve(mech)
        curves.append(collect(mech)["crank/angle"].data)
    np.testing.assert_allclose(curves[0], curves[1], atol=1e-8)


def test_bad_spring_keys_are_refused_in_one_line():
    for override, key in (("drive.spring_segments=0", "drive.spring_segments"),
                          ("drive.spring_segments=2.5", "drive.spring_segments"),
                          ("drive.spring_mass_kg=0", "drive.spring_mass_kg"),
                          ('drive.spring_model="springy"', "drive.spring_model")):
        with pytest.raises(SceneError) as error:
            load_scene(None, [override])
        assert key in str(error.value) and "\n" not in str(error.value)


def test_massless_spring_leaves_chain_keys_unused():
    assert "drive.spring_segments" in unused_keys(load_scene())
    assert "drive.spring_segments" not in unused_keys(load_scene(None, chain(2)))


def test_wing_spring_mass_resizes_the_thesis_design():
    """Same rate -> the thesis spring's mass; mass goes as D ~ k^(-1/3)."""
    design = CONSISTENT_THESIS_SPRING
    assert wing_spring_mass_kg(design.rate_N_per_m) == pytest.approx(design.active_mass_kg)
    assert wing_spring_mass_kg(8 * design.rate_N_per_m) == pytest.approx(
        design.active_mass_kg / 2)


def test_deployment_cases_cover_every_model():
    cases = deployment_cases({"thesis": load_scene()}, (1, 4))
    assert set(cases) == {f"thesis_{links}_{model}" for links in ("rigid", "ffrf")
                          for model in ("massless", "chain_1", "chain_4")}
    assert cases["thesis_ffrf_chain_4"]["drive"]["spring_segments"] == 4


def test_stop_index_skips_a_start_up_ripple():
    """A ripple maximum before half the rise is not the deployment's end."""
    from flex.experiments.models.spring_mass import stop_index

    time_s = np.linspace(0.0, 1.0, 1001)
    angle = np.sin(np.pi * time_s / 0.8)
    angle[:20] += 1e-2 * np.sin(np.pi * time_s[:20] / 0.004)  # maxima during the ripple
    from flex.data.headlines import first_maximum_index

    # the ripple's tops, which the rise later passes by far more than they rose, are not a
    # first maximum either (since issue 48: a crank held by its damper's wiggle)
    assert time_s[first_maximum_index(angle)] == pytest.approx(0.4, abs=1e-3)
    assert time_s[stop_index(angle)] == pytest.approx(0.4, abs=1e-3)


def test_governing_error_of_a_scaled_run():
    """A run whose angle and slider deviate by 1 % of their rise has error 0.01."""
    from flex.experiments.models.spring_mass import governing_error

    time_s = np.linspace(0.0, 1.0, 101)
    full = {"time": time_s, "crank/angle": np.sin(np.pi * time_s),
            "slider/position": 2.0 - np.sin(np.pi * time_s)}
    run = dict(full, **{"crank/angle": 1.01 * full["crank/angle"]})
    assert governing_error(run, full) == pytest.approx(0.01, rel=1e-9)
    assert governing_error(full, full) == 0.0
