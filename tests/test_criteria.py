"""Rigid-or-flexible criterion: n conventions, error measures, fitted laws with a known
answer, k for a tolerance, the stored criterion, and the auto decision."""

import math

import numpy as np
import pytest

from flex.base import physics
from flex.base.errors import FlexError, SceneError
from flex.base.physics import Plate, n_values, pinned_pinned_omega
from flex.data.scene import load_scene
from flex.fidelity import auto, criteria, laws
from flex.fidelity.auto import decide_links
from flex.fidelity.laws import (
    Criterion,
    ErrorLaw,
    fit_error_law,
    load_criterion,
)


# ------------------------------------------------------------------------------------------
# frequencies and n
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("thickness_m, thesis_frequency, thesis_n",
                         [(0.001, 2247.04282, 36), (0.003, 6741.12847, 108),
                          (0.005, 11235.2141, 181), (0.010, 22470.4282, 362)])
def test_table5_frequency_is_euler_bernoulli_pinned_pinned_in_rad_per_s(
        thickness_m, thesis_frequency, thesis_n):
    omega = pinned_pinned_omega(0.08, thickness_m, 200e9, 7850.0)
    assert omega == pytest.approx(thesis_frequency, rel=1e-5)  # (thesis: pi ~ 3.1416)
    n = n_values(criteria.THESIS_DELTA_T_S, omega)
    assert n["thesis"] == pytest.approx(thesis_n, abs=1.0)  # the thesis's T = 1/omega
    assert n["physical"] == pytest.approx(n["thesis"] / (2 * math.pi))


def test_convert_n_round_trip_and_refuses_unknown_convention():
    assert criteria.convert_n(2.0, "physical", "thesis") == pytest.approx(4 * math.pi)
    assert criteria.convert_n(4 * math.pi, "thesis", "physical") == pytest.approx(2.0)
    with pytest.raises(ValueError, match="convention"):
        criteria.convert_n(1.0, "physical", "angular")


def test_deployment_times_of_a_sine_swing():
    # crank angle 0.5 + (1 - cos(w t)) / 2: stop at pi/w, half swing at pi/(2w), speed peak
    # at pi/(2w)
    w = 100.0
    time_s = np.linspace(0, 0.05, 5001)
    angle = 0.5 + 0.5 * (1 - np.cos(w * time_s))
    speed = 0.5 * w * np.sin(w * time_s)
    times = criteria.deployment_times(time_s, angle, speed)
    assert times["stop"] == pytest.approx(math.pi / w, abs=2e-5)
    assert times["half_swing"] == pytest.approx(math.pi / (2 * w), abs=1e-6)
    assert times["peak_speed"] == pytest.approx(math.pi / (2 * w), abs=2e-5)
    assert times["thesis"] == criteria.THESIS_DELTA_T_S
    with pytest.raises(ValueError, match="no maximum"):
        criteria.deployment_times(time_s[:100], angle[:100], speed[:100])


# ------------------------------------------------------------------------------------------
# error measures
# ------------------------------------------------------------------------------------------
def test_quasi_static_stress_of_a_uniform_load_is_the_simply_supported_beam():
    # rigid translation across the link: uniform inertial load W = 2F, joints carry F each;
    # maximum moment W L / 8 at mid-span, no axial force
    length, thickness, width, force = 0.08, 0.002, 0.01, 3.0
    angle = np.array([0.3])
    normal = np.array([[-math.sin(0.3), math.cos(0.3)]])
    stress = criteria.quasi_static_stress(force * normal, force * normal, angle, length,
                                          thickness, width, x_range_m=(0.0, length),
                                          points=201)
    moment = 2 * force * length / 8
    assert stress[0] == pytest.approx(6 * moment / (width * thickness**2), rel=1e-9)


def test_quasi_static_stress_axial_force_only():
    axis = np.array([[1.0, 0.0]])
    stress = criteria.quasi_static_stress(-5.0 * axis, 5.0 * axis, np.array([0.0]), 0.08,
                                          0.002, 0.01)
    assert stress[0] == pytest.approx(5.0 / (0.002 * 0.01))  # tension 5 N everywhere


