"""Regenerate the reference curves of ``tests/test_reference_curves.py``.

    .venv/bin/python tests/reference_curves/make.py

writes ``tests/reference_curves/deployment_preload_22mm.h5``: the thesis deployment (chapter
5, the bundled ``cavezza2012`` scene, spring preload 0.022 m) solved by the independent
reference DAE (:func:`flex.reference.solve_reference`, 9 coordinates, Lagrange multipliers,
DOP853 at rtol 1e-12) -- not by Exudyn -- sampled every 0.2 ms (151 samples; a cubic spline
through them reproduces the curve to ~1e-9 relative, far inside the tolerance). Stored with
:func:`flex.results.write_results` (case ``preload_22mm``, like ``results/dynamics.h5``), so
``python -m flex compare results/dynamics.h5 tests/reference_curves/deployment_preload_22mm.h5``
compares a study run with it. The tolerance travels with the file as root attributes
``compare_rtol`` / ``compare_atol`` (and on the case); the test states it too.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flex.data.results import CaseResult, Dataset, write_results
from flex.data.scene import load_scene, to_toml
from flex.dynamics.reference import solve_reference

FOLDER = Path(__file__).resolve().parent
DEPLOYMENT_FILE = FOLDER / "deployment_preload_22mm.h5"
CASE = "preload_22mm"
OVERRIDES = ["drive.spring_preload_m=0.022"]
SAMPLE_STEP_S = 2e-4
# pass if max|a - b| <= atol + rtol * max|b|: 1.7e-6 rad on the crank angle (Exudyn's
# index-3 generalized-alpha at 1e-5 s is ~1.3e-7 rad off), 1.1e-7 m on the slider
# (~5.9e-9 m off): about ten times the deviation measured when the curves were made
RTOL = 1e-6
ATOL = 0.0
PATHS = [f"{CASE}/crank/angle", f"{CASE}/slider/position"]


def make_deployment(path: Path = DEPLOYMENT_FILE) -> Path:
    """Solve the reference DAE and write the reference curve file; return its path."""
    scene = load_scene(overrides=OVERRIDES)
    end_s = scene["simulation"]["end_time_s"]
    count = int(round(end_s / SAMPLE_STEP_S))
    time_s = np.linspace(0.0, count * SAMPLE_STEP_S, count + 1)
    reference = solve_reference(scene, time_s)
    tolerance = {"compare_rtol": RTOL, "compare_atol": ATOL,
                 "tolerance": "pass if max|a - b| <= atol + rtol * max|b| (b: this file)"}
    case = CaseResult(CASE, to_toml(scene), {
        "time": Dataset(reference.time_s, "s", "simulation time"),
        "crank/angle": Dataset(reference.q[:, 2], "rad",
                               "crank angle from the slide line (+x), reference DAE"),
        "slider/position": Dataset(reference.q[:, 6], "m",
                                   "slider x (joint C) along the slide line, reference DAE"),
    }, attrs={"source": "flex.reference.solve_reference (DOP853, rtol 1e-12)", **tolerance})
    write_results(path, "reference_curves", [case], to_toml(scene), attrs={
        **tolerance,
        "compare_paths": " ".join(PATHS),
        "regenerate": "python tests/reference_curves/make.py",
        "rerun": f"python -m flex compare results/dynamics.h5 "
                 f"tests/reference_curves/{path.name} --rtol {RTOL:g} --atol {ATOL:g} "
                 f"{' '.join(PATHS)}",
    })
    return path


if __name__ == "__main__":
    print(f"wrote {make_deployment()}")
