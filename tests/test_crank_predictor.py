"""The crank's rigid-model deflection predictor (flex.fidelity.predictor, link "crank") and
the closed forms it rests on: each against an independent computation (a Ritz sine series
from the beam's potential energy), the pivot moment against Exudyn's weld, the prediction
against FFRF cranks, and what ``auto`` stores and decides with it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from flex.base.physics import (
    Plate,
    pinned_beam_end_moment_midpoint_deflection_m,
    pinned_beam_midpoint_deflection_m,
)
from flex.data.scene import apply_overrides, default_scene
from flex.fidelity.predictor import _crank_history, predict_deflection

L, T, W, E, RHO = 0.04, 0.001, 0.01, 200e9, 7850.0
EI = E * W * T**3 / 12
#: the crank study's settings (studies/crank.py) and its full model, an FFRF crank of 12 modes
STUDY = ['crank.geometry="plate"', "simulation.error_estimate=false", "simulation.step_s=2e-5",
         "simulation.end_time_s=0.05"]
FULL = ['crank.model="ffrf"', "crank.modes=12"]


def _ritz_deflection(x_m: np.ndarray, load_N_per_m, moment_at_0_N_m: float = 0.0,
                     terms: int = 1000) -> np.ndarray:
    """Deflection of a pinned-pinned beam (along +x, deflection along +y) under a load
    ``q(x)`` along +y and a counter-clockwise moment at x = 0, by minimising its potential
    energy over w = sum a_n sin(n pi x / L): a_n = (int q sin + M n pi / L) / (EI (n pi /
    L)^4 L / 2), the moment working on the end rotation w'(0). Independent of any closed
    form and of any sign convention for bending moments."""
    grid = np.linspace(0.0, L, 4001)
    n = np.arange(1, terms + 1)[:, None]
    wave = n * np.pi / L
    generalized = np.trapezoid(load_N_per_m(grid) * np.sin(wave * grid), grid, axis=1)
    amplitude = (generalized + moment_at_0_N_m * wave[:, 0]) / (EI * wave[:, 0] ** 4 * L / 2)
    return np.sin(wave * np.asarray(x_m)[None, :]).T @ amplitude


def test_end_moment_midpoint_deflection_against_ritz():
    moment = 0.37  # N m, counter-clockwise at the first end: the beam arches towards +y
    expected = _ritz_deflection(np.array([L / 2]), lambda x: 0.0 * x, moment)[0]
    assert expected > 0
    assert pinned_beam_end_moment_midpoint_deflection_m(moment, L, T, W, E) == pytest.approx(
        expected, rel=1e-6)


def test_a_triangular_load_bends_the_midpoint_as_its_total_and_peaks_near_it():
    # the crank's own d'Alembert load, zero at the pivot and q_end at B: the midpoint closed
    # form of any linear load (its mean) holds, and the peak over the length (at 0.519 L)
    # is only 0.18 % above it, so the midpoint measure (crank/midpoint_deflection) is the peak
    q_end = -250.0  # N/m
    x = np.linspace(0.0, L, 2001)
    ritz = _ritz_deflection(x, lambda s: q_end * s / L)
    assert pinned_beam_midpoint_deflection_m(q_end * L / 2, L, T, W, E) == pytest.approx(
        ritz[1000], rel=1e-6)
    assert np.max(np.abs(ritz)) / abs(ritz[1000]) == pytest.approx(1.0018, abs=1e-4)


def _synthetic_crank(alpha_rad_per_s2: float, force_b_transverse_N: float, angle_rad: float,
                     samples: int = 50) -> dict[str, np.ndarray]:
    """A rigid crank's series with constant acceleration from rest (rate 0: no centrifugal
    load) and a transverse force at B, as the result layout holds them."""
    normal = np.array([-math.sin(angle_rad), math.cos(angle_rad)])
    return {"time": np.linspace(0.0, 1e-3, samples),
            "crank/angle": np.full(samples, angle_rad),
            "crank/angular_velocity": np.zeros(samples),
            "crank/angular_acceleration": np.full(samples, alpha_rad_per_s2),
            "joints/B/force_on_crank": np.tile(force_b_transverse_N * normal, (samples, 1))}


@pytest.mark.parametrize("force_b", [0.0, 1.0 / 3.0, 2.5])  # x mu alpha L^2: wing-free at 1/3
def test_the_crank_s_quasi_static_deflection_against_ritz(force_b):
    """The predictor's crank: its d'Alembert load -mu alpha x, and at the pivot the moment
    that balances it against B's transverse force, against the Ritz beam under both."""
    plate = {"length_m": L, "thickness_m": T, "width_m": W, "youngs_modulus_Pa": E,
             "density_kg_per_m3": RHO}
    per_length, alpha = RHO * T * W, 3.0e4
    force = force_b * per_length * alpha * L**2
    pivot_moment = per_length * alpha * L**3 / 3 - force * L  # moments about A vanish
    expected = _ritz_deflection(np.array([L / 2]), lambda x: -per_length * alpha * x,
                                pivot_moment)[0]
    deflection, compression = _crank_history(_synthetic_crank(alpha, force, 0.7),
                                             Plate.of(plate))
    np.testing.assert_allclose(deflection, expected, rtol=1e-6)
    np.testing.assert_allclose(compression, 0.0, atol=1e-12)
    prediction = predict_deflection(_synthetic_crank(alpha, force, 0.7), plate, "crank")
    assert prediction.quasi_static_peak_m == pytest.approx(abs(expected), rel=1e-6)