def _pair(n_samples: int = 400):
    time_s = np.linspace(0.0, 0.02, n_samples)
    angle = 0.6 + 0.5 * (1 - np.cos(157.0 * time_s))
    slider = 0.11 - 0.02 * (1 - np.cos(157.0 * time_s))
    ones = np.ones((n_samples, 2))
    rigid = {"time": time_s, "crank/angle": angle, "slider/position": slider,
             "coupler/angle": np.zeros(n_samples),
             "joints/B/force_on_coupler": ones * [0.0, 1.0],
             "joints/C/force_on_coupler": ones * [0.0, 1.0]}
    ffrf = dict(rigid)
    return rigid, ffrf


def test_error_measures_are_relative_and_use_the_window():
    rigid, ffrf = _pair()
    qs_peak = criteria.quasi_static_stress(rigid["joints/B/force_on_coupler"][:1],
                                           rigid["joints/C/force_on_coupler"][:1],
                                           np.zeros(1), 0.08, 0.002, 0.01)[0]
    ffrf = dict(ffrf, **{"crank/angle": rigid["crank/angle"] + 1e-3,
                         "slider/position": rigid["slider/position"] - 2e-6,
                         "coupler/midpoint_deflection": np.full(400, 8e-6),
                         "coupler/peak_bending_stress": np.full(400, 1.5 * qs_peak)})
    ffrf["coupler/midpoint_deflection"][-1] = 1.0  # outside the window: ignored
    window = rigid["time"][-2]
    e = criteria.error_measures(rigid, ffrf, Plate(0.08, 0.002, 0.01, 200e9, 7850.0), window)
    swing = np.max(np.abs(rigid["crank/angle"][:-1] - rigid["crank/angle"][0]))
    travel = np.max(np.abs(rigid["slider/position"][:-1] - rigid["slider/position"][0]))
    assert e["deflection"] == pytest.approx(8e-6 / 0.08)
    assert e["crank_angle"] == pytest.approx(1e-3 / swing)
    assert e["slider_position"] == pytest.approx(2e-6 / travel)
    assert e["stress_amplification"] == pytest.approx(0.5)
    assert e["stress_ratio"] == pytest.approx(1.5)
    assert e["euler_load_ratio"] == 0.0  # transverse joint forces only
    assert e["governing"] == max(e["deflection"], e["crank_angle"], e["slider_position"])


# ------------------------------------------------------------------------------------------
# fitted laws with a known answer
# ------------------------------------------------------------------------------------------
def test_exact_power_law_gives_its_exponent_and_k():
    c, p = 0.08, 2.0  # quasi-static: deflection ~ 1/n^2
    n = np.geomspace(1.0, 100.0, 25)
    law = fit_error_law(n, c * n**-p)
    assert law.exponent == pytest.approx(p, abs=1e-10)
    assert law.coefficient == pytest.approx(c, rel=1e-10)
    assert law.r_squared == pytest.approx(1.0)
    for tolerance in (0.1, 0.01, 0.001):
        k = (c / tolerance) ** (1 / p)
        assert law.k(tolerance) == pytest.approx(k, rel=1e-9)
        assert law.k(tolerance, "thesis") == pytest.approx(2 * math.pi * k, rel=1e-9)
        # no scatter: the conservative k equals the central one
        assert law.k(tolerance, bound="upper") == pytest.approx(k, rel=1e-6)
    assert law.predict(10.0) == pytest.approx(c / 100)
    assert law.predict(20 * math.pi, "thesis") == pytest.approx(c / 100)  # n_physical = 10


def test_fit_in_thesis_convention_is_the_same_law():
    n_physical = np.geomspace(2.0, 60.0, 12)
    errors = 0.3 * n_physical**-2.4
    a = fit_error_law(n_physical, errors)
    b = fit_error_law(n_physical * 2 * math.pi, errors, convention="thesis")
    assert b.exponent == pytest.approx(a.exponent)
    assert b.log_coefficient == pytest.approx(a.log_coefficient)
    assert b.coefficient_in("thesis") == pytest.approx(0.3 * (2 * math.pi) ** 2.4)


