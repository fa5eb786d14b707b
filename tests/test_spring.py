"""Helical spring of the thesis (sec. 6.1) against textbook values and hand computations.

"Shigley" = Budynas and Nisbett, Shigley's Mechanical Engineering Design, 10th ed.
Example 10-1: no. 16 music wire d = 0.037 in, OD 7/16 in (D = 0.400 in, C = 10.8),
12.5 total turns with squared ends (N_a = 10.5), G = 11.85 Mpsi: S_ut = 324 kpsi,
S_sy = 0.45 S_ut = 146 kpsi, K_B = 1.124, F at S_sy = 6.46 lbf, k = 4.13 lbf/in.
"""

import math

import pytest

from flex.base import thesis
from flex.base.errors import SceneError
from flex.bodies import spring, spring_fe

INCH_M = 0.0254
LBF_N = 4.4482216152605
KPSI_PA = 6.894757293168e6
MPSI_PA = 6.894757293168e9
LBF_PER_IN_N_PER_M = LBF_N / INCH_M

G_PA = spring.MUSIC_WIRE_SHEAR_MODULUS_PA


# --- rate and its inversions ------------------------------------------------------------------

def test_shigley_example_10_1_rate():
    rate = spring.helical_spring_rate_N_per_m(11.85 * MPSI_PA, 0.037 * INCH_M, 0.400 * INCH_M,
                                              10.5)
    assert rate / LBF_PER_IN_N_PER_M == pytest.approx(4.13, rel=2e-3)


def test_thesis_inconsistency_stated_diameter_gives_367_N_per_m():
    rate = spring.helical_spring_rate_N_per_m(G_PA, 0.0044, 0.150, 3)
    # hand: 79.3e9 * 0.0044**4 / (8 * 0.150**3 * 3) = 29.723 / 0.081 = 366.9 N/m
    assert rate == pytest.approx(366.9, abs=0.1)


def test_thesis_rate_needs_mean_diameter_near_94_mm():
    diameter = spring.mean_coil_diameter_for_rate_m(1500.0, G_PA, 0.0044, 3)
    assert diameter == pytest.approx(0.0938, abs=2e-4)
    assert spring.helical_spring_rate_N_per_m(G_PA, 0.0044, diameter, 3) == pytest.approx(1500.0)


def test_each_solver_reproduces_the_rate():
    rows = spring.rate_reproduction_table()
    names = [row.input_name for row in rows]
    assert names[0].startswith("spring rate")
    by_name = {row.input_name.split()[-1]: row for row in rows[1:]}
    assert by_name["D"].value_for_rate == pytest.approx(0.093812, rel=1e-4)
    assert by_name["N"].value_for_rate == pytest.approx(0.73389, rel=1e-4)
    assert by_name["d"].value_for_rate == pytest.approx(0.0062564, rel=1e-4)
    assert by_name["G"].value_for_rate == pytest.approx(3.2416e11, rel=1e-4)
    assert rows[0].value_for_rate == pytest.approx(366.94, rel=1e-4)
    # each solved value, put back with the others as stated, gives 1500 N/m
    stated = {"G": G_PA, "d": 0.0044, "D": 0.150, "N": 3.0}
    for key, row in by_name.items():
        inputs = dict(stated, **{key: row.value_for_rate})
        rate = spring.helical_spring_rate_N_per_m(inputs["G"], inputs["d"], inputs["D"],
                                                  inputs["N"])
        assert rate == pytest.approx(1500.0, rel=1e-12), key
    text = spring.format_rate_reproduction_table(rows)
    assert "mean coil diameter D" in text and "0.093812" in text


# --- end geometry and the consistent design ---------------------------------------------------

