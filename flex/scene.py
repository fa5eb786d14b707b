"""Scenes: TOML parameter sets with units in every key, validated before anything runs.

A scene is a nested ``dict`` ``{section: {key: value}}``. The accepted sections and keys,
with their types and ranges, are in :data:`SCHEMA`; every key ends in its unit (``_m``,
``_kg``, ``_deg``, ...) or is dimensionless. Scenes are loaded from TOML files (the bundled
parameter sets live in ``flex/scenes/``, e.g. ``cavezza2012``), changed by ``--set
section.key=value`` overrides, and checked by :func:`validate`, which refuses an unknown key,
a wrong type, a non-finite or out-of-range number, and a linkage that cannot assemble, with
one message naming the key and the accepted range.
"""

from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import tomli_w

from .errors import SceneError

Scene = dict[str, dict[str, Any]]


@dataclass(frozen=True)
class Field:
    """One scene key: its type, accepted range and meaning (unit is in the key name)."""

    kind: type | tuple[str, ...]  # float, int, bool, or a tuple of accepted strings
    doc: str
    minimum: float | None = None  # inclusive lower bound
    positive: bool = False  # strictly > 0
    maximum: float | None = None  # inclusive upper bound
    below: float | None = None  # strictly < below
    auto: bool = False  # "auto" accepted too: flex chooses (flex.settings)

    def accepted(self) -> str:
        """Human-readable accepted range, used in error messages."""
        text = self._accepted()
        return text + ' or "auto"' if self.auto else text

    def _accepted(self) -> str:
        if isinstance(self.kind, tuple):
            return "one of " + ", ".join(f'"{c}"' for c in self.kind)
        if self.kind is bool:
            return "true or false"
        parts = []
        if self.positive:
            parts.append("> 0")
        if self.minimum is not None:
            parts.append(f">= {self.minimum:g}")
        if self.below is not None:
            parts.append(f"< {self.below:g}")
        if self.maximum is not None:
            parts.append(f"<= {self.maximum:g}")
        name = "an integer" if self.kind is int else "a finite number"
        return name + (" " + " and ".join(parts) if parts else "")


_POS = {"kind": float, "positive": True}


def _plate_fields(link: str) -> dict[str, Field]:
    """The keys describing a link as a meshed plate (same for crank and coupler)."""
    return {
        "geometry": Field(("lumped", "plate"),
                          f"lumped: the {link}'s mass_kg/inertia_kgm2; plate: the plate of "
                          "the keys below (needed by ffrf and auto)"),
        "thickness_m": Field(doc="plate thickness, in the mechanism plane", **_POS),
        "width_m": Field(doc="plate width, out of the mechanism plane", **_POS),
        "youngs_modulus_Pa": Field(doc="Young's modulus", **_POS),
        "density_kg_per_m3": Field(doc="material density", **_POS),
        "poisson_ratio": Field(float, "Poisson's ratio", positive=True, below=0.5),
        "modes": Field(int, "fixed-interface Craig-Bampton modes", minimum=1, maximum=100),
        "mesh_size_m": Field(doc="netgen maximum element size", **_POS),
        "damping_ratio": Field(float, "modal damping ratio", minimum=0.0, below=1.0),
    }


