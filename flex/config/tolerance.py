"""What ``fidelity.tolerance`` asks, resolved once from a scene.

A :class:`Tolerance` holds the relative error accepted (``fidelity.tolerance``), the headline
quantities it applies to (``fidelity.quantities``: names of :data:`flex.data.headlines.
BUILTIN_HEADLINES` or the groups of :data:`flex.data.headlines.QUANTITY_GROUPS`), whether
refinement runs (``fidelity.refine``) and its cost limit. Every reader of the tolerance (the
solver defaults, the knobs' ``"auto"``, ``auto``'s decisions, refinement, the statement of
what the tolerance covered) reads it through :meth:`Tolerance.of`, so it means one thing: each
quantity asked, relative to the quantity itself. The one other reading, the rigid decision of
``model = "auto"``, is named for what it is: the predicted deflection relative to the link's
length (:mod:`flex.fidelity.auto`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from flex.data.headlines import BUILTIN_HEADLINES, QUANTITY_GROUPS

#: the group of the flexible links' own deflections: applied only to links flexible in a run
FLEXIBLE_DEFLECTIONS = "flexible_deflections"


@dataclass(frozen=True)
class Tolerance:
    """The tolerance a scene asks for (see the module doc): ``relative`` [1], the
    ``quantities`` as given (names and groups), ``refine`` and its ``limit_s`` [s]."""

    relative: float
    quantities: tuple[str, ...]
    refine: bool = False
    limit_s: float = 600.0

    @classmethod
    def of(cls, scene: Mapping[str, Mapping[str, Any]]) -> Tolerance:
        """The tolerance of a validated scene's ``[fidelity]``."""
        fidelity = scene["fidelity"]
        return cls(float(fidelity["tolerance"]), tuple(fidelity["quantities"]),
                   bool(fidelity["refine"]), float(fidelity["refine_limit_s"]))

    def explicit(self) -> tuple[str, ...]:
        """The quantities asked whatever the links' models (groups expanded, but not the
        flexible links' deflections), in order, each once."""
        names: list[str] = []
        for item in self.quantities:
            if item != FLEXIBLE_DEFLECTIONS:
                names += QUANTITY_GROUPS.get(item, (item,))
        return tuple(dict.fromkeys(names))

    def asked(self, flexible_links: Iterable[str]) -> tuple[str, ...]:
        """The quantities the tolerance applies to in a run whose ``flexible_links`` are
        those named (the flexible links' deflections for ``"flexible_deflections"``)."""
        flexible = set(flexible_links)
        names = list(self.explicit())
        if FLEXIBLE_DEFLECTIONS in self.quantities:
            names += [name for name in QUANTITY_GROUPS[FLEXIBLE_DEFLECTIONS]
                      if BUILTIN_HEADLINES[name].link in flexible]
        return tuple(dict.fromkeys(names))

    def wants_flexible(self, link: str) -> bool:
        """Whether a quantity of ``link``'s own elastic response is asked explicitly (its
        deflection, a stress: a rigid link would give it as a prediction only)."""
        return any(BUILTIN_HEADLINES[name].link == link for name in self.explicit()
                   if name in BUILTIN_HEADLINES)

    def text(self) -> str:
        """``"0.1 % of each of: motion, flexible_deflections"``."""
        return f"{100 * self.relative:g} % of each of: {', '.join(self.quantities)}"


__all__ = ["FLEXIBLE_DEFLECTIONS", "Tolerance"]
