"""Time integration of a built mechanism and collection of its outputs.

:func:`integrate` integrates a concrete scene (the studies reach it through
:func:`flex.fidelity.simulation.simulate`, which decides every ``"auto"`` first). Contract:

- input: a validated, concrete scene (and, for an FFRF link, its reduction);
- output: a :class:`~flex.data.results.CaseResult` whose datasets are the quantities of the
  result layout (``time``, ``crank/...``, ``slider/...``, ``joints/<A|B|C>/...``,
  ``constraint_norm``, ``energy/...`` (rigid and FFRF links), ``coupler/...``), each with units;
- refused before anything is built: what :func:`flex.config.settings.check_concrete` refuses
  (:class:`~flex.base.errors.SceneError`, a ``failed`` case from
  :func:`flex.fidelity.simulation.simulate_case`);
- status: ``ok``; a diverging run (solver failure, NaN, exploding constraint norm) raises
  :class:`~flex.base.errors.SimulationError` naming the step and time and what may help
  (:func:`divergence_advice`: a smaller step only where the step does not resolve the
  scene's fastest time scale; the extreme inputs), and
  :func:`flex.fidelity.simulation.simulate_case` turns that
  into a ``failed`` case instead of data; an ``ok`` run whose validity is in doubt (a
  linear FFRF link deflecting beyond 1 % of its length) carries the case attribute
  ``validity_warning`` (:func:`validity_warning`);
- counters: steps, Newton iterations, Jacobian updates, wall time [s].

The integrator follows the scene's ``[simulation]`` knobs (:func:`solver_settings`): Exudyn's
implicit generalized-alpha (index 3; or Newmark with index-2 constraints), full or modified
Newton (or a Jacobian once per step), or an explicit Runge-Kutta method with penalty joints;
always at a fixed step (a Newton failure is reported, not retried with a smaller step). Step
N covers t = (N - 1) h ... N h: a Newton failure names the step and its start time, a
non-finite or exploding output the step that produced it and its end time.

Each link's model (``link_models``, :mod:`flex.dynamics.link_models`) prepares, builds, senses
and adjusts the solver for itself; the datasets are collected by :mod:`flex.dynamics.collect`,
the validity warnings, time scales and divergence advice are :mod:`flex.dynamics.advice`'s
(their names are importable from here too).
"""

from __future__ import annotations

import io
import signal
import sys
import threading
import time
from collections.abc import Mapping
from contextlib import redirect_stdout
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import SimulationError, Terminated
from flex.base.interrupts import interrupts_not_swallowed
from flex.base.progress import heartbeat
from flex.config.settings import check_concrete
from flex.data.headlines import BUILTIN_HEADLINES, Headline, channel_series
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, to_toml
from flex.dynamics.advice import (
    CHANNEL_ATTR,
    VALIDITY_WARNING,
    channel_cutoff_Hz,
    channel_datasets,
    check_finite,
    divergence_advice,
    mechanism_reductions,
    validity_warning,
)
from flex.dynamics.builder import Mechanism
from flex.dynamics.collect import collect
from flex.dynamics.link_models import (
    BUILTIN_LINK_MODELS,
    EXACT_BEAM,
    LinkModel,
    entries,
)
from flex.dynamics.mechanism import build_mechanism
from flex.dynamics.runtime import SolverOutput, announce_integration


def solver_settings(scene: Scene, link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS
                    ) -> dict[str, Any]:
    """The integrator settings used for a concrete ``scene`` (stored in every result
    file); its link models adjust them (:mod:`flex.dynamics.link_models`, point 8)."""
    sim = scene["simulation"]
    settings = {
        "integrator": "generalized-alpha (Exudyn, index 3)",
        "step_s": sim["step_s"],
        "end_time_s": sim["end_time_s"],
        "steps": int(round(sim["end_time_s"] / sim["step_s"])),
        "output_step_s": sim["output_step_s"] or sim["step_s"],
        "spectral_radius": sim["spectral_radius"],
        "newton_relative_tolerance": sim["newton_relative_tolerance"],
        "newton_absolute_tolerance": 1e-2 * sim["newton_relative_tolerance"],
        "modified_newton": sim["newton"] in ("modified", "jacobian_per_step"),
        "adaptive_step": False,  # fixed step: a Newton failure is a divergence, not a retry
    }
    if sim["newton"] == "jacobian_per_step":  # only then: other runs' stored settings stay
        settings["jacobian_per_step"] = True
    settings.update(_integrator_settings(sim))
    for link, model in entries(scene, link_models).items():
        model.adjust_solver(settings, scene[link])
    return settings


