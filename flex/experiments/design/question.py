"""``flex design``: a designer's question about their own scene, answered with its evidence.

A :class:`Question` varies one input (``thickness`` of the coupler, initial crank ``angle``,
spring ``preload`` or ``rate``) to meet one target (``peak_speed`` at least, ``deployment_time``
at most, ``final_angle`` at least) while the peak coupler stress times the safety factor stays
below the allowable stress, every case simulated with ``coupler.model = "auto"``
(:func:`flex.experiments.design.cases.design_case`). The answer is the feasible value nearest the
preferred end: the smallest thickness (the lightest coupler), preload and rate, and for the
angle the one nearest the scene's own.

How (:func:`answer`): a scan of :data:`SCAN_POINTS` values over the range (log-spaced except
the angle), then the boundary of the feasible set between the last infeasible and the first
feasible scan point by scipy's ``brentq`` on the smallest margin (target margin, stress margin;
-1 where ``auto`` refuses the scene). A target no scanned value meets raises
:class:`flex.base.errors.FlexError` (exit status 2) naming the best value reached. Every
evaluated case is evidence: :func:`write_answer` stores them in an HDF5 file like a study's.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from flex.base.errors import FlexError
from flex.data.results import CaseResult, Dataset, write_results
from flex.data.scene import Scene, to_toml
from flex.data.scene_edit import derive_scene
from flex.experiments.design.cases import A36_YIELD_STRESS_PA, design_case
from flex.experiments.design.summary import table, table_datasets
from flex.experiments.fitting.kfit import mesh_size_m

#: variable -> (scene section, key, default range, unit, log-spaced scan, prefer)
VARIABLES = {
    "thickness": ("coupler", "thickness_m", (0.5e-3, 12.37e-3), "m", True, "smallest"),
    "angle": ("crank", "initial_angle_deg", (5.0, 85.0), "deg", False, "nearest"),
    "preload": ("drive", "spring_preload_m", (1e-3, 0.044), "m", True, "smallest"),
    "rate": ("drive", "spring_stiffness_N_per_m", (150.0, 20000.0), "N/m", True, "smallest"),
}
#: target -> (measure, sense: +1 at least, -1 at most, scale of the given value to SI, unit)
TARGETS = {"peak_speed": ("peak_crank_speed", 1, 1.0, "rad/s"),
           "deployment_time": ("deployment_time", -1, 1.0, "s"),
           "final_angle": ("final_crank_angle", 1, math.pi / 180, "deg")}
SCAN_POINTS = 9
#: brentq's tolerance, relative to the range
RELATIVE_XTOL = 1e-4


@dataclass
class Question:
    """Vary ``vary`` to meet ``target`` >= or <= ``value`` (in the target's unit) with peak
    stress x ``safety_factor`` <= ``allowable_stress_Pa``; ``bounds``: the range searched
    (default: :data:`VARIABLES`)."""

    vary: str
    target: str
    value: float
    allowable_stress_Pa: float = A36_YIELD_STRESS_PA
    safety_factor: float = 1.5
    bounds: tuple[float, float] | None = None

    def check(self) -> None:
        """Refuse a question that cannot be asked (FlexError, one line)."""
        if self.vary not in VARIABLES:
            raise FlexError(f"design: --vary {self.vary!r}: one of {', '.join(VARIABLES)}")
        if self.target not in TARGETS:
            raise FlexError(f"design: target {self.target!r}: one of {', '.join(TARGETS)}")
        if not (math.isfinite(self.value) and self.value > 0):
            raise FlexError(f"design: target value {self.value!r}: must be a positive number")
        if not (self.safety_factor >= 1 and self.allowable_stress_Pa > 0):
            raise FlexError("design: --safety-factor must be >= 1 and --allowable-stress > 0")
        low, high = self.range()
        if not (math.isfinite(low) and math.isfinite(high) and 0 < low < high):
            raise FlexError(f"design: range [{low:g}, {high:g}] {VARIABLES[self.vary][3]}: "
                            f"needs 0 < min < max")

    def range(self) -> tuple[float, float]:
        return self.bounds or VARIABLES[self.vary][2]


@dataclass
class Evaluation:
    """One evaluated value: its case, measures and margins (>= 0: met)."""

    value: float
    case: CaseResult
    measures: dict[str, float]
    target_margin: float
    stress_margin: float

    @property
    def margin(self) -> float:
        return min(self.target_margin, self.stress_margin)

    @property
    def model(self) -> str:
        return str(self.case.attrs.get("design_model", "refused"))


@dataclass
class Answer:
    """The answer: the value found, its evaluation, and every evaluation made (evidence)."""

    question: Question
    value: float
    best: Evaluation
    evidence: list[Evaluation] = field(default_factory=list)
    note: str = ""


def check_scene(scene: Scene, question: Question) -> None:
    """Refuse (FlexError, one line) a scene the question cannot be asked of: a spring that
    stores no energy whatever the varied value (no rate when the preload varies, no preload
    when the rate varies), a drive without a spring, a deployment time asked at or
    beyond the run's end time (a longer deployment is not measured), or refinement (its
    cases have no error budget to follow)."""
    drive, end_s = scene["drive"], float(scene["simulation"]["end_time_s"])
    if question.target == "deployment_time" and question.value >= end_s:
        raise FlexError(f"design: deployment_time <= {question.value:g} s with "
                        f"simulation.end_time_s = {end_s:g} s: a deployment longer than the "
                        f"run is not measured, so the answer would be bounded by the end "
                        f"time, not the target; accepted: simulation.end_time_s > "
                        f"{question.value:g} s (e.g. --set simulation.end_time_s="
                        f"{1.5 * question.value:g})")
    if scene["fidelity"]["refine"]:
        raise FlexError("design: fidelity.refine = true: flex design runs its cases without "
                        "error budgets (simulation.error_estimate = false), which refinement "
                        "follows; accepted: fidelity.refine = false (refine the answer with "
                        "'flex run simulate' afterwards)")
    if drive["kind"] != "spring":
        raise FlexError(f'design: drive.kind = "{drive["kind"]}": flex design varies a '
                        f'spring-driven deployment; accepted: drive.kind = "spring"')
    for vary, key, what in (("preload", "spring_stiffness_N_per_m", "rate"),
                            ("rate", "spring_preload_m", "preload")):
        if question.vary == vary and drive[key] <= 0:
            raise FlexError(f"design: --vary {vary} with drive.{key} = {drive[key]:g}: the "
                            f"spring stores no energy at any {vary} (k delta^2 / 2), nothing "
                            f"deploys; accepted: a {what} > 0")


def scene_for(scene: Scene, vary: str, value: float) -> Scene:
    """``scene`` with the varied input set (a thickness also sets its mesh)."""
    section, key = VARIABLES[vary][:2]
    overrides = {f"{section}.{key}": float(value)}
    if vary == "thickness":
        overrides["coupler.mesh_size_m"] = mesh_size_m(value)
    return derive_scene(scene, overrides)


def evaluator(scene: Scene, question: Question, cache_dir: Path | None,
              simulate: Callable[..., CaseResult] = design_case,
              say: Callable[[str], None] | None = None
              ) -> tuple[Callable[[float], Evaluation], dict[float, Evaluation]]:
    """A memoised function value -> :class:`Evaluation`, and the memo it fills (in order).
    ``say``: where a progress line per evaluated case goes (default: stderr). A target
    measure the run did not reach (a deployment not completed within the run: NaN) is not
    met."""
    measure, sense, scale, unit = TARGETS[question.target]
    target = question.value * scale
    seen: dict[float, Evaluation] = {}
    say = say or (lambda text: print(f"flex: design: {text}", file=sys.stderr, flush=True))

    def evaluate(value: float) -> Evaluation:
        if value not in seen:
            name = f"{question.vary}_{len(seen):02d}"
            start = time.perf_counter()
            case = simulate(name, scene_for(scene, question.vary, value), cache_dir=cache_dir)
            values = {key[len("measures/"):]: float(np.asarray(d.data))
                      for key, d in case.datasets.items() if key.startswith("measures/")}
            if case.status != "ok" or not values:
                seen[value] = Evaluation(value, case, values, -1.0, -1.0)
            else:
                stress = values["peak_coupler_stress"] * question.safety_factor
                reached = sense * (values[measure] - target) / target
                seen[value] = Evaluation(value, case, values,
                                         -1.0 if math.isnan(reached) else reached,
                                         1 - stress / question.allowable_stress_Pa)
            got = seen[value].measures.get(measure, math.nan) / scale
            say(f"case {name}: {question.vary} = {value:.6g} {VARIABLES[question.vary][3]} -> "
                f"coupler {seen[value].model}, {question.target} "
                f"{'not reached' if math.isnan(got) else f'{got:.5g} {unit}'}, margin "
                f"{seen[value].margin:+.2%} ({time.perf_counter() - start:.1f} s)")
        return seen[value]

    return evaluate, seen


def scan_values(question: Question) -> np.ndarray:
    low, high = question.range()
    if VARIABLES[question.vary][4]:
        return np.geomspace(low, high, SCAN_POINTS)
    return np.linspace(low, high, SCAN_POINTS)


def boundary(evaluate: Callable[[float], Evaluation], infeasible: float, feasible: float,
             xtol: float) -> float:
    """The feasible side of the boundary between two values (brentq on the smallest margin,
    then a step of ``xtol`` into the feasible side if needed)."""
    root = brentq(lambda v: evaluate(v).margin, infeasible, feasible, xtol=xtol)
    step = math.copysign(xtol, feasible - infeasible)
    while evaluate(root).margin < 0 and (feasible - root) * step > 0:
        root += step
    return float(root)


def answer(scene: Scene, question: Question, cache_dir: Path | None = None,
           simulate: Callable[..., CaseResult] = design_case) -> Answer:
    """Answer ``question`` about ``scene`` (module doc); FlexError for an unreachable target."""
    question.check()
    check_scene(scene, question)
    evaluate, seen = evaluator(scene, question, cache_dir, simulate)
    values = scan_values(question)
    low, high = question.range()
    print(f"flex: design: {len(values)} scan values of {question.vary} over [{low:g}, {high:g}] "
          f"{VARIABLES[question.vary][3]}, then a bisection (~10 more cases); each case is "
          f"one run with coupler.model = auto (about a second rigid, minutes when auto "
          f"chooses a flexible coupler)", file=sys.stderr, flush=True)
    scanned = [evaluate(float(v)) for v in values]
    feasible = [e.margin >= 0 for e in scanned]
    if not any(feasible):
        raise FlexError(unreachable(question, scanned))
    low, high = question.range()
    xtol = RELATIVE_XTOL * (high - low)
    pairs = [(i, i + 1) for i in range(len(values) - 1) if feasible[i] != feasible[i + 1]]
    if VARIABLES[question.vary][5] == "nearest":
        current = float(scene[VARIABLES[question.vary][0]][VARIABLES[question.vary][1]])
        if low <= current <= high and evaluate(current).margin >= 0:
            return Answer(question, current, evaluate(current), list(seen.values()),
                          "the scene's own value already meets the target")
    else:  # smallest: the first boundary from below
        current = low
        pairs = pairs[:1] if not feasible[0] else []
    if not pairs:
        first = feasible.index(True)
        return Answer(question, float(values[first]), scanned[first], list(seen.values()),
                      "at the end of the range (every smaller value meets it too)")
    found = [boundary(evaluate, *(float(values[j]) for j in (pair if feasible[pair[1]]
                                                             else pair[::-1])), xtol)
             for pair in pairs]
    best = min(found, key=lambda v: abs(v - current))
    limit = max((e for e in seen.values() if e.margin < 0), key=lambda e: -abs(e.value - best))
    return Answer(question, best, evaluate(best), list(seen.values()),
                  f"on the feasible boundary (brentq), limited by "
                  f"{limiting(limit, TARGETS[question.target][0])}")


def limiting(evaluation: Evaluation, measure: str = "") -> str:
    """What an infeasible evaluation fails: auto's refusal, the stress, the run's end time
    (its ``measure`` not reached within the run: NaN) or the target."""
    if not evaluation.measures:
        reason = str(evaluation.case.attrs.get("design_reason", "")).split(";")[0]
        return f"auto's refusal ({reason or 'a coupler near buckling'})"
    if evaluation.stress_margin < evaluation.target_margin:
        return "the stress"
    if math.isnan(evaluation.measures.get(measure, 0.0)):
        return (f"the run's end time (its {measure.replace('_', ' ')} was not reached within "
                f"the run: simulation.end_time_s bounds the answer, not the target)")
    return "the target"


def unreachable(question: Question, scanned: list[Evaluation]) -> str:
    """The one-line refusal of a target no scanned value meets."""
    measure, sense, scale, unit = TARGETS[question.target]
    variable_unit = VARIABLES[question.vary][3]
    ran = [e for e in scanned if e.measures and not math.isnan(e.measures[measure])]
    low, high = question.range()
    what = (f"design: {question.target} {'>=' if sense > 0 else '<='} {question.value:g} "
            f"{unit} with stress x {question.safety_factor:g} <= "
            f"{question.allowable_stress_Pa / 1e6:g} MPa is unreachable by varying "
            f"{question.vary} over [{low:g}, {high:g}] {variable_unit}")
    if not ran and any(e.measures for e in scanned):
        end = scanned[0].case.scene_toml and _end_time(scanned[0].case.scene_toml)
        return (what + f": no scanned case reached its {measure.replace('_', ' ')} within the "
                f"run (simulation.end_time_s = {end:g} s: the deployment did not complete)")
    if not ran:
        reason = str(scanned[0].case.attrs.get("design_reason", "")) if scanned else ""
        return what + f": auto refused every scanned scene ({reason or 'near buckling'})"
    best = max(ran, key=lambda e: sense * e.measures[measure])
    safe = [e for e in ran if e.stress_margin >= 0]
    text = (f"{what}: the best reached is {best.measures[measure] / scale:.4g} {unit} at "
            f"{best.value:.4g} {variable_unit} (stress margin {best.stress_margin:+.2f})")
    if safe:
        top = max(safe, key=lambda e: sense * e.measures[measure])
        text += (f", the best within the stress limit {top.measures[measure] / scale:.4g} "
                 f"{unit} at {top.value:.4g} {variable_unit}")
    return text


def _end_time(scene_toml: str) -> float:
    import tomllib

    return float(tomllib.loads(scene_toml)["simulation"]["end_time_s"])


def answer_text(result: Answer) -> str:
    """The answer and its evidence (every case: value, model, measures, margins)."""
    q = result.question
    measure, sense, scale, unit = TARGETS[q.target]
    variable_unit = VARIABLES[q.vary][3]
    best = result.best
    lines = [f"answer: {q.vary} = {result.value:.6g} {variable_unit} ({result.note}): "
             f"{q.target} {best.measures[measure] / scale:.5g} {unit} "
             f"({'>=' if sense > 0 else '<='} {q.value:g}; margin {best.target_margin:+.2%}), "
             f"peak coupler stress {best.measures['peak_coupler_stress'] / 1e6:.4g} MPa x "
             f"{q.safety_factor:g} against {q.allowable_stress_Pa / 1e6:g} MPa (margin "
             f"{best.stress_margin:+.2%}), coupler model {best.model}",
             f"evidence ({len(result.evidence)} cases, coupler.model = auto):",
             f"  {'case':<14} {q.vary + ' [' + variable_unit + ']':>18} {'model':>8} "
             f"{q.target + ' [' + unit + ']':>22} {'stress [MPa]':>13} {'margin':>8}"]
    for e in sorted(result.evidence, key=lambda e: e.value):
        got = e.measures.get(measure, math.nan) / scale
        stress = e.measures.get("peak_coupler_stress", math.nan) / 1e6
        lines.append(f"  {e.case.name:<14} {e.value:>18.6g} {e.model:>8} {got:>22.5g} "
                     f"{stress:>13.4g} {e.margin:>+8.2%}")
    return "\n".join(lines)


def write_answer(result: Answer, scene: Scene, path: Path) -> Path:
    """The evidence cases and the answer in an HDF5 result file (study ``design``)."""
    q = result.question
    rows = table({e.case.name: e.case for e in result.evidence})
    summary = table_datasets(rows)
    unit = VARIABLES[q.vary][3]
    summary.update({
        "question/vary": Dataset(q.vary, "1", "the input varied"),
        "question/target": Dataset(q.target, "1", "the target measure"),
        "question/value": Dataset(q.value, TARGETS[q.target][3], "target value"),
        "question/allowable_stress": Dataset(q.allowable_stress_Pa, "Pa", "allowable stress"),
        "question/safety_factor": Dataset(q.safety_factor, "1", "on the peak stress"),
        "answer/value": Dataset(result.value, unit, f"the {q.vary} found"),
        "answer/case": Dataset(result.best.case.name, "1", "the case at the answer"),
        "answer/target_margin": Dataset(result.best.target_margin, "1", "relative"),
        "answer/stress_margin": Dataset(result.best.stress_margin, "1", "1 - SF stress/allowable"),
        "answer/evidence_values": Dataset(np.array([e.value for e in result.evidence]), unit,
                                          "every value evaluated, in order")})
    return write_results(path, "design", [e.case for e in result.evidence], to_toml(scene),
                         summary, {"summary_report": answer_text(result)})
