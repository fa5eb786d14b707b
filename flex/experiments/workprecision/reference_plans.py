"""Reference plans: which runs make a converged reference and which runs show it converged.

A :class:`ReferencePlan` names the finest setting, its one-level coarsenings, the relative
accuracy it claims, a description, the three-level knob sequences
(:class:`flex.experiments.workprecision.convergence.Refinement`) and the anchor of the check
that the knobs' errors add up; :func:`build_reference` runs it
(:func:`flex.experiments.workprecision.convergence.converged_reference`).
:func:`reference_plan` gives the work-precision study's plans: the scipy reference DAE for the
rigid coupler, and flex's FFRF model for the 10 mm steel plate (:data:`FFRF_REFERENCE`),
refined in step, mesh and modes (and Newton tolerance). The 1 mm plate's reference is stored
(``make references``; :func:`~flex.experiments.workprecision.measurement.stored_as_reference`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

from flex.data.scene import Scene
from flex.experiments.workprecision.convergence import Refinement, converged_reference
from flex.experiments.workprecision.measurement import ReductionPool, Reference, Setting

S = Setting.of


class ReferencePlan(NamedTuple):
    """Finest setting, its one-level coarsenings (name -> setting), claimed relative accuracy
    (dimensionless), a description, the three-level knob sequences, the anchor of the
    additivity check (None when every sequence runs through the reference) and the model
    term: a function of the scene giving the reference model's own error bound (relative)
    and what it is (None: the reference is the model whose settings it measures)."""

    finest: Setting
    coarsenings: dict[str, Setting]
    tolerance: float
    description: str
    refinements: Sequence[Refinement] = ()
    anchor: Setting | None = None
    model_bound: Callable[[Scene], tuple[float, str]] | None = None


#: FFRF references: the finest step, mesh and modes, and where each knob's three-level sequence is
#: run (``*_base``: the values of the other knobs; its finest level has the reference's value of
#: its own knob; :func:`through_reference`: every base at the reference's values, then each
#: estimate is the knob's error *at the reference* and no additivity check is needed). 10 mm: the
#: sequences run at cheaper values of the other knobs, with the additivity check (``anchor``).
#: Measured on its raw peak (the largest of several crests within ~1 % of each other, 24.3, 24.6,
#: 24.8 ms, which one wins following the phase of 20-27 kHz modes): h = 1.25e-6 -> 6.25e-7 ->
#: 3.125e-7 -> 1.5625e-7 s changed it by -0.15 %, -0.18 %, then +0.30 % (1.5 mm, 12 modes); below
#: 2e-7 s the step converged at second order, but 24 modes instead of 12 at 2e-7 s moved it by
#: -0.52 % to another crest. The errors are now read on the deployment peak of the headline
#: channel (:data:`~flex.experiments.workprecision.measurement.PEAK_HEADLINE`). The 1 mm plate's
#: reference is the exact beam (:data:`BEAM_REFERENCE`)
FFRF_REFERENCE: dict[str, dict[str, Any]] = {
    "ffrf_10mm": {"step": 3.125e-7, "mesh": 0.005, "modes": 24,
                  "step_base": {"mesh": 0.005, "modes": 12},
                  "mesh_base": {"step": 1.25e-6, "modes": 12}, "mesh_ratio": 2**0.5,
                  "modes_base": {"step": 1.25e-6, "mesh": 0.005},
                  "newton_base": {"step": 1.25e-6, "mesh": 0.005, "modes": 12}},
}
#: formal orders that cap an observed order: generalized-alpha is second order in the step;
#: quadratic tetrahedra converge at up to fourth order in the element size (eigenvalues,
#: energy); the modal truncation has no formal order (2 assumed as the cap)
MAX_ORDER = {"step": 2.0, "mesh": 4.0, "modes": 2.0}


def scipy_setting(rtol: float, method: str = "DOP853",
                  group: str = "scipy reference DAE") -> Setting:
    """The scipy reference DAE (rigid coupler) at relative tolerance ``rtol`` (absolute:
    ``rtol`` x 1e-2)."""
    return Setting(f"scipy {method} rtol={rtol:g}", engine="scipy", method=method, rtol=rtol,
                   atol=rtol * 1e-2, group=group)


def rigid_plan() -> ReferencePlan:
    """scipy DOP853 at rtol 1e-13, shown converged by rtol 1e-12 and by flex's Exudyn model
    at h = 1e-6 s; claims 1e-8."""
    return ReferencePlan(scipy_setting(1e-13), {
        "scipy rtol 1e-13 -> 1e-12": scipy_setting(1e-12),
        "independent model: Exudyn h = 1e-6 s": S("exudyn h=1e-6", step_s=1e-6,
                                                  newton_relative_tolerance=1e-10),
    }, 1e-8, ("scipy DOP853 on the 9-coordinate DAE, rtol 1e-13, atol 1e-15; shown converged "
              "by rtol 1e-12 and by flex's Exudyn model at h = 1e-6 s"))


def _ffrf_setting(step: float, mesh: float, modes: int, tol: float = 1e-10) -> Setting:
    """An FFRF reference-level setting: step [s], mesh size [m], modes, modified Newton to
    ``tol``, spectral radius 0.9."""
    return S(f"reference h={step:g} mesh={mesh * 1e3:.3g}mm modes={modes}"
             + (f" tol={tol:g}" if tol != 1e-10 else ""),
             step_s=step, coupler__mesh_size_m=mesh, coupler__modes=modes,
             newton="modified", newton_relative_tolerance=tol, spectral_radius=0.9)


def ffrf_refinements(plan: dict[str, Any]) -> list[Refinement]:
    """The knob sequences of an FFRF plan: step (x2), mesh (x ``mesh_ratio``) and modes (/2),
    three levels each, and the Newton tolerance 1e-10 -> 1e-8 (a two-level pair: its change
    bounds the looser run's error)."""
    step, mesh, modes = plan["step"], plan["mesh"], plan["modes"]
    base, ratio, newton = plan["step_base"], plan["mesh_ratio"], plan["newton_base"]
    return [
        Refinement("step_s", tuple(_ffrf_setting(step * k, base["mesh"], base["modes"])
                                   for k in (1, 2, 4)), 2.0, MAX_ORDER["step"]),
        Refinement("coupler.mesh_size_m", tuple(
            _ffrf_setting(plan["mesh_base"]["step"], round(mesh * ratio**k, 9),
                          plan["mesh_base"]["modes"])
            for k in (0, 1, 2)), ratio, MAX_ORDER["mesh"]),
        Refinement("coupler.modes", tuple(
            _ffrf_setting(plan["modes_base"]["step"], plan["modes_base"]["mesh"], modes // k)
            for k in (1, 2, 4)), 2.0, MAX_ORDER["modes"]),
        Refinement("newton_relative_tolerance",
                   (_ffrf_setting(newton["step"], newton["mesh"], newton["modes"]),
                    _ffrf_setting(newton["step"], newton["mesh"], newton["modes"], tol=1e-8)),
                   100.0, 1.0),
    ]


def reference_plan(scene_name: str) -> ReferencePlan:
    """The plan of the work-precision study's scene ``scene_name``: ``"rigid"``
    (:func:`rigid_plan`) or a key of :data:`FFRF_REFERENCE` (claims 1e-3; the anchor is the
    step sequence's finest level unless every sequence runs through the reference,
    :func:`through_reference`)."""
    if scene_name == "rigid":
        return rigid_plan()
    plan = FFRF_REFERENCE[scene_name]
    step, mesh, modes = plan["step"], plan["mesh"], plan["modes"]
    refinements = ffrf_refinements(plan)
    through = through_reference(plan)
    where = ("each through the reference (the other knobs at its values)" if through
             else "each at cheaper values of the other knobs (their additivity checked "
                  "against the reference)")
    description = (
        f"flex's FFRF model, generalized-alpha index 3 (rho 0.9), h = {step:g} s, mesh "
        f"{mesh * 1e3:g} mm quadratic tetrahedra, {modes} fixed-interface modes, modified "
        f"Newton to 1e-10; shown converged by three-level sequences of step (x2), mesh "
        f"(x{plan['mesh_ratio']:.3g}) and modes (/2) with Richardson error estimates, {where}, "
        f"and Newton 1e-10 -> 1e-8")
    # sequences through the reference need no additivity check (its prediction is the
    # reference itself)
    anchor = None if through else refinements[0].levels[0]
    return ReferencePlan(_ffrf_setting(step, mesh, modes), {}, 1e-3, description, refinements,
                         anchor)


def through_reference(plan: dict[str, Any]) -> bool:
    """Whether every knob sequence of an FFRF reference plan runs at the reference's values
    of the other knobs (then each estimate is that knob's error at the reference)."""
    return (plan["step_base"] == {"mesh": plan["mesh"], "modes": plan["modes"]}
            and plan["mesh_base"] == {"step": plan["step"], "modes": plan["modes"]}
            and plan["modes_base"] == {"step": plan["step"], "mesh": plan["mesh"]})


def build_reference(base: Scene, label: str, plan: ReferencePlan,
                    pool: ReductionPool | None = None,
                    progress: Callable[[str], None] | None = None) -> Reference:
    """Run ``plan`` on ``base``
    (:func:`flex.experiments.workprecision.convergence.converged_reference`), its model term
    (if any) added to the evidence as ``model``; raises :class:`~flex.base.errors.FlexError`
    if the finest run fails."""
    reference = converged_reference(base, label, plan.finest, plan.coarsenings,
                                    plan.tolerance, pool, plan.description, progress,
                                    plan.refinements, plan.anchor)
    if plan.model_bound is not None:
        bound, what = plan.model_bound(base)
        reference.evidence["model"] = {"error": bound, "governing": "peak_deflection_relative",
                                       "settings": [what]}
    return reference
