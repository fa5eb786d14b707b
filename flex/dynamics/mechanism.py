"""Slider-crank assembly in Exudyn: a ready multibody system from a scene.

Sketch (mechanism plane x-y; rotation axes along z)::

                 B (revolute, crank-coupler)
                / \\
     crank L1  /   \\  coupler L2 (rigid body, FFRF plate or nonlinear FE plate)
    (rigid or /     \\
  FFRF plate)/       \\
    frame == A       C (x,y pinned: non-redundant loop) -- slider ==[spring]== frame
    (revolute)         prismatic joint along x, slide line y = offset

All three links are 3D bodies moving in the x-y plane (nodes with Tait-Bryan rotation
coordinates, so the z-rotation coordinate is the planar angle). A planar loop of 3D joints
is redundant, so joint C constrains only x and y (17 constraints on 18 coordinates: one
degree of freedom, as Gruebler's count in the thesis, Eq. 1). The same builder makes the
rigid model and the flexible ones: only the crank and coupler bodies change
(``crank.model``, ``coupler.model``). A scene with rigid links and an implicit integrator is
built planar instead (:mod:`flex.dynamics.planar` extends this builder with 2D items).

Drives: ``spring`` -- a linear spring (and optional damper) on the slider's x coordinate,
compressed by ``spring_preload_m`` at t = 0 and attached throughout, released from rest;
``constant_speed`` -- a velocity-level constraint on the crank angle.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from flex.base.errors import SceneError
from flex.data.scene import Scene
from flex.dynamics.builder import (
    Builder,
    Mechanism,
)
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel, entries
from flex.dynamics.planar import PlanarBuilder, is_planar


def build_mechanism(scene: Scene, reduction: Any = None, crank_reduction: Any = None, *,
                    ffrf_joint_markers: str = "fewest", planar: bool | None = None,
                    link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> Mechanism:
    """Build and assemble the slider-crank of ``scene`` in a new Exudyn system.

    ``reduction`` is the Craig-Bampton reduction (:func:`flex.bodies.reduction.build_reduction`)
    for an ``ffrf`` coupler (or the plate of a ``nonlinear_fe`` one; ``None``: built from the
    scene), ``crank_reduction`` the one of an ``ffrf`` crank; ``None`` for rigid links.
    Links with ``model = "auto"`` must be resolved first
    (:func:`flex.fidelity.simulation.simulate`). ``ffrf_joint_markers``: how FFRF links attach
    to their joints (:func:`flex.bodies.reduction.add_ffrf_link`; ``"all_face_nodes"`` only to
    measure what the default ``"fewest"`` saves). ``planar``: build with 2D items
    (:mod:`flex.dynamics.planar`: the same datasets at a quarter of the cost per step);
    None: wherever the scene allows it (:func:`flex.dynamics.planar.is_planar`); False:
    always 3D (for callers that read 3D coordinates, e.g. the out-of-plane modes); True:
    planar or SceneError. ``link_models``: the registry the links' models come from
    (:mod:`flex.dynamics.link_models`; each adds itself, point 5 of its contract). Returns a
    :class:`Mechanism`.
    """
    entries(scene, link_models)  # SceneError for "auto" or an unknown model, first
    if planar and not is_planar(scene, link_models):
        raise SceneError("a planar build needs rigid crank and coupler and an implicit "
                         "integrator (simulation.integrator != \"explicit_penalty\")")
    use_planar = is_planar(scene, link_models) if planar is None else planar
    builder = (PlanarBuilder(scene, link_models=link_models) if use_planar
               else Builder(scene, ffrf_joint_markers, link_models=link_models))
    builder.add_crank_and_slider(crank_reduction)
    builder.add_coupler(reduction)
    builder.add_joints()
    builder.add_drive()
    builder.add_sensors()
    builder.mbs.Assemble()
    return builder.mech
