"""Simulate any scene: resolve ``model = "auto"`` links, then integrate.

The layer above :mod:`flex.dynamics.solver` (which integrates scenes whose links have concrete
models) and :mod:`flex.fidelity.criteria` (which decides ``auto`` from a rigid probe run, made with
:func:`flex.dynamics.solver.integrate`). The fitted laws ``auto`` reads are arguments: ``None``
means the installed criterion files (:data:`flex.fidelity.criteria.DEFAULT_CRITERION`,
:data:`flex.fidelity.criteria.DEFAULT_CRANK_CRITERION`); a study that has just fitted a law passes
it as a :class:`flex.fidelity.criteria.Criterion`.

The reduction cache folder is an argument too (``cache_dir``, keyword): FFRF reductions are
loaded from it or written to it; ``None`` builds them in memory, with no disk cache. The
command line and :mod:`flex.api` pass the user's folder
(:func:`flex.bodies.reduction.reduction_cache_dir` of the environment, read at that edge).
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path
from typing import Any

from flex.base.errors import FlexError
from flex.config.settings import (
    check_runnable,
    resolve_solver_settings,
    tolerance_beyond_reach,
)
from flex.data.results import CaseResult
from flex.data.scene import Scene, to_toml
from flex.dynamics.solver import VALIDITY_WARNING, integrate, scene_reductions, time_scales
from flex.fidelity.criteria import Criterion, FidelityDecision, resolve_fidelity
from flex.fidelity.error_budget import error_budget
from flex.fidelity.spring_choice import decide_spring


def resolve_auto(scene: Scene, criterion: Criterion | None = None,
                 crank_criterion: Criterion | None = None, *, cache_dir: Path | None = None
                 ) -> tuple[Scene, list[FidelityDecision]]:
    """Resolve ``drive.spring_model = "auto"`` first
    (:func:`flex.fidelity.spring_choice.decide_spring`: the links' probe then runs with the
    chosen spring), then ``model = "auto"`` links
    (:func:`flex.fidelity.criteria.resolve_fidelity`), and print each choice and its reason to
    stderr. A scene without them is returned as it is, with no decisions. ``cache_dir``: the
    reduction cache folder (module doc)."""
    if "auto" not in (scene["coupler"]["model"], scene["crank"]["model"],
                      scene["drive"]["spring_model"]):
        return scene, []
    spring: list[FidelityDecision] = []
    if scene["drive"]["spring_model"] == "auto":
        scene = copy.deepcopy(scene)
        spring.append(decide_spring(scene))
    resolved, decisions = resolve_fidelity(scene, criterion, crank_criterion,
                                           cache_dir=cache_dir)
    decisions = spring + decisions
    for decision in decisions:
        modes = f" ({decision.modes} modes)" if decision.modes else ""
        key = "drive.spring_model" if decision.link == "spring" else f"{decision.link}.model"
        print(f"flex: fidelity: {key} = auto -> {decision.model}{modes}: "
              f"{decision.reason}", file=sys.stderr)
    return resolved, decisions


def simulate(scene: Scene, name: str = "case", reduction: Any = None,
             crank_reduction: Any = None, criterion: Criterion | None = None,
             crank_criterion: Criterion | None = None, *,
             cache_dir: Path | None = None) -> CaseResult:
    """One case of any scene; raises :class:`~flex.base.errors.FlexError` on bad input or
    divergence.

    ``model = "auto"`` links are first resolved to concrete models (given reductions are
    then ignored: auto picks the modes), by ``criterion`` / ``crank_criterion`` (None: the
    installed laws); the choice and its reason go to stderr and into the result's
    attributes ``fidelity_<link>_*``. Then :func:`flex.dynamics.solver.integrate` fills the
    ``"auto"`` solver keys and integrates. ``reduction`` / ``crank_reduction``: reductions
    of ``ffrf`` links (None: built, or loaded from ``cache_dir``). ``cache_dir``: the
    reduction cache folder (None: reductions are built in memory, no disk cache).

    With ``simulation.error_estimate`` (the default), companion runs estimate the run's error
    budget on its headline quantities, term by term (step, modes, mesh, model;
    :mod:`flex.fidelity.error_budget`): case attributes ``estimated_error_*``. A failed
    companion leaves the run as it is, its term out, and says why in
    ``estimated_error_leaves_out``.
    """
    check_runnable(scene)  # before anything is built or probed
    beyond = tolerance_beyond_reach(scene)
    if beyond:  # said before the (possibly long) work starts, and stored with the result
        print(f"flex: warning: case {name}: {beyond}", file=sys.stderr, flush=True)
    scene, decisions = resolve_auto(scene, criterion, crank_criterion, cache_dir=cache_dir)
    if decisions:
        reduction = crank_reduction = None
    if scene["simulation"]["error_estimate"]:  # the companion run reuses the reductions
        reduction, crank_reduction = scene_reductions(scene, reduction, crank_reduction,
                                                      cache_dir=cache_dir)
    result = integrate(scene, name, reduction, crank_reduction, cache_dir=cache_dir)
    for decision in decisions:
        result.attrs.update(decision.attrs())
    if result.attrs.get("solver_defaults_entry") == "flexible_fallback":
        print(f"flex: note: case {name}: outside the calibrated family: "
              f"{result.attrs.get('solver_defaults_reason', '')}", file=sys.stderr, flush=True)
    if beyond:
        result.attrs[VALIDITY_WARNING] = "; ".join(
            filter(None, [str(result.attrs.get(VALIDITY_WARNING, "")), beyond]))
    if scene["simulation"]["error_estimate"]:
        resolved, _ = resolve_solver_settings(scene)
        reductions = {link: built for link, built in (("coupler", reduction),
                                                       ("crank", crank_reduction))
                      if built is not None and resolved[link]["model"] == "ffrf"}

        def run_companion(companion: Scene) -> CaseResult:
            # the run's reductions serve a companion whose links are meshed and reduced alike
            same = all(companion[link][key] == resolved[link][key] for link in ("coupler",
                                                                              "crank")
                       for key in ("model", "modes", "mesh_size_m"))
            return integrate(companion, f"{name}_companion", reduction if same else None,
                             crank_reduction if same else None, cache_dir=cache_dir)

        budget = error_budget(resolved, result, run_companion,
                              time_scales(resolved, reductions))
        result.attrs.update(budget.attrs())
    return result


def simulate_case(scene: Scene, name: str = "case", reduction: Any = None,
                  crank_reduction: Any = None, criterion: Criterion | None = None,
                  crank_criterion: Criterion | None = None, *,
                  cache_dir: Path | None = None) -> CaseResult:
    """Like :func:`simulate`, but a failure becomes a ``failed`` case with its message."""
    try:
        return simulate(scene, name, reduction, crank_reduction, criterion, crank_criterion,
                        cache_dir=cache_dir)
    except FlexError as exc:
        return CaseResult(name, to_toml(scene), status="failed", message=str(exc))