SCHEMA: dict[str, dict[str, Field]] = {
    "crank": {
        "length_m": Field(doc="crank length L1 between joints A and B", **_POS),
        "mass_kg": Field(doc="crank mass (geometry = lumped)", **_POS),
        "inertia_kgm2": Field(doc="crank inertia about its centre of mass (lumped)", **_POS),
        "initial_angle_deg": Field(float, "crank angle at t = 0, from the slide line",
                                   minimum=-360.0, maximum=360.0),
        "model": Field(("rigid", "ffrf", "auto"),
                       "rigid body or floating-frame flexible body (plate geometry); auto: "
                       "rigid or ffrf (and modes) from the fitted criterion and "
                       "fidelity.tolerance"),
        **_plate_fields("crank"),
    },
    "coupler": {
        "length_m": Field(doc="coupler length L2 between joints B and C", **_POS),
        "mass_kg": Field(doc="coupler mass (geometry = lumped)", **_POS),
        "inertia_kgm2": Field(doc="coupler inertia about its centre of mass (lumped)", **_POS),
        "model": Field(("rigid", "ffrf", "nonlinear_fe", "auto"),
                       "rigid body, floating-frame flexible body, or fully nonlinear FE body "
                       "(accuracy reference, ~50x slower per step); auto: rigid or "
                       "ffrf (and modes) from the fitted criterion and fidelity.tolerance"),
        **_plate_fields("coupler"),
    },
    "wing": {
        "enabled": Field(bool, "weld a wing plate to the crank at A (sec. 6.4 application)"),
        "span_m": Field(doc="wing span, from the crank pivot A along the crank", **_POS),
        "chord_m": Field(doc="wing chord, in the mechanism plane across the span", **_POS),
        "thickness_m": Field(doc="wing thickness, out of the mechanism plane", **_POS),
        "density_kg_per_m3": Field(doc="wing material density", **_POS),
        "youngs_modulus_Pa": Field(doc="wing material Young's modulus", **_POS),
    },
    "slider": {
        "mass_kg": Field(doc="slider mass", **_POS),
        "inertia_kgm2": Field(doc="slider inertia about its centre of mass", **_POS),
        "offset_m": Field(float, "distance of the slide line from the crank pivot A"),
    },
    "drive": {
        "kind": Field(("spring", "constant_speed"), "what moves the mechanism"),
        "spring_stiffness_N_per_m": Field(float, "linear spring on the slider", minimum=0.0),
        "spring_preload_m": Field(float, "spring compression at t = 0", minimum=0.0),
        "spring_damping_Ns_per_m": Field(float, "viscous damper beside the spring",
                                         minimum=0.0),
        "crank_speed_rad_per_s": Field(float, "crank speed for kind = constant_speed"),
    },
    "simulation": {
        "end_time_s": Field(doc="simulated time span", **_POS),
        "step_s": Field(doc="fixed time step of the integrator (auto: by model, flex.settings)",
                        auto=True, **_POS),
        "output_step_s": Field(float, "interval of the stored samples (>= step_s; 0: every "
                               "step)", minimum=0.0),
        "spectral_radius": Field(float, "generalized-alpha spectral radius at infinity",
                                 minimum=0.0, maximum=1.0, auto=True),
        "integrator": Field(("generalized_alpha", "explicit_penalty"),
                            "implicit generalized-alpha with exact joints, or an explicit "
                            "Runge-Kutta method with penalty joints (rigid coupler, spring drive)"),
        "formulation": Field(("index3", "index2"),
                             "generalized_alpha: position-level constraints (index 3), or "
                             "velocity-level constraints (index 2, Newmark with the same "
                             "spectral_radius)"),
        "newton": Field(("full", "modified"),
                        "Newton iteration: Jacobian every iteration, or reused while it converges",
                        auto=True),
        "newton_relative_tolerance": Field(float, "Newton residual reduction per step "
                                           "(absolute tolerance: 1e-2 of it)", positive=True,
                                           maximum=1e-3, auto=True),
        "explicit_method": Field(("RK44", "RK67", "ExplicitMidpoint"),
                                 "explicit_penalty: fixed-step Runge-Kutta method (Exudyn's "
                                 "DOPRI5 needs its own step control and is not offered)"),
        "penalty_stiffness_N_per_m": Field(doc="explicit_penalty: stiffness of the joint springs "
                                           "at A, B, C and across the slide line", **_POS),
    },
    "fidelity": {
        "tolerance": Field(float, "model = \"auto\": accepted error of the rigid model "
                           "(dimensionless: deflection / L2, crank-angle and slider deviation "
                           "relative to their swing)", positive=True, maximum=0.5),
    },
}

DEFAULT_SCENE = "cavezza2012"


def bundled_scenes() -> list[str]:
    """Names of the parameter sets shipped in ``flex/scenes`` (without ``.toml``)."""
    folder = resources.files("flex.scenes")
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_scene(source: str | Path | None = None, overrides: list[str] | None = None) -> Scene:
    """Load, override and validate a scene.

    ``source`` is a TOML file path or the name of a bundled parameter set (default
    ``cavezza2012``). Sections and keys missing from a file are taken from the default
    parameter set, so a user scene needs to state only what it changes. ``overrides`` are
    ``"section.key=value"`` strings, the value in TOML syntax (``1e-3``, ``"ffrf"``,
    ``true``); a bare word is read as a string. Returns the validated scene.
    """
    scene = _read_toml(_scene_path(DEFAULT_SCENE), DEFAULT_SCENE)
    if source is not None and str(source) != DEFAULT_SCENE:
        path = Path(source)
        user = _read_toml(path if path.suffix == ".toml" or path.exists()
                          else _scene_path(str(source)), str(source))
        scene = merge(scene, user)
    if overrides:
        scene = apply_overrides(scene, overrides)
    validate(scene)
    return scene


def _scene_path(name: str) -> Path:
    path = Path(str(resources.files("flex.scenes").joinpath(f"{name}.toml")))
    if not path.exists():
        raise SceneError(f"scene '{name}' is neither a TOML file nor a bundled parameter set "
                         f"(bundled: {', '.join(bundled_scenes())})")
    return path


