"""An estimate of a run's own step (time discretization) error on its headline quantities,
measured on *finer* companions.

Contract of :func:`estimate_step_error`: given a finished run of a concrete scene (links
rigid, ffrf, exact_beam or nonlinear_fe; ``"auto"`` solver keys resolved) and a way to run a
companion scene, it runs companions that differ only in the step -- at half the step, and at
a quarter when the run's step leaves a time scale of the scene unresolved (the order must
then be observed) -- and returns an :class:`ErrorEstimate`:

- ``values``: for each headline quantity (``headlines``, default
  :data:`flex.data.headlines.BUILTIN_HEADLINES`), the estimated error of the run's value
  [the quantity's unit], by Richardson extrapolation from the finer runs: with the run at h
  and its companion at h/2, ``|q_h - q_h/2| 2^p / (2^p - 1)`` with the integrator's order p
  (:func:`integrator_order`: 2 for generalized-alpha). With a third run at h/4 the order is
  observed, ``p_obs = log2(|q_h - q_h/2| / |q_h/2 - q_h/4|)``: inside :data:`ORDER_WINDOW`
  of p the estimate uses it; outside, the quantity is not in the asymptotic range and its
  value is a *bound*, :data:`BOUND_FACTOR` times the larger of the two differences (named so
  in ``bounds``). Coarser companions are not used: the content a coarser step cannot
  resolve (a thin plate's ringing) would put their damping in the estimate (make estimates
  measured it 3-60x pessimistic, and on the deployment time 4x optimistic);
- ``bounds``: the quantities whose value is such a bound, each with its observed order;
- ``method``: that sentence, with the companions' steps;
- ``validity``: ``"asymptotic"`` when every time scale of the scene
  (:func:`flex.dynamics.advice.time_scales`: the spring or crank period, the highest
  retained mode of each flexible link) has at least :data:`MIN_STEPS_PER_PERIOD` steps per
  period at the run's step; otherwise the sentence names the time scales below it, and the
  quantities whose observed order left the window;
- ``companion_wall_time_s``: what the estimate cost [s].

It covers the step only: modal truncation and mesh errors are not estimated here. A
companion that fails (a step the scene cannot take) gives no values and says why in
``validity``; the error budget (:mod:`flex.fidelity.error_budget`) stores it as its step term.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from flex.base.errors import FlexError
from flex.config.knobs import STEP, integrator_order
from flex.data.headlines import BUILTIN_HEADLINES, Headline, history_difference
from flex.data.results import CaseResult
from flex.data.scene import Scene, apply_overrides
from flex.dynamics.advice import CHANNEL_ATTR

#: a time scale with fewer steps per period than this is outside the asymptotic range
MIN_STEPS_PER_PERIOD = 10.0
#: an observed order within this distance of the integrator's is in the asymptotic range
ORDER_WINDOW = 0.5
#: an unresolved time scale whose numerical frequency lies at least this many times above the
#: headline channel's cut-off is outside what a quantity read on the channel sees
#: (:func:`filtered_out`)
CHANNEL_MARGIN = 2.0
#: outside the window the step term is a bound: this many times the larger difference of
#: the three runs (a grid convergence index's safety factor for an unproven order)
BOUND_FACTOR = 3.0
#: the share of a quantity's allowance (the tolerance times the quantity) the step term may
#: take as an unobserved bound: the second, finer companion then runs no more
BOUND_SHARE = 0.7


def headline_difference(headline: Headline, run: Mapping[str, Any], other: Mapping[str, Any]
                        ) -> float | None:
    """How far two runs' values of ``headline`` lie apart [its unit]: a peak's by
    :func:`peak_difference` (a missing series counts as zero: a rigid twin has no
    deflection), any other's as the difference of the values (a link's own quantity the
    other run lacks counts as zero: a rigid twin's first crest); None if the run has no
    value or the other run none of a quantity of the motion."""
    mine = headline.read(run)
    if mine is None:
        return None
    if headline.kind == "peak":
        if headline.series not in other:
            return mine
        return peak_difference(run, other, headline.series)
    if headline.kind == "history":
        if headline.series not in other and headline.link is None:
            return None
        return history_difference(run, other, headline.series)
    value = headline.read(other)
    if value is None and headline.link is not None:  # a rigid twin: none of its own
        value = 0.0
    return None if value is None else abs(mine - value)


@dataclass
class ErrorEstimate:
    """The estimated step error of one run (see the module doc)."""

    values: dict[str, float] = field(default_factory=dict)
    method: str = ""
    validity: str = ""
    companion_wall_time_s: float = 0.0
    #: the quantities whose value is a bound (outside the asymptotic range), with the order
    #: their three runs showed
    bounds: dict[str, float] = field(default_factory=dict)
    #: the finest companion run when ``values`` are its errors (``report_finest``), else None
    finest: CaseResult | None = None




def richardson_error(value: float, companion: float, step_s: float, companion_step: float,
                     order: int) -> float:
    """Estimated error of ``value`` (run at ``step_s``) from a ``companion`` at twice or half
    the step, for a method of ``order``: ``|q_h - q_2h| / (2^p - 1)`` or
    ``|q_h - q_h/2| 2^p / (2^p - 1)``."""
    factor = 2.0 ** order
    difference = abs(value - companion)
    if companion_step > step_s:
        return difference / (factor - 1.0)
    return difference * factor / (factor - 1.0)


def unresolved_time_scales(time_scales: list[tuple[float, float, str]], step_s: float
                           ) -> list[str]:
    """The time scales (``(period [s], needed, what)``) with fewer than
    :data:`MIN_STEPS_PER_PERIOD` steps per period at ``step_s``, as phrases."""
    return [f"{what} ({period:.3g} s: {period / step_s:.3g} steps per period)"
            for period, _, what in _unresolved(time_scales, step_s)]


def _unresolved(time_scales: list[tuple[float, float, str]], step_s: float
                ) -> list[tuple[float, float, str]]:
    return [scale for scale in time_scales
            if math.isfinite(scale[0]) and scale[0] / step_s < MIN_STEPS_PER_PERIOD]


def numerical_frequency_Hz(period_s: float, step_s: float) -> float:
    """The frequency [Hz] at which an implicit second-order integrator carries a mode of
    ``period_s`` [s] at ``step_s`` [s]: 2 atan(omega h / 2) / (2 pi h), the trapezoidal
    rule's algorithmic frequency (generalized-alpha's lies near it): the mode itself when
    resolved, below the Nyquist frequency 1 / (2 h) however fast it is."""
    omega_h = 2 * math.pi * step_s / period_s
    return 2 * math.atan(omega_h / 2) / (2 * math.pi * step_s)


def filtered_out(time_scales: list[tuple[float, float, str]], step_s: float,
                 cutoff_Hz: float | None) -> bool:
    """Whether every time scale ``step_s`` leaves unresolved rings, as integrated, at least
    :data:`CHANNEL_MARGIN` times above the headline channel's cut-off ``cutoff_Hz`` [Hz]:
    a quantity read on the channel then does not see it (its low-pass passes 1 / (1 +
    margin^8) of it, 0.4 %, and less the higher it lies), and is in the asymptotic range of
    what it does see. False without a channel."""
    if cutoff_Hz is None or not math.isfinite(cutoff_Hz):
        return False
    return all(numerical_frequency_Hz(period, step_s) >= CHANNEL_MARGIN * cutoff_Hz
               for period, _, _ in _unresolved(time_scales, step_s))


def estimate_step_error(scene: Scene, result: CaseResult,
                        run_companion: Callable[[Scene], CaseResult],
                        time_scales: list[tuple[float, float, str]],
                        headlines: Mapping[str, Headline] = BUILTIN_HEADLINES,
                        allowances: Mapping[str, float] | None = None,
                        report_finest: bool = False) -> ErrorEstimate:
    """The estimated step error of ``result``, the run of ``scene`` (concrete models, solver
    keys resolved), from finer companion runs made by ``run_companion`` (see the module
    doc). ``time_scales``: the scene's (:func:`flex.dynamics.advice.time_scales`);
    ``headlines``: the quantities estimated (:mod:`flex.data.headlines`); ``allowances``:
    the error the tolerance allows each quantity it applies to [its unit]: where the run's
    step leaves a time scale unresolved and the bound from the first companion alone
    (:data:`BOUND_FACTOR` times its difference) stays within :data:`BOUND_SHARE` of every
    allowance, the second companion is not run (its order would change nothing the
    tolerance asks) and every value is that bound. ``report_finest``: the values are the
    errors of the finest companion (returned as ``finest``: the run a caller reports), not
    of ``result``: ``|q_h - q_h/2| / (2^p - 1)`` (with a third run, of its last difference
    at the observed order)."""
    sim = scene["simulation"]
    step = float(sim["step_s"])
    unresolved = unresolved_time_scales(time_scales, step)
    # quantities read on the headline channel do not see time scales it filters out
    seen = set() if not unresolved else {
        name for name, headline in headlines.items()
        if not (headline.channel and filtered_out(time_scales, step,
                                                  result.attrs.get(CHANNEL_ATTR)))}
    order = integrator_order(sim)
    steps = [step, STEP.finer(step)] + ([STEP.finer(STEP.finer(step))] if seen else [])
    start = time.perf_counter()
    made = [result]
    for companion_step in steps[1:]:
        if len(made) == 2 and allowances is not None and _bound_suffices(
                {name: h for name, h in headlines.items() if name in seen},
                [run.datasets for run in made],
                {name: a for name, a in allowances.items() if name in seen}):
            steps = steps[:2]
            break
        try:
            made.append(run_companion(apply_overrides(scene, [
                f"simulation.step_s={companion_step!r}", "simulation.output_step_s=0.0",
                "simulation.error_estimate=false"])))
        except FlexError as exc:
            return ErrorEstimate({}, _method(steps, step, order, unresolved, False),
                                 f"not estimated: the companion run at {companion_step:g} s "
                                 f"failed ({exc})", time.perf_counter() - start)
    # the finest run is reported only where it has every quantity the run has
    report_finest = report_finest and all(
        headline.read(made[-1].datasets) is not None for headline in headlines.values()
        if headline.read(result.datasets) is not None)
    values, bounds = _step_values(headlines, [run.datasets for run in made], order,
                                  seen, report_finest)
    return ErrorEstimate(values, _method(steps, step, order, unresolved, report_finest),
                         _validity(unresolved, bounds, len(seen) < len(headlines)),
                         time.perf_counter() - start, bounds,
                         made[-1] if report_finest else None)


def _step_values(headlines: Mapping[str, Headline], runs: list[Mapping[str, Any]], order: int,
                 unresolved: set[str], finest: bool
                 ) -> tuple[dict[str, float], dict[str, float]]:
    """Each quantity's step error (of the run, or of the finest run) and the quantities
    whose value is a bound, with their observed order (NaN: not observed); ``unresolved``:
    the quantities that see a time scale the step leaves unresolved."""
    values: dict[str, float] = {}
    bounds: dict[str, float] = {}
    for name, headline in headlines.items():
        read_values = [headline.read(datasets) for datasets in runs]
        if read_values[0] is None:
            continue
        if any(value is None for value in read_values):  # a companion lacks it: unknown
            values[name] = math.nan
            continue
        differences = [_difference(headline, runs[k], runs[k + 1], read_values[k:k + 2])
                       for k in range(len(runs) - 1)]
        if name in unresolved and len(differences) == 1:  # the order unobserved: a bound
            values[name], bounds[name] = BOUND_FACTOR * differences[0], math.nan
            continue
        values[name], observed = (finest_estimate if finest else finer_estimate)(differences,
                                                                                  order)
        if observed is not None:
            bounds[name] = observed
    return values, bounds


def _method(steps: list[float], step: float, order: int, unresolved: list[str],
            finest: bool) -> str:
    at = ", ".join(f"{h:g}" for h in steps[1:])
    if len(steps) > 2:
        how = (f"the observed order (within {ORDER_WINDOW:g} of the integrator's {order}; "
               f"outside it a bound, {BOUND_FACTOR:g}x the larger difference)")
    elif unresolved:
        how = (f"no second companion: the bound {BOUND_FACTOR:g}x the difference (the order "
               f"unobserved) met the tolerance")
    else:
        how = f"the integrator's order {order}"
    reported = (f" The finest run (h = {steps[-1]:g} s) is the one reported; the term is its "
                f"error." if finest else "")
    return (f"step halving: {'companion runs' if len(steps) > 2 else 'a companion run'} at "
            f"h = {at} s (the run: {step:g} s), Richardson extrapolation with {how}."
            + reported)


def _bound_suffices(headlines: Mapping[str, Headline], runs: list[Mapping[str, Any]],
                    allowances: Mapping[str, float]) -> bool:
    """Whether :data:`BOUND_FACTOR` times the first companion's difference stays within
    :data:`BOUND_SHARE` of each quantity's allowance [its unit]."""
    for name, allowance in allowances.items():
        headline = headlines.get(name)
        values = [None if headline is None else headline.read(datasets) for datasets in runs]
        if headline is None or any(value is None for value in values):
            return False
        difference = _difference(headline, runs[0], runs[1], values)
        if not BOUND_FACTOR * difference <= BOUND_SHARE * allowance:
            return False
    return True


