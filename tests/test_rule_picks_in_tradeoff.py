"""The tradeoff study runs what flex's FFRF rule picks per accuracy level, and its report and
figures mark those picks (flex.experiments.workprecision.defaults_check,
flex.experiments.workprecision.tradeoff_report).

Nothing here simulates: the rule's picks are resolved, the measurements are synthetic."""

from __future__ import annotations

import matplotlib.figure
import numpy as np
import pytest

import studies.tradeoff as study
from flex.base.plotting import review
from flex.config.ffrf_rule import pick
from flex.config.settings import resolve_solver_settings
from flex.data.results import Dataset
from flex.data.scene import Scene, load_scene
from flex.experiments.workprecision.measurement import (
    Measurement,
    Observables,
    ReductionPool,
    Reference,
    Setting,
    scene_for,
)
from flex.experiments.workprecision.pareto import pareto_front
from flex.experiments.workprecision.rule_check import (
    RULE_GROUP,
    RULE_LEVELS,
    rule_level,
    rule_run,
    rule_settings,
)
from flex.experiments.workprecision.tradeoff import SceneRuns
from flex.experiments.workprecision.tradeoff_report import (
    measurements_table,
    summarize_work_precision,
    work_precision_figures,
)

FFRF_SCENES = ("ffrf_1mm", "ffrf_10mm")


@pytest.fixture(scope="module")
def case_scenes() -> dict[str, Scene]:
    return study.cases(load_scene(overrides=study.OVERRIDES))


def _rule_settings_of(scene_name: str, scene: Scene) -> list[Setting]:
    return [s for s in study.settings(scene_name, False, scene) if s.group == RULE_GROUP]


@pytest.mark.parametrize("scene_name", FFRF_SCENES)
def test_ffrf_scenes_run_what_the_rule_picks_per_level(case_scenes, scene_name):
    scene = case_scenes[scene_name]
    rules = _rule_settings_of(scene_name, scene)
    assert [rule_level(s) for s in rules] == list(RULE_LEVELS)
    for setting in rules:
        level = rule_level(setting)
        asked = scene_for(scene, setting)
        assert asked["fidelity"]["tolerance"] == level
        assert asked["coupler"]["modes"] == "auto" and asked["simulation"]["step_s"] == "auto"
        resolved = resolve_solver_settings(asked)[0]
        chosen = pick(asked, level)  # independently of the study's resolution
        assert resolved["coupler"]["modes"] == chosen.modes
        assert resolved["coupler"]["mesh_size_m"] == pytest.approx(chosen.mesh_size_m)
        assert ("fallback" in setting.label) == (chosen.level is None)
        if chosen.step_s is not None:  # rounded down to whole steps in the end time
            assert resolved["simulation"]["step_s"] <= chosen.step_s * (1 + 1e-9)
            assert resolved["simulation"]["step_s"] == pytest.approx(chosen.step_s, rel=0.05)
        assert all(resolved["simulation"][key] != "auto"
                   for key in ("step_s", "spectral_radius", "newton"))


def test_the_rigid_scene_has_no_rule_setting(case_scenes):
    assert not _rule_settings_of("rigid", case_scenes["rigid"])


def test_the_reduction_pool_keys_auto_modes_by_the_rule(case_scenes, monkeypatch):
    # a rule setting's reduction is the one the run resolves, not one shared by all "auto"s
    monkeypatch.setattr("flex.dynamics.link_models.reduction_for_scene",
                        lambda scene, cache_dir=None, mesh_order=2, solve_modes=None: (
                            scene["coupler"]["modes"], scene["coupler"]["mesh_size_m"]))
    scene = case_scenes["ffrf_1mm"]
    pool = ReductionPool()
    for setting in rule_settings(scene):
        run = rule_run(scene, rule_level(setting))
        built = pool.for_scene(scene_for(scene, setting))
        assert built == (run.modes, pytest.approx(run.mesh_size_m))


