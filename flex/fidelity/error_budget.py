"""The error budget of a run: what separates each headline quantity from the truth that
flex can know, term by term, in the quantity's unit and relative to it.

Contract of :func:`error_budget`: given a finished run of a concrete scene (links rigid,
ffrf, nonlinear_fe or exact_beam; ``"auto"`` keys resolved) and a way to run companion
scenes, it returns an :class:`ErrorBudget` with, for each headline quantity of the run
(:data:`flex.data.headlines.BUILTIN_HEADLINES`: crank angle and slider position at the end
time, deployment time, peak joint forces, each flexible link's peak midpoint deflection and
peak bending stress), four named terms and their total [the quantity's units]:

- ``step``: the time step, by Richardson extrapolation from finer companions at h / 2 (and
  h / 4, observing the order) (:func:`flex.fidelity.error_estimate.estimate_step_error`);
- ``modes`` and ``mesh``: the links' discretization knobs (:mod:`flex.config.knobs`, each
  named by the link's model entry): for each knob the difference to a companion with the knob
  turned once on every link that has it (the modes raised, a plate's mesh halved, a beam's
  elements doubled), times the knob's extrapolation factor (``r^p / (r^p - 1)`` at its order:
  a mesh at each quantity's ``mesh_order``, a beam at 2; the modes taken whole, the richer
  basis as converged); a mesh companion that cannot run (a mesh too fine for the machine)
  gives way to a coarser one, its difference taken whole;
- ``model``: the link model against the next rung of flex's ladder, read from the rung each
  link's model entry names (:mod:`flex.config.ladder`; no model is named here): a rung that
  measures its term on the scene (``measured_against``: the FFRF bodies, against the exact
  beam) gets the difference to that companion (an FFRF body's: to two beam companions
  extrapolated, plus the extrapolation's size, ``measured_against_coarser``); a link on another
  bounded rung (the exact beam) gets its rung's ``own_fraction`` of what its elasticity
  changes in its own quantities and the ``motion_fraction`` of what it changes in the
  motion and the joint forces (the difference to a companion whose bounded links are rigid
  twins), plus the difference to the rung's companion one step up (the linear FFRF body:
  geometric stiffness on); a rigid link and the top rung add their ``leaves_out`` lines,
  and a model on no rung says that its model error is left out.

``total`` is the root-sum-square of the terms: they come from independent directions of
refinement (step, basis, mesh, model), whose errors add with unknown signs (the practice of
the GUM for independent components; ``make estimates`` measured the plain sum 3-30x
pessimistic on most FFRF quantities, the root-sum-square never optimistic by more than 1.5x);
``relative`` is the total over the quantity's magnitude. What no term
covers is said in :attr:`ErrorBudget.leaves_out`. Companions that fail leave their term out
and say why. :meth:`ErrorBudget.attrs` are the case attributes ``estimated_error_*``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError
from flex.config.knobs import NO_KNOB, Knob, linked_knobs
from flex.config.ladder import Rung
from flex.config.tolerance import Tolerance
from flex.data.headlines import (
    BUILTIN_HEADLINES,
    DEPLOYMENT,
    Headline,
    channel,
    crest_gap,
    peak_at_deployment_end,
)
from flex.data.results import CaseResult
from flex.data.scene import LINKS, Scene, apply_overrides, model_names
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel, flexible_links
from flex.fidelity.error_estimate import estimate_step_error, headline_difference
from flex.fidelity.stored_budget import TERMS, ErrorBudget


def _companion(scene: Scene, overrides: list[str]) -> Scene:
    return apply_overrides(scene, [*overrides, "simulation.output_step_s=0.0",
                                   "simulation.error_estimate=false"])


class _Companions:
    """Runs companion scenes, timing them and keeping what failed; ``differences`` compares
    a companion's headline quantities with the run's."""

    def __init__(self, run_companion: Callable[[Scene], CaseResult],
                 headlines: Mapping[str, Headline]) -> None:
        self.run_companion = run_companion
        self.headlines = headlines
        self.failures: list[str] = []
        self.wall_time_s = 0.0

    def differences(self, result: CaseResult, other: CaseResult | None) -> dict[str, float]:
        """Each headline quantity's difference between ``result`` and ``other`` (0 for a
        link's own quantity ``other`` lacks where ``result`` has it, e.g. a rigid twin's
        stress; NaN, unknown, for a quantity of the motion ``other`` lacks, e.g. a deployment
        time its crank never reached)."""
        if other is None:
            return {}
        out = {}
        for name, headline in self.headlines.items():
            difference = headline_difference(headline, result.datasets, other.datasets)
            if difference is not None:
                out[name] = difference
            elif headline.read(result.datasets) is not None:  # the companion lacks it
                out[name] = math.nan
        return out

    def run(self, what: str, scene: Scene) -> CaseResult | None:
        start = time.perf_counter()
        try:
            return self.run_companion(scene)
        except FlexError as exc:
            self.failures.append(f"{what}: the companion run failed ({exc})")
            return None
        finally:
            self.wall_time_s += time.perf_counter() - start


def _knob_terms(scene: Scene, result: CaseResult, companions: _Companions,
                link_models: Mapping[str, LinkModel], inside: set[str] = frozenset()
                ) -> tuple[dict[str, dict[str, float]], dict[str, str]]:
    """The terms the link knobs measure (:mod:`flex.config.knobs`: modes, mesh, a beam's
    elements), by term: for each knob the scene's links have, the difference to a companion
    with that knob turned once on each of them, times the knob's extrapolation factor; a
    term's knobs add. The knobs of the ``inside`` links are not measured apart: the model
    term's companion resolves them (:func:`_inside_model`). Returns the terms and one
    sentence per term."""
    terms: dict[str, dict[str, float]] = {term: {} for term in NO_KNOB}
    sentences: dict[str, list[str]] = {term: [] for term in NO_KNOB}
    for knob, all_links in linked_knobs(scene, link_models):
        links = [link for link in all_links if link not in inside]
        if len(links) < len(all_links):
            sentences[knob.term].append(INSIDE_TEXT.format(
                knob=knob.name, links=" and ".join(sorted(set(all_links) - set(links)))))
        if not links:
            continue
        values, sentence = _knob_term(knob, links, scene, result, companions)
        for name, value in values.items():
            terms[knob.term][name] = terms[knob.term].get(name, 0.0) + value
        sentences[knob.term].append(sentence)
    return terms, {term: "; ".join(said) or NO_KNOB[term][0] for term, said in sentences.items()}


#: a link knob's sentence when the model term's companion holds its error
INSIDE_TEXT = ("{links}'s {knob}: inside the model term (its companion one rung up resolves "
               "them, and its difference met the tolerance: not measured apart)")
#: the share of each asked quantity's allowance (the tolerance times the quantity) the model
#: term may take for the knob errors it holds to go unmeasured apart: the whole (a term that
#: misses the tolerance has each knob's companion run: refinement and the reader then see
#: which knob to turn)
INSIDE_SHARE = 1.0


def _inside_model(model: Mapping[str, float], measured: set[str],
                  rungs: Mapping[str, Rung | None], allowances: Mapping[str, float]
                  ) -> set[str]:
    """The links whose knob errors the model term holds and need not be measured apart:
    measured against a companion that resolves their knobs
    (:attr:`flex.config.ladder.Rung.resolves_knobs`), with every asked quantity's model
    term within :data:`INSIDE_SHARE` of its allowance [its unit]."""
    if not all(model.get(name, math.nan) <= INSIDE_SHARE * allowance
               for name, allowance in allowances.items()):
        return set()
    return {link for link in measured
            if (rung := rungs.get(link)) is not None and rung.resolves_knobs}


def _knob_term(knob: Knob, links: list[str], scene: Scene, result: CaseResult,
               companions: _Companions) -> tuple[dict[str, float], str]:
    """One knob's term on ``links``: the finer companion's differences, extrapolated with the
    knob's factor (per headline quantity's mesh order where the knob says so); where that
    companion cannot run and the knob has a coarser fallback (a mesh too fine for the
    machine), the coarser one's difference taken whole, and the sentence says so."""
    new = {link: knob.finer(knob.value(scene, link)) for link in links}
    how = ", ".join(knob.change_text.format(link=link, old=knob.value(scene, link), new=value)
                    for link, value in new.items())
    failures = len(companions.failures)
    finer = companions.run(knob.term, _companion(
        scene, [knob.override(link, value) for link, value in new.items()]))
    if finer is not None or not knob.fallback:
        return ({name: knob.factor(companions.headlines[name].mesh_order) * value
                 for name, value in companions.differences(result, finer).items()},
                knob.sentence.format(how=how, factor=knob.factor()))
    reason = companions.failures.pop(failures).split(": ", 1)[1]
    coarse = {link: min(2.0 * float(knob.value(scene, link)),
                        float(scene[link]["length_m"])) for link in links}
    coarser = companions.run(knob.term, _companion(
        scene, [knob.override(link, value) for link, value in coarse.items()]))
    how = ", ".join(knob.change_text.format(link=link, old=knob.value(scene, link), new=value)
                    for link, value in coarse.items())
    return (companions.differences(result, coarser),
            f"difference to a companion on a 2x coarser mesh ({how}), taken whole (the finer "
            f"one: {reason})")


