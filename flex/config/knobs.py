"""The discretization knobs as data: each knob once, with everything its users read.

A knob is a scene key that trades cost for accuracy and whose error the budget measures with
a finer companion run: the step (``simulation.step_s``) and, per link, a reduction's modes, a
meshed plate's mesh size and a beam's elements. A link model's registry entry names its knobs
(:attr:`flex.data.scene.LinkSchema.knobs`: the FFRF body ``("modes", "mesh")``, the nonlinear
FE body ``("mesh",)``, the exact beam ``("elements",)``, a rigid body none); the error budget
(:mod:`flex.fidelity.error_budget`), ``auto`` (:mod:`flex.config.settings`) and refinement
(:mod:`flex.fidelity.refinement`) loop over them and name no model.

The contract of a :class:`Knob`, point by point:

1. ``name``, the budget ``term`` its companion measures (``"step"``, ``"modes"``, ``"mesh"``:
   a link's spatial discretization, whether a mesh or a beam's elements) and its scene
   ``key`` (``"{link}.modes"`` stands for each link's);
2. ``scene_keys``: the link keys it brings beside its own (a reduction's ``mode_selection``),
   which a model naming it reads (:func:`reads_key`);
3. ``finer(value)``: one turn of the knob, the value of the budget's companion, which is also
   refinement's move (``limit``: the finest value it may take, None: no limit);
4. ``order`` and ``ratio``: the convergence of its term under one turn (a difference taken
   ``r^p / (r^p - 1)`` times: Richardson; ``order`` None: the difference taken whole), read per
   headline quantity where ``per_headline_order`` (a mesh: a deflection converges at 2, a
   stress at 1, :attr:`flex.data.headlines.Headline.mesh_order`); ``prior_fall``: how many
   times its term is predicted to shrink under one turn until refinement has observed it;
5. ``preparation_s(values, knobs)``: what a link at this value costs to prepare beyond its run
   [s] (meshing, reducing; flex's estimate before anything runs);
6. ``auto``: how ``"auto"`` resolves it from ``fidelity.tolerance`` (:func:`auto_value`);
7. words: ``what`` (its term's words), ``change_text`` and ``text`` (how a run's settings name
   it).

Adding a knob (the next: the element order of 3-D bodies): one :class:`Knob` in :data:`KNOBS`
and its name in the entries of the models it applies to (docs/extending.md).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from flex.config.calibration import Calibration
from flex.config.ffrf_rule import pick
from flex.config.tolerance import Tolerance
from flex.data.plates import EXACT_BEAM_ELEMENTS, estimate_mesh
from flex.data.scene import LINKS, SCHEMA, Scene

#: order of accuracy of the explicit Runge-Kutta methods (``simulation.explicit_method``)
EXPLICIT_ORDERS = {"RK44": 4, "RK67": 6, "ExplicitMidpoint": 2}


def integrator_order(simulation: Mapping[str, Any]) -> int:
    """Order of accuracy of the scene's integrator (resolved ``[simulation]`` keys):
    generalized-alpha 2 (Chung and Hulbert, any spectral radius); Newmark with velocity-level
    constraints 2 at spectral radius 1 (trapezoidal rule), else 1 (gamma > 1/2); explicit
    Runge-Kutta its own (:data:`EXPLICIT_ORDERS`)."""
    if simulation["integrator"] == "explicit_penalty":
        return EXPLICIT_ORDERS[simulation["explicit_method"]]
    if simulation["formulation"] == "index2" and simulation["spectral_radius"] < 1.0:
        return 1
    return 2


def richer_modes(modes: int) -> int:
    """The modes companion's count for a link with ``modes``: twice as many, at least two
    more (1 -> 3, 2 -> 4, 6 -> 12)."""
    return int(modes + max(modes, 2))


#: the exact beam's first-guess settings by tolerance: (tolerance at or above, elements,
#: step [s]), tightest last. Measured on the thesis deployment (0.5-1 mm plates, the run's
#: own budget): 32 elements at 1e-5 s stated 0.14-0.31 % on the first crest and 0.05-0.23 %
#: on the deployment time (step and element terms); 64 elements at 5e-6 s on the 0.7 mm
#: plate stated 0.067 % on the first crest (step 0.051 %, elements 0.004 %, model 0.044 %)
#: and 0.045 % on the deployment time, with its whole budget in 31 s on a loaded 2-core
#: machine. A first guess like the FFRF rule's: each run's budget says what it achieved.
EXACT_BEAM_SETTINGS = ((0.005, EXACT_BEAM_ELEMENTS, 1e-5), (0.0, 64, 5e-6))


def exact_beam_settings(tolerance: float) -> tuple[int, float]:
    """The exact beam's elements and step [s] at ``fidelity.tolerance`` (dimensionless):
    the first row of :data:`EXACT_BEAM_SETTINGS` whose tolerance it reaches."""
    return next((elements, step) for floor, elements, step in EXACT_BEAM_SETTINGS
                if tolerance >= floor)


AutoRule = Callable[[Scene, str, float, Calibration | None], Any]


def _rule_modes(scene: Scene, link: str, tolerance: float,
                calibration: Calibration | None) -> int:
    return pick(scene, tolerance, link, calibration).modes


def _rule_mesh(scene: Scene, link: str, tolerance: float,
               calibration: Calibration | None) -> float:
    return pick(scene, tolerance, link, calibration).mesh_size_m


def _beam_elements(scene: Scene, link: str, tolerance: float,
                   calibration: Calibration | None) -> int:
    return exact_beam_settings(tolerance)[0]


def _no_preparation(values: Mapping[str, Any], knobs: tuple[str, ...]) -> float:
    return 0.0


def _plate(values: Mapping[str, Any]) -> tuple[float, float, float, float]:
    return (values["length_m"], values["thickness_m"], values["width_m"],
            values["mesh_size_m"])


def _mesh_preparation_s(values: Mapping[str, Any], knobs: tuple[str, ...]) -> float:
    """Meshing (and reducing, for a model with modes) the link's plate [s], estimated."""
    return estimate_mesh(*_plate(values), values["modes"] if "modes" in knobs else None
                         ).build_time_s


