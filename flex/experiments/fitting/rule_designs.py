"""How close can a rule get to each scene's fastest setting? Rule designs judged side by side.

Issue 15's validation target asks the rule's pick to be within its tolerance and at most
:data:`flex.experiments.fitting.calibration.SLOWDOWN_LIMIT` x slower than the fastest grid pair
robustly within it, on scenes the rule never saw. The installed design is one law per damping class,
safe on every calibration scene (:func:`flex.experiments.fitting.calibration.fit_levels`); a scene's
needed steps and modes scatter around any smooth law, and the law keeps that scatter as margin.
:func:`design_frontier` measures the trade this forces, by leave-one-out over the measured scenes,
for the installed design and for a local one that keeps no global law:

- **nearest neighbours** (:func:`neighbour_pick`): the grid pair robustly within ``margin`` x
  the level on the ``k`` scenes of the same damping class nearest in (ln n, ln L / t), the
  one whose worst modelled slowdown on them is least; for k in :data:`NEIGHBOURS` and
  margins in :data:`NEIGHBOUR_MARGINS`.

Each design is judged on the same (scene, level) pairs: those the installed design's
leave-one-out judges with a reference that can certify the level. Per design: pairs over the
level (what a user would see), picks not robustly within it, picks robustly within it but more
than the slowdown limit slower, and picks that meet the target.

:func:`near_twins` shows why no rule of these inputs can be fast everywhere: pairs of scenes of
one damping class whose n and L / t lie within :data:`TWIN_CLOSENESS` of each other (a rule of
(n, L / t) gives them nearly the same settings), with the grid pair robust on both that is
least slow on the slower of the two.

Contract: pure functions of the stored cases; nothing is run.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from flex.data.results import CaseResult
from flex.experiments.fitting.calibration import (
    LEVELS,
    SLOWDOWN_LIMIT,
    certifiable,
    coupler_of,
    cross_validate,
    damping_of,
    grid_table,
    modelled_time_s,
    n_load_of,
    robustly_within,
    validation_row,
)

#: neighbour counts k of the local design
NEIGHBOURS = (1, 2, 3)
#: the local design keeps its pick robustly within this fraction of the level on the neighbours
NEIGHBOUR_MARGINS = (1.0, 0.7, 0.5)
#: near twins: n and L / t within this relative distance of each other
TWIN_CLOSENESS = 0.15
#: the installed design's name in the rows
INSTALLED = "installed: one law per class"


def scene_features(case: CaseResult) -> tuple[float, float]:
    """The local design's coordinates of a scene: (ln n, ln L / t), n = t_load / T1."""
    coupler = coupler_of(case)
    return math.log(n_load_of(case)), math.log(coupler["length_m"] / coupler["thickness_m"])


def neighbour_pick(held: CaseResult, others: Mapping[str, CaseResult], level: float, k: int,
                   margin: float) -> int | None:
    """Index of the grid pair the local design picks for ``held`` at ``level``: robustly
    within ``margin`` x ``level`` (:func:`flex.experiments.fitting.calibration.robustly_within`) on
    the ``k`` scenes of ``others`` nearest to it (:func:`scene_features`; same damping class,
    a reference that can certify the level and some grid pair within it), with the least
    worst modelled slowdown (:func:`flex.experiments.fitting.calibration.modelled_time_s`) on them.
    None if fewer than ``k`` such scenes exist or they share no such pair."""
    x = np.array(scene_features(held))
    candidates = []
    for case in others.values():
        if damping_of(case) != damping_of(held) or not certifiable(case, level):
            continue
        table = grid_table(case)
        ok = robustly_within(table, margin * level)
        if ok.any():
            distance = float(np.linalg.norm(np.array(scene_features(case)) - x))
            candidates.append((distance, modelled_time_s(table), ok))
    if len(candidates) < k:
        return None
    nearest = sorted(candidates, key=lambda item: item[0])[:k]
    shared = np.all([ok for _, _, ok in nearest], axis=0)
    if not shared.any():
        return None
    slowdown = np.max([time / np.min(time[ok]) for _, time, ok in nearest], axis=0)
    slowdown[~shared] = np.inf
    return int(np.argmin(slowdown))


