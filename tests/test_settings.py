"""Solver settings by model: the bundled scene's "auto" keys (flex/settings.py)."""

from __future__ import annotations

import pytest

from flex.base.errors import SceneError
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


def test_the_certified_plate_gets_the_ffrf_entry():
    scene, choice = resolve_solver_settings(load_scene(None, PLATE))
    assert choice.entry == "ffrf_coupler"
    assert scene["simulation"]["step_s"] == 4e-4
    assert scene["simulation"]["newton"] == "modified"
    assert "357.6 Hz" in choice.reason  # 1 mm steel plate, 80 mm pinned-pinned


@pytest.mark.parametrize("change, why", [
    ("coupler.thickness_m=0.003", "thickness_m = 0.003 (certified: 0.001)"),
    # thinner plates deflect more: 0.3 mm fails Newton at the second 4e-4 s step, 0.5 mm at
    # 21 ms (measured with flex run simulate); they keep the rigid model's step
    ("coupler.thickness_m=0.0005", "thickness_m = 0.0005 (certified: 0.001)"),
    ("coupler.width_m=0.02", "width_m = 0.02 (certified: 0.01)"),
    ("fidelity.tolerance=0.001", "finer than the FFRF coupler's certified 0.01"),
    ('coupler.model="nonlinear_fe"', 'no certified setting for coupler.model = "nonlinear_fe"'),
])
def test_uncertified_flexible_scenes_fall_back_to_the_flexible_entry(change, why):
    scene, choice = resolve_solver_settings(load_scene(None, PLATE + [change]))
    assert choice.entry == "flexible_fallback" and why in choice.reason
    assert scene["simulation"]["step_s"] == 1e-5  # the rigid step, with modified Newton
    assert scene["simulation"]["newton"] == "modified"


def test_mesh_and_modes_are_the_scene_s_choice():
    _, choice = resolve_solver_settings(load_scene(None, PLATE + [
        "coupler.mesh_size_m=0.004", "coupler.modes=2"]))
    assert choice.entry == "ffrf_coupler"


def test_an_ffrf_crank_falls_back_to_the_flexible_entry():
    _, choice = resolve_solver_settings(load_scene(None, [
        'crank.geometry="plate"', 'crank.model="ffrf"']))
    assert choice.entry == "flexible_fallback" and "FFRF crank" in choice.reason


def test_explicit_values_win_and_only_auto_keys_are_filled():
    scene, choice = resolve_solver_settings(load_scene(None, PLATE + [
        "simulation.step_s=1e-4", "simulation.spectral_radius=0.5"]))
    assert scene["simulation"]["step_s"] == 1e-4 and scene["simulation"]["spectral_radius"] == 0.5
    assert set(choice.keys) == {"newton", "newton_relative_tolerance"}
    assert scene["simulation"]["newton"] == "modified"


def test_pinned_overrides_leave_nothing_to_resolve():
    scene = load_scene(None, PLATE + pinned_overrides())
    assert resolve_solver_settings(scene) == (scene, None)
    assert scene["simulation"]["step_s"] == 1e-5


def test_an_output_interval_below_the_chosen_step_is_one_clear_error():
    scene = load_scene(None, PLATE + ["simulation.output_step_s=1e-5"])
    with pytest.raises(SceneError, match=r"output_step_s = 1e-05 must be >= simulation.step_s "
                                         r"= 0.0004.*step_s = \"auto\" chose 0.0004 s"):
        resolve_solver_settings(scene)


def test_auto_is_refused_where_flex_has_no_choice():
    with pytest.raises(SceneError, match=r"simulation.end_time_s = 'auto': must be a finite "
                                         r"number > 0$"):
        load_scene(None, ['simulation.end_time_s="auto"'])
    with pytest.raises(SceneError, match=r'or "auto"'):
        load_scene(None, ["simulation.step_s=-1"])


def test_solver_settings_report_the_resolved_values():
    settings = solver_settings(load_scene(None, PLATE))
    assert settings["step_s"] == 4e-4 and settings["modified_newton"] is True
    assert settings["steps"] == 75


def test_a_default_ffrf_run_uses_and_records_the_chosen_settings(reduction_cache):
    result = simulate(load_scene(None, PLATE + ["simulation.end_time_s=0.004"]), "default",
                      cache_dir=reduction_cache)
    time_s = result.datasets["time"].data
    assert len(time_s) == 11 and time_s[1] - time_s[0] == pytest.approx(4e-4)  # 0.004 s
    assert result.attrs["solver_defaults_entry"] == "ffrf_coupler"
    assert "step_s = 0.0004" in result.attrs["solver_defaults_keys"]
    assert 'step_s = 0.0004' in result.scene_toml and '"auto"' not in result.scene_toml
    assert resolved_simulation(load_scene(None, PLATE))["step_s"] == 4e-4


def test_inspect_shows_the_resolved_solver_keys_and_no_scene_change(tmp_path, capsys,
                                                                   reduction_cache):
    from flex.cli import main
    from flex.data.results import write_results
    from flex.data.scene import to_toml

    scene = load_scene(None, PLATE + ["simulation.end_time_s=0.004"])
    case = simulate(scene, "default", cache_dir=reduction_cache)
    path = write_results(tmp_path / "auto.h5", "simulate", [case], to_toml(scene))
    assert main(["inspect", str(path)]) == 0
    out = capsys.readouterr().out
    assert 'solver: "auto" -> step_s = 0.0004' in out and "(ffrf_coupler: " in out
    assert "the file's scene with" not in out  # flex's choices are not the user's changes


def test_flex_scene_says_what_auto_resolves_to(capsys):
    import tomllib

    from flex.cli import main

    assert main(["scene", "simulate", "--set", 'coupler.geometry="plate"',
                 "--set", 'coupler.model="ffrf"']) == 0
    out = capsys.readouterr().out
    assert out.startswith('# [simulation] "auto" keys -> step_s = 0.0004')
    assert tomllib.loads(out)["simulation"]["step_s"] == "auto"  # still valid TOML
    assert main(["scene", "simulate", "--set", 'coupler.geometry="plate"',
                 "--set", 'coupler.model="auto"']) == 0
    assert "chosen at run time" in capsys.readouterr().out
