"""The flexible (FFRF) crank: against its rigid twin, energy, its frequency, bad input."""

import numpy as np
import pytest

from flex.base.errors import SceneError
from flex.base.physics import pinned_pinned_omega
from flex.data.scene import load_scene
from flex.fidelity.auto import crank_elastic_omega, decide_links
from flex.fidelity.simulation import simulate

PLATE = ['crank.geometry="plate"', "simulation.step_s=2e-5", "simulation.end_time_s=0.01"]


@pytest.fixture(scope="module")
def stiff_pair(reduction_cache):
    rigid = simulate(load_scene(None, PLATE))
    flexible = simulate(load_scene(None, [*PLATE, 'crank.model="ffrf"']),
                        cache_dir=reduction_cache)
    return ({k: v.data for k, v in rigid.datasets.items()},
            {k: v.data for k, v in flexible.datasets.items()})


def test_stiff_ffrf_crank_follows_its_rigid_twin(stiff_pair):
    # the 4.56 mm crank's first elastic mode is ~6.5 kHz: n ~ 170 over the deployment, so
    # the elastic crank must move as the rigid one (measured 7.9e-7 rad over 10 ms)
    rigid, flexible = stiff_pair
    assert np.max(np.abs(flexible["crank/angle"] - rigid["crank/angle"])) < 1e-5
    assert np.max(np.abs(flexible["slider/position"] - rigid["slider/position"])) < 1e-7
    deflection = np.max(np.abs(flexible["crank/midpoint_deflection"]))
    assert 0 < deflection < 1e-6  # elastic, and tiny (m)
    assert flexible["crank/modal_coordinates"].shape[1] == 3 + 6  # in-plane static + modes


def test_ffrf_crank_conserves_energy(stiff_pair):
    # undamped, spring drive: kinetic + strain + spring energy is an invariant
    _, flexible = stiff_pair
    total = flexible["energy/total"]
    assert np.ptp(total) / total[0] < 1e-5
    assert flexible["energy/strain"].max() > 0


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_ffrf_coupler_reports_energy(reduction_cache):
    scene = load_scene(None, ['coupler.geometry="plate"', 'coupler.model="ffrf"',
                              "simulation.step_s=2e-5", "simulation.end_time_s=0.01"])
    data = {k: v.data for k, v in simulate(scene, cache_dir=reduction_cache).datasets.items()}
    assert np.ptp(data["energy/total"]) / data["energy/total"][0] < 1e-5
    assert data["energy/strain"].max() > 0


def test_crank_frequency_without_wing_is_pinned_pinned(reduction_cache):
    # B is held by the coupler and slider: the crank's in-mechanism mode is the plate's
    # pinned-pinned bending (Euler-Bernoulli closed form; L/t = 40, shear negligible)
    scene = load_scene(None, ['crank.geometry="plate"', "crank.thickness_m=0.001"])
    crank = scene["crank"]
    expected = pinned_pinned_omega(crank["length_m"], crank["thickness_m"],
                                   crank["youngs_modulus_Pa"], crank["density_kg_per_m3"])
    assert crank_elastic_omega(scene, cache_dir=reduction_cache) == pytest.approx(expected,
                                                                                 rel=0.03)


def test_crank_frequency_with_wing_is_far_lower(reduction_cache):
    # the welded wing holds the root: a cantilever carrying coupler and slider at B
    scene = load_scene(None, ['crank.geometry="plate"', "crank.thickness_m=0.001",
                              "wing.enabled=true"])
    crank = scene["crank"]
    pinned = pinned_pinned_omega(crank["length_m"], crank["thickness_m"],
                                 crank["youngs_modulus_Pa"], crank["density_kg_per_m3"])
    assert crank_elastic_omega(scene, cache_dir=reduction_cache) < 0.1 * pinned


@pytest.mark.parametrize("overrides, message", [
    (['crank.model="ffrf"'], 'crank.geometry = "plate"'),
    (['crank.geometry="plate"', 'crank.model="ffrf"', 'drive.kind="constant_speed"'],
     'drive.kind = "spring"'),
    (['crank.geometry="plate"', "crank.thickness_m=0.05"], "must be smaller"),
    (['crank.geometry="plate"', 'crank.model="ffrf"', 'simulation.integrator="explicit_penalty"'],
     "explicit_penalty"),
])
def test_bad_crank_scenes_are_refused(overrides, message):
    with pytest.raises(SceneError, match=message.replace("(", r"\(").replace('"', '"')):
        load_scene(None, overrides)


def test_auto_picks_ffrf_for_a_soft_crank_and_rigid_for_a_stiff_one(reduction_cache):
    soft = load_scene(None, ['crank.geometry="plate"', "crank.thickness_m=0.001",
                             "wing.enabled=true", 'crank.model="auto"', "simulation.step_s=1e-4"])
    resolved, decisions = decide_links(soft, cache_dir=reduction_cache)
    assert resolved["crank"]["model"] == "ffrf" and resolved["crank"]["modes"] >= 2
    assert "crank_criteria_fit.toml" in decisions[0].reason  # the crank's own law
    stiff = load_scene(None, ['crank.model="auto"', "simulation.step_s=1e-4"])
    resolved, decisions = decide_links(stiff, cache_dir=reduction_cache)
    assert resolved["crank"]["model"] == "rigid"
    assert decisions[0].n_physical > decisions[0].k_physical


def test_auto_refuses_a_flexible_lumped_crank(reduction_cache):
    # a lumped crank has no mesh: if the criterion calls it flexible, auto says what to set
    scene = load_scene(None, ["crank.mass_kg=0.00314", "crank.inertia_kgm2=4.2e-7",
                              "wing.enabled=true", 'crank.model="auto"',
                              "simulation.step_s=1e-4"])
    with pytest.raises(SceneError, match='crank.geometry = "plate"'):
        decide_links(scene, cache_dir=reduction_cache)


def test_crank_law_beats_the_coupler_law_where_the_coupler_law_failed(reduction_cache):
    # measured: with the coupler's law, auto kept a 1.5 mm crank carrying the wing rigid
    # at 1 % tolerance and erred by 1.8 %; the crank's own law must make it flexible
    scene = load_scene(None, ['crank.geometry="plate"', "crank.thickness_m=0.0015",
                              "wing.enabled=true", 'crank.model="auto"',
                              "simulation.step_s=1e-4"])
    resolved, _ = decide_links(scene, cache_dir=reduction_cache)
    assert resolved["crank"]["model"] == "ffrf"


@pytest.mark.slow
def test_crank_study_fits_a_law_and_auto_holds_on_every_validation_scene(reduction_cache):
    from flex.study import execute, load_study, study_scene

    module = load_study("crank")
    output = execute(module, study_scene(module), cache_dir=reduction_cache)
    data = output.summary.datasets
    assert data["fit/r_squared"].data > 0.95
    assert data["fit/exponent"].data == pytest.approx(2.0, abs=0.3)  # as the coupler's ~1.9
    for name in module.SCENES:
        assert bool(data[f"validation/{name}/within_tolerance"].data), name