def _rungs(scene: Scene, link_models: Mapping[str, LinkModel]) -> dict[str, Rung | None]:
    """Each link's rung on the ladder (None: its model is on no rung)."""
    return {link: link_models[scene[link]["model"]].rung(scene[link]) for link in LINKS}


def _grouped(links: dict[str, Rung], text: str, joiner: str = " and ") -> list[str]:
    """The rungs' field ``text``, once per distinct line, with ``{links}`` its links."""
    out: dict[str, list[str]] = {}
    for link, rung in links.items():
        out.setdefault(getattr(rung, text), []).append(link)
    return [line.format(links=joiner.join(names)) for line, names in out.items() if line]


def _measured_model_term(scene: Scene, result: CaseResult, companions: _Companions,
                         rungs: dict[str, Rung]) -> tuple[dict[str, Any], list[str]]:
    """The model term of the links whose rung measures it on the run's scene (a companion
    one rung up, :attr:`flex.config.ladder.Rung.measured_against`: an FFRF body's, a rigid
    plate's): each headline quantity's difference to that companion (where a rung has a
    coarser companion too, to the two extrapolated, plus the extrapolation's size:
    :func:`_extrapolated_difference`), the sentence, and under ``""`` the links it measured.
    A companion the scene cannot run (a model the rung above does not offer for it, e.g. a
    damped link) leaves a bounded rung's links to its measured fractions, and says so; a
    rung without fractions (rigid) keeps the failure: its term is unknown."""
    measured = {link: rung for link, rung in rungs.items() if rung.measured_against}
    if not measured:
        return {}, []
    failures = len(companions.failures)
    above = companions.run("model", _measuring_companion(scene, measured))
    if above is None:
        if not all(rung.bounded for rung in measured.values()):
            return {}, []
        reason = companions.failures.pop(failures).split(": ", 1)[1]
        return {}, [f"not measured on the scene ({reason}): the measured fractions instead"]
    terms: dict[str, Any] = dict(companions.differences(result, above))
    if any(rung.measured_against_coarser for rung in measured.values()):
        coarser = companions.run("model", _measuring_companion(scene, measured, level=1))
        coarsest = (companions.run("model", _measuring_companion(scene, measured, level=2))
                    if coarser is not None and any(rung.measured_against_coarsest
                                                   for rung in measured.values()) else None)
        if coarser is not None:
            for name in terms:
                terms[name] = _extrapolated_difference(companions.headlines[name], result,
                                                       above, coarser, terms[name], coarsest)
    terms[""] = set(measured)
    return terms, _grouped(measured, "measured_against_text")