def _difference(headline: Headline, run: Mapping[str, Any], other: Mapping[str, Any],
                values: list[float]) -> float:
    if headline.kind == "peak":
        return peak_difference(run, other, headline.series)
    if headline.kind == "history":
        return history_difference(run, other, headline.series)
    return abs(values[0] - values[1])


def finer_estimate(differences: list[float], order: int) -> tuple[float, float | None]:
    """The run's step error from ``|q_h - q_h/2|`` (and ``|q_h/2 - q_h/4|``) for an
    integrator of ``order`` (module doc), and the observed order when the value is a bound
    (None: an estimate)."""
    first = differences[0]
    if len(differences) < 2:
        return richardson_error(first, 0.0, 1.0, 0.5, order), None
    second = differences[1]
    if first == 0.0 and second == 0.0:
        return 0.0, None
    observed = math.log2(first / second) if first > 0 and second > 0 else math.nan
    if abs(observed - order) <= ORDER_WINDOW:
        return richardson_error(first, 0.0, 1.0, 0.5, observed), None
    return BOUND_FACTOR * max(first, second), observed


def finest_estimate(differences: list[float], order: int) -> tuple[float, float | None]:
    """The finest run's step error from the differences of the runs at h, h/2 (and h/4),
    for an integrator of ``order``: the last difference over ``2^p - 1``, at the observed
    order when three runs show one inside :data:`ORDER_WINDOW`; outside it a bound,
    :data:`BOUND_FACTOR` times the larger difference, with the observed order (None: an
    estimate)."""
    last = differences[-1]
    if len(differences) < 2:
        return richardson_error(last, 0.0, 0.5, 1.0, order), None
    first = differences[0]
    if first == 0.0 and last == 0.0:
        return 0.0, None
    observed = math.log2(first / last) if first > 0 and last > 0 else math.nan
    if abs(observed - order) <= ORDER_WINDOW:
        return richardson_error(last, 0.0, 0.5, 1.0, observed), None
    return BOUND_FACTOR * max(first, last), observed