def test_shigley_table_10_1_end_types():
    d, n_active = 0.002, 10.0
    assert spring.total_coils(n_active, "plain") == 10.0
    assert spring.total_coils(n_active, "plain_ground") == 11.0
    assert spring.total_coils(n_active, "squared_ground") == 12.0
    assert spring.solid_length_m(d, n_active, "plain") == pytest.approx(0.022)
    assert spring.solid_length_m(d, n_active, "plain_ground") == pytest.approx(0.022)
    assert spring.solid_length_m(d, n_active, "squared") == pytest.approx(0.026)
    assert spring.solid_length_m(d, n_active, "squared_ground") == pytest.approx(0.024)
    assert spring.pitch_m(0.050, d, n_active, "squared_ground") == pytest.approx(0.0046)
    assert spring.pitch_m(0.055, d, n_active, "plain_ground") == pytest.approx(0.005)


def test_consistent_design_fits_the_22_mm_press():
    design = spring.CONSISTENT_THESIS_SPRING
    assert design.rate_N_per_m == pytest.approx(1500.0)
    assert design.wire_diameter_m == 0.0044 and design.active_coils == 3.0
    assert design.solid_length_m == pytest.approx(0.0176)  # 4 coils x 4.4 mm
    assert design.deflection_to_solid_m == pytest.approx(0.0254)
    assert design.fractional_overrun_to_closure(0.022) >= 0.15
    assert design.outside_diameter_m <= thesis.THESIS_SPRING_DIAMETER_M
    assert math.degrees(design.helix_angle_rad) == pytest.approx(2.09, abs=0.01)


def test_squared_and_ground_ends_would_go_solid_before_22_mm():
    design = spring.SpringDesign(0.0044, spring.CONSISTENT_THESIS_SPRING.mean_coil_diameter_m,
                                 3.0, 0.043, "squared_ground")
    assert design.solid_length_m == pytest.approx(5 * 0.0044)
    assert design.deflection_to_solid_m == pytest.approx(0.021)
    assert design.deflection_to_solid_m < thesis.THESIS_COMPRESSION_M


# --- stress factors, strength, stress check ---------------------------------------------------

def test_wahl_and_bergstrasser_at_index_10():
    assert spring.wahl_factor(10.0) == pytest.approx(1.1448, abs=1e-4)
    assert spring.bergstrasser_factor(10.0) == pytest.approx(42.0 / 37.0)  # 1.1351
    assert spring.direct_shear_factor(10.0) == pytest.approx(1.05)


def test_shigley_example_10_1_strength_and_load():
    d = 0.037 * INCH_M
    tensile = spring.a228_minimum_tensile_strength_Pa(d)
    assert tensile / KPSI_PA == pytest.approx(324.0, rel=3e-3)
    yield_shear = spring.music_wire_allowable_torsional_stress_Pa(d)
    assert yield_shear / KPSI_PA == pytest.approx(146.0, rel=5e-3)
    index = spring.spring_index(0.400 * INCH_M, d)
    assert index == pytest.approx(10.81, abs=0.01)
    assert spring.bergstrasser_factor(index) == pytest.approx(1.124, abs=1e-3)
    # F = pi d^3 S_sy / (8 K_B D) = 6.46 lbf; check via the nominal stress function
    force = 6.46 * LBF_N
    stress = spring.bergstrasser_factor(index) * spring.nominal_torsional_shear_stress_Pa(
        force, 0.400 * INCH_M, d)
    assert stress / KPSI_PA == pytest.approx(146.0, rel=5e-3)


def test_tensile_strength_of_the_thesis_wire_and_its_range():
    # hand: 2211 MPa / 4.4**0.145 = 2211 / 1.23964 = 1783.6 MPa
    assert spring.a228_minimum_tensile_strength_Pa(0.0044) == pytest.approx(1783.6e6, rel=1e-4)
    with pytest.raises(SceneError, match="0.0001 ... 0.0065 m"):
        spring.a228_minimum_tensile_strength_Pa(0.008)


