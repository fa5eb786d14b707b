"""Whether flex's bundled solver defaults are what the work-precision runs measured as fastest.

The setting labelled :data:`DEFAULT_LABEL` is what a user gets: the bundled scene's ``"auto"``
solver keys (:data:`flex.config.settings.AUTO_OVERRIDES`), which :mod:`flex.config.settings` fills
from
``flex/solver_defaults.toml`` (README "Defaults"). On the 1 mm FFRF plate (the bundled 2 mm
mesh and 6 modes) they resolve to its ``ffrf_coupler`` entry, the certified 1 % pick
h = 4e-4 s, modified Newton 1e-8; on the rigid scene to the ``rigid`` entry.
:func:`ffrf_defaults_check` and :func:`rigid_defaults_check` store whether a run confirms
both (``<scene>/default/matches_table``): within the tolerance (certified) and no slower than
the run's pick by more than :data:`DEFAULT_TIE` (two runs of make tradeoff swapped the 2 mm and
4 mm meshes at h = 4e-4 s: 83 / 62 ms, then 63 / 70 ms); tests/test_tradeoff.py checks that it
reaches the tolerance, and how much faster it is than the rigid-model settings.

The settings labelled ``flex rule (<level> %)`` (group :data:`RULE_GROUP`, :func:`rule_settings`)
are what a user gets by asking flex for an accuracy: the coupler's modes and mesh and the solver
keys ``"auto"`` at ``fidelity.tolerance`` = the level, filled by the calibrated rule
(:mod:`flex.config.ffrf_rule`) or, outside its calibrated family, by the flexible fallback
(then labelled ``fallback``). :func:`rule_check` stores where each sits among the measured runs
(``<scene>/rule/...``): its error against the level, its time, whether it is on the Pareto
front and its slowdown against the fastest run within the level.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.config.ffrf_rule import LINK_KEYS, pick
from flex.config.settings import AUTO_OVERRIDES, resolve_solver_settings
from flex.data.results import Dataset
from flex.data.scene import Scene
from flex.experiments.tradeoff import (
    Measurement,
    Reference,
    Setting,
    certifies,
    describe,
    fastest,
    recommend,
    scene_for,
)

DEFAULT_LABEL = "flex defaults (auto)"
#: the default scene's tolerance, as the test suite holds it to the reference DAE (crank angle
#: 1e-6 rad, slider 1e-7 m) on the 1e-5 s output grid of the thesis table (README); and
#: robust: spectral radius below 1 (with rho = 1 the index-3 integrator leaves its algebraic
#: modes undamped and Newton failed after 0.78 s of free motion: make stability)
DEFAULT_TOLERANCE = {"crank_angle_rad": 1e-6, "slider_position_m": 1e-7, "max_step_s": 1e-5,
                     "max_spectral_radius": 0.95}
#: timing noise between runs on the shared machine: a setting this much slower than the pick
#: still counts as equally fast for the defaults check
DEFAULT_TIE = 0.5


def default_setting() -> Setting:
    """The bundled scene's solver keys ("auto"): what a user gets."""
    return Setting(DEFAULT_LABEL, AUTO_OVERRIDES, group="flex defaults")


def is_default(setting: Setting) -> bool:
    """Whether ``setting`` is the bundled scene's solver settings (all keys "auto")."""
    return setting.engine == "exudyn" and setting.overrides == AUTO_OVERRIDES


def same_discretization(plate_scene: Scene, setting: Setting) -> bool:
    """Whether ``setting`` runs the plate scene's own mesh, modes and element order."""
    try:
        scene = scene_for(plate_scene, setting)
    except SceneError:
        return False
    return (setting.element_order == 2 and scene["coupler"]["model"] == "ffrf"
            and all(scene["coupler"][key] == plate_scene["coupler"][key]
                    for key in ("mesh_size_m", "modes")))


def within_default_tolerance(m: Measurement, base: Scene) -> bool:
    """Whether a run of the rigid scene ``base`` (solver keys pinned) meets
    :data:`DEFAULT_TOLERANCE` ("auto" keys resolved)."""
    limit = DEFAULT_TOLERANCE
    if not (m.ok and m.setting.engine == "exudyn"):
        return False
    sim = resolve_solver_settings(scene_for(base, m.setting))[0]["simulation"]
    return (m.errors["crank_angle_rad"] <= limit["crank_angle_rad"]
            and m.errors["slider_position_m"] <= limit["slider_position_m"]
            and sim["step_s"] <= limit["max_step_s"] * (1 + 1e-9)
            and sim["spectral_radius"] <= limit["max_spectral_radius"])


