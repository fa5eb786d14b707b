"""Scenes: TOML parameter sets with units in every key, validated before anything runs.

A scene is a nested ``dict`` ``{section: {key: value}}``. The accepted sections and keys,
with their types and ranges, are in :data:`SCHEMA`; every key ends in its unit (``_m``,
``_kg``, ``_deg``, ...) or is dimensionless. Scenes are loaded from TOML files (the bundled
parameter sets live in ``flex/data/scenes/``, e.g. ``cavezza2012``), changed by ``--set
section.key=value`` overrides, and checked by :func:`validate`, which refuses an unknown key,
a wrong type, a non-finite or out-of-range number, and a linkage that cannot assemble, with
one message naming the key and the accepted range.

The link models a scene may name (``crank.model``, ``coupler.model``) are an argument,
``link_models``, of every function here that checks a scene: a mapping from a model's name to
its entry, of which this layer reads only the scene-level part, :class:`LinkSchema` (links,
flags, extra check). Its default, :data:`BUILTIN_LINK_SCHEMAS`, names the built-in models once;
their full entries are :data:`flex.dynamics.link_models.BUILTIN_LINK_MODELS`, built from these.
"""

from __future__ import annotations

import copy
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any

import tomli_w

from flex.base.errors import SceneError
from flex.data.fields import AUTO, Field, check_value, show
from flex.data.headlines import BUILTIN_HEADLINES, DEFAULT_QUANTITIES, QUANTITY_GROUPS
from flex.data.plates import (
    EXACT_BEAM_ELEMENTS,
    check_beam_plate,
    check_damping_model,
)
from flex.data.plates import check_meshed_plate as _check_meshed_plate
from flex.data.plates import meshed_plate as _meshed_plate
from flex.data.steps import (
    check_drive_steps,
    check_steps,
)

Scene = dict[str, dict[str, Any]]
#: the links whose model a scene chooses
LINKS = ("crank", "coupler")



@dataclass(frozen=True)
class LinkSchema:
    """The scene-level part of a link model's entry (points 1-3 of the contract in
    :mod:`flex.dynamics.link_models`): what validation, the usage of keys and the solver
    defaults read. Every flag is a fact about the keys of ``[crank]``/``[coupler]`` it reads.
    """

    #: (1) the value of ``<link>.model`` that selects it
    name: str
    #: the links it may model (``"crank"``, ``"coupler"``)
    links: tuple[str, ...]
    #: (2) a rigid body: reads the link's mass keys only (``mass_kg``/``inertia_kgm2`` or the
    #: plate's mass); builds planar; runs with the explicit integrators
    rigid: bool = False
    #: (2) reads ``damping_ratio`` (False: it has no damping model, the key must be 0)
    damped: bool = True
    #: (2) its discretization knobs, by name (:data:`flex.config.knobs.KNOBS`): the link keys
    #: it reads beyond the plate's (a knob's own, ``modes``, and those it brings,
    #: ``mode_selection``), what the error budget and refinement turn, what ``"auto"``
    #: fills; ``"mesh"`` meshes the link's plate (``geometry = "plate"``, the plate checks of
    #: :func:`flex.data.plates.check_meshed_plate`)
    knobs: tuple[str, ...] = ()
    #: (2) the link keys it reads beyond the plate's and its knobs' (``geometric_stiffness``)
    reads: tuple[str, ...] = ()
    #: (2) what gives its ``"auto"`` knobs and, as the coupler on a rigid crank, the run's
    #: ``"auto"`` step from ``fidelity.tolerance`` (:mod:`flex.config.settings`):
    #: ``"ffrf_rule"`` (the calibrated rule, :mod:`flex.config.ffrf_rule`), ``"exact_beam"``
    #: (:data:`flex.config.knobs.EXACT_BEAM_SETTINGS`, measured), ``""``: none (the fallback)
    settings: str = ""
    #: (3) its own checks on the scene's keys beyond the flags' (raise SceneError), or None
    check: Callable[[str, Scene], None] | None = None