def _measurement(setting: Setting, wall: float, error: float) -> Measurement:
    return Measurement(setting, wall_time_s=wall, wall_times_s=[wall], errors={"error": error})


def _reference(accuracy: float) -> Reference:
    zeros = np.zeros(3)
    observables = Observables(np.arange(3.0), zeros, zeros, np.array([0.0, 1e-4, 0.0]))
    return Reference("synthetic", observables, Setting("fine"), {"step": {"error": accuracy}},
                     1e-2, 0.0)


def test_the_report_states_where_the_rule_picks_sit(case_scenes):
    scene = case_scenes["ffrf_1mm"]
    one, tenth = rule_settings(scene)
    runs = [_measurement(Setting.of("coarse", step_s=4e-4), 0.010, 5e-3),
            _measurement(one, 0.020, 4e-3),
            _measurement(Setting.of("fine", step_s=1e-5), 0.030, 8e-4),
            _measurement(tenth, 0.050, 9e-4)]  # beaten by "fine": off the front
    datasets, report = summarize_work_precision(
        {"ffrf_1mm": SceneRuns(_reference(1e-4), runs, 0.0)}, {"ffrf_1mm": scene})
    rule = {key.split("/rule/")[1]: value for key, value in datasets.items()
            if key.startswith("ffrf_1mm/rule/")}
    assert list(rule["setting"].data) == [one.label, tenth.label]
    assert list(rule["on_pareto_front"].data) == [True, False]
    assert list(rule["within_level"].data) == [True, True]
    assert list(rule["fastest_within_setting"].data) == ["coarse", "fine"]
    np.testing.assert_allclose(rule["slowdown"].data, [0.020 / 0.010, 0.050 / 0.030])
    fallback = [pick(scene_for(scene, s), rule_level(s)).level is None for s in (one, tenth)]
    assert list(rule["fallback"].data) == fallback
    assert rule["wall_time"].units == "s" and rule["step"].units == "s"
    assert rule["mesh_size"].units == "m" and rule["slowdown"].units == "1"
    assert all(isinstance(value, Dataset) and value.description for value in rule.values())
    assert "rule 1 %" in report and "rule 0.1 %" in report
    assert ("FALLBACK" in report) == any(fallback)
    # no rule settings: nothing stored
    plain, _ = summarize_work_precision(
        {"ffrf_1mm": SceneRuns(_reference(1e-4), runs[::2], 0.0)}, {"ffrf_1mm": scene})
    assert not any("/rule/" in key for key in plain)


def test_the_figure_marks_the_rule_picks(tmp_path, monkeypatch):
    saved: list = []
    save = matplotlib.figure.Figure.savefig

    def checked(self, path, *args, **kwargs):
        saved.append((self, review(self)))
        return save(self, path, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", checked)
    runs = [_measurement(Setting(f"run {i}"), wall, error)
            for i, (wall, error) in enumerate([(1e-3, 1e-2), (1e-2, 1e-3), (1e-1, 1e-4)])]
    points = [(m.wall_time_s, m.error) for m in runs]
    datasets = {f"demo/runs/{key}": value
                for key, value in measurements_table(runs, pareto_front(points)).items()}
    datasets.update({
        "demo/rule/level": Dataset(np.array([1e-2, 1e-3]), "1", "level"),
        "demo/rule/wall_time": Dataset(np.array([2e-3, 1e-1]), "s", "wall time"),
        "demo/rule/error": Dataset(np.array([5e-3, 5e-4]), "1", "error"),
        "demo/rule/fallback": Dataset(np.array([False, True]), "1", "fallback")})
    paths = work_precision_figures(datasets, tmp_path)
    assert [path.name for path in paths] == ["tradeoff-demo.png"]
    (fig, problems), = saved
    assert not problems
    ax = fig.axes[0]
    stars = [line for line in ax.get_lines() if line.get_marker() == "*"]
    assert len(stars) == 2
    texts = [text.get_text() for text in ax.texts]
    assert "rule 1 %" in texts and "rule 0.1 % (fallback)" in texts
