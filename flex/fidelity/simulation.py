"""Simulate any scene: decide its ``"auto"`` values once, integrate, estimate the error.

The layer above :mod:`flex.dynamics.solver` (which integrates concrete scenes): every
``"auto"`` (link and spring models, modes, mesh, solver keys) is decided by
:func:`flex.fidelity.auto.resolve`, once per scene; the fitted laws it reads are arguments
(``None``: the installed criterion files); a study that has just fitted a law passes it as a
:class:`flex.fidelity.laws.Criterion`.

The reduction cache folder is an argument too (``cache_dir``, keyword): FFRF reductions are
loaded from it or written to it; ``None`` builds them in memory, with no disk cache. The
command line and :mod:`flex.api` pass the user's folder
(:func:`flex.bodies.reduction.reduction_cache_dir` of the environment, read at that edge).
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError, SceneError, SimulationError
from flex.config.calibration import Calibration
from flex.config.knobs import KNOB_KEYS, settings_text
from flex.config.settings import FALLBACK, tolerance_beyond_reach
from flex.config.tolerance import Tolerance
from flex.data.headlines import BUILTIN_HEADLINES, Headline
from flex.data.results import CaseResult
from flex.data.scene import LINKS, Scene, to_toml
from flex.dynamics.advice import VALIDITY_WARNING, time_scales
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel, flexible_links
from flex.dynamics.solver import integrate, scene_reductions
from flex.fidelity.auto import Resolution, resolve
from flex.fidelity.error_budget import error_budget
from flex.fidelity.laws import Criterion
from flex.fidelity.refinement import (
    MAX_ATTEMPTS,
    NOTHING_TO_REFINE,
    Step,
    free_knobs,
    next_attempt,
    observed_fall,
)
from flex.fidelity.stored_budget import (
    BudgetRow,
    ErrorBudget,
    coverage_attrs,
    coverage_text,
    headline_attrs,
    tolerance_coverage,
)


def simulate(scene: Scene, name: str = "case", reduction: Any = None,
             crank_reduction: Any = None, criterion: Criterion | None = None,
             crank_criterion: Criterion | None = None, *,
             cache_dir: Path | None = None, calibration: Calibration | None = None,
             link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS,
             headlines: Mapping[str, Headline] = BUILTIN_HEADLINES) -> CaseResult:
    """One case of any scene; raises :class:`~flex.base.errors.FlexError` on bad input or
    divergence.

    Its ``"auto"`` values are decided once (:func:`flex.fidelity.auto.resolve`, with
    ``criterion`` / ``crank_criterion``, None: ``calibration``'s laws; given reductions are
    ignored when ``auto`` picked a link's model: it picks the modes too); the choices and
    their reasons go to stderr and into the result's attributes (``fidelity_<link>_*``,
    ``solver_defaults_*``); then :func:`flex.dynamics.solver.integrate` integrates the
    concrete scene. ``reduction`` / ``crank_reduction``: reductions of ``ffrf`` links (None:
    built, or loaded from ``cache_dir``). ``cache_dir``: the reduction cache folder (None:
    reductions are built in memory, no disk cache). ``calibration``: the laws, FFRF rule and
    solver defaults the ``"auto"`` values resolve from (:mod:`flex.config.calibration`;
    None: the bundled one). ``link_models``: the link models the scene may name
    (:mod:`flex.dynamics.link_models`; default: the built-in ones).

    With ``simulation.error_estimate`` (the default), companion runs estimate the run's error
    budget on its headline quantities, term by term (step, modes, mesh, model;
    :mod:`flex.fidelity.error_budget`): case attributes ``estimated_error_*``. A failed
    companion leaves the run as it is, its term out, and says why in
    ``estimated_error_leaves_out``. ``headlines``: the quantities budgeted and certified
    (:mod:`flex.data.headlines`; default: the built-in ones).
    """
    beyond = tolerance_beyond_reach(scene, calibration, link_models=link_models)
    if beyond:  # said before the (possibly long) work starts, and stored with the result
        print(f"flex: warning: case {name}: {beyond}", file=sys.stderr, flush=True)
    resolution = resolve(scene, criterion, crank_criterion, cache_dir=cache_dir,
                         calibration=calibration, link_models=link_models)
    if scene["fidelity"]["refine"]:
        return refine(resolution, name, cache_dir=cache_dir, link_models=link_models,
                      headlines=headlines, free=free_knobs(scene))
    return simulate_resolved(resolution, name, reduction, crank_reduction,
                             cache_dir=cache_dir, beyond=beyond, link_models=link_models,
                             headlines=headlines)


def simulate_resolved(resolution: Resolution, name: str = "case", reduction: Any = None,
                      crank_reduction: Any = None, *, cache_dir: Path | None = None,
                      beyond: str = "",
                      link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS,
                      headlines: Mapping[str, Headline] = BUILTIN_HEADLINES,
                      companions: dict[str, CaseResult] | None = None) -> CaseResult:
    """:func:`simulate` of a scene already resolved (:func:`flex.fidelity.auto.resolve`):
    integrate, attributes (the headline values always, :func:`flex.fidelity.stored_budget.
    headline_attrs`), error budget. ``beyond``: why the scene's tolerance is beyond what flex
    can certify ("" if it is not), stored as a validity warning. ``companions``: runs already
    made, by their scene's TOML (:func:`companion_key`; :func:`refine` keeps them across its
    attempts): a companion found there is not run again, and neither is the run itself when
    one of them is its scene (the next attempt of a refinement is the last one's finer
    companion); the companions this run makes are added."""
    result, budget = _run_budgeted(resolution, name, reduction, crank_reduction,
                                   cache_dir=cache_dir, beyond=beyond, link_models=link_models,
                                   headlines=headlines, companions=companions)
    _state_coverage(result, budget, resolution.scene, name, link_models, refined=False)
    return result


def _run_budgeted(resolution: Resolution, name: str, reduction: Any, crank_reduction: Any, *,
                  cache_dir: Path | None, beyond: str, link_models: Mapping[str, LinkModel],
                  headlines: Mapping[str, Headline], companions: dict[str, CaseResult] | None
                  ) -> tuple[CaseResult, ErrorBudget | None]:
    """:func:`simulate_resolved`, returning the run and its budget in memory (None: not
    estimated)."""
    scene = resolution.scene
    if any(decision.link != "spring" for decision in resolution.decisions):
        reduction = crank_reduction = None
    if scene["simulation"]["error_estimate"]:  # the companion runs reuse the reductions
        reduction, crank_reduction = scene_reductions(scene, reduction, crank_reduction,
                                                      cache_dir=cache_dir,
                                                      link_models=link_models)
    made = (companions or {}).get(companion_key(scene))
    result = (replace(made, name=name, scene_toml=to_toml(scene), attrs=dict(made.attrs))
              if made is not None else
              integrate(scene, name, reduction, crank_reduction, cache_dir=cache_dir,
                        link_models=link_models, headlines=headlines))
    _case_attrs(result, scene, resolution, beyond, link_models, headlines)
    if FALLBACK in str(result.attrs.get("solver_defaults_reason", "")):
        print(f"flex: note: case {name}: outside the calibrated family: "
              f"{result.attrs.get('solver_defaults_reason', '')}", file=sys.stderr, flush=True)
    if not scene["simulation"]["error_estimate"]:
        return result, None
    prepared = {link: built for link, built in (("coupler", reduction),
                                                ("crank", crank_reduction))
                if built is not None}
    run_companion = _companion_runner(scene, name, prepared, cache_dir, link_models,
                                      headlines, companions)
    scales = time_scales(scene, prepared, link_models)
    budget = error_budget(scene, result, run_companion, scales, link_models, headlines,
                          cache_dir)
    if budget.reported_run is not None:
        result = _finest_reported(budget.reported_run, result, scene, resolution, beyond,
                                  link_models, headlines)
    _unbounded_beyond_load(scene, result, budget, link_models, headlines, cache_dir)
    result.attrs.update(budget.attrs())
    _warn_unresolved_drive(result, scales, float(scene["simulation"]["step_s"]))
    if budget.unknown:
        print(f"flex: warning: case {name}: estimated error unknown for "
              f"{', '.join(budget.unknown_quantities())}: {'; '.join(budget.unknown)}",
              file=sys.stderr, flush=True)
    return result, budget


#: case attribute naming the run a case reports when it is its step's finest companion
REPORTED_RUN_ATTR = "reported_run"


def _case_attrs(result: CaseResult, scene: Scene, resolution: Resolution, beyond: str,
                link_models: Mapping[str, LinkModel], headlines: Mapping[str, Headline]
                ) -> None:
    """The attributes every reported run carries beside its integration's: the rigid
    links' predictions, the resolution's, the headline values and the validity warning of a
    tolerance beyond reach (in place)."""
    result.attrs.update(_rigid_predictions(scene, result, link_models))
    result.attrs.update(resolution.attrs())
    result.attrs.update(headline_attrs(result.datasets, headlines))
    if beyond:
        result.attrs[VALIDITY_WARNING] = "; ".join(
            filter(None, [str(result.attrs.get(VALIDITY_WARNING, "")), beyond]))


def _finest_reported(finest: CaseResult, run: CaseResult, scene: Scene,
                     resolution: Resolution, beyond: str,
                     link_models: Mapping[str, LinkModel], headlines: Mapping[str, Headline]
                     ) -> CaseResult:
    """The step's finest companion as the case: its curves and values with the scene at
    its step (the budget states its error, :mod:`flex.fidelity.error_budget`), named and
    attributed as the run, which stays its coarser companion."""
    import tomllib

    from flex.data.scene import apply_overrides

    step_s = float(tomllib.loads(finest.scene_toml)["simulation"]["step_s"])
    at = apply_overrides(scene, [f"simulation.step_s={step_s!r}"])
    out = replace(finest, name=run.name, scene_toml=to_toml(at), attrs=dict(finest.attrs))
    _case_attrs(out, at, resolution, beyond, link_models, headlines)
    out.attrs[REPORTED_RUN_ATTR] = (
        f"the step's finest companion, at {step_s:g} s: its values and curves, with the "
        f"error the budget extrapolates for it (the run at {scene['simulation']['step_s']:g} "
        f"s is its coarser companion)")
    return out


def _companion_runner(scene: Scene, name: str, prepared: dict[str, Any],
                      cache_dir: Path | None, link_models: Mapping[str, LinkModel],
                      headlines: Mapping[str, Headline],
                      companions: dict[str, CaseResult] | None
                      ) -> Callable[[Scene], CaseResult]:
    """How the budget runs a companion scene: from ``companions`` where it was made before
    (kept there when made), with the run's reductions where its links are meshed and reduced
    alike."""
    def run_companion(companion: Scene) -> CaseResult:
        toml = to_toml(companion)
        if companions is not None and toml in companions:
            return companions[toml]
        same = all(companion[link][key] == scene[link][key] for link in ("coupler", "crank")
                   for key in ("model", "modes", "mesh_size_m"))
        out = integrate(companion, f"{name}_companion",
                        prepared.get("coupler") if same else None,
                        prepared.get("crank") if same else None, cache_dir=cache_dir,
                        link_models=link_models, headlines=headlines)
        if companions is not None:
            companions[toml] = out
        return out
    return run_companion


def companion_key(scene: Scene) -> str | None:
    """The key under which a run of ``scene`` would be found among companion runs: the TOML
    of the scene as a companion runs it (every step stored, no budget of its own); None for
    a scene that stores fewer samples than every step (no companion is such a run)."""
    from flex.data.scene import apply_overrides

    if float(scene["simulation"]["output_step_s"]) != 0.0:
        return None
    return to_toml(apply_overrides(scene, ["simulation.output_step_s=0.0",
                                           "simulation.error_estimate=false"]))


def _unbounded_beyond_load(scene: Scene, result: CaseResult, budget: Any,
                           link_models: Mapping[str, LinkModel],
                           headlines: Mapping[str, Headline],
                           cache_dir: Path | None = None) -> None:
    """Model terms that are unknown (no certificate) when the run compressed the coupler
    beyond the load up to which they were measured: its own quantities' when its rung has no
    bound there (or the run lies beyond the rung's ``measured_load_ratio``,
    :mod:`flex.config.ladder`: an exact beam 1.5-100 x beyond its Euler load was certified
    to 0.07-5 %), every quantity's when the term is the difference to an exact-beam
    companion beyond the beam's (a rigid 0.3 mm plate's 'met' against a buckled beam)."""
    from flex.base.physics import Plate
    from flex.config.ladder import EXACT_BEAM_MEASURED_LOAD_RATIO
    from flex.fidelity.criteria import euler_load_ratio

    coupler = scene["coupler"]
    rung = link_models[coupler["model"]].rung(coupler)
    needed = ("joints/B/force_on_coupler", "joints/C/force_on_coupler", "coupler/angle")
    if rung is None or not all(n in result.datasets for n in needed):
        return
    ratio = euler_load_ratio(*(np.asarray(result.datasets[n].data) for n in needed),
                             Plate.of(coupler))
    against = rung.measured_against is not None and ratio > EXACT_BEAM_MEASURED_LOAD_RATIO
    unbounded = rung.bound is not None and not (math.isfinite(rung.bound(coupler, ratio,
                                                                         cache_dir))
                                                and ratio <= rung.measured_load_ratio)
    names = list(budget.terms) if against else [
        name for name in budget.terms if unbounded and headlines[name].link == "coupler"]
    for name in names:
        budget.terms[name]["model"] = math.nan
    if names:
        budget.unknown.append(f"model: the coupler is compressed to {ratio:.3g} x its Euler "
                              f"load, where the {rung.name} model's error was never measured "
                              f"(no bound: see the validity warning)")


def _warn_unresolved_drive(result: CaseResult, scales: list[tuple[float, float, str]],
                           step_s: float) -> None:
    """A drive time scale (the spring on the mechanism, a crank turn) with fewer steps per
    period than the step estimate's asymptotic range: the motion itself is numerically
    damped and its error not covered; stored as a validity warning (stderr repeats it)."""
    from flex.dynamics.advice import DRIVE_SCALES
    from flex.fidelity.error_estimate import MIN_STEPS_PER_PERIOD, unresolved_time_scales

    unresolved = unresolved_time_scales([s for s in scales if s[2] in DRIVE_SCALES], step_s)
    if unresolved:
        text = (f"the step does not resolve the drive: {'; '.join(unresolved)}, fewer than "
                f"{MIN_STEPS_PER_PERIOD:g}: the motion is numerically damped and its estimated "
                f"error does not cover that")
        result.attrs[VALIDITY_WARNING] = "; ".join(
            filter(None, [str(result.attrs.get(VALIDITY_WARNING, "")), text]))


def refine(resolution: Resolution, name: str = "case", *, cache_dir: Path | None = None,
           link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS,
           headlines: Mapping[str, Headline] = BUILTIN_HEADLINES,
           free: frozenset[str] = frozenset(KNOB_KEYS)) -> CaseResult:
    """``fidelity.refine``: run the resolved scene with its error budget; while a certified
    quantity (a headline whose entry says ``certified``: each flexible link's peak
    deflection and first crest, docs/criterion.md) has a certified error above
    ``fidelity.tolerance`` relative to itself, turn the knob predicted to remove the most of
    its certificate per second of cost (:func:`flex.fidelity.refinement.next_attempt`: the
    step halved, the modes of the modal links raised as the modes companion's, the mesh of the
    meshed links halved, a link climbed to the next rung of the ladder; each term's fall as
    observed when its knob was last turned) and run again, until every one meets it, the next
    run's estimated cost would pass ``fidelity.refine_limit_s`` [s], :data:`MAX_ATTEMPTS`
    runs are made or no knob can lower it. Returns the last run, with ``refine_status``
    (``met``, or why not), ``refine_attempts`` (one line per run: its settings, the worst
    quantity, what changed and why) and ``refine_wall_time_s``; a run that did not meet the
    tolerance says so in one stderr line. The companion runs are kept across attempts: the
    next attempt's run is the last one's finer companion where its settings are that
    companion's (the step halved, the modes raised, the mesh halved; its attempt line says
    so), and a companion made once is not made again. A quantity flagged outside the
    asymptotic range (its step term a bound) is not chased: when only such quantities miss
    the tolerance it stops and names them. ``free``: the knobs it may turn
    (:func:`flex.fidelity.refinement.free_knobs`); when the terms of the values the user set
    keep the certificate above the tolerance it stops, and the status says which value and
    what refinement would make of it."""
    if not resolution.scene["simulation"]["error_estimate"]:
        raise SceneError("fidelity.refine = true with simulation.error_estimate = false: "
                         "refinement follows the error budget; set error_estimate = true or "
                         "refine = false")
    start, lines = time.perf_counter(), []
    tolerance = Tolerance.of(resolution.scene).relative
    current = resolution
    made: dict[str, CaseResult] = {}  # every companion run so far, by its scene
    falls: dict[str, float] = {}  # each term's fall, observed when its knob was last turned
    last: tuple[Step, dict[str, Any], CaseResult, ErrorBudget, Scene] | None = None
    for attempt in range(1, MAX_ATTEMPTS + 1):
        reused = companion_key(current.scene) in made
        try:
            result, budget = _run_budgeted(current, name, None, None, cache_dir=cache_dir,
                                           beyond="", link_models=link_models,
                                           headlines=headlines, companions=made)
        except SimulationError as failed:  # a diverging attempt: the last one stays
            if last is None:  # the first guess itself: nothing to keep
                raise
            step = Step(None, f"the next attempt failed ({failed}); the last run is kept",
                        f"failed: {failed}")
            lines.append(f"{attempt}: {settings_text(current.scene, link_models)}: "
                         f"{step.line}")
            result, budget, kept = last[2], last[3], last[4]
            break
        kept = current.scene
        rows = _asked_rows(kept, budget, link_models)
        if last is not None:  # the term whose knob the last attempt turned, on its worst
            fall = observed_fall(last[1].get(last[0].worst), rows.get(last[0].worst),
                                 last[0].term)
            falls.update({last[0].term: fall} if fall is not None else {})
        floors = (_noise_floors(current.scene, result, rows, name, cache_dir, link_models,
                                headlines)
                  if any(not row.certified_relative <= tolerance for row in rows.values())
                  else {})
        step = next_attempt(current.scene, list(rows.values()), tolerance, attempt,
                            time.perf_counter() - start, link_models, free,
                            _flagged(rows, budget.step_bounds), falls, floors)
        lines.append(f"{attempt}: {settings_text(current.scene, link_models)}"
                     f"{' (the last companion at these settings, reused)' if reused else ''}: "
                     f"{step.line}")
        if step.refined is None:
            break
        last = (step, rows, result, budget, kept)
        current = replace(current, scene=step.refined)
    result.attrs.update({"refine_status": step.status, "refine_attempts": "\n".join(lines),
                         "refine_wall_time_s": time.perf_counter() - start})
    _say_status(name, step.status, tolerance)
    _state_coverage(result, budget, kept, name, link_models, refined=True)
    return result


def _flagged(rows: Mapping[str, Any], step_bounds: tuple[str, ...]) -> frozenset[str]:
    """The quantities refinement does not chase: their step term is a bound (outside the
    asymptotic range: it need not shrink with the step) and their largest term (where
    another term dominates, its knob is still worth turning)."""
    return frozenset(name for name in step_bounds if name in rows and rows[name].terms
                     and max(rows[name].terms, key=lambda term: rows[name].terms[term])
                     == "step")


def _asked_rows(scene: Scene, budget: ErrorBudget, link_models: Mapping[str, LinkModel]
                ) -> dict[str, BudgetRow]:
    """The budget rows of the quantities the tolerance applies to in the run of ``scene``
    (:meth:`flex.config.tolerance.Tolerance.asked`), by quantity: what refinement chases."""
    asked = Tolerance.of(scene).asked(flexible_links(scene, link_models))
    return {row.quantity: row for row in budget.rows() if row.quantity in asked}


def _state_coverage(result: CaseResult, budget: ErrorBudget | None, scene: Scene, name: str,
                    link_models: Mapping[str, LinkModel], refined: bool) -> None:
    """Store what the tolerance covered (:func:`flex.fidelity.stored_budget.
    tolerance_coverage`): each quantity asked, met or not; a quantity missed (or unknown) is
    a warning on stderr naming it, and, without refinement, what ``fidelity.refine = true``
    would do (a run that met it says so in ``inspect``, the report and ``flex run
    simulate``'s line)."""
    if budget is None:
        return
    tolerance = Tolerance.of(scene)
    coverage = tolerance_coverage(budget.rows(), tolerance.asked(
        flexible_links(scene, link_models)), tolerance.relative)
    result.attrs.update(coverage_attrs(coverage, tolerance.relative))
    if not any(status in ("missed", "unknown") for _, status, _ in coverage):
        return  # met: stored, printed by inspect and the report (and flex run simulate)
    text = coverage_text(coverage, tolerance.relative)
    if not refined:
        text += ("; fidelity.refine = true would turn the knobs of the missed quantities "
                 "(step, modes, mesh, elements, rung) until they meet it, or say why not")
    print(f"flex: warning: case {name}: {text}", file=sys.stderr, flush=True)


#: the noise floor's companion runs at this many times the run's Newton tolerance (looser, so
#: it converges wherever the run did); the floor is their difference over (factor - 1): the
#: tolerance's effect taken as linear in it
NOISE_FACTOR = 4.0


def _noise_floors(scene: Scene, result: CaseResult, rows: Mapping[str, Any], name: str,
                  cache_dir: Path | None, link_models: Mapping[str, LinkModel],
                  headlines: Mapping[str, Headline]) -> dict[str, float]:
    """Each certified quantity's noise floor [its unit]: the Newton tolerance's effect on it,
    measured by a companion run at :data:`NOISE_FACTOR` times the tolerance the run's solver
    used (its links may loosen the scene's, :func:`flex.dynamics.solver.solver_settings`).
    None for an explicit integrator (no Newton iteration) or a companion that fails."""
    from flex.data.scene import SCHEMA, apply_overrides
    from flex.dynamics.solver import solver_settings
    from flex.fidelity.error_estimate import headline_difference

    if scene["simulation"]["integrator"] == "explicit_penalty":
        return {}
    used = float(solver_settings(scene, link_models)["newton_relative_tolerance"])
    loose = min(NOISE_FACTOR * used,
                SCHEMA["simulation"]["newton_relative_tolerance"].maximum)
    try:
        other = integrate(apply_overrides(scene, [
            f"simulation.newton_relative_tolerance={loose!r}", "simulation.output_step_s=0.0",
            "simulation.error_estimate=false"]), f"{name}_noise_floor", cache_dir=cache_dir,
            link_models=link_models, headlines=headlines)
    except SimulationError:
        return {}
    factor = loose / used - 1.0 if loose > used else math.inf
    out = {}
    for quantity in rows:
        difference = headline_difference(headlines[quantity], result.datasets, other.datasets)
        if difference is not None:
            out[quantity] = difference / factor
    return out


def _say_status(name: str, status: str, tolerance: float) -> None:
    """:func:`refine`'s one stderr line: a note when there was nothing to refine, the
    status when the tolerance was not met."""
    if status == NOTHING_TO_REFINE:
        print(f"flex: note: case {name}: fidelity.refine: {status}", file=sys.stderr,
              flush=True)
    elif status != "met":
        print(f"flex: case {name}: fidelity.tolerance = {tolerance:g} not met by refinement "
              f"({status}); the last run is stored with its budget", file=sys.stderr,
              flush=True)


def _rigid_predictions(scene: Scene, result: CaseResult,
                       link_models: Mapping[str, LinkModel]) -> dict[str, Any]:
    """What the run's loads predict of its rigid plate links' bending over the deployment
    (:func:`flex.fidelity.predictor.rigid_link_predictions`); none for a drive other than the
    spring (the predictor's measured family) or a run that failed to sample its loads."""
    from flex.data.headlines import deployment_end
    from flex.fidelity.predictor import rigid_link_predictions

    rigid = [link for link in LINKS if link_models[scene[link]["model"]].rigid
             and scene[link]["geometry"] == "plate"]
    needed = ("joints/B/force_on_coupler", "joints/C/force_on_coupler", "coupler/angle")
    if not rigid or scene["drive"]["kind"] != "spring" or not all(
            path in result.datasets for path in needed):
        return {}
    series = {path: np.asarray(dataset.data) for path, dataset in result.datasets.items()}
    end = deployment_end(result.datasets)
    window_end_s = np.inf if end is None else float(series["time"][end])
    return rigid_link_predictions(scene, series, rigid, window_end_s)


def simulate_case(scene: Scene, name: str = "case", reduction: Any = None,
                  crank_reduction: Any = None, criterion: Criterion | None = None,
                  crank_criterion: Criterion | None = None, *,
                  cache_dir: Path | None = None, calibration: Calibration | None = None,
                  link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> CaseResult:
    """Like :func:`simulate`, but a failure becomes a ``failed`` case with its message."""
    try:
        return simulate(scene, name, reduction, crank_reduction, criterion, crank_criterion,
                        cache_dir=cache_dir, calibration=calibration, link_models=link_models)
    except FlexError as exc:
        return CaseResult(name, to_toml(scene), status="failed", message=str(exc))
