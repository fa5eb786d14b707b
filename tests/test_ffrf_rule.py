"""The FFRF settings rule (flex/config/ffrf_rule.py) and its calibration's fit and validation
(flex/experiments/fitting/calibration.py) on synthetic grids whose answer is known."""

from __future__ import annotations

import math

import numpy as np
import pytest

from flex.base.errors import FlexError
from flex.base.physics import in_plane_fixed_interface_omegas
from flex.config.ffrf_rule import (
    STEP_GRID,
    fill_link_keys,
    first_period_s,
    level_for,
    level_modes,
    load_time_scale_s,
    outside_family,
    pick,
    rule_constants,
    rule_mesh_size_m,
    steps_per_first_period,
    top_mode_ratio,
)
from flex.data.results import CaseResult, Dataset
from flex.data.scene import load_scene
from flex.experiments.fitting.calibration import (
    GRID_MODES,
    GRID_STEPS_PER_PERIOD,
    fit_levels,
    robustly_within,
    validate,
)

STEEL_1MM = {"length_m": 0.08, "thickness_m": 0.001, "width_m": 0.01,
             "youngs_modulus_Pa": 200e9, "density_kg_per_m3": 7850.0}


def test_first_period_is_the_pinned_pinned_euler_bernoulli_period():
    # f = (pi / 2) / L^2 sqrt(E t^2 / (12 rho)) = 357.6 Hz for the thesis's 1 mm steel plate
    hertz = math.pi / 2 / 0.08**2 * math.sqrt(200e9 * 0.001**2 / 12 / 7850.0)
    assert first_period_s(STEEL_1MM) == pytest.approx(1 / hertz, rel=1e-12)
    assert hertz == pytest.approx(357.6, abs=0.1)  # thesis Table 5, model 0


@pytest.mark.parametrize("thickness_m, expected_m", [
    (0.001, 0.002),   # 2 t
    (0.002, 0.004),   # 2 t
    (0.003, 0.005),   # L / 16
    (0.02, 0.005),    # L / 16
])
def test_mesh_rule(thickness_m, expected_m):
    assert rule_mesh_size_m(dict(STEEL_1MM, thickness_m=thickness_m)) == pytest.approx(expected_m)


def test_levels_serve_every_tolerance_at_or_above_them():
    for damping in ("undamped", "damped"):
        levels = sorted(level["tolerance"] for level in rule_constants()["levels"]
                        if level["damping"] == damping)
        for tolerance in levels:
            assert level_for(tolerance, damping)["tolerance"] == tolerance
            assert level_for(tolerance * 3, damping)["tolerance"] == tolerance  # next finer
    undamped = min(level["tolerance"] for level in rule_constants()["levels"]
                   if level["damping"] == "undamped")
    assert outside_family(STEEL_1MM, undamped / 10).startswith("fidelity.tolerance")


def _scene(thickness_m=0.001, *extra):
    return load_scene(None, ['coupler.geometry="plate"', 'coupler.model="ffrf"',
                             f"coupler.thickness_m={thickness_m}", *extra])