def _validity(unresolved: list[str], bounds: dict[str, float], channel_sees: bool) -> str:
    if not unresolved:
        return (f"asymptotic: every time scale of the scene has at least "
                f"{MIN_STEPS_PER_PERIOD:g} steps per period")
    text = "outside the asymptotic range for " + "; ".join(unresolved)
    if channel_sees:
        text += (f" (not for the quantities read on the headline channel: as integrated "
                 f"it rings at least {CHANNEL_MARGIN:g}x above the channel's cut-off, which "
                 f"filters it out; their step terms are estimates at the integrator's order)")
    if bounds and all(math.isnan(order) for order in bounds.values()):
        return text + (": the order was not observed (its bound met the tolerance): the step "
                       "terms are bounds")
    text += ": the order was observed on a second, finer companion"
    if bounds:
        text += (" and left the window for " + ", ".join(
            f"{name} (observed order {order:.2g})" for name, order in bounds.items())
            + ": their step terms are bounds")
    return text


def peak_difference(run: dict[str, Any], other: dict[str, Any], path: str) -> float:
    """How far two runs' peaks of ``|path|`` may lie apart: the larger of the peaks'
    difference and what remains of the runs' difference over the peak's crest (where the
    run's ``|path|`` stays above half its peak) once the other run is shifted in time to
    match it best. A crest's height does not change when the whole crest moves in time
    (phase error of the dominant mode), but it does when faster content riding on it lands
    at another phase: two runs' peaks can then agree by luck (measured by ``make
    estimates``: an undamped 1 mm plate at h = 1e-5 s, 4.3 kHz content, 21x optimistic from
    the peaks alone). Conservative where the peak is the top of an envelope of many similar
    crests (an undamped thick plate ringing): each crest's height moves with the phase of
    the ringing while the envelope's top stays (a 5 mm plate's estimate 70x its true
    error; using the peaks' difference alone wherever another crest wins in the other run
    made a 10 mm plate's 13x optimistic instead)."""
    time_a, a = _series(run, path)
    time_b, b = _series(other, path)
    peaks = abs(float(np.max(np.abs(a))) - float(np.max(np.abs(b))))
    crest = _crest(np.abs(a))
    if crest.size < 3:
        return peaks
    spacing = max(float(np.median(np.diff(time_a))), float(np.median(np.diff(time_b))))

    def mismatch(shift: float) -> float:
        return float(np.max(np.abs(a[crest] - np.interp(time_a[crest] + shift, time_b, b))))

    shifts = np.linspace(-4.0 * spacing, 4.0 * spacing, 161)
    return max(peaks, min(mismatch(shift) for shift in shifts))


def _series(datasets: dict[str, Any], path: str) -> tuple[np.ndarray, np.ndarray]:
    return (np.asarray(datasets["time"].data, dtype=float),
            np.asarray(datasets[path].data, dtype=float))


def _crest(magnitude: np.ndarray) -> np.ndarray:
    """Indices of the crest that holds the peak: the contiguous samples around it at or
    above half the peak."""
    top = int(np.argmax(magnitude))
    below = magnitude < 0.5 * magnitude[top]
    start = top - int(np.argmax(below[top::-1])) + 1 if below[:top + 1].any() else 0
    end = top + int(np.argmax(below[top:])) if below[top:].any() else magnitude.size
    return np.arange(start, end)


__all__ = ["BOUND_FACTOR", "BOUND_SHARE", "ErrorEstimate", "MIN_STEPS_PER_PERIOD",
           "ORDER_WINDOW", "estimate_step_error", "finer_estimate", "finest_estimate",
           "headline_difference",
           "peak_difference", "richardson_error", "unresolved_time_scales", "CHANNEL_MARGIN",
           "filtered_out", "numerical_frequency_Hz"]
