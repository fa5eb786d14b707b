"""Predict the elastic deflection a rigid link leaves out, from the rigid run's own loads.

Contract of :func:`predict_deflection`: given the series of a rigid run (``time``, the link's
angle, the joint forces on it at its two ends, global x-y [N]) and the link's plate (length,
thickness in the mechanism plane, width, Young's modulus, density), it returns a
:class:`DeflectionPrediction`: the quasi-static midpoint deflection at every sample (the
link a pinned-pinned beam under its own d'Alembert inertia, whose total is the sum of the
transverse joint reactions: :func:`flex.base.physics.pinned_beam_midpoint_deflection_m`),
amplified by the axial compression at midspan (``1 / (1 - P / P_Euler)``,
:func:`flex.base.physics.axial_load_amplification`); then the response of the link's first
pinned-pinned bending mode to that history, a single-degree-of-freedom oscillator starting
at rest (``x'' + w^2 x = w^2 x_qs(t)``, scipy's ``lsim``: the Duhamel integral). Its peak over
the window is the predicted peak elastic deflection [m], and that over the length the rigid
model's predicted deflection error. Beside it, the simpler bound the dynamic load factor of
the load's rise gives (:func:`flex.base.physics.ramp_load_factor` times the quasi-static
peak: 2 for a load that starts at its peak), which misses the free vibration a load step at
the start leaves under a later, higher quasi-static peak.

Nothing here is fitted. Measured against FFRF couplers (6 in-plane modes, h = 1e-5 s) on 12
scenes (steel 1-10 mm, springs 500-20000 N/m, 11 and 22 mm preloads, aluminium, titanium):
the oscillator's peak / the FFRF peak 0.79-0.99 (0.79 at the stiffest spring, P / P_E =
0.075), the load-factor bound 0.63-1.06.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from flex.base.kinematics import chord_components
from flex.base.physics import (
    axial_load_amplification,
    euler_buckling_load_N,
    pinned_beam_midpoint_deflection_m,
    pinned_pinned_omega,
    ramp_load_factor,
)

#: a load that starts at no less than this fraction of its peak counts as a step (r = 0)
STEP_FRACTION = 0.5
#: what ``auto`` multiplies the prediction by before it compares it with the tolerance: the
#: 95 % quantile of measured / predicted deflection error over the 106 fitted cases of make
#: kfit (fresh clone, commit 62741ed; the kfit report shows the distribution every run)
PREDICTION_MARGIN = 1.31


@dataclass(frozen=True)
class DeflectionPrediction:
    """What :func:`predict_deflection` found (see the module doc)."""

    peak_deflection_m: float  #: predicted peak elastic midpoint deflection (oscillator)
    quasi_static_peak_m: float  #: peak of the amplified quasi-static deflection
    load_factor_peak_m: float  #: quasi-static peak times the ramp load factor (the bound)
    load_factor: float  #: that ramp load factor
    rise_time_s: float  #: the load's rise time (0: a step)
    period_s: float  #: first pinned-pinned bending period of the link
    euler_load_ratio: float  #: largest midspan compression / Euler load

    def relative_error(self, length_m: float) -> float:
        """The rigid model's predicted deflection error: peak deflection / length."""
        return self.peak_deflection_m / length_m


def _loads(series: Mapping[str, np.ndarray], link: str) -> tuple[np.ndarray, np.ndarray]:
    """Transverse load total [N] and midspan compression [N] of a rigid link per sample."""
    first, second = (("joints/B/force_on_coupler", "joints/C/force_on_coupler")
                     if link == "coupler" else ("joints/A/force_on_crank",
                                                "joints/B/force_on_crank"))
    axial_a, transverse_a = chord_components(series[first], series[f"{link}/angle"])
    axial_b, transverse_b = chord_components(series[second], series[f"{link}/angle"])
    return transverse_a + transverse_b, (axial_a - axial_b) / 2


def predict_deflection(series: Mapping[str, np.ndarray], plate: Mapping[str, Any],
                       link: str = "coupler", window_end_s: float = np.inf
                       ) -> DeflectionPrediction:
    """The predicted peak elastic midpoint deflection of ``link`` (``"coupler"``) from a
    rigid run's ``series`` (see the module doc); ``plate``: the link's scene values
    (``length_m``, ``thickness_m``, ``width_m``, ``youngs_modulus_Pa``,
    ``density_kg_per_m3``; ``damping_ratio`` of the first mode if given, else 0); samples
    after ``window_end_s`` [s] are left out."""
    time_s = np.asarray(series["time"], dtype=float)
    keep = time_s <= window_end_s * (1 + 1e-12)
    transverse, compression = (values[keep] for values in _loads(series, link))
    sizes = (plate["length_m"], plate["thickness_m"], plate["width_m"],
             plate["youngs_modulus_Pa"])
    euler = euler_buckling_load_N(*sizes)
    static = np.abs(pinned_beam_midpoint_deflection_m(transverse, *sizes))
    amplified = static * axial_load_amplification(compression, euler)
    period = 2 * np.pi / pinned_pinned_omega(plate["length_m"], plate["thickness_m"],
                                             plate["youngs_modulus_Pa"],
                                             plate["density_kg_per_m3"])
    peak_index = int(np.argmax(amplified))
    starts_high = static[0] >= STEP_FRACTION * static.max()
    rise = 0.0 if starts_high else float(time_s[keep][peak_index] - time_s[0])
    factor = float(ramp_load_factor(rise, period))
    signed = np.sign(pinned_beam_midpoint_deflection_m(transverse, *sizes)) * amplified
    response = oscillator_response(time_s[keep], signed, 2 * np.pi / period,
                                   float(plate.get("damping_ratio", 0.0)))
    return DeflectionPrediction(float(np.max(np.abs(response))), float(amplified[peak_index]),
                                float(factor * amplified[peak_index]), factor, rise,
                                float(period), float(max(compression.max(), 0.0) / euler))


def oscillator_response(time_s: np.ndarray, quasi_static: np.ndarray, omega_rad_per_s: float,
                        damping_ratio: float = 0.0) -> np.ndarray:
    """Response x(t) of an oscillator ``x'' + 2 zeta w x' + w^2 x = w^2 x_qs(t)`` starting at
    rest (x = x' = 0 at the first sample) to the quasi-static history ``quasi_static`` sampled
    at ``time_s`` (linear between samples; scipy.signal.lsim). Undamped, a step gives 2 x its
    static value, a slow rise x_qs itself."""
    from scipy.signal import lsim

    if len(time_s) < 2:
        return np.asarray(quasi_static, dtype=float)
    _, response, _ = lsim(([omega_rad_per_s**2],
                           [1.0, 2.0 * damping_ratio * omega_rad_per_s, omega_rad_per_s**2]),
                          np.asarray(quasi_static, dtype=float),
                          np.asarray(time_s, dtype=float) - time_s[0])
    return np.asarray(response, dtype=float)


__all__ = ["DeflectionPrediction", "PREDICTION_MARGIN", "STEP_FRACTION", "oscillator_response",
           "predict_deflection"]
