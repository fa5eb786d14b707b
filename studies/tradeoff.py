"""Study ``tradeoff``: work-precision of every knob, for the rigid and the FFRF coupler.

Three scenes of the thesis deployment (22 mm preload, 0.03 s): the rigid Table 1 model
(``rigid``) and steel-plate FFRF couplers 1 and 10 mm thick (``ffrf_1mm``, ``ffrf_10mm``). Each
gets a converged reference: a plate the stored one of its physics (``make references``,
:data:`STORED`), the rigid model the scipy DAE shown converged here
(``workprecision.reference_plans``); the knobs vary
one at a time around a base setting and in combination (:func:`settings`): step, spectral
radius, index-3 or index-2, Newton variant and tolerance, explicit Runge-Kutta with penalty
joints (rigid), modes, mesh size and element order, the nonlinear FE coupler, and the scipy
reference DAE (rigid) at several tolerances.

Stored (``workprecision.tradeoff``): a case ``<scene>__<setting>`` per run (a diverged run:
a ``failed`` case); under ``/summary/<scene>/`` (``workprecision.tradeoff_report``) ``runs``,
``reference``, ``recommended`` (1 %, 0.1 %, 0.01 %), ``default`` and (FFRF) ``rule``: the
bundled "auto" keys and the rule's picks against the runs (``defaults_check``, ``rule_check``).
"""

from __future__ import annotations

from pathlib import Path

from flex.config.settings import pinned_overrides
from flex.data.results import CaseResult
from flex.data.scene import Scene, derived_scenes
from flex.experiments.workprecision.defaults_check import default_setting
from flex.experiments.workprecision.measurement import Setting, nonlinear_available
from flex.experiments.workprecision.reference_plans import scipy_setting
from flex.experiments.workprecision.rule_check import rule_settings
from flex.experiments.workprecision.tradeoff import run_work_precision
from flex.experiments.workprecision.tradeoff_report import (
    summarize_work_precision,
    tradeoff_findings,
    work_precision_figures,
)
from flex.study import StudyRun, Summary

NAME = "tradeoff"
DESCRIPTION = "work-precision: every knob against a converged reference, rigid and FFRF 1/10 mm"
OVERRIDES = pinned_overrides() + ["simulation.error_estimate=false"]  # own references
# keys the study reads itself (the accuracy levels), beside its cases
READS = ("fidelity.tolerance",)
REPEATS = 3

PLATE = ['coupler.geometry="plate"', 'coupler.model="ffrf"']
SCENES: dict[str, list[str]] = {
    "rigid": [],
    "ffrf_1mm": PLATE + ["coupler.thickness_m=0.001", "coupler.mesh_size_m=0.002"],
    "ffrf_10mm": PLATE + ["coupler.thickness_m=0.01", "coupler.mesh_size_m=0.005"],
}
#: scenes judged against the stored reference of their physics (``make references``: the
#: calibrated exact beam, 256 elements at 1.25e-6 s for the 1 mm plate, 64 for the stocky
#: 10 mm one). The rigid scene keeps the scipy reference DAE (an independent implementation;
#: the stored rigid reference is Exudyn's own model at a fine step). The 10 mm plate's in-run
#: FFRF reference it replaced reached 1.4e-2 only (its mesh sequence at observed order 0.24)
STORED = ("ffrf_1mm", "ffrf_10mm")
#: the plate the ``ffrf_coupler`` entry of flex/config/solver_defaults.toml is for (its bundled 2 mm
#: mesh and 6 modes): where the FFRF defaults are checked
FFRF_DEFAULT_SCENE = "ffrf_1mm"

S = Setting.of
ONE = "one knob: "  # the group of the one-knob-at-a-time sweeps


def settings(scene_name: str, nonlinear: bool, scene: Scene) -> list[Setting]:
    """The knob settings measured for one scene (``scene``: its case scene): one knob at a
    time around the base, then combinations, then the flex defaults and (FFRF) the rule's
    picks at 1 % and 0.1 % (``nonlinear``: the nonlinear FE coupler is installed)."""
    if scene_name == "rigid":
        return _rigid_settings() + [default_setting()]
    return (_ffrf_settings(scene_name == "ffrf_1mm", nonlinear) + [default_setting()]
            + rule_settings(scene))


