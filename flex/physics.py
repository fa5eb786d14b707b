"""Closed forms of beam and plate theory used across flex (numpy and math only).

Each formula exists once, here; the library and the studies import it. Units are in the
names; frequencies are circular [rad/s].
"""

from __future__ import annotations

import math

TWO_PI = 2.0 * math.pi


def pinned_pinned_omega(length_m: float, height_m: float, youngs_modulus_Pa: float,
                        density_kg_per_m3: float) -> float:
    """First bending circular frequency [rad/s] of a pinned-pinned rectangular beam.

    Euler-Bernoulli: ``omega = (pi / L)^2 sqrt(E I / (rho A))`` with ``I / A = h^2 / 12``
    (``h`` the bending height, the plate thickness in the mechanism plane; the width
    cancels). Thesis Table 5's "Frequency" column is this value. The finite-element value
    of :class:`flex.reduction.Reduction` is within 2.4 % of it up to t = 10 mm (L/t = 8).
    """
    for name, value in (("length_m", length_m), ("height_m", height_m),
                        ("youngs_modulus_Pa", youngs_modulus_Pa),
                        ("density_kg_per_m3", density_kg_per_m3)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r}: must be a finite number > 0")
    return (math.pi / length_m) ** 2 * math.sqrt(youngs_modulus_Pa * height_m**2
                                                 / (12.0 * density_kg_per_m3))


def n_values(delta_t_s: float, omega_rad_per_s: float) -> dict[str, float]:
    """``{"thesis": delta_t * omega, "physical": delta_t * omega / (2 pi)}`` (dimensionless)."""
    n_thesis = float(delta_t_s) * float(omega_rad_per_s)
    return {"thesis": n_thesis, "physical": n_thesis / TWO_PI}


_CLAMPED_BETA_L = (4.730040745, 7.853204624, 10.99560784, 14.13716549, 17.27875966)


def _clamped_beta_l(index: int) -> float:
    return _CLAMPED_BETA_L[index] if index < len(_CLAMPED_BETA_L) else (index + 1.5) * math.pi


def clamped_plate_frequencies(length_m: float, thickness_m: float, width_m: float,
                              youngs_modulus_Pa: float, density_kg_per_m3: float,
                              poisson_ratio: float, count: int = 40) -> list[tuple[float, str]]:
    """Beam-theory estimates of the fixed-interface (both ends clamped) modes of a plate.

    Returns the ``count`` lowest ``(omega [rad/s], kind)`` with kind ``in_plane`` (bending
    height t), ``out_of_plane`` (height w), ``torsion`` (St. Venant, J = b h^3 (1/3 - 0.21
    h/b (1 - h^4/(12 b^4)))) or ``axial``: the order in which the Craig-Bampton
    fixed-interface modes of :func:`flex.reduction.build_reduction` appear (estimates;
    shear and warping shift them by some per cent).
    """
    e, rho, length = youngs_modulus_Pa, density_kg_per_m3, length_m
    shear = e / (2 * (1 + poisson_ratio))
    b, h = max(width_m, thickness_m), min(width_m, thickness_m)
    torsion_j = b * h**3 * (1 / 3 - 0.21 * h / b * (1 - h**4 / (12 * b**4)))
    polar = width_m * thickness_m * (width_m**2 + thickness_m**2) / 12
    modes: list[tuple[float, str]] = []
    for index in range(count):
        beta = _clamped_beta_l(index) / length
        modes.append((beta**2 * math.sqrt(e * thickness_m**2 / (12 * rho)), "in_plane"))
        modes.append((beta**2 * math.sqrt(e * width_m**2 / (12 * rho)), "out_of_plane"))
        modes.append(((index + 1) * math.pi / length * math.sqrt(shear * torsion_j
                                                                 / (rho * polar)), "torsion"))
        modes.append(((index + 1) * math.pi / length * math.sqrt(e / rho), "axial"))
    return sorted(modes)[:count]