def test_stress_check_of_the_consistent_design_at_22_mm():
    check = spring.spring_stress_check(spring.CONSISTENT_THESIS_SPRING, 0.022)
    assert check.force_N == pytest.approx(33.0)
    # hand: 8 * 33 * 0.093812 / (pi * 0.0044**3) = 92.55 MPa; K_W(21.32) = 1.06575
    assert check.nominal_shear_stress_Pa == pytest.approx(92.55e6, rel=1e-3)
    assert check.wahl_factor == pytest.approx(1.06575, abs=1e-5)
    assert check.wahl_shear_stress_Pa == pytest.approx(98.63e6, rel=1e-3)
    assert check.allowable_shear_stress_Pa == pytest.approx(0.45 * 1783.6e6, rel=1e-4)
    assert check.safety_factor == pytest.approx(8.14, abs=0.01)


# --- surge ---------------------------------------------------------------------------------

def test_surge_frequencies_by_hand():
    # m = rho pi^2 d^2 D N / 4 with rho = 8000, d = 2 mm, D = 20 mm, N = 10:
    # 8000 * 9.8696044 * 4e-6 * 0.02 * 10 / 4 = 0.015791367 kg
    mass = spring.active_coil_mass_kg(8000.0, 0.002, 0.020, 10.0)
    assert mass == pytest.approx(0.015791367, rel=1e-8)
    # k = 1500 N/m, m = 0.1 kg: sqrt(15000) = 122.474 -> 61.237 Hz and 30.619 Hz
    assert spring.surge_frequency_fixed_fixed_Hz(1500.0, 0.1) == pytest.approx(61.237, abs=1e-3)
    assert spring.surge_frequency_fixed_free_Hz(1500.0, 0.1) == pytest.approx(30.619, abs=1e-3)


def test_surge_with_end_mass_matches_bar_with_tip_mass():
    # beta tan(beta) = 1 has the root beta = 0.86033 (m = M)
    frequency = spring.surge_frequency_fixed_end_mass_Hz(1.0, 1.0, 1.0)
    assert frequency * 2 * math.pi == pytest.approx(0.8603336, abs=1e-6)
    # a heavy end mass tends to the Rayleigh estimate sqrt(k / (M + m/3))
    frequency = spring.surge_frequency_fixed_end_mass_Hz(1500.0, 0.01, 10.0)
    assert frequency == pytest.approx(math.sqrt(1500.0 / (10.0 + 0.01 / 3)) / (2 * math.pi),
                                      rel=1e-6)


def test_thesis_criterion_conventions_reproduce_table_5_model_1():
    omega_rad_per_s = 6741.12847  # thesis Table 5, model 1 ("Frequency", rad/s)
    frequency = omega_rad_per_s / (2 * math.pi)
    n_thesis = spring.rigid_or_flexible_ratio(0.016128, frequency, "thesis")
    n_physical = spring.rigid_or_flexible_ratio(0.016128, frequency, "physical")
    assert n_thesis == pytest.approx(108.7, abs=0.1)
    assert n_physical == pytest.approx(17.3, abs=0.05)


def test_surge_check_of_the_consistent_design():
    check = spring.surge_check(spring.CONSISTENT_THESIS_SPRING)
    assert check.active_mass_kg == pytest.approx(0.10568, rel=1e-4)
    assert check.fixed_fixed_Hz == pytest.approx(0.5 * math.sqrt(1500.0 / 0.10568), rel=1e-4)
    assert check.n_fixed_fixed_physical == pytest.approx(0.961, abs=1e-3)
    assert check.n_fixed_fixed_thesis == pytest.approx(2 * math.pi * 0.961, abs=1e-2)
    assert check.flexible_by_thesis_criterion


# --- errors -------------------------------------------------------------------------------

