"""What refinement does after each attempt: the tolerance met, or the next knob to turn.

:func:`flex.fidelity.simulation.refine` runs a resolved scene with its error budget, then asks
:func:`next_attempt` what to do. Contract of :func:`next_attempt`: given the attempt's scene, its
certified budget rows (:class:`flex.fidelity.stored_budget.BudgetRow`), the tolerance and what
refinement has observed so far, it returns a :class:`Step`: stop (met, nothing to certify, a
quantity outside the asymptotic range only, a value the user set that blocks, the cost limit)
or the next scene. The knob it turns is the one whose term is predicted to lower the worst
certified quantity's certificate the most per second of added cost:

- each term's knob (:func:`refined_change`: the step halved, the modes raised as the modes
  companion's, the mesh halved or a beam's elements doubled, a link climbed to the next rung)
  is predicted to divide its term by its *fall*: the one refinement observed when it last
  turned that knob (the term before over the term after, on the same quantity), or until then
  :func:`prior_fall`; a rung climb is predicted to remove its term;
- its cost is :func:`attempt_cost_s` of the next scene minus this one's [s] (flex's own
  estimates of run and meshing time, before anything runs);
- a term whose knob did not make it fall (observed fall at most 1) is not chased again;
- the terms whose knobs cannot move (a value the user set, a limit) stay: when they alone
  keep the certificate above the tolerance, refinement stops and says which value and what it
  would take.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from flex.base.errors import SceneError
from flex.config.knobs import KNOB_KEYS, KNOBS, NO_KNOB, STEP, linked_knobs, preparation_s
from flex.config.ladder import next_rung
from flex.config.settings import resolve_solver_settings
from flex.data.fields import AUTO
from flex.data.scene import Scene, default_scene
from flex.data.scene_edit import derive_scene
from flex.dynamics.link_models import LinkModel
from flex.dynamics.runtime import estimated_run_time_s
from flex.fidelity.stored_budget import BudgetRow, combined

#: most attempts of a refinement (each one a run with its whole error budget)
MAX_ATTEMPTS = 6
#: refinement's status of a run with no quantity it certifies
NOTHING_TO_REFINE = ("nothing to refine: no quantity the tolerance applies to is in the run "
                     "(fidelity.quantities; a rigid link has no deflection of its own)")


def free_knobs(scene: Scene) -> frozenset[str]:
    """The knobs (:data:`flex.config.knobs.KNOB_KEYS`) of ``scene`` as the user gave it
    (before ``"auto"`` is resolved) that refinement may turn: those left on ``"auto"`` or on
    the bundled scene's value. A value the user set is never changed."""
    bundled = default_scene()
    out = set()
    for knob in KNOB_KEYS:
        section, key = knob.split(".")
        value = scene[section][key]
        if value == AUTO or value == bundled[section][key]:
            out.add(knob)
    return frozenset(out)


def prior_fall(term: str) -> float:
    """How many times a term is predicted to shrink when its knob is turned once, until
    refinement has observed it on the run: the knob's own (:attr:`flex.config.knobs.Knob.
    prior_fall`: the step halved at the integrator's order 2, a mesh halved at the certified
    deflections' order 2, a beam's elements doubled at its order 2, the modes raised taken
    alike); a rung climbed: its term is predicted gone (the rung above's own term is not known
    before it runs)."""
    if term == "model":
        return math.inf
    return min(knob.prior_fall for knob in KNOBS.values() if knob.term == term)


@dataclass(frozen=True)
class Step:
    """What refinement does after an attempt: the next scene (None: stop, with ``status``),
    the attempt's line after its settings, the term whose knob it turned and the quantity it
    turned it for ("" if none)."""

    refined: Scene | None
    status: str
    line: str
    term: str = ""
    worst: str = ""


@dataclass(frozen=True)
class _Move:
    """A knob refinement may turn: its term, the next scene, what it does, the worst
    quantity's certificate predicted after it [fraction of the quantity] and the next
    attempt's estimated cost [s]."""

    term: str
    scene: Scene
    why: str
    predicted: float
    cost_s: float


