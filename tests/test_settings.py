"""Solver settings by model: the bundled scene's "auto" keys (flex/config/settings.py)."""

from __future__ import annotations

import math
import re

import pytest

from flex.base.errors import SceneError
from flex.config.ffrf_rule import (
    level_for,
    level_modes,
    load_time_scale_s,
    steps_per_first_period,
    top_mode_ratio,
)
from flex.config.settings import (
    AUTO_KEYS,
    pinned_overrides,
    resolve_solver_settings,
    resolved_simulation,
    solver_defaults,
)
from flex.data.scene import load_scene
from flex.dynamics.solver import solver_settings
from flex.fidelity.simulation import simulate

PLATE = ['coupler.geometry="plate"', 'coupler.model="ffrf"']


def test_bundled_scene_leaves_the_solver_keys_to_flex():
    sim = load_scene()["simulation"]
    assert all(sim[key] == "auto" for key in AUTO_KEYS)


def test_rigid_links_get_the_rigid_entry():
    scene, choice = resolve_solver_settings(load_scene())
    assert choice.entry == "rigid"
    expected = solver_defaults()["rigid"]
    assert {key: scene["simulation"][key] for key in AUTO_KEYS} == {
        key: expected[key] for key in AUTO_KEYS}
    assert scene["simulation"]["step_s"] == 1e-5  # the thesis table's grid


def _rule_step(thickness_m=0.001, tolerance=0.01):
    """The step the rule should give an 80 mm steel plate: T1 / N of the level (closed form
    pinned-pinned period, independent of flex.config.ffrf_rule), rounded down to the largest
    step that divides the bundled end time into a whole number of 4 steps; the level and
    n = t_load / T1."""
    omega = (math.pi / 0.080) ** 2 * math.sqrt(200e9 * thickness_m**2 / 12 / 7850.0)
    level = level_for(tolerance)
    scene = load_scene(None, PLATE + [f"coupler.thickness_m={thickness_m}"])
    n_load = load_time_scale_s(scene) * omega / (2 * math.pi)
    per = steps_per_first_period(level, n_load, top_mode_ratio(level, scene["coupler"], n_load))
    step = 2 * math.pi / omega / per
    end = scene["simulation"]["end_time_s"]
    return end / (4 * math.ceil(end / (4 * step))), level, n_load


def test_an_ffrf_coupler_gets_the_rule_s_step_modes_and_mesh():
    scene, choice = resolve_solver_settings(load_scene(None, PLATE))
    step, level, n_load = _rule_step()
    assert choice.entry == "ffrf_rule" and choice.accuracy == level["tolerance"]
    assert scene["simulation"]["step_s"] == pytest.approx(step, rel=1e-9)
    assert scene["simulation"]["newton"] == "modified"
    assert scene["coupler"]["modes"] == level_modes(level, scene["coupler"], n_load)
    assert scene["coupler"]["mesh_size_m"] == pytest.approx(0.002)  # min(2 t, L / 16)
    assert choice.keys["coupler.modes"] == scene["coupler"]["modes"]
    assert "T1 = 0.002796 s" in choice.reason  # 357.6 Hz: 1 mm steel, 80 mm pinned-pinned


@pytest.mark.parametrize("thickness_m, mesh_m", [(0.003, 0.005), (0.005, 0.005)])
def test_the_rule_scales_with_the_plate(thickness_m, mesh_m):
    scene, choice = resolve_solver_settings(load_scene(None, PLATE + [
        f"coupler.thickness_m={thickness_m}"]))
    step = _rule_step(thickness_m)[0]
    assert choice.entry == "ffrf_rule"
    assert scene["simulation"]["step_s"] == pytest.approx(step, rel=1e-9)
    assert scene["coupler"]["mesh_size_m"] == pytest.approx(mesh_m)  # L / 16 caps 2 t


