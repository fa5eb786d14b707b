"""An estimate of a run's own step (time discretization) error on its headline quantities.

Contract of :func:`estimate_step_error`: given a finished run of a concrete scene (links
rigid, ffrf or nonlinear_fe; ``"auto"`` solver keys resolved) and a way to run a companion
scene, it runs companions that differ only in the step -- at twice and four times the step
when the end time is a whole number of doubled steps, else one at half the step -- and
returns an :class:`ErrorEstimate`:

- ``values``: for each headline quantity (``headlines``, default
  :data:`flex.fidelity.headlines.BUILTIN_HEADLINES`: the crank angle and the slider position
  at the end time, the peak elastic midpoint deflection of each flexible link, the peak von
  Mises stress of each FFRF link away from its joint faces), the
  estimated error of the run's value [the quantity's units], by Richardson extrapolation.
  With the runs at h, 2h and 4h: the larger of ``|q_h - q_2h| / (2^p - 1)`` and the pair
  (2h, 4h)'s, scaled to h by ``2^-p``, with p the order the three runs show
  (:func:`observed_order`, clipped to 1..the integrator's order). The second pair guards
  against two runs that agree by the phase of a crest (measured by ``make estimates``: 27x
  optimistic on a 5 mm plate's crank angle with one pair), and the observed order against
  the formal one's optimism outside the asymptotic range. With one companion at h/2:
  ``|q_h - q_h/2| * 2^p / (2^p - 1)`` with the integrator's order p
  (:func:`integrator_order`: 2 for generalized-alpha);
- ``method``: that sentence, with the companions' steps;
- ``validity``: ``"asymptotic"`` when every time scale of the scene
  (:func:`flex.dynamics.solver.time_scales`: the spring or crank period, the highest
  retained mode of each flexible link) has at least :data:`MIN_STEPS_PER_PERIOD` steps per
  period at the run's step; otherwise the sentence names the time scales below it: their
  content is numerically damped in both runs, so the estimate does not cover it (it may be
  optimistic there);
- ``companion_wall_time_s``: what the estimate cost [s].

It covers the step only: modal truncation and mesh errors are not estimated here. A
companion that fails (a step the scene cannot take) gives no values and says why in
``validity``. :func:`ErrorEstimate.attrs` are the case attributes ``estimated_error_*``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from flex.base.errors import FlexError
from flex.data.results import CaseResult
from flex.data.scene import Scene, apply_overrides
from flex.fidelity.headlines import BUILTIN_HEADLINES, Headline, crest_gap

#: order of accuracy of the explicit Runge-Kutta methods (``simulation.explicit_method``)
EXPLICIT_ORDERS = {"RK44": 4, "RK67": 6, "ExplicitMidpoint": 2}
#: a time scale with fewer steps per period than this is outside the asymptotic range
MIN_STEPS_PER_PERIOD = 10.0
#: case attribute prefix
PREFIX = "estimated_error_"


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

    def attrs(self) -> dict[str, Any]:
        """Case attributes: ``estimated_error_<quantity>`` [its units, in the name] and
        ``estimated_error_method``, ``_validity``, ``_companion_wall_time_s``."""
        out: dict[str, Any] = {f"{PREFIX}{name}": value for name, value in self.values.items()}
        out.update({f"{PREFIX}method": self.method, f"{PREFIX}validity": self.validity,
                    f"{PREFIX}companion_wall_time_s": self.companion_wall_time_s})
        return out


def integrator_order(simulation: dict[str, Any]) -> int:
    """Order of accuracy of the scene's integrator (resolved ``[simulation]`` keys):
    generalized-alpha 2 (Chung and Hulbert, any spectral radius); Newmark with velocity-level
    constraints 2 at spectral radius 1 (trapezoidal rule), else 1 (gamma > 1/2); explicit
    Runge-Kutta its own (:data:`EXPLICIT_ORDERS`)."""
    if simulation["integrator"] == "explicit_penalty":
        return EXPLICIT_ORDERS[simulation["explicit_method"]]
    if simulation["formulation"] == "index2" and simulation["spectral_radius"] < 1.0:
        return 1
    return 2


def companion_step_s(step_s: float, end_time_s: float) -> float:
    """Twice ``step_s`` if the end time is a whole number of doubled steps, else half."""
    doubled = 2.0 * step_s
    count = end_time_s / doubled
    return doubled if abs(count - round(count)) < 1e-9 * max(count, 1.0) else step_s / 2.0


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
            for period, _, what in time_scales
            if math.isfinite(period) and period / step_s < MIN_STEPS_PER_PERIOD]


def estimate_step_error(scene: Scene, result: CaseResult,
                        run_companion: Callable[[Scene], CaseResult],
                        time_scales: list[tuple[float, float, str]],
                        headlines: Mapping[str, Headline] = BUILTIN_HEADLINES) -> ErrorEstimate:
    """The estimated step error of ``result``, the run of ``scene`` (concrete models, solver
    keys resolved), from one companion run made by ``run_companion`` (see the module doc).
    ``time_scales``: the scene's (:func:`flex.dynamics.solver.time_scales`); ``headlines``:
    the quantities estimated (:mod:`flex.fidelity.headlines`)."""
    sim = scene["simulation"]
    step = float(sim["step_s"])
    other = companion_step_s(step, float(sim["end_time_s"]))
    unresolved = unresolved_time_scales(time_scales, step)
    validity = ("asymptotic: every time scale of the scene has at least "
                f"{MIN_STEPS_PER_PERIOD:g} steps per period" if not unresolved else
                "outside the asymptotic range for " + "; ".join(unresolved)
                + ": that content is numerically damped in both runs and the estimate does "
                  "not cover it")
    order = integrator_order(sim)
    steps = [step, other]
    further = companion_step_s(other, float(sim["end_time_s"])) if other > step else 0.0
    if further > other:  # a second pair: guards against a lucky first one, shows the order
        steps.append(further)  # (only a doubling: a halving would repeat the run's own step)
    at = ", ".join(f"{h:g}" for h in steps[1:])
    method = (f"step doubling: {'companion runs' if len(steps) > 2 else 'a companion run'} "
              f"at h = {at} s (the run: {step:g} s), Richardson extrapolation with the "
              f"integrator's order "
              f"{order}{'; the larger of the two pairs, scaled to h' if len(steps) > 2 else ''}"
              f".")
    start = time.perf_counter()
    runs = [result.datasets]
    for companion_step in steps[1:]:
        try:
            runs.append(run_companion(apply_overrides(scene, [
                f"simulation.step_s={companion_step!r}", "simulation.output_step_s=0.0",
                "simulation.error_estimate=false"])).datasets)
        except FlexError as exc:
            return ErrorEstimate({}, method, f"not estimated: the companion run at "
                                 f"{companion_step:g} s failed ({exc})",
                                 time.perf_counter() - start)
    values = {}
    for name, headline in headlines.items():
        read_values = [headline.read(datasets) for datasets in runs]
        if read_values[0] is None:
            continue
        if any(value is None for value in read_values):  # a companion lacks it: unknown
            values[name] = math.nan
            continue
        if headline.kind == "peak":
            differences = [peak_difference(runs[k], runs[k + 1], headline.series)
                           for k in range(len(runs) - 1)]
            values[name] = _estimate_from_differences(differences, steps, order)
        else:
            values[name] = _estimate(read_values, steps, order)
    return ErrorEstimate(values, method, validity, time.perf_counter() - start)


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


def _estimate_from_differences(differences: list[float], steps: list[float], order: int
                               ) -> float:
    """:func:`_estimate` from the pairs' differences ``|q_h - q_2h|`` (and ``|q_2h -
    q_4h|``) or ``|q_h - q_h/2|``."""
    if len(differences) < 2:
        return richardson_error(differences[0], 0.0, steps[0], steps[1], order)
    p = _order(differences[0], differences[1], order)
    first = richardson_error(differences[0], 0.0, steps[0], steps[1], p)
    second = richardson_error(differences[1], 0.0, steps[1], steps[2], p)
    return max(first, second * (steps[0] / steps[1]) ** p)


def _estimate(values: list[float], steps: list[float], order: int) -> float:
    """The run's (``values[0]`` at ``steps[0]``) estimated error from its companions: the
    first pair's Richardson estimate; with a third run (steps h, 2h, 4h) the larger of it and
    the second pair's scaled to the run's step by ``2^-p``, both with the observed order
    (:func:`observed_order`) in place of the formal one."""
    if len(values) < 3:
        return richardson_error(values[0], values[1], steps[0], steps[1], order)
    p = observed_order(values, order)
    first = richardson_error(values[0], values[1], steps[0], steps[1], p)
    second = richardson_error(values[1], values[2], steps[1], steps[2], p)
    return max(first, second * (steps[0] / steps[1]) ** p)


def observed_order(values: list[float], order: int) -> float:
    """The order of convergence three runs at h, 2h, 4h show, ``log2(|q_2h - q_4h| / |q_h -
    q_2h|)``, clipped to [1, ``order``]: outside the asymptotic range the error falls more
    slowly than the formal order says (unresolved content damped step by step), and a
    formal-order Richardson estimate is then optimistic; an agreement by luck (a vanishing
    first difference) reads as the formal order."""
    return _order(abs(values[0] - values[1]), abs(values[1] - values[2]), order)


def _order(near: float, far: float, order: int) -> float:
    """:func:`observed_order` from the two differences."""
    if near == 0.0 or far == 0.0:
        return float(order)
    return float(min(max(math.log2(far / near), 1.0), order))


__all__ = ["ErrorEstimate", "MIN_STEPS_PER_PERIOD", "companion_step_s", "crest_gap",
           "headline_difference", "peak_difference",
           "estimate_step_error", "integrator_order", "observed_order", "richardson_error",
           "unresolved_time_scales"]