def test_the_pivot_moment_from_statics_is_the_wing_s_weld_moment():
    """With the wing welded at A, the moment the crank's statics put at A is the wing's
    inertia moment Exudyn's weld carries (joints/W/root_moment), to the plate's rotary
    inertia (t^2 / 4 L^2)."""
    from flex.fidelity.simulation import simulate

    scene = apply_overrides(default_scene(), [*STUDY, "crank.thickness_m=0.002",
                                              "wing.enabled=true",
                                              "simulation.end_time_s=0.01"])
    series = {k: v.data for k, v in simulate(scene).datasets.items()}
    deflection, _ = _crank_history(series, Plate.of(scene["crank"]))
    crank = scene["crank"]
    sizes = (crank["length_m"], crank["thickness_m"], crank["width_m"],
             crank["youngs_modulus_Pa"])
    per_length = crank["density_kg_per_m3"] * crank["thickness_m"] * crank["width_m"]
    by_weld = (pinned_beam_midpoint_deflection_m(
        -per_length * series["crank/angular_acceleration"] * crank["length_m"] ** 2 / 2, *sizes)
        + pinned_beam_end_moment_midpoint_deflection_m(series["joints/W/root_moment"], *sizes))
    np.testing.assert_allclose(deflection, by_weld, rtol=0, atol=2e-3 * np.abs(by_weld).max())


def _strict_criterion():
    """An n-law that calls every crank flexible (e = 1e9 n^-2)."""
    from flex.fidelity.laws import (
        Criterion,
        fit_error_law,
    )

    n = np.geomspace(1.0, 100.0, 20)
    return Criterion({(0.0, "governing"): fit_error_law(n, 1e9 * n**-2.0)})


def test_without_a_wing_the_loads_decide_the_crank_with_one_the_n_law(reduction_cache):
    from flex.fidelity.auto import decide_links

    strict = _strict_criterion()
    bare = apply_overrides(default_scene(), ['crank.model="auto"', "simulation.step_s=1e-4"])
    resolved, (decision,) = decide_links(bare, strict, strict, cache_dir=reduction_cache)
    assert resolved["crank"]["model"] == "rigid"  # the thesis crank: ~1e-5 predicted
    assert "n-law baseline (would pick ffrf)" in decision.reason
    assert 0 < decision.predicted_rigid_error < 1e-4
    winged = apply_overrides(bare, ['crank.geometry="plate"', "wing.enabled=true"])
    resolved, (decision,) = decide_links(winged, strict, strict, cache_dir=reduction_cache)
    assert resolved["crank"]["model"] == "ffrf"  # the n-law's verdict stands
    assert "stored, not deciding" in decision.reason
    assert decision.predicted_rigid_error < 0.01  # what the loads alone would have allowed