def _modes_preparation_s(values: Mapping[str, Any], knobs: tuple[str, ...]) -> float:
    """The modes companion's own reduction [s], estimated."""
    return estimate_mesh(*_plate(values), richer_modes(values["modes"])).build_time_s


@dataclass(frozen=True)
class Knob:
    """One discretization knob (see the module's contract)."""

    name: str
    term: str
    key: str
    what: str
    finer: Callable[[Any], Any]
    limit: Any = None
    #: where its finer companion cannot run, a coarser one's difference taken whole
    fallback: bool = False
    scene_keys: tuple[str, ...] = ()
    ratio: float = 2.0
    order: int | None = 2
    per_headline_order: bool = False
    prior_fall: float = 4.0
    preparation_s: Callable[[Mapping[str, Any], tuple[str, ...]], float] = _no_preparation
    auto: AutoRule | None = None
    #: how a turn is written for one link (``{link}``, ``{old}``, ``{new}``), and the verb of
    #: a turn
    change_text: str = "{link} {old:g} -> {new:g}"
    moved_text: str = "{link}"
    verb: str = ""
    #: how a run's settings name its value (``{value}``)
    text: str = "{value}"
    #: the budget's sentence on its companion (``{how}``: the changes; ``{factor}``)
    sentence: str = ""

    @property
    def per_link(self) -> bool:
        """Whether it is a link's knob (its key has ``{link}``), not the scene's."""
        return "{link}" in self.key

    def scene_key(self, link: str = "") -> str:
        """Its ``section.key`` for ``link`` (a link knob) or the scene's."""
        return self.key.format(link=link)

    def link_key(self) -> str:
        """The key under ``[<link>]`` a link knob sets (``"modes"``)."""
        return self.key.split(".", 1)[1]

    def value(self, scene: Scene, link: str = "") -> Any:
        """Its value in ``scene`` (for ``link``)."""
        section, key = self.scene_key(link).split(".")
        return scene[section][key]

    def turned(self, scene: Scene, link: str = "") -> Any | None:
        """Its value one turn finer in ``scene`` (None: beyond its ``limit``)."""
        new = self.finer(self.value(scene, link))
        return None if self.limit is not None and new > self.limit else new

    def override(self, link: str, value: Any) -> str:
        """The ``--set`` override that gives it ``value`` (for ``link``)."""
        return f"{self.scene_key(link)}={value!r}"

    def factor(self, mesh_order: int = 2) -> float:
        """Its companion's difference over the run's error (Richardson, ``r^p / (r^p - 1)``
        with ``mesh_order`` as p where :attr:`per_headline_order`; 1: taken whole)."""
        order = mesh_order if self.per_headline_order else self.order
        if order is None:
            return 1.0
        grown = self.ratio ** order
        return grown / (grown - 1.0)


#: the step: halved, at the integrator's order (the step term itself is measured by
#: :mod:`flex.fidelity.error_estimate`, which observes the order on a second companion)
STEP = Knob("step", "step", "simulation.step_s", "step", lambda step: step / 2,
            verb="step halved", text="step {value:g} s")
#: a reduction's modes: raised as the modes companion's; modal convergence is fast, so the
#: richer basis is taken as converged and its difference whole
MODES = Knob("modes", "modes", "{link}.modes", "modes", richer_modes, limit=100,
             scene_keys=("mode_selection",), order=None, preparation_s=_modes_preparation_s,
             auto=_rule_modes, change_text="{link} {old} -> {new}", moved_text="{link} {old} "
             "-> {new}", verb="modes raised", text="{value} modes",
             sentence="difference to a companion with more modes ({how})")