def default_recommendation(measurements: Sequence[Measurement], base: Scene
                           ) -> Measurement | None:
    """The fastest Exudyn setting meeting :data:`DEFAULT_TOLERANCE` on the rigid scene
    ``base``."""
    within = [m for m in measurements if within_default_tolerance(m, base)]
    return fastest(within) if within else None


def _verdict(matches: bool) -> str:
    return "confirmed" if matches else "NOT confirmed"


def rigid_defaults_check(group: str, measurements: Sequence[Measurement], base: Scene
                         ) -> tuple[dict[str, Dataset], list[str]]:
    """``<group>/default/...`` datasets and report lines: the fastest run within
    :data:`DEFAULT_TOLERANCE` and whether the defaults' run matches it."""
    best = default_recommendation(measurements, base)
    table = [m for m in measurements if m.ok and is_default(m.setting)]
    matches = bool(best and table and within_default_tolerance(table[0], base)
                   and table[0].wall_time_s <= (1 + DEFAULT_TIE) * best.wall_time_s)
    datasets = {
        f"{group}/default/setting": Dataset(
            best.setting.label if best else "", "1",
            "fastest setting within the default scene's tolerance (DEFAULT_TOLERANCE)"),
        f"{group}/default/knobs": Dataset(repr(best.setting.knobs()) if best else "", "1",
                                          "its knobs"),
        f"{group}/default/matches_table": Dataset(
            matches, "1", f"the defaults are within DEFAULT_TOLERANCE and at most "
                          f"{DEFAULT_TIE:g} x slower than the pick")}
    return datasets, [f"    default scene tolerance {DEFAULT_TOLERANCE}: {describe(best)}; "
                      f"defaults {describe(table[0]) if table else 'not run'}: "
                      f"{_verdict(matches)}"]


def ffrf_defaults_check(group: str, measurements: Sequence[Measurement],
                        reference: Reference, plate_scene: Scene
                        ) -> tuple[dict[str, Dataset], list[str]]:
    """``<group>/default/...`` datasets and report lines: the fastest certified run within
    the plate scene's ``fidelity.tolerance`` on its own mesh and modes (the solver defaults
    are for the scene's own discretization), on any, and whether the defaults' run is
    certified within it and at most :data:`DEFAULT_TIE` slower than the pick."""
    level = float(plate_scene["fidelity"]["tolerance"])
    resolved = resolve_solver_settings(scene_for(plate_scene, default_setting()))[1]
    pick = recommend(measurements, reference, [level],
                     eligible=lambda m: m.setting.engine == "exudyn"
                     and same_discretization(plate_scene, m.setting))[0]
    coarser = recommend(measurements, reference, [level],
                        eligible=lambda m: m.setting.engine == "exudyn")[0]
    table = [m for m in measurements if m.ok and is_default(m.setting)]
    matches = bool(pick.measurement and table
                   and table[0].error + reference.accuracy <= level
                   and table[0].wall_time_s <= (1 + DEFAULT_TIE) * pick.measurement.wall_time_s)
    datasets = {
        f"{group}/default/level": Dataset(level, "1", "the scene's tolerance"),
        f"{group}/default/setting": Dataset(
            pick.measurement.setting.label if pick.measurement else "", "1",
            f"fastest certified setting within it ({pick.reason or 'certified'})"),
        f"{group}/default/table_setting": Dataset(
            f"{DEFAULT_LABEL}: {resolved.keys if resolved else ''}", "1",
            "what the bundled scene's solver keys resolve to (flex/solver_defaults.toml)"),
        f"{group}/default/matches_table": Dataset(
            matches, "1", f"the defaults are within the tolerance (certified) and at most "
                          f"{DEFAULT_TIE:g} x slower than the pick"),
        f"{group}/default/any_discretization_setting": Dataset(
            coarser.measurement.setting.label if coarser.measurement else "", "1",
            "fastest certified setting within it on any mesh and modes")}
    return datasets, [f"    scene tolerance {level:g}, scene's mesh and modes: "
                      f"{describe(pick.measurement)}; defaults "
                      f"{describe(table[0]) if table else 'not run'}: {_verdict(matches)}; "
                      f"on any mesh and modes: {describe(coarser.measurement)}"]


