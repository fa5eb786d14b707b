"""Solver settings by model: what the ``"auto"`` values of ``[simulation]`` resolve to.

The bundled scene leaves ``simulation.step_s``, ``spectral_radius``, ``newton`` and
``newton_relative_tolerance`` to flex (``"auto"``); a number (or choice) written in a scene
or given with ``--set`` always wins. :func:`resolve_solver_settings` fills the ``"auto"`` keys
from ``solver_defaults.toml`` of a calibration (:mod:`flex.config.calibration`: the bundled
``flex/config/solver_defaults.toml``, or one passed in), the settings ``make tradeoff``
measured as fastest within a certified accuracy:

- ``ffrf_coupler`` (h = 4e-4 s, modified Newton): an FFRF coupler on a rigid crank, when the
  scene's ``fidelity.tolerance`` is at least the entry's certified ``accuracy`` (1 %) and the
  plate is the one it was certified on (the bundled 1 mm steel coupler: same length,
  thickness, width and material; mesh and modes are the scene's);
- ``rigid`` (h = 1e-5 s, full Newton): everything else -- rigid links, and flexible links for
  which no setting is certified (other plates, finer tolerances, FFRF cranks, the nonlinear
  FE coupler): a 40x smaller step than the certified FFRF one, but not certified for them
  (:data:`FALLBACK`). Neither direction transfers: thinner plates fail Newton at 4e-4 s
  (0.3 mm at the second step, 0.5 mm at 21 ms: they deflect more), and at 10 mm the same
  fraction of the first bending period (4e-5 s) erred by 2.4 % in make tradeoff.

Contract: input a validated scene whose links are concrete (``model = "auto"`` already
resolved, :func:`flex.fidelity.auto.resolve`); output the scene with numbers in place
of
``"auto"`` and a :class:`SolverChoice` (which entry, why; stored with every result). A scene
without ``"auto"`` values is returned unchanged with ``None``.

:func:`check_concrete` refuses, before anything is built, a concrete scene that cannot run or
would mean nothing (step count, irregular samples, an aliased crank, meshed plates that mean
nothing or do not fit this machine); :func:`flex.fidelity.auto.check` applies it to what a
scene's ``"auto"`` values may become.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from flex.base.errors import SceneError
from flex.config.calibration import Calibration, calibration_of
from flex.config.ffrf_rule import RulePick, pick, rule_constants
from flex.config.knobs import Knob, auto_value, exact_beam_settings, knobs_of
from flex.config.tolerance import Tolerance
from flex.data.fields import AUTO
from flex.data.scene import (
    BUILTIN_LINK_SCHEMAS,
    LINKS,
    Scene,
    check_meshed_plate,
    link_model,
    model_names,
)
from flex.data.steps import check_drive_steps, check_steps

#: the ``[simulation]`` keys that may be ``"auto"``
AUTO_KEYS = ("step_s", "spectral_radius", "newton", "newton_relative_tolerance")

#: the ``--set`` pairs that leave every solver key to flex (what the bundled scene does)
AUTO_OVERRIDES = tuple((f"simulation.{key}", AUTO) for key in AUTO_KEYS)
#: what an uncertified flexible scene runs with, and what is known of it
#: a model's ``settings`` (:attr:`flex.data.scene.LinkSchema.settings`): the calibrated FFRF
#: rule, the exact beam's measured table
FFRF_RULE, EXACT_BEAM_STEP = "ffrf_rule", "exact_beam"
FALLBACK = ("the flexible fallback (the rigid model's 40x smaller step with modified Newton), "
            "not certified for it")


@dataclass(frozen=True)
class SolverChoice:
    """Which entry of the solver defaults (``solver_defaults.toml``) filled the ``"auto"``
    keys, and why.

    ``entry``: ``"rigid"`` or ``"ffrf_coupler"``; ``accuracy``: the relative error the entry
    is certified to on the model it was measured on (dimensionless); ``keys``: the keys it
    filled with their values; ``reason``: one sentence.
    """

    entry: str
    accuracy: float
    keys: dict[str, Any]
    reason: str

    def attrs(self) -> dict[str, Any]:
        """Result-file attributes (``solver_defaults_*``)."""
        return {"solver_defaults_entry": self.entry,
                "solver_defaults_accuracy": self.accuracy,
                "solver_defaults_keys": ", ".join(f"{k} = {v!r}" for k, v in self.keys.items()),
                "solver_defaults_reason": self.reason}


def solver_defaults(calibration: Calibration | None = None) -> Mapping[str, Mapping[str, Any]]:
    """The entries of ``calibration``'s ``solver_defaults.toml`` (None: the bundled
    calibration's, ``flex/config/solver_defaults.toml``; :mod:`flex.config.calibration`)."""
    return calibration_of(calibration).solver_defaults


