"""flex.base.physics: each closed form against an independent check (a hand computation, a
textbook value, a limiting case or a numerical solution), and flex.base.thesis against itself."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigvalsh_tridiagonal
from scipy.optimize import brentq

from flex.base import physics, thesis

STEEL_E_PA, STEEL_RHO = 200e9, 7850.0


def _fd_beam_lambda(end: str, points: int = 400) -> float:
    """Smallest eigenvalue of w'''' = lambda w on [0, 1] by central differences (w = 0 at
    both ends; pinned: w'' = 0, ghost w_-1 = -w_1; clamped: w' = 0, ghost w_-1 = w_1)."""
    h = 1.0 / points
    n = points - 1
    matrix = (np.diag(np.full(n, 6.0)) + np.diag(np.full(n - 1, -4.0), 1)
              + np.diag(np.full(n - 1, -4.0), -1) + np.diag(np.ones(n - 2), 2)
              + np.diag(np.ones(n - 2), -2))
    ghost = -1.0 if end == "pinned" else 1.0
    matrix[0, 0] += ghost
    matrix[-1, -1] += ghost
    return float(np.linalg.eigvalsh(matrix / h**4)[0])


# --- pinned-pinned bending frequency ------------------------------------------------------------

def test_pinned_pinned_omega_of_a_steel_strip_by_hand():
    # 80 x 10 x 3 mm steel strip: I / A = t^2 / 12 = 7.5e-7 m^2;
    # sqrt(E I / (rho A)) = sqrt(200e9 * 7.5e-7 / 7850) = sqrt(19.10828) = 4.371302 m^2/s;
    # (pi / 0.08)^2 = 1542.1257 1/m^2; omega = 1542.1257 * 4.371302 = 6741.097 rad/s
    by_hand = 1542.1257 * 4.371302
    assert by_hand == pytest.approx(6741.097, abs=1e-3)
    assert physics.pinned_pinned_omega(0.08, 0.003, STEEL_E_PA, STEEL_RHO) == pytest.approx(
        by_hand, rel=1e-7)


def test_pinned_pinned_omega_is_thesis_table5_frequency():
    # Table 5 "Frequency" is this value for all four plates (t = 1, 3, 5, 10 mm), 4.7e-6 high:
    # the thesis took pi = 3.1416 ((3.1416 / pi)^2 = 1 + 4.7e-6); with that pi, to 1e-9
    table = thesis.THESIS_TABLE5
    for t, published in zip(table["coupler_thickness_m"], table["frequency_as_published"],
                            strict=True):
        omega = physics.pinned_pinned_omega(thesis.THESIS_COUPLER_LENGTH_M, float(t),
                                            thesis.THESIS_YOUNGS_MODULUS_PA,
                                            thesis.THESIS_DENSITY_KG_PER_M3)
        assert omega == pytest.approx(published, rel=5e-6)
        assert omega * (3.1416 / math.pi) ** 2 == pytest.approx(published, rel=2e-9)


def test_pinned_pinned_omega_against_finite_differences():
    # w'''' = (beta)^4 w on [0, 1]: lambda_1 = pi^4 for pinned ends
    lam = _fd_beam_lambda("pinned")
    assert lam == pytest.approx(math.pi**4, rel=2e-5)
    length, t = 0.08, 0.002
    scale = math.sqrt(STEEL_E_PA * t**2 / 12 / STEEL_RHO)
    assert physics.pinned_pinned_omega(length, t, STEEL_E_PA, STEEL_RHO) == pytest.approx(
        math.sqrt(lam) / length**2 * scale, rel=2e-5)


def test_pinned_pinned_omega_refuses_bad_inputs():
    with pytest.raises(ValueError, match="height_m"):
        physics.pinned_pinned_omega(0.08, 0.0, STEEL_E_PA, STEEL_RHO)
    with pytest.raises(ValueError, match="density"):
        physics.pinned_pinned_omega(0.08, 0.001, STEEL_E_PA, math.nan)


