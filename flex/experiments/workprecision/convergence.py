"""Converged references: a reference solution shown converged, knob by knob.

A reference is *shown* converged (:func:`converged_reference`): the finest setting is run,
then each knob is coarsened. A :class:`Refinement` coarsens one knob by two levels (three
runs at a constant ratio r: fine, medium, coarse); :func:`richardson` turns the two changes
into the observed order p and an estimate of the fine run's own error (grid-convergence-index
style, safety factor :data:`RICHARDSON_SAFETY`; oscillating or pre-asymptotic sequences get
the conservative :data:`FALLBACK_FACTOR` x the largest change). A plain one-level coarsening
(``coarsenings``) contributes its change itself. The reference's accuracy is the sum of the
knobs' estimates; it counts as converged to ``tolerance`` when that sum is below it.
Settings, runs and errors: :mod:`flex.experiments.workprecision.measurement`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from flex.base.errors import FlexError
from flex.data.scene import Scene
from flex.experiments.workprecision.measurement import (
    ANGLE_SCALE_RAD,
    Observables,
    ReductionPool,
    Reference,
    Setting,
    run_once,
    scene_for,
)

#: safety factor on a Richardson error estimate from three levels in the asymptotic range
#: (Roache's grid convergence index for three grids)
RICHARDSON_SAFETY = 1.25
#: an observed order below this (or an oscillating sequence) is not trusted as asymptotic
MIN_ASYMPTOTIC_ORDER = 1.0
#: estimate outside the asymptotic range: this factor x the larger of the two changes (the
#: factor of safety of a study whose order is not verified; Roache, Eca & Hoekstra)
FALLBACK_FACTOR = 3.0
#: the relative error measures a knob's sequence is judged by (:meth:`Reference.errors`)
MEASURES = ("crank_angle_relative", "slider_position_relative", "peak_deflection_relative")


@dataclass(frozen=True)
class Refinement:
    """One knob coarsened by two levels at a constant ``ratio`` (> 1): ``levels`` = (fine,
    medium, coarse) settings. The fine level is normally the reference's own setting (then
    not run twice); it may be a cheaper one when the knob's error is measured at a coarser
    value of another knob (errors of independent knobs add up). ``max_order``: the formal
    order of the knob (generalized-alpha: 2 in the step); a larger observed order is capped
    to it, which keeps the estimate conservative. With two levels only (fine, coarse) the
    estimate is the change itself, as for a one-level coarsening (e.g. a Newton tolerance:
    the change bounds the looser run's error, the finer one's is smaller)."""

    knob: str
    levels: tuple[Setting, ...]
    ratio: float
    max_order: float


def richardson(change_fine: float, change_coarse: float, ratio: float, max_order: float,
               monotone: bool = True) -> dict[str, Any]:
    """Estimate of the fine run's own error from the changes fine -> medium
    (``change_fine``) and medium -> coarse (``change_coarse``) of a sequence refined by
    ``ratio``.

    In the asymptotic range (``monotone``, the coarse change larger, observed order
    p = ln(change_coarse / change_fine) / ln(ratio) at least :data:`MIN_ASYMPTOTIC_ORDER`):
    :data:`RICHARDSON_SAFETY` x change_fine / (ratio^min(p, max_order) - 1), the
    Richardson-extrapolated error with a safety factor (grid convergence index). Otherwise
    (oscillating, stalling or too slow to be asymptotic): :data:`FALLBACK_FACTOR` x the
    larger change. Returns ``estimate``, ``order`` (observed, nan if none), ``asymptotic``.
    """
    out: dict[str, Any] = {"change_fine": change_fine, "change_coarse": change_coarse,
                           "order": math.nan, "asymptotic": False}
    if not (math.isfinite(change_fine) and math.isfinite(change_coarse)):
        out["estimate"] = math.inf
        return out
    if change_fine == 0.0 and change_coarse == 0.0:
        out.update(estimate=0.0, asymptotic=True)
        return out
    if monotone and change_coarse > change_fine:
        order = (math.inf if change_fine == 0.0
                 else math.log(change_coarse / change_fine) / math.log(ratio))
        out["order"] = order
        if order >= MIN_ASYMPTOTIC_ORDER:
            used = min(order, max_order)
            out.update(estimate=RICHARDSON_SAFETY * change_fine / (ratio**used - 1.0),
                       asymptotic=True)
            return out
    out["estimate"] = FALLBACK_FACTOR * max(change_fine, change_coarse)
    return out


def converged_reference(base: Scene, label: str, finest: Setting,
                        coarsenings: dict[str, Setting], tolerance: float,
                        pool: ReductionPool | None = None, description: str = "",
                        progress: Callable[[str], None] | None = None,
                        refinements: Sequence[Refinement] = (),
                        anchor: Setting | None = None) -> Reference:
    """Run ``finest``, each one-knob ``coarsenings`` of it and each :class:`Refinement`
    sequence; return the reference with its evidence.

    A coarsening's evidence is its :meth:`Reference.errors` against the finest run (relative
    changes of crank angle, slider position and peak deflection, and their maximum
    ``error``, which is also its contribution to the accuracy). A refinement's evidence, per
    error measure, is :func:`richardson` on the changes fine -> medium -> coarse (relative to
    the fine run; the peak deflection's sequence is monotone when both changes have the same
    sign); ``error`` is the largest estimate, ``order``, ``change_fine``, ``change_coarse``
    and ``asymptotic`` are those of that measure, ``values`` the three peak deflections (or
    final crank angles) and ``wall_times_s`` the runs' integration times. A failed run makes
    its evidence infinite (the reference is then not converged).

    Sequences run at cheaper values of the other knobs rest on the knobs' errors adding up.
    ``anchor`` checks it: a setting with each knob at a value one of its sequence's levels
    has (typically the finest level of the first sequence). The additive prediction of the
    reference's value is the anchor's plus, per three-level sequence, its fine level minus
    its level at the anchor's value of the knob; the relative difference between the
    reference and that prediction is stored as the evidence ``interaction`` and counts in the
    accuracy like a knob (the knobs' joint effect that the sequences do not see). Raises
    :class:`~flex.base.errors.FlexError` if the finest run fails.
    """
    scene = scene_for(base, finest)
    if progress:
        progress(f"reference {label}: {finest.label}")
    observables, counters = run_once(scene, finest, pool)
    reference = Reference(label, observables, finest, {}, tolerance,
                          float(counters["wall_time_s"]), description)
    run = _memoized_run(base, label, pool, progress, {
        repr(finest.knobs()): (observables, float(counters["wall_time_s"]))})
    for name, coarser in coarsenings.items():
        try:
            coarse_observables, wall = run(coarser)
        except FlexError as exc:  # no evidence: the reference then counts as not converged
            reference.evidence[name] = {"error": math.inf, "failed": str(exc)}
            continue
        reference.evidence[name] = reference.errors(coarse_observables)
        reference.evidence[name]["wall_times_s"] = [wall]
    for refinement in refinements:
        try:
            levels = [run(setting) for setting in refinement.levels]
        except FlexError as exc:
            reference.evidence[refinement.knob] = {"error": math.inf, "failed": str(exc)}
            continue
        reference.evidence[refinement.knob] = _refinement_evidence(reference, refinement,
                                                                   levels)
    if anchor is not None and refinements:
        reference.evidence["interaction"] = _interaction(reference, refinements, anchor, run)
    return reference


def _memoized_run(base: Scene, label: str, pool: ReductionPool | None,
                  progress: Callable[[str], None] | None,
                  runs: dict[str, tuple[Observables, float]]
                  ) -> Callable[[Setting], tuple[Observables, float]]:
    """A function running a setting of ``base`` once per knob values (``runs``: the runs so
    far, keyed by ``repr`` of the knobs): its observables and integration wall time [s]."""
    def run(setting: Setting) -> tuple[Observables, float]:
        key = repr(setting.knobs())
        if key not in runs:
            if progress:
                progress(f"reference {label}: evidence {setting.label}")
            obs, count = run_once(scene_for(base, setting), setting, pool)
            runs[key] = (obs, float(count["wall_time_s"]))
        return runs[key]

    return run


def _refinement_evidence(reference: Reference, refinement: Refinement,
                         levels: Sequence[tuple[Observables, float]]) -> dict[str, Any]:
    """The evidence record of one knob sequence from its levels' runs (observables, wall
    time [s]), finest first (see :func:`converged_reference`)."""
    tolerance = reference.tolerance
    fine_ref = Reference("fine", levels[0][0], refinement.levels[0], {}, tolerance, 0.0)
    changes_fine = fine_ref.errors(levels[1][0])
    three = len(levels) == 3
    if three:
        medium_ref = Reference("medium", levels[1][0], refinement.levels[1], {},
                               tolerance, 0.0)
        changes_coarse = medium_ref.errors(levels[2][0])
    peaks = [obs.peak_m for obs, _ in levels]
    record: dict[str, Any] = {"error": 0.0}
    for measure_name in MEASURES:
        d1 = changes_fine[measure_name]
        if not math.isfinite(d1) and measure_name == "peak_deflection_relative" \
                and not reference.flexible:
            continue  # a measure the scene does not have (peak of a rigid coupler)
        if not three:
            estimate = {"estimate": d1, "change_fine": d1, "change_coarse": math.nan,
                        "order": math.nan, "asymptotic": False}
        else:
            d2 = changes_coarse[measure_name]
            monotone = True
            if measure_name == "peak_deflection_relative":
                monotone = (peaks[1] - peaks[0]) * (peaks[2] - peaks[1]) > 0
            estimate = richardson(d1, d2, refinement.ratio, refinement.max_order, monotone)
        record[measure_name] = estimate["estimate"]
        if estimate["estimate"] >= record["error"]:
            record.update(error=estimate["estimate"], governing=measure_name,
                          **{k: v for k, v in estimate.items() if k != "estimate"})
    record["values"] = (peaks if reference.flexible
                        else [float(obs.crank_angle_rad[-1]) for obs, _ in levels])
    record["settings"] = [setting.label for setting in refinement.levels]
    record["wall_times_s"] = [wall for _, wall in levels]
    record["ratio"] = refinement.ratio
    return record


def _knob_key(knob: str) -> str:
    return knob if "." in knob else f"simulation.{knob}"


def _value(observables: Observables, flexible: bool) -> float:
    return (observables.peak_m if flexible
            else float(observables.crank_angle_rad[-1]))


def _interaction(reference: Reference, refinements: Sequence[Refinement], anchor: Setting,
                 run: Callable[[Setting], tuple[Observables, float]]) -> dict[str, Any]:
    """Evidence that the knobs' errors add up (see :func:`converged_reference`)."""
    flexible = reference.flexible
    try:
        anchor_observables, wall = run(anchor)
    except FlexError as exc:
        return {"error": math.inf, "failed": str(exc)}
    anchor_knobs = dict(anchor.overrides)
    actual = _value(reference.observables, flexible)
    predicted = _value(anchor_observables, flexible)
    walls = [wall]
    for refinement in refinements:
        if len(refinement.levels) != 3:
            continue
        key = _knob_key(refinement.knob)
        at_anchor = [setting for setting in refinement.levels
                     if key in anchor_knobs and dict(setting.overrides).get(key)
                     == anchor_knobs[key]]
        if not at_anchor:
            return {"error": math.inf, "failed": f"no level of {refinement.knob} at the "
                                                 f"anchor's value"}
        fine, fine_wall = run(refinement.levels[0])
        level, level_wall = run(at_anchor[0])
        predicted += _value(fine, flexible) - _value(level, flexible)
        walls += [fine_wall, level_wall]
    scale = abs(actual) if flexible else ANGLE_SCALE_RAD
    difference = abs(actual - predicted) / scale
    return {"error": difference, "change_fine": difference, "values": [actual, predicted],
            "settings": [reference.setting.label, f"additive prediction from {anchor.label}"],
            "wall_times_s": [wall], "governing": "peak_deflection_relative" if flexible
            else "crank_angle_relative"}