#: the built-in link models' scene-level part, by name, in the order messages list them
BUILTIN_LINK_SCHEMAS: Mapping[str, LinkSchema] = MappingProxyType({
    "rigid": LinkSchema("rigid", LINKS, rigid=True),
    "ffrf": LinkSchema("ffrf", LINKS, knobs=("modes", "mesh"),
                       reads=("geometric_stiffness",), settings="ffrf_rule"),
    "nonlinear_fe": LinkSchema("nonlinear_fe", ("coupler",), damped=False, knobs=("mesh",)),
    "exact_beam": LinkSchema("exact_beam", LINKS, damped=False, knobs=("elements",),
                             settings="exact_beam", check=check_beam_plate),
})


def model_names(link: str, link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS,
                knob: str | None = None, **flags: bool) -> list[str]:
    """The names of the models of ``link`` in ``link_models`` whose flags have the given values
    (``rigid=True``: the rigid ones) and that name ``knob`` (if given), in the registry's
    order."""
    return [name for name, entry in link_models.items() if link in entry.links
            and all(getattr(entry, flag) == value for flag, value in flags.items())
            and (knob is None or knob in entry.knobs)]


def quoted(names: list[str]) -> str:
    """``"a"``, ``"a" or "b"``, ``"a", "b" or "c"``: names as a message lists them."""
    words = [f'"{name}"' for name in names]
    return " or ".join(filter(None, [", ".join(words[:-1]), words[-1]])) if words else ""


def link_model(link: str, values: dict[str, Any], link_models: Mapping[str, Any]) -> Any:
    """The entry of ``link``'s model (``values["model"]``, not ``"auto"``) in ``link_models``;
    SceneError naming the accepted models if it has none or it does not model ``link``."""
    model = values["model"]
    names = model_names(link, link_models)
    if not isinstance(model, str) or model not in names:
        raise SceneError(f"{link}.model = {show(model)}: must be one of "
                         + ", ".join(f'"{name}"' for name in [*names, AUTO]))
    return link_models[model]


def meshes(link: str, values: dict[str, Any], link_models: Mapping[str, Any]) -> bool:
    """Whether ``link``'s concrete model meshes its plate (False for ``"auto"``)."""
    return values["model"] != AUTO and "mesh" in link_model(link, values, link_models).knobs


