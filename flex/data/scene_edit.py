"""Editing a scene, the one way: :func:`derive_scene` applies ``section.key`` overrides as the
command line's ``--set`` does (:func:`flex.data.scene.apply_overrides`) and validates the
result as a whole (:func:`flex.data.scene.validate`), so an edited scene is exactly what
``flex run ... --set`` would run. Library code and studies edit scenes only through it
(:func:`flex.api.derive_scene`, the public face for scripts, is built on it)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from flex.base.errors import SceneError
from flex.data.scene import BUILTIN_LINK_SCHEMAS, Scene, apply_overrides, validate


def override_text(key: str, value: Any) -> str:
    """``"section.key=value"`` with ``value`` (a string, number or boolean; a numpy scalar is
    taken as its Python value) written as TOML; SceneError for a value TOML cannot hold."""
    import tomli_w

    if hasattr(value, "item") and not isinstance(value, str | bytes):
        value = value.item()  # numpy scalar -> Python scalar
    try:
        text = tomli_w.dumps({"v": value}).strip().removeprefix("v = ")
    except (TypeError, ValueError):
        raise SceneError(f"override {key}: {value!r} is not a scene value (a string, "
                         f"number or boolean)") from None
    return f"{key}={text}"


def derive_scene(scene: Scene, overrides: Mapping[str, Any] | Sequence[str], *,
                 link_models: Mapping[str, Any] = BUILTIN_LINK_SCHEMAS) -> Scene:
    """A new scene: ``scene`` (not modified) with ``overrides`` applied, validated as a whole.

    ``overrides``: ``{"section.key": value}`` (values in the units their keys name, e.g.
    ``{"drive.spring_preload_m": 0.011}`` [m]) or ``"section.key=value"`` strings (TOML
    values, as ``--set``). Raises :class:`SceneError` naming the first problem (unknown key,
    type, range, linkage, ...). ``link_models``: the link models the scene may name (their
    scene-level part; :mod:`flex.dynamics.link_models` passes its registry)."""
    if isinstance(overrides, Mapping):
        strings = [override_text(key, value) for key, value in overrides.items()]
    else:
        strings = list(overrides)
    derived = apply_overrides(scene, strings)
    validate(derived, link_models)
    return derived
