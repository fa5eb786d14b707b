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
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import tomli_w

from flex.base.errors import SceneError
from flex.base.progress import duration_text

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
    auto: bool = False  # "auto" accepted too: flex chooses (flex.config.settings)
    #: value of a key the bundled parameter set does not state (a flex model choice added
    #: after it was written, not a thesis value): :func:`default_scene` fills it in
    default: Any = None

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
#: a material density [kg/m^3] that describes a solid: at least the lightest solids' (silica
#: aerogels, 1-3 kg/m^3; the plate's FE mass matrix loses definiteness far below: the
#: eigen-solve failed at 1e-3), at most 4 x the densest element's (osmium, 22.6e3; it failed
#: at 1e30)
_DENSITY = {"kind": float, "minimum": 1.0, "maximum": 1e5}


def _plate_fields(link: str) -> dict[str, Field]:
    """The keys describing a link as a meshed plate (same for crank and coupler)."""
    return {
        "geometry": Field(("lumped", "plate"),
                          f"lumped: the {link}'s mass_kg/inertia_kgm2; plate: the plate of "
                          "the keys below (needed by ffrf and auto)"),
        "thickness_m": Field(doc="plate thickness, in the mechanism plane", **_POS),
        "width_m": Field(doc="plate width, out of the mechanism plane", **_POS),
        "youngs_modulus_Pa": Field(doc="Young's modulus", **_POS),
        "density_kg_per_m3": Field(doc="material density (a solid's)", **_DENSITY),
        "poisson_ratio": Field(float, "Poisson's ratio", positive=True, below=0.5),
        "modes": Field(int, "fixed-interface Craig-Bampton modes (auto: from "
                       "fidelity.tolerance, flex.config.ffrf_rule)", minimum=1, maximum=100,
                       auto=True),
        "mode_selection": Field(("in_plane", "all"),
                                "which modes the reduction keeps: in_plane (the modes a planar "
                                "mechanism loads, symmetric about its plane) or all (the "
                                "lowest of any kind)"),
        "mesh_size_m": Field(doc="netgen maximum element size (auto: min(2 t, L / 16), "
                             "flex.config.ffrf_rule)", auto=True, **_POS),
        "damping_ratio": Field(float, "modal damping ratio", minimum=0.0, below=1.0),
        "geometric_stiffness": Field(bool, "model = ffrf: soften the bending modes under the "
                                     "link's own axial force (flex.bodies.geometric_stiffness; "
                                     "false: the linear FFRF body, for comparison)",
                                     default=True),
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
        "spring_model": Field(("massless", "chain", "auto"),
                              "massless: one spring on the slider; chain: the coil's mass as "
                              "spring_segments springs with lumped masses between "
                              "(flex.dynamics.builder.spring_chain); auto: massless or chain "
                              "(and its segments) from the massless spring's error predicted "
                              "by a rigid probe run and fidelity.tolerance "
                              "(flex.fidelity.spring_choice)"),
        "spring_mass_kg": Field(doc="mass of the spring's active coils (spring_model = chain)",
                                **_POS),
        "spring_segments": Field(int, "spring_model = chain: segments of the coil (its "
                                 "lumped masses: segments - 1 inside, half a segment's on "
                                 "the slider)", minimum=1, maximum=256),
    },
    "simulation": {
        "end_time_s": Field(doc="simulated time span", **_POS),
        "step_s": Field(doc="fixed time step of the integrator (auto: by model, "
                            "flex.config.settings)",
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
        "newton": Field(("full", "modified", "jacobian_per_step"),
                        "Newton iteration: Jacobian every iteration, reused while it converges "
                        "(modified), or computed once per step and reused within it",
                        auto=True),
        "error_estimate": Field(bool, "estimate the run's own step error on its headline "
                                      "quantities with a companion run at twice (or half) the "
                                      "step (false: no companion, for speed)"),
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
    folder = resources.files("flex.data.scenes")
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_scene(source: str | Path | None = None, overrides: list[str] | None = None) -> Scene:
    """Load, override and validate a scene.

    ``source`` is a TOML file path or the name of a bundled parameter set (default
    ``cavezza2012``). Sections and keys missing from a file are taken from the default
    parameter set, so a user scene needs to state only what it changes. ``overrides`` are
    ``"section.key=value"`` strings, the value in TOML syntax (``1e-3``, ``"ffrf"``,
    ``true``); a bare word is read as a string. Returns the validated scene.
    """
    scene = default_scene()
    user = read_source(source)
    if user is not None:
        scene = merge(scene, user)
    if overrides:
        scene = apply_overrides(scene, overrides)
    validate(scene)
    return scene


def default_scene() -> Scene:
    """The bundled default parameter set (:data:`DEFAULT_SCENE`), as read from its file,
    with the schema default of every key the file does not state (:attr:`Field.default`)."""
    scene = _read_toml(_scene_path(DEFAULT_SCENE), DEFAULT_SCENE)
    for section, fields in SCHEMA.items():
        for key, field in fields.items():
            if field.default is not None:
                scene.setdefault(section, {}).setdefault(key, field.default)
    return scene


def read_source(source: str | Path | None) -> Scene | None:
    """The tables of a user scene file or bundled parameter set, as written (not merged,
    not validated); None for no source or the default parameter set."""
    if source is None or str(source) == DEFAULT_SCENE:
        return None
    path = Path(source)
    return _read_toml(path if path.suffix == ".toml" or path.exists()
                      else _scene_path(str(source)), str(source))


def _scene_path(name: str) -> Path:
    path = Path(str(resources.files("flex.data.scenes").joinpath(f"{name}.toml")))
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
    try:  # a UTF-8 byte-order mark (some Windows editors write one) is not content
        parsed = tomllib.loads(data.decode("utf-8").removeprefix("\ufeff"))
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
        section, key, value = parse_override(item)
        changes.setdefault(section, {})[key] = value
    return merge(scene, changes)


def derived_scenes(scene: Scene, overrides_by_name: Mapping[str, list[str]]) -> dict[str, Scene]:
    """One validated scene per name: ``scene`` with that name's overrides (a study's cases
    declared as data); raises SceneError naming the first that does not validate."""
    out = {name: apply_overrides(scene, overrides)
           for name, overrides in overrides_by_name.items()}
    for derived in out.values():
        validate(derived)
    return out


def parse_override(item: str) -> tuple[str, str, Any]:
    """``"section.key=value"`` -> ``(section, key, value)`` (value in TOML syntax; a bare
    word is a string); SceneError if it is not of that form."""
    if "=" not in item or "." not in item.split("=", 1)[0]:
        raise SceneError(f"--set {_show(item)}: expected section.key=value, "
                         f"e.g. coupler.thickness_m=0.003")
    dotted, text = item.split("=", 1)
    section, key = (part.strip() for part in dotted.split(".", 1))
    return section, key, _parse_value(text.strip())


def _parse_value(text: str) -> Any:
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except (ValueError, RecursionError):  # not TOML (or absurdly long/deep): a bare word
        return text


def validate(scene: Scene) -> None:
    """Raise :class:`SceneError` naming the first problem; return ``None`` if valid.

    Checks: known sections and keys, every key present, types, finiteness, ranges, and the
    geometry: the crank must be able to turn (``L1 + |offset| < L2``), the step settings
    consistent (an explicit step: :func:`check_steps`, :func:`check_drive_steps`; an
    ``"auto"`` one is checked once resolved, :func:`flex.fidelity.auto.check`), FFRF
    couplers need plate geometry, and plates that will be meshed must make sense and fit
    this machine (:func:`check_meshed_plate`).
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
    check_drive_steps(scene)
    for link in ("crank", "coupler"):
        _check_link(link, scene[link])
    if scene["crank"]["model"] == "ffrf" and scene["drive"]["kind"] == "constant_speed":
        raise SceneError('crank.model = "ffrf" needs drive.kind = "spring": the constant-speed '
                         "drive constrains the rotation coordinate of a rigid crank, which a "
                         'flexible crank\'s floating frame does not have; accepted: "rigid"')
    if scene["crank"]["model"] == "auto" and scene["drive"]["kind"] != "spring":
        raise SceneError('crank.model = "auto" needs drive.kind = "spring": auto analyses the '
                         "crank as a flexible plate in the mechanism, and a flexible crank needs "
                         'the spring drive; accepted with a constant-speed drive: "rigid"')
    if scene["drive"]["spring_model"] == "auto" and scene["drive"]["kind"] != "spring":
        raise SceneError('drive.spring_model = "auto" needs drive.kind = "spring" (a '
                         "constant-speed drive has no spring to choose a model for); "
                         'accepted: "massless" or "chain"')
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


def _check_link(link: str, values: dict[str, Any]) -> None:
    """A flexible (or auto) link needs plate geometry, and the plate must fit its length;
    a plate that will be meshed must make sense as a meshed link (:func:`check_meshed_plate`).
    """
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
    check_meshed_plate(link, values)


# ------------------------------------------------------------------------------------------
# meshed plates: what makes sense, and what this machine can mesh
# ------------------------------------------------------------------------------------------
#: largest mesh_size_m / min(thickness_m, width_m) of a meshed plate. Quadratic tetrahedra
#: bend well with one element across the thickness while the elements are not much longer
#: than thick: measured first pinned-pinned bending frequency against Euler-Bernoulli
#: (80 x 10 mm steel plates): ratio 2 (1 mm, 2 mm elements) +0.08 %; ratio 20: +1.8 %
#: (0.1 mm, 2 mm) and +6.4 % (0.3 mm, 6 mm: also only 13 elements along the length); ratio
#: 50: +13 %; ratio 100: +14 %; ratio 200: +20 %. The studies mesh at ratios 2-20.
MESH_ASPECT_LIMIT = 20.0
#: largest length_m / thickness_m of a meshed plate link (smallest thickness: L / 1000).
#: Slenderness L / r = 3464 (r = t / sqrt(12)): Euler buckling at pi^2 E / (L/r)^2 =
#: 8e-7 E, e.g. 0.16 MPa in steel; such a strip is a foil that buckles under any load the
#: mechanism carries, not a link the linear FFRF body (or a solid mesh) describes. The studies
#: reach L / t = 267 (0.3 mm coupler).
PLATE_SLENDERNESS_LIMIT = 1000.0
#: smallest length_m / thickness_m of a meshed plate link: the rigid joint faces disturb
#: the plate over about one thickness from each end (Saint-Venant), so below 2 no part of the
#: link is free of them: its midpoint deflection and bending stress (evaluated away from
#: the end faces, one thickness from each) would mean nothing. The studies reach 4 (20 mm).
PLATE_STUBBINESS_LIMIT = 2.0
#: largest estimated memory of a plate reduction (or nonlinear FE body) [bytes]: two thirds
#: of this machine's 24 GiB, the rest for the simulation, the operating system and the
#: other process of a 2-core run (about 870k DOF by :func:`estimate_mesh`, ~30 min to build).
MESH_MEMORY_LIMIT_BYTES = 16 * 2**30


@dataclass(frozen=True)
class MeshEstimate:
    """Estimated size and cost of meshing and reducing one plate (before any meshing).

    Calibrated on netgen meshes of steel plates 80 mm long (second-order tetrahedra, as
    :mod:`flex.bodies.reduction` builds them), one process, 2-core machine:

    ==========================  ========  =======  ======  ===========  =========
    t x w, maxh [mm]            elements  DOF      est.    build [s]    peak RSS
    ==========================  ========  =======  ======  ===========  =========
    1 x 10, 2                   1463      9627     10.7k   2.6          0.24 GB
    1 x 10, 1                   5711      35805    42.9k   13.7         0.50 GB
    1 x 10, 0.5                 23403     143670   177k    77.5         1.56 GB
    3 x 10, 0.7                 36065     175212   194k    154          2.07 GB
    2 x 10, 0.3 (mesh only)     333045    --       --      23 (mesh)    --
    1 x 100, 2 (mesh only)      13895     --       --      2.3 (mesh)   --
    ==========================  ========  =======  ======  ===========  =========

    Elements: ``max(5.6 V / h^3, 3.65 S / h^2)`` (V volume, S surface area, h = maxh):
    netgen fills a plate thicker than h with ~5.6 elements per h^3 and meshes a thinner one
    from its two large faces (~3.65 elements per h^2 of surface), within +-25 % on the
    meshes above (1.5x high on the 1 mm, 0.5 mm mesh). Nodes of the quadratic mesh: 2.2
    per element when the surface term dominates, 1.65 when the volume does; DOF = 3 x
    nodes. Memory: 0.15 GB + 11.5 kB per DOF, the sparse factorisation's share growing as
    DOF^(1/3) beyond the largest mesh measured (175k DOF); build time: 154 s x (DOF /
    175k)^1.5 (Craig-Bampton eigenmodes dominate). Estimates: within a factor 2 of what a
    build takes.
    """

    elements: float
    dof: float
    memory_bytes: float
    build_time_s: float

    def text(self) -> str:
        """One-line description, e.g. ``~1.5e+03 elements, ~1.1e+04 DOF, ~0.26 GiB, ~2 s``."""
        return (f"~{self.elements:.2g} quadratic tetrahedra, ~{self.dof:.2g} DOF, "
                f"~{self.memory_bytes / 2**30:.2g} GiB, ~{duration_text(self.build_time_s)} to "
                f"mesh and reduce")


#: the Craig-Bampton modes the build times of :class:`MeshEstimate` were measured with
ESTIMATE_MODES = 6


def modes_cost_factor(modes: int) -> float:
    """Build time of a reduction to ``modes`` in-plane modes relative to one to
    :data:`ESTIMATE_MODES`: the eigen-solve computes about 2 x modes + 4 eigenmodes (more
    when the in-plane ones are not all among them) and its orthogonalisation grows with
    their square. Measured on a 1 mm plate, 2 mm mesh (9.6k DOF, one process on a 2-core
    machine loaded by others): 7.6 / 20 / 53 / 216 s at 2 / 6 / 24 / 40 modes;
    ``1 + 0.3 m + 4e-4 m^3`` follows those ratios within a factor 1.5."""
    def grow(count: float) -> float:
        return 1.0 + 0.3 * count + 4e-4 * count**3

    return grow(float(modes)) / grow(ESTIMATE_MODES)


def estimate_mesh(length_m: float, thickness_m: float, width_m: float,
                  mesh_size_m: float, modes: int | None = None) -> MeshEstimate:
    """Elements, DOF, memory and build time of a plate mesh before meshing (see
    :class:`MeshEstimate` for the calibration); ``modes``: the reduction's mode count,
    which scales the build time (:func:`modes_cost_factor`; None: the calibration's).
    Pure arithmetic: never meshes."""
    h = mesh_size_m
    volume = length_m * thickness_m * width_m
    surface = 2.0 * (length_m * thickness_m + length_m * width_m + thickness_m * width_m)
    from_volume, from_surface = 5.6 * volume / h**3, 3.65 * surface / h**2
    elements = max(from_volume, from_surface, 6.0)
    nodes = elements * (2.2 if from_surface >= from_volume else 1.65)
    dof = 3.0 * nodes
    memory = 0.15e9 + 11.5e3 * dof * max(1.0, dof / 175e3) ** (1.0 / 3.0)
    build = 154.0 * (dof / 175e3) ** 1.5
    if modes is not None:
        build *= modes_cost_factor(modes)
    return MeshEstimate(elements, dof, memory, build)


def meshed_plate(link: str, values: dict[str, Any]) -> tuple[float, str, str] | None:
    """Whether the scene meshes ``link``'s plate: ``(thickness_m meshed, its name, why)`` or
    None.

    ``ffrf`` and ``nonlinear_fe`` links are meshed; an ``auto`` crank always is (its
    frequency is computed on the mesh; a lumped crank as the plate of its mass, of thickness
    mass / (density x length x width), as :func:`flex.fidelity.auto.equivalent_crank_plate`); an
    ``auto`` coupler is when the criterion chooses ``ffrf``.
    """
    model = values["model"]
    name = f"{link}.thickness_m"
    if model in ("ffrf", "nonlinear_fe"):
        return values["thickness_m"], name, f'{link}.model = "{model}"'
    if model != "auto":
        return None
    if link == "crank" and values["geometry"] == "lumped":
        from flex.base.physics import plate_thickness_for_mass_m

        thickness = plate_thickness_for_mass_m(values["mass_kg"], values["length_m"],
                                               values["width_m"], values["density_kg_per_m3"])
        return (thickness, "the thickness of the plate of crank.mass_kg (mass / (density_kg_"
                "per_m3 x length_m x width_m))", 'crank.model = "auto" meshes a lumped crank '
                "as the plate of its mass")
    if link == "crank":
        return values["thickness_m"], name, 'crank.model = "auto" meshes the crank plate'
    return (values["thickness_m"], name,
            'coupler.model = "auto" meshes the plate if it chooses "ffrf"')


def check_meshed_plate(link: str, values: dict[str, Any]) -> None:
    """Refuse a plate that will be meshed but cannot mean anything, or that this machine
    cannot mesh (the estimate is in the message); nothing is meshed here."""
    meshed = meshed_plate(link, values)
    if meshed is None:
        return
    thickness, name, why = meshed
    length, width, mesh = values["length_m"], values["width_m"], values["mesh_size_m"]

    def as_mass(relation: str, bound: float) -> str:  # a lumped auto crank: on its mass_kg
        if values["geometry"] != "lumped":
            return ""
        mass = bound * values["density_kg_per_m3"] * length * width
        return (f"; i.e. {link}.mass_kg {relation} {mass:g} kg at its density_kg_per_m3, "
                f"length_m and width_m")

    for word, ratio, relation, outside, meaning in (
            ("least", PLATE_SLENDERNESS_LIMIT, ">=", -1,
             "thinner, it is a foil that buckles under any load the mechanism carries"),
            ("most", PLATE_STUBBINESS_LIMIT, "<=", 1,
             "thicker, the rigid joint faces reach its midpoint (Saint-Venant) and its "
             "deflection and stress mean nothing")):
        bound = length / ratio
        if outside * (thickness - bound * (1 + outside * 1e-9)) > 0:
            raise SceneError(f"{name} = {thickness:g}: a meshed plate link must be at "
                             f"{word} {link}.length_m / {ratio:g} = {bound:g} m thick "
                             f"({why}){as_mass(relation, bound)}; {meaning}")
    if mesh == "auto":  # checked once resolved (flex.fidelity.auto.check)
        return
    if mesh > length * (1 + 1e-9):
        raise SceneError(f"{link}.mesh_size_m = {mesh:g} must be <= {link}.length_m = "
                         f"{length:g} ({why}); about 1-2 x thickness_m is accurate")
    smallest = min(thickness, width)
    limit = MESH_ASPECT_LIMIT * smallest
    if mesh > limit * (1 + 1e-9):
        side = name if thickness <= width else f"{link}.width_m"
        raise SceneError(f"{link}.mesh_size_m = {mesh:g} must be <= {MESH_ASPECT_LIMIT:g} x "
                         f"{side} = {limit:g} ({why}): longer elements than that make "
                         f"the plate too stiff in bending (+13 % at 50 x); about 1-2 x "
                         f"thickness is accurate")
    estimate = estimate_mesh(length, thickness, width, mesh)
    if estimate.memory_bytes > MESH_MEMORY_LIMIT_BYTES:
        raise SceneError(f"{link}.mesh_size_m = {mesh:g} on a {length:g} x {thickness:g} x "
                         f"{width:g} m plate needs {estimate.text()} (estimate); this machine "
                         f"takes at most {MESH_MEMORY_LIMIT_BYTES / 2**30:g} GiB ({why}): use "
                         f"a coarser mesh_size_m or a smaller plate")


def to_toml(scene: Scene) -> str:
    """The fully resolved scene as TOML text (what ``python -m flex scene`` prints)."""
    return tomli_w.dumps(scene)


def plate_mass_properties(scene: Scene, link: str = "coupler") -> tuple[float, float]:
    """Mass [kg] and in-plane inertia about the centre of mass [kg m^2] of a link.

    ``link`` is ``"coupler"`` or ``"crank"``. Lumped geometry returns the scene's
    ``mass_kg`` and ``inertia_kgm2``; plate geometry computes them from length x thickness x
    width and density (a cuboid: m (L^2 + t^2)/12).
    """
    from flex.base.physics import cuboid_inertia_kgm2, cuboid_mass_kg

    values = scene[link]
    if values["geometry"] == "lumped":
        return values["mass_kg"], values["inertia_kgm2"]
    length_m, thickness_m = values["length_m"], values["thickness_m"]
    mass_kg = cuboid_mass_kg(length_m, thickness_m, values["width_m"],
                             values["density_kg_per_m3"])
    return mass_kg, cuboid_inertia_kgm2(mass_kg, length_m, thickness_m)