#: a meshed plate's element size: halved, extrapolated with each quantity's mesh order (2 for
#: deflections and the motion, 1 for stresses; measured on the 2 mm plate's deployment peak
#: at 8, 4 and 2 mm meshes: observed order 4.1, so 2 leans safe)
MESH = Knob("mesh", "mesh", "{link}.mesh_size_m", "mesh", lambda size: size / 2,
            per_headline_order=True, fallback=True, preparation_s=_mesh_preparation_s,
            auto=_rule_mesh,
            change_text="{link} {old:g} -> {new:g} m", verb="mesh halved",
            text="mesh {value:g} m",
            sentence="difference to a companion on a 2x finer mesh ({how}), extrapolated with "
                     "each quantity's mesh order (2: deflections and the motion, 1: stresses)")
#: a beam's elements: doubled, at the beam's order 2 (tests/test_exact_beam.py: 2.0 on the
#: pinned-pinned frequency, 1.98 on the first crest of the deployment; a companion with fewer
#: elements would put the racing peak of a coarse beam in the term)
ELEMENTS = Knob("elements", "mesh", "{link}.elements", "beam elements", lambda count: 2 * count,
                limit=SCHEMA["coupler"]["elements"].maximum, auto=_beam_elements,
                change_text="{link} {old} -> {new}", moved_text="{link} elements doubled",
                verb="mesh refined", text="{value} elements",
                sentence="difference to a companion with more beam elements ({how}) x "
                         "{factor:.3g} (order 2)")

#: every knob, by name, in the order budgets and settings name them
KNOBS: Mapping[str, Knob] = MappingProxyType({knob.name: knob for knob in (STEP, MODES, MESH,
                                                                          ELEMENTS)})
#: the link knobs, in that order
LINK_KNOBS: tuple[Knob, ...] = tuple(knob for knob in KNOBS.values() if knob.per_link)
#: the model term's knob: the link a refinement may climb the ladder with
MODEL_KEY = "coupler.model"
#: every scene key a refinement may turn
KNOB_KEYS: tuple[str, ...] = (STEP.scene_key(), MODEL_KEY, *(
    knob.scene_key(link) for knob in LINK_KNOBS for link in LINKS))
#: what a budget says for a term no link has a knob of, and refinement when none can turn
NO_KNOB = {"modes": ("no FFRF link (no modes)",
                     "the modes term dominates and no link can take more modes"),
           "mesh": ("no meshed link", "the mesh term dominates and no link is meshed")}


def knobs_of(entry: Any) -> tuple[Knob, ...]:
    """The link knobs a model's registry entry names (:attr:`LinkSchema.knobs`), in order."""
    return tuple(knob for knob in LINK_KNOBS if knob.name in entry.knobs)


def linked_knobs(scene: Scene, link_models: Mapping[str, Any], term: str | None = None
                 ) -> list[tuple[Knob, list[str]]]:
    """The link knobs of ``scene``'s concrete models (of ``term`` only, if given), each with
    the links that have it, in :data:`LINK_KNOBS`' order."""
    out = []
    for knob in LINK_KNOBS:
        links = [link for link in LINKS if knob.name in link_models[scene[link]["model"]].knobs]
        if links and (term is None or knob.term == term):
            out.append((knob, links))
    return out


def reads_key(entry: Any, key: str) -> bool:
    """Whether a model's entry reads the link key ``key`` through its knobs (a knob's own key
    or one it brings) or its ``reads``."""
    return key in entry.reads or any(key == knob.link_key() or key in knob.scene_keys
                                     for knob in knobs_of(entry))


def auto_value(knob: Knob, scene: Scene, link: str, calibration: Calibration | None) -> Any:
    """``knob``'s value for ``link`` from ``scene``'s ``fidelity.tolerance`` (its ``auto``)."""
    return knob.auto(scene, link, Tolerance.of(scene).relative, calibration)


def preparation_s(scene: Scene, link_models: Mapping[str, Any]) -> float:
    """What ``scene``'s links cost to prepare at their knobs' values [s] (estimate)."""
    cost = 0.0
    for link in LINKS:
        entry = link_models[scene[link]["model"]]
        for knob in knobs_of(entry):
            cost += knob.preparation_s(scene[link], entry.knobs)
    return cost


def settings_text(scene: Scene, link_models: Mapping[str, Any]) -> str:
    """A run's settings in a few words: its step, and each link's model and knobs."""
    parts = [STEP.text.format(value=STEP.value(scene))]
    for link in LINKS:
        entry = link_models[scene[link]["model"]]
        knobs = knobs_of(entry)
        if knobs:
            parts.append(", ".join([f"{link} {scene[link]['model']}"] + [
                knob.text.format(value=knob.value(scene, link)) for knob in knobs]))
    return "; ".join(parts)


__all__ = ["ELEMENTS", "EXACT_BEAM_SETTINGS", "EXPLICIT_ORDERS", "KNOBS", "KNOB_KEYS",
           "LINK_KNOBS", "MESH", "MODEL_KEY", "MODES", "NO_KNOB", "STEP", "Knob",
           "auto_value", "exact_beam_settings", "integrator_order", "knobs_of",
           "linked_knobs", "preparation_s", "reads_key", "richer_modes", "settings_text"]