def test_euler_bernoulli_omega_scales_as_beta_l_squared_and_is_the_pinned_case_at_pi():
    args = (0.08, 0.003, STEEL_E_PA, STEEL_RHO)
    assert physics.euler_bernoulli_omega(math.pi, *args) == physics.pinned_pinned_omega(*args)
    # arrays: omega_n / omega_1 = (beta_n L / beta_1 L)^2
    beta = np.array(physics.euler_bernoulli_beta_l("clamped-clamped", 3))
    omegas = physics.euler_bernoulli_omega(beta, *args)
    np.testing.assert_allclose(omegas / omegas[0], (beta / beta[0]) ** 2, rtol=1e-14)


# --- beam wave numbers ------------------------------------------------------------------------

@pytest.mark.parametrize("end, equation, textbook", [
    ("clamped-clamped", lambda x: math.cos(x) * math.cosh(x) - 1.0,
     (4.73004074, 7.85320462, 10.9956078, 14.1371655, 17.2787597)),
    ("free-free", lambda x: math.cos(x) * math.cosh(x) - 1.0,
     (4.73004074, 7.85320462, 10.9956078, 14.1371655, 17.2787597)),
    ("clamped-free", lambda x: math.cos(x) * math.cosh(x) + 1.0,
     (1.87510407, 4.69409113, 7.85475744, 10.9955407, 14.1371684)),
    ("clamped-pinned", lambda x: math.tan(x) - math.tanh(x),
     (3.92660231, 7.06858275, 10.2101761, 13.3517688, 16.4933614)),
])
def test_beta_l_roots_against_brentq_and_blevins(end, equation, textbook):
    roots = physics.euler_bernoulli_beta_l(end, 12)
    assert len(roots) == 12
    # the textbook values (Blevins 1979, ch. 8), rounded to 9 digits
    np.testing.assert_allclose(roots[:5], textbook, rtol=5e-9)
    guesses = {"clamped-free": -0.5, "clamped-pinned": 0.25}
    for n, root in enumerate(roots, start=1):
        centre = (n + guesses.get(end, 0.5)) * math.pi
        half = 0.3 if end == "clamped-pinned" else 0.5
        reference = brentq(equation, max(centre - half, 1.0), centre + half, xtol=1e-15,
                           rtol=4 * np.finfo(float).eps)
        assert root == pytest.approx(reference, rel=1e-14, abs=1e-14), n


def test_beta_l_pinned_is_n_pi_and_high_modes_do_not_overflow():
    assert physics.euler_bernoulli_beta_l("pinned-pinned", 3) == [math.pi, 2 * math.pi,
                                                                  3 * math.pi]
    roots = physics.euler_bernoulli_beta_l("clamped-clamped", 300)  # cosh(940) overflows
    # limiting case: beta_n L -> (n + 1/2) pi as n grows
    assert roots[-1] == pytest.approx(300.5 * math.pi, rel=1e-15)
    with pytest.raises(ValueError, match="end_condition"):
        physics.euler_bernoulli_beta_l("glued-glued", 1)


def test_clamped_clamped_first_mode_against_finite_differences():
    lam = _fd_beam_lambda("clamped")
    beta_l = physics.euler_bernoulli_beta_l("clamped-clamped", 1)[0]
    assert lam == pytest.approx(beta_l**4, rel=1e-4)


# --- Euler buckling -----------------------------------------------------------------------------

def test_euler_buckling_load_by_hand_and_against_finite_differences():
    # 80 x 10 x 1 mm steel: I = 0.01 * 1e-9 / 12 = 8.333e-13 m^4,
    # P = pi^2 * 200e9 * 8.333e-13 / 0.0064 = 257.02 N
    load = physics.euler_buckling_load_N(0.08, 0.001, 0.01, STEEL_E_PA)
    assert load == pytest.approx(257.02, abs=0.01)
    # E I w'' + P w = 0, w(0) = w(L) = 0: P_cr = E I x smallest eigenvalue of -d2/dx2
    points, length = 2000, 0.08
    h = length / points
    smallest = eigvalsh_tridiagonal(np.full(points - 1, 2.0 / h**2),
                                    np.full(points - 2, -1.0 / h**2),
                                    select="i", select_range=(0, 0))[0]
    inertia = 0.01 * 0.001**3 / 12
    assert load == pytest.approx(STEEL_E_PA * inertia * smallest, rel=1e-6)


