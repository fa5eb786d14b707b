"""A scene key's field: its type, accepted range and meaning, and the check of a value.

:data:`flex.data.scene.SCHEMA` is made of :class:`Field` s; :func:`check_value` refuses a value
outside its field with one message naming the key and the accepted range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from flex.base.errors import SceneError

#: the value that leaves a key to flex (a field with ``auto``)
AUTO = "auto"


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
    #: a list (a TOML array) of one or more distinct values of ``kind``'s choices
    many: bool = False
    #: the accepted values in words, where listing every choice would not fit a message
    choices_text: str = ""

    def accepted(self) -> str:
        """Human-readable accepted range, used in error messages."""
        if self.many:
            return "a list of one or more distinct values, each " + self._accepted()
        return self._accepted() + (' or "auto"' if self.auto else "")

    def _accepted(self) -> str:
        if self.choices_text:
            return self.choices_text
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


def check_value(name: str, field: Field, value: Any) -> None:
    if field.auto and value == AUTO:
        return
    if field.many:
        _check_list(name, field, value)
        return
    if isinstance(field.kind, tuple):
        if not isinstance(value, str) or value not in field.kind:
            raise SceneError(f"{name} = {show(value)}: must be {field.accepted()}")
        return
    if field.kind is bool:
        if not isinstance(value, bool):
            raise SceneError(f"{name} = {show(value)}: must be true or false")
        return
    is_number = isinstance(value, int | float) and not isinstance(value, bool)
    if (not is_number or (field.kind is int and not isinstance(value, int))
            or not _finite(value) or (field.positive and not value > 0)
            or (field.minimum is not None and value < field.minimum)
            or (field.maximum is not None and value > field.maximum)
            or (field.below is not None and not value < field.below)):
        raise SceneError(f"{name} = {show(value)}: must be {field.accepted()}")


def _finite(value: float) -> bool:
    try:
        return math.isfinite(value)
    except OverflowError:  # an integer beyond the float range
        return False


def show(value: Any, limit: int = 60) -> str:
    """``repr(value)`` shortened to one line: safe inside a one-line error message."""
    try:
        text = repr(value)
    except ValueError:  # an integer beyond Python's digit limit for str()
        text = "<an integer of thousands of digits>"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _check_list(name: str, field: Field, value: Any) -> None:
    """A list field's value: a non-empty list of distinct accepted strings."""
    if (not isinstance(value, list) or not value or len(set(map(repr, value))) != len(value)
            or not all(isinstance(item, str) and item in field.kind for item in value)):
        raise SceneError(f"{name} = {show(value)}: must be {field.accepted()}")


__all__ = ["AUTO", "Field", "check_value", "show"]