def _measuring_companion(scene: Scene, measured: Mapping[str, Rung], level: int = 0) -> Scene:
    """The companion scene whose ``measured`` links stand on the rung above (each rung's
    ``measured_against``; at ``level`` 1 its ``measured_against_coarser``, at 2 its
    ``measured_against_coarsest``, where it has one)."""
    def against(rung: Rung) -> Callable[[Mapping[str, Any]], tuple[str, ...]]:
        coarser = (None, rung.measured_against_coarser, rung.measured_against_coarsest)[level]
        return coarser or rung.measured_against

    overrides = [override.format(link=link) for link, rung in measured.items()
                 for override in against(rung)(scene)]
    return _companion(scene, list(dict.fromkeys(overrides)))


def _extrapolated_difference(headline: Headline, result: CaseResult, fine: CaseResult,
                             coarse: CaseResult, difference: float,
                             coarsest: CaseResult | None = None) -> float:
    """A quantity's model term from companions one rung up [its unit]: the difference of
    ``result`` to the Richardson extrapolation of the two finer at the quantity's
    ``mesh_order`` (the elements halved between them), plus the extrapolation's size, its
    sign unknown: where a third, ``coarsest``, companion shows the order (within
    :data:`flex.fidelity.error_estimate.ORDER_WINDOW`), how far the limits of the finer and
    the coarser pair lie apart; else the finer companion's own error. A history: the same on
    its curves (:func:`_extrapolated_curves`). A raw peak: the difference to the finer
    companion plus the finer companion's error (its difference is crest-aware,
    :func:`flex.fidelity.error_estimate.peak_difference`, and its total a bound).
    ``difference``: the run's difference to the finer companion, kept where the coarser one
    lacks the quantity."""
    change = headline_difference(headline, fine.datasets, coarse.datasets)
    if change is None or math.isnan(change) or math.isnan(difference):
        return difference
    share = 1.0 / (2.0 ** headline.mesh_order - 1.0)
    if headline.kind == "history":
        return _extrapolated_curves(headline, result, (fine, coarse, coarsest), share,
                                    difference + share * change)
    ours, finer, coarser = (headline.read(case.datasets) for case in (result, fine, coarse))
    if headline.kind == "peak" or None in (ours, finer, coarser):
        return difference + share * change
    size = share * change
    third = None if coarsest is None else headline.read(coarsest.datasets)
    if third is not None and _order_shown(finer - coarser, coarser - third, headline):
        size = abs(finer + share * (finer - coarser) - (coarser + share * (coarser - third)))
    return abs(ours - (finer + share * (finer - coarser))) + size


