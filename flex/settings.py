"""Solver settings by model: what the ``"auto"`` values of ``[simulation]`` resolve to.

The bundled scene leaves ``simulation.step_s``, ``spectral_radius``, ``newton`` and
``newton_relative_tolerance`` to flex (``"auto"``); a number (or choice) written in a scene
or given with ``--set`` always wins. :func:`resolve_solver_settings` fills the ``"auto"`` keys
from ``flex/solver_defaults.toml``, the settings ``make tradeoff`` measured as fastest within
a certified accuracy:

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
resolved, :func:`flex.criteria.resolve_fidelity`); output the scene with numbers in place of
``"auto"`` and a :class:`SolverChoice` (which entry, why; stored with every result). A scene
without ``"auto"`` values is returned unchanged with ``None``.
"""

from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import Any

from .errors import SceneError
from .scene import Scene, check_steps

#: the ``[simulation]`` keys that may be ``"auto"``
AUTO_KEYS = ("step_s", "spectral_radius", "newton", "newton_relative_tolerance")
AUTO = "auto"
#: the ``--set`` pairs that leave every solver key to flex (what the bundled scene does)
AUTO_OVERRIDES = tuple((f"simulation.{key}", AUTO) for key in AUTO_KEYS)
#: what an uncertified flexible scene runs with, and what is known of it
FALLBACK = ("the rigid model's 40x smaller step, not certified for it (README \"Defaults\")")


@dataclass(frozen=True)
class SolverChoice:
    """Which entry of ``flex/solver_defaults.toml`` filled the ``"auto"`` keys, and why.

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


@cache
def solver_defaults() -> dict[str, dict[str, Any]]:
    """The entries of ``flex/solver_defaults.toml`` (read once)."""
    text = resources.files("flex").joinpath("solver_defaults.toml").read_text("utf-8")
    return tomllib.loads(text)


def has_auto(scene: Scene) -> bool:
    """Whether any ``[simulation]`` solver key of ``scene`` is ``"auto"``."""
    return any(scene["simulation"].get(key) == AUTO for key in AUTO_KEYS)


def _bending_omega(plate: dict[str, Any]) -> float:
    from .criteria import pinned_pinned_omega

    return pinned_pinned_omega(plate["length_m"], plate["thickness_m"],
                               plate["youngs_modulus_Pa"], plate["density_kg_per_m3"])


def choose_entry(scene: Scene) -> tuple[str, str]:
    """The entry (``"rigid"`` or ``"ffrf_coupler"``) for ``scene`` and the reason."""
    defaults = solver_defaults()
    crank, coupler = scene["crank"]["model"], scene["coupler"]["model"]
    if AUTO in (crank, coupler):
        raise ValueError('resolve model = "auto" links before the solver settings')
    if crank == "rigid" and coupler == "rigid":
        return "rigid", "rigid links"
    entry = defaults["ffrf_coupler"]
    level = entry["accuracy"]
    if coupler != "ffrf" or crank != "rigid":
        what = ("an FFRF crank" if crank == "ffrf" else f'coupler.model = "{coupler}"')
        return "rigid", f"no certified setting for {what}: {FALLBACK}"
    tolerance = scene["fidelity"]["tolerance"]
    if tolerance < level:
        return "rigid", (f"fidelity.tolerance = {tolerance:g} is finer than the FFRF coupler's "
                         f"certified {level:g}: {FALLBACK}")
    plate = entry["certified_plate"]
    differs = [f"{key} = {scene['coupler'][key]:g} (certified: {value:g})"
               for key, value in plate.items()
               if not math.isclose(scene["coupler"][key], value, rel_tol=1e-9)]
    if differs:
        return "rigid", (f"the coupler plate is not the certified one ({', '.join(differs)}): "
                         f"{FALLBACK}")
    omega = _bending_omega(scene["coupler"])
    return "ffrf_coupler", (f"FFRF coupler on a rigid crank, fidelity.tolerance = {tolerance:g} "
                            f">= {level:g}, the certified plate (first bending frequency "
                            f"{omega / (2 * math.pi):.4g} Hz)")


def resolve_solver_settings(scene: Scene) -> tuple[Scene, SolverChoice | None]:
    """``scene`` with its ``"auto"`` solver keys filled in (see module doc)."""
    if not has_auto(scene):
        return scene, None
    name, reason = choose_entry(scene)
    entry = solver_defaults()[name]
    resolved = copy.deepcopy(scene)
    filled = {}
    for key in AUTO_KEYS:
        if resolved["simulation"][key] == AUTO:
            resolved["simulation"][key] = filled[key] = entry[key]
    step, end = resolved["simulation"]["step_s"], resolved["simulation"]["end_time_s"]
    if step > end:  # a short run: one step over the whole span
        resolved["simulation"]["step_s"] = filled["step_s"] = end
    try:
        check_steps(resolved["simulation"])
    except SceneError as exc:
        raise SceneError(f"{exc} (step_s = \"auto\" chose {filled.get('step_s', step):g} s "
                         f"for {name}: set simulation.step_s explicitly)") from None
    return resolved, SolverChoice(name, entry["accuracy"], filled, reason)


def resolved_simulation(scene: Scene) -> dict[str, Any]:
    """The ``[simulation]`` section of ``scene`` with ``"auto"`` keys filled in.

    For code that needs the step before a run (its links must be concrete; an ``"auto"``
    link is taken as rigid here, which is what the fidelity probe runs).
    """
    if not has_auto(scene):
        return scene["simulation"]
    probe = copy.deepcopy(scene)
    for link in ("crank", "coupler"):
        if probe[link]["model"] == AUTO:
            probe[link]["model"] = "rigid"
    return resolve_solver_settings(probe)[0]["simulation"]


def pinned_overrides(entry: str = "rigid") -> list[str]:
    """``--set`` overrides that fix the solver keys to an entry's values.

    For studies whose numbers must not move with the defaults (a knob study varies one
    setting around a fixed base; a thesis figure needs the 1e-5 s grid).
    """
    values = solver_defaults()[entry]
    return [f"simulation.{key}={values[key]!r}" if not isinstance(values[key], str)
            else f'simulation.{key}="{values[key]}"' for key in AUTO_KEYS]