def test_the_load_time_scale_is_the_spring_s_quarter_period_or_half_a_turn():
    scene = _scene()
    mass = 0.0264 + 0.01432 + 7850.0 * 0.08 * 0.001 * 0.01  # slider, lumped crank, plate
    assert load_time_scale_s(scene) == pytest.approx(math.pi / 2 * math.sqrt(mass / 1500.0))
    turning = _scene(0.001, 'drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=40.0")
    assert load_time_scale_s(turning) == pytest.approx(math.pi / 40.0)


def test_a_pick_outside_the_family_has_no_step_and_says_why():
    foil = 0.08 / (rule_constants()["family"]["slenderness_max"] * 2)
    chosen = pick(_scene(foil), 0.01)
    assert chosen.step_s is None and chosen.level is None
    assert "outside the calibrated family" in chosen.reason


def test_a_pick_inside_the_family_is_t1_over_the_law_s_grid_count():
    scene = _scene()
    level = level_for(0.01)
    n_load = load_time_scale_s(scene) / first_period_s(scene["coupler"])
    per = steps_per_first_period(level, n_load, top_mode_ratio(level, scene["coupler"],
                                                               n_load))
    chosen = pick(scene, 0.01)
    assert per in STEP_GRID
    assert chosen.step_s == pytest.approx(first_period_s(scene["coupler"]) / per)
    assert chosen.modes == level_modes(level, scene["coupler"], n_load)
    assert chosen.level == level["tolerance"]


def test_a_load_faster_than_the_level_s_calibration_scenes_falls_back():
    """A level holds for the n = t_load / T1 its calibration scenes spanned: a spring of
    1e6 N/m loads the 1 mm plate within a fraction of its first period (n << 1)."""
    level = level_for(0.01)
    if "n_load_min" not in level:
        pytest.skip("the installed rule predates per-level load ranges")
    scene = _scene(0.001, "drive.spring_stiffness_N_per_m=1e6")
    assert load_time_scale_s(scene) / first_period_s(scene["coupler"]) < level["n_load_min"]
    chosen = pick(scene, 0.01)
    assert chosen.step_s is None and "n = t_load / T1" in chosen.reason


def test_the_step_law_rounds_up_to_the_grid():
    law = {"steps_coefficient": 100.0, "steps_exponent": 0.5}
    assert steps_per_first_period(law, 4.0) == 64  # 50 -> 64
    assert steps_per_first_period(law, 100.0) == 16  # 10 -> 16
    assert steps_per_first_period(law, 0.1) is None  # 316: beyond the grid


def test_modes_up_to_a_multiple_of_the_first_rounded_up_to_the_grid():
    thin, thick = STEEL_1MM | {"poisson_ratio": 0.3}, STEEL_1MM | {"thickness_m": 0.01,
                                                                    "poisson_ratio": 0.3}
    # beam estimates, 1 mm: 811, 2235, 4381, 7242 Hz; 10 mm: 8107, 22347, 31547 (axial) Hz
    assert level_modes({"mode_cutoff_ratio": 1.0}, thin) == 1
    assert level_modes({"mode_cutoff_ratio": 3.0}, thin) == 2
    assert level_modes({"mode_cutoff_ratio": 6.0}, thin) == 4  # 3 modes -> grid 4
    assert level_modes({"mode_cutoff_ratio": 4.0}, thick) == 4  # the axial mode crowds in
    assert level_modes({"modes": 8}, thin) == 8  # a fixed count


def test_a_slowly_loaded_link_keeps_the_modes_its_load_can_excite():
    """Cut-off max(r, c / n): at n = 2 first periods per load time scale a load cut-off of 16
    reaches 8 x the first mode (1 mm plate: 811, 2235, 4381 Hz below 6488 Hz: 3 -> grid 4);
    a stiff link (n = 32) keeps the ratio's one mode."""
    from flex.config.ffrf_rule import mode_cutoff

    thin = STEEL_1MM | {"poisson_ratio": 0.3}
    level = {"mode_cutoff_ratio": 1.0, "mode_cutoff_load": 16.0}
    assert mode_cutoff(level, 2.0) == pytest.approx(8.0)
    assert mode_cutoff(level, 32.0) == pytest.approx(1.0)
    assert level_modes(level, thin, 2.0) == level_modes({"mode_cutoff_ratio": 8.0}, thin) == 4
    assert level_modes(level, thin, 32.0) == 1
    assert level_modes(level, thin) == 1  # no load given: the ratio alone
    assert top_mode_ratio(level, thin, 2.0) == pytest.approx(
        top_mode_ratio({"mode_cutoff_ratio": 8.0}, thin))


def test_the_highest_retained_mode_bounds_the_step():
    level = {"steps_coefficient": 4.0, "steps_exponent": 0.0, "steps_per_top_period": 8.0}
    assert steps_per_first_period(level, 10.0, 1.0) == 8
    assert steps_per_first_period(level, 10.0, 5.4) == 64  # 43.2 -> 64


def test_only_auto_link_keys_are_filled():
    scene = _scene(0.001, 'coupler.modes="auto"', "coupler.mesh_size_m=0.003")
    filled = fill_link_keys(scene, "coupler", 0.01)
    n_load = load_time_scale_s(scene) / first_period_s(scene["coupler"])
    assert filled == {"modes": level_modes(level_for(0.01), scene["coupler"], n_load)}
    assert scene["coupler"]["mesh_size_m"] == 0.003


def test_a_lumped_link_keeps_auto():
    scene = load_scene(None, ['crank.modes="auto"'])
    assert fill_link_keys(scene, "crank", 0.01) == {} and scene["crank"]["modes"] == "auto"


def test_bundled_scene_leaves_the_coupler_discretization_to_the_rule():
    coupler = load_scene()["coupler"]
    assert coupler["modes"] == "auto" and coupler["mesh_size_m"] == "auto"


def test_in_plane_estimates_skip_the_antisymmetric_modes():
    # beam theory: clamped-clamped in-plane bending 22.37/L^2 sqrt(EI/rho A) = 811 Hz for
    # 1 mm (FE 823 Hz), the first axial mode c / 2L = 31.5 kHz after the 8th bending mode
    omegas = in_plane_fixed_interface_omegas(0.08, 0.001, 0.01, 200e9, 7850.0, 0.3, 10)
    hertz = np.array(omegas) / (2 * math.pi)
    assert hertz[0] == pytest.approx(4.7300**2 / 0.08**2 * math.sqrt(
        200e9 * 0.001**2 / 12 / 7850.0) / (2 * math.pi), rel=1e-4)
    assert hertz[8] == pytest.approx(math.sqrt(200e9 / 7850.0) / 0.16, rel=1e-9)  # axial


# ------------------------------------------------------------------------------------------
# fit and validation on synthetic grids
# ------------------------------------------------------------------------------------------
def _case(name, thickness_m, error_of, time_of, reference_accuracy=1e-4):
    """A calibration case of the 80 mm steel plate ``thickness_m`` thick whose grid errors and
    times are ``error_of(modes, steps per period, n_load)`` and ``time_of(...)``."""
    from flex.data.scene import to_toml

    scene = _scene(thickness_m)
    n_load = load_time_scale_s(scene) / first_period_s(scene["coupler"])
    modes = np.repeat(GRID_MODES, len(GRID_STEPS_PER_PERIOD)).astype(float)
    per = np.tile(GRID_STEPS_PER_PERIOD, len(GRID_MODES))
    triples = [(m, n, n_load) for m, n in zip(modes, per, strict=True)]
    datasets = {"grid/modes": Dataset(modes, "1"),
                "grid/steps_per_first_period": Dataset(per, "1"),
                "grid/peak_deflection_error": Dataset(np.array([error_of(*t) for t in triples]),
                                                      "1"),
                "grid/total_time": Dataset(np.array([time_of(*t) for t in triples]), "s")}
    return CaseResult(name, to_toml(scene), datasets,
                      attrs={"reference_accuracy": reference_accuracy,
                             "reference_peak_deflection_m": 1e-4})  # within 1 % of L


def step_law_error(m, n, n_load):
    """(h / T1)^2 error falling with n_load^-1 (a stiffer plate follows its load), plus a
    modal truncation term: needs N ~ n_load^-0.5."""
    return 4.0 / (n**2 * n_load) + 1e-4 / m


def cost(m, n, n_load):
    return 1e-3 * n * (1 + 0.1 * m)


def test_robustly_within_refuses_a_lucky_coarse_step():
    from flex.experiments.fitting.calibration import grid_table

    case = _case("lucky", 0.001, lambda m, n, _: 1e-4 if n == 4 else (0.05 if n == 8 else 1e-4),
                 cost)
    table = grid_table(case)
    ok = robustly_within(table, 0.01)
    assert not ok[(table["modes"] == 1) & (table["steps_per_first_period"] == 4)].any()
    assert ok[(table["modes"] == 1) & (table["steps_per_first_period"] == 16)].all()


def test_the_fitted_law_covers_every_calibration_scene():
    from flex.experiments.fitting.calibration import (
        MARGIN,
        coupler_of,
        grid_table,
        n_load_of,
        needed_steps,
    )

    cases = {f"t{t}": _case(f"t{t}", t, step_law_error, cost) for t in (0.001, 0.002, 0.005)}
    level = next(lv for lv in fit_levels(cases, [0.01]) if lv["damping"] == "undamped")
    assert level["modes"] == 1  # the truncation term is small: the fewest modes are cheapest
    for case in cases.values():
        coupler = coupler_of(case)
        table = grid_table(case)
        per = steps_per_first_period(level, n_load_of(case), top_mode_ratio(level, coupler))
        row = (table["modes"] == 1) & (table["steps_per_first_period"] == per)
        assert robustly_within(table, MARGIN * 0.01)[row].all()
        assert per == needed_steps(table, 1, MARGIN * 0.01)  # the cheapest: nothing to spare


def test_the_fit_s_time_model_recovers_a_noisy_grid_s_time_per_step():
    """Times a x N (1 + 0.1 m) with every other pair timed 3x slow (a busy machine): the
    modelled time is the median time per step with those modes times the steps."""
    from flex.experiments.fitting.calibration import grid_table, modelled_time_s

    def noisy(m, n, n_load):
        return cost(m, n, n_load) * (3.0 if int(math.log2(n)) % 2 else 1.0)

    table = grid_table(_case("noisy", 0.001, step_law_error, noisy))
    modelled = modelled_time_s(table)
    exact = np.array([cost(m, n, 0) for m, n in zip(table["modes"],
                                                      table["steps_per_first_period"],
                                                      strict=True)])
    # 6 steps per mode count, 3 of them 3x slow: the median lies between, at sqrt(3)x
    assert modelled == pytest.approx(exact * math.sqrt(3.0), rel=1e-9)
    assert np.all(np.diff(modelled[table["modes"] == 1]) > 0)  # monotone in the steps


def test_the_law_reaches_each_scene_s_needed_steps_before_rounding():
    """C is the smallest for which the law itself reaches every scene's needed steps: one
    scene sits on the law, and 10 % less C leaves it short of its needed value (before the
    rounding up to the grid, which would hide a shortfall of up to one grid step)."""
    from flex.experiments.fitting.calibration import _step_law

    needed, n_load = np.array([32.0, 16.0, 8.0]), np.array([2.0, 5.0, 30.0])
    law = _step_law(needed, n_load, np.zeros(3), 0.5)
    wanted = law["steps_coefficient"] * n_load ** -law["steps_exponent"]
    assert np.all(wanted >= needed * (1 - 1e-12))
    assert np.any(0.9 * wanted < needed)
    assert all(steps_per_first_period(law, n) >= need for n, need in zip(n_load, needed,
                                                                         strict=True))


def test_a_level_rests_on_the_longest_run_of_scenes_the_grid_can_meet():
    """Ordered by n: three scenes the grid meets, one it cannot (its errors never fall
    within the level), one more it meets: the level keeps the first three, leaves out the
    rest, and so holds only over their n."""
    from flex.experiments.fitting.calibration import grid_table, reachable_run

    def unreachable(m, n, n_load):
        return 0.05

    usable = {}
    for index, t in enumerate((0.0008, 0.001, 0.0015, 0.002, 0.003)):
        error = unreachable if index == 3 else step_law_error
        case = _case(f"t{t}", t, error, cost)
        usable[case.name] = (grid_table(case), float(index + 1), None)
    kept, left = reachable_run(usable, 0.01)
    assert sorted(kept) == ["t0.0008", "t0.001", "t0.0015"]
    assert [text.split()[0] for text in left] == ["t0.002", "t0.003"]


def test_cross_validation_judges_each_scene_by_a_fit_without_it():
    """Four scenes follow one law, a fifth needs 4x the steps: in the fit it is covered
    (the law bends to it), left out it is not: the leave-one-out row says so. A scene at
    either end of n, left out, lies outside the others' range."""
    from flex.experiments.fitting.calibration import cross_validate

    def hard(m, n, n_load):
        return 16.0 * step_law_error(m, n, n_load)

    cases = {f"t{t}": _case(f"t{t}", t, step_law_error, cost)
             for t in (0.001, 0.0015, 0.002, 0.003)}
    cases["hard"] = _case("hard", 0.0025, hard, cost)
    assert all(row["rule_error"] <= 0.01 for row in validate(cases, fit_levels(cases, [0.01]))
               if "rule_error" in row)
    rows = {row["scene"]: row for row in cross_validate(cases, [0.01])}
    assert set(rows) == set(cases)
    assert rows["hard"]["rule_error"] > 0.01 and not rows["hard"]["meets"]
    # the thinnest and thickest left out lie beyond the others' n: judged outside the level
    assert "outside" in rows["t0.001"] and "outside" in rows["t0.003"]


def test_the_local_design_picks_the_cheapest_pair_robust_on_the_nearest_scenes():
    """Left out, the 1 mm scene takes, with one neighbour, the cheapest pair robust on the
    nearest scene (1.2 mm); with two, a pair robust on the far one too, which needs 16x the
    error's steps squared: the pick moves to more steps."""
    from flex.experiments.fitting.calibration import grid_table, modelled_time_s
    from flex.experiments.fitting.rule_designs import neighbour_pick

    def hard(m, n, n_load):
        return 16.0 * step_law_error(m, n, n_load)

    held = _case("t0.001", 0.001, step_law_error, cost)
    near = _case("t0.0012", 0.0012, step_law_error, cost)
    far = _case("far", 0.005, hard, cost)
    others = {"t0.0012": near, "far": far}
    table = grid_table(near)
    ok = robustly_within(table, 0.01)
    cheapest = int(np.flatnonzero(ok)[np.argmin(modelled_time_s(table)[ok])])
    assert neighbour_pick(held, others, 0.01, 1, 1.0) == cheapest
    both = neighbour_pick(held, others, 0.01, 2, 1.0)
    assert robustly_within(grid_table(far), 0.01)[both] and ok[both]
    assert table["steps_per_first_period"][both] > table["steps_per_first_period"][cheapest]
    assert neighbour_pick(held, others, 0.01, 3, 1.0) is None  # only two scenes to ask


def test_every_rule_design_is_judged_on_the_installed_design_s_pairs():
    from flex.experiments.fitting.calibration import cross_validate
    from flex.experiments.fitting.rule_designs import INSTALLED, design_frontier

    cases = {f"t{t}": _case(f"t{t}", t, step_law_error, cost)
             for t in (0.001, 0.0012, 0.0015, 0.002, 0.003)}
    designs = design_frontier(cases, [0.01])
    judged = [row for row in cross_validate(cases, [0.01])
              if "rule_pair" in row and row["certifiable"]]
    assert designs[0]["design"] == INSTALLED and designs[0]["judged"] == len(judged) > 0
    assert designs[0]["meets"] == sum(row["meets"] for row in judged)
    for row in designs:
        assert row["judged"] == len(judged)
        assert row["no_pick"] + row["not_robust"] + row["slower"] + row["meets"] \
            == row["judged"]


def test_near_twins_one_setting_cannot_serve_fast_are_found():
    """Two plates 5 % apart in thickness, one needing 4x the steps of the other (16x the
    error): the pair robust on both is the harder one's, 4x slower on the easier one. A plate
    3x thicker is nobody's twin."""
    from flex.experiments.fitting.rule_designs import near_twins

    def hard(m, n, n_load):
        return 16.0 * step_law_error(m, n, n_load)

    cases = {"a": _case("a", 0.001, step_law_error, cost),
             "b": _case("b", 0.00105, hard, cost),
             "far": _case("far", 0.003, step_law_error, cost)}
    (row,) = near_twins(cases, 0.01)
    assert row["scenes"] == ("a", "b")
    assert row["slowdown"] == pytest.approx(4.0)
    assert row["shared_pair"].startswith("1 modes")


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_the_calibration_summary_stores_and_reports_the_designs_compared():
    from flex.experiments.fitting.calibration_report import calibration_summary
    from flex.experiments.fitting.rule_designs import NEIGHBOUR_MARGINS, NEIGHBOURS

    thicknesses = {f"t{t}": t for t in (0.001, 0.0012, 0.0015, 0.002, 0.003)}
    results = {name: _case(name, t, step_law_error, cost) for name, t in thicknesses.items()}
    scenes = {name: _scene(t) for name, t in thicknesses.items()}
    for name, case in results.items():  # what the report's references table reads
        case.attrs["first_period_s"] = first_period_s(scenes[name]["coupler"])
    datasets, report = calibration_summary(results, {k: scenes[k] for k in list(scenes)[:4]},
                                           {"t0.003": scenes["t0.003"]})
    designs = 1 + len(NEIGHBOURS) * len(NEIGHBOUR_MARGINS)
    assert len(datasets["design_frontier/meets"].data) == designs
    assert "## Rule designs compared" in report and "Near twins" in report
    assert "near_twins/slowdown" in datasets


def test_a_level_too_few_references_can_certify_is_not_fitted():
    levels = fit_levels({"a": _case("a", 0.001, step_law_error, cost,
                                    reference_accuracy=1e-2)}, [1e-3])
    assert all(level["modes"] is None for level in levels)
    assert "at least" in levels[0]["reason"]


def test_a_scene_beyond_the_linear_ffrf_validity_does_not_certify():
    from flex.experiments.fitting.calibration import certifiable

    case = _case("big", 0.001, step_law_error, cost)
    assert certifiable(case, 0.01)
    case.attrs["reference_peak_deflection_m"] = 0.02 * 0.08  # 2 % of the length
    assert not certifiable(case, 0.01)


def test_validation_compares_the_rule_with_the_fastest_robust_pair():
    cases = {"v": _case("v", 0.002, step_law_error, cost)}
    law = {"damping": "undamped", "tolerance": 0.01, "modes": 8, "steps_coefficient": 128.0,
           "steps_exponent": 0.0}
    (row,) = validate(cases, [law])
    assert row["rule_pair"] == "8 modes, T1/128"
    best_modes, best_per = row["best_pair"].split(" modes, T1/")
    assert int(best_modes) == 1 and row["slowdown"] == pytest.approx(
        cost(8, 128, 0) / cost(1, float(best_per), 0))
    assert not row["meets"]  # far slower than needed


def test_rule_extraction_refuses_a_foreign_result_file(tmp_path):
    from flex.data.results import write_results
    from flex.experiments.fitting.calibration_report import extract_rule

    path = write_results(tmp_path / "other.h5", "simulate", [], "")
    rule = tmp_path / "rule.toml"
    rule.write_text("kept")
    with pytest.raises(FlexError, match="not calibrate"):
        extract_rule(path, rule)
    assert rule.read_text() == "kept"


def test_the_installed_damped_levels_are_carried_when_the_fit_has_no_damped_scene():
    """The calibration family is undamped (the stored references' beam has no damping): the
    refit keeps the installed damped levels as they are, and says what moved per level."""
    from flex.experiments.fitting.calibration import carried_levels
    from flex.experiments.fitting.calibration_report import moved_rows

    cases = {f"t{t}": _case(f"t{t}", t, step_law_error, cost)
             for t in (0.001, 0.0012, 0.0015, 0.002)}
    fitted = fit_levels(cases, [0.01])
    installed = rule_constants()["levels"]
    carried = carried_levels(fitted, installed)
    damped = [level for level in installed if level["damping"] == "damped"]
    assert [level["tolerance"] for level in carried] == [level["tolerance"] for level in damped]
    assert all(level["carried"] and level["modes"] == level["modes_max"] for level in carried)
    rows = {(row["damping"], row["tolerance"]): row for row in moved_rows(
        installed, [*fitted, *carried])}
    for level in damped:  # carried: nothing moved
        row = rows[("damped", level["tolerance"])]
        assert row["before"] == row["after"] != "none"
    assert rows[("undamped", 0.01)]["after"].startswith(f"{fitted[0]['modes']} modes")