@pytest.mark.parametrize("change, why", [
    # 0.2 mm: L / t = 400, beyond the calibrated slenderness
    ("coupler.thickness_m=0.0002", "outside the calibrated family (length_m / thickness_m"),
    ("fidelity.tolerance=1e-5", "finer than the finest calibrated level"),
    # 10 mm undamped on an 800 N/m spring: n = t_load / T1 = 64 beyond the 1 % level's
    # calibration scenes (the 10 mm plate on the thesis spring, n = 47, is one of them)
    ("coupler.thickness_m=0.01 drive.spring_stiffness_N_per_m=800.0",
     "of level 0.01's calibration scenes"),
    ('coupler.model="nonlinear_fe"', 'no calibrated rule for coupler.model = "nonlinear_fe"'),
])
def test_flexible_scenes_outside_the_rule_fall_back_visibly(change, why):
    scene, choice = resolve_solver_settings(load_scene(None, PLATE + change.split()))
    assert choice.entry == "flexible_fallback" and why in choice.reason
    assert scene["simulation"]["step_s"] == 1e-5  # the rigid step, with modified Newton
    assert scene["simulation"]["newton"] == "modified"


def test_mesh_and_modes_given_by_the_scene_are_kept():
    scene, choice = resolve_solver_settings(load_scene(None, PLATE + [
        "coupler.mesh_size_m=0.004", "coupler.modes=12"]))
    assert choice.entry == "ffrf_rule"
    assert scene["coupler"]["modes"] == 12 and scene["coupler"]["mesh_size_m"] == 0.004
    assert "coupler.modes = 12 is more than the rule's" in choice.reason


def test_an_ffrf_crank_falls_back_to_the_flexible_entry():
    _, choice = resolve_solver_settings(load_scene(None, [
        'crank.geometry="plate"', 'crank.model="ffrf"']))
    assert choice.entry == "flexible_fallback" and "FFRF crank" in choice.reason


def test_explicit_values_win_and_only_auto_keys_are_filled():
    scene, choice = resolve_solver_settings(load_scene(None, PLATE + [
        "simulation.step_s=1e-4", "simulation.spectral_radius=0.5"]))
    assert scene["simulation"]["step_s"] == 1e-4 and scene["simulation"]["spectral_radius"] == 0.5
    assert set(choice.keys) == {"newton", "newton_relative_tolerance", "coupler.modes",
                                "coupler.mesh_size_m"}
    assert scene["simulation"]["newton"] == "modified"


def test_pinned_overrides_leave_nothing_to_resolve():
    scene = load_scene(None, PLATE + pinned_overrides())
    assert resolve_solver_settings(scene) == (scene, None)
    assert scene["simulation"]["step_s"] == 1e-5


def test_an_output_interval_below_the_chosen_step_is_one_clear_error():
    scene = load_scene(None, PLATE + ["simulation.output_step_s=1e-6"])
    step = re.escape(f"{_rule_step()[0]:g}")
    with pytest.raises(SceneError, match=rf"output_step_s = 1e-06 must be >= simulation.step_s "
                                         rf"= {step}.*step_s = \"auto\" chose {step} s"):
        resolve_solver_settings(scene)


def test_auto_is_refused_where_flex_has_no_choice():
    with pytest.raises(SceneError, match=r"simulation.end_time_s = 'auto': must be a finite "
                                         r"number > 0$"):
        load_scene(None, ['simulation.end_time_s="auto"'])
    with pytest.raises(SceneError, match=r'or "auto"'):
        load_scene(None, ["simulation.step_s=-1"])


def test_solver_settings_report_the_resolved_values():
    from flex.fidelity.auto import resolve

    settings = solver_settings(resolve(load_scene(None, PLATE)).scene)
    step = _rule_step()[0]
    assert settings["step_s"] == pytest.approx(step, rel=1e-9)
    assert settings["modified_newton"] is True
    assert settings["steps"] == round(0.03 / step)


def test_a_default_ffrf_run_uses_and_records_the_chosen_settings(reduction_cache):
    step = _rule_step()[0]
    # without a budget: the run itself is the case (with one, its step's finest companion)
    result = simulate(load_scene(None, PLATE + [f"simulation.end_time_s={12 * step!r}",
                                                "simulation.error_estimate=false"]),
                      "default", cache_dir=reduction_cache)
    time_s = result.datasets["time"].data
    assert len(time_s) == 13 and time_s[1] - time_s[0] == pytest.approx(step)
    assert result.attrs["solver_defaults_entry"] == "ffrf_rule"
    assert f"step_s = {step!r}" in result.attrs["solver_defaults_keys"]
    assert f"step_s = {step!r}" in result.scene_toml and '"auto"' not in result.scene_toml
    assert resolved_simulation(load_scene(None, PLATE))["step_s"] == pytest.approx(step)