def test_euler_buckling_load_scales_with_thickness_cubed_and_refuses_zero():
    thin = physics.euler_buckling_load_N(0.08, 0.001, 0.01, STEEL_E_PA)
    assert physics.euler_buckling_load_N(0.08, 0.002, 0.01, STEEL_E_PA) == pytest.approx(
        8 * thin, rel=1e-14)
    with pytest.raises(ValueError, match="length_m"):
        physics.euler_buckling_load_N(0.0, 0.001, 0.01, STEEL_E_PA)


# --- torsion and rods ---------------------------------------------------------------------------

def test_torsion_constant_square_and_thin_strip_limits():
    # square: J = 0.1406 a^4 (Timoshenko & Goodier; Roark)
    assert physics.rectangle_torsion_constant_m4(0.01, 0.01) == pytest.approx(0.1406e-8,
                                                                              rel=5e-4)
    # thin strip a >> b: J -> a b^3 / 3 (1 - 0.630 b / a)
    a, b = 0.1, 0.001
    assert physics.rectangle_torsion_constant_m4(b, a) == pytest.approx(
        a * b**3 / 3 * (1 - 0.630 * b / a), rel=1e-4)
    # symmetric in its sides
    assert (physics.rectangle_torsion_constant_m4(0.003, 0.01)
            == physics.rectangle_torsion_constant_m4(0.01, 0.003))


def test_rod_frequencies_by_hand():
    # steel, c = sqrt(E / rho) = 5047.5 m/s; a fixed-free 80 mm rod: f = c / (4 L) = 15774 Hz
    omega = physics.axial_omega(0.5, 0.08, STEEL_E_PA, STEEL_RHO)
    assert omega / (2 * math.pi) == pytest.approx(15773.6, abs=0.1)
    # torsion of a circular-like section (J = I_p): the shear wave speed sqrt(G / rho)
    shear = physics.shear_modulus_Pa(STEEL_E_PA, 0.3)
    assert shear == pytest.approx(76.923e9, rel=1e-4)
    assert physics.torsion_omega(1, 0.08, shear, 1.0, 1.0, STEEL_RHO) == pytest.approx(
        math.pi / 0.08 * math.sqrt(shear / STEEL_RHO), rel=1e-15)
    assert physics.rectangle_polar_moment_m4(0.003, 0.01) == pytest.approx(
        (0.01 * 0.003**3 + 0.003 * 0.01**3) / 12, rel=1e-15)


# --- clamped plates -----------------------------------------------------------------------------

def test_clamped_plate_frequencies_merge_the_four_families():
    length, t, w = 0.08, 0.003, 0.01
    modes = physics.clamped_plate_frequencies(length, t, w, STEEL_E_PA, STEEL_RHO, 0.3,
                                              count=12)
    assert len(modes) == 12 and modes == sorted(modes)
    first_in_plane = next(omega for omega, kind in modes if kind == "in_plane")
    assert first_in_plane == pytest.approx(
        4.7300407449 ** 2 / length**2 * math.sqrt(STEEL_E_PA * t**2 / 12 / STEEL_RHO),
        rel=1e-10)
    first_torsion = next(omega for omega, kind in modes if kind == "torsion")
    shear = STEEL_E_PA / 2.6
    j_series = physics.rectangle_torsion_constant_m4(t, w)
    assert first_torsion == pytest.approx(
        math.pi / length * math.sqrt(shear * j_series / (STEEL_RHO * (w * t**3 + t * w**3)
                                                          / 12)), rel=1e-14)
    assert {kind for _, kind in modes} <= {"in_plane", "out_of_plane", "torsion", "axial"}


