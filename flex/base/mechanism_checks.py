"""Mechanism checks a designer needs: mobility, constraint-Jacobian rank, dead centres and
the transmission angle of a planar linkage (closed forms; numpy only).

- **Mobility by counting** (thesis sec. 4.1): Gruebler, Eq. 1, ``M = 3 (L - 1) - 2 J1 - J2``
  (L links with the frame, J1 one-freedom joints, J2 two-freedom joints), and Kutzbach, Eq. 2,
  ``M = gamma (L - j - 1) + sum f_i`` (gamma = 3 in the plane, j joints of connectivity
  f_i). Gruebler's equation has no term for a weld (f = 0): :func:`gruebler_mobility` takes
  such joints as ``welds`` (three constraints each), so that both counts hold for any planar
  joint set and agree (they are the same count written twice).
- **Mobility by rank** (:func:`jacobian_mobility`): the number of coordinates minus the rank
  of the constraint Jacobian at a configuration. Counting and rank agree when no constraint
  is redundant; ``rows - rank`` is the number of redundant constraints.
- **Dead centres** (:func:`dead_centre_angles_rad`): the crank angles at which crank and
  coupler of an offset slider-crank are collinear; a slider drive gives the crank no torque
  there. The smallest singular value of the Jacobian with the slider coordinate taken as
  the input (:func:`smallest_singular_value`) falls to 0 at them.
- **Transmission angle** (:func:`transmission_angle_rad`): the acute angle between coupler
  and crank at the crank pin B, in [0, pi/2]; a coupler force F gives the crank the torque
  ``F L1 sin(mu)``: 90 deg is ideal, 0 a dead centre.

Angles in radians, lengths in metres.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: degrees of freedom a planar joint leaves between its two bodies
JOINT_FREEDOMS = {"revolute": 1, "prismatic": 1, "pin_in_slot": 2, "cam": 2, "weld": 0}
PLANAR_MOBILITY_PARAMETER = 3


@dataclass(frozen=True)
class Joint:
    """A planar joint: ``name``, the two bodies it connects and its ``kind`` (a key of
    :data:`JOINT_FREEDOMS`)."""

    name: str
    bodies: tuple[str, str]
    kind: str

    @property
    def freedom(self) -> int:
        """Degrees of freedom the joint leaves (1 revolute or prismatic, 2, 0 a weld)."""
        return JOINT_FREEDOMS[self.kind]


def gruebler_mobility(links: int, one_freedom_joints: int, two_freedom_joints: int = 0,
                      welds: int = 0) -> int:
    """Gruebler (thesis Eq. 1): ``M = 3 (L - 1) - 2 J1 - J2`` (``- 3`` per weld).
    ``links``: bodies including the frame."""
    return 3 * (links - 1) - 2 * one_freedom_joints - two_freedom_joints - 3 * welds


def kutzbach_mobility(links: int, joint_freedoms: Sequence[int],
                      mobility_parameter: int = PLANAR_MOBILITY_PARAMETER) -> int:
    """Kutzbach (thesis Eq. 2): ``M = gamma (L - j - 1) + sum f_i`` for j joints of
    connectivity ``joint_freedoms``; ``links`` includes the frame."""
    return mobility_parameter * (links - len(joint_freedoms) - 1) + int(sum(joint_freedoms))


def counted_mobility(bodies: Sequence[str], joints: Sequence[Joint]) -> dict[str, int]:
    """Gruebler's and Kutzbach's mobility of a planar linkage given as its bodies (with the
    frame) and joints; raises ValueError for a joint naming a body not in ``bodies``."""
    for joint in joints:
        missing = [body for body in joint.bodies if body not in bodies]
        if missing:
            raise ValueError(f"joint {joint.name} connects {missing[0]!r}, not a body of "
                             f"the linkage ({', '.join(bodies)})")
    freedoms = [joint.freedom for joint in joints]
    return {"gruebler": gruebler_mobility(len(bodies), freedoms.count(1), freedoms.count(2),
                                          freedoms.count(0)),
            "kutzbach": kutzbach_mobility(len(bodies), freedoms)}


def jacobian_mobility(jacobian: np.ndarray, relative_tolerance: float = 1e-9
                      ) -> dict[str, object]:
    """Rank of a constraint Jacobian (rows: constraints, columns: coordinates), its singular
    values, the mobility ``columns - rank`` and the redundant constraints ``rows - rank``;
    a singular value counts when above ``relative_tolerance`` x the largest."""
    matrix = np.atleast_2d(np.asarray(jacobian, dtype=float))
    values = np.linalg.svd(matrix, compute_uv=False)
    rank = int(np.sum(values > relative_tolerance * max(float(values.max(initial=0.0)), 1e-300)))
    return {"rank": rank, "singular_values": values, "mobility": matrix.shape[1] - rank,
            "redundant": matrix.shape[0] - rank}


def smallest_singular_value(matrix: np.ndarray) -> float:
    """Smallest singular value of a square matrix (0 where it is singular)."""
    return float(np.linalg.svd(np.asarray(matrix, dtype=float), compute_uv=False).min())


def dead_centre_angles_rad(crank_length_m: float, coupler_length_m: float,
                           offset_m: float = 0.0) -> tuple[float, float]:
    """Crank angles [rad] of the extended (B beyond A on the line A-C) and folded dead
    centres of a slider-crank with slide line y = ``offset_m``: ``asin(e / (L2 + L1))`` and
    ``pi + asin(e / (L2 - L1))`` (0 and pi in line). Needs ``L1 + |e| < L2``."""
    if crank_length_m + abs(offset_m) >= coupler_length_m:
        raise ValueError("dead centres: the crank must turn (L1 + |offset| < L2)")
    return (float(np.arcsin(offset_m / (coupler_length_m + crank_length_m))),
            float(np.pi + np.arcsin(offset_m / (coupler_length_m - crank_length_m))))


def angle_to_dead_centres_rad(crank_angle_rad, dead_centres_rad: Sequence[float]) -> np.ndarray:
    """Angular distance [rad] of each crank angle to the nearest dead centre (modulo 2 pi)."""
    theta = np.asarray(crank_angle_rad, dtype=float)[..., None]
    gap = np.abs((theta - np.asarray(dead_centres_rad) + np.pi) % (2 * np.pi) - np.pi)
    return gap.min(axis=-1)


def transmission_angle_rad(crank_angle_rad, coupler_angle_rad) -> np.ndarray:
    """Transmission angle [rad] at the crank pin: the acute angle between the crank (A -> B
    at ``crank_angle_rad``) and the coupler (B -> C at ``coupler_angle_rad``), in [0, pi/2];
    ``arcsin |sin(theta - phi)|``."""
    difference = np.asarray(crank_angle_rad, dtype=float) - np.asarray(coupler_angle_rad,
                                                                       dtype=float)
    return np.arcsin(np.clip(np.abs(np.sin(difference)), 0.0, 1.0))