def test_noisy_power_law_recovers_exponent_within_its_confidence_interval():
    rng = np.random.default_rng(7)
    c, p = 0.05, 2.3
    n = np.geomspace(0.5, 120.0, 40)
    errors = c * n**-p * np.exp(rng.normal(0.0, 0.2, n.size))  # 20 % lognormal scatter
    law = fit_error_law(n, errors)
    half = laws._t_quantile(law.dof, 0.95) * math.sqrt(law.covariance[1, 1])
    assert abs(law.exponent - p) < half
    assert law.residual_std == pytest.approx(0.2, rel=0.3)
    lower, upper = law.band(n, kind="prediction")
    inside = np.mean((errors >= lower) & (errors <= upper))
    assert 0.85 <= inside <= 1.0  # a 95 % prediction band
    conf_lo, conf_hi = law.band(n, kind="confidence")
    assert np.all(conf_hi <= upper) and np.all(conf_lo >= lower)
    true_k = (c / 0.01) ** (1 / p)
    assert law.k(0.01) == pytest.approx(true_k, rel=0.1)
    assert law.k(0.01, bound="upper") > law.k(0.01)  # scatter: conservative is larger


def test_law_with_a_floor_has_no_k_below_the_floor():
    n = np.geomspace(1.0, 200.0, 30)
    errors = 0.1 + 2.0 * n**-1.5
    law = fit_error_law(n, errors, floor=True)
    assert law.floor == pytest.approx(0.1, rel=1e-3)
    assert law.exponent == pytest.approx(1.5, rel=1e-3)
    assert math.isinf(law.k(0.1)) and math.isinf(law.k(0.05))
    assert law.k(0.3) == pytest.approx((2.0 / 0.2) ** (1 / 1.5), rel=1e-3)


def test_increasing_or_flat_error_gives_no_threshold():
    n = np.geomspace(1.0, 100.0, 10)
    law = fit_error_law(n, 0.01 * n**0.5)
    assert law.exponent < 0
    assert math.isinf(law.k(0.01))
    with pytest.raises(ValueError, match="usable points"):
        fit_error_law([1.0, 2.0], [0.1, 0.05])
    with pytest.raises(ValueError, match="tolerance"):
        law.k(0.0)


def test_zero_and_nan_errors_are_dropped():
    n = np.array([1.0, 2.0, 4.0, 8.0, 16.0])
    errors = 0.2 * n**-2.0
    law = fit_error_law(np.append(n, [3.0, 5.0]), np.append(errors, [0.0, np.nan]))
    assert law.n_points == 5
    assert law.exponent == pytest.approx(2.0)


# ------------------------------------------------------------------------------------------
# stored criterion and the auto decision
# ------------------------------------------------------------------------------------------
def _synthetic_criterion(c: float = 0.08, p: float = 2.0) -> Criterion:
    n = np.geomspace(1.0, 100.0, 20)
    undamped = fit_error_law(n, c * n**-p)
    damped = fit_error_law(n, 0.5 * c * n**-p)
    return Criterion({(0.0, "governing"): undamped, (0.02, "governing"): damped})


def test_criterion_toml_round_trip_and_damping_choice(tmp_path):
    criterion = _synthetic_criterion()
    path = tmp_path / "criterion.toml"
    path.write_text(criterion.to_toml("# test\n"))
    loaded = load_criterion(path)
    for key, law in criterion.laws.items():
        assert loaded.laws[key].exponent == pytest.approx(law.exponent)
        assert loaded.laws[key].k(0.01, bound="upper") == pytest.approx(
            law.k(0.01, bound="upper"))
    assert loaded.law(0.0)[0] == 0.0
    assert loaded.law(0.01)[0] == 0.0  # the largest fitted damping not above the scene's
    assert loaded.law(0.05)[0] == 0.02
    with pytest.raises(FlexError, match="does not exist"):
        load_criterion(tmp_path / "missing.toml")
    (tmp_path / "bad.toml").write_text("[criterion]\nformat = 'x'\n")
    with pytest.raises(FlexError, match="format"):
        load_criterion(tmp_path / "bad.toml")


