"""Closed-form kinematics of the offset slider-crank (positions, velocities, accelerations).

Sketch (mechanism plane x-y, crank pivot A at the origin, slide line y = e)::

            B
           / \\
       L1 /   \\ L2
         /     \\
        A-------C====  slide line y = e (e = 0: in-line)
        theta: crank angle from +x; phi: coupler angle from +x (B -> C)

    x_C = L1 cos(theta) + sqrt(L2^2 - (L1 sin(theta) - e)^2)

All lengths in metres, angles in radians, rates per second.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flex.base.errors import SceneError


@dataclass(frozen=True)
class SliderCrankState:
    """Kinematic state arrays (same shape as the input angle)."""

    slider_position_m: np.ndarray
    slider_velocity_m_per_s: np.ndarray
    slider_acceleration_m_per_s2: np.ndarray
    coupler_angle_rad: np.ndarray
    coupler_angular_velocity_rad_per_s: np.ndarray
    coupler_angular_acceleration_rad_per_s2: np.ndarray


def slider_crank(crank_length_m: float, coupler_length_m: float, crank_angle_rad,
                 crank_speed_rad_per_s=0.0, crank_acceleration_rad_per_s2=0.0,
                 offset_m: float = 0.0) -> SliderCrankState:
    """Exact slider and coupler motion for given crank angle, speed and acceleration.

    Inputs may be scalars or arrays (broadcast). Raises :class:`SceneError` if the linkage
    cannot assemble at some angle (``|L1 sin(theta) - e| >= L2``).
    """
    theta = np.asarray(crank_angle_rad, dtype=float)
    omega = np.asarray(crank_speed_rad_per_s, dtype=float)
    alpha = np.asarray(crank_acceleration_rad_per_s2, dtype=float)
    height = crank_length_m * np.sin(theta) - offset_m  # y_B - y_C
    if np.any(np.abs(height) >= coupler_length_m):
        raise SceneError("linkage cannot assemble: |L1 sin(theta) - offset| >= L2 "
                         "at some crank angle")
    phi = np.arcsin(-height / coupler_length_m)  # coupler points from B down to C
    # phi from L2 sin(phi) = e - L1 sin(theta); differentiate twice
    cos_phi = np.cos(phi)
    phi_dot = -crank_length_m * np.cos(theta) * omega / (coupler_length_m * cos_phi)
    phi_ddot = (-crank_length_m * (np.cos(theta) * alpha - np.sin(theta) * omega**2)
                + coupler_length_m * np.sin(phi) * phi_dot**2) / (coupler_length_m * cos_phi)
    x = crank_length_m * np.cos(theta) + coupler_length_m * cos_phi
    v = -crank_length_m * np.sin(theta) * omega - coupler_length_m * np.sin(phi) * phi_dot
    a = (-crank_length_m * (np.cos(theta) * omega**2 + np.sin(theta) * alpha)
         - coupler_length_m * (np.cos(phi) * phi_dot**2 + np.sin(phi) * phi_ddot))
    return SliderCrankState(x, v, a, phi, phi_dot, phi_ddot)


def crank_pin(crank_length_m: float, crank_angle_rad: float, crank_speed_rad_per_s: float = 0.0
              ) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] and velocity [m/s] of the crank pin B, (x, y) each:
    ``L1 (cos theta, sin theta)`` and ``omega L1 (-sin theta, cos theta)``."""
    position = np.array([crank_length_m * np.cos(crank_angle_rad),
                         crank_length_m * np.sin(crank_angle_rad)])
    velocity = crank_speed_rad_per_s * crank_length_m * np.array([-np.sin(crank_angle_rad),
                                                                   np.cos(crank_angle_rad)])
    return position, velocity


def constant_speed_motion(crank_length_m: float, coupler_length_m: float,
                          initial_angle_rad: float, crank_speed_rad_per_s: float, time_s,
                          offset_m: float = 0.0) -> tuple[np.ndarray, SliderCrankState]:
    """Crank angle ``theta0 + omega t`` [rad] at the times ``time_s`` [s] and the exact motion
    (:func:`slider_crank`) of a crank turning at the constant speed ``omega`` [rad/s]."""
    theta = initial_angle_rad + crank_speed_rad_per_s * np.asarray(time_s, dtype=float)
    return theta, slider_crank(crank_length_m, coupler_length_m, theta, crank_speed_rad_per_s,
                               0.0, offset_m)


def chord_components(force_N, angle_rad) -> tuple[np.ndarray, np.ndarray]:
    """Components [N] of global x-y forces ``force_N`` (n, 2) along a link's chord at
    ``angle_rad`` (n,) from +x and along the chord's in-plane normal (the chord turned by
    +90 deg): ``(axial, transverse)``, each (n,)."""
    force = np.asarray(force_N, dtype=float)
    angle = np.asarray(angle_rad, dtype=float)
    cos, sin = np.cos(angle), np.sin(angle)
    return force[:, 0] * cos + force[:, 1] * sin, -force[:, 0] * sin + force[:, 1] * cos
