"""Study ``modal`` (thesis sec. 6.2-6.3, Tables 5, 7, 9): eigenmodes of the links.

Each link is meshed as a steel plate (NGsolve, second-order tetrahedra): the coupler
0.08 x 0.01 x t for the four Table 5 models, the crank 0.04 x 0.01 x 0.01. First five modes
free-free and with the mechanism's joint conditions (pinned-pinned: each end face pinned
about z at its centre), each classified (in-plane / out-of-plane bending, torsion, axial) and
compared with Euler-Bernoulli and Timoshenko beam theory. Table 5 is reproduced in both
period conventions (thesis T = 1/omega; physical T = 2 pi/omega) with n = delta_t / T;
Tables 7 and 9 (ANSYS BEAM188, units and sections not stated) with flex's reading of them.
Mesh convergence is part of the result: per model the element count, DOF and frequency of
each second-order refinement level (up to ~20k DOF), the production mesh (coarsest level
within 0.1 % of the reference, and every finer level too) and the reference itself: the
element order raised to 3 and 4 on one level's mesh (p-refinement, stored with its
estimated error, 1e-5 to 3e-5). Until issue 50 the reference was the Richardson extrapolation
of levels refined to 60k DOF: they cost two thirds of the study's time (75 s then, 22 s now,
measured on 2 shared cores) and were 1e-5 to 3e-5 off the order-4 value; the production
meshes chosen are the same. The survey is :func:`flex.experiments.thesis.modal.survey`;
nothing is simulated.
"""

from __future__ import annotations

from pathlib import Path

from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.experiments.thesis import modal
from flex.study import StudyRun, Summary

NAME = "modal"
DESCRIPTION = "link eigenmodes: FE vs beam theory, Tables 5, 7, 9, mesh convergence"
OVERRIDES: list[str] = []
# keys the study reads itself (its modal analyses), beside what its cases simulate
READS = ("coupler.length_m", "coupler.width_m", "coupler.youngs_modulus_Pa",
         "coupler.density_kg_per_m3", "coupler.poisson_ratio", "crank.length_m")


def cases(scene: Scene) -> dict[str, Scene]:
    return {}


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    return {}


def summarize(scene: Scene, results: dict[str, CaseResult],
              run: StudyRun) -> Summary:
    return Summary(*modal.survey(scene, run.progress))


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    return modal.draw_figures(summary.datasets, folder)


if __name__ == "__main__":
    from flex.cli import main

    raise SystemExit(main(["run", NAME]))