def _ffrf_deflection_error(scene, reduction_cache) -> dict[str, float]:
    """The crank study's errors of the rigid crank against the full FFRF crank."""
    from flex.fidelity.laws import (
        errors_against_full,
    )
    from flex.fidelity.simulation import simulate

    rigid, full = (simulate(apply_overrides(scene, changes), cache_dir=reduction_cache)
                   for changes in (['crank.model="rigid"'], FULL))
    return errors_against_full({k: v.data for k, v in rigid.datasets.items()},
                               {k: v.data for k, v in full.datasets.items()}, "crank",
                               scene["crank"]["length_m"])


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_auto_stores_the_crank_s_prediction_and_it_meets_the_ffrf_crank(reduction_cache):
    """A 1 mm steel crank, thesis spring, no wing: auto stores the rigid model's deflection
    error predicted from its probe's loads (fidelity_crank_predicted_rigid_error), and it is
    within [0.8, 1.25] of the FFRF crank's (measured 1.01, nothing fitted)."""
    from flex.fidelity.simulation import simulate

    scene = apply_overrides(default_scene(), [*STUDY, "crank.thickness_m=0.001"])
    auto = simulate(apply_overrides(scene, ['crank.model="auto"']), cache_dir=reduction_cache)
    predicted = auto.attrs["fidelity_crank_predicted_rigid_error"]
    assert math.isfinite(predicted) and predicted > 0
    assert auto.attrs["fidelity_crank_model"] == "rigid"
    measured = _ffrf_deflection_error(scene, reduction_cache)
    assert 0.8 <= predicted / measured["deflection"] <= 1.25


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_with_the_wing_the_prediction_meets_the_deflection_not_the_governing_error(
        reduction_cache):
    """A 2 mm crank carrying the wing: the prediction (the crank's in-mechanism mode) is
    within [0.8, 1.25] of the FFRF crank's deflection error (measured 1.05), but the
    crank-angle error governs, about 3 x larger (measured prediction / governing 0.34):
    why ``auto`` does not decide a winged crank by it."""
    from flex.fidelity.auto import crank_elastic_omega
    from flex.fidelity.probe import deployment_probe

    scene = apply_overrides(default_scene(), [*STUDY, "crank.thickness_m=0.002",
                                              "wing.enabled=true"])
    delta_t_s, _, probe = deployment_probe(scene)
    omega = crank_elastic_omega(scene, cache_dir=reduction_cache)
    predicted = predict_deflection(probe, scene["crank"], "crank", delta_t_s,
                                   omega).relative_error(scene["crank"]["length_m"])
    measured = _ffrf_deflection_error(scene, reduction_cache)
    assert 0.8 <= predicted / measured["deflection"] <= 1.25
    assert 0.25 <= predicted / measured["governing"] <= 0.5


#: the other scenes measured (docs/criterion.md): name -> overrides of the crank study's scene
MEASURED = {
    "t0p8mm": ["crank.thickness_m=0.0008"],
    "t1mm_k500": ["crank.thickness_m=0.001", "drive.spring_stiffness_N_per_m=500.0"],
    "t1mm_k6000": ["crank.thickness_m=0.001", "drive.spring_stiffness_N_per_m=6000.0"],
    "t1mm_k20000": ["crank.thickness_m=0.001", "drive.spring_stiffness_N_per_m=20000.0"],
    "t1mm_damping2pct": ["crank.thickness_m=0.001", "crank.damping_ratio=0.02"],
    "t1mm_aluminium": ["crank.thickness_m=0.001", "crank.youngs_modulus_Pa=71.7e9",
                       "crank.density_kg_per_m3=2810.0"],
    "t1p5mm_preload11mm": ["crank.thickness_m=0.0015", "drive.spring_preload_m=0.011"],
    "t2mm": ["crank.thickness_m=0.002"],
    "t3mm_k6000": ["crank.thickness_m=0.003", "drive.spring_stiffness_N_per_m=6000.0"],
    "t4p56mm": [],
    "wing_t1mm": ["crank.thickness_m=0.001", "wing.enabled=true"],
    "wing_t3p5mm_k6000": ["crank.thickness_m=0.0035", "wing.enabled=true",
                          "drive.spring_stiffness_N_per_m=6000.0"],
    "wing_t4p56mm": ["wing.enabled=true"],
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(MEASURED))
def test_the_prediction_meets_ffrf_cranks(name, reduction_cache):
    """The measurement behind docs/criterion.md (with the two tests above: 15 scenes):
    predicted / FFRF deflection error within [0.8, 1.3] (measured 0.89-1.23, the highest at
    20000 N/m, P / P_E = 0.11); without the wing the deflection is the governing error
    (measured: the crank-angle and slider errors below 8 % of it), with the wing
    prediction / governing error within [0.25, 0.5] (measured 0.33-0.35)."""
    from flex.fidelity.auto import crank_elastic_omega
    from flex.fidelity.probe import deployment_probe

    scene = apply_overrides(default_scene(), [*STUDY, *MEASURED[name]])
    delta_t_s, _, probe = deployment_probe(scene)
    omega = crank_elastic_omega(scene, cache_dir=reduction_cache)
    prediction = predict_deflection(probe, scene["crank"], "crank", delta_t_s, omega)
    predicted = prediction.relative_error(scene["crank"]["length_m"])
    measured = _ffrf_deflection_error(scene, reduction_cache)
    print(f"{name}: predicted {predicted:.3g}, FFRF deflection {measured['deflection']:.3g} "
          f"(ratio {predicted / measured['deflection']:.3f}), governing "
          f"{measured['governing']:.3g}, P/P_E {prediction.euler_load_ratio:.3g}")
    assert 0.8 <= predicted / measured["deflection"] <= 1.3
    if scene["wing"]["enabled"]:
        assert 0.25 <= predicted / measured["governing"] <= 0.5
    else:
        assert measured["governing"] == measured["deflection"]