def _rigid_settings() -> list[Setting]:
    """Rigid coupler: Exudyn implicit and explicit, and the scipy reference DAE."""
    out: list[Setting] = []
    base = {"step_s": 1e-5}
    for step in (3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6):
        out.append(S(f"h={step:g}", ONE + "step", step_s=step))
    for rho in (0.0, 0.5, 1.0):
        out.append(S(f"h=1e-5 rho={rho:g}", ONE + "spectral radius", spectral_radius=rho,
                     **base))
    out.append(S("h=1e-5 index2", ONE + "index 2", formulation="index2", **base))
    out.append(S("h=1e-5 modified", ONE + "Newton", newton="modified", **base))
    for tol in (1e-10, 1e-6):
        out.append(S(f"h=1e-5 tol={tol:g}", ONE + "Newton tolerance",
                     newton_relative_tolerance=tol, **base))
    out.append(S("h=1e-5 explicit RK44 k=1e8", ONE + "explicit + penalty",
                 integrator="explicit_penalty", **base))
    for step in (1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6):
        for rho in (0.5, 1.0):
            out.append(S(f"h={step:g} rho={rho:g} tol=1e-8", "combination: step x rho",
                         step_s=step, spectral_radius=rho, newton_relative_tolerance=1e-8))
        out.append(S(f"h={step:g} modified tol=1e-8", "combination: step x Newton",
                     step_s=step, newton="modified", newton_relative_tolerance=1e-8))
        out.append(S(f"h={step:g} index2 rho=1", "combination: step x index 2",
                     step_s=step, formulation="index2", spectral_radius=1.0))
        out.append(S(f"h={step:g} index2 rho=0.9", "combination: step x index 2",
                     step_s=step, formulation="index2"))
    # explicit: the step near the RK44 stability limit of each penalty stiffness
    for stiffness, step in ((1e6, 1e-4), (1e7, 3e-5), (1e8, 1e-5), (1e9, 3e-6),
                            (1e10, 1e-6)):
        out.append(S(f"explicit RK44 k={stiffness:g} h={step:g}",
                     "combination: explicit penalty", integrator="explicit_penalty",
                     penalty_stiffness_N_per_m=stiffness, step_s=step))
    out.append(S("explicit RK67 k=1e8 h=1e-5", "combination: explicit penalty",
                 integrator="explicit_penalty", explicit_method="RK67", step_s=1e-5))
    out.append(S("explicit midpoint k=1e8 h=2e-6", "combination: explicit penalty",
                 integrator="explicit_penalty", explicit_method="ExplicitMidpoint",
                 step_s=2e-6))
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10):
        out.append(scipy_setting(rtol))
        out.append(scipy_setting(rtol, "RK45"))
    return out


