"""Study ``crank``: the flexible (FFRF) crank, and whether ``crank.model = "auto"`` holds.

The thesis models only the coupler as flexible. flex also meshes the crank (a steel plate
A-B, ``[crank] geometry = "plate"``, reduced like the coupler) and lets ``auto`` choose
rigid or FFRF for it from a fitted criterion, with the crank's first in-plane elastic
frequency in the assembled mechanism (:func:`flex.fidelity.auto.crank_elastic_omega`). Without a
wing that is the plate's pinned-pinned frequency; with the wing welded at A the crank is a
cantilever from the wing carrying coupler and slider at B, an order of magnitude softer.

The kfit law, fitted on couplers, under-predicts the error of a rigid crank that carries
the wing (measured about 2x at equal n: at the same n the wing makes the crank a cantilever
under a larger quasi-static load). So the crank gets its own law, through the same pipeline
as the coupler's (:mod:`flex.experiments.fitting.lawfit`, the crank's half in
:mod:`flex.experiments.fitting.crank`). Phase 1
(fit): crank thicknesses 0.8-5 mm x two spring rates, all with the wing (the harder case;
cranks without a wing err less at equal n, so the law is conservative for them), each run
rigid and as the full model, an FFRF crank with 12 modes; the governing error against n is
fitted and written to ``results/crank-criterion.toml`` (``make calibration-install`` installs it
as ``flex/config/crank_criteria_fit.toml``, which ``auto`` reads). Phase 2 (validation): scenes not
in the fit (other thicknesses, with and without the wing, tolerances 1 % and 0.1 %) run
``auto`` with the law just fitted and the full model.

Errors (of rigid or auto against the full model, over the deployment: to the first
crank-angle maximum of the full run) are the kfit measures with the crank in the coupler's
place: crank midpoint deflection / L1, crank angle / swing, slider position / travel; the
largest (governing) is fitted and held against the tolerance.
"""

from __future__ import annotations

from contextlib import closing
from pathlib import Path

from flex.base.thesis import THESIS_SPRING_RATE_N_PER_M
from flex.config.settings import pinned_overrides
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.fitting import crank, lawfit
from flex.study import RESULTS_DIR, StudyRun, Summary

NAME = "crank"
DESCRIPTION = "flexible FFRF crank against auto's choice, with and without the wing"
# the solver entry of flexible links: the rigid entry's 1e-5 s grid with modified Newton (on
# the 1 mm plate every headline equal to full Newton's within 3e-7, in half the time)
OVERRIDES = pinned_overrides("flexible_fallback") + [
    "simulation.error_estimate=false",  # own references
    'crank.geometry="plate"', "simulation.step_s=2e-5", "simulation.end_time_s=0.05"]
# keys the study reads itself (its fit grid), beside what its cases simulate
READS = ("crank.length_m", "crank.thickness_m", "drive.spring_stiffness_N_per_m")

#: fit scenes (all with the wing): (crank thickness [mm], spring rate [N/m]). Every
#: thickness with both springs except 0.8 mm at 6000 N/m: that full FFRF run fails Newton at
#: 17.9 ms (h = 2e-5 s), a failed case that would stop `make all`
FIT_CASES = ((0.8, THESIS_SPRING_RATE_N_PER_M),
             *((t, k) for t in (1.2, 1.8, 2.5, 3.5, 5.0)
               for k in (THESIS_SPRING_RATE_N_PER_M, 6000.0)))
#: validation scenes (not in the fit): name -> (overrides, fidelity tolerance)
SCENES: dict[str, tuple[list[str], float]] = {
    "wing_t1mm_tol1pct": (["crank.thickness_m=0.001", "wing.enabled=true"], 0.01),
    "wing_t1p5mm_tol1pct": (["crank.thickness_m=0.0015", "wing.enabled=true"], 0.01),
    "wing_t2mm_tol1pct": (["crank.thickness_m=0.002", "wing.enabled=true"], 0.01),
    "wing_t3mm_tol0p1pct": (["crank.thickness_m=0.003", "wing.enabled=true"], 0.001),
    "wing_t4p56mm_tol0p1pct": (["wing.enabled=true"], 0.001),
    "t1mm_tol0p1pct": (["crank.thickness_m=0.001"], 0.001),
}
#: where phase 1 writes the fitted crank law
CRITERION_PATH = RESULTS_DIR / "crank-criterion.toml"


def cases(scene: Scene) -> dict[str, Scene]:
    """Fit scenes as ``__rigid`` and ``__full`` cases; validation scenes as ``__auto`` and
    ``__full`` cases (run after the fit, see :func:`simulate_cases`)."""
    return crank.cases(scene, FIT_CASES, SCENES)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Phase 1: fit cases; fit the law, write :data:`CRITERION_PATH`; phase 2: validation
    cases, ``auto`` reading the law just fitted (passed as an argument). The cases run on
    local processes, those of one crank plate together."""
    from flex.sweep import make_executor

    with closing(make_executor()) as executor:
        runner = lawfit.SerialRunner("crank", NAME, len(scenes), run.progress,
                                     cache_dir=run.cache_dir, executor=executor,
                                     group=crank.same_crank)
        results, run.notes["analysis"] = crank.fit_then_validate(
            scenes, runner, CRITERION_PATH, run.cache_dir)
    return results


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*crank.summarize(cases(scene), results, run.notes.get("analysis"),
                                       CRITERION_PATH))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    from flex.experiments.fitting.lawplots import crank_figures

    return crank_figures(results, summary, list(SCENES), folder)
