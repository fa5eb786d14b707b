"""The model ladder, as data: each link model's rung, what bounds its error against the rung
above, what that leaves out, and what ``auto`` and the refinement may do with it.

A link model's registry entry says its rung (:attr:`flex.dynamics.link_models.LinkModel.rung`,
a function of the link's scene values: the FFRF model is the linear rung without geometric
stiffness); the callers read the rungs and name no model:

- the error budget's ``model`` term (:mod:`flex.fidelity.error_budget`): a link on a
  *bounded* rung gets ``own_fraction`` of what its elasticity changes in its own quantities
  and ``motion_fraction`` of what it changes in the motion (the difference to a companion
  whose bounded links are rigid twins), plus the difference to the rung's ``companion``
  (overrides one step up, e.g. geometric stiffness on); every other rung adds its
  ``leaves_out`` line;
- ``auto``'s climb (:func:`climb`): past rigid, the lowest rung ``auto`` may take whose
  ``bound`` meets the tolerance, else the highest;
- the refinement's model knob (:func:`next_rung`): the next rung up that refinement may take;
- the readers of stored motion read the entry's ``motion`` (the contract's point 9).

The levels order the rungs (higher: closer to the truth); the numbers are the measured
bounds of ``make ladder`` and ``make flexible`` (docs/geometric-stiffness.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from flex.config.tolerance import Tolerance


@dataclass(frozen=True)
class Rung:
    """One rung of the ladder (see the module doc); fractions are relative [1]."""

    #: its place: higher is closer to the truth
    level: int
    #: how reasons and budgets name it
    name: str
    #: its model error against the rung above relative to the link's own peak deflection,
    #: given the link's scene values and the rigid probe's compression / Euler load (what
    #: ``auto`` climbs on); None: no bound (a rigid link: its elasticity is predicted from
    #: its loads; the top rung)
    bound: Callable[[Mapping[str, Any], float, Path | None], float] | None = None
    #: the budget's model term: fractions of what the elasticity changes in the link's own
    #: quantities (a number, or a function of the link's scene values) and in the motion
    own_fraction: float | Callable[[Mapping[str, Any], Path | None], float] = 0.0
    motion_fraction: float = 0.0
    #: overrides (``{link}`` stands for the link) of a companion one step up whose
    #: difference the model term adds, and the sentence that says so (``{links}``)
    companion: tuple[str, ...] = ()
    companion_text: str = ""
    #: the budget's sentence on how the term was measured
    measured_by: str = ""
    #: a companion one rung up that measures the model term on the run's own scene: the
    #: overrides (``{link}`` for the link) for a scene's resolved values; the term is then the
    #: companion's difference, not the fractions (None: the fractions)
    measured_against: Callable[[Mapping[str, Any]], tuple[str, ...]] | None = None
    measured_against_text: str = ""
    #: a second ``measured_against`` companion, coarser (overrides as there): the term is then
    #: the difference to the two extrapolated (Richardson at each quantity's ``mesh_order``)
    #: plus the extrapolation's size, the companion's own error (None: one companion, its
    #: difference whole)
    measured_against_coarser: Callable[[Mapping[str, Any]], tuple[str, ...]] | None = None
    #: a third, coarser still (overrides as there): where the three show the quantity's order,
    #: the extrapolation's size is how far the two Richardson limits lie apart, not the finer
    #: companion's own error (None: two companions)
    measured_against_coarsest: Callable[[Mapping[str, Any]], tuple[str, ...]] | None = None
    #: the ``measured_against`` companion resolves the link's own knobs (an FFRF body's
    #: modes and mesh: the exact beam has neither), so its difference holds their errors
    #: too: the budget measures them apart only when that difference is a sizable share of
    #: the tolerance (:mod:`flex.fidelity.error_budget`)
    resolves_knobs: bool = False
    #: what a budget leaves out for links on this rung (``{links}``)
    leaves_out: str = ""
    #: ``auto`` may climb onto it; the refinement may climb onto it
    auto: bool = True
    refine: bool = True
    #: the largest compression / Euler load at which a run's budget may use its bound (a
    #: run compressed beyond it gets an unknown model term on its link's own quantities)
    measured_load_ratio: float = math.inf

    @property
    def bounded(self) -> bool:
        """Its model error is bounded by measured fractions (the budget's model term)."""
        return self.bound is not None

    def own(self, values: Mapping[str, Any], cache_dir: Path | None = None) -> float:
        """Its own fraction [1] for a link's scene ``values``."""
        return (self.own_fraction(values, cache_dir) if callable(self.own_fraction)
                else self.own_fraction)


GEOMETRIC_FFRF_ERROR = 0.005
"""The FFRF rungs' model errors relative to the quantity, measured by ``make ladder``
(thesis deployment, steel plates 0.5-10 mm, peak elastic midpoint deflection against the
nonlinear FE coupler's, docs/geometric-stiffness.md): the FFRF coupler (chord frame, with
the geometric stiffness of its axial force, flex's default) stayed within 0.35 % (largest at
0.5-0.7 mm and at 10 mm, where both FFRF bodies differ alike from the nonlinear FE one: the
rigid end faces), bounded by ``GEOMETRIC_FFRF_ERROR``; the linear FFRF coupler
(``geometric_stiffness = false``) below ``LINEAR_FFRF_ERROR_FLOOR + LINEAR_FFRF_ERROR_PER_LOAD
x`` (x the rigid probe's compression / Euler load; measured 0.32 % at x = 1e-4, 0.53 % at
0.0076, 3.2 % at 0.049, 13 % at 0.13, 16 % at 0.20, 18 % at 0.33)."""
LINEAR_FFRF_ERROR_FLOOR = 0.005
LINEAR_FFRF_ERROR_PER_LOAD = 1.0

FFRF_MOTION_ERROR_FRACTION = 0.15
"""The FFRF body's error against the nonlinear FE coupler on the quantities of the motion
(crank angle and slider position at the end time, peak joint forces, deployment time), as a
fraction of what the link's elasticity changes in them (the FFRF run against its rigid twin),
measured by ``make flexible`` against the nonlinear FE coupler (1-10 mm plates over the
reference's first 2.5-5 ms): up to 0.13 on the joint forces' peaks (the axial ringing the
reduced body represents with one axial mode), up to 0.16 on the crank angle. Since issue 50
``make flexible`` holds the runs against the stored exact-beam references over the whole
deployment instead and prints the fractions it finds there (headline values on the
deployment's channel; larger on the joint forces' deployment peaks, 0.2-0.43 measured, where
the exact beam's axial ringing is the other model's): this bound is not refitted to them."""


#: the largest compression / Euler load at which the FFRF bodies' bounds were measured (the
#: 0.5 mm plate on the thesis spring, make ladder); beyond it they have none (the body's
#: geometric stiffness is linearized: it does not represent buckling)
FFRF_MEASURED_LOAD_RATIO = 0.33


def _geometric_ffrf_bound(values: Mapping[str, Any], load_ratio: float,
                          cache_dir: Path | None = None) -> float:
    return GEOMETRIC_FFRF_ERROR if load_ratio <= FFRF_MEASURED_LOAD_RATIO else math.inf


def _linear_ffrf_bound(values: Mapping[str, Any], load_ratio: float,
                       cache_dir: Path | None = None) -> float:
    if load_ratio > FFRF_MEASURED_LOAD_RATIO:
        return math.inf
    return LINEAR_FFRF_ERROR_FLOOR + LINEAR_FFRF_ERROR_PER_LOAD * load_ratio


_FFRF_MEASURED_BY = (
    f"FFRF with geometric stiffness against the nonlinear FE coupler: "
    f"{GEOMETRIC_FFRF_ERROR:g} of a link's own peak deflection and stress (make ladder), "
    f"{FFRF_MOTION_ERROR_FRACTION:g} of what the elasticity changes in the motion and the "
    f"joint forces (make flexible; the difference to rigid twins)")

#: the exact beam companions that measure a link's model term (an FFRF body's, a rigid
#: plate's), sized to the tolerance. Rows: (tolerance at or above, elements, step at most
#: [s]), tightest last; an FFRF body's term also runs a second companion at half the elements
#: (:data:`COARSER_COMPANION_DIVISOR`) and extrapolates the two (Richardson at the quantity's
#: order, :attr:`flex.data.headlines.Headline.mesh_order`), adding the extrapolation's size.
#: Measured against 256 elements at 2.5e-6 s (thesis deployment, 30 ms): 32 elements at
#: 2e-5 s 0.30 / 0.21 / 0.15 % (0.7 / 1 / 3 mm; 0.3 s), 64 at 2e-5 s 0.07 / 0.04 / 0.03 %
#: (0.5-0.7 s), 128 at 1e-5 s 0.011 / 0.006 / 0.001 % (2-2.5 s); at 4e-5 s the 3 mm plate's
#: step error reached 0.37 %. Against the stored references (8 FFRF scenes of make estimates
#: at 1 %, the deployment peak deflection and first crest): 32 elements with a fixed own-error
#: bound of 0.33 % made the term 6-60x the FFRF's true error (0.01-0.3 %); 64 and 32
#: extrapolated brought the pairs the references decide to 0.5-0.8 of it, the joint forces'
#: and stresses' within 0.5-1.2 (``/tmp/s12/comp.py`` in session 12's note). 64 alone (no
#: extrapolation, a fixed bound) had let 8 certificates fall below the truth.
EXACT_BEAM_COMPANIONS = ((0.003, 64, 2e-5), (0.0, 128, 1e-5))
"""Rows (tolerance at or above, elements, step at most [s]): the finer companion's."""
#: the second, coarser companion's elements: the finer one's over this
COARSER_COMPANION_DIVISOR = 2


def exact_beam_companion(tolerance: float) -> tuple[int, float]:
    """The exact beam companion's elements and largest step [s] at ``tolerance`` [1]: the
    first row of :data:`EXACT_BEAM_COMPANIONS` it reaches."""
    return next((elements, step) for floor, elements, step in EXACT_BEAM_COMPANIONS
                if tolerance >= floor)


def _against_exact_beam(scene: Mapping[str, Any], divisor: int = 1) -> tuple[str, ...]:
    """A scene's overrides that put a link on the exact beam rung, sized to the scene's
    tolerance (:func:`exact_beam_companion`), at the run's step or the companion's, whichever
    is finer (the companion's: the largest that divides the run's end time, so it ends where
    the run does; the budget compares the curves interpolated, not sample by sample); its
    elements over ``divisor``."""
    elements, step_s = exact_beam_companion(Tolerance.of(scene).relative)
    elements //= divisor
    run_step_s = float(scene["simulation"]["step_s"])
    end_s = float(scene["simulation"]["end_time_s"])
    if step_s < run_step_s:
        step_s = end_s / math.ceil(end_s / step_s - 1e-9)
    step_s = min(step_s, run_step_s, end_s)
    return ('{link}.model="exact_beam"', f"{{link}}.elements={elements}",
            f"simulation.step_s={step_s!r}")


def _against_coarser_beam(scene: Mapping[str, Any]) -> tuple[str, ...]:
    """:func:`_against_exact_beam` with :data:`COARSER_COMPANION_DIVISOR` times fewer
    elements, at the same step: the pair the model term extrapolates."""
    return _against_exact_beam(scene, COARSER_COMPANION_DIVISOR)


def _against_coarsest_beam(scene: Mapping[str, Any]) -> tuple[str, ...]:
    """:func:`_against_exact_beam` with :data:`COARSER_COMPANION_DIVISOR` squared times fewer
    elements, at the same step: the third level, which observes the elements' order."""
    return _against_exact_beam(scene, COARSER_COMPANION_DIVISOR ** 2)


_AGAINST_EXACT_BEAM_TEXT = (
    "FFRF ({links}): the difference to the geometrically exact beam, calibrated on the plate "
    "(the rung above, on the same scene: the difference holds the FFRF body's modes, mesh and "
    "step errors), extrapolated from two companions (the beam's elements halved, Richardson "
    "at each quantity's order: 2 for a displacement or the motion, 1 for a stress), plus the "
    "extrapolation's size (its sign unknown: where a third companion, the elements halved "
    "again, shows the quantity's order within 0.5, how far the two levels' limits lie apart, "
    "else the finer companion's own error); the beam's own step error, common to both, and "
    "its measured idealization are not in it")

#: a rigid plate link: its elasticity is measured on the run's own scene, the difference to a
#: companion whose link is the geometrically exact beam (the rung the rigid model leaves out
#: for a plate: what its elasticity changes in every quantity, the motion's included)
RIGID_RUNG = Rung(0, "rigid", measured_against=_against_exact_beam,
                  measured_against_text="rigid ({links}): the difference to a companion whose "
                  "{links} is the geometrically exact beam (the elasticity the rigid model "
                  "leaves out, measured on the scene)")
#: a rigid lumped link (a mass and an inertia, no plate): its elasticity is unknown
LUMPED_RIGID_RUNG = Rung(0, "rigid (lumped)", leaves_out="the elasticity of the lumped rigid "
                         "{links} (a mass and an inertia: no plate to bend)")
#: the FFRF body without geometric stiffness: softens wrongly under compression
LINEAR_FFRF_RUNG = Rung(
    1, "linear FFRF (geometric_stiffness = false)", _linear_ffrf_bound, GEOMETRIC_FFRF_ERROR,
    FFRF_MOTION_ERROR_FRACTION, ("{link}.geometric_stiffness=true",),
    "linear FFRF ({links}): plus the difference to a companion with geometric stiffness",
    _FFRF_MEASURED_BY, measured_against=_against_exact_beam,
    measured_against_text="linear " + _AGAINST_EXACT_BEAM_TEXT, resolves_knobs=True,
    measured_against_coarser=_against_coarser_beam,
    measured_against_coarsest=_against_coarsest_beam)
#: flex's default flexible body: FFRF in the chord frame with geometric stiffness
FFRF_RUNG = Rung(2, "FFRF", _geometric_ffrf_bound, GEOMETRIC_FFRF_ERROR,
                 FFRF_MOTION_ERROR_FRACTION, measured_by=_FFRF_MEASURED_BY,
                 measured_against=_against_exact_beam,
                 measured_against_text=_AGAINST_EXACT_BEAM_TEXT, resolves_knobs=True,
                 measured_against_coarser=_against_coarser_beam,
                 measured_against_coarsest=_against_coarsest_beam)
EXACT_BEAM_ERROR_PER_SLENDERNESS = 0.05
"""The geometrically exact beam's model error against the 3-D plate, relative to the link's
own deflection, per thickness / length (its idealization: plane sections, a pin at the
section centre instead of a joint face, the width's plate effects, all of which fade with
the slenderness). Measured on the thesis deployment's first crest of the coupler's midpoint
deflection (steel, 80 x t x 10 mm; a 64-element beam, within 0.03 % of its element limit,
against the nonlinear FE coupler at its default mesh and at half that mesh): 1 mm +0.08 %
(default mesh only), 2 mm +0.12 %, 3 mm +0.13 % against the half mesh (+0.24 %, +0.25 %
against the default one: the FE coupler's own mesh error is of the same size, so the bound
cannot be tighter than the FE reference; 2026-11-28, notes in the issue's closing note).
0.05 t / L covers them: 0.06 % at 1 mm, 0.125 % at 2 mm, 0.19 % at 3 mm. On the deployment's
peak deflection (headline channel, h = 1e-5 s; the beam extrapolated from 32, 64 and 128
elements, observed order 2.2-2.4): +0.17 % (1 mm), +0.30 % (2 mm), +0.28 % (3 mm) against the
FE coupler at its default mesh, whose half mesh raised its own first crest by 0.13-0.14 %
(2, 3 mm; at 1 mm not run: 18 min at the default mesh); against that mesh-extrapolated FE
coupler about +0.1 % at 2 and 3 mm. The bound at 1 mm rests on the FE coupler's mesh error
there being of the same size (not measured)."""


#: the largest compression / Euler load at which a run's budget may use the exact beam's
#: bound: below it the beam's idealization does not depend on the load; beyond it the beam
#: buckles, and a buckled beam's deflection and stress follow imperfections it does not have
#: (an initial bow, an eccentric pin) and round-off (0.3 mm and thinner on the thesis
#: spring, 1.5-100 x, were certified to 0.07-5 %). ``auto`` still climbs onto the beam there
#: (the best model short of the nonlinear FE plate); its run's budget says it is uncertified
EXACT_BEAM_MEASURED_LOAD_RATIO = 1.0


def _exact_beam_bound(values: Mapping[str, Any], load_ratio: float,
                      cache_dir: Path | None = None) -> float:
    return EXACT_BEAM_ERROR_PER_SLENDERNESS * values["thickness_m"] / values["length_m"]


def _exact_beam_own(values: Mapping[str, Any], cache_dir: Path | None = None) -> float:
    return _exact_beam_bound(values, 0.0)


#: the geometrically exact planar beam (shear, rotary inertia, large rotations): between the
#: FFRF body and the nonlinear FE coupler, at a beam's cost (0.1-1 s per deployment)
EXACT_BEAM_RUNG = Rung(
    5, "exact beam", _exact_beam_bound, _exact_beam_own, FFRF_MOTION_ERROR_FRACTION,
    measured_by=f"the geometrically exact beam against the nonlinear FE coupler: "
    f"{EXACT_BEAM_ERROR_PER_SLENDERNESS:g} x thickness / length of a link's own peak "
    f"deflection and stress (measured on 1-3 mm plates), {FFRF_MOTION_ERROR_FRACTION:g} of "
    f"what the elasticity changes in the motion (the FFRF body's, not measured for the beam)",
    measured_load_ratio=EXACT_BEAM_MEASURED_LOAD_RATIO,
    leaves_out="the exact beam's idealization of the {links} beyond its measured bound (plane "
    "sections, pins at the section centres): measured only on 1-3 mm steel plates, against "
    "a nonlinear FE coupler whose own mesh error is of the same size")
#: the top: the fully nonlinear FE plate, the reference the others are measured against
NONLINEAR_FE_RUNG = Rung(
    9, "nonlinear FE", leaves_out="the nonlinear FE coupler's own model error (the top rung: "
    "St. Venant-Kirchhoff continuum, deformable joint faces)")


def ffrf_rung(values: Mapping[str, Any]) -> Rung:
    """The FFRF model's rung for a link's scene values: linear without geometric stiffness."""
    return FFRF_RUNG if values.get("geometric_stiffness", True) else LINEAR_FFRF_RUNG


def rungs(link: str, values: Mapping[str, Any], link_models: Mapping[str, Any],
          **flags: bool) -> list[tuple[Rung, str]]:
    """The rungs ``link`` may stand on (with ``values``, its scene values), lowest first, as
    (rung, model name); ``flags``: rung fields that must hold (``auto=True``)."""
    out = []
    for name, entry in link_models.items():
        rung = entry.rung(values) if link in entry.links else None
        if rung is not None and all(getattr(rung, flag) == value
                                    for flag, value in flags.items()):
            out.append((rung, name))
    return sorted(out, key=lambda pair: pair[0].level)


@dataclass(frozen=True)
class Climb:
    """``auto``'s flexible rung for a link: the model, its rung, and the reason (the rungs
    tried with their bounds against the tolerance)."""

    model: str
    rung: Rung
    reason: str


def climb(link: str, values: Mapping[str, Any], load_ratio: float, tolerance: float,
          link_models: Mapping[str, Any], cache_dir: Path | None = None) -> Climb:
    """Past rigid: the lowest rung ``auto`` may pick whose bound (relative to the link's own
    deflection, at ``load_ratio``, the rigid probe's compression / Euler load; a bound
    measured per plate reads and keeps its reference in ``cache_dir``) meets ``tolerance``,
    else the highest one (ValueError when ``auto`` may pick none)."""
    options = [(rung, name) for rung, name in rungs(link, values, link_models, auto=True)
               if not link_models[name].rigid and link_models[name].auto_choice]
    if not options:
        raise ValueError(f"{link}: no flexible rung that auto may pick")
    tried = []
    for rung, name in options:
        if rung.bound is None:
            return Climb(name, rung, "; ".join(tried))
        relative = rung.bound(values, load_ratio, cache_dir)
        meets = relative <= tolerance
        tried.append(f"{rung.name} model error {relative:.3g} of the deflection, make ladder's "
                     f"measured bound, {'<=' if meets else '>'} tolerance {tolerance:g}"
                     if math.isfinite(relative) else
                     f"{rung.name}: no bound at {load_ratio:.3g} x the Euler load (measured "
                     f"up to {FFRF_MEASURED_LOAD_RATIO:g} x)")
        if meets:
            return Climb(name, rung, "; ".join(tried))
    rung, name = options[-1]
    return Climb(name, rung, "; ".join(tried))


def next_rung(link: str, values: Mapping[str, Any], link_models: Mapping[str, Any]
              ) -> str | None:
    """The model of the next rung above ``link``'s (scene ``values``) that the refinement may
    climb to, or None: from a rung whose model term is neither bounded nor measured (a lumped
    rigid link; the top has none above), or a model on no rung."""
    entry = link_models[values["model"]]
    current = entry.rung(values) if link in entry.links else None
    if current is None or not (current.bounded or current.measured_against):
        return None
    above = [name for rung, name in rungs(link, values, link_models, refine=True)
             if rung.level > current.level]
    return above[0] if above else None


__all__ = ["COARSER_COMPANION_DIVISOR", "EXACT_BEAM_COMPANIONS", "exact_beam_companion",
           "EXACT_BEAM_ERROR_PER_SLENDERNESS", "EXACT_BEAM_MEASURED_LOAD_RATIO",
           "EXACT_BEAM_RUNG", "FFRF_MEASURED_LOAD_RATIO",
           "FFRF_MOTION_ERROR_FRACTION", "FFRF_RUNG", "GEOMETRIC_FFRF_ERROR",
           "LINEAR_FFRF_ERROR_FLOOR", "LINEAR_FFRF_ERROR_PER_LOAD", "LINEAR_FFRF_RUNG",
           "LUMPED_RIGID_RUNG", "NONLINEAR_FE_RUNG", "RIGID_RUNG", "Climb", "Rung", "climb",
           "ffrf_rung", "next_rung",
           "rungs"]
