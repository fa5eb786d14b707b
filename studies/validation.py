"""Study ``validation``: flex against a published benchmark, the flexible slider-crank of the
IVP test set (Mazzia & Magherini, *Test Set for IVP Solvers*, Bari; problem "crank", B.
Simeon's two-mode model, reference values at t = 0.1 s).

Crank 0.15 m at 150 rad/s, steel rod 0.3 m x 8 x 8 mm, slider 0.075552 kg, no gravity, no
damping. Runs: flex's rigid rod (against the closed form), flex's default FFRF rod (chord
frame, geometric stiffness) under step, mode and mesh refinement, the linear FFRF rod, the
nonlinear FE rod at two steps (the reference), and the independent two-mode model
(:mod:`flex.experiments.models.ivp_crank`) with the published settings and one change at a time.
What
each comparison means: :mod:`flex.experiments.models.validation`, docs/validation.md.
"""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.models import validation
from flex.study import StudyRun, Summary, simulate_each

NAME = "validation"
DESCRIPTION = "IVP test set flexible slider-crank (Simeon): published values, FFRF, nonlinear FE"
OVERRIDES = validation.benchmark_overrides()
#: flex runs: name -> (coupler model, mesh size [m], Craig-Bampton modes, step [s], geometric
#: stiffness). The FFRF base is flex's default body on a mesh of 8 mm (the rod's height), 6
#: modes; each group refines one knob; ``ffrf_linear`` is the linear FFRF rod.
RUNS: dict[str, tuple[str, float, int, float, bool]] = {
    "rigid": ("rigid", 0.008, 6, 1e-4, False),
    "ffrf_h1e-4": ("ffrf", 0.008, 6, 1e-4, True),
    "ffrf_h5e-5": ("ffrf", 0.008, 6, 5e-5, True),
    "ffrf_h2e-5": ("ffrf", 0.008, 6, 2e-5, True),
    validation.FFRF_DEFAULT: ("ffrf", 0.008, 6, 1e-5, True),
    "ffrf_modes2_h1e-5": ("ffrf", 0.008, 2, 1e-5, True),
    "ffrf_modes12_h1e-5": ("ffrf", 0.008, 12, 1e-5, True),
    "ffrf_mesh4mm_h1e-5": ("ffrf", 0.004, 6, 1e-5, True),
    validation.FFRF_LINEAR: ("ffrf", 0.008, 6, 1e-5, False),
    "nonlinear_fe_h5e-5": ("nonlinear_fe", 0.008, 6, 5e-5, False),
    "nonlinear_fe_h2p5e-5": ("nonlinear_fe", 0.008, 6, 2.5e-5, False),
}
#: the most complete model, finest step: what the other runs are measured against
REFERENCE = "nonlinear_fe_h2p5e-5"
#: the curves drawn (summary datasets runs/<name>/...)
SHOWN = ("two-mode_rigid_start_stiffened", "two-mode_rigid_start", validation.FFRF_DEFAULT,
         validation.FFRF_LINEAR, REFERENCE)


def cases(scene: Scene) -> dict[str, Scene]:
    return validation.flex_cases(scene, RUNS)


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """flex's runs (reductions cached in ``run.cache_dir``), two at a time (the nonlinear FE
    references first; the runs of one reduction together), then the independent two-mode
    runs into ``run.notes``, two at a time."""
    from contextlib import closing

    from flex.sweep import make_executor

    with closing(make_executor()) as executor:
        results = simulate_each(scenes, run, executor, _reduction_of, _cost)
        run.notes["two_mode"] = validation.two_mode_runs(progress=run.progress,
                                                         executor=executor)
    return results


def _reduction_of(name: str, scene: Scene) -> tuple | None:
    """The runs of one reduction go together (built once); a nonlinear FE run alone."""
    rod = scene["coupler"]
    return None if rod["model"] != "ffrf" else (rod["mesh_size_m"], rod["modes"])


def _cost(name: str, scene: Scene) -> float:
    """A run's rough cost for ordering: its steps, a nonlinear FE step ~20x an FFRF one."""
    steps = scene["simulation"]["end_time_s"] / scene["simulation"]["step_s"]
    return steps * (20.0 if scene["coupler"]["model"] == "nonlinear_fe" else 1.0)


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    solutions = run.notes.get("two_mode") or validation.two_mode_runs()
    return Summary(*validation.analyse(scene, results, solutions, REFERENCE))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return validation.draw_figures(summary.datasets, folder, SHOWN)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