@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf, "x"])
@pytest.mark.parametrize("call", [
    lambda v: spring.helical_spring_rate_N_per_m(v, 0.0044, 0.09, 3),
    lambda v: spring.helical_spring_rate_N_per_m(G_PA, v, 0.09, 3),
    lambda v: spring.helical_spring_rate_N_per_m(G_PA, 0.0044, v, 3),
    lambda v: spring.helical_spring_rate_N_per_m(G_PA, 0.0044, 0.09, v),
    lambda v: spring.mean_coil_diameter_for_rate_m(v, G_PA, 0.0044, 3),
    lambda v: spring.active_coils_for_rate(1500, G_PA, 0.0044, v),
    lambda v: spring.wire_diameter_for_rate_m(1500, G_PA, 0.09, v),
    lambda v: spring.shear_modulus_for_rate_Pa(1500, v, 0.09, 3),
    lambda v: spring.wahl_factor(v),
    lambda v: spring.bergstrasser_factor(v),
    lambda v: spring.nominal_torsional_shear_stress_Pa(v, 0.09, 0.0044),
    lambda v: spring.a228_minimum_tensile_strength_Pa(v),
    lambda v: spring.active_coil_mass_kg(7861.0, 0.0044, 0.09, v),
    lambda v: spring.surge_frequency_fixed_fixed_Hz(1500.0, v),
    lambda v: spring.surge_frequency_fixed_free_Hz(v, 0.1),
    lambda v: spring.surge_frequency_fixed_end_mass_Hz(1500.0, 0.1, v),
    lambda v: spring.rigid_or_flexible_ratio(v, 60.0, "physical"),
    lambda v: spring.spring_stress_check(spring.CONSISTENT_THESIS_SPRING, v),
    lambda v: spring.SpringDesign(v, 0.09, 3, 0.043),
    lambda v: spring_fe.fe_helix_segment_stress(spring.CONSISTENT_THESIS_SPRING, v),
])
def test_non_positive_inputs_raise_scene_error(call, bad):
    with pytest.raises(SceneError, match="must be"):
        call(bad)


def test_other_invalid_inputs_raise_scene_error():
    with pytest.raises(SceneError, match="> 1"):
        spring.wahl_factor(0.9)
    with pytest.raises(SceneError, match="one of plain"):
        spring.total_coils(3, "closed")
    with pytest.raises(SceneError, match="'physical'"):
        spring.rigid_or_flexible_ratio(0.01, 60.0, "angular")
    with pytest.raises(SceneError, match="index C > 1"):
        spring.SpringDesign(0.0044, 0.004, 3, 0.043)
    with pytest.raises(SceneError, match=r"\(0, 1\]"):
        spring_fe.fe_helix_segment_stress(spring.CONSISTENT_THESIS_SPRING, 33.0, segment_turns=2)


# --- finite-element check ---------------------------------------------------------------------

@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_fe_helix_segment_matches_wahl_coarse():
    result = spring_fe.fe_helix_segment_stress(spring.CONSISTENT_THESIS_SPRING, 33.0)
    assert result.peak_angle_deg == pytest.approx(0.0, abs=20.0)  # inner fibre
    assert result.fe_over_wahl == pytest.approx(1.0, abs=0.02)
    assert result.fe_over_bergstrasser == pytest.approx(1.0, abs=0.02)
    assert result.inner_fibre_von_mises_Pa == pytest.approx(
        math.sqrt(3) * result.inner_fibre_max_shear_Pa, rel=0.01)  # nearly pure shear
    assert result.fe_rate_N_per_m == pytest.approx(1500.0, rel=0.01)


@pytest.mark.slow
@pytest.mark.parametrize(("segment_turns", "mesh_size_m"), [(0.125, 0.0008), (0.5, 0.0022)])
def test_fe_helix_refined_and_longer(segment_turns, mesh_size_m):
    # finer mesh (converged within 0.1 %) and a longer segment (end effects): same answer
    result = spring_fe.fe_helix_segment_stress(spring.CONSISTENT_THESIS_SPRING, 33.0,
                                            segment_turns=segment_turns, mesh_size_m=mesh_size_m)
    assert result.fe_over_wahl == pytest.approx(0.995, abs=0.006)
    assert result.fe_over_bergstrasser == pytest.approx(1.0, abs=0.006)
    assert result.fe_rate_N_per_m == pytest.approx(1500.0, rel=0.003)