def observed_fall(before: BudgetRow | None, after: BudgetRow | None, term: str) -> float | None:
    """How many times ``term`` shrank on one quantity from the attempt ``before`` to the one
    ``after`` it, where its knob was turned (None: not measurable, a term zero or unknown)."""
    if before is None or after is None:
        return None
    old, new = before.terms.get(term, math.nan), after.terms.get(term, math.nan)
    if not (math.isfinite(old) and math.isfinite(new)) or old <= 0.0:
        return None
    return math.inf if new <= 0.0 else old / new


def next_attempt(scene: Scene, rows: list[BudgetRow], tolerance: float, attempt: int,
                 spent_s: float, link_models: Mapping[str, LinkModel],
                 free: frozenset[str], flagged: frozenset[str] = frozenset(),
                 falls: Mapping[str, float] | None = None,
                 noise_floors: Mapping[str, float] | None = None, limit_s: float | None = None,
                 max_attempts: int = MAX_ATTEMPTS) -> Step:
    """After attempt ``attempt`` (its certified budget ``rows``, ``spent_s`` [s] so far): the
    tolerance met, nothing to certify, or the next scene (module doc). A quantity in
    ``flagged`` (outside the asymptotic range: its step term a bound that need not shrink with
    the step) is not chased: when only such quantities miss the tolerance, refinement stops
    and names them. ``falls``: each term's fall observed so far (:func:`observed_fall`);
    ``noise_floors``: each quantity's noise floor [its unit] (the Newton tolerance's effect on
    it): a term at or below it is not chased, and a tolerance its certificate cannot clear
    stops refinement; ``limit_s``: the cost limit [s] (None: the scene's
    ``fidelity.refine_limit_s``)."""
    if not rows:
        return Step(None, NOTHING_TO_REFINE, NOTHING_TO_REFINE)
    missing = [row for row in rows if not row.certified_relative <= tolerance]
    if missing and all(row.quantity in flagged for row in missing):
        status = ("not chased: " + "; ".join(
            f"{row.what} certified to {100 * row.certified_relative:.3g} % is outside the "
            f"asymptotic range (its step term a bound: the observed order left the window)"
            for row in missing) + f" (tolerance {100 * tolerance:g} %)")
        return Step(None, status, f"stopped: {status}")
    chased = [row for row in rows if row.quantity not in flagged] or rows
    worst = max(chased, key=lambda row: row.certified_relative
                if row.certified_relative >= 0 else math.inf)
    found = (f"{worst.what} certified to {100 * worst.certified_relative:.3g} % of itself "
             f"(estimate {100 * worst.relative:.3g} %; tolerance {100 * tolerance:g} %)"
             if not worst.problem else
             f"{worst.what} {worst.problem} (tolerance {100 * tolerance:g} %)")
    if all(row.certified_relative <= tolerance for row in rows):
        return Step(None, "met", f"met; worst {found}")
    noise = (noise_floors or {}).get(worst.quantity)
    if noise is not None:
        found += (f"; noise floor {100 * _certified_per_unit(worst) * noise:.2g} % (the Newton "
                  f"tolerance's effect)")
    limit = float(scene["fidelity"]["refine_limit_s"] if limit_s is None else limit_s)
    move, why_not = _best_move(scene, worst, tolerance, link_models, free, dict(falls or {}),
                               noise or 0.0)
    if move is None:
        return Step(None, why_not, f"{found}; stopped: {why_not}")
    if spent_s > limit or attempt >= max_attempts:
        status = (f"cost limit ({spent_s:.0f} s of fidelity.refine_limit_s = {limit:g} s)"
                  if attempt < max_attempts else f"{max_attempts} runs made")
        return Step(None, status, f"{found}; stopped: {status}")
    if spent_s + move.cost_s > limit:
        status = (f"cost limit: {move.why} would take ~{move.cost_s:.3g} s with its budget "
                  f"(estimate), beyond fidelity.refine_limit_s = {limit:g} s after "
                  f"{spent_s:.3g} s")
        return Step(None, status, f"{found}; stopped: {status}")
    return Step(move.scene, "", f"{found} -> {move.why}: the {move.term} term's knob, "
                f"predicted to leave {100 * move.predicted:.3g} % for ~{move.cost_s:.3g} s "
                f"(the most certified error removed per second)", move.term, worst.quantity)


