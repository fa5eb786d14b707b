"""Reference plans: which runs make a converged reference and which runs show it converged.

A :class:`ReferencePlan` names the finest setting, its one-level coarsenings, the relative
accuracy it claims, a description, the three-level knob sequences
(:class:`flex.experiments.workprecision.convergence.Refinement`) and the anchor of the check
that the knobs' errors add up; :func:`build_reference` runs it
(:func:`flex.experiments.workprecision.convergence.converged_reference`).
:func:`reference_plan` gives the work-precision study's plans: the scipy reference DAE for the
rigid coupler; a plate's reference is stored (``make references``;
:func:`~flex.experiments.workprecision.measurement.stored_as_reference`: the in-run FFRF
reference of the 10 mm plate, 24 modes at 3.125e-7 s with its sequences, took 159 s and
reached 1.4e-2 only, its mesh sequence at observed order 0.24; the stored beam states
2.7e-3).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import NamedTuple

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


def reference_plan(scene_name: str) -> ReferencePlan:
    """The plan of the work-precision study's scene ``scene_name``: ``"rigid"``
    (:func:`rigid_plan`); a plate's reference is stored (``make references``), so any other
    name is a :class:`ValueError` naming what is accepted."""
    if scene_name == "rigid":
        return rigid_plan()
    raise ValueError(f"no reference plan for {scene_name!r}: a plate's reference is the stored "
                     f"one of its physics (make references); accepted: 'rigid'")


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