def _read_toml(path: Path, label: str) -> Scene:
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise SceneError(f"scene file '{label}' does not exist") from None
    except OSError as exc:
        raise SceneError(f"scene file '{label}' cannot be read: {exc.strerror}") from None
    try:
        parsed = tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise SceneError(f"scene file '{label}' is not UTF-8 text") from None
    except RecursionError:
        raise SceneError(f"scene file '{label}' is not valid TOML: nested too deeply") from None
    except ValueError as exc:  # TOMLDecodeError, or an integer of too many digits
        raise SceneError(f"scene file '{label}' is not valid TOML: {exc}") from None
    for section, table in parsed.items():
        if not isinstance(table, dict):
            raise SceneError(f"scene file '{label}': '{_name(section)}' must be a [section] "
                             f"table; "
                             f"accepted sections: {', '.join(SCHEMA)}")
    return parsed


def merge(base: Scene, changes: Scene) -> Scene:
    """Return ``base`` with the keys of ``changes`` replacing its own (section by section)."""
    merged = copy.deepcopy(base)
    for section, table in changes.items():
        if not isinstance(table, dict):
            raise SceneError(f"'{_name(section)}' must be a [section] table; "
                             f"accepted sections: {', '.join(SCHEMA)}")
        merged.setdefault(section, {}).update(copy.deepcopy(table))
    return merged


def apply_overrides(scene: Scene, overrides: list[str]) -> Scene:
    """Apply ``"section.key=value"`` overrides (TOML values; bare words are strings)."""
    changes: Scene = {}
    for item in overrides:
        if "=" not in item or "." not in item.split("=", 1)[0]:
            raise SceneError(f"--set {_show(item)}: expected section.key=value, "
                             f"e.g. coupler.thickness_m=0.003")
        dotted, text = item.split("=", 1)
        section, key = (part.strip() for part in dotted.split(".", 1))
        changes.setdefault(section, {})[key] = _parse_value(text.strip())
    return merge(scene, changes)


def _parse_value(text: str) -> Any:
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except (ValueError, RecursionError):  # not TOML (or absurdly long/deep): a bare word
        return text


def validate(scene: Scene) -> None:
    """Raise :class:`SceneError` naming the first problem; return ``None`` if valid.

    Checks: known sections and keys, every key present, types, finiteness, ranges, and the
    geometry: the crank must be able to turn (``L1 + |offset| < L2``), the slider's step
    settings consistent, and FFRF couplers need plate geometry.
    """
    for section, table in scene.items():
        if section not in SCHEMA:
            raise SceneError(f"unknown section [{_name(section)}]; accepted sections: "
                             f"{', '.join(SCHEMA)}")
        for key, value in table.items():
            if key not in SCHEMA[section]:
                raise SceneError(f"unknown key {_name(section)}.{_name(key)}; accepted keys in "
                                 f"[{section}]: "
                                 f"{', '.join(SCHEMA[section])}")
            _check_value(f"{section}.{key}", SCHEMA[section][key], value)
    for section, fields in SCHEMA.items():
        for key in fields:
            if key not in scene.get(section, {}):
                raise SceneError(f"missing key {section}.{key} ({fields[key].doc})")
    _check_geometry(scene)


def _check_value(name: str, field: Field, value: Any) -> None:
    if field.auto and value == "auto":
        return
    if isinstance(field.kind, tuple):
        if not isinstance(value, str) or value not in field.kind:
            raise SceneError(f"{name} = {_show(value)}: must be {field.accepted()}")
        return
    if field.kind is bool:
        if not isinstance(value, bool):
            raise SceneError(f"{name} = {_show(value)}: must be true or false")
        return
    is_number = isinstance(value, int | float) and not isinstance(value, bool)
    if field.kind is int and not (isinstance(value, int) and not isinstance(value, bool)):
        raise SceneError(f"{name} = {_show(value)}: must be {field.accepted()}")
    if not is_number or not _finite(value):
        raise SceneError(f"{name} = {_show(value)}: must be {field.accepted()}")
    if ((field.positive and not value > 0)
            or (field.minimum is not None and value < field.minimum)
            or (field.maximum is not None and value > field.maximum)
            or (field.below is not None and not value < field.below)):
        raise SceneError(f"{name} = {_show(value)}: must be {field.accepted()}")


def _finite(value: float) -> bool:
    try:
        return math.isfinite(value)
    except OverflowError:  # an integer beyond the float range
        return False


