"""Which scene keys a scene's models use, and which keys the user gave.

A scene holds every key of :data:`flex.data.scene.SCHEMA`, but a scene's models read only some:
``--set coupler.thickness_m=0.003`` on a lumped coupler changes nothing. Two functions let a
study refuse such input instead of silently ignoring it:

- :func:`unused_keys`: for one (case) scene, the ``"section.key"`` names its models do not
  read, each with a short reason naming what would read it;
- :func:`explicit_keys`: the ``"section.key"`` values the user gave (every ``--set`` key, and
  every key of a user scene file whose value differs from the bundled default scene).

A key the user gave that no case of a study uses (and that the study does not read itself,
``read_by_study``) changed nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from flex.config.knobs import knobs_of, reads_key
from flex.config.settings import reads_tolerance
from flex.data.fields import AUTO
from flex.data.scene import (
    BUILTIN_LINK_SCHEMAS,
    LINKS,
    Scene,
    default_scene,
    link_model,
    model_names,
    parse_override,
    quoted,
    read_source,
)

#: plate keys of a link beyond the mass-giving ones
_PLATE_MASS = ("thickness_m", "width_m", "density_kg_per_m3")
_PLATE_ELASTIC = ("youngs_modulus_Pa", "poisson_ratio", "modes", "mode_selection",
                  "mesh_size_m", "damping_ratio", "damping_model")
_SOLVER_ALPHA = ("spectral_radius", "formulation", "newton", "newton_relative_tolerance")
_SOLVER_EXPLICIT = ("explicit_method", "penalty_stiffness_N_per_m")
_SPRING = ("spring_stiffness_N_per_m", "spring_preload_m", "spring_damping_Ns_per_m",
           "spring_model", "spring_mass_kg", "spring_segments")
_SPRING_CHAIN = ("spring_mass_kg", "spring_segments")
_WING = ("span_m", "chord_m", "thickness_m", "density_kg_per_m3", "youngs_modulus_Pa")


def unused_keys(scene: Scene, read_by_study: Iterable[str] = frozenset(), *,
                link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> dict[str, str]:
    """The keys of ``scene`` that its models do not read: ``{"section.key": reason}``.

    Contract: ``scene`` is a validated scene (link models and solver keys may be
    ``"auto"``: a key that ``auto`` may read counts as used; ``modes`` of an ``auto`` link
    does not, ``auto`` chooses them). ``read_by_study``: ``"section.key"`` names a study
    reads itself (e.g. the modal study's plate keys of rigid links); they are never
    reported. The reason names what would read the key. ``link_models``: the registry of
    the link models (a model's flags say which of its link's keys it reads). Pure: reads
    nothing but its arguments.
    """
    unused: dict[str, str] = {}
    for link in LINKS:
        unused.update(_link_unused(link, scene, link_models))
    wing = scene["wing"]
    if not wing["enabled"]:
        for key in _WING:
            unused[f"wing.{key}"] = "wing.enabled = false: used with a wing (enabled = true)"
    else:
        unused["wing.youngs_modulus_Pa"] = ("the wing is a rigid body in the mechanism: its "
                                            "Young's modulus is read by no model (only by "
                                            "the wing study's frequency estimate)")
    unused["slider.inertia_kgm2"] = ("the slider does not turn (prismatic joint): its inertia "
                                     "changes no result")
    drive = scene["drive"]
    if drive["kind"] == "spring":
        unused["drive.crank_speed_rad_per_s"] = ('drive.kind = "spring": the spring moves the '
                                                 'crank; used with kind = "constant_speed"')
        if drive["spring_model"] == "massless":
            for key in _SPRING_CHAIN:
                unused[f"drive.{key}"] = ('drive.spring_model = "massless": the spring has no '
                                          'mass; used with spring_model = "chain"')
        elif drive["spring_model"] == AUTO:
            unused["drive.spring_segments"] = ('drive.spring_model = "auto" chooses the '
                                               'segments itself; used with spring_model = '
                                               '"chain"')
    else:
        for key in _SPRING:
            unused[f"drive.{key}"] = ('drive.kind = "constant_speed": no spring; used with '
                                      'kind = "spring"')
    sim = scene["simulation"]
    if sim["integrator"] == "explicit_penalty":
        for key in _SOLVER_ALPHA:
            unused[f"simulation.{key}"] = ('simulation.integrator = "explicit_penalty": used '
                                           'with integrator = "generalized_alpha"')
    else:
        for key in _SOLVER_EXPLICIT:
            unused[f"simulation.{key}"] = ('simulation.integrator = "generalized_alpha": used '
                                           'with integrator = "explicit_penalty"')
    refine = scene["fidelity"].get("refine", False)
    if not (refine or sim.get("error_estimate", True)
            or reads_tolerance(scene, link_models=link_models)):
        for key in ("tolerance", "quantities"):
            unused[f"fidelity.{key}"] = (
                'no "auto" choice reads it and simulation.error_estimate = false (no budget '
                'to state what the tolerance covers): used by model = "auto" links, by "auto" '
                "solver keys of an FFRF coupler on a rigid crank, by a run's error budget and "
                "by fidelity.refine = true")
    if not refine:
        unused["fidelity.refine_limit_s"] = "used with fidelity.refine = true"
    for name in read_by_study:
        unused.pop(name, None)
    return unused


def _link_unused(link: str, scene: Scene, link_models: Mapping[str, Any]) -> dict[str, str]:
    values = scene[link]
    model, geometry = values["model"], values["geometry"]
    entry = None if model == AUTO else link_model(link, values, link_models)
    unused: dict[str, str] = {}

    def used_with(**flags: bool) -> str:  # the models reading a key, and "auto"
        return quoted([*model_names(link, link_models, **flags), AUTO])

    def mark(keys: Iterable[str], reason: str) -> None:
        for key in keys:
            unused.setdefault(f"{link}.{key}", reason)

    if geometry == "plate":
        mark(("mass_kg", "inertia_kgm2"),
             f'{link}.geometry = "plate": mass and inertia come from the plate (thickness_m, '
             f'width_m, density_kg_per_m3); used with geometry = "lumped"')
    if entry is not None and entry.rigid:
        if geometry == "lumped":
            mark(_PLATE_MASS + _PLATE_ELASTIC,
                 f'{link}.geometry = "lumped": the {link} is its mass_kg and inertia_kgm2; '
                 f'used with geometry = "plate"')
        mark(_PLATE_ELASTIC, f'{link}.model = "{model}": a rigid link has no elasticity; used '
                             f"with model = {used_with(rigid=False)}")
    elif entry is not None:
        if not entry.damped:
            mark(("damping_ratio", "damping_model"),
                 f'{link}.model = "{model}" has no damping model; used with model = '
                 f"{used_with(rigid=False, damped=True)}")
    elif model == AUTO:
        mark(("modes",), f'{link}.model = "auto" chooses the modes itself; used with '
                         f"model = {quoted(model_names(link, link_models, knob='modes'))}")
        mark(("elements",), f'{link}.model = "auto" chooses the elements itself; used with '
                            f"model = {quoted(model_names(link, link_models, knob='elements'))}")
        if geometry == "lumped":  # an auto crank: analysed as the plate of its mass
            mark(("thickness_m",), f'{link}.model = "auto" with geometry = "lumped" analyses '
                                   f"the plate of the {link}'s mass_kg (its thickness follows "
                                   f'from it); used with geometry = "plate"')
    if entry is not None:
        _mark_knob_keys(link, model, entry, link_models, mark)
    return unused


#: a link's keys that only some models read: their knobs' keys and what they bring
#: (flex.config.knobs), and what a model reads beyond them
_MODEL_KEYS = ("modes", "mode_selection", "mesh_size_m", "elements", "geometric_stiffness")


def _mark_knob_keys(link: str, model: str, entry: Any, link_models: Mapping[str, Any],
                    mark: Callable[[Iterable[str], str], None]) -> None:
    """Mark the keys of :data:`_MODEL_KEYS` that ``entry`` (``link``'s concrete model) does
    not read, naming the models that do (:func:`flex.config.knobs.reads_key`)."""
    own = ", ".join(knob.name for knob in knobs_of(entry)) or "none"
    for key in _MODEL_KEYS:
        if reads_key(entry, key):
            continue
        readers = [name for name, other in link_models.items()
                   if link in other.links and reads_key(other, key)]
        mark((key,), f'{link}.model = "{model}" does not read it (its discretization knobs: '
                     f"{own}); " + (f"used with model = {quoted([*readers, AUTO])}"
                                    if readers else f"no {link} model reads it"))


def explicit_keys(source: str | Path | None = None,
                  overrides: Sequence[str] | None = None) -> dict[str, Any]:
    """The values the user gave: ``{"section.key": value}``.

    Every key of ``overrides`` (``--set section.key=value`` strings; the last of a repeated
    key wins), and every key of the scene file or bundled parameter set ``source`` whose
    value differs from the bundled default scene's (a key absent from the default counts as
    given). ``source`` None or the default parameter set gives no file keys. Inputs as
    :func:`flex.data.scene.load_scene` takes them; a malformed one raises SceneError as there.
    """
    given: dict[str, Any] = {}
    user = read_source(source)
    if user is not None:
        bundled = default_scene()
        missing = object()
        for section, table in user.items():
            if not isinstance(table, dict):
                continue  # load_scene refuses it
            for key, value in table.items():
                default = bundled.get(section, {}).get(key, missing)
                if default is missing or default != value:
                    given[f"{section}.{key}"] = value
    for item in overrides or ():
        section, key, value = parse_override(item)
        given[f"{section}.{key}"] = value
    return given