def _order_shown(fine_change: float, coarse_change: float, headline: Headline) -> bool:
    """Whether two successive changes of a quantity (their sign and size) show its
    ``mesh_order`` within :data:`flex.fidelity.error_estimate.ORDER_WINDOW`."""
    from flex.fidelity.error_estimate import ORDER_WINDOW

    if not fine_change * coarse_change > 0:
        return False
    return abs(math.log2(coarse_change / fine_change) - headline.mesh_order) <= ORDER_WINDOW


def _extrapolated_curves(headline: Headline, result: CaseResult,
                         levels: tuple[CaseResult, CaseResult, CaseResult | None], share: float,
                         fallback: float) -> float:
    """A history's model term from companions one rung up: the largest difference of the
    run's curve to the two finer companions' extrapolated curve, plus the largest distance of
    that curve to the coarser pair's, where the three show the order on the curves' largest
    changes; else ``fallback`` (the difference to the finer companion plus its own error)
    [the curve's unit]. Curves on the headline channel, at the run's times both determine."""
    from flex.data.headlines import channel_curve

    path = headline.series
    if levels[2] is None or any(path not in case.datasets for case in (result, *levels)):
        return fallback
    time_s, ours = channel_curve(result.datasets, path)
    curves = [channel_curve(case.datasets, path) for case in levels]
    inside = time_s <= min(other_s[-1] for other_s, _ in curves)
    fine, coarse, coarsest = (np.interp(time_s[inside], other_s, values)
                              for other_s, values in curves)
    changes = fine - coarse, coarse - coarsest
    if not _order_shown(float(np.max(np.abs(changes[0]))), float(np.max(np.abs(changes[1]))),
                        headline):
        return fallback
    limit, coarser_limit = fine + share * changes[0], coarse + share * changes[1]
    return (float(np.max(np.abs(ours[inside] - limit)))
            + float(np.max(np.abs(limit - coarser_limit))))