def check_meshed_plate(link: str, values: dict[str, Any],
                       link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> None:
    """:func:`flex.data.plates.check_meshed_plate` for ``link``'s model in ``link_models``."""
    _check_meshed_plate(link, values, meshes(link, values, link_models))


def meshed_plate(link: str, values: dict[str, Any],
                 link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS
                 ) -> tuple[float, str, str] | None:
    """:func:`flex.data.plates.meshed_plate` for ``link``'s model in ``link_models``."""
    return _meshed_plate(link, values, meshes(link, values, link_models))


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
        "damping_model": Field(("stiffness_proportional", "modal_bands"),
                               "stiffness_proportional: damping_ratio of the first pinned "
                               "bending mode, higher modes proportionally more; modal_bands: "
                               "1 % below 100 Hz, 10 % to 1 kHz, 100 % above, every mode of "
                               "the reduced body (the commercial codes' default; "
                               "flex.bodies.reduction.damping)",
                               default="stiffness_proportional"),
        "elements": Field(int, "model = exact_beam: beam elements along the link (auto, and "
                          "when auto picks the beam: from fidelity.tolerance)", minimum=2,
                          maximum=1024, auto=True, default=EXACT_BEAM_ELEMENTS),
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
        "model": Field((*model_names("crank"), AUTO),
                       "rigid body or floating-frame flexible body (plate geometry); auto: rigid "
                       "or ffrf (and modes) from the fitted criterion and fidelity.tolerance"),
        **_plate_fields("crank"),
    },
    "coupler": {
        "length_m": Field(doc="coupler length L2 between joints B and C", **_POS),
        "mass_kg": Field(doc="coupler mass (geometry = lumped)", **_POS),
        "inertia_kgm2": Field(doc="coupler inertia about its centre of mass (lumped)", **_POS),
        "model": Field((*model_names("coupler"), AUTO),
                       "rigid body, floating-frame flexible body, fully nonlinear FE body "
                       "(accuracy reference, ~50x slower per step) or geometrically exact beam; "
                       "auto: rigid or ffrf (and modes) from the fitted criterion and tolerance"),
        **_plate_fields("coupler"),
    },
    "wing": {
        "enabled": Field(bool, "weld a wing plate to the crank at A (sec. 6.4 application)"),
        "span_m": Field(doc="wing span, from the crank pivot A along the crank", **_POS),
        "chord_m": Field(doc="wing chord, in the mechanism plane across the span", **_POS),
        "thickness_m": Field(doc="wing thickness, out of the mechanism plane", **_POS),
        "density_kg_per_m3": Field(doc="wing material density (a solid's)", **_DENSITY),
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
                            "flex.config.settings)", auto=True, **_POS),
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
                        "(modified), or computed once per step and reused within it", auto=True),
        "error_estimate": Field(bool, "estimate the run's own step error on its headline "
                                      "quantities by a companion run at 2x (or 1/2) the step"),
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
        "tolerance": Field(float, "accepted relative error of each quantity asked "
                           "(fidelity.quantities), relative to the quantity itself; the rigid "
                           "decision of model = \"auto\": the predicted deflection relative to "
                           "the link's length (docs/criterion.md)", positive=True, maximum=0.5),
        "quantities": Field((*QUANTITY_GROUPS, *BUILTIN_HEADLINES),
                            "the headline quantities the tolerance applies to: their names, or "
                            '"motion", "deflections" (the link is made flexible), '
                            '"flexible_deflections" (of the links that are flexible) '
                            "(docs/error-budget.md)", many=True,
                            default=list(DEFAULT_QUANTITIES),
                            choices_text="a group (" + ", ".join(QUANTITY_GROUPS) + ") or a "
                            "headline quantity's name (flex inspect lists them; "
                            "docs/error-budget.md)"),
        "refine": Field(bool, "refine step, modes, mesh, rung until every quantity asked "
                        "meets the tolerance (docs/error-budget.md)", default=False),
        "refine_limit_s": Field(float, "refine: none starts after", positive=True, default=600.0),
    },
}

DEFAULT_SCENE = "cavezza2012"


def bundled_scenes() -> list[str]:
    """Names of the parameter sets shipped in ``flex/data/scenes`` (without ``.toml``)."""
    folder = resources.files("flex.data.scenes")
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_scene(source: str | Path | None = None, overrides: list[str] | None = None, *,
               link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> Scene:
    """Load, override and validate a scene.

    ``source`` is a TOML file path or the name of a bundled parameter set (default
    ``cavezza2012``). Sections and keys missing from a file are taken from the default
    parameter set, so a user scene needs to state only what it changes. ``overrides`` are
    ``"section.key=value"`` strings, the value in TOML syntax (``1e-3``, ``"ffrf"``,
    ``true``); a bare word is read as a string. ``link_models``: the link models a scene
    may name (:func:`validate`). Returns the validated scene.
    """
    scene = default_scene()
    user = read_source(source)
    if user is not None:
        scene = merge(scene, user)
    if overrides:
        scene = apply_overrides(scene, overrides)
    validate(scene, link_models)
    return scene


def default_scene() -> Scene:
    """The bundled default parameter set (:data:`DEFAULT_SCENE`), as read from its file,
    with the schema default of every key the file does not state (:attr:`Field.default`)."""
    scene = read_toml(scene_path(DEFAULT_SCENE), DEFAULT_SCENE)
    for section, fields in SCHEMA.items():
        for key, field in fields.items():
            if field.default is not None:
                scene.setdefault(section, {}).setdefault(key, copy.deepcopy(field.default))
    return scene


def read_source(source: str | Path | None) -> Scene | None:
    """The tables of a user scene file or bundled parameter set, as written (not merged,
    not validated); None for no source or the default parameter set."""
    if source is None or str(source) == DEFAULT_SCENE:
        return None
    path = Path(source)
    return read_toml(path if path.suffix == ".toml" or path.exists()
                      else scene_path(str(source)), str(source))


def scene_path(name: str) -> Path:
    """The file of bundled scene ``name`` (SceneError naming the bundled ones if missing)."""
    path = Path(str(resources.files("flex.data.scenes").joinpath(f"{name}.toml")))
    if not path.exists():
        raise SceneError(f"scene '{name}' is neither a TOML file nor a bundled parameter set "
                         f"(bundled: {', '.join(bundled_scenes())})")
    return path


def read_toml(path: Path, label: str) -> Scene:
    """The TOML scene file ``path`` as a dict (SceneError naming ``label`` if unreadable)."""
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
                             f"table; accepted sections: {', '.join(SCHEMA)}")
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


