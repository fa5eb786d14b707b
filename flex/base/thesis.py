"""The numbers the thesis reports, each once, with the section, table or equation it is from.

Cavezza, F. (2012). *Flexibility and Transient Dynamic Analysis of a Slider-Crank Deployment
Mechanism*. MS thesis, West Virginia University ("the thesis"). Values the thesis reads off
its own figures are marked "approx." as it marks them. The library and the studies import
them from here (:mod:`flex.fidelity.criteria`, :mod:`flex.experiments.thesis.modal` and
:mod:`flex.bodies.spring` re-export
the ones they have always exposed); the closed forms that use them are in
:mod:`flex.base.physics`. The bundled scene ``flex/data/scenes/cavezza2012.toml`` is the thesis's
mechanism as an input file (data, with its own citations).

SI units, in the names. No flex imports.
"""

from __future__ import annotations

import numpy as np

# --- sec. 4: geometry -------------------------------------------------------------------------
THESIS_CRANK_LENGTH_M = 0.040
"""Crank length L1 (sec. 4), m."""

THESIS_COUPLER_LENGTH_M = 0.080
"""Coupler length L2 (sec. 4), m. Also the length of the Table 5 plates."""

# --- sec. 4.3-4.4: constant-speed kinematics (MATLAB and SolidWorks agree) ---------------------
THESIS_SLIDER_KINEMATICS: dict[str, float] = {
    "stroke_m": 0.080, "velocity_max_m_per_s": 0.28, "velocity_min_m_per_s": -0.28,
    "acceleration_max_m_per_s2": 1.2, "acceleration_min_m_per_s2": -2.3}
"""Slider stroke and extreme velocity and acceleration at one crank turn per second."""

# --- sec. 5.5: spring-driven deployment (read off figures 14-23, "approx.") --------------------
THESIS_CRANK_ANGLE_MAX_RAD = 1.09
"""Crank angle maximum (sec. 5.5), rad."""

THESIS_ANGLE_MAX_TIME_S = 0.0265
"""Time of the crank angle maximum, the end of the half swing (sec. 5.5.1), s."""

THESIS_CRANK_SPEED_MAX_RAD_PER_S = 29.0
"""Crank speed maximum (sec. 5.5), rad/s."""

THESIS_CRANK_SPEED_MAX_TIME_S = 0.013
"""Time of the crank speed maximum (sec. 5.5), s."""

THESIS_SLIDER_TRAVEL_M = 0.022
"""Slider displacement at the crank angle maximum (sec. 5.5.1), m."""

THESIS_SLIDER_INITIAL_POSITION_M = 0.11
"""Slider position at t = 0 (sec. 5.5), m."""

THESIS_CONSTRAINT_NORM_MAX_M = 1e-8
"""Largest norm of the constraint equations (sec. 5.5), m."""

# --- sec. 6.1, Tables 2 and 3: the spring -------------------------------------------------------
THESIS_SPRING_RATE_N_PER_M = 1500.0
"""Spring rate (Table 2; the unit is printed as N/m^2, a typo), N/m."""

THESIS_FREE_LENGTH_M = 0.043
"""Spring free length (sec. 6.1), m."""

THESIS_WIRE_DIAMETER_M = 0.0044
"""Spring wire diameter (sec. 6.1), m."""

THESIS_SPRING_DIAMETER_M = 0.150
"""Spring "diameter" (sec. 6.1, the datasheet's D_max; read as the mean coil diameter), m."""

THESIS_ACTIVE_COILS = 3.0
"""Spring "minimum number of coils" (sec. 6.1), read as the active coils."""

THESIS_COMPRESSION_M = 0.022
"""Spring compression: the top plate pressed 0.022 m, then released (sec. 6.1), m."""

THESIS_MUSIC_WIRE_YOUNGS_MODULUS_PA = 206.84e9
"""Young's modulus of the music wire (Table 3: 206 842 710 000 Pa = 30.0 Mpsi), Pa."""

THESIS_MUSIC_WIRE_DENSITY_KG_PER_M3 = 7861.09
"""Density of the music wire (Table 3), kg/m^3."""