def _model_term(scene: Scene, result: CaseResult, companions: _Companions,
                leaves_out: list[str], link_models: Mapping[str, LinkModel],
                cache_dir: Path | None = None) -> tuple[dict[str, float], str, set[str]]:
    """The links' model errors from their rungs (:mod:`flex.config.ladder`): measured on the
    scene where the rung says so (the difference to a companion one rung up); else a bounded
    rung's fractions of what the elasticity changes (the difference to rigid twins), plus its
    companion's difference; every rung's ``leaves_out`` line, highest first."""
    rungs = _rungs(scene, link_models)
    placed = {link: rung for link, rung in rungs.items() if rung is not None}
    terms, sentences = _measured_model_term(scene, result, companions, placed)
    measured = terms.pop("", set())
    bounded = {link: rung for link, rung in placed.items()
               if rung.bounded and link not in measured}
    if bounded:
        sentences += _fractions(scene, result, companions, bounded, terms, link_models,
                                cache_dir)
    leaves_out += _grouped(dict(sorted(placed.items(), key=lambda item: -item[1].level)),
                           "leaves_out")
    leaves_out += [f"the {link_models[scene[link]['model']].label or scene[link]['model']} "
                   f"{link}'s model error (its model stands on no rung of the ladder)"
                   for link, rung in rungs.items() if rung is None]
    return terms, "; ".join(sentences) or "no flexible link below the top rung", measured


def _fractions(scene: Scene, result: CaseResult, companions: _Companions,
               bounded: dict[str, Rung], terms: dict[str, float],
               link_models: Mapping[str, LinkModel], cache_dir: Path | None) -> list[str]:
    """The bounded rungs' measured fractions of what the elasticity changes (the difference
    to rigid twins), plus their companions' differences one step up, added to ``terms`` in
    place; their sentences."""
    twin = companions.run("model", _companion(
        scene, [f'{link}.model="{model_names(link, link_models, rigid=True)[0]}"'
                for link in bounded] + [f'{link}.geometry="plate"' for link in bounded]))
    motion = max(rung.motion_fraction for rung in bounded.values())
    for name, value in companions.differences(result, twin).items():
        owner = companions.headlines[name].link
        terms[name] = math.hypot(terms.get(name, 0.0), value * (
            bounded[owner].own(scene[owner], cache_dir) if owner in bounded else motion))
    sentences = _grouped(bounded, "measured_by")
    steps_up = {link: rung for link, rung in bounded.items() if rung.companion}
    if steps_up:
        above = companions.run("model", _companion(scene, [
            override.format(link=link) for link, rung in steps_up.items()
            for override in rung.companion]))
        for name, value in companions.differences(result, above).items():
            terms[name] = terms.get(name, 0.0) + value
        sentences += _grouped(steps_up, "companion_text", ", ")
    return sentences