def _show(value: Any, limit: int = 60) -> str:
    """``repr(value)`` shortened to one line: safe inside a one-line error message."""
    try:
        text = repr(value)
    except ValueError:  # an integer beyond Python's digit limit for str()
        text = "<an integer of thousands of digits>"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _name(text: str, limit: int = 60) -> str:
    """A user-written section or key name, control characters escaped, shortened."""
    text = text if text.isprintable() else repr(text)[1:-1]
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _check_geometry(scene: Scene) -> None:
    crank_m = scene["crank"]["length_m"]
    coupler_m = scene["coupler"]["length_m"]
    offset_m = scene["slider"]["offset_m"]
    if crank_m >= coupler_m:
        raise SceneError(f"linkage cannot assemble: crank.length_m = {crank_m:g} must be "
                         f"shorter than coupler.length_m = {coupler_m:g}")
    if crank_m + abs(offset_m) >= coupler_m:
        raise SceneError(f"linkage cannot assemble over a full crank turn: slider.offset_m = "
                         f"{offset_m:g} puts the slide line off the reachable range; need "
                         f"|offset_m| < coupler.length_m - crank.length_m = "
                         f"{coupler_m - crank_m:g}")
    check_steps(scene["simulation"])
    for link in ("crank", "coupler"):
        _check_link(link, scene[link])
    if scene["crank"]["model"] == "ffrf" and scene["drive"]["kind"] == "constant_speed":
        raise SceneError('crank.model = "ffrf" needs drive.kind = "spring": the constant-speed '
                         "drive constrains the rotation coordinate of a rigid crank, which a "
                         'flexible crank\'s floating frame does not have; accepted: "rigid"')
    coupler = scene["coupler"]
    if coupler["model"] == "nonlinear_fe" and coupler["damping_ratio"] != 0:
        raise SceneError(f"coupler.damping_ratio = {coupler['damping_ratio']:g}: "
                         'coupler.model = "nonlinear_fe" has no damping model; accepted: 0')
    if scene["simulation"]["integrator"] == "explicit_penalty" and (
            coupler["model"] != "rigid" or scene["crank"]["model"] != "rigid"
            or scene["drive"]["kind"] != "spring"):
        raise SceneError('simulation.integrator = "explicit_penalty" needs crank.model and '
                         'coupler.model = "rigid" and drive.kind = "spring" (Exudyn\'s explicit '
                         "solvers take no algebraic constraints: the flexible bodies' "
                         "Euler-parameter frames and the crank-speed constraint have them); "
                         'accepted: "generalized_alpha"')


def check_steps(sim: dict[str, Any]) -> None:
    """Step, output interval and step count; an ``"auto"`` step is checked once resolved."""
    if sim["step_s"] == "auto":
        return
    if sim["step_s"] > sim["end_time_s"]:
        raise SceneError(f"simulation.step_s = {sim['step_s']:g} must be <= "
                         f"simulation.end_time_s = {sim['end_time_s']:g}")
    if 0 < sim["output_step_s"] < sim["step_s"] * (1 - 1e-9):
        raise SceneError(f"simulation.output_step_s = {sim['output_step_s']:g} must be >= "
                         f"simulation.step_s = {sim['step_s']:g} (or 0: every step)")
    steps = sim["end_time_s"] / sim["step_s"]
    if steps > 5e7:
        raise SceneError(f"simulation needs {steps:.3g} steps (end_time_s / step_s); "
                         f"accepted: at most 5e7")


def _check_link(link: str, values: dict[str, Any]) -> None:
    """A flexible (or auto) link needs plate geometry, and the plate must fit its length."""
    model = values["model"]
    if model in ("ffrf", "nonlinear_fe") and values["geometry"] != "plate":
        raise SceneError(f'{link}.model = "{model}" needs {link}.geometry = "plate" (the '
                         "flexible body is meshed from the plate's dimensions)")
    if model == "auto" and values["geometry"] != "plate" and link == "coupler":
        raise SceneError('coupler.model = "auto" needs coupler.geometry = "plate" (the '
                         "criterion needs the plate's bending frequency; a lumped coupler has "
                         'no stiffness): use coupler.model = "rigid" for a lumped coupler')
    if values["geometry"] == "plate" and values["thickness_m"] >= values["length_m"]:
        raise SceneError(f"{link}.thickness_m = {values['thickness_m']:g} must be smaller "
                         f"than {link}.length_m = {values['length_m']:g}")


def to_toml(scene: Scene) -> str:
    """The fully resolved scene as TOML text (what ``python -m flex scene`` prints)."""
    return tomli_w.dumps(scene)


def plate_mass_properties(scene: Scene, link: str = "coupler") -> tuple[float, float]:
    """Mass [kg] and in-plane inertia about the centre of mass [kg m^2] of a link.

    ``link`` is ``"coupler"`` or ``"crank"``. Lumped geometry returns the scene's
    ``mass_kg`` and ``inertia_kgm2``; plate geometry computes them from length x thickness x
    width and density (a cuboid: m (L^2 + t^2)/12).
    """
    values = scene[link]
    if values["geometry"] == "lumped":
        return values["mass_kg"], values["inertia_kgm2"]
    length_m, thickness_m = values["length_m"], values["thickness_m"]
    mass_kg = values["density_kg_per_m3"] * length_m * thickness_m * values["width_m"]
    return mass_kg, mass_kg * (length_m**2 + thickness_m**2) / 12.0