def test_committed_criterion_loads_and_is_decreasing():
    criterion = load_criterion(laws.DEFAULT_CRITERION)  # the bundled file, by its path
    _, law = criterion.law(0.0)
    assert law.exponent > 1.0
    assert 1.0 < law.k(0.01, bound="upper") < 100.0


def test_law_round_trip_through_dict():
    law = fit_error_law(np.geomspace(1, 50, 8), 0.1 * np.geomspace(1, 50, 8) ** -2.2
                        * np.array([1, 1.1, 0.9, 1.05, 0.97, 1.02, 0.95, 1.0]))
    again = ErrorLaw.from_dict(law.to_dict())
    assert again.band(7.0) == pytest.approx(law.band(7.0))


def test_modes_for_cutoff_follow_the_beam_estimates():
    scene = load_scene(None, ['coupler.geometry="plate"', "coupler.thickness_m=0.001"])
    estimates = physics.clamped_plate_frequencies(0.08, 0.001, 0.01, 200e9, 7850, 0.3, 6)
    # 1 mm plate, measured fixed-interface modes 827, 2282, 4113, 4487 Hz (in-plane,
    # in-plane, torsion, in-plane): the estimates give the same order, within 2.5 % for
    # bending and 9 % for torsion (St. Venant, no warping restraint at the clamped faces)
    hz = [omega / (2 * math.pi) for omega, _ in estimates[:4]]
    assert [kind for _, kind in estimates[:4]] == ["in_plane", "in_plane", "torsion",
                                                   "in_plane"]
    assert hz == pytest.approx([827, 2282, 4113, 4487], rel=0.1)
    assert auto.modes_for_cutoff(scene, 2 * math.pi * 1000) == 2  # at least 2
    # in_plane reductions keep no torsion mode: below 4300 Hz only the two bending modes
    assert auto.modes_for_cutoff(scene, 2 * math.pi * 4300) == 2
    assert auto.modes_for_cutoff(scene, 2 * math.pi * 4600) == 3
    every_kind = load_scene(None, ['coupler.geometry="plate"', "coupler.thickness_m=0.001",
                                   'coupler.mode_selection="all"'])
    assert auto.modes_for_cutoff(every_kind, 2 * math.pi * 4300) == 3
    assert auto.modes_for_cutoff(scene, 1e9) == auto.MAX_AUTO_MODES


def _auto_scene(thickness_m: float, tolerance: float = 0.01, *extra: str):
    return load_scene(None, ['coupler.geometry="plate"', 'coupler.model="auto"',
                             f"coupler.thickness_m={thickness_m}",
                             f"fidelity.tolerance={tolerance}", "simulation.step_s=1e-4",
                             *extra])


def test_auto_decides_rigid_for_a_stiff_coupler_and_ffrf_for_a_soft_one():
    criterion = _synthetic_criterion()  # k(1 %) = sqrt(8) = 2.83, k(0.1 %) = 8.9
    thick, decisions = decide_links(_auto_scene(0.010), criterion)
    assert thick["coupler"]["model"] == "rigid"
    (decision,) = decisions
    assert decision.model == "rigid" and decision.n_physical >= decision.k_physical
    assert "n = delta_t/T" in decision.reason and "k = " in decision.reason
    assert decision.delta_t_s == pytest.approx(0.0246, abs=5e-4)  # 10 mm plate's stop time
    # 0.6 mm: the rigid probe predicts 0.5 % of the length (x 1.15 margin > 0.55 %); the
    # FFRF rung's model error (0.5 % of the deflection) meets 0.55 %
    thin, decisions = decide_links(_auto_scene(0.0006, 0.0055), criterion)
    assert thin["coupler"]["model"] == "ffrf"
    assert decisions[0].modes == thin["coupler"]["modes"] >= 1  # the tolerance rule's
    assert "tolerance rule" in decisions[0].reason
    assert decisions[0].n_physical < decisions[0].k_physical
    assert decisions[0].attrs()["fidelity_coupler_model"] == "ffrf"
    assert "Euler load" in decisions[0].reason


