"""The design point's mechanism checked from its scene: mobility by Gruebler and Kutzbach, the
rank of the reference DAE's constraint Jacobian along the deployment and over a full turn, the
dead centres and the transmission angle (``mechanism/*`` datasets of the design study).
"""

from __future__ import annotations

import numpy as np

from flex.base.kinematics import slider_crank
from flex.base.mechanism_checks import (
    Joint,
    counted_mobility,
    dead_centre_angles_rad,
    jacobian_mobility,
    smallest_singular_value,
    transmission_angle_rad,
)
from flex.data.results import Dataset
from flex.data.scene import Scene


def topology(scene: Scene) -> tuple[list[str], list[Joint]]:
    """Bodies (with the frame) and joints of the scene's mechanism (docs/model.md): revolute
    A, B, C, prismatic P; a welded wing adds a body and weld W. The drive is an input, not a
    joint (a constant-speed crank is a driving constraint that takes the one freedom)."""
    bodies = ["frame", "crank", "coupler", "slider"]
    joints = [Joint("A", ("frame", "crank"), "revolute"),
              Joint("B", ("crank", "coupler"), "revolute"),
              Joint("C", ("coupler", "slider"), "revolute"),
              Joint("P", ("slider", "frame"), "prismatic")]
    if scene.get("wing", {}).get("enabled", False):
        bodies.append("wing")
        joints.append(Joint("W", ("crank", "wing"), "weld"))
    return bodies, joints


def jacobian_along(scene: Scene, crank_angles_rad: np.ndarray) -> dict[str, np.ndarray]:
    """The reference DAE's constraint Jacobian (:class:`flex.dynamics.reference.SliderCrankDAE`,
    9 coordinates) at the closed-form configuration of each crank angle: its rank, smallest
    singular value, and the smallest singular value of the square Jacobian of the other
    coordinates with the slider position as the input (0 at a dead centre)."""
    from flex.dynamics.reference import SliderCrankDAE

    dae = SliderCrankDAE(scene)
    ranks, smallest, slider_input = [], [], []
    for theta in np.asarray(crank_angles_rad, dtype=float):
        dae.initial_crank_angle_rad = theta
        q, _ = dae.initial_state()
        jac = dae.jacobian(q)
        found = jacobian_mobility(jac)
        ranks.append(found["rank"])
        smallest.append(float(found["singular_values"].min()))
        slider_input.append(smallest_singular_value(np.delete(jac, 6, axis=1)[:8]))
    return {"rank": np.asarray(ranks), "smallest_singular_value": np.asarray(smallest),
            "slider_input_smallest_singular_value": np.asarray(slider_input),
            "rows": np.asarray(dae.n_constraints), "coordinates": np.asarray(9)}


def mechanism_checks(scene: Scene, deployment_angles_rad: np.ndarray) -> dict[str, Dataset]:
    """Mobility by Gruebler and Kutzbach from the scene's bodies and joints, by the rank of
    the constraint Jacobian along the deployment and over a full turn, the dead centres and
    the transmission angle over a full turn: ``mechanism/*`` datasets."""
    bodies, joints = topology(scene)
    counted = counted_mobility(bodies, joints)
    turn = np.radians(np.arange(0.0, 360.0, 1.0))
    along = jacobian_along(scene, deployment_angles_rad)
    full = jacobian_along(scene, turn)
    coupler = slider_crank(scene["crank"]["length_m"], scene["coupler"]["length_m"], turn,
                           offset_m=scene["slider"]["offset_m"]).coupler_angle_rad
    dead = dead_centre_angles_rad(scene["crank"]["length_m"], scene["coupler"]["length_m"],
                                  scene["slider"]["offset_m"])
    return {
        "mechanism/bodies": Dataset(np.array(bodies, dtype=object), "1", "bodies with frame"),
        "mechanism/joints": Dataset(np.array([f"{j.name}:{j.kind}" for j in joints],
                                             dtype=object), "1", "joints and kinds"),
        "mechanism/gruebler_mobility": Dataset(counted["gruebler"], "1", "thesis Eq. 1"),
        "mechanism/kutzbach_mobility": Dataset(counted["kutzbach"], "1", "thesis Eq. 2"),
        "mechanism/jacobian_rows": Dataset(along["rows"], "1", "reference DAE constraints"),
        "mechanism/jacobian_rank_min": Dataset(int(min(along["rank"].min(), full["rank"].min())),
                                               "1", "smallest rank, deployment and full turn"),
        "mechanism/jacobian_mobility": Dataset(int(9 - along["rank"].min()), "1",
                                               "9 coordinates - rank (deployment)"),
        "mechanism/redundant_constraints": Dataset(int(along["rows"] - along["rank"].min()), "1",
                                                   "constraint rows - rank"),
        "mechanism/dead_centre_angles": Dataset(np.degrees(dead), "deg",
                                                "extended and folded dead centres"),
        "mechanism/turn_angle": Dataset(np.degrees(turn), "deg", "crank angle, full turn"),
        "mechanism/turn_transmission_angle": Dataset(
            np.degrees(transmission_angle_rad(turn, coupler)), "deg", "transmission angle"),
        "mechanism/turn_slider_input_singular_value": Dataset(
            full["slider_input_smallest_singular_value"], "1",
            "smallest singular value, Jacobian with the slider as input"),
        "mechanism/deployment_angle": Dataset(np.degrees(deployment_angles_rad), "deg",
                                              "crank angle over the design deployment"),
        "mechanism/deployment_slider_input_singular_value": Dataset(
            along["slider_input_smallest_singular_value"], "1",
            "smallest singular value along the design deployment")}