def _certified_per_unit(row: BudgetRow) -> float:
    """The certified relative error per unit of error in the row's quantity [1/its unit]:
    the certificate's factor over the quantity's magnitude (0 for an error-free row)."""
    return row.certified_relative / row.total if row.total > 0 else 0.0


def _best_move(scene: Scene, worst: BudgetRow, tolerance: float,
               link_models: Mapping[str, LinkModel], free: frozenset[str],
               falls: dict[str, float], noise_floor: float = 0.0
               ) -> tuple[_Move | None, str]:
    """The knob to turn for ``worst`` (module doc), or None and why none: an unknown term
    (its companion failed) stops it; else the most predicted certificate removed per second
    of added cost, unless the terms no knob can lower keep it above the tolerance."""
    unknown = [term for term, value in worst.terms.items() if not value >= 0.0]
    if unknown:  # turning its knob would run the very companion that failed
        return None, (f"the {', '.join(unknown)} term of {worst.what} is unknown (its "
                      f"companion run failed; estimated_error_unknown says why), and the "
                      f"next attempt would be that companion")
    scale = _certified_per_unit(worst)
    if scale * noise_floor > tolerance:
        return None, (f"the tolerance is below the solver's noise floor: the Newton "
                      f"tolerance moves {worst.what} by ~{noise_floor:.3g} {worst.units} "
                      f"({100 * scale * noise_floor:.3g} % certified)")
    moves, stuck = _moves(scene, worst, link_models, free, falls, noise_floor)
    floor = scale * combined(value for term, value in worst.terms.items()
                             if term in dict(stuck))
    if floor > tolerance or not moves:
        return None, max(stuck, key=lambda item: worst.terms[item[0]],
                         default=("", "no knob can lower it"))[1]
    base_s = attempt_cost_s(scene, link_models)
    gains = [(worst.certified_relative - move.predicted)
             / max(move.cost_s - base_s, 1e-3 * base_s, 1e-9) for move in moves]
    best = max(range(len(moves)), key=gains.__getitem__)
    if gains[best] <= 0.0:
        return None, "no knob is predicted to lower it (the terms did not fall when turned)"
    return moves[best], ""


def _moves(scene: Scene, worst: BudgetRow, link_models: Mapping[str, LinkModel],
           free: frozenset[str], falls: dict[str, float], noise_floor: float = 0.0
           ) -> tuple[list[_Move], list[tuple[str, str]]]:
    """The knobs that can turn for ``worst``'s nonzero terms, with their predictions; and
    the terms that cannot move (or sit at the noise floor), with why."""
    moves, stuck = [], []
    scale = _certified_per_unit(worst)
    for term in [term for term, value in worst.terms.items() if value > 0.0]:
        if worst.terms[term] <= noise_floor:
            stuck.append((term, f"the {term} term ({worst.terms[term]:.3g} {worst.units}) is "
                                f"at the solver's noise floor ({noise_floor:.3g})"))
            continue
        change, why = refined_change(scene, term, link_models, free)
        if change is None:
            stuck.append((term, why))
            continue
        try:  # validated as --set is: a mesh too fine for this machine stops here
            refined = derive_scene(scene, change, link_models=link_models)
            refined, _ = resolve_solver_settings(refined, link_models=link_models)
        except SceneError as refused:
            stuck.append((term, f"{why}: refused: {refused}"))
            continue
        fallen = worst.terms[term] / falls.get(term, prior_fall(term))
        left = {**worst.terms, term: max(fallen, noise_floor)}  # not below the solver's noise
        predicted = scale * combined(left.values()) if math.isfinite(scale) else math.nan
        moves.append(_Move(term, refined, why, predicted, attempt_cost_s(refined, link_models)))
    return moves, stuck


