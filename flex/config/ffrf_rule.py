"""Settings from the tolerance for an FFRF link: modes, mesh and step from the scene's physics.

Given ``fidelity.tolerance`` (relative error of the peak elastic midpoint deflection, the
most demanding headline quantity), the rule chooses for an FFRF coupler on a rigid crank:

- the **step** as a fraction of the link's first bending period ``T1`` (pinned-pinned,
  Euler-Bernoulli, :func:`flex.base.physics.pinned_pinned_omega`): ``h = T1 / N`` with ``N =
  C n^-B`` rounded up to :data:`STEP_GRID`, where ``n = t_load / T1`` counts first periods
  per time scale of the load (:func:`load_time_scale_s`: the spring's quarter period, or
  half a crank turn) -- the thesis's rigid-or-flexible number. The deflection is the first
  mode's response to the joint loads; a plate that vibrates many times while its load
  changes follows it nearly quasi-statically, and its peak is less sensitive to the phase
  of that vibration, so it needs fewer steps per period;
- the **modes**: the in-plane fixed-interface eigenmodes (symmetric about the mechanism
  plane: what a planar load excites) up to a calibrated multiple of the first
  (:func:`level_modes`; a thick plate's axial and shear-softened modes crowd towards it).
  More modes than the step resolves do not help: generalized-alpha damps a mode of period
  below a few steps, and an unresolved mode rings with a step-dependent phase that moves
  the peak;
- the **mesh**: ``min(MESH_PER_THICKNESS t, L / MESH_PER_LENGTH)`` -- quadratic tetrahedra
  resolve bending across a thin plate at about twice its thickness (modal study: first
  frequency within 0.1 %), and a thick one needs elements along its length.

The mode cut-off ratio, ``C`` and ``B`` are calibrated per tolerance level and per damping class
(:func:`damping_class`) by ``make calibrate`` (:mod:`flex.experiments.fitting.calibration`) over a
family of plates, materials, springs and drives, and live in ``ffrf_rule.toml`` of a calibration
(:mod:`flex.config.calibration`: the bundled ``flex/config/ffrf_rule.toml``, or one passed in)
with the family's bounds and the worst calibration error. A tolerance between levels uses
the next finer level. Outside the calibrated family (slenderness, a tolerance finer than the
finest level of the class, an ``n`` that would need more steps than the grid, an FFRF crank,
the nonlinear FE coupler) the rule says so and :mod:`flex.config.settings` falls back
visibly.

Contract: pure functions of the scene's values; nothing is meshed or run.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from flex.base.physics import Plate
from flex.config.calibration import Calibration, calibration_of
from flex.data.fields import AUTO
from flex.data.plates import MESH_ASPECT_LIMIT, plate_mass_properties
from flex.data.scene import LINKS

#: steps per first bending period the rule chooses from (make calibrate's grid)
STEP_GRID = (4, 8, 16, 32, 64, 128)
#: in-plane eigenmode counts the rule chooses from (make calibrate's grid)
MODE_GRID = (1, 2, 4, 8)
#: scene keys of a link the rule may fill when they are ``"auto"``
LINK_KEYS = ("modes", "mesh_size_m")



def rule_constants(calibration: Calibration | None = None) -> Mapping[str, Any]:
    """The calibrated constants of ``calibration``'s rule (``ffrf_rule.toml``; None: the
    bundled calibration's, :mod:`flex.config.calibration`)."""
    return calibration_of(calibration).ffrf_rule


@dataclass(frozen=True)
class RulePick:
    """What the rule chose for one FFRF link: ``step_s`` [s], ``modes`` (in-plane
    fixed-interface eigenmodes), ``mesh_size_m`` [m], the calibrated ``level`` applied
    (relative; None outside the calibrated family, then ``step_s`` is None) and one sentence
    ``reason``."""

    step_s: float | None
    modes: int
    mesh_size_m: float
    level: float | None
    reason: str