def test_auto_climbs_past_the_ffrf_body_for_a_coupler_near_buckling():
    """0.3 mm plate: Euler load 6.9 N, the 22 mm spring preload pushes with ~33 N (4.8 x):
    the fitted laws stop at 0.25 x (no rigid), the FFRF body's bound was measured up to
    0.33 x (none beyond), the geometrically exact beam's holds (0.05 t / L = 0.019 %): it
    is taken, and the reason says why each rung below it was passed."""
    resolved, (decision,) = decide_links(_auto_scene(0.0003), _synthetic_criterion())
    assert resolved["coupler"]["model"] == decision.model == "exact_beam"
    assert "the rigid model is not offered" in decision.reason
    assert "FFRF: no bound at" in decision.reason and "measured up to 0.33 x" in decision.reason


def test_euler_load_ratio_of_a_compressed_link():
    axis = np.array([[1.0, 0.0]])
    euler = math.pi**2 * 200e9 * 0.01 * 0.001**3 / 12 / 0.08**2  # 257 N
    plate = Plate(0.08, 0.001, 0.01, 200e9, 7850.0)
    ratio = criteria.euler_load_ratio(128.5 * axis, -128.5 * axis, np.zeros(1), plate)
    assert ratio == pytest.approx(128.5 / euler)
    assert criteria.euler_load_ratio(-axis, axis, np.zeros(1), plate) == 0.0  # tension


def test_auto_crank_is_rigid_ffrf_or_refused_with_a_reason(reduction_cache):
    criterion = _synthetic_criterion()
    # with the wing the crank's n-law decides (without one its loads do: test_crank_predictor)
    scene = load_scene(None, ['crank.model="auto"', "simulation.step_s=1e-4",
                              "wing.enabled=true"])
    resolved, decisions = decide_links(scene, criterion, criterion,
                                           cache_dir=reduction_cache)
    assert resolved["crank"]["model"] == "rigid"
    assert decisions[0].link == "crank" and "plate of its mass" in decisions[0].reason
    strict = _synthetic_criterion(c=1e9)  # every link flexible
    with pytest.raises(SceneError, match='set crank.geometry = "plate"'):
        decide_links(scene, strict, strict, cache_dir=reduction_cache)  # lumped: no mesh
    plate = load_scene(None, ['crank.model="auto"', 'crank.geometry="plate"',
                              "simulation.step_s=1e-4", "wing.enabled=true"])
    resolved, decisions = decide_links(plate, strict, strict, cache_dir=reduction_cache)
    assert resolved["crank"]["model"] == "ffrf" and resolved["crank"]["modes"] >= 2


def test_auto_needs_a_plate_and_a_tolerance_in_range():
    with pytest.raises(SceneError, match='coupler.model = "auto" needs coupler.geometry'):
        load_scene(None, ['coupler.model="auto"'])
    with pytest.raises(SceneError, match="fidelity.tolerance"):
        load_scene(None, ["fidelity.tolerance=0.0"])
    with pytest.raises(SceneError, match="fidelity.tolerance"):
        load_scene(None, ["fidelity.tolerance=0.9"])


def test_simulate_resolves_auto_prints_and_stores_the_choice(capsys):
    from flex.fidelity.simulation import simulate

    # the law is an argument (a fitted Criterion), not an environment variable
    result = simulate(_auto_scene(0.010, 0.01, "simulation.end_time_s=0.005"),
                      criterion=_synthetic_criterion())
    assert result.attrs["fidelity_coupler_model"] == "rigid"
    assert "model = \"rigid\"" in result.scene_toml
    assert "coupler.model = auto -> rigid" in capsys.readouterr().err