# ------------------------------------------------------------------------------------------
# the rule's picks: what flex runs when asked for an accuracy
# ------------------------------------------------------------------------------------------
RULE_GROUP = "flex rule"
#: the accuracy levels (``fidelity.tolerance``, relative) at which the study asks flex for the
#: rule's settings: 1 % and 0.1 %, the levels of the study's recommendations the rule is
#: calibrated towards (0.01 % is beyond both its calibration and the study's FFRF references)
RULE_LEVELS = (1e-2, 1e-3)
#: the coupler keys the rule fills, left to flex
RULE_LINK_OVERRIDES = tuple((f"coupler.{key}", "auto") for key in LINK_KEYS)


@dataclass(frozen=True)
class RuleRun:
    """What flex runs on a plate scene asked for ``level`` (relative): the resolved
    ``step_s`` [s], coupler ``modes`` and ``mesh_size_m`` [m]; ``fallback``: the rule does
    not cover the scene at that level (:attr:`flex.config.ffrf_rule.RulePick.level` None) and
    flex falls back; ``reason``: the rule's sentence."""

    level: float
    step_s: float
    modes: int
    mesh_size_m: float
    fallback: bool
    reason: str


def rule_overrides(level: float) -> tuple[tuple[str, Any], ...]:
    """Coupler modes and mesh, solver keys ``"auto"`` and ``fidelity.tolerance = level``."""
    return RULE_LINK_OVERRIDES + AUTO_OVERRIDES + (("fidelity.tolerance", float(level)),)


def rule_run(plate_scene: Scene, level: float) -> RuleRun:
    """What flex fills in on ``plate_scene`` (an FFRF plate coupler) asked for ``level``
    (:func:`flex.config.settings.resolve_solver_settings`, :func:`flex.config.ffrf_rule.pick`).
    """
    scene = scene_for(plate_scene, Setting("rule", rule_overrides(level)))
    resolved = resolve_solver_settings(scene)[0]
    chosen = pick(scene, level)
    return RuleRun(level, float(resolved["simulation"]["step_s"]),
                   int(resolved["coupler"]["modes"]), float(resolved["coupler"]["mesh_size_m"]),
                   chosen.level is None, chosen.reason)


def rule_label(level: float, fallback: bool) -> str:
    """``"flex rule (1 %)"``, ``"flex rule (0.1 %, fallback)"``."""
    return f"flex rule ({level * 100:g} %{', fallback' if fallback else ''})"


def rule_settings(plate_scene: Scene, levels: Sequence[float] = RULE_LEVELS) -> list[Setting]:
    """One setting per accuracy level: what a user of ``plate_scene`` gets by asking flex for
    it (:func:`rule_overrides`), labelled a fallback where the rule does not cover it."""
    return [Setting(rule_label(level, rule_run(plate_scene, level).fallback),
                    rule_overrides(level), group=RULE_GROUP) for level in levels]


def rule_level(setting: Setting) -> float | None:
    """The accuracy level (relative) a rule setting asks for; None for other settings."""
    if setting.group != RULE_GROUP:
        return None
    return float(dict(setting.overrides)["fidelity.tolerance"])


def _quickest_within(measurements: Sequence[Measurement], level: float) -> Measurement | None:
    """The fastest ``ok`` Exudyn run whose measured error is within ``level``."""
    within = [m for m in measurements
              if m.ok and m.setting.engine == "exudyn" and m.error <= level]
    return min(within, key=lambda m: m.wall_time_s) if within else None


