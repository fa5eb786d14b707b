"""The deployment spring as a rod: Rayleigh's effective mass and the released coil's waves,
each closed form once (numpy/math only; :mod:`flex.fidelity.spring_choice` and
:mod:`flex.bodies.spring` read them)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from flex.base.physics import bisect_root, require_positive


def spring_effective_mass_kg(spring_mass_kg: float) -> float:
    """Rayleigh's effective mass [kg] of a uniform spring of mass ``m_s`` [kg] fixed at one
    end, its other end moving with the load: ``m_s / 3``.

    Quasi-statically each coil moves in proportion to its distance from the fixed end (a
    linear velocity profile), so the coil's kinetic energy is ``int_0^1 m_s (v xi)^2 / 2
    d xi = (m_s / 3) v^2 / 2`` with v the moving end's speed (Rayleigh, *The Theory of
    Sound*, 1877, vol. 1, sec. 156; Shigley sec. 10-8 for coil springs).
    """
    require_positive(spring_mass_kg=spring_mass_kg)
    return spring_mass_kg / 3.0


def spring_end_mass_wave_numbers(mass_ratio: float, count: int) -> np.ndarray:
    """Wave numbers ``beta_j`` [rad], j = 1..count, of a uniform spring (rate k, mass m_s) fixed
    at one end and carrying a point mass M at the other: the roots of ``beta tan(beta) =
    m_s / M`` (``mass_ratio`` = m_s / M > 0), one in each ``((j-1) pi, (j-1) pi + pi/2)``.

    The mode shapes are ``sin(beta_j x / L)``, the circular frequencies ``beta_j sqrt(k /
    m_s)`` (a rod with a tip mass, Blevins 1979, ch. 8). M -> 0 gives the fixed-free spring,
    ``(j - 1/2) pi`` (the first period ``4 sqrt(m_s / k)``); m_s << M gives ``beta_1^2 ->
    m_s / M``, i.e. ``omega_1^2 -> k / M``. Solved by bisection to the last bit, as ``beta
    sin(beta) - mu cos(beta) = 0`` (no poles).
    """
    require_positive(mass_ratio=mass_ratio)
    roots = []
    for j in range(count):
        lower = j * math.pi
        roots.append(bisect_root(lambda b: b * math.sin(b) - mass_ratio * math.cos(b),
                             lower, lower + math.pi / 2))
    return np.array(roots)


def released_spring_end_displacement(mass_ratio: float, scaled_time: Any,
                                     modes: int = 64) -> np.ndarray:
    """End displacement, as a fraction of its initial value, of a uniform spring (rate k,
    mass m_s) fixed at one end and carrying a point mass M at the other, released at rest
    from a uniform compression (the deployment spring at t = 0), at ``scaled_time`` ``t
    sqrt(k / m_s)`` [-] (``mass_ratio`` = m_s / M).

    Modal series over the first ``modes`` modes of :func:`spring_end_mass_wave_numbers`:
    ``x(t) / x_0 = sum_j a_j sin(beta_j) cos(beta_j tau)``, ``a_j`` the projection of the
    linear initial shape ``xi`` on ``sin(beta_j xi)`` in the inner product of the spring and
    its end mass (``m_s int_0^1 f g d xi + M f(1) g(1)``, in which the modes are orthogonal):
    ``a_j = [(sin b - b cos b) / b^2 + sin(b) / mu] / [1/2 - sin(2 b) / (4 b) + sin(b)^2 /
    mu]``. The terms fall fast: 64 modes hold the series to 1e-5 of x_0.
    """
    beta = spring_end_mass_wave_numbers(mass_ratio, modes)
    sin_b = np.sin(beta)
    shape = (sin_b - beta * np.cos(beta)) / beta**2 + sin_b / mass_ratio
    norm = 0.5 - np.sin(2.0 * beta) / (4.0 * beta) + sin_b**2 / mass_ratio
    tau = np.asarray(scaled_time, dtype=float)
    return np.cos(np.multiply.outer(tau, beta)) @ (shape / norm * sin_b)


def released_spring_rayleigh_deviation(mass_ratio: float, modes: int = 64,
                                       samples: int = 2001) -> float:
    """Largest deviation of the released spring's end (:func:`released_spring_end_displacement`)
    from its Rayleigh model, a massless spring on the mass M + m_s / 3
    (:func:`spring_effective_mass_kg`; ``cos(tau / sqrt(1/mu + 1/3))``), over the spring's
    first half period ``pi / beta_1`` (its swing), relative to that swing (2 x_0) [-].

    What the coil's waves (surge) and the shift of its first frequency from Rayleigh's add
    to the quasi-static effect of its mass; ``mass_ratio`` = m_s / M. Of order mu^2 for a
    light coil: 2.7e-4 at mu = 0.1, 0.013 at 1, 0.063 at 3.
    """
    beta_1 = spring_end_mass_wave_numbers(mass_ratio, 1)[0]
    tau = np.linspace(0.0, math.pi / beta_1, samples)
    exact = released_spring_end_displacement(mass_ratio, tau, modes)
    rayleigh = np.cos(tau / math.sqrt(1.0 / mass_ratio + 1.0 / 3.0))
    return float(np.max(np.abs(exact - rayleigh)) / 2.0)
