"""How loaded a coupler is, and how far a model's motion is from a reference's.

- :func:`coupler_compression_N`: the link's compression along its chord B-C, against the
  pinned-pinned Euler load pi^2 E I / L^2 (I = w t^3 / 12) of its plate
  (:attr:`flex.base.physics.Plate.euler_load_N`);
  near 1 the axial force changes the bending stiffness (the linear FFRF body is blind to
  it, flex's default FFRF body carries it: :mod:`flex.bodies.geometric_stiffness`);
- :func:`motion_error_fractions`: an FFRF run's error on the motion (headline values against
  a reference's: the stored converged references of ``make flexible``,
  :mod:`flex.experiments.thesis.flexible`) as a fraction of what the link's elasticity changes
  in it (the FFRF run against its rigid twin).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from flex.base.kinematics import chord_components
from flex.dynamics.link_models import BUILTIN_LINK_MODELS


def coupler_compression_N(data: dict[str, np.ndarray], samples: int | None = None
                          ) -> np.ndarray:
    """Compression of the coupler along its chord B-C at each sample [N] (> 0: pushed).

    The slider pushes on the coupler at C: compression is the joint C force on the coupler
    pointing from C toward B. ``samples``: only the first that many samples (None: all).
    """
    axial, _ = chord_components(data["joints/C/force_on_coupler"][:samples],
                                data["coupler/angle"][:samples])
    return -axial


Values = dict[str, tuple[Any, str, str]]  # key -> (value, units, description)

#: what each compared model (a case named after it) is called in reports
LABELS = {**{name: model.label for name, model in BUILTIN_LINK_MODELS.items()},
          "linear": "linear FFRF (geometric_stiffness = false)"}

#: the headline quantities of the motion whose FFRF error is compared with the elasticity's
#: effect on them (:func:`motion_error_fractions`), by report name
MOTION = {"joint A peak force": "joint_A_deployment_peak_force_N",
          "joint B peak force": "joint_B_deployment_peak_force_N",
          "joint C peak force": "joint_C_deployment_peak_force_N",
          "deployment time": "deployment_time_s",
          "crank angle": "crank_angle_end_rad",
          "slider position": "slider_position_end_m"}


def motion_error_fractions(ffrf: Mapping[str, float], rigid: Mapping[str, float],
                           reference: Mapping[str, float]) -> dict[str, float]:
    """|FFRF - reference| / |FFRF - rigid twin| of each :data:`MOTION` quantity (headline
    values by name, each in its unit; NaN where one is missing or the twins agree): the FFRF
    body's model error as a fraction of what the elasticity changes (what
    :data:`flex.config.ladder.FFRF_MOTION_ERROR_FRACTION` bounds)."""
    out = {}
    for name, quantity in MOTION.items():
        values = [source.get(quantity) for source in (ffrf, rigid, reference)]
        if any(value is None for value in values):
            out[name] = float("nan")
            continue
        ffrf_value, rigid_value, reference_value = (float(value) for value in values)
        effect = abs(ffrf_value - rigid_value)
        out[name] = abs(ffrf_value - reference_value) / effect if effect > 0 else float("nan")
    return out
