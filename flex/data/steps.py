"""A scene's step settings: step, output interval and step count, and the constant-speed
crank's turn per step and per stored sample (split from :mod:`flex.data.scene`, which
re-exports these names and runs them in its validation).
"""

from __future__ import annotations

import math
from typing import Any

from flex.base.errors import SceneError

Scene = dict[str, dict[str, Any]]

#: most integration steps of one run: ~25 min of the rigid model (0.03 ms per step), days of
#: an FFRF one, and 5e7 samples x ~40 datasets is ~16 GB of output at output_step_s = 0
MAX_STEPS = 5e7
#: largest crank rotation per integration step of the constant-speed drive [rad]: 63 steps
#: per crank turn, 31 per period of the slider's second harmonic (the largest after the
#: first for L1 / L2 = 1/2), where the generalized-alpha period error (omega h)^2 / 12 is
#: 3e-3. At 10 rad per step (1e6 rad/s, 1e-5 s) the motion is aliased: the crank turns
#: 1.6 times between steps. The studies reach 6.3e-3 rad (100 turns per second, 1e-5 s).
MAX_CRANK_TURN_PER_STEP_RAD = 0.1
#: largest crank rotation between stored samples [rad]: the stored slider curve is sampled
#: at least 4 times per period of its second harmonic (Nyquist: 2; the studies store at
#: 6.3e-3 rad per sample)
MAX_CRANK_TURN_PER_SAMPLE_RAD = math.pi / 4


def check_steps(sim: dict[str, Any]) -> None:
    """Step, output interval and step count; an ``"auto"`` step is checked once resolved.

    The output interval must be 0 (every step) or an integer multiple of the step: Exudyn
    stores a sample at the first step at or after each interval, so another interval gives
    irregularly spaced samples (e.g. 2.5e-5 s at 1e-5 s: 3e-5, 5e-5, 8e-5, ...).
    """
    if sim["step_s"] == "auto":
        return
    step, output = sim["step_s"], sim["output_step_s"]
    if step > sim["end_time_s"]:
        raise SceneError(f"simulation.step_s = {step:g} must be <= "
                         f"simulation.end_time_s = {sim['end_time_s']:g}")
    if 0 < output < step * (1 - 1e-9):
        raise SceneError(f"simulation.output_step_s = {output:g} must be >= "
                         f"simulation.step_s = {step:g} (or 0: every step)")
    steps = sim["end_time_s"] / step
    if steps > MAX_STEPS:
        raise SceneError(f"simulation.end_time_s = {sim['end_time_s']:g} at simulation.step_s "
                         f"= {step:g} needs {steps:.3g} steps; accepted: at most "
                         f"{MAX_STEPS:g} steps (end_time_s <= {MAX_STEPS * step:.3g} at this "
                         f"step)")
    if output > 0:
        ratio = output / step
        if abs(ratio - round(ratio)) > 1e-6 + 1e-9 * ratio:  # float noise only
            below, above = math.floor(ratio) * step, math.ceil(ratio) * step
            raise SceneError(f"simulation.output_step_s = {output:g} must be an integer "
                             f"multiple of simulation.step_s = {step:g} (it is {ratio:.6g} "
                             f"steps: the samples would be irregular); nearest valid: "
                             f"{below:.6g} or {above:.6g} (or 0: every step)")


def check_drive_steps(scene: Scene) -> None:
    """A constant-speed crank must turn at most :data:`MAX_CRANK_TURN_PER_STEP_RAD` per step
    and :data:`MAX_CRANK_TURN_PER_SAMPLE_RAD` between stored samples (an ``"auto"`` step is
    checked once resolved)."""
    sim, drive = scene["simulation"], scene["drive"]
    if drive["kind"] != "constant_speed" or sim["step_s"] == "auto":
        return
    speed = abs(drive["crank_speed_rad_per_s"])
    step, sample = sim["step_s"], sim["output_step_s"] or sim["step_s"]
    for interval, limit, what, key, aliased, extra in (
            (step, MAX_CRANK_TURN_PER_STEP_RAD, "per step", "simulation.step_s", "motion is",
             ""),
            (sample, MAX_CRANK_TURN_PER_SAMPLE_RAD, "between stored samples",
             "simulation.output_step_s", "stored curves are", " (or 0: every step)")):
        if speed * interval > limit * (1 + 1e-9):
            raise SceneError(f"drive.crank_speed_rad_per_s = {drive['crank_speed_rad_per_s']:g} "
                             f"turns the crank {speed * interval:.3g} rad {what} ({key} = "
                             f"{interval:g} s): the {aliased} aliased; accepted: at most "
                             f"{limit:.3g} rad {what}, i.e. |crank_speed_rad_per_s| <= "
                             f"{limit / interval:.4g}, or {key} <= {limit / speed:.3g}{extra}")