def first_period_s(link: Mapping[str, Any]) -> float:
    """First in-plane bending period [s] of a plate link, pinned-pinned (Euler-Bernoulli)."""
    return 2.0 * math.pi / Plate.of(link).pinned_pinned_omega


def rule_mesh_size_m(link: Mapping[str, Any], mesh: Mapping[str, float] | None = None,
                     calibration: Calibration | None = None) -> float:
    """Element size [m] the rule gives a plate link: ``min(MESH_PER_THICKNESS t, L /
    MESH_PER_LENGTH)``, and at most :data:`flex.data.plates.MESH_ASPECT_LIMIT` x the plate's
    smaller side (the elements' aspect limit the scene checks). ``mesh``: the constants
    ``per_thickness`` and ``per_length`` (default: ``calibration``'s)."""
    mesh = rule_constants(calibration)["mesh"] if mesh is None else mesh
    size = min(mesh["per_thickness"] * link["thickness_m"],
               link["length_m"] / mesh["per_length"])
    return float(min(size, MESH_ASPECT_LIMIT * min(link["thickness_m"], link["width_m"])))


def outside_family(link: Mapping[str, Any], tolerance: float,
                   calibration: Calibration | None = None) -> str:
    """Why a plate link and tolerance lie outside the calibrated family ("" if inside)."""
    family = rule_constants(calibration)["family"]
    slenderness = link["length_m"] / link["thickness_m"]
    damping = damping_class(link, calibration)
    levels = _levels(damping, calibration)
    if not levels:
        return f"no level is calibrated for {damping} links"
    finest = levels[0]["tolerance"]
    if not family["slenderness_min"] <= slenderness <= family["slenderness_max"]:
        return (f"length_m / thickness_m = {slenderness:.4g} is outside the calibrated "
                f"[{family['slenderness_min']:g}, {family['slenderness_max']:g}]")
    if tolerance < finest * (1 - 1e-9):
        return (f"fidelity.tolerance = {tolerance:g} is finer than the finest calibrated "
                f"level {finest:g} for {damping} links")
    return ""


def damping_class(link: Mapping[str, Any], calibration: Calibration | None = None) -> str:
    """``"damped"`` if the link's ``damping_ratio`` reaches the calibrated damped class's
    (``family.damped_ratio_min``), else ``"undamped"``.

    Why two classes: damped, the free vibration the release starts decays within about
    1 / (2 pi zeta) first-mode periods (stiffness-proportional damping kills the higher modes
    faster), so the peak is an early crest and only the first period needs resolving;
    undamped, the peak is the highest of many crests over the whole run, and the step must
    keep the first mode's phase and the retained modes' ringing over every period of it.
    """
    minimum = rule_constants(calibration)["family"].get("damped_ratio_min", math.inf)
    return "damped" if link.get("damping_ratio", 0.0) >= minimum * (1 - 1e-9) else "undamped"


def _levels(damping: str, calibration: Calibration | None = None) -> list[dict[str, Any]]:
    return sorted((level for level in rule_constants(calibration)["levels"]
                   if level.get("damping", damping) == damping),
                  key=lambda level: level["tolerance"])


def level_for(tolerance: float, damping: str = "undamped",
              calibration: Calibration | None = None) -> dict[str, Any]:
    """The calibrated level of the ``damping`` class (:func:`damping_class`) that serves
    ``tolerance``: the coarsest level at or below it (the finest level when ``tolerance``
    is finer than every level)."""
    levels = _levels(damping, calibration)
    within = [level for level in levels if level["tolerance"] <= tolerance * (1 + 1e-9)]
    return within[-1] if within else levels[0]