def has_auto(scene: Scene) -> bool:
    """Whether any ``[simulation]`` solver key of ``scene`` is ``"auto"``."""
    return any(scene["simulation"].get(key) == AUTO for key in AUTO_KEYS)


def has_auto_link_keys(scene: Scene, *,
                       link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> bool:
    """Whether a link knob of a link's concrete model is ``"auto"`` (its modes, mesh size or
    elements: :mod:`flex.config.knobs`)."""
    return any(_auto_knobs(scene, link, link_models) for link in LINKS)


def _auto_knobs(scene: Scene, link: str, link_models: Mapping[str, Any]) -> list[Knob]:
    """The knobs of ``link``'s concrete model left ``"auto"`` (none for an ``"auto"`` or
    unknown model)."""
    model = scene[link]["model"]
    if model not in link_models or link not in link_models[model].links:
        return []
    return [knob for knob in knobs_of(link_models[model])
            if knob.value(scene, link) == AUTO]


def resolve_link_keys(scene: Scene, calibration: Calibration | None = None, *,
                      link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS
                      ) -> tuple[Scene, dict[str, Any]]:
    """``scene`` (a copy) with each link's ``"auto"`` knobs filled from ``fidelity.tolerance``
    (:func:`flex.config.knobs.auto_value`: an FFRF link's modes and mesh by ``calibration``'s
    rule, None: the bundled one; a beam's elements by its table; a link whose model does not
    read a knob keeps its ``"auto"``), and what was filled (``"coupler.modes"`` -> value)."""
    resolved = copy.deepcopy(scene)
    filled: dict[str, Any] = {}
    for link in LINKS:
        for knob in _auto_knobs(scene, link, link_models):
            resolved[link][knob.link_key()] = filled[knob.scene_key(link)] = auto_value(
                knob, scene, link, calibration)
    return resolved, filled


def choose_entry(scene: Scene, calibration: Calibration | None = None, *,
                 link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS
                 ) -> tuple[str, str, RulePick | None]:
    """The entry (``"rigid"``, ``"ffrf_rule"`` or ``"flexible_fallback"``) for ``scene``,
    the reason, and the rule's pick (``ffrf_rule`` only). ``link_models``: the registry of
    the scene's link models (their ``rigid`` flags and ``settings`` choose)."""
    if AUTO in (scene["crank"]["model"], scene["coupler"]["model"]):
        raise ValueError('resolve model = "auto" links before the solver settings')
    crank, coupler = (link_model(link, scene[link], link_models) for link in ("crank",
                                                                              "coupler"))
    if crank.rigid and coupler.rigid:
        return "rigid", "rigid links", None
    if not (coupler.settings == FFRF_RULE and crank.rigid):  # the rule's: on a rigid crank
        what = ("an FFRF crank" if crank.settings == FFRF_RULE
                else f'coupler.model = "{coupler.name}"')
        return "flexible_fallback", f"no calibrated rule for {what}: {FALLBACK}", None
    tolerance = Tolerance.of(scene).relative
    chosen = pick(scene, tolerance, calibration=calibration)
    if chosen.step_s is None:
        return "flexible_fallback", f"FFRF coupler {chosen.reason}: {FALLBACK}", None
    reason = f"FFRF coupler on a rigid crank at fidelity.tolerance = {tolerance:g}: {chosen.reason}"
    if scene["coupler"]["modes"] > chosen.modes:
        reason += (f"; coupler.modes = {scene['coupler']['modes']} is more than the rule's "
                   f"{chosen.modes}: the step is calibrated for {chosen.modes} (modes the step "
                   f"does not resolve can move the peak, set simulation.step_s smaller)")
    return "ffrf_rule", reason, chosen


def finest_certified_accuracy(calibration: Calibration | None = None) -> tuple[float, str]:
    """The smallest relative error any model's settings are certified to (the solver
    defaults' ``accuracy`` and the FFRF rule's calibrated levels), and where it comes from."""

    # the fallback's and the rule entry's "accuracy" are placeholders, not certifications
    found = [(float(entry["accuracy"]), f"solver defaults entry '{name}'")
             for name, entry in solver_defaults(calibration).items()
             if "accuracy" in entry and name not in ("flexible_fallback", "ffrf_rule")]
    found += [(float(level["tolerance"]), "the FFRF settings rule's finest level")
              for level in rule_constants(calibration)["levels"]]
    return min(found)


def _beam_step(scene: Scene, link_models: Mapping[str, Any]) -> bool:
    """Whether the run's step is the exact beam's (a beam coupler on a link that is none)."""
    rules = {link: link_model(link, scene[link], link_models).settings for link in LINKS}
    return rules["coupler"] == EXACT_BEAM_STEP and rules["crank"] != EXACT_BEAM_STEP


def reads_tolerance(scene: Scene, *, link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> bool:
    """Whether ``fidelity.tolerance`` is read: by an ``auto`` link or spring model (validated:
    only with a spring drive), by ``"auto"`` solver keys choosing the FFRF coupler's entry
    (:func:`choose_entry`), or by an exact beam coupler's ``"auto"`` step or elements
    (:func:`flex.config.knobs.exact_beam_settings`)."""
    if AUTO in (scene["crank"]["model"], scene["coupler"]["model"]) \
            or scene["drive"]["spring_model"] == AUTO:
        return True
    if not link_model("crank", scene["crank"], link_models).rigid:
        return False
    coupler = link_model("coupler", scene["coupler"], link_models).settings
    if coupler == EXACT_BEAM_STEP:  # its step and elements (exact_beam_settings)
        return has_auto(scene) or bool(_auto_knobs(scene, "coupler", link_models))
    return has_auto(scene) and coupler == FFRF_RULE


def tolerance_beyond_reach(scene: Scene, calibration: Calibration | None = None, *,
                           link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> str:
    """Why ``fidelity.tolerance`` asks for more than flex can certify ("" if it does not, or
    if no ``auto`` choice reads it): a tolerance below :func:`finest_certified_accuracy`
    is met by no model flex has measured (``auto`` then takes its most accurate model, up to
    the nonlinear FE coupler, whose own error is not known to be that small)."""
    tolerance = Tolerance.of(scene).relative
    finest, source = finest_certified_accuracy(calibration)
    if tolerance >= finest * (1 - 1e-9) or not reads_tolerance(scene,
                                                                link_models=link_models):
        return ""
    return (f"fidelity.tolerance = {tolerance:g} is beyond reach: no model's settings are "
            f"certified finer than {finest:g} ({source}); \"auto\" takes its most accurate "
            f"choice (up to the nonlinear FE coupler, slow and uncertified), which is not "
            f"known to meet it; accepted: a tolerance >= {finest:g} for a certified result")


def whole_steps_s(step_s: float, end_time_s: float, multiple: int) -> float:
    """The largest step [s] at most ``step_s`` that divides ``end_time_s`` into a whole
    number of ``multiple`` steps."""
    groups = max(1, math.ceil(end_time_s / (multiple * step_s) - 1e-9))
    return end_time_s / (multiple * groups)


def resolve_solver_settings(scene: Scene, calibration: Calibration | None = None, *,
                            link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS
                            ) -> tuple[Scene, SolverChoice | None]:
    """``scene`` with its ``"auto"`` solver and link keys filled in (see module doc), from
    ``calibration``'s solver defaults and rule (None: the bundled calibration);
    ``link_models``: the registry of its link models."""
    if not (has_auto(scene) or has_auto_link_keys(scene, link_models=link_models)):
        return scene, None
    resolved, filled = resolve_link_keys(scene, calibration, link_models=link_models)
    name, reason, chosen = choose_entry(resolved, calibration, link_models=link_models)
    entry = solver_defaults(calibration)[name]
    values = dict(entry)
    accuracy = entry["accuracy"]
    if chosen is not None:  # the end time a whole number of 4 steps: the error estimate's
        # companions at 2 and 4 steps then end on it (a half-step companion costs 2 runs)
        values["step_s"], accuracy = whole_steps_s(
            chosen.step_s, float(resolved["simulation"]["end_time_s"]), 4), chosen.level
        reason += (f"; step rounded down to {values['step_s']:.6g} s, a whole number of 4 "
                   f"steps in the end time")
    elif name == "flexible_fallback" and _beam_step(resolved, link_models):
        tolerance = Tolerance.of(resolved).relative
        values["step_s"] = exact_beam_settings(tolerance)[1]
        reason = (f"exact beam coupler at fidelity.tolerance = {tolerance:g}: its first guess, "
                  f"step {values['step_s']:g} s (and its elements; flex.config.knobs."
                  f"EXACT_BEAM_SETTINGS, measured on the 0.5-1 mm thesis plates, not calibrated "
                  f"over a family as the FFRF rule is: the run's error budget certifies what it "
                  f"achieved), the flexible solver settings otherwise")
    for key in AUTO_KEYS:
        if resolved["simulation"][key] == AUTO:
            resolved["simulation"][key] = filled[key] = values[key]
    step, end = resolved["simulation"]["step_s"], resolved["simulation"]["end_time_s"]
    if step > end:  # a short run: one step over the whole span
        resolved["simulation"]["step_s"] = filled["step_s"] = end
    try:
        check_steps(resolved["simulation"])
    except SceneError as exc:
        raise SceneError(f"{exc} (step_s = \"auto\" chose {filled.get('step_s', step):g} s "
                         f"for {name}: set simulation.step_s explicitly)") from None
    return resolved, SolverChoice(name, accuracy, filled, reason)


def resolved_simulation(scene: Scene, calibration: Calibration | None = None, *,
                        link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS
                        ) -> dict[str, Any]:
    """The ``[simulation]`` section of ``scene`` with ``"auto"`` keys filled in.

    For code that needs the step before a run (its links must be concrete; an ``"auto"``
    link is taken as rigid here, which is what the fidelity probe runs).
    """
    if not has_auto(scene):
        return scene["simulation"]
    probe = copy.deepcopy(scene)
    for link in LINKS:
        if probe[link]["model"] == AUTO:
            probe[link]["model"] = model_names(link, link_models, rigid=True)[0]
    return resolve_solver_settings(probe, calibration,
                                   link_models=link_models)[0]["simulation"]


#: the coupler's modes and mesh size the bundled scene had before they became "auto" (6
#: fixed-interface modes, 2 mm): pinned with the solver keys, so a pinned study's numbers do not
#: move with the rule (flex.config.ffrf_rule)
PINNED_COUPLER_DISCRETIZATION = ("coupler.modes=6", "coupler.mesh_size_m=0.002")


def pinned_overrides(entry: str = "rigid", calibration: Calibration | None = None
                     ) -> list[str]:
    """``--set`` overrides that fix the solver keys to an entry's values (and the coupler's
    modes and mesh size to :data:`PINNED_COUPLER_DISCRETIZATION`).

    For studies whose numbers must not move with the defaults (a knob study varies one
    setting around a fixed base; a thesis figure needs the 1e-5 s grid).
    """
    values = solver_defaults(calibration)[entry]
    return [f"simulation.{key}={values[key]!r}" if not isinstance(values[key], str)
            else f'simulation.{key}="{values[key]}"' for key in AUTO_KEYS] + list(
        PINNED_COUPLER_DISCRETIZATION)


def check_concrete(scene: Scene, choice: SolverChoice | None = None, *,
                   link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> None:
    """Refuse, before anything is built, meshed or simulated, a concrete scene (no
    ``"auto"`` left: :func:`flex.fidelity.auto.resolve`) that cannot run or whose result
    would mean nothing; return None when it can run. Takes milliseconds. ``choice``: the
    solver choice that filled its ``"auto"`` keys (named in a refusal of its step).

    - steps (:func:`flex.data.scene.check_steps`): step <= end time, at most 5e7 steps, output
      interval 0 or an integer multiple of the step;
    - a constant-speed crank turns at most 0.1 rad per step and pi/4 per stored sample
      (:func:`flex.data.scene.check_drive_steps`);
    - every plate that will be meshed makes sense as a meshed link and fits this machine
      (:func:`flex.data.scene.check_meshed_plate`, with the mesh estimate in the message).
    """
    for link in LINKS:
        values = scene[link]
        if values["model"] == AUTO or _auto_knobs(scene, link, link_models):  # a link keeps
            # the "auto"s of the knobs its model does not read
            raise ValueError(f"{link}: resolve its \"auto\" values first "
                             f"(flex.fidelity.auto.resolve)")
        check_meshed_plate(link, values, link_models)
    if has_auto(scene) or scene["drive"]["spring_model"] == AUTO:
        raise ValueError('[simulation] or drive.spring_model: resolve its "auto" values first '
                         "(flex.fidelity.auto.resolve)")
    check_steps(scene["simulation"])
    try:
        check_drive_steps(scene)
    except SceneError as exc:
        if choice is None or "step_s" not in choice.keys:
            raise
        raise SceneError(f"{exc} (step_s = \"auto\" chose {choice.keys['step_s']:g} s for "
                         f"{choice.entry}: set simulation.step_s explicitly)") from None