def design_frontier(cases: Mapping[str, CaseResult], levels: Sequence[float] = LEVELS
                    ) -> list[dict[str, Any]]:
    """Leave-one-out over ``cases`` for the installed design and the local ones (see the
    module doc). Rows: ``design``, ``judged``, ``no_pick`` (the neighbours share no pair),
    ``over_level``, ``not_robust``, ``slower`` (robustly within, more than the slowdown
    limit slower), ``meets``, ``worst_ratio`` (largest certified error / level), ``rows``
    (the per-pair rows of :func:`flex.experiments.fitting.calibration.validate`)."""
    installed = [row for row in cross_validate(cases, levels)
                 if "rule_pair" in row and row["certifiable"]]
    out = [_tally(INSTALLED, installed)]
    for margin in NEIGHBOUR_MARGINS:
        for k in NEIGHBOURS:
            rows = []
            for judged in installed:
                name, level = judged["scene"], judged["tolerance"]
                others = {other: case for other, case in cases.items() if other != name}
                pick = neighbour_pick(cases[name], others, level, k, margin)
                rows.append(_neighbour_row(cases[name], name, level, pick))
            out.append(_tally(f"nearest {k}, within {margin:g} x the level", rows))
    return out


def _neighbour_row(case: CaseResult, name: str, level: float, pick: int | None
                   ) -> dict[str, Any]:
    if pick is None:  # the neighbours share no pair within the margin: the design is silent
        return {"scene": name, "tolerance": level, "no_pick": True, "rule_error": math.nan,
                "meets": False, "robust": False, "slowdown": math.nan}
    table = grid_table(case)
    pair = (int(table["modes"][pick]), float(table["steps_per_first_period"][pick]))
    return validation_row(name, table, level, pair, True)


def _tally(design: str, rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    picked = [row for row in rows if not row.get("no_pick")]
    robust = [row for row in picked if row["robust"]]
    return {"design": design, "judged": len(rows), "no_pick": len(rows) - len(picked),
            "over_level": sum(row["rule_error"] > row["tolerance"] for row in picked),
            "not_robust": len(picked) - len(robust),
            "slower": sum(row["slowdown"] > SLOWDOWN_LIMIT for row in robust),
            "meets": sum(row["meets"] for row in picked),
            "worst_ratio": max((row["rule_error"] / row["tolerance"] for row in picked),
                               default=math.nan), "rows": list(rows)}


def near_twins(cases: Mapping[str, CaseResult], level: float,
               closeness: float = TWIN_CLOSENESS) -> list[dict[str, Any]]:
    """Pairs of ``cases`` of one damping class, both able to certify ``level`` and some grid
    pair robustly within it, whose n and L / t differ by at most ``closeness`` (relative).
    Row keys: ``scenes`` (the two names), ``shared_pair`` ("" if none), ``slowdown``: the
    least, over grid pairs robustly within the level on both, of the larger of the two
    scenes' modelled slowdowns against their own fastest robust pair (inf if none)."""
    usable = {}
    for name, case in cases.items():
        if not certifiable(case, level):
            continue
        table = grid_table(case)
        ok = robustly_within(table, level)
        if ok.any():
            time = modelled_time_s(table)
            usable[name] = (case, table, ok, time / np.min(time[ok]))
    rows = []
    names = sorted(usable)
    limit = math.log1p(closeness)
    for index, first in enumerate(names):
        for second in names[index + 1:]:
            (a, table, ok_a, slow_a), (b, _, ok_b, slow_b) = usable[first], usable[second]
            gaps = np.abs(np.subtract(scene_features(a), scene_features(b)))
            if damping_of(a) != damping_of(b) or np.any(gaps > limit):
                continue
            worst = np.where(ok_a & ok_b, np.maximum(slow_a, slow_b), np.inf)
            best = int(np.argmin(worst))
            rows.append({"scenes": (first, second), "slowdown": float(worst[best]),
                         "shared_pair": "" if math.isinf(worst[best]) else
                         f"{int(table['modes'][best])} modes, "
                         f"T1/{table['steps_per_first_period'][best]:g}"})
    return rows
