"""The rigid probe ``auto`` runs first, and the record of what ``auto`` chose.

Every ``"auto"`` choice that depends on the deployment (a link's model, the spring's model)
starts from one rigid run of the scene: :func:`probe_scene` says what that run is (every
link rigid, the coupler with its own mass; step min(the rigid step, 1e-4 s, end / 200) over
the end time, or over half a crank turn with a constant-speed drive, which has no
deployment of its own), :func:`deployment_probe` runs it and reads delta_t. The policy is
written here once: :func:`flex.fidelity.auto.check` refuses before anything runs a probe that
cannot run, with the same numbers. :class:`FidelityDecision` is what each choice stores.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.config.calibration import Calibration
from flex.config.settings import solver_defaults
from flex.data.fields import AUTO
from flex.data.steps import MAX_STEPS
from flex.dynamics.link_models import RIGID
from flex.fidelity.criteria import PRIMARY_DELTA_T, deployment_times

#: the probe's step: at most this [s], and at most end time / PROBE_SAMPLES
PROBE_MAX_STEP_S = 1e-4
PROBE_SAMPLES = 200


@dataclass
class FidelityDecision:
    """What ``auto`` chose for one link, and why (stored in the case attributes)."""

    link: str
    model: str
    modes: int | None
    reason: str
    tolerance: float
    delta_t_s: float
    omega_rad_per_s: float
    n_physical: float
    n_thesis: float
    k_physical: float
    predicted_error: float
    extrapolated: bool
    #: the rigid model's deflection error (peak elastic midpoint deflection / length)
    #: predicted from the rigid probe's own loads (:mod:`flex.fidelity.predictor`), for
    #: the coupler and the crank; NaN where not predicted
    predicted_rigid_error: float = math.nan

    def attrs(self) -> dict[str, Any]:
        """Flat attributes ``fidelity_<link>_*`` for :class:`flex.data.results.CaseResult`."""
        prefix = f"fidelity_{self.link}_"
        return {prefix + "model": self.model, prefix + "modes": -1 if self.modes is None
                else self.modes, prefix + "reason": self.reason,
                prefix + "tolerance": self.tolerance, prefix + "delta_t_s": self.delta_t_s,
                prefix + "omega_rad_per_s": self.omega_rad_per_s,
                prefix + "n_physical": self.n_physical, prefix + "n_thesis": self.n_thesis,
                prefix + "k_physical": self.k_physical,
                prefix + "predicted_error": self.predicted_error,
                prefix + "predicted_rigid_error": self.predicted_rigid_error,
                prefix + "extrapolated": self.extrapolated}




def probe_scene(scene: Mapping[str, Mapping[str, Any]], end_time_s: float | None = None,
                calibration: Calibration | None = None) -> dict[str, dict[str, Any]]:
    """The rigid probe run of ``scene`` (see the module doc) over ``end_time_s`` [s] (None:
    the scene's), with ``calibration``'s rigid solver defaults (None: the bundled ones): a
    concrete scene, every link rigid, its step and end time set, every
    sample stored. Raises :class:`SceneError` for a constant-speed drive at rest (no half
    turn to probe) and for a probe over the step limit."""
    rigid = copy.deepcopy({k: dict(v) for k, v in scene.items()})
    rigid["coupler"]["model"] = rigid["crank"]["model"] = RIGID
    end = float(rigid["simulation"]["end_time_s"] if end_time_s is None else end_time_s)
    drive = scene["drive"]
    if drive["kind"] == "constant_speed":
        speed = abs(drive["crank_speed_rad_per_s"])
        if speed == 0:
            raise SceneError('model = "auto" with a constant-speed drive needs '
                             "drive.crank_speed_rad_per_s != 0 (the criterion uses half a "
                             "crank turn as the deployment time)")
        end = min(end, math.pi / speed)
    rigid_entry = solver_defaults(calibration)["rigid"]
    step = scene["simulation"]["step_s"]
    step = min(float(rigid_entry["step_s"] if step == AUTO else step), PROBE_MAX_STEP_S,
               end / PROBE_SAMPLES)
    if end / step > MAX_STEPS:  # the message of a scene's end time (check: end_time_s None)
        raise SceneError(f"simulation.end_time_s = {scene['simulation']['end_time_s']:g}: "
                         f'model = "auto" first runs the rigid model over it at a step of '
                         f"{step:g} s to find the deployment time: {end / step:.3g} steps; "
                         f"accepted: at most {MAX_STEPS:g} (end_time_s <= "
                         f"{MAX_STEPS * step:.3g})")
    rigid["simulation"].update(end_time_s=end, step_s=step, output_step_s=0.0)
    for key in ("spectral_radius", "newton", "newton_relative_tolerance"):
        if rigid["simulation"][key] == AUTO:  # the probe's links are rigid
            rigid["simulation"][key] = rigid_entry[key]
    return rigid


def deployment_probe(scene: Mapping[str, Mapping[str, Any]],
                     calibration: Calibration | None = None,
                     ) -> tuple[float, str, dict[str, np.ndarray]]:
    """Deployment time [s] of a scene for the criterion, how it was obtained, and the rigid
    probe run's data (result paths -> arrays).

    The run of :func:`probe_scene`. Spring drive: extended up to 8 x end_time_s until the
    crank angle has its first maximum; delta_t by the
    :data:`flex.fidelity.criteria.PRIMARY_DELTA_T` definition. Constant-speed drive: no
    deployment; half a crank turn, pi / speed, is used (an extrapolation of a criterion
    fitted on spring deployments), the probe covering it.
    """
    from flex.dynamics.solver import integrate

    end = float(scene["simulation"]["end_time_s"])
    drive = scene["drive"]
    for _ in range(4):
        result = integrate(probe_scene(scene, end, calibration), "fidelity_probe")
        data = {k: np.asarray(v.data) for k, v in result.datasets.items()}
        if drive["kind"] == "constant_speed":
            if drive["crank_speed_rad_per_s"] == 0:  # half a turn never ends: no time scale
                raise SceneError('model = "auto": a constant-speed crank at rest '
                                 "(drive.crank_speed_rad_per_s = 0) has no deployment time "
                                 "for the criterion; accepted: a speed other than 0 rad/s, "
                                 'or the link model set ("rigid", "ffrf")')
            return (math.pi / abs(drive["crank_speed_rad_per_s"]),
                    "constant-speed drive: delta_t = half a crank turn", data)
        try:
            times = deployment_times(data["time"], data["crank/angle"],
                                     data["crank/angular_velocity"])
        except ValueError:
            end *= 2
            continue
        delta_t = times[PRIMARY_DELTA_T]
        keep = data["time"] <= delta_t * (1 + 1e-12)
        data = {k: v[keep] if v.ndim and len(v) == len(keep) else v for k, v in data.items()}
        return delta_t, (f"delta_t = {delta_t:.5g} s (first crank-angle maximum of the rigid "
                         f"run)"), data
    angle = data["crank/angle"]
    if np.ptp(angle) <= 1e-9 * max(1.0, float(np.max(np.abs(angle)))):  # at rest
        raise SceneError(f'model = "auto": the rigid run does not deploy (the crank does not '
                         f"move within {end:g} s; drive.spring_preload_m = "
                         f"{drive.get('spring_preload_m', 0.0):g} m), so the criterion has no "
                         f'time scale; give the spring a preload > 0 or set the link model '
                         f'("rigid", "ffrf")')
    raise SceneError(f'model = "auto": the crank angle has no maximum within {end:g} s: '
                     f"no deployment time; set the model explicitly")