# --- mass properties ----------------------------------------------------------------------------

def test_cuboid_mass_inertia_and_thickness_round_trip():
    mass = physics.cuboid_mass_kg(0.08, 0.003, 0.01, STEEL_RHO)
    assert mass == pytest.approx(0.01884, rel=1e-12)  # 7850 * 2.4e-6 m^3
    assert physics.cuboid_inertia_kgm2(mass, 0.08, 0.003) == pytest.approx(
        mass * (0.0064 + 9e-6) / 12, rel=1e-14)
    assert physics.plate_thickness_for_mass_m(mass, 0.08, 0.01, STEEL_RHO) == pytest.approx(
        0.003, rel=1e-14)


# --- n = delta_t / T ----------------------------------------------------------------------------

def test_n_values_conventions_and_thesis_table5():
    n = physics.n_values(0.01, 100.0)
    assert n == {"thesis": 1.0, "physical": 1.0 / (2 * math.pi)}
    array = physics.n_values(0.01, np.array([100.0, 200.0]))
    np.testing.assert_allclose(array["thesis"], [1.0, 2.0], rtol=1e-15)
    # Table 5: n = delta_t x Frequency, printed truncated (36, 108, 181, 362)
    table = thesis.THESIS_TABLE5
    counts = physics.n_values(thesis.THESIS_DELTA_T_S, table["frequency_as_published"])
    np.testing.assert_array_equal(np.floor(counts["thesis"]), table["n_as_published"])
    assert table["n_as_published"][1] == thesis.THESIS_K  # model 1 is the criterion's k


def test_thesis_constants_agree_with_the_tables_they_came_from():
    # Eq. 66-67: k = delta_t / (fifth-mode period)
    assert round(thesis.THESIS_DELTA_T_S
                 / thesis.THESIS_TABLE7_CRANK["period_as_published_s"][-1]) == \
        thesis.THESIS_K_CRANK
    assert round(thesis.THESIS_DELTA_T_S
                 / thesis.THESIS_TABLE9_COUPLER["period_as_published_s"][-1]) == \
        thesis.THESIS_K_COUPLER
    assert set(thesis.THESIS_TABLE5["coupler_length_m"]) == {thesis.THESIS_COUPLER_LENGTH_M}
    assert set(thesis.THESIS_TABLE5["coupler_width_m"]) == {thesis.THESIS_TABLE5_WIDTH_M}


def test_a_plate_value_reads_a_scene_link_and_calls_the_closed_forms():
    from flex.data.scene import default_scene

    values = dict(default_scene()["coupler"], thickness_m=0.002)
    plate = physics.Plate.of(values)
    assert plate.sizes_m == (0.08, 0.002, 0.01) and plate.poisson_ratio == 0.3
    assert plate.mass_kg == physics.cuboid_mass_kg(0.08, 0.002, 0.01, 7850.0)
    assert plate.inertia_kgm2 == physics.cuboid_inertia_kgm2(plate.mass_kg, 0.08, 0.002)
    assert plate.euler_load_N == physics.euler_buckling_load_N(0.08, 0.002, 0.01, 200e9)
    assert plate.pinned_pinned_omega == physics.pinned_pinned_omega(0.08, 0.002, 200e9, 7850.0)
    assert plate.in_plane_omegas(3) == physics.in_plane_fixed_interface_omegas(
        0.08, 0.002, 0.01, 200e9, 7850.0, 0.3, 3)
    assert plate.clamped_frequencies(5) == physics.clamped_plate_frequencies(
        0.08, 0.002, 0.01, 200e9, 7850.0, 0.3, 5)


# --- Timoshenko closed forms from a section (the plate reference's calibration) ------------

STRIP = dict(length_m=0.08, bending_stiffness_Nm2=200e9 * 0.01 * 0.003**3 / 12,
             shear_stiffness_N=5 / 6 * 200e9 / 2.6 * 0.01 * 0.003)


