"""The calibration's tolerance levels and the solver keys of its runs (the FFRF rule is
calibrated at these levels, :mod:`flex.experiments.fitting.calibration`, against the stored
references of ``make references``; the in-run converged FFRF reference that lived here is
gone: every study that judged against it reads the store).
"""

from __future__ import annotations

from collections.abc import Callable

from flex.experiments.workprecision.measurement import Setting

#: the tolerance levels calibrated (relative error of the peak midpoint deflection); a
#: reference must be converged to a third of the finest
LEVELS = (0.01, 0.001)
#: solver keys of every run (make tradeoff's fastest FFRF choices)
SOLVER = {"newton": "modified", "newton_relative_tolerance": 1e-8, "spectral_radius": 0.9}

Progress = Callable[[str], None]


def coupler_setting(label: str, step_s: float, modes: int, mesh_m: float) -> Setting:
    """A setting of the coupler's step [s], modes and mesh size [m], with :data:`SOLVER`'s
    keys and no output sampling."""
    return Setting.of(label, step_s=step_s, coupler__modes=modes,
                      coupler__mesh_size_m=mesh_m, output_step_s=0.0, **SOLVER)