def _ffrf_settings(thin: bool, nonlinear: bool) -> list[Setting]:
    """FFRF plate 1 mm (``thin``) or 10 mm thick."""
    out: list[Setting] = []
    base_step = 1e-4 if thin else 1e-5
    base_mesh = 0.002 if thin else 0.005
    base = {"step_s": base_step}
    for factor in (4, 2, 1, 0.5, 0.2):
        step = base_step * factor
        out.append(S(f"h={step:g}", ONE + "step", step_s=step))
    for rho in (0.0, 0.5, 1.0):
        out.append(S(f"h={base_step:g} rho={rho:g}", ONE + "spectral radius",
                     spectral_radius=rho, **base))
    out.append(S(f"h={base_step:g} index2", ONE + "index 2", formulation="index2", **base))
    out.append(S(f"h={base_step:g} index2 rho=1", ONE + "index 2", formulation="index2",
                 spectral_radius=1.0, **base))
    out.append(S(f"h={base_step:g} modified", ONE + "Newton", newton="modified", **base))
    for tol in (1e-10, 1e-6):
        out.append(S(f"h={base_step:g} tol={tol:g}", ONE + "Newton tolerance",
                     newton_relative_tolerance=tol, **base))
    for modes in (2, 4, 12):
        out.append(S(f"h={base_step:g} modes={modes}", ONE + "modes", coupler__modes=modes,
                     **base))
    meshes = (0.006, 0.004, 0.003) if thin else (0.01, 0.007, 0.003)
    for mesh in meshes:
        out.append(S(f"h={base_step:g} mesh={mesh * 1e3:g}mm", ONE + "mesh size",
                     coupler__mesh_size_m=mesh, **base))
    linear = S(f"h={base_step:g} linear tets", ONE + "element order", **base)
    out.append(Setting(linear.label, linear.overrides, group=linear.group, element_order=1))
    # the fully nonlinear FE coupler (same mesh and step as FFRF runs of the table, so the
    # model difference can be read beside the discretization error): ~50x the FFRF cost per
    # step at 1 mm; at 10 mm the 10 mm mesh has a few hundred nodes
    steps_meshes = ((1e-4, 0.004),) if thin else ((1e-5, 0.01), (1e-5, 0.005), (5e-6, 0.005))
    for step, mesh in steps_meshes if nonlinear else ():
        out.append(S(f"nonlinear FE h={step:g} mesh={mesh * 1e3:g}mm", ONE
                     + "nonlinear FE coupler", coupler__model="nonlinear_fe",
                     coupler__mesh_size_m=mesh, newton="modified",
                     newton_relative_tolerance=1e-8, step_s=step))
    fast = {"newton": "modified", "newton_relative_tolerance": 1e-8}
    for factor in (4, 2, 1, 0.5):
        step = base_step * factor
        for mesh in (base_mesh, 2 * base_mesh):
            for modes in (2, 6):
                out.append(S(f"h={step:g} mesh={mesh * 1e3:g}mm modes={modes} modified tol=1e-8",
                             "combination: step x mesh x modes (modified Newton, tol 1e-8)",
                             step_s=step, coupler__mesh_size_m=mesh, coupler__modes=modes,
                             **fast))
    if thin:
        # toward 0.1 %: the bundled 2 mm mesh and 6 modes err by ~1e-3 on their own, so the
        # candidates for that level refine mesh and modes together with the step
        for step in (1e-4, 5e-5, 2.5e-5):
            for mesh, modes in ((0.0015, 12), (0.00106, 24)):
                out.append(S(f"h={step:g} mesh={mesh * 1e3:g}mm modes={modes} modified "
                             "tol=1e-8", "combination: finer mesh and more modes (toward "
                             "0.1 %)", step_s=step, coupler__mesh_size_m=mesh,
                             coupler__modes=modes, **fast))
    return out


def cases(scene: Scene) -> dict[str, Scene]:
    """One scene per work-precision diagram (the references' scenes)."""
    return derived_scenes(scene, SCENES)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """References first, then every setting, per scene; returns one case per run."""
    from flex.data.reference_store import bundled_store, read_store, reference_for
    from flex.experiments.workprecision.measurement import EVERY_MEASURE, stored_as_reference

    store = read_store(bundled_store())
    stored = {name: stored_as_reference(reference_for(store, scenes[name]), EVERY_MEASURE)
              for name in STORED if name in scenes}
    plans = {name: settings(name, nonlinear_available(), scene)
             for name, scene in scenes.items()}
    return run_work_precision(scenes, plans, REPEATS, run.progress, run.notes,
                              cache_dir=run.cache_dir, stored=stored)


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    """Per scene the run table, the reference and its evidence, the recommendations and the
    defaults check
    (:func:`flex.experiments.workprecision.tradeoff_report.summarize_work_precision`); the
    findings: per scene its Pareto front, levels and rule picks as tables
    (``tradeoff_findings``)."""
    datasets, report = summarize_work_precision(run.notes.get("runs", {}), cases(scene),
                                                FFRF_DEFAULT_SCENE)
    tables, findings = tradeoff_findings(datasets)
    return Summary(datasets | tables, report, findings=findings)


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    """Work-precision diagram per scene: every ok run (colour: sweep; marker: engine), the
    Pareto front of all runs (solid) and of flex's own settings (dashed, labelled), the
    rule's picks (open stars)."""
    return work_precision_figures(summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