def derived_scenes(scene: Scene, overrides_by_name: Mapping[str, list[str]], *,
                   link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> dict[str, Scene]:
    """One validated scene per name: ``scene`` with that name's overrides (a study's cases
    declared as data); raises SceneError naming the first that does not validate."""
    out = {name: apply_overrides(scene, overrides)
           for name, overrides in overrides_by_name.items()}
    for derived in out.values():
        validate(derived, link_models)
    return out


def parse_override(item: str) -> tuple[str, str, Any]:
    """``"section.key=value"`` -> ``(section, key, value)`` (value in TOML syntax; a bare
    word is a string); SceneError if it is not of that form."""
    if "=" not in item or "." not in item.split("=", 1)[0]:
        raise SceneError(f"--set {show(item)}: expected section.key=value, "
                         f"e.g. coupler.thickness_m=0.003")
    dotted, text = item.split("=", 1)
    section, key = (part.strip() for part in dotted.split(".", 1))
    return section, key, _parse_value(text.strip())


def _parse_value(text: str) -> Any:
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except (ValueError, RecursionError):  # not TOML (or absurdly long/deep): a bare word
        return text


def validate(scene: Scene, link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> None:
    """Raise :class:`SceneError` naming the first problem; return ``None`` if valid.

    Checks: known sections and keys, every key present, types, finiteness, ranges, and the
    geometry: the crank must be able to turn (``L1 + |offset| < L2``), the step settings
    consistent (an explicit step: :func:`check_steps`, :func:`check_drive_steps`; an
    ``"auto"`` one is checked once resolved, :func:`flex.fidelity.auto.check`), FFRF
    couplers need plate geometry, and plates that will be meshed must make sense and fit
    this machine (:func:`check_meshed_plate`). ``link_models``: the models ``crank.model``
    and ``coupler.model`` may name, by name (entries with the fields of :class:`LinkSchema`:
    their flags and own checks apply; default: the built-in ones).
    """
    for section, table in scene.items():
        if section not in SCHEMA:
            raise SceneError(f"unknown section [{_name(section)}]; accepted sections: "
                             f"{', '.join(SCHEMA)}")
        for key, value in table.items():
            if key not in SCHEMA[section]:
                raise SceneError(f"unknown key {_name(section)}.{_name(key)}; accepted keys in "
                                 f"[{section}]: {', '.join(SCHEMA[section])}")
            field = SCHEMA[section][key]
            if section in LINKS and key == "model":  # the models of the registry given
                field = replace(field, kind=(*model_names(section, link_models), AUTO))
            check_value(f"{section}.{key}", field, value)
    for section, fields in SCHEMA.items():
        for key in fields:
            if key not in scene.get(section, {}):
                raise SceneError(f"missing key {section}.{key} ({fields[key].doc})")
    _check_geometry(scene, link_models)


def _name(text: str, limit: int = 60) -> str:
    """A user-written section or key name, control characters escaped, shortened."""
    text = text if text.isprintable() else repr(text)[1:-1]
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _check_geometry(scene: Scene, link_models: Mapping[str, Any]) -> None:
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
    for link in LINKS:
        _check_link(link, scene[link], link_models)
    entries = {link: None if scene[link]["model"] == AUTO
               else link_models[scene[link]["model"]] for link in LINKS}
    rigid_cranks = quoted(model_names("crank", link_models, rigid=True))
    crank_model = scene["crank"]["model"]
    if (entries["crank"] is not None and not entries["crank"].rigid
            and scene["drive"]["kind"] == "constant_speed"):
        raise SceneError(f'crank.model = "{crank_model}" needs drive.kind = "spring": the '
                         "constant-speed drive constrains the rotation coordinate of a rigid "
                         "crank, which a flexible crank's floating frame does not have; "
                         f"accepted: {rigid_cranks}")
    if crank_model == AUTO and scene["drive"]["kind"] != "spring":
        raise SceneError('crank.model = "auto" needs drive.kind = "spring": auto analyses the '
                         "crank as a flexible plate in the mechanism, and a flexible crank needs "
                         f"the spring drive; accepted with a constant-speed drive: {rigid_cranks}")
    if scene["drive"]["spring_model"] == AUTO and scene["drive"]["kind"] != "spring":
        raise SceneError('drive.spring_model = "auto" needs drive.kind = "spring" (a '
                         "constant-speed drive has no spring to choose a model for); "
                         'accepted: "massless" or "chain"')
    for link, entry in entries.items():
        values = scene[link]
        if entry is not None and not entry.damped and values["damping_ratio"] != 0:
            raise SceneError(f"{link}.damping_ratio = {values['damping_ratio']:g}: "
                             f'{link}.model = "{values["model"]}" has no damping model; '
                             "accepted: 0")
        check_damping_model(link, values, entry)
    if scene["simulation"]["integrator"] == "explicit_penalty" and (
            not all(entry is not None and entry.rigid for entry in entries.values())
            or scene["drive"]["kind"] != "spring"):
        raise SceneError('simulation.integrator = "explicit_penalty" needs crank.model and '
                         'coupler.model = "rigid" and drive.kind = "spring" (Exudyn\'s explicit '
                         "solvers take no algebraic constraints: the flexible bodies' "
                         "Euler-parameter frames and the crank-speed constraint have them); "
                         'accepted: "generalized_alpha"')
    for link, entry in entries.items():
        if entry is not None and entry.check is not None:
            entry.check(link, scene)


def _check_link(link: str, values: dict[str, Any], link_models: Mapping[str, Any]) -> None:
    """A flexible (or auto) link needs plate geometry, and the plate must fit its length;
    a plate that will be meshed must make sense as a meshed link (:func:`check_meshed_plate`).
    """
    model = values["model"]
    if meshes(link, values, link_models) and values["geometry"] != "plate":
        raise SceneError(f'{link}.model = "{model}" needs {link}.geometry = "plate" (the '
                         "flexible body is meshed from the plate's dimensions)")
    if model == AUTO and values["geometry"] != "plate" and link == "coupler":
        raise SceneError('coupler.model = "auto" needs coupler.geometry = "plate" (the '
                         "criterion needs the plate's bending frequency; a lumped coupler has "
                         'no stiffness): use coupler.model = "rigid" for a lumped coupler')
    if values["geometry"] == "plate" and values["thickness_m"] >= values["length_m"]:
        raise SceneError(f"{link}.thickness_m = {values['thickness_m']:g} must be smaller "
                         f"than {link}.length_m = {values['length_m']:g}")
    check_meshed_plate(link, values, link_models)


def to_toml(scene: Scene) -> str:
    """The fully resolved scene as TOML text (what ``python -m flex scene`` prints)."""
    return tomli_w.dumps(scene)
