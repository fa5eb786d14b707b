"""The link models a scene may name (``crank.model``, ``coupler.model``): a registry of entries
under a written contract.

:data:`BUILTIN_LINK_MODELS` is an immutable mapping (``types.MappingProxyType``) from a model's
name to its :class:`LinkModel`, in the order messages list them: ``"rigid"``, ``"ffrf"``,
``"nonlinear_fe"``, ``"exact_beam"``. Every function that checks, resolves, builds or runs a
scene takes the registry as an argument, ``link_models``, with the built-ins as its default; a
caller with another model builds its own registry (``MappingProxyType({**BUILTIN_LINK_MODELS,
"toy": toy})``) and passes it along. Nothing here is mutable and nothing registers itself. The
layers below (:mod:`flex.data`, :mod:`flex.config`) read only an entry's scene-level part,
:class:`flex.data.scene.LinkSchema` (its fields are :class:`LinkModel`'s first ones), with
:data:`flex.data.scene.BUILTIN_LINK_SCHEMAS` as their default (a test ties the two).

The contract of an entry -- what a link model declares, point by point:

1. **name**: the value of ``<link>.model`` that selects it (``name``), and the links it may
   model (``links``). A name not in the registry, or a model of another link, is refused
   with a :class:`~flex.base.errors.SceneError` naming the accepted models
   (:func:`flex.data.scene.validate`, :func:`entry_of`).
2. **scene keys it reads and its knobs**: ``rigid`` (mass keys only), ``damped``
   (``damping_ratio``), ``knobs`` (its discretization knobs by name,
   :mod:`flex.config.knobs`: ``"modes"`` reads ``modes`` and ``mode_selection``, ``"mesh"``
   meshes the plate and reads ``mesh_size_m``, ``"elements"`` a beam's ``elements``; the error
   budget, ``auto`` and refinement loop over them), ``reads`` (further keys:
   ``geometric_stiffness``) and ``settings`` (what fills its ``"auto"`` knobs and step from
   the tolerance). A key a model does not read and the user set is refused
   (:func:`flex.config.usage.unused_keys`).
3. **checks on those keys** (SceneError, before anything runs): the flags' and knobs' (a
   meshed model needs ``geometry = "plate"`` and a plate that can be meshed, an undamped one
   ``damping_ratio = 0``, a non-rigid crank the spring drive, the explicit integrators rigid
   links), then its own ``check(link, scene)`` if it has one.
4. **what it prepares before a run**: ``prepare(scene, link, given, cache_dir)`` returns what
   its ``add`` needs (the Craig-Bampton reduction of an FFRF link; ``given``: one the caller
   built; None for models that need nothing).
5. **how it adds itself to the Exudyn builder**: ``add(builder, link, prepared)`` adds the
   link's bodies to :class:`flex.dynamics.builder.Builder` and returns the handles it made:
   a dict with ``joint_markers`` (the markers at the link's two joints: A and B for the
   crank, B and C for the coupler) and whatever its own sensors and datasets read (a rigid
   link's ``body`` and ``node``; an FFRF link's ``reduction``, ``node_modal``,
   ``node_frame``, ``object``, ``marker_mid``; ``planar_pins``: true when its joint markers
   carry x and y only, as a planar beam's nodes: the builder then pins them in x and y); the
   builder keeps them as ``mech.crank`` and ``mech.coupler``. A rigid crank is added before
   the slider (the order numbers the coordinates), any other after the ground markers.
6. **its sensors and datasets**: ``sensors(builder, link, handles)`` adds what its
   ``datasets(mech,
   link, time_s)`` reads after the run (the coupler's ``coupler/...`` datasets; a crank's
   motion is read from its joint markers or rigid body by :mod:`flex.dynamics.collect`;
   a link with a stress field also its stress peaks on the headline channel,
   ``channel/<link>/...``, read on the field low-passed at ``mech.channel_cutoff_Hz``,
   :mod:`flex.base.channel`);
   ``energy``: whether its energy is known (else the run has no ``energy/...``);
   ``recorder(mech, link, settings)``: an extra recorder of the run (nodal coordinates), or
   None.
7. **its time scales**: ``time_scale(link, values, prepared)`` -> ``(omega [rad/s], what)``
   or None: the fastest motion the link adds (the highest retained mode of a reduction, the
   first bending mode of a nonlinear FE plate), which the step advice must resolve
   (:func:`flex.dynamics.advice.time_scales`); ``step_cost_s(values, modes)``: its share of
   the wall time per integration step [s] (:func:`flex.dynamics.runtime.estimated_run_time_s`).
8. **solver adjustments**: ``adjust_solver(settings, values)`` changes the integrator
   settings in place for a link of scene ``values`` (a sparse solver, a looser absolute
   tolerance, a Newton tolerance that follows the element count); ``own_progress``: the model prints
   its own progress during a solve.
9. **its rung on the ladder**: ``rung(values)`` -> a :class:`flex.config.ladder.Rung` (or
   None: on no rung): what bounds its model error against the rung above, what that leaves
   out, and whether ``auto`` and the refinement may climb onto it. The error budget,
   ``auto``'s climb and the refinement read it and name no model.
10. **how its stored motion is read back** (``flex export``, ``flex animate``):
    ``stored_motion``, a :class:`flex.dynamics.link_outputs.MotionReader` that rebuilds the
    link's mesh from the case (its ``body``) and its state at each sample (its ``state``):
    :data:`~flex.dynamics.link_outputs.RIGID_MOTION` (a box of the plate moved with the
    stored angles and joints), ``MODAL_MOTION`` (a reduction's modal coordinates in its
    floating frame), ``NODAL_MOTION`` (every node's stored position) or ``NO_MOTION`` (not
    read back: export and animate refuse it, naming the model). :mod:`flex.tools.motion`
    calls through it and names no kind.

Capability flags the callers read: ``rigid``, ``damped`` and ``knobs`` (above);
``linear_elastic``: its results are trusted only for small elastic deflections and loads
below buckling (validity warnings, :func:`flex.dynamics.advice.validity_warning`);
``reference``: an accuracy reference the others are compared with (named in advice);
``auto_choice``: ``model = "auto"`` may pick it (:mod:`flex.fidelity.auto`, whose fitted laws
decide among the built-in models only); ``label``: its name in reports. A model of one's own
is an entry built the same way (``dataclasses.replace`` of a built-in one, or
:meth:`LinkModel.extending` a :class:`~flex.data.scene.LinkSchema`): tests/test_link_models.py
runs such a toy through :func:`flex.simulate`.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import Plate, axial_omega
from flex.base.progress import heartbeat
from flex.config.ladder import (
    LUMPED_RIGID_RUNG,
    NONLINEAR_FE_RUNG,
    RIGID_RUNG,
    Rung,
    ffrf_rung,
)
from flex.data.fields import AUTO
from flex.data.plates import estimate_mesh, plate_mass_properties
from flex.data.results import Dataset
from flex.data.scene import (
    BUILTIN_LINK_SCHEMAS,
    LINKS,
    LinkSchema,
    Scene,
    check_meshed_plate,
    link_model,
)
from flex.dynamics.exact_beam_link import (
    CALIBRATED_BEAM_RUNG,
    add_exact_beam,
    exact_beam_datasets,
    exact_beam_sensors,
    exact_beam_solver,
    exact_beam_step_cost_s,
    prepare_beam,
)
from flex.dynamics.link_outputs import (
    NO_MOTION,
    NODAL_MOTION,
    RIGID_MOTION,
    MotionReader,
    flexible_datasets,
    flexible_sensors,
    modal_motion,
    sensor_data,
)

#: the built-in models' names (for code that sets a model in a scene)
RIGID, FFRF, NONLINEAR_FE, EXACT_BEAM = BUILTIN_LINK_SCHEMAS


def _nothing(*args: Any) -> None:
    return None


def _given(scene: Scene, link: str, given: Any, cache_dir: Path | None) -> Any:
    return given


def _free(values: dict[str, Any], modes: int | None) -> float:
    return 0.0


def _no_rung(values: Mapping[str, Any]) -> Rung | None:
    return None


def _no_datasets(mech: Any, link: str, time_s: np.ndarray) -> dict[str, Dataset]:
    return {}




@dataclass(frozen=True)
class LinkModel(LinkSchema):
    """One link model: its scene-level part (:class:`flex.data.scene.LinkSchema`, points 1-3)
    and what it does in a run (points 4-8 of the module's contract)."""

    #: its name in reports and figures
    label: str = ""
    #: an accuracy reference the other models are compared with
    reference: bool = False
    #: results trusted only for small elastic deflections, below buckling (validity warnings)
    linear_elastic: bool = False
    #: ``model = "auto"`` may pick it
    auto_choice: bool = False
    #: (4) ``prepare(scene, link, given, cache_dir)``: what ``add`` needs
    prepare: Callable[[Scene, str, Any, Path | None], Any] = _given
    #: (5) ``add(builder, link, prepared)`` -> its handles (a dict with ``joint_markers``)
    add: Callable[[Any, str, Any], dict[str, Any]] = _nothing
    #: (6) ``sensors(builder, link, handles)``, ``datasets(mech, link, time_s)``, known energy,
    #: ``recorder(mech, link, settings)``
    sensors: Callable[[Any, str, dict[str, Any]], None] = _nothing
    datasets: Callable[[Any, str, np.ndarray], dict[str, Dataset]] = _no_datasets
    energy: bool = True
    recorder: Callable[[Any, str, dict[str, Any]], Any] = _nothing
    #: (7) ``time_scale(link, values, prepared)`` -> (omega [rad/s], what) or None;
    #: ``step_cost_s(values, modes)`` [s per step]
    time_scale: Callable[[str, dict[str, Any], Any], tuple[float, str] | None] = _nothing
    step_cost_s: Callable[[dict[str, Any], int | None], float] = _free
    #: (8) ``adjust_solver(settings, values)`` in place; prints its own progress
    adjust_solver: Callable[[dict[str, Any], dict[str, Any]], None] = _nothing
    own_progress: bool = False
    #: (9) its rung on the model ladder for a link's scene values (:mod:`flex.dynamics.
    #: ladder`), or None: a model on no rung (its budget then says its model error is left out)
    rung: Callable[[Mapping[str, Any]], Rung | None] = _no_rung
    #: (10) how its stored motion is read back (export, animate)
    stored_motion: MotionReader = RIGID_MOTION

    def __post_init__(self) -> None:
        if not isinstance(self.stored_motion, MotionReader):
            raise ValueError(f"link model {self.name}: stored_motion {self.stored_motion!r} "
                             f"is not a MotionReader (flex.dynamics.link_outputs)")

    @classmethod
    def extending(cls, schema: LinkSchema, **behaviour: Any) -> LinkModel:
        """The entry of ``schema`` (its scene-level part) with ``behaviour`` (points 4-8)."""
        return cls(**{f.name: getattr(schema, f.name) for f in fields(LinkSchema)}, **behaviour)


def entry_of(link: str, scene: Scene, link_models: Mapping[str, LinkModel]) -> LinkModel:
    """The entry of ``link``'s concrete model in ``link_models`` (SceneError naming the
    accepted models otherwise; ``"auto"`` must be resolved first)."""
    if scene[link]["model"] == AUTO:
        raise SceneError(f'{link}.model = "auto" must be resolved before building '
                         "(flex.fidelity.simulation.simulate does it with "
                         "flex.fidelity.auto.resolve)")
    return link_model(link, scene[link], link_models)


def entries(scene: Scene, link_models: Mapping[str, LinkModel]) -> dict[str, LinkModel]:
    """The entries of a concrete scene's links, by link."""
    return {link: entry_of(link, scene, link_models) for link in LINKS}


def flexible_links(scene: Scene, link_models: Mapping[str, LinkModel]) -> list[str]:
    """The links of a concrete ``scene`` whose model is not rigid."""
    return [link for link in LINKS if not link_models[scene[link]["model"]].rigid]


# ------------------------------------------------------------------------------------------
# rigid: a rigid body of the link's mass properties
# ------------------------------------------------------------------------------------------
def _add_rigid(builder: Any, link: str, prepared: Any) -> dict[str, Any]:
    scene, init = builder.scene, builder.init
    if link == "crank":
        body = builder.rigid_body(
            "crank", *plate_mass_properties(scene, "crank"), init.joint_B_m / 2,
            init.crank_angle_rad, init.joint_B_velocity_m_per_s / 2, init.crank_speed_rad_per_s)
        ends = (np.zeros(3), init.joint_B_m)
    else:
        body = builder.rigid_body(
            "coupler", *plate_mass_properties(scene), (init.joint_B_m + init.joint_C_m) / 2,
            init.coupler_angle_rad,
            (init.joint_B_velocity_m_per_s + init.joint_C_velocity_m_per_s) / 2,
            init.coupler_speed_rad_per_s)
        ends = (init.joint_B_m, init.joint_C_m)
    return {"body": body["bodyNumber"], "node": body["nodeNumber"], "rigid_body": body,
            "joint_markers": tuple(builder.body_marker(body, end) for end in ends)}


def _rigid_sensors(builder: Any, link: str, handles: dict[str, Any]) -> None:
    """A rigid coupler's node (its centre of mass is the midpoint); a rigid crank's body
    sensors are the builder's, as every rigid body's."""
    if link == "coupler":
        for output in ("Position", "Velocity", "Acceleration", "Rotation", "AngularVelocity"):
            builder.add(f"coupler.{output}",
                        builder.sensor("Node", output, nodeNumber=handles["node"]))


def _rigid_datasets(mech: Any, link: str, time_s: np.ndarray) -> dict[str, Dataset]:
    if link != "coupler":
        return {}
    return {
        "coupler/midpoint_position": Dataset(sensor_data(mech, "coupler.Position")[:, 1:3], "m",
                                             "coupler midpoint x, y"),
        "coupler/midpoint_acceleration": Dataset(
            sensor_data(mech, "coupler.Acceleration")[:, 1:3], "m/s^2",
            "coupler midpoint acceleration x, y (thesis figs. 35-42)"),
        "coupler/midpoint_deflection": Dataset(np.zeros_like(time_s), "m",
                                               "elastic midpoint deflection (rigid: 0)"),
        "coupler/angle": Dataset(sensor_data(mech, "coupler.Rotation")[:, 3], "rad",
                                 "coupler angle from +x (B to C)")}


# ------------------------------------------------------------------------------------------
# FFRF: a Craig-Bampton reduction of the meshed plate in a floating frame
# ------------------------------------------------------------------------------------------
#: a mesh whose estimated build takes longer than this is announced on stderr first [s]
ANNOUNCE_MESH_S = 30.0
#: wall time per step [s] of an FFRF link, rough (2-core machine, shared; within ~3x), per
#: link and per modal coordinate beyond its frame (1 mm plate, 2 mm mesh, 1e-5 s, modified
#: Newton: 0.25 ms at 2 modes, 0.38 at 6, 0.99 at 20, 2.5 at 40)
STEP_COST_FFRF_S = (1.5e-4, 5e-5)  # (per FFRF link, per mode)
#: the nonlinear FE coupler's wall time per step per DOF of its mesh [s] (40 ms per step at
#: ~5.6k DOF, 80 x 3 x 10 mm plate, 4 mm mesh)
STEP_COST_NONLINEAR_FE_PER_DOF_S = 7e-6


def announce_mesh(link: str, values: dict[str, Any], what: str, modes: int | None = None
                   ) -> None:
    """Say on stderr what a long meshing job will cost before it starts (so a big mesh, or
    a reduction to many modes, is not a silent hang)."""
    estimate = estimate_mesh(values["length_m"], values["thickness_m"], values["width_m"],
                             values["mesh_size_m"], modes)
    if estimate.build_time_s > ANNOUNCE_MESH_S:
        print(f"flex: meshing the {link} plate for its {what}: {estimate.text()} "
              f"(estimate)", file=sys.stderr, flush=True)


def reduction_for_scene(scene: Scene, link: str = "coupler", *,
                        cache_dir: Path | None = None, mesh_order: int = 2,
                        solve_modes: int | None = None):
    """The Craig-Bampton reduction of the scene's plate ``link`` (coupler or crank).

    ``cache_dir``: the reduction cache folder (loaded from there if present, written there
    if built; :func:`flex.bodies.reduction.reduction_cache_dir` names the user's), or None to
    build it in memory without any disk cache. ``mesh_order``: the tetrahedra's order (2, or
    1 for the work-precision study's linear ones). ``solve_modes``: the link's modes as the
    first of an eigen-solve of that many (:func:`flex.bodies.reduction.build_reduction`),
    None: solved for its own count.
    """
    from flex.bodies.reduction import build_reduction

    c = scene[link]
    if AUTO in (c["modes"], c["mesh_size_m"]):
        raise ValueError(f'{link}: resolve its "auto" modes and mesh first '
                         f"(flex.fidelity.auto.resolve, flex.config.settings.resolve_link_keys)")
    check_meshed_plate(link, dict(c, model=FFRF))  # refused before any meshing
    announce_mesh(link, c, f"reduction with {c['modes']} modes (instant if cached)",
                   c["modes"])
    with heartbeat(f"{link} reduction ({c['modes']} modes)"):
        reduction = build_reduction(Plate.of(c), c["mesh_size_m"], c["modes"], cache_dir,
                                    mode_selection=c["mode_selection"], mesh_order=mesh_order,
                                    solve_modes=solve_modes)
    if c.get("geometric_stiffness") and not reduction.from_cache:
        from flex.bodies.geometric_stiffness import geometric_stiffness

        # now, while the build's mesh is at hand (0.1 s), and stored beside the reduction:
        # a run that loads the reduction in another process would mesh the plate again (1-2 s)
        geometric_stiffness(reduction)
    return reduction


#: an FFRF link's stored motion: its modal coordinates on its reduction's basis
MODAL_MOTION = modal_motion(reduction_for_scene)
#: the readers of stored motion a built-in model names (the contract's point 10), by kind
STORED_MOTIONS: Mapping[str, MotionReader] = MappingProxyType(
    {reader.kind: reader for reader in (RIGID_MOTION, MODAL_MOTION, NODAL_MOTION, NO_MOTION)})


def _prepare_reduction(scene: Scene, link: str, given: Any, cache_dir: Path | None) -> Any:
    return given if given is not None else reduction_for_scene(scene, link,
                                                               cache_dir=cache_dir)


def _add_ffrf(builder: Any, link: str, reduction: Any) -> dict[str, Any]:
    from flex.bodies.reduction import add_ffrf_link

    scene, init = builder.scene, builder.init
    if reduction is None:
        raise SceneError(f'{link}.model = "{scene[link]["model"]}" needs its reduction '
                         "(flex.fidelity.simulation.simulate builds it from the scene)")
    if link == "crank":  # the plate's end_a face is the pivot A (the floating frame), end_b B
        added = add_ffrf_link(
            builder.mbs, reduction, [0.0, 0.0, 0.0], init.crank_angle_rad,
            damping_ratio=scene["crank"]["damping_ratio"],
            damping_model=scene["crank"]["damping_model"],
            initial_angular_velocity_rad_per_s=init.crank_speed_rad_per_s, name="crank",
            joint_markers=builder.ffrf_joint_markers,
            end_a_rotation=bool(scene["wing"]["enabled"]))  # the weld turns with A
    else:
        added = add_ffrf_link(
            builder.mbs, reduction, list(init.joint_B_m), init.coupler_angle_rad,
            damping_ratio=scene["coupler"]["damping_ratio"],
            damping_model=scene["coupler"]["damping_model"],
            initial_velocity_B_m_per_s=list(init.joint_B_velocity_m_per_s),
            initial_angular_velocity_rad_per_s=init.coupler_speed_rad_per_s,
            joint_markers=builder.ffrf_joint_markers,
            end_a_rotation=False,  # the pin at B is free about z
            end_b_rotation=False)  # the pin at C constrains x and y only
    return dict(added, reduction=reduction,
                joint_markers=(added["marker_B"], added["marker_C"]))


def highest_retained_omega(values: dict[str, Any]) -> float:
    """Beam estimate of the highest fixed-interface circular frequency [rad/s] a link's
    reduction keeps (its ``modes`` lowest of the kinds its ``mode_selection`` keeps)."""
    plate = Plate.of(values)
    if values["mode_selection"] == "in_plane":
        return plate.in_plane_omegas(values["modes"])[-1]
    return plate.clamped_frequencies(values["modes"])[-1][0]


def _ffrf_time_scale(link: str, values: dict[str, Any], reduction: Any
                     ) -> tuple[float, str]:
    """The fastest motion the FFRF body carries: its highest retained mode or, above it, the
    axial one its end B static modes carry (the joint forces ring with it)."""
    if reduction is not None:
        hertz = max(float(np.max(reduction.fixed_interface_frequencies_Hz)),
                    reduction.highest_body_frequency_Hz)
        return 2 * np.pi * hertz, "highest frequency of the reduced body (end modes included)"
    axial = axial_omega(0.5, float(values["length_m"]), float(values["youngs_modulus_Pa"]),
                        float(values["density_kg_per_m3"]))
    return (max(highest_retained_omega(values), axial),
            "highest frequency of the reduced body (beam estimate: the fixed-free rod's "
            "axial one, or the highest retained mode)")


def _ffrf_step_cost_s(values: dict[str, Any], modes: int | None) -> float:
    return STEP_COST_FFRF_S[0] + STEP_COST_FFRF_S[1] * float(modes or values["modes"])


# ------------------------------------------------------------------------------------------
# nonlinear FE: every node of the meshed plate, large deformation
# ------------------------------------------------------------------------------------------
#: nonlinear FE coupler (~10k coordinates): a sparse LU (a dense one would take seconds and
#: ~1 GB per Newton step), reused while Newton converges -- the Jacobian and its
#: factorisation dominate a full Newton iteration. Measured on the 1 mm plate, 30 steps:
#: modified Newton 3 iterations per step and one Jacobian in all, 5x faster than full Newton
#: (2 iterations per step, each with a new Jacobian)
NONLINEAR_FE_SOLVER = {"linear_solver": "EigenSparse", "modified_newton": True}
#: the Newton residual of the nonlinear FE system stalls at ~9e-8 (Exudyn's residual norm,
#: measured at step 1e-5 s over the deployment): round-off of the face-marker positions
#: (weighted sums over ~100 nodes), scaled by 1 / step^2 in the index-3 equations. Relative
#: tolerances cannot reach below it (Newton failed at 6.6 ms with 1e-8 and at 7.9 ms with
#: 1e-7), so the absolute tolerance is raised above it; 1e-8 and 1e-7 relative gave midpoint
#: deflections 5e-12 m apart
NONLINEAR_FE_NEWTON_ABSOLUTE_TOLERANCE = 1e-6


def _add_nonlinear_fe(builder: Any, link: str, plate: Any) -> dict[str, Any]:
    from flex.bodies.nonlinear import add_nonlinear_fe_coupler, nonlinear_plate_for_scene

    scene, init = builder.scene, builder.init
    if plate is None:
        announce_mesh(link, scene[link], "nonlinear FE body")
        plate = nonlinear_plate_for_scene(scene)
    added = add_nonlinear_fe_coupler(
        builder.mbs, plate, list(init.joint_B_m), init.coupler_angle_rad,
        initial_velocity_B_m_per_s=list(init.joint_B_velocity_m_per_s),
        initial_angular_velocity_rad_per_s=init.coupler_speed_rad_per_s)
    return dict(added, plate=plate, joint_markers=(added["marker_B"], added["marker_C"]))


def _nonlinear_fe_datasets(mech: Any, link: str, time_s: np.ndarray) -> dict[str, Dataset]:
    out = flexible_datasets(mech, link, time_s)
    # the face markers' linearised rotation can tilt the faces out of plane (see
    # flex.bodies.nonlinear): record how far the midpoint leaves the plane
    position_mid = sensor_data(mech, f"marker_{link}_mid.Position")[:, 1:4]
    out[f"{link}/midpoint_out_of_plane"] = Dataset(
        position_mid[:, 2] - position_mid[0, 2], "m",
        "midpoint displacement normal to the mechanism plane (z), 0 at t = 0")
    return out


def _nodal_recorder(mech: Any, link: str, settings: dict[str, Any]) -> Any:
    """A :class:`flex.bodies.nonlinear.NodalRecorder` of the link's nodes."""
    from flex.bodies.nonlinear import NodalRecorder

    return NodalRecorder(mech.mbs, mech.coupler["nodes"], settings["step_s"],
                         settings["output_step_s"], settings["end_time_s"])


def _nonlinear_fe_time_scale(link: str, values: dict[str, Any], plate: Any
                             ) -> tuple[float, str]:
    return Plate.of(values).pinned_pinned_omega, "first bending mode"


def _nonlinear_fe_step_cost_s(values: dict[str, Any], modes: int | None) -> float:
    dof = estimate_mesh(values["length_m"], values["thickness_m"], values["width_m"],
                        values["mesh_size_m"]).dof
    return STEP_COST_NONLINEAR_FE_PER_DOF_S * dof


def _nonlinear_fe_solver(settings: dict[str, Any], values: dict[str, Any]) -> None:
    settings.update(NONLINEAR_FE_SOLVER)
    settings["newton_absolute_tolerance"] = max(settings["newton_absolute_tolerance"],
                                                NONLINEAR_FE_NEWTON_ABSOLUTE_TOLERANCE)


def _rigid_rung(values: Mapping[str, Any]) -> Rung:
    return RIGID_RUNG if values.get("geometry") == "plate" else LUMPED_RIGID_RUNG


def _nonlinear_fe_rung(values: Mapping[str, Any]) -> Rung:
    return NONLINEAR_FE_RUNG


def _exact_beam_rung(values: Mapping[str, Any]) -> Rung:
    return CALIBRATED_BEAM_RUNG


# ------------------------------------------------------------------------------------------
# the registry
# ------------------------------------------------------------------------------------------
#: what each built-in model does in a run (points 4-10), by name: one entry per schema of
#: :data:`flex.data.scene.BUILTIN_LINK_SCHEMAS` (the scene-level part, points 1-3)
_BEHAVIOUR: Mapping[str, dict[str, Any]] = MappingProxyType({
    RIGID: dict(label="rigid twin", auto_choice=True, add=_add_rigid, sensors=_rigid_sensors,
                datasets=_rigid_datasets, rung=_rigid_rung),
    FFRF: dict(label="FFRF (flex's default: geometric stiffness)", linear_elastic=True,
               auto_choice=True, prepare=_prepare_reduction, add=_add_ffrf,
               sensors=flexible_sensors, datasets=flexible_datasets,
               time_scale=_ffrf_time_scale, step_cost_s=_ffrf_step_cost_s, rung=ffrf_rung,
               stored_motion=MODAL_MOTION),
    NONLINEAR_FE: dict(label="nonlinear FE (reference)", reference=True, auto_choice=True,
                       add=_add_nonlinear_fe, sensors=flexible_sensors,
                       datasets=_nonlinear_fe_datasets, energy=False, recorder=_nodal_recorder,
                       time_scale=_nonlinear_fe_time_scale,
                       step_cost_s=_nonlinear_fe_step_cost_s,
                       adjust_solver=_nonlinear_fe_solver, own_progress=True,
                       rung=_nonlinear_fe_rung, stored_motion=NODAL_MOTION),
    EXACT_BEAM: dict(label="geometrically exact beam", auto_choice=True, prepare=prepare_beam,
                     add=add_exact_beam, sensors=exact_beam_sensors,
                     datasets=exact_beam_datasets, time_scale=_nonlinear_fe_time_scale,
                     step_cost_s=exact_beam_step_cost_s, adjust_solver=exact_beam_solver,
                     rung=_exact_beam_rung, stored_motion=NO_MOTION),
})
#: the built-in link models, by name (immutable; pass another mapping to add models): one
#: registry, generated from the schemas (a schema without its behaviour fails here, at import)
BUILTIN_LINK_MODELS: Mapping[str, LinkModel] = MappingProxyType({
    name: LinkModel.extending(schema, **_BEHAVIOUR[name])
    for name, schema in BUILTIN_LINK_SCHEMAS.items()})

__all__ = ["LinkModel", "BUILTIN_LINK_MODELS", "STORED_MOTIONS", "RIGID", "FFRF",
           "NONLINEAR_FE", "EXACT_BEAM", "entry_of", "entries", "flexible_links",
           "reduction_for_scene"]