def test_timoshenko_midpoint_deflection_against_the_beam_equations_solved_numerically():
    """Independent: the Timoshenko equations E I psi'' + kGA (w' - psi) = 0, kGA (w'' -
    psi') = -q with w = 0, psi' = 0 at both pins, solved by scipy's collocation."""
    from scipy.integrate import solve_bvp

    length, bending, shear, load = (STRIP["length_m"], STRIP["bending_stiffness_Nm2"],
                                    STRIP["shear_stiffness_N"], 2.0)

    def rhs(x, s):  # s = (w, w', psi, psi')
        return np.vstack([s[1], s[3] - load / shear, s[3],
                          -shear / bending * (s[1] - s[2])])

    x = np.linspace(0.0, length, 101)
    solution = solve_bvp(rhs, lambda a, b: np.array([a[0], b[0], a[3], b[3]]), x,
                         np.zeros((4, x.size)), tol=1e-10, max_nodes=100000)
    assert solution.success
    numeric = float(solution.sol(length / 2)[0])
    closed = physics.pinned_timoshenko_midpoint_deflection_m(load, length, bending, shear)
    assert closed == pytest.approx(numeric, rel=1e-7)
    # without shear deformation it is the Euler-Bernoulli beam of the older closed form
    assert physics.pinned_timoshenko_midpoint_deflection_m(
        load, length, 200e9 * 0.01 * 0.003**3 / 12, math.inf) == pytest.approx(
        physics.pinned_beam_midpoint_deflection_m(load * length, length, 0.003, 0.01, 200e9),
        rel=1e-14)
    with pytest.raises(ValueError, match="shear_stiffness_N"):
        physics.pinned_timoshenko_midpoint_deflection_m(load, length, bending, 0.0)


def test_timoshenko_pinned_omega_against_the_transfer_matrix_roots_and_euler_bernoulli():
    """The closed form against the transfer-matrix root search of
    flex.experiments.thesis.beams (which solves any end condition from the Timoshenko
    equations), and its Euler-Bernoulli limit."""
    from flex.experiments.thesis.beams import _timoshenko_roots

    length, bending, shear = (STRIP["length_m"], STRIP["bending_stiffness_Nm2"],
                              STRIP["shear_stiffness_N"])
    area, inertia, rho = 0.01 * 0.003, 0.01 * 0.003**3 / 12, 7850.0
    roots = _timoshenko_roots("pinned-pinned", 3, inertia / (area * length**2),
                              bending / (shear * length**2), True)
    by_roots = np.array(roots) / length**2 * math.sqrt(bending / (rho * area))
    closed = physics.timoshenko_pinned_pinned_omega(np.arange(1, 4), length, bending, shear,
                                                    rho * area, rho * inertia)
    np.testing.assert_allclose(closed, by_roots, rtol=1e-9)
    euler = physics.timoshenko_pinned_pinned_omega(1, length, 200e9 * inertia, math.inf,
                                                   rho * area, 0.0)
    assert euler == pytest.approx(physics.pinned_pinned_omega(length, 0.003, 200e9, rho),
                                  rel=1e-14)
    assert closed[0] < euler  # shear and rotary inertia soften


def test_anticlastic_offset_is_point_four_nu_w_over_l_squared_for_a_thin_strip():
    thin = physics.anticlastic_centroid_offset(0.08, 1e-9, 0.01, 0.3)
    assert thin == pytest.approx(0.4 * 0.3 * (0.01 / 0.08) ** 2, rel=1e-12)
    # a square section does not curl on the mean: the y and z terms cancel
    assert physics.anticlastic_centroid_offset(0.08, 0.01, 0.01, 0.3) == 0.0
    assert physics.lame_first_parameter_Pa(200e9, 0.3) == pytest.approx(
        200e9 * 0.3 / (1.3 * 0.4), rel=1e-15)