def test_inspect_shows_the_resolved_solver_keys_and_no_scene_change(tmp_path, capsys,
                                                                   reduction_cache):
    from flex.cli import main
    from flex.data.results import write_results
    from flex.data.scene import to_toml

    step = _rule_step()[0]
    scene = load_scene(None, PLATE + [f"simulation.end_time_s={12 * step!r}"])
    case = simulate(scene, "default", cache_dir=reduction_cache)
    path = write_results(tmp_path / "auto.h5", "simulate", [case], to_toml(scene))
    assert main(["inspect", str(path)]) == 0
    out = capsys.readouterr().out
    assert 'solver: "auto" -> coupler.modes = ' in out and f"step_s = {step!r}" in out
    assert "(ffrf_rule: " in out
    assert "the file's scene with" not in out  # flex's choices are not the user's changes


def test_flex_scene_says_what_auto_resolves_to(capsys):
    import tomllib

    from flex.cli import main

    assert main(["scene", "simulate", "--set", 'coupler.geometry="plate"',
                 "--set", 'coupler.model="ffrf"']) == 0
    out = capsys.readouterr().out
    head = out.splitlines()[0]
    assert head.startswith('# [simulation] "auto" keys -> coupler.modes = ')
    assert f"step_s = {_rule_step()[0]!r}" in head
    assert tomllib.loads(out)["simulation"]["step_s"] == "auto"  # still valid TOML
    assert main(["scene", "simulate", "--set", 'coupler.geometry="plate"',
                 "--set", 'coupler.model="auto"']) == 0
    assert "chosen at run time" in capsys.readouterr().out


def test_one_simulate_resolves_each_scene_once(monkeypatch, reduction_cache):
    """flex.fidelity.auto.resolve is the one place "auto" is decided: one simulate() of an
    FFRF coupler with "auto" modes, mesh and solver keys (its error budget's companion runs
    included) resolves the scene once, the rigid probe's scene once, nothing below it."""
    import flex.config.settings as settings
    from flex.data.scene import to_toml
    from flex.fidelity import auto
    from flex.fidelity.simulation import simulate

    seen = {"resolve": 0, "solver": [], "links": []}
    real_resolve, real_solver = auto.resolve, settings.resolve_solver_settings
    real_links = settings.resolve_link_keys

    def counting_resolve(*args, **kwargs):
        seen["resolve"] += 1
        return real_resolve(*args, **kwargs)

    def counting_solver(scene, calibration=None, **kwargs):
        seen["solver"].append(to_toml(scene))
        return real_solver(scene, calibration, **kwargs)

    def counting_links(scene, calibration=None, **kwargs):
        seen["links"].append(to_toml(scene))
        return real_links(scene, calibration, **kwargs)

    monkeypatch.setattr("flex.fidelity.simulation.resolve", counting_resolve)
    monkeypatch.setattr("flex.fidelity.auto.resolve_solver_settings", counting_solver)
    monkeypatch.setattr("flex.config.settings.resolve_link_keys", counting_links)
    monkeypatch.setattr("flex.fidelity.auto.resolve_link_keys", counting_links)
    # 0.6 mm: auto takes the FFRF body at 0.55 % (tests/test_criteria.py)
    scene = load_scene(None, PLATE + ['coupler.model="auto"', "coupler.thickness_m=0.0006",
                                      "coupler.mesh_size_m=0.005", "coupler.modes=2",
                                      "fidelity.tolerance=0.0055",
                                      "simulation.end_time_s=0.002"])
    result = simulate(scene, cache_dir=reduction_cache)
    assert result.attrs["fidelity_coupler_model"] == "ffrf"
    assert "coupler" in result.attrs["estimated_error_method"]  # FFRF companions ran
    assert seen["resolve"] == 1
    assert seen["solver"] and len(seen["solver"]) == len(set(seen["solver"]))
    assert len(seen["links"]) == len(set(seen["links"]))
