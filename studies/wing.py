"""Study ``wing`` (thesis sec. 6.4, figs. 59-60): a missile wing deployed by the mechanism.

The thesis gives only the outcome: deployment ~0.017 s, wing-tip angular velocity peaking near 7219
deg/s at ~0.008 s; no wing geometry, inertia or spring. flex states a wing (an aluminium switchblade
plate in the mechanism plane, welded to the crank at the pivot A, the ``[wing]`` keys of the scene)
and fits the two spring values the thesis leaves open -- stiffness and preload -- so that the
deployment reproduces the reported peak speed and its time
(:func:`flex.experiments.thesis.wing.fit_spring`). The deployment time (first crank-angle maximum)
is then a prediction, compared with the thesis's ~0.017 s.
Reported beside it: the joint loads and the wing-root bending moment; the wing's own
flexibility (cantilever bending frequencies in and out of plane, the thesis's ratio n, and
the quasi-static tip deflection under the peak inertial load); and, for the other bodies,
the ``auto`` fidelity decision of :mod:`flex.fidelity.criteria` where a fitted criterion exists.
"""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.thesis import wing
from flex.study import StudyRun, Summary, simulate_each

NAME = "wing"
DESCRIPTION = "wing deployment (sec. 6.4): fitted spring, loads, wing flexibility"
OVERRIDES = ["wing.enabled=true", "simulation.end_time_s=0.025"]
# keys the study reads itself (the wing's frequency and tip deflection, the spring fit)
READS = ("wing.span_m", "wing.chord_m", "wing.thickness_m", "wing.density_kg_per_m3",
         "wing.youngs_modulus_Pa", "drive.spring_preload_m",
         "drive.spring_stiffness_N_per_m")


def cases(scene: Scene) -> dict[str, Scene]:
    return {"wing_deployment": wing.fit_spring(scene)[0]}


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Each case on its own; the summary's ``auto`` decisions get the reduction cache."""
    return simulate_each(scenes, run)


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*wing.summary(results["wing_deployment"], run.cache_dir))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return wing.draw_figures(results["wing_deployment"], folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