def _integrator_settings(sim: dict[str, Any]) -> dict[str, Any]:
    """Settings of the ``[simulation]`` integrator knobs (``integrator``, ``formulation``).

    ``index2`` is Exudyn's Newmark integrator with velocity-level constraints (Exudyn allows
    index 2 only with Newmark); its numerical damping follows ``spectral_radius`` rho:
    gamma = 1/2 + a, beta = (1 + a)^2 / 4 with a = (1 - rho) / (1 + rho), which has the same
    spectral radius at infinity (rho = 1: trapezoidal rule; rho < 1 is first-order accurate).
    """
    if sim["integrator"] == "explicit_penalty":
        return {"integrator": f"explicit {sim['explicit_method']} (Exudyn), penalty joints",
                "explicit_method": sim["explicit_method"],
                "penalty_stiffness_N_per_m": sim["penalty_stiffness_N_per_m"]}
    if sim["formulation"] == "index2":
        damping = (1 - sim["spectral_radius"]) / (1 + sim["spectral_radius"])
        return {"integrator": "Newmark (Exudyn, index 2)", "newmark_gamma": 0.5 + damping,
                "newmark_beta": (1 + damping) ** 2 / 4}
    return {}


def _is_explicit(settings: dict[str, Any]) -> bool:
    return "explicit_method" in settings


def _exudyn_settings(settings: dict[str, Any]):
    import exudyn as exu

    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.numberOfSteps = settings["steps"]
    ti.endTime = settings["steps"] * settings["step_s"]
    ti.adaptiveStep = settings["adaptive_step"]
    ti.automaticStepSize = False
    ti.generalizedAlpha.spectralRadius = settings["spectral_radius"]
    if "newmark_beta" in settings:
        ti.generalizedAlpha.useNewmark = True
        ti.generalizedAlpha.useIndex2Constraints = True
        ti.generalizedAlpha.newmarkBeta = settings["newmark_beta"]
        ti.generalizedAlpha.newmarkGamma = settings["newmark_gamma"]
    if _is_explicit(settings):
        ti.solverType = getattr(exu.DynamicSolverType, settings["explicit_method"])
        ti.explicit.eliminateConstraints = True  # the planar-motion coordinate constraints
    if settings.get("newton_on_increment"):  # an exact beam: its residual has a round-off floor
        ti.newton.residualMode = 1
    ti.newton.relativeTolerance = settings["newton_relative_tolerance"]
    ti.newton.absoluteTolerance = settings["newton_absolute_tolerance"]
    ti.newton.useModifiedNewton = settings["modified_newton"]
    ti.newton.modifiedNewtonJacUpdatePerStep = settings.get("jacobian_per_step", False)
    if "linear_solver" in settings:
        s.linearSolver.solverType = getattr(exu.LinearSolverType, settings["linear_solver"])
    ti.verboseMode = 1  # Exudyn's step lines every 2 s: progress (:class:`_SolverOutput`)
    s.solution.file.write = False
    s.solution.sensors.writePeriod = settings["output_step_s"]
    s.solution.sensors.writeHeader = False
    s.show.computationTime = False
    s.show.statistics = False
    return s


