"""Closed forms of beam and plate theory used across flex (numpy and math only).

Each formula exists once, here; the library and the studies import it
(:mod:`flex.experiments.thesis.modal` adds the input checks of its public functions, Timoshenko
beams and finite elements). Units are in the names; frequencies are circular [rad/s]. The thesis's
own numbers are in :mod:`flex.base.thesis`.

Theory: Euler-Bernoulli beams, elementary rods and St-Venant torsion as tabulated in
Blevins, *Formulas for Natural Frequency and Mode Shape* (1979), ch. 8 (straight beams:
the characteristic equations of the end conditions and their roots beta_n L); the torsion
constant of a rectangle from Timoshenko & Goodier, *Theory of Elasticity* (3rd ed. 1970),
ch. 10 (torsion of a rectangular bar); Euler buckling from Timoshenko & Gere, *Theory of
Elastic Stability* (2nd ed. 1961), ch. 2 (Euler's column). The deployment spring as a rod
with an end mass (Rayleigh's effective mass, the released coil's modal series): the last
section.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from flex.base.errors import SceneError

TWO_PI = 2.0 * math.pi

BEAM_END_CONDITIONS: tuple[str, ...] = (
    "free-free", "pinned-pinned", "clamped-clamped", "clamped-free", "clamped-pinned")
"""End conditions of one beam bending plane (first end - second end)."""


def require_positive(**values: float) -> None:
    for name, value in values.items():
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r}: must be a finite number > 0")


def _check_stiffness(shear_stiffness_N: float) -> None:
    if not shear_stiffness_N > 0:  # math.inf allowed: a beam without shear deformation
        raise ValueError(f"shear_stiffness_N = {shear_stiffness_N!r}: must be > 0 (or inf)")


def shear_modulus_Pa(youngs_modulus_Pa: float, poisson_ratio: float) -> float:
    """Shear modulus of an isotropic material, ``G = E / (2 (1 + nu))`` [Pa]."""
    return youngs_modulus_Pa / (2.0 * (1.0 + poisson_ratio))


def lame_first_parameter_Pa(youngs_modulus_Pa: float, poisson_ratio: float) -> float:
    """Lame's first parameter of an isotropic material, ``lambda = E nu / ((1 + nu) (1 - 2
    nu))`` [Pa] (with :func:`shear_modulus_Pa`, ``sigma = 2 G eps + lambda tr(eps) I``)."""
    return youngs_modulus_Pa * poisson_ratio / ((1.0 + poisson_ratio)
                                                * (1.0 - 2.0 * poisson_ratio))


def cuboid_mass_kg(length_m: float, thickness_m: float, width_m: float,
                   density_kg_per_m3: float) -> float:
    """Mass [kg] of a solid rectangular block (a plate link, the wing): ``rho L t w``."""
    return density_kg_per_m3 * length_m * thickness_m * width_m


def cuboid_inertia_kgm2(mass_kg: float, length_m: float, thickness_m: float) -> float:
    """Moment of inertia [kg m^2] of a solid rectangular block about the axis through its
    centre normal to its ``length x thickness`` face: ``m (L^2 + t^2) / 12``."""
    return mass_kg * (length_m**2 + thickness_m**2) / 12.0


def plate_thickness_for_mass_m(mass_kg: float, length_m: float, width_m: float,
                               density_kg_per_m3: float) -> float:
    """Thickness [m] of the plate of a given mass: ``m / (rho L w)`` (:func:`cuboid_mass_kg`
    solved for t)."""
    return mass_kg / (density_kg_per_m3 * length_m * width_m)


def euler_buckling_load_N(length_m: float, thickness_m: float, width_m: float,
                          youngs_modulus_Pa: float) -> float:
    """Euler buckling load [N] of a pinned-pinned rectangular strut, buckling in-plane.

    ``P_cr = pi^2 E I / L^2`` with ``I = w t^3 / 12`` (Timoshenko & Gere 1961, ch. 2; ``t``
    the thickness in the mechanism plane, ``w`` the width across it).
    """
    require_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m,
                    youngs_modulus_Pa=youngs_modulus_Pa)
    return math.pi**2 * youngs_modulus_Pa * width_m * thickness_m**3 / 12 / length_m**2


def bisect_root(function: Callable[[float], float], lower: float, upper: float) -> float:
    """Root of ``function`` in [lower, upper] (it must change sign there), to the last bit."""
    f_lower = function(lower)
    if f_lower * function(upper) > 0:
        raise ValueError(f"no sign change in [{lower!r}, {upper!r}]")
    while True:
        middle = 0.5 * (lower + upper)
        if middle <= lower or middle >= upper:
            return middle
        f_middle = function(middle)
        if f_middle == 0.0:
            return middle
        if (f_middle < 0.0) == (f_lower < 0.0):
            lower, f_lower = middle, f_middle
        else:
            upper = middle


def _sech(x: float) -> float:
    """1 / cosh(x) without overflow for large x."""
    decay = math.exp(-abs(x))
    return 2.0 * decay / (1.0 + decay * decay)


def euler_bernoulli_beta_l(end_condition: str, mode_count: int) -> list[float]:
    """Wave numbers ``beta_n L`` of an Euler-Bernoulli beam, n = 1..mode_count (rad).

    Roots of the characteristic equations (Blevins 1979, ch. 8): pinned-pinned
    ``beta L = n pi``; free-free and clamped-clamped ``cos(bL) cosh(bL) = 1`` (4.7300,
    7.8532, ...; the rigid-body root 0 of free-free excluded); clamped-free
    ``cos(bL) cosh(bL) = -1`` (1.8751, 4.6941, ...); clamped-pinned ``tan(bL) = tanh(bL)``
    (3.9266, 7.0686, ...). Solved by bisection to the last bit, as
    ``cos x -+ sech x = 0`` and ``sin x - cos x tanh x = 0`` (no overflow, no poles).
    """
    if end_condition not in BEAM_END_CONDITIONS:
        raise ValueError(f"end_condition = {end_condition!r}: must be one of "
                         f"{', '.join(BEAM_END_CONDITIONS)}")
    return list(_beta_l_roots(end_condition, mode_count))


@cache  # a constant table: make calibrate's fit asks for the same roots ~10^4 times
def _beta_l_roots(end_condition: str, mode_count: int) -> tuple[float, ...]:
    roots: list[float] = []
    for n in range(1, mode_count + 1):
        if end_condition == "pinned-pinned":
            roots.append(float(n) * math.pi)
        elif end_condition in ("free-free", "clamped-clamped"):
            # one sign change within 0.5 of (n + 1/2) pi (the root is within 0.02 of it)
            guess = (n + 0.5) * math.pi
            roots.append(bisect_root(lambda x: math.cos(x) - _sech(x), guess - 0.5, guess + 0.5))
        elif end_condition == "clamped-free":
            guess = (n - 0.5) * math.pi
            roots.append(bisect_root(lambda x: math.cos(x) + _sech(x), max(guess - 0.5, 1.0),
                                 guess + 0.5))
        else:  # clamped-pinned
            guess = (n + 0.25) * math.pi
            roots.append(bisect_root(lambda x: math.sin(x) - math.cos(x) * math.tanh(x),
                                 guess - 0.3, guess + 0.3))
    return tuple(roots)


def euler_bernoulli_omega(beta_l: Any, length_m: float, height_m: float,
                          youngs_modulus_Pa: float, density_kg_per_m3: float) -> Any:
    """Bending circular frequency [rad/s] of a rectangular Euler-Bernoulli beam.

    ``omega = (beta L / L)^2 sqrt(E I / (rho A))`` with ``I / A = h^2 / 12`` (Blevins 1979,
    ch. 8; ``h`` the section's side along the bending displacement, the other side
    cancels). ``beta_l``: a wave number of :func:`euler_bernoulli_beta_l` (a float or an
    array of them).
    """
    return (beta_l / length_m) ** 2 * math.sqrt(youngs_modulus_Pa * height_m**2
                                                / (12.0 * density_kg_per_m3))


def pinned_beam_midpoint_deflection_m(transverse_load_N: Any, length_m: float,
                                      thickness_m: float, width_m: float,
                                      youngs_modulus_Pa: float) -> Any:
    """Static midpoint deflection [m] of a pinned-pinned rectangular beam under a linearly
    distributed transverse load whose total is ``transverse_load_N`` [N], relative to the
    chord, bending in-plane (``I = w t^3 / 12``).

    Only the load's mean acts at midspan: the antisymmetric part of a linear distribution
    bends the beam into an odd shape, zero at the middle. A uniform load W: ``delta = 5 W
    L^3 / (384 E I)`` (Timoshenko & Gere, *Mechanics of Materials*, simply supported beam;
    :func:`pinned_timoshenko_midpoint_deflection_m` without its shear part).
    The total load of a rigid link's d'Alembert inertia is the sum of its transverse joint
    reactions, so a rigid run's joint forces give it directly. Arrays broadcast.
    """
    require_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m,
                    youngs_modulus_Pa=youngs_modulus_Pa)
    inertia_m4 = width_m * thickness_m**3 / 12
    return _uniform_load_bending_deflection_m(np.asarray(transverse_load_N), length_m,
                                              youngs_modulus_Pa * inertia_m4)


def _uniform_load_bending_deflection_m(total_load_N: Any, length_m: float,
                                       bending_stiffness_Nm2: float) -> Any:
    """Bending part ``5 W L^3 / (384 E I)`` [m] of a pinned-pinned beam's midpoint deflection
    under a uniform load of total ``W`` [N]."""
    return 5.0 * total_load_N * length_m**3 / (384 * bending_stiffness_Nm2)


def pinned_timoshenko_midpoint_deflection_m(line_load_N_per_m: Any, length_m: float,
                                            bending_stiffness_Nm2: float,
                                            shear_stiffness_N: float) -> Any:
    """Static midpoint deflection [m] of a pinned-pinned Timoshenko beam under a uniform
    transverse load ``q`` [N/m]: the bending part ``5 q L^4 / (384 E I)`` plus the shear
    part ``q L^2 / (8 kappa G A)`` (``bending_stiffness_Nm2`` E I [N m^2],
    ``shear_stiffness_N`` kappa G A [N]; ``math.inf``: no shear deformation, the
    Euler-Bernoulli beam).

    The shear part is the shear force's work, ``int Q^2 / (kappa G A) dx`` by Castigliano
    with a unit load at midspan: ``M_mid / (kappa G A)`` with ``M_mid = q L^2 / 8``
    (Timoshenko, *Strength of Materials*, Part I, 3rd ed. 1955, art. 39, effect of the
    shearing force on the deflection of beams). Arrays broadcast.
    """
    require_positive(length_m=length_m, bending_stiffness_Nm2=bending_stiffness_Nm2)
    _check_stiffness(shear_stiffness_N)
    load = np.asarray(line_load_N_per_m)
    return (_uniform_load_bending_deflection_m(load * length_m, length_m,
                                               bending_stiffness_Nm2)
            + load * length_m**2 / (8.0 * shear_stiffness_N))


def timoshenko_pinned_pinned_omega(mode_number: Any, length_m: float,
                                   bending_stiffness_Nm2: float, shear_stiffness_N: float,
                                   mass_per_length_kg_per_m: float,
                                   rotary_inertia_kg_m: float) -> Any:
    """Bending circular frequency [rad/s] of mode ``mode_number`` (1, 2, ...; a float or an
    array) of a pinned-pinned Timoshenko beam, from its section: ``E I`` [N m^2], ``kappa G
    A`` [N] (``math.inf``: no shear deformation), ``rho A`` [kg/m], ``rho I`` [kg m] (0: no
    rotary inertia; both off: Euler-Bernoulli).

    With ``w ~ sin(k x)``, ``psi ~ cos(k x)``, ``k = n pi / L`` the Timoshenko equations give
    the frequency equation ``rho A rho I / (kappa G A) omega^4 - omega^2 (rho A + rho I k^2 +
    rho A E I k^2 / (kappa G A)) + E I k^4 = 0``, whose lower root is the bending mode (Han,
    Benaroya and Wei, *Dynamics of transversely vibrating beams using four engineering
    theories*, J. Sound Vib. 225 (1999) 935-988, the hinged-hinged Timoshenko beam); here
    written without cancellation, ``omega^2 = 2 c / (b + sqrt(b^2 - 4 a c))``.
    """
    require_positive(length_m=length_m, bending_stiffness_Nm2=bending_stiffness_Nm2,
                    mass_per_length_kg_per_m=mass_per_length_kg_per_m)
    _check_stiffness(shear_stiffness_N)
    if not (math.isfinite(rotary_inertia_kg_m) and rotary_inertia_kg_m >= 0):
        raise ValueError(f"rotary_inertia_kg_m = {rotary_inertia_kg_m!r}: must be finite, >= 0")
    wave_number = np.asarray(mode_number, dtype=float) * math.pi / length_m
    flexibility = 1.0 / shear_stiffness_N  # 0 without shear deformation
    quartic = mass_per_length_kg_per_m * rotary_inertia_kg_m * flexibility
    quadratic = (rotary_inertia_kg_m * wave_number**2 + mass_per_length_kg_per_m
                 + mass_per_length_kg_per_m * bending_stiffness_Nm2 * wave_number**2
                 * flexibility)
    constant = bending_stiffness_Nm2 * wave_number**4
    discriminant = np.sqrt(quadratic**2 - 4.0 * quartic * constant)
    return np.sqrt(2.0 * constant / (quadratic + discriminant))


def anticlastic_centroid_offset(length_m: float, thickness_m: float, width_m: float,
                                poisson_ratio: float) -> float:
    """How much less the centroid of the mid-span section of a pinned-pinned plate strip
    under a uniform transverse load deflects than the section's mean, relative to the
    deflection [-]: ``0.4 nu (w^2 - t^2) / L^2`` (``~0.4 nu (w / L)^2`` for a thin strip).

    In bending of curvature ``1/R`` a section does not stay straight (Saint-Venant's pure
    bending of a prismatic bar, Timoshenko & Goodier, *Theory of Elasticity*, 3rd ed. 1970,
    art. 103): ``u_y = -(x^2 + nu (y^2 - z^2)) / (2 R)``, ``y`` across the thickness t (the
    bending direction), ``z`` across the width w. Over the section ``<y^2> = t^2 / 12``,
    ``<z^2> = w^2 / 12``, so the mean moves ``nu (w^2 - t^2) / (24 R)`` beyond the centroid.
    At mid-span of a uniform load ``1 / R = (q L^2 / 8) / (E I) = 9.6 delta / L^2`` (delta =
    ``5 q L^4 / (384 E I)``). An estimate: it neglects the shear part and the ends.
    """
    require_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m)
    return 0.4 * poisson_ratio * (width_m**2 - thickness_m**2) / length_m**2


def pinned_beam_end_moment_midpoint_deflection_m(end_moment_N_m: Any, length_m: float,
                                                 thickness_m: float, width_m: float,
                                                 youngs_modulus_Pa: float) -> Any:
    """Static midpoint deflection [m] of a pinned-pinned rectangular beam under a moment
    ``end_moment_N_m`` [N m] applied at its first end, relative to the chord, bending
    in-plane (``I = w t^3 / 12``): ``delta = M L^2 / (16 E I)``.

    Signs: the beam along +x from the loaded end, the moment about +z (counter-clockwise),
    the deflection along +y (the chord turned by +90 deg); a counter-clockwise moment at the
    first end arches the beam towards +y. The bending moment falls linearly from M to 0
    along the beam (Timoshenko & Gere, *Mechanics of Materials*, simply supported beam with
    an end couple; the peak, 1 / (9 sqrt 3) M L^2 / EI at x = L (1 - 1/sqrt 3), is 2.6 %
    above the midpoint value). The crank of a mechanism with a wing welded at its pivot
    carries the wing's inertia moment there. Arrays broadcast.
    """
    require_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m,
                    youngs_modulus_Pa=youngs_modulus_Pa)
    inertia_m4 = width_m * thickness_m**3 / 12
    return np.asarray(end_moment_N_m) * length_m**2 / (16 * youngs_modulus_Pa * inertia_m4)


def axial_load_amplification(compression_N: Any, euler_load_N: float) -> Any:
    """Amplification ``1 / (1 - P / P_E)`` of a pinned-pinned beam's bending by an axial
    compression ``P`` [N] (tension: below 1), the geometric stiffness of the axial load
    (Timoshenko & Gere 1961, ch. 1, beam-columns; exact for a sine-shaped deflection);
    infinite at and beyond the Euler load ``P_E`` [N]."""
    ratio = np.asarray(compression_N, dtype=float) / euler_load_N
    with np.errstate(divide="ignore"):
        return np.where(ratio < 1.0, 1.0 / (1.0 - np.minimum(ratio, 1.0)), np.inf)


def ramp_load_factor(rise_time_s: Any, period_s: float) -> Any:
    """Dynamic load factor of an undamped single-degree-of-freedom oscillator of ``period_s``
    under a load that rises linearly over ``rise_time_s`` and then stays: ``1 + |sin(pi r)|
    / (pi r)`` with ``r = t_rise / T`` (Biggs, *Introduction to Structural Dynamics*, 1964,
    ch. 2); 2 for a step (r = 0), towards 1 for a slow rise."""
    ratio = np.asarray(rise_time_s, dtype=float) / period_s
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = 1.0 + np.abs(np.sin(np.pi * ratio)) / (np.pi * ratio)
    return np.where(ratio > 0, factor, 2.0)


def pinned_pinned_omega(length_m: float, height_m: float, youngs_modulus_Pa: float,
                        density_kg_per_m3: float) -> float:
    """First bending circular frequency [rad/s] of a pinned-pinned rectangular beam.

    Euler-Bernoulli: ``omega = (pi / L)^2 sqrt(E I / (rho A))`` with ``I / A = h^2 / 12``
    (``h`` the bending height, the plate thickness in the mechanism plane; the width
    cancels). Thesis Table 5's "Frequency" column is this value (4.7e-6 higher: the thesis
    took pi = 3.1416). The finite-element value of :class:`flex.bodies.reduction.Reduction` is
    within 2.4 % of it up to t = 10 mm (L/t = 8).
    """
    require_positive(length_m=length_m, height_m=height_m,
                    youngs_modulus_Pa=youngs_modulus_Pa, density_kg_per_m3=density_kg_per_m3)
    return euler_bernoulli_omega(math.pi, length_m, height_m, youngs_modulus_Pa,
                                 density_kg_per_m3)


def rectangle_torsion_constant_m4(height_m: float, width_m: float, series_terms: int = 50
                                  ) -> float:
    """St-Venant torsion constant J [m^4] of a solid rectangle.

    ``J = a b^3 / 3 (1 - 192 b / (pi^5 a) sum_{n odd} tanh(n pi a / (2 b)) / n^5)``, ``a >= b``
    the long and short sides (Timoshenko & Goodier 1970, ch. 10, the exact series).
    Square: ``J = 0.1406 a^4``.
    """
    long_side_m, short_side_m = max(height_m, width_m), min(height_m, width_m)
    odd = np.arange(1, 2 * series_terms, 2, dtype=float)
    series = np.sum(np.tanh(odd * math.pi * long_side_m / (2.0 * short_side_m)) / odd**5)
    return float(long_side_m * short_side_m**3 / 3.0
                 * (1.0 - 192.0 * short_side_m / (math.pi**5 * long_side_m) * series))


def rectangle_polar_moment_m4(height_m: float, width_m: float) -> float:
    """Polar moment of area [m^4] of a rectangle about its centre: ``w h^3/12 + h w^3/12``."""
    return width_m * height_m**3 / 12.0 + height_m * width_m**3 / 12.0


def torsion_omega(mode_number: Any, length_m: float, shear_modulus_Pa: float,
                  torsion_constant_m4: float, polar_moment_m4: float,
                  density_kg_per_m3: float) -> Any:
    """St-Venant torsion circular frequency [rad/s] of a uniform bar (warping neglected).

    ``omega = m pi / L sqrt(G J / (rho I_p))`` (Blevins 1979, ch. 8; the torsion constant J
    in the stiffness, the polar moment I_p in the inertia): ``m = n`` for fixed-fixed and
    free-free ends, ``m = n - 1/2`` for fixed-free (a float or an array).
    """
    return mode_number * math.pi / length_m * math.sqrt(
        shear_modulus_Pa * torsion_constant_m4 / (density_kg_per_m3 * polar_moment_m4))


def axial_omega(mode_number: Any, length_m: float, youngs_modulus_Pa: float,
                density_kg_per_m3: float) -> Any:
    """Axial (rod) circular frequency [rad/s]: ``omega = m pi / L sqrt(E / rho)``.

    Elementary rod theory, no lateral inertia (Blevins 1979, ch. 8): ``m = n`` for fixed-fixed
    and free-free ends, ``m = n - 1/2`` for fixed-free (a float or an array).
    """
    return mode_number * math.pi / length_m * math.sqrt(youngs_modulus_Pa / density_kg_per_m3)


def n_values(delta_t_s: Any, omega_rad_per_s: Any) -> dict[str, Any]:
    """The thesis's rigid-or-flexible count n = delta_t / T in both period conventions.

    ``{"thesis": delta_t * omega, "physical": delta_t * omega / (2 pi)}`` (dimensionless):
    the thesis (Cavezza 2012, sec. 6.2, Eq. 64-65, Table 5) takes T = 1/omega; the period
    is T = 2 pi / omega. Scalars give floats, arrays arrays.
    """
    if np.ndim(delta_t_s) == 0 and np.ndim(omega_rad_per_s) == 0:
        n_thesis = float(delta_t_s) * float(omega_rad_per_s)
    else:
        n_thesis = np.asarray(delta_t_s, dtype=float) * np.asarray(omega_rad_per_s, dtype=float)
    return {"thesis": n_thesis, "physical": n_thesis / TWO_PI}


def clamped_plate_frequencies(length_m: float, thickness_m: float, width_m: float,
                              youngs_modulus_Pa: float, density_kg_per_m3: float,
                              poisson_ratio: float, count: int = 40) -> list[tuple[float, str]]:
    """Beam-theory estimates of the fixed-interface (both ends clamped) modes of a plate.

    Returns the ``count`` lowest ``(omega [rad/s], kind)`` with kind ``in_plane`` (bending
    height t), ``out_of_plane`` (height w), ``torsion`` (St-Venant,
    :func:`rectangle_torsion_constant_m4`) or ``axial``: the order in which the Craig-Bampton
    fixed-interface modes of :func:`flex.bodies.reduction.build_reduction` appear (estimates;
    shear and warping shift them by some per cent).
    """
    e, rho, length = youngs_modulus_Pa, density_kg_per_m3, length_m
    shear = shear_modulus_Pa(e, poisson_ratio)
    torsion_j = rectangle_torsion_constant_m4(thickness_m, width_m)
    polar = rectangle_polar_moment_m4(thickness_m, width_m)
    modes: list[tuple[float, str]] = []
    for index, beta_l in enumerate(euler_bernoulli_beta_l("clamped-clamped", count)):
        modes.append((euler_bernoulli_omega(beta_l, length, thickness_m, e, rho), "in_plane"))
        modes.append((euler_bernoulli_omega(beta_l, length, width_m, e, rho), "out_of_plane"))
        modes.append((torsion_omega(index + 1, length, shear, torsion_j, polar, rho),
                      "torsion"))
        modes.append((axial_omega(index + 1, length, e, rho), "axial"))
    return sorted(modes)[:count]


#: mode kinds symmetric about the mechanism plane: what an ``in_plane`` reduction keeps
IN_PLANE_KINDS = ("in_plane", "axial")


def in_plane_fixed_interface_omegas(length_m: float, thickness_m: float, width_m: float,
                                    youngs_modulus_Pa: float, density_kg_per_m3: float,
                                    poisson_ratio: float, count: int) -> list[float]:
    """The ``count`` lowest estimated fixed-interface circular frequencies [rad/s] of the
    modes symmetric about the mechanism plane (in-plane bending and axial): the eigenmodes
    an ``in_plane`` reduction keeps (the in-plane and axial modes of
    :func:`clamped_plate_frequencies`, ascending; a wide plate's torsion and out-of-plane
    modes, however low, are not among them)."""
    del width_m, poisson_ratio  # in-plane bending and axial modes do not depend on them
    bending = [euler_bernoulli_omega(beta_l, length_m, thickness_m, youngs_modulus_Pa,
                                     density_kg_per_m3)
               for beta_l in euler_bernoulli_beta_l("clamped-clamped", count)]
    axial = [axial_omega(index + 1, length_m, youngs_modulus_Pa, density_kg_per_m3)
             for index in range(count)]
    return sorted(bending + axial)[:count]



# ------------------------------------------------------------------------------------------
# Rectangular sections: what the beam models share (the exact beam, the thesis studies)
# ------------------------------------------------------------------------------------------
SHEAR_CORRECTION_RECTANGLE = 5.0 / 6.0
"""Timoshenko shear correction factor of a rectangular cross-section (Poisson-independent
textbook value; Cowper's 10(1+nu)/(12+11 nu) = 0.850 at nu = 0.3 would raise the Timoshenko
frequencies slightly)."""


def check_positive(**sizes: float) -> None:
    """Raise :class:`SceneError` unless every value is a positive finite number."""
    for name, value in sizes.items():
        if not (isinstance(value, int | float | np.floating | np.integer) and value > 0
                and math.isfinite(value)):
            raise SceneError(f"{name} = {value!r}: must be a positive finite number")


@dataclass(frozen=True)
class RectangleSection:
    """Section properties of a solid rectangle.

    ``height_m`` is the side along the bending displacement considered (for in-plane bending of
    the plate links: the thickness t, along y), ``width_m`` the other side. Attributes in SI:
    area (m^2), second moment about the axis parallel to the width (m^4), second moment about
    the other axis (m^4), polar moment of area (m^4) and St-Venant torsion constant (m^4).
    """

    height_m: float
    width_m: float
    area_m2: float
    second_moment_m4: float
    second_moment_other_m4: float
    polar_moment_m4: float
    torsion_constant_m4: float


def checked_rectangle_torsion_constant_m4(height_m: float, width_m: float, series_terms: int = 50
                                  ) -> float:
    """St-Venant torsion constant J of a solid rectangle, m^4: the series of
    :func:`rectangle_torsion_constant_m4` (Timoshenko & Goodier), sizes checked.
    """
    check_positive(height_m=height_m, width_m=width_m)
    return rectangle_torsion_constant_m4(height_m, width_m, series_terms)


def rectangle_section(height_m: float, width_m: float) -> RectangleSection:
    """Area, second moments, polar moment and torsion constant of a height x width rectangle.

    Inputs in m; see :class:`RectangleSection` for the outputs and their units.
    """
    check_positive(height_m=height_m, width_m=width_m)
    area_m2 = height_m * width_m
    second_moment_m4 = width_m * height_m**3 / 12.0
    second_moment_other_m4 = height_m * width_m**3 / 12.0
    return RectangleSection(
        height_m=height_m, width_m=width_m, area_m2=area_m2,
        second_moment_m4=second_moment_m4, second_moment_other_m4=second_moment_other_m4,
        polar_moment_m4=rectangle_polar_moment_m4(height_m, width_m),
        torsion_constant_m4=checked_rectangle_torsion_constant_m4(height_m, width_m))


@dataclass(frozen=True)
class Plate:
    """A plate link's geometry and material: the one value the closed forms above are read
    from (instead of six loose numbers).

    Sizes [m]: ``length_m`` along the link, ``thickness_m`` in the mechanism plane (the
    in-plane bending height), ``width_m`` across it; ``youngs_modulus_Pa`` [Pa],
    ``density_kg_per_m3`` [kg/m^3], ``poisson_ratio`` [-]. The derived values call the
    module's formulas (each exists once, as a function of loose numbers)."""

    length_m: float
    thickness_m: float
    width_m: float
    youngs_modulus_Pa: float
    density_kg_per_m3: float
    poisson_ratio: float = 0.3

    @classmethod
    def of(cls, values: Mapping[str, Any]) -> Plate:
        """The plate of a scene link's values (``scene["coupler"]``, ``scene["crank"]``: the
        keys of the same names; ``poisson_ratio`` 0.3 where absent)."""
        return cls(values["length_m"], values["thickness_m"], values["width_m"],
                   values["youngs_modulus_Pa"], values["density_kg_per_m3"],
                   values.get("poisson_ratio", 0.3))

    @property
    def sizes_m(self) -> tuple[float, float, float]:
        """``(length_m, thickness_m, width_m)`` [m]."""
        return self.length_m, self.thickness_m, self.width_m

    @property
    def mass_kg(self) -> float:
        """Its mass [kg] (:func:`cuboid_mass_kg`)."""
        return cuboid_mass_kg(*self.sizes_m, self.density_kg_per_m3)

    @property
    def inertia_kgm2(self) -> float:
        """Its in-plane inertia about the centre of mass [kg m^2] (:func:`cuboid_inertia_kgm2`)."""
        return cuboid_inertia_kgm2(self.mass_kg, self.length_m, self.thickness_m)

    @property
    def euler_load_N(self) -> float:
        """Its pinned-pinned in-plane Euler buckling load [N] (:func:`euler_buckling_load_N`)."""
        return euler_buckling_load_N(*self.sizes_m, self.youngs_modulus_Pa)

    @property
    def pinned_pinned_omega(self) -> float:
        """Its first pinned-pinned in-plane bending circular frequency [rad/s]
        (:func:`pinned_pinned_omega`)."""
        return pinned_pinned_omega(self.length_m, self.thickness_m, self.youngs_modulus_Pa,
                                   self.density_kg_per_m3)

    def clamped_frequencies(self, count: int = 40) -> list[tuple[float, str]]:
        """Its ``count`` lowest fixed-interface ``(omega [rad/s], kind)`` estimates
        (:func:`clamped_plate_frequencies`)."""
        return clamped_plate_frequencies(*self.sizes_m, self.youngs_modulus_Pa,
                                         self.density_kg_per_m3, self.poisson_ratio, count)

    def in_plane_omegas(self, count: int) -> list[float]:
        """Its ``count`` lowest in-plane fixed-interface circular frequencies [rad/s]
        (:func:`in_plane_fixed_interface_omegas`)."""
        return in_plane_fixed_interface_omegas(*self.sizes_m, self.youngs_modulus_Pa,
                                               self.density_kg_per_m3, self.poisson_ratio,
                                               count)