#: runs of an attempt's error budget, in run-equivalents (a companion at h / 2, more modes, a
#: coarser mesh, the rung above; rough: the coarser ones cost less, one at h / 4 more)
BUDGET_RUNS = 5.0


def attempt_cost_s(scene: Scene, link_models: Mapping[str, LinkModel]) -> float:
    """Rough wall time [s] of one attempt on ``scene``: the run and its budget's companions
    (:data:`BUDGET_RUNS`), plus what its links' knobs cost to prepare (meshing and reducing
    each meshed link at its mesh, and the modes companion's reduction:
    :func:`flex.config.knobs.preparation_s`), as flex estimates them before meshing."""
    return ((1.0 + BUDGET_RUNS) * estimated_run_time_s(scene, link_models=link_models)
            + preparation_s(scene, link_models))


def refined_change(scene: Scene, term: str, link_models: Mapping[str, LinkModel],
                   free: frozenset[str] = frozenset(KNOB_KEYS)) -> tuple[list[str] | None, str]:
    """The overrides that refine the knob of ``term`` (step, modes, mesh, model) and what
    they do; (None, why not) when it cannot move, or when it would change a value the user
    set (not in ``free``): then why says which value and what it would take."""
    change, why = _refined_any(scene, term, link_models)
    set_by_user = [item for item in change or [] if item.split("=")[0] not in free]
    if not set_by_user:
        return change, why
    keys = ", ".join(f"{item.split('=')[0]} = {_value(scene, item.split('=')[0])}"
                     for item in set_by_user)
    return None, (f"the {term} term's knob {keys} was set in the scene (refinement changes "
                  f"only \"auto\" or default values): lowering it would take "
                  f"{', '.join(set_by_user)} ({why})")


def _value(scene: Scene, knob: str) -> Any:
    section, key = knob.split(".")
    return scene[section][key]


def _refined_any(scene: Scene, term: str, link_models: Mapping[str, LinkModel]
                 ) -> tuple[list[str] | None, str]:
    """:func:`refined_change` with every knob free: the step halved; a term's link knobs
    turned once on every link that has them and can take it (:mod:`flex.config.knobs`); the
    model term: the coupler, then the crank, climbed to the next rung."""
    if term == STEP.term:
        step = STEP.finer(STEP.value(scene))
        return [STEP.override("", step)], f"{STEP.verb} to {step:g} s"
    if term in NO_KNOB:
        return _turned(scene, term, link_models)
    for link in ("coupler", "crank"):
        higher = next_rung(link, scene[link], link_models)
        if higher is not None:
            return ([f'{link}.model="{higher}"'],
                    f"{link} climbed to the {link_models[higher].label} rung")
    return None, "the model term dominates and no link has a higher rung"


def _turned(scene: Scene, term: str, link_models: Mapping[str, LinkModel]
            ) -> tuple[list[str] | None, str]:
    """The overrides that turn ``term``'s link knobs once where they can turn, and what they
    do (``"mesh halved (coupler)"``); (None, why) when none can."""
    overrides, said, verbs = [], [], set()
    for knob, links in linked_knobs(scene, link_models, term):
        for link in links:
            new = knob.turned(scene, link)
            if new is not None:
                overrides.append(knob.override(link, new))
                said.append(knob.moved_text.format(link=link, old=knob.value(scene, link),
                                                   new=new))
                verbs.add(knob.verb)
    if not overrides:
        return None, NO_KNOB[term][1]
    verb = verbs.pop() if len(verbs) == 1 else f"{term} refined"
    return overrides, f"{verb} ({', '.join(said)})"



