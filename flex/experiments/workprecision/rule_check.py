"""What flex runs when asked for an accuracy, against the work-precision runs.

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

from flex.config.ffrf_rule import LINK_KEYS, pick
from flex.config.settings import AUTO_OVERRIDES, resolve_solver_settings
from flex.data.results import Dataset
from flex.data.scene import Scene
from flex.data.tables import table_datasets
from flex.experiments.workprecision.measurement import (
    Measurement,
    Reference,
    Setting,
    certifies,
    scene_for,
)

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
    lines = ["    flex rule picks (fidelity.tolerance = level; coupler modes, mesh and solver keys "
             "auto):"] + [_rule_line(row) for row in rows]
    return table_datasets(rows, RULE_COLUMNS, f"{group}/rule"), lines