def error_budget(scene: Scene, result: CaseResult,
                 run_companion: Callable[[Scene], CaseResult],
                 time_scales: list[tuple[float, float, str]],
                 link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS,
                 headlines: Mapping[str, Headline] = BUILTIN_HEADLINES,
                 cache_dir: Path | None = None) -> ErrorBudget:
    """The error budget of ``result``, the run of ``scene`` (concrete models, solver keys
    resolved), from companion runs made by ``run_companion`` (see the module doc);
    ``time_scales``: the scene's (:func:`flex.dynamics.advice.time_scales`);
    ``link_models``: the registry of its link models (their flags and rungs choose the
    terms); ``headlines``: the quantities budgeted (:mod:`flex.data.headlines`);
    ``cache_dir``: where a rung measured per plate keeps its reference (the exact beam's)."""
    values = {name: headline.read(result.datasets) for name, headline in headlines.items()}
    values = {name: value for name, value in values.items() if value is not None}
    tolerance = Tolerance.of(scene)
    allowances = {name: tolerance.relative * abs(values[name]) for name in
                  tolerance.asked(flexible_links(scene, link_models)) if name in values}
    # the finest step companion is reported where it stores what the run would (every step)
    step = estimate_step_error(scene, result, run_companion, time_scales, headlines,
                               allowances, float(scene["simulation"]["output_step_s"]) == 0.0)
    if step.finest is not None:
        values = {name: headlines[name].read(step.finest.datasets) for name in values}
    companions = _Companions(run_companion, headlines)
    leaves_out = ["the spring's and joints' idealizations (massless spring unless chained, "
                  "ideal pins)"]
    # the model term against the run reported (the finest where it is): its companion one
    # rung up runs at its own, finer step, so the difference is the reported run's
    model, model_how, measured_links = _model_term(scene, step.finest or result, companions,
                                                   leaves_out, link_models, cache_dir)
    inside = _inside_model(model, measured_links, _rungs(scene, link_models), allowances)
    knobbed, knob_how = _knob_terms(scene, result, companions, link_models, inside)
    failed = {failure.split(":")[0] for failure in companions.failures}
    if not step.values:
        failed.add("step")
    leaves_out += companions.failures
    if "step" in failed:
        leaves_out.append(f"step: {step.validity}")
    measured = {"step": step.values, **knobbed, "model": model}
    terms = {name: {term: measured[term].get(name, math.nan if term in failed else 0.0)
                    for term in TERMS} for name in values}
    methods = {"step": step.method, **knob_how, "model": model_how}
    return ErrorBudget(values, terms, {k: v for k, v in methods.items() if k not in failed},
                       leaves_out, step.validity + _rising_at_end(step.finest or result, values,
                                                                  headlines),
                       step.companion_wall_time_s + companions.wall_time_s,
                       _crest_gaps(step.finest or result, values, headlines),
                       {name: (headlines[name].unit, headlines[name].what) for name in values},
                       _unknown(terms, failed, [f"step: {step.validity}", *companions.failures],
                                headlines), tuple(step.bounds),
                       tuple(name for name in values if headlines[name].bound),
                       step.finest)


def _unknown(terms: dict[str, dict[str, float]], failed: set[str], failures: list[str],
             headlines: Mapping[str, Headline]) -> list[str]:
    """Why each unknown (NaN) term could not be measured: its companion failed, or it has no
    value of a quantity the run has (one phrase per term, on one line)."""
    out: dict[str, str] = {}
    for name, row in terms.items():
        for term, value in row.items():
            if math.isfinite(value) or term in out:
                continue
            reason = next((text for text in failures if text.startswith(f"{term}:")), None)
            out[term] = (reason if term in failed and reason else
                         f"{term}: its companion run has no {headlines[name].what}")
    return [" ".join(text.split()) for text in out.values()]


def _rising_at_end(result: CaseResult, values: dict[str, float],
                   headlines: Mapping[str, Headline]) -> str:
    """The validity's sentence on the deployment peaks that are no crest: the deployment's
    last sample, still rising (:func:`flex.data.headlines.peak_at_deployment_end`); their
    step and model terms compare values read at each run's own deployment end, so they hold
    the deployment time's error, but the value is as sensitive to it as the deflection is
    steep there. Empty when every deployment peak is a crest."""
    names = [name for name in values if headlines[name].window == DEPLOYMENT
             and headlines[name].kind == "value" and headlines[name].series is not None
             and peak_at_deployment_end(result.datasets, headlines[name].series)]
    if not names:
        return ""
    return (f"; {', '.join(names)}: no crest, the deployment's last sample with the series "
            f"still rising (the value follows the deployment time; its terms compare each "
            f"run at its own deployment end)")


def _crest_gaps(result: CaseResult, values: dict[str, float],
                headlines: Mapping[str, Headline]) -> dict[str, float]:
    """Each peak's crest gap [its unit] where its headline asks for one, on the series as
    the headline reads it (its channel where it has one: the peak races between crests when
    its error exceeds it; the first crest does not)."""
    out = {}
    for name in values:
        headline = headlines[name]
        if headline.crest_gap:
            gap = crest_gap(channel(result.datasets, headline.series)
                            if headline.series in headline.channel
                            else result.datasets[headline.series].data)
            if gap is not None:
                out[name] = gap
    return out



__all__ = ["error_budget"]
