"""An FFRF coupler scene's converged reference, the one the FFRF rule is calibrated against
(:mod:`flex.experiments.fitting.calibration`) and the benchmark's plates are measured against
(:mod:`flex.experiments.workprecision.benchmark`).

The reference: :data:`REFERENCE_MODES` in-plane modes, a mesh of about the thickness (at most
L / 32, at least :data:`REFERENCE_MESH_FLOOR_M`) and a step that resolves the top mode
(:data:`REFERENCE_STEPS_PER_TOP_PERIOD` steps per period, at most T1 / 400), with the evidence
of three one-level coarsenings (8 modes, twice the step, 1.5 x the mesh; their changes summed
are the reference's accuracy,
:func:`flex.experiments.workprecision.convergence.converged_reference`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from flex.base.physics import Plate
from flex.config.ffrf_rule import first_period_s
from flex.data.scene import Scene
from flex.experiments.workprecision.convergence import converged_reference
from flex.experiments.workprecision.measurement import ReductionPool, Reference, Setting

#: the tolerance levels calibrated (relative error of the peak midpoint deflection); a
#: reference must be converged to a third of the finest
LEVELS = (0.01, 0.001)
#: reference discretization
REFERENCE_MODES = 12
REFERENCE_STEPS_PER_TOP_PERIOD = 16.0
REFERENCE_MESH_FLOOR_M = 0.00075
#: solver keys of every run (make tradeoff's fastest FFRF choices)
SOLVER = {"newton": "modified", "newton_relative_tolerance": 1e-8, "spectral_radius": 0.9}

Progress = Callable[[str], None]


def coupler_setting(label: str, step_s: float, modes: int, mesh_m: float) -> Setting:
    """A setting of the coupler's step [s], modes and mesh size [m], with :data:`SOLVER`'s
    keys and no output sampling."""
    return Setting.of(label, step_s=step_s, coupler__modes=modes,
                      coupler__mesh_size_m=mesh_m, output_step_s=0.0, **SOLVER)


def reference_discretization(coupler: Mapping[str, Any]) -> tuple[float, int, float]:
    """Step [s], modes and mesh size [m] of a scene's reference (see the module doc)."""
    omegas = Plate.of(coupler).in_plane_omegas(REFERENCE_MODES)
    top_period = 2 * math.pi / omegas[-1]
    step = min(first_period_s(coupler) / 400.0, top_period / REFERENCE_STEPS_PER_TOP_PERIOD)
    mesh = max(min(coupler["thickness_m"], coupler["length_m"] / 32.0), REFERENCE_MESH_FLOOR_M)
    return step, REFERENCE_MODES, mesh


def scene_reference(scene: Scene, pool: ReductionPool, progress: Progress | None = None
                    ) -> Reference:
    """The converged reference of ``scene`` with its evidence (see the module doc)."""
    step, modes, mesh = reference_discretization(scene["coupler"])
    finest = coupler_setting("reference", step, modes, mesh)
    coarsenings = {f"modes {modes} -> 8": coupler_setting("modes 8", step, 8, mesh),
                   "step_s x2": coupler_setting("step x2", 2 * step, modes, mesh),
                   "mesh x1.5": coupler_setting("mesh x1.5", step, modes, 1.5 * mesh)}
    return converged_reference(scene, "reference", finest, coarsenings, min(LEVELS) / 3,
                               pool, progress=progress)