def load_time_scale_s(scene: Mapping[str, Mapping[str, Any]]) -> float:
    """The time scale [s] on which the mechanism loads its links: a spring drive's quarter
    period ``(pi / 2) sqrt(m / k)`` with m the slider's, coupler's and crank's masses (the
    spring pushing the whole mechanism), a constant-speed crank's half turn ``pi / |w|``."""
    drive = scene["drive"]
    if drive["kind"] == "constant_speed":
        speed = abs(drive["crank_speed_rad_per_s"])
        return math.pi / speed if speed > 0 else float(scene["simulation"]["end_time_s"])
    mass = scene["slider"]["mass_kg"] + sum(plate_mass_properties(scene, link)[0]
                                            for link in LINKS)
    if drive["spring_stiffness_N_per_m"] <= 0:  # a spring of no stiffness loads nothing
        return float(scene["simulation"]["end_time_s"])
    return 0.5 * math.pi * math.sqrt(mass / drive["spring_stiffness_N_per_m"])


def mode_cutoff(level: Mapping[str, Any], n_load: float = math.inf) -> float:
    """The level's mode cut-off over the first bending frequency for a link with ``n_load =
    t_load / T1``: the larger of ``mode_cutoff_ratio`` and ``mode_cutoff_load / n_load``.
    The second is a cut-off at ``mode_cutoff_load`` x ``2 pi / t_load``: the modes the
    load's own time scale can excite, which for a slender, slowly loaded link (small n)
    reach far above its first mode, and for a stiff one stay below it."""
    return max(level["mode_cutoff_ratio"], level.get("mode_cutoff_load", 0.0) / n_load)


def holds_at(level: Mapping[str, Any], n_load: float) -> bool:
    """Whether ``n_load = t_load / T1`` lies within the range the level's calibration scenes
    spanned (``n_load_min`` / ``n_load_max``; a level without them holds everywhere)."""
    return (level.get("n_load_min", 0.0) * (1 - 1e-9) <= n_load
            <= level.get("n_load_max", math.inf) * (1 + 1e-9))


def level_modes(level: Mapping[str, Any], link: Mapping[str, Any],
                n_load: float = math.inf) -> int:
    """The in-plane eigenmodes a level keeps for ``link`` (``n_load = t_load / T1``): every
    estimated in-plane fixed-interface mode
    (:func:`flex.base.physics.in_plane_fixed_interface_omegas`) up to :func:`mode_cutoff`
    x the first, rounded up to :data:`MODE_GRID`. A thick plate's axial and shear-softened
    modes crowd towards its first bending mode, so it keeps more. (A level with a fixed
    ``modes`` count keeps that.)"""
    if "mode_cutoff_ratio" not in level:
        return int(level["modes"])
    omegas = Plate.of(link).in_plane_omegas(MODE_GRID[-1] + 1)
    cut = mode_cutoff(level, n_load)
    below = sum(1 for omega in omegas if omega <= cut * omegas[0])
    return next((m for m in MODE_GRID if m >= below), MODE_GRID[-1])


def top_mode_ratio(level: Mapping[str, Any], link: Mapping[str, Any],
                   n_load: float = math.inf) -> float:
    """Estimated frequency of the highest in-plane mode the level keeps for ``link`` (with
    ``n_load``, :func:`level_modes`) over the first's (1 for one mode)."""
    modes = level_modes(level, link, n_load)
    omegas = Plate.of(link).in_plane_omegas(modes)
    return omegas[-1] / omegas[0]


def steps_per_first_period(level: Mapping[str, Any], n_load: float,
                           top_ratio: float = 1.0) -> float | None:
    """The grid value of steps per first period the level gives a link with ``n_load = t_load
    / T1`` first periods per load time scale and its highest retained mode ``top_ratio``
    times the first: the smallest of :data:`STEP_GRID` at or above both ``steps_coefficient
    x n_load^(-steps_exponent)`` and ``steps_per_top_period x top_ratio`` (every retained
    mode resolved); None beyond the grid's finest."""
    wanted = max(level["steps_coefficient"] * n_load ** (-level["steps_exponent"]),
                 level.get("steps_per_top_period", 0.0) * top_ratio)
    return next((float(n) for n in STEP_GRID if n >= wanted * (1 - 1e-9)), None)