def _rule_row(m: Measurement, level: float, measurements: Sequence[Measurement],
              reference: Reference, on_front: bool, plate_scene: Scene) -> dict[str, Any]:
    """One rule run's row of :func:`rule_check` (errors relative, times in s)."""
    run = rule_run(plate_scene, level)
    quickest = _quickest_within(measurements, level)
    return {"level": level, "setting": m.setting.label, "fallback": run.fallback,
            "reason": run.reason, "step": run.step_s, "modes": run.modes,
            "mesh_size": run.mesh_size_m, "status": m.status, "error": m.error,
            "wall_time": m.wall_time_s, "within_level": m.ok and m.error <= level,
            "certified": m.ok and certifies(reference.accuracy, level)
            and m.error + reference.accuracy <= level, "on_pareto_front": on_front,
            "fastest_within_setting": quickest.setting.label if quickest else "",
            "fastest_within_wall_time": quickest.wall_time_s if quickest else math.nan,
            "slowdown": m.wall_time_s / quickest.wall_time_s if m.ok and quickest
            else math.nan}


#: ``<scene>/rule/<column>``: units and description of each column of :func:`rule_check`
RULE_COLUMNS = {
    "level": ("1", "fidelity.tolerance flex was asked for (relative accuracy level)"),
    "setting": ("1", "the rule setting's label"),
    "fallback": ("1", "outside the rule's calibrated family: flex's flexible fallback"),
    "reason": ("1", "the rule's reason (flex.config.ffrf_rule.pick)"),
    "step": ("s", "time step flex chose"),
    "modes": ("1", "coupler modes flex chose"),
    "mesh_size": ("m", "coupler mesh size flex chose"),
    "status": ("1", "ok | failed"),
    "error": ("1", "measured largest relative error"),
    "wall_time": ("s", "median integration wall time"),
    "within_level": ("1", "measured error <= level"),
    "certified": ("1", "error + reference accuracy <= level, and the reference certifies it"),
    "on_pareto_front": ("1", "not beaten in both wall time and error by any run"),
    "fastest_within_setting": ("1", "fastest Exudyn run with measured error <= level"),
    "fastest_within_wall_time": ("s", "its median integration wall time"),
    "slowdown": ("1", "rule run's wall time / the fastest within the level's"),
}


def _rule_line(row: dict[str, Any]) -> str:
    """Report line of one rule row."""
    head = (f"    rule {row['level'] * 100:g} %{' FALLBACK' if row['fallback'] else ''}: "
            f"h = {row['step']:.3g} s, {row['modes']} mode{'' if row['modes'] == 1 else 's'}, mesh "
            f"{row['mesh_size'] * 1e3:.3g} mm")
    if row["status"] != "ok":
        return head + " -> failed" + (f" ({row['reason']})" if row["fallback"] else "")
    verdict = "within" if row["within_level"] else "NOT within"
    text = (f"{head} -> error {row['error']:.1e} ({verdict} {row['level']:g}"
            f"{', certified' if row['certified'] else ''}), {row['wall_time'] * 1e3:.1f} ms, "
            f"{'on' if row['on_pareto_front'] else 'off'} the Pareto front, ")
    text += (f"{row['slowdown']:.2f} x the fastest run within the level "
             f"({row['fastest_within_setting']}, {row['fastest_within_wall_time'] * 1e3:.1f} "
             f"ms)" if row["fastest_within_setting"] else "no run reaches the level")
    return text + (f"\n      ({row['reason']})" if row["fallback"] else "")


def rule_check(group: str, measurements: Sequence[Measurement], reference: Reference,
               front: Collection[int], plate_scene: Scene | None
               ) -> tuple[dict[str, Dataset], list[str]]:
    """``<group>/rule/...`` datasets (:data:`RULE_COLUMNS`, one row per rule setting) and
    report lines: where each rule pick sits among ``measurements`` (``front``: the indices on
    the Pareto front of all runs). Empty without rule settings."""
    rows = [_rule_row(m, level, measurements, reference, i in front, plate_scene)
            for i, m in enumerate(measurements)
            if (level := rule_level(m.setting)) is not None and plate_scene is not None]
    if not rows:
        return {}, []
    datasets = {f"{group}/rule/{key}": Dataset(
        np.array([row[key] for row in rows],
                 dtype=object if isinstance(rows[0][key], str) else None), units, text)
        for key, (units, text) in RULE_COLUMNS.items()}
    return datasets, ["    flex rule picks (fidelity.tolerance = level; coupler modes, mesh "
                      "and solver keys auto):"] + [_rule_line(row) for row in rows]
