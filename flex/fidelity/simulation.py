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

import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from flex.base.errors import FlexError
from flex.config.calibration import Calibration
from flex.config.settings import tolerance_beyond_reach
from flex.data.results import CaseResult
from flex.data.scene import Scene, to_toml
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel
from flex.dynamics.solver import VALIDITY_WARNING, integrate, scene_reductions, time_scales
from flex.fidelity.auto import Resolution, resolve
from flex.fidelity.error_budget import error_budget
from flex.fidelity.laws import Criterion


def simulate(scene: Scene, name: str = "case", reduction: Any = None,
             crank_reduction: Any = None, criterion: Criterion | None = None,
             crank_criterion: Criterion | None = None, *,
             cache_dir: Path | None = None, calibration: Calibration | None = None,
             link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> CaseResult:
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
    ``estimated_error_leaves_out``.
    """
    beyond = tolerance_beyond_reach(scene, calibration, link_models=link_models)
    if beyond:  # said before the (possibly long) work starts, and stored with the result
        print(f"flex: warning: case {name}: {beyond}", file=sys.stderr, flush=True)
    resolution = resolve(scene, criterion, crank_criterion, cache_dir=cache_dir,
                         calibration=calibration, link_models=link_models)
    return simulate_resolved(resolution, name, reduction, crank_reduction,
                             cache_dir=cache_dir, beyond=beyond, link_models=link_models)


def simulate_resolved(resolution: Resolution, name: str = "case", reduction: Any = None,
                      crank_reduction: Any = None, *, cache_dir: Path | None = None,
                      beyond: str = "",
                      link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS
                      ) -> CaseResult:
    """:func:`simulate` of a scene already resolved (:func:`flex.fidelity.auto.resolve`):
    integrate, attributes, error budget. ``beyond``: why the scene's tolerance is beyond
    what flex can certify ("" if it is not), stored as a validity warning."""
    scene = resolution.scene
    if any(decision.link != "spring" for decision in resolution.decisions):
        reduction = crank_reduction = None
    if scene["simulation"]["error_estimate"]:  # the companion runs reuse the reductions
        reduction, crank_reduction = scene_reductions(scene, reduction, crank_reduction,
                                                      cache_dir=cache_dir,
                                                      link_models=link_models)
    result = integrate(scene, name, reduction, crank_reduction, cache_dir=cache_dir,
                       link_models=link_models)
    result.attrs.update(resolution.attrs())
    if result.attrs.get("solver_defaults_entry") == "flexible_fallback":
        print(f"flex: note: case {name}: outside the calibrated family: "
              f"{result.attrs.get('solver_defaults_reason', '')}", file=sys.stderr, flush=True)
    if beyond:
        result.attrs[VALIDITY_WARNING] = "; ".join(
            filter(None, [str(result.attrs.get(VALIDITY_WARNING, "")), beyond]))
    if scene["simulation"]["error_estimate"]:
        reductions = {link: built for link, built in (("coupler", reduction),
                                                       ("crank", crank_reduction))
                      if built is not None and link_models[scene[link]["model"]].modal}

        def run_companion(companion: Scene) -> CaseResult:
            # the run's reductions serve a companion whose links are meshed and reduced alike
            same = all(companion[link][key] == scene[link][key] for link in ("coupler",
                                                                            "crank")
                       for key in ("model", "modes", "mesh_size_m"))
            return integrate(companion, f"{name}_companion", reduction if same else None,
                             crank_reduction if same else None, cache_dir=cache_dir,
                             link_models=link_models)

        budget = error_budget(scene, result, run_companion,
                              time_scales(scene, reductions, link_models), link_models)
        result.attrs.update(budget.attrs())
    return result


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