def run(mech: Mechanism, label: str = "") -> dict[str, Any]:
    """Integrate ``mech`` in place; return counters. Raises SimulationError on failure.
    A solve that takes more than a few seconds prints progress lines to stderr (``label``
    names the case in them)."""
    import exudyn as exu

    settings = solver_settings(mech.scene, mech.link_models)
    solver = (exu.MainSolverExplicit() if _is_explicit(settings)
              else exu.MainSolverImplicitSecondOrder())
    captured = SolverOutput(label, settings["steps"] * settings["step_s"],
                             lambda: mech.mbs.SetRenderEngineStopFlag(True))
    if any(model.own_progress for model in mech.models.values()):
        captured.progress.first_s = float("inf")  # the model reports its own
    start = time.perf_counter()
    # Ctrl-C (or SIGTERM) inside Exudyn's C++ loop may come back as a failed solve; note it
    # ourselves so an interrupt is never mistaken for (and stored as) a diverged case
    interrupted: list[int] = []
    previous: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        def on_interrupt(signum, frame):
            interrupted.append(signum)
            mech.mbs.SetRenderEngineStopFlag(True)  # Exudyn may drop the exception: stop it
            raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt
        previous = {sig: signal.signal(sig, on_interrupt)
                    for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        with redirect_stdout(captured), interrupts_not_swallowed():
            ok = solver.SolveSystem(mech.mbs, _exudyn_settings(settings))
    except Exception as exc:  # Exudyn raises RuntimeError/ValueError on Newton failure
        ok = False
        captured.write(str(exc))
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if interrupted:
        if previous.get(interrupted[0]) not in (None, signal.SIG_DFL, signal.SIG_IGN,
                                                signal.default_int_handler):
            previous[interrupted[0]](interrupted[0], None)  # the caller's handler notes it
        raise Terminated if interrupted[0] == signal.SIGTERM else KeyboardInterrupt
    wall = time.perf_counter() - start
    if not ok:
        step, now = solver.it.currentStepIndex, solver.it.currentTime
        failure = "explicit solver failed" if _is_explicit(settings) else "Newton failed"
        detail = " ".join(captured.getvalue().split())[-300:]
        advice = divergence_advice(mech.scene, mechanism_reductions(mech), mech.link_models)
        raise SimulationError(f"solver diverged at step {step} (t = {now:.6g} s, step "
                              f"{settings['step_s']:g} s): {failure}"
                              f"{f' ({detail})' if detail else ''}; "
                              f"{advice}")
    return {"steps": int(solver.it.currentStepIndex), "newton_iterations":
            int(solver.it.newtonStepsCount), "jacobian_updates": int(solver.it.newtonJacobiCount),
            "wall_time_s": wall}


def run_profiled(mech: Mechanism) -> tuple[dict[str, float], str]:
    """Integrate ``mech`` once (implicit integrator) with Exudyn's CPU-time statistics on, for
    benchmarks (:mod:`flex.experiments.workprecision.benchmark`; :func:`run` is the production
    path): counters (``steps``, ``newton_iterations``, ``jacobian_updates``; ``wall_time_s`` [s],
    the solve alone) and the statistics text of Exudyn's solver timer. Raises SimulationError
    if it fails."""
    import exudyn as exu

    settings = _exudyn_settings(solver_settings(mech.scene, mech.link_models))
    settings.show.computationTime = True
    settings.timeIntegration.verboseMode = 1  # the statistics are printed only when verbose
    solver = exu.MainSolverImplicitSecondOrder()
    captured = io.StringIO()
    start = time.perf_counter()
    with redirect_stdout(captured):
        ok = solver.SolveSystem(mech.mbs, settings)
    wall = time.perf_counter() - start
    if not ok:
        raise SimulationError("profiled run failed")
    # the statistics from the solver's own timer (the printed copy goes to whatever
    # sys.stdout is at print time, which another part of a long process may have replaced)
    return {"wall_time_s": wall, "steps": float(solver.it.currentStepIndex),
            "newton_iterations": float(solver.it.newtonStepsCount),
            "jacobian_updates": float(solver.it.newtonJacobiCount)}, solver.timer.ToString()


def scene_reductions(scene: Scene, reduction: Any = None, crank_reduction: Any = None, *,
                     cache_dir: Path | None = None,
                     link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS
                     ) -> tuple[Any, Any]:
    """What the scene's coupler and crank models prepare before a run (point 4 of
    :mod:`flex.dynamics.link_models`: the reductions of ``ffrf`` links, built or loaded from
    ``cache_dir`` by :func:`reduction_for_scene`): the given ones, else their models'."""
    models = entries(scene, link_models)
    return (models["coupler"].prepare(scene, "coupler", reduction, cache_dir),
            models["crank"].prepare(scene, "crank", crank_reduction, cache_dir))


def flexible_link_attrs(scene: Scene, datasets: dict[str, Dataset],
                        reductions: dict[str, Any]) -> dict[str, Any]:
    """Case attributes of each FFRF link: the identity of its mode basis (what its stored
    modal coordinates mean) and its peak von Mises stresses, where and when
    (:mod:`flex.bodies.stress`)."""
    from flex.bodies.stress import basis_identity, peak_attrs

    out: dict[str, Any] = {}
    for link, reduction in reductions.items():
        if f"{link}/modal_coordinates" not in datasets:  # a modal (FFRF) link's
            continue
        out.update(basis_identity(link, reduction))
        if reduction.has_stress_modes:
            out.update(peak_attrs(link, reduction, datasets[f"{link}/modal_coordinates"].data,
                                  datasets["time"].data, datasets))
    return out


def integrate(scene: Scene, name: str = "case", reduction: Any = None,
              crank_reduction: Any = None, *, cache_dir: Path | None = None,
              link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS,
              headlines: Mapping[str, Headline] = BUILTIN_HEADLINES) -> CaseResult:
    """Build, integrate and collect one case of a concrete scene (every ``"auto"`` decided
    a layer above, :func:`flex.fidelity.auto.resolve`; here it is refused); raises on
    divergence (see module doc). ``reduction`` / ``crank_reduction``: the reductions of an
    ``ffrf`` coupler / crank (None: :func:`reduction_for_scene` builds them, or loads them from
    ``cache_dir``: the reduction cache folder; None: built in memory, no disk cache).
    ``scene_toml`` holds the scene. ``link_models``: the link models the scene may name
    (:mod:`flex.dynamics.link_models`); ``headlines``: the quantities read from it, whose
    series it stores on the headline channel (:func:`flex.data.headlines.channel_series`).
    """
    retries: list[str] = []
    while True:
        try:
            result = _integrate(scene, name, reduction, crank_reduction, cache_dir=cache_dir,
                                link_models=link_models, headlines=headlines)
            break
        except SimulationError as exc:
            looser = (_newton_floor_retry(scene, str(exc), link_models)
                      if len(retries) < NEWTON_FLOOR_RETRIES else None)
            if looser is None:
                raise
            scene, said = looser
            print(f"flex: warning: case {name}: {said}", file=sys.stderr, flush=True)
            retries.append(said)
    if retries:
        result.attrs[NEWTON_RETRY_ATTR] = "; ".join(retries)
    return result


#: a run with an exact beam link whose Newton stalls (on a round-off floor: on its residual
#: the 3 mm plate driven at 60 rad/s as a 128-element beam stalled at 1.36e-6 against 1e-6;
#: an exact beam now stops on its increment, flex.dynamics.exact_beam_link) is run again at
#: this many times the error it stalled at, at most NEWTON_FLOOR_RETRIES times; a stall above
#: INCREMENT_CEILING (on the residual: above this many times the tolerance), or a third, is a
#: divergence
NEWTON_FLOOR_RETRY = 4.0
#: a Newton stopping on its increment (an exact beam) that stalls at most this far (relative)
#: is run again at 4x the stall: its solution is converged to round-off (a beam crank on a beam
#: coupler stalled at 1.4e-10 against 1e-12 in its first step; the residual default of a rigid
#: run is 1e-8)
INCREMENT_CEILING = 1e-8
NEWTON_FLOOR_RETRIES = 2
#: the case attribute that says a run was made again at a looser Newton tolerance, and why
NEWTON_RETRY_ATTR = "newton_floor_retry"


def _newton_floor_retry(scene: Scene, message: str, link_models: Mapping[str, LinkModel]
                        ) -> tuple[Scene, str] | None:
    """The scene to run again after a Newton stall on an exact beam's round-off floor (its
    tolerance :data:`NEWTON_FLOOR_RETRY` x the error it stalled at) and the sentence
    that says so; None for any other failure."""
    import re

    from flex.data.scene_edit import derive_scene

    if EXACT_BEAM not in {scene[link]["model"] for link in entries(scene, link_models)}:
        return None
    found = re.search(r"relative error = ([0-9.eE+-]+)", message)
    settings = solver_settings(scene, link_models)
    tolerance = float(settings["newton_relative_tolerance"])
    stalled = float(found.group(1)) if found else float("inf")
    # on the increment, any stall below the ceiling is a converged solution's round-off
    limit = max(NEWTON_FLOOR_RETRY * tolerance,
                INCREMENT_CEILING if settings.get("newton_on_increment") else 0.0)
    if not tolerance < stalled <= limit:
        return None
    # the scene's tolerance loosened (the beam stops at its fraction of it, on the increment)
    looser = (NEWTON_FLOOR_RETRY * stalled / tolerance
              * float(scene["simulation"]["newton_relative_tolerance"]))
    return (derive_scene(scene, [f"simulation.newton_relative_tolerance={looser!r}"]),
            f"the exact beam's Newton stalled on its round-off floor (relative error "
            f"{stalled:.3g} against {tolerance:.3g}); run again with "
            f"simulation.newton_relative_tolerance = {looser:.3g} (stored in the case's scene)")


def _integrate(scene: Scene, name: str, reduction: Any, crank_reduction: Any, *,
               cache_dir: Path | None, link_models: Mapping[str, LinkModel],
               headlines: Mapping[str, Headline]) -> CaseResult:
    """:func:`integrate` once."""
    check_concrete(scene, link_models=link_models)  # no "auto" left, steps and meshes
    reduction, crank_reduction = scene_reductions(scene, reduction, crank_reduction,
                                                  cache_dir=cache_dir, link_models=link_models)
    announce_integration(scene, name, {"coupler": reduction, "crank": crank_reduction},
                         link_models)
    with heartbeat(f"building {name}"):
        mech = build_mechanism(scene, reduction, crank_reduction, link_models=link_models)
    settings = solver_settings(scene, link_models)
    recorders = [recorder for link, model in mech.models.items()
                 if (recorder := model.recorder(mech, link, settings)) is not None]
    counters = run(mech, name)
    cutoff_Hz = mech.channel_cutoff_Hz = channel_cutoff_Hz(scene, link_models)
    with np.errstate(all="ignore"):  # a diverged run overflows; check_finite reports it
        datasets = collect(mech)
    check_finite(datasets, settings, scene, mechanism_reductions(mech), link_models)
    for recorder in recorders:  # its own time: after the check of the sampled datasets
        datasets.update(recorder.datasets())
    datasets.update(channel_datasets(datasets, cutoff_Hz, channel_series(headlines)))
    import tomli_w

    result = CaseResult(name, to_toml(scene), datasets, counters=counters,
                        solver_settings_toml=tomli_w.dumps(settings))
    result.attrs.update(flexible_link_attrs(scene, datasets, mechanism_reductions(mech)))
    for link, handles in (("crank", mech.crank), ("coupler", mech.coupler)):
        calibration = getattr(handles.get("section"), "calibration", None) or {}
        result.attrs.update({f"{link}_beam_{key}": value for key, value in calibration.items()})
    if cutoff_Hz is not None:
        result.attrs[CHANNEL_ATTR] = cutoff_Hz
    warning = validity_warning(scene, datasets, link_models)
    if warning:
        result.attrs[VALIDITY_WARNING] = warning
    return result


__all__ = ["NEWTON_FLOOR_RETRIES", "NEWTON_FLOOR_RETRY", "NEWTON_RETRY_ATTR", "integrate",
           "solver_settings", "run", "run_profiled", "scene_reductions", "flexible_link_attrs"]