# --- sec. 6.2-6.3: the rigid-or-flexible criterion ---------------------------------------------
THESIS_DELTA_T_S = 0.016128
"""Deployment time delta_t of the criterion (sec. 6.2, note below Table 5; how it was
measured is not stated), s."""

THESIS_K = 108.0
"""The criterion's k (sec. 6.2, Eq. 64-65: rigid if n = delta_t / T > k), in the thesis's
convention T = 1/omega (n = delta_t * omega); Table 5's model 1."""

THESIS_YOUNGS_MODULUS_PA = 200e9
"""Young's modulus of the links' steel, ASTM A36 (Tables 6 and 8), Pa. Poisson's ratio is not
stated."""

THESIS_DENSITY_KG_PER_M3 = 7850.0
"""Density of the links' steel, ASTM A36 (Tables 6 and 8), kg/m^3."""

THESIS_TABLE5_WIDTH_M = 0.010
"""Width of the Table 5 plates ("0.08 x 0.01 x t"), m: out of the mechanism plane (z)."""

# Table 5 "Models Description", verbatim. "Frequency" has no unit in the thesis; it equals the
# Euler-Bernoulli pinned-pinned circular frequency in rad/s (bending height t in the mechanism
# plane; computed with pi = 3.1416, so 4.7e-6 high), and the thesis's period is 1/Frequency
# (not 2 pi/omega).
THESIS_TABLE5: dict[str, np.ndarray] = {
    "model": np.array([0, 1, 2, 3]),
    "coupler_length_m": np.array([0.08, 0.08, 0.08, 0.08]),
    "coupler_width_m": np.array([0.01, 0.01, 0.01, 0.01]),
    "coupler_thickness_m": np.array([0.001, 0.003, 0.005, 0.010]),
    "frequency_as_published": np.array([2247.04282, 6741.12847, 11235.2141, 22470.4282]),
    "period_as_published_s": np.array([0.00044503, 0.00014834, 0.000089006, 0.000044503]),
    "n_as_published": np.array([36, 108, 181, 362]),
    "verdict_as_published": np.array(["flexible", "rigid", "rigid", "rigid"]),
}
"""Table 5: the four plate couplers 0.08 x 0.01 x t m, as published."""

# Table 7 "Modal Results" (crank, ANSYS BEAM188, 5 modes), verbatim. Units are not stated
# ("TIME/FREQ"; ANSYS lists Hz there); the period column is 1/value, rounded.
THESIS_TABLE7_CRANK: dict[str, np.ndarray] = {
    "mode": np.array([1, 2, 3, 4, 5]),
    "frequency_as_published": np.array([13254.0, 24536.0, 31598.0, 36431.0, 45426.0]),
    "period_as_published_s": np.array([0.000075, 0.000040, 0.000031, 0.000027, 0.000022]),
}
"""Table 7 (crank). The thesis derives k = 733 = 0.016128 / 0.000022 (Eq. 66)."""

# Table 9 "Modal Results" (coupler, ANSYS BEAM188, 5 modes), verbatim.
THESIS_TABLE9_COUPLER: dict[str, np.ndarray] = {
    "mode": np.array([1, 2, 3, 4, 5]),
    "frequency_as_published": np.array([3548.4, 7631.5, 13922.0, 15799.0, 18215.0]),
    "period_as_published_s": np.array([0.000281, 0.000131, 0.000071, 0.000063, 0.000054]),
}
"""Table 9 (coupler). The thesis derives k = 299 = 0.016128 / 0.000054 (Eq. 67)."""

THESIS_K_CRANK = 733
"""Eq. 66: k of the crank, delta_t over its fifth-mode "period" (Table 7)."""

THESIS_K_COUPLER = 299
"""Eq. 67: k of the coupler, delta_t over its fifth-mode "period" (Table 9)."""

# --- sec. 6.4: the wing (fig. 60, "approx.") ------------------------------------------------
THESIS_WING_PEAK_RATE_DEG_PER_S = 7219.0
"""Peak wing angular velocity (sec. 6.4, fig. 60), deg/s."""

THESIS_WING_PEAK_TIME_S = 0.008
"""Time of the peak wing angular velocity (sec. 6.4, fig. 60, "approx."), s."""

THESIS_WING_DEPLOYMENT_TIME_S = 0.017
"""Wing deployment time (sec. 6.4, "approx."), s."""