def pick(scene: Mapping[str, Mapping[str, Any]], tolerance: float, link: str = "coupler",
         calibration: Calibration | None = None) -> RulePick:
    """The rule's settings for the FFRF plate ``link`` of ``scene`` at ``tolerance``
    (``calibration``'s rule; None: the bundled one)."""
    values = scene[link]
    damping = damping_class(values, calibration)
    mesh = rule_mesh_size_m(values, calibration=calibration)
    outside = outside_family(values, tolerance, calibration)
    period = first_period_s(values)
    n_load = load_time_scale_s(scene) / period
    if outside:  # the modes of the class's first level at this load, not the ratio alone
        levels = (_levels(damping, calibration) or _levels("undamped", calibration)
                  or rule_constants(calibration)["levels"])
        return RulePick(None, level_modes(levels[0], values, n_load), mesh, None,
                        f"outside the calibrated family ({outside})")
    level = level_for(tolerance, damping, calibration)
    if not holds_at(level, n_load):
        return RulePick(None, level_modes(level, values, n_load), mesh, None, (
            f"outside the calibrated family (n = t_load / T1 = {n_load:.3g} is outside the "
            f"[{level['n_load_min']:.3g}, {level['n_load_max']:.3g}] of level "
            f"{level['tolerance']:g}'s calibration scenes)"))
    modes = level_modes(level, values, n_load)
    per = steps_per_first_period(level, n_load, top_mode_ratio(level, values, n_load))
    if per is None:
        return RulePick(None, modes, mesh, None, (
            f"outside the calibrated family (n = t_load / T1 = {n_load:.3g} would need more "
            f"than {STEP_GRID[-1]} steps per first period)"))
    step = period / per
    return RulePick(step, modes, mesh, float(level["tolerance"]), (
        f"calibrated level {level['tolerance']:g} for {damping} links (make calibrate; "
        f"worst calibration error {level['worst_error']:.2g}): n = t_load / T1 = "
        f"{n_load:.3g} (load time scale {load_time_scale_s(scene):.3g} s), step T1 / {per:g} "
        f"= {step:.3g} s (first bending period T1 = {period:.4g} s), {modes} "
        f"in-plane modes ({_modes_text(level, n_load)}), mesh {_mesh_text(calibration)} = "
        f"{mesh * 1e3:.3g} mm"))


def _mesh_text(calibration: Calibration | None) -> str:
    mesh = rule_constants(calibration)["mesh"]
    return f"min({mesh['per_thickness']:g} t, L / {mesh['per_length']:g})"


def _modes_text(level: Mapping[str, Any], n_load: float) -> str:
    if "mode_cutoff_ratio" not in level:
        return "the level's count"
    text = f"every one up to {mode_cutoff(level, n_load):.3g} x the first"
    if level.get("mode_cutoff_load", 0.0) > 0:
        text += (f": the larger of {level['mode_cutoff_ratio']:g} and "
                 f"{level['mode_cutoff_load']:g} / n")
    return text


def fill_link_keys(scene: dict[str, dict[str, Any]], link: str, tolerance: float,
                   calibration: Calibration | None = None) -> dict[str, Any]:
    """Fill the ``"auto"`` modes and mesh size of ``scene[link]`` in place with the rule's
    (``calibration``'s; None: the bundled one); return what was filled (key -> value)."""
    values = scene[link]
    wanted = [key for key in LINK_KEYS if values.get(key) == AUTO]
    if not wanted:
        return {}
    if values.get("geometry") != "plate":  # never meshed: left "auto"
        return {}
    chosen = pick(scene, tolerance, link, calibration)
    chosen_modes, chosen_mesh = chosen.modes, chosen.mesh_size_m
    choice = {"modes": chosen_modes, "mesh_size_m": chosen_mesh}
    filled = {key: choice[key] for key in wanted}
    values.update(filled)
    return filled
