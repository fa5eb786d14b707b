"""The error budget of a run: what separates each headline quantity from the truth that
flex can know, term by term, in the quantity's unit and relative to it.

Contract of :func:`error_budget`: given a finished run of a concrete scene (links rigid,
ffrf, nonlinear_fe or exact_beam; ``"auto"`` keys resolved) and a way to run companion
scenes, it returns an :class:`ErrorBudget` with, for each headline quantity of the run
(:data:`flex.fidelity.error_estimate.HEADLINES`: crank angle and slider position at the end
time, deployment time, peak joint forces, each flexible link's peak midpoint deflection and
peak bending stress), four named terms and their total [the quantity's units]:

- ``step``: the time step, by Richardson extrapolation over companions at 2 h and 4 h (or
  h / 2) (:func:`flex.fidelity.error_estimate.estimate_step_error`);
- ``modes``: the modal truncation of the FFRF links: the difference to a companion whose
  FFRF links keep :func:`richer_modes` modes (the richer basis taken as converged: modal
  convergence is fast, so the difference is the run's truncation error);
- ``mesh``: the mesh of the FFRF links: the difference to a companion on a mesh
  :data:`MESH_FACTOR` times coarser, taken whole (first order assumed: the peak stress from
  the nodes converges about that slowly, the deflection faster, so the term leans safe); a
  beam link's elements: the difference to a companion with :data:`MESH_FACTOR` times more,
  extrapolated with the beam's order :data:`BEAM_ORDER` (measured on its frequency and its
  first crest; a companion with fewer elements would put the racing peak of a coarse beam
  in the term);
- ``model``: the link model against the next rung of flex's ladder (rigid, linear FFRF,
  FFRF with geometric stiffness, nonlinear FE). An FFRF link with geometric stiffness: its
  measured error against the nonlinear FE coupler as a fraction of what the elasticity
  changes in the quantity (the difference to a companion whose flexible links are rigid
  twins): :data:`flex.fidelity.criteria.GEOMETRIC_FFRF_ERROR` of the link's own peak
  deflection and stress (``make ladder``), :data:`flex.fidelity.criteria.
  FFRF_MOTION_ERROR_FRACTION` of the elastic part of the motion and the joint forces (``make
  flexible``); a linear FFRF link (``geometric_stiffness = false``) adds its difference to
  a companion with geometric stiffness; a nonlinear FE link is the top rung (no term);
  rigid links: not estimated here (the ``auto`` decision predicts a rigid link's deflection
  error, ``fidelity_*``).

``total`` is the root-sum-square of the terms: they come from independent directions of
refinement (step, basis, mesh, model), whose errors add with unknown signs (the practice of
the GUM for independent components; ``make estimates`` measured the plain sum 3-30x
pessimistic on most FFRF quantities, the root-sum-square never optimistic by more than 1.5x);
``relative`` is the total over the quantity's magnitude. What no term
covers is said in :attr:`ErrorBudget.leaves_out`. Companions that fail leave their term out
and say why. :meth:`ErrorBudget.attrs` are the case attributes ``estimated_error_*``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from flex.base.errors import FlexError
from flex.data.results import CaseResult
from flex.data.scene import Scene, apply_overrides, model_names
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel
from flex.fidelity.criteria import FFRF_MOTION_ERROR_FRACTION, GEOMETRIC_FFRF_ERROR
from flex.fidelity.error_estimate import (
    HEADLINES,
    PEAK_PATHS,
    PREFIX,
    crest_gap,
    estimate_step_error,
    headline_difference,
)

#: the named terms of a budget, in the order they are printed
TERMS = ("step", "modes", "mesh", "model")
#: the mesh companion's element size over the run's (a beam companion: its elements over the
#: run's)
MESH_FACTOR = 2.0
#: order of convergence of a beam link under element refinement (tests/test_exact_beam.py:
#: 2.0 on the pinned-pinned frequency, 1.98 on the first crest of the deployment)
BEAM_ORDER = 2
#: case attribute prefix of a headline quantity's value
HEADLINE_PREFIX = "headline_"
LINKS = ("crank", "coupler")


def richer_modes(modes: int) -> int:
    """The modes companion's count for a link with ``modes``: twice as many, at least two
    more (1 -> 3, 2 -> 4, 6 -> 12)."""
    return int(modes + max(modes, 2))


@dataclass
class ErrorBudget:
    """A run's error budget (see the module doc): ``terms[quantity][term]`` [its units],
    ``values[quantity]`` (the run's value), one sentence per term in ``methods``, what the
    budget leaves out, the step estimate's ``validity`` and the companions' wall time."""

    values: dict[str, float] = field(default_factory=dict)
    terms: dict[str, dict[str, float]] = field(default_factory=dict)
    methods: dict[str, str] = field(default_factory=dict)
    leaves_out: list[str] = field(default_factory=list)
    validity: str = ""
    companion_wall_time_s: float = 0.0
    #: a peak deflection's crest gap [m]: the second-largest crest's distance below it
    crest_gaps: dict[str, float] = field(default_factory=dict)

    def total(self, quantity: str) -> float:
        """The root-sum-square of the quantity's terms [its units] (module doc)."""
        return combined(self.terms[quantity].values())

    def relative(self, quantity: str) -> float:
        """The total over the quantity's magnitude (NaN for a zero quantity)."""
        value = abs(self.values[quantity])
        return self.total(quantity) / value if value > 0 else math.nan

    def attrs(self) -> dict[str, Any]:
        """Case attributes: ``headline_<quantity>`` (the run's value, in the unit its name
        ends with), ``estimated_error_<quantity>`` (the total, same unit), ``..._<term>``
        per term, ``..._relative``; ``estimated_error_method`` (one sentence per term),
        ``_leaves_out``, ``_validity``, ``_companion_wall_time_s``."""
        out: dict[str, Any] = {}
        for quantity, terms in self.terms.items():
            out[f"{HEADLINE_PREFIX}{quantity}"] = self.values[quantity]
            out[f"{PREFIX}{quantity}"] = self.total(quantity)
            out[f"{PREFIX}{quantity}_relative"] = self.relative(quantity)
            out.update({f"{PREFIX}{quantity}_{term}": value for term, value in terms.items()})
        out.update({f"{PREFIX}method": "; ".join(f"{term}: {text.rstrip('.')}" for term, text
                                                 in self.methods.items()) + ".",
                    f"{PREFIX}leaves_out": "; ".join(self.leaves_out) or "nothing flex knows of",
                    f"{PREFIX}validity": self.validity,
                    f"{PREFIX}companion_wall_time_s": self.companion_wall_time_s})
        out.update({f"{CREST_GAP_PREFIX}{quantity}": gap
                    for quantity, gap in self.crest_gaps.items()})
        return out


def combined(terms: Any) -> float:
    """The total of independent error terms: their root-sum-square [their units]."""
    return float(math.sqrt(math.fsum(value * value for value in terms)))


#: the headline quantities of a link's own elastic response (their model term is
#: GEOMETRIC_FFRF_ERROR of the quantity); the others are quantities of the motion
OWN = ("_peak_deflection_m", "_peak_bending_stress_Pa", "_peak_von_mises_Pa",
       "_first_crest_deflection_m")
#: case attribute prefix of a peak's crest gap (:func:`flex.fidelity.error_estimate.crest_gap`)
CREST_GAP_PREFIX = "crest_gap_"


def _links(scene: Scene, link_models: Mapping[str, LinkModel], **flags: bool) -> list[str]:
    """The links whose models have the given flags (``modal=True``: the FFRF links)."""
    return [link for link in LINKS
            if all(getattr(link_models[scene[link]["model"]], flag) == value
                   for flag, value in flags.items())]


def _companion(scene: Scene, overrides: list[str]) -> Scene:
    return apply_overrides(scene, [*overrides, "simulation.output_step_s=0.0",
                                   "simulation.error_estimate=false"])


def _differences(result: CaseResult, other: CaseResult | None) -> dict[str, float]:
    """Each headline quantity's difference between ``result`` and ``other`` (0 for a
    quantity ``other`` lacks where ``result`` has it, e.g. a rigid twin's stress)."""
    if other is None:
        return {}
    out = {}
    for name in HEADLINES:
        difference = headline_difference(name, result.datasets, other.datasets)
        if difference is not None:
            out[name] = difference
    return out


class _Companions:
    """Runs companion scenes, timing them and keeping what failed."""

    def __init__(self, run_companion: Callable[[Scene], CaseResult]) -> None:
        self.run_companion = run_companion
        self.failures: list[str] = []
        self.wall_time_s = 0.0

    def run(self, what: str, scene: Scene) -> CaseResult | None:
        start = time.perf_counter()
        try:
            return self.run_companion(scene)
        except FlexError as exc:
            self.failures.append(f"{what}: the companion run failed ({exc})")
            return None
        finally:
            self.wall_time_s += time.perf_counter() - start


def _modes_term(scene: Scene, result: CaseResult, companions: _Companions,
                link_models: Mapping[str, LinkModel]) -> tuple[dict[str, float], str]:
    ffrf = _links(scene, link_models, modal=True)
    if not ffrf:
        return {}, "no FFRF link (no modes)"
    changes = {link: richer_modes(int(scene[link]["modes"])) for link in ffrf}
    richer = companions.run("modes", _companion(scene, [f"{link}.modes={modes}" for link, modes
                                                        in changes.items()]))
    how = ", ".join(f"{link} {scene[link]['modes']} -> {modes}" for link, modes in
                    changes.items())
    return _differences(result, richer), f"difference to a companion with more modes ({how})"


def _mesh_term(scene: Scene, result: CaseResult, companions: _Companions,
               link_models: Mapping[str, LinkModel]) -> tuple[dict[str, float], str]:
    meshed = [link for link in _links(scene, link_models, meshed=True)
              if scene[link]["geometry"] == "plate"]
    beams = _links(scene, link_models, beam=True)
    if not (meshed or beams):
        return {}, "no meshed link"
    terms: dict[str, float] = {}
    sentences = []
    if meshed:
        sizes = {link: min(MESH_FACTOR * float(scene[link]["mesh_size_m"]),
                           float(scene[link]["length_m"])) for link in meshed}
        coarser = companions.run("mesh", _companion(
            scene, [f"{link}.mesh_size_m={size!r}" for link, size in sizes.items()]))
        terms = _differences(result, coarser)
        how = ", ".join(f"{link} {scene[link]['mesh_size_m']:g} -> {size:g} m"
                        for link, size in sizes.items())
        sentences.append(f"difference to a companion on a {MESH_FACTOR:g}x coarser mesh "
                         f"({how}), taken whole")
    if beams:
        counts = {link: int(MESH_FACTOR * int(scene[link]["elements"])) for link in beams}
        finer = companions.run("mesh", _companion(
            scene, [f"{link}.elements={count}" for link, count in counts.items()]))
        factor = MESH_FACTOR**BEAM_ORDER / (MESH_FACTOR**BEAM_ORDER - 1)  # Richardson
        for name, value in _differences(result, finer).items():
            terms[name] = terms.get(name, 0.0) + factor * value
        how = ", ".join(f"{link} {scene[link]['elements']} -> {count}"
                        for link, count in counts.items())
        sentences.append(f"difference to a companion with more beam elements ({how}) x "
                         f"{factor:.3g} (order {BEAM_ORDER})")
    return terms, "; ".join(sentences)


def _model_term(scene: Scene, result: CaseResult, companions: _Companions,
                leaves_out: list[str], link_models: Mapping[str, LinkModel]
                ) -> tuple[dict[str, float], str]:
    # the measured model error of the linear-elastic (FFRF) links: make ladder, make flexible
    ffrf = _links(scene, link_models, linear_elastic=True)
    sentences, terms = [], {}
    if ffrf:
        twin = companions.run("model", _companion(
            scene, [f'{link}.model="{model_names(link, link_models, rigid=True)[0]}"'
                    for link in ffrf]
            + [f'{link}.geometry="plate"' for link in ffrf]))
        elastic = _differences(result, twin)
        terms = {name: (GEOMETRIC_FFRF_ERROR if name.endswith(OWN)
                        else FFRF_MOTION_ERROR_FRACTION) * value
                 for name, value in elastic.items()}
        sentences.append(f"FFRF with geometric stiffness against the nonlinear FE coupler: "
                         f"{GEOMETRIC_FFRF_ERROR:g} of a link's own peak deflection and "
                         f"stress (make ladder), {FFRF_MOTION_ERROR_FRACTION:g} of what the "
                         f"elasticity changes in the motion and the joint forces (make "
                         f"flexible; the difference to rigid twins)")
        linear = [link for link in ffrf if not scene[link]["geometric_stiffness"]]
        if linear:
            stiffened = companions.run("model", _companion(
                scene, [f"{link}.geometric_stiffness=true" for link in linear]))
            for name, value in _differences(result, stiffened).items():
                terms[name] = terms.get(name, 0.0) + value
            sentences.append(f"linear FFRF ({', '.join(linear)}): plus the difference to a "
                             f"companion with geometric stiffness")
    if _links(scene, link_models, reference=True):
        leaves_out.append("the nonlinear FE coupler's own model error (the top rung: "
                          "St. Venant-Kirchhoff continuum, deformable joint faces)")
    beams = _links(scene, link_models, beam=True)
    if beams:
        leaves_out.append(f"the beam model error of the {' and '.join(beams)} (a "
                          "geometrically exact beam: plane sections, pins at the section "
                          "centres; not measured against the nonlinear FE coupler here)")
    rigid = _links(scene, link_models, rigid=True)
    if rigid:
        leaves_out.append(f"the elasticity of the rigid {' and '.join(rigid)} (predicted by "
                          f"model = \"auto\", fidelity_* attributes)")
    return terms, "; ".join(sentences) or "no flexible link below the top rung"


def error_budget(scene: Scene, result: CaseResult,
                 run_companion: Callable[[Scene], CaseResult],
                 time_scales: list[tuple[float, float, str]],
                 link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> ErrorBudget:
    """The error budget of ``result``, the run of ``scene`` (concrete models, solver keys
    resolved), from companion runs made by ``run_companion`` (see the module doc);
    ``time_scales``: the scene's (:func:`flex.dynamics.solver.time_scales`);
    ``link_models``: the registry of its link models (their flags choose the terms)."""
    values = {name: read(result.datasets) for name, (_, _, read) in HEADLINES.items()}
    values = {name: value for name, value in values.items() if value is not None}
    step = estimate_step_error(scene, result, run_companion, time_scales)
    companions = _Companions(run_companion)
    leaves_out = ["the spring's and joints' idealizations (massless spring unless chained, "
                  "ideal pins)"]
    modes, modes_how = _modes_term(scene, result, companions, link_models)
    mesh, mesh_how = _mesh_term(scene, result, companions, link_models)
    model, model_how = _model_term(scene, result, companions, leaves_out, link_models)
    failed = {failure.split(":")[0] for failure in companions.failures}
    if not step.values:
        failed.add("step")
    leaves_out += companions.failures
    if "step" in failed:
        leaves_out.append(f"step: {step.validity}")
    terms = {}
    for name in values:
        terms[name] = {"step": step.values.get(name, 0.0), "modes": modes.get(name, 0.0),
                       "mesh": mesh.get(name, 0.0), "model": model.get(name, 0.0)}
        for term in failed:
            terms[name].pop(term, None)
    methods = {"step": step.method, "modes": modes_how, "mesh": mesh_how, "model": model_how}
    return ErrorBudget(values, terms, {k: v for k, v in methods.items() if k not in failed},
                       leaves_out, step.validity,
                       step.companion_wall_time_s + companions.wall_time_s,
                       _crest_gaps(result, values))


def _crest_gaps(result: CaseResult, values: dict[str, float]) -> dict[str, float]:
    """Each peak deflection's crest gap [m] (the peak races between crests when its error
    exceeds it; the first crest does not)."""
    out = {}
    for name in values:
        if name.endswith("_peak_deflection_m"):
            gap = crest_gap(result.datasets[PEAK_PATHS[name]].data)
            if gap is not None:
                out[name] = gap
    return out


@dataclass(frozen=True)
class BudgetRow:
    """One headline quantity of a stored case, for display: its name, what it is, units,
    value, total estimated error, relative error and the terms (from the case
    attributes)."""

    quantity: str
    what: str
    units: str
    value: float
    total: float
    relative: float
    terms: dict[str, float]

    def text(self) -> str:
        """``what: value units +- total (relative %) = rss of step a, modes b, ...``."""
        relative = (f" ({100 * self.relative:.2g} %)" if math.isfinite(self.relative)
                    else "")
        terms = ", ".join(f"{term} {value:.2g}" for term, value in self.terms.items())
        return (f"{self.what}: {self.value:.6g} {self.units} +- {self.total:.2g} "
                f"{self.units}{relative} (root-sum-square of {terms})")


def budget_rows(attrs: dict[str, Any]) -> list[BudgetRow]:
    """The stored error budget of a case (its attributes; see :meth:`ErrorBudget.attrs`),
    one row per headline quantity it holds, in :data:`HEADLINES` order. A file written
    before budgets (a step estimate alone) gives rows with that one term."""
    rows = []
    for quantity, (units, what, _) in HEADLINES.items():
        if f"{PREFIX}{quantity}" not in attrs:
            continue
        terms = {term: float(attrs[f"{PREFIX}{quantity}_{term}"]) for term in TERMS
                 if f"{PREFIX}{quantity}_{term}" in attrs} or {
            "step": float(attrs[f"{PREFIX}{quantity}"])}
        value = float(attrs.get(f"{HEADLINE_PREFIX}{quantity}", math.nan))
        total = float(attrs[f"{PREFIX}{quantity}"])
        rows.append(BudgetRow(quantity, what, units, value, total,
                              float(attrs.get(f"{PREFIX}{quantity}_relative", math.nan)),
                              terms))
    return rows


__all__ = ["BudgetRow", "ErrorBudget", "HEADLINE_PREFIX", "MESH_FACTOR", "TERMS",
           "budget_rows", "combined", "error_budget", "richer_modes"]
