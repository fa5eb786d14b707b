"""Beam and rod theory of rectangular plate links: sections, Euler-Bernoulli and Timoshenko
bending, axial and torsional modes, and a link's lowest modes merged over the four kinds.

Geometry and axes are those of :mod:`flex.bodies.plate`: x along the link (0..L), y across the
thickness t (in the mechanism plane: t is the height of in-plane bending), z across the width
(out of the mechanism plane). All quantities are SI: metres, seconds, kilograms, pascals;
circular frequencies in rad/s, cyclic ones in Hz. Names carry their unit.

Mode kinds (:data:`MODE_KINDS`), named for the link in the mechanism:

- ``"in-plane bending"``: displacement along y, bending in the mechanism plane (x-y);
- ``"out-of-plane bending"``: displacement along z;
- ``"torsion"``: rotation of the cross-sections about x;
- ``"axial"``: displacement along x (and anything else symmetric in both y and z).

Link boundary conditions (:data:`LINK_BOUNDARY_CONDITIONS`):

- ``"free-free"``: unsupported; the six rigid-body modes are skipped.
- ``"pinned-pinned"``: the coupler between its two revolute joints; each end rotates freely
  about the z axis through its centre (:func:`flex.experiments.thesis.fe_modes.plate_modes` says
  how the 3D
  model imposes it and why it is the simply supported end of in-plane bending).
- ``"pinned-roller"``: as pinned-pinned, but ``end_b`` may slide along x (the textbook simply
  supported beam: pin and roller). Bending and torsion are those of pinned-pinned; the axial
  modes become fixed-free. This is the support that reproduces the thesis's ANSYS Tables 7
  and 9 (:func:`flex.experiments.thesis.thesis_tables.thesis_link_modal_reproduction`).

The 3D finite-element modes are in :mod:`flex.experiments.thesis.fe_modes`, the BEAM188 emulation in
:mod:`flex.experiments.thesis.beam_elements`, the thesis's Tables 5, 7, 9 in
:mod:`flex.experiments.thesis.thesis_tables`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from flex.base import physics
from flex.base.errors import SceneError
from flex.base.physics import (
    BEAM_END_CONDITIONS,
    SHEAR_CORRECTION_RECTANGLE,
    check_positive,
    rectangle_section,
)
from flex.base.thesis import THESIS_DENSITY_KG_PER_M3, THESIS_YOUNGS_MODULUS_PA

# ---------------------------------------------------------------------------------------------
# Constants and inputs
# ---------------------------------------------------------------------------------------------

MODE_KINDS: tuple[str, ...] = ("axial", "in-plane bending", "out-of-plane bending", "torsion")
"""Kinds of link modes; also the column order of
:attr:`flex.experiments.thesis.fe_modes.PlateModes.kind_shares`."""

LINK_BOUNDARY_CONDITIONS: tuple[str, ...] = ("free-free", "pinned-pinned", "pinned-roller")
"""Boundary conditions of a whole link (3D FE model and :func:`beam_link_modes`)."""

ROD_END_CONDITIONS: tuple[str, ...] = ("free-free", "fixed-fixed", "fixed-free")
"""End conditions of axial and torsional (rod) vibration."""


@dataclass(frozen=True)
class Material:
    """Linear elastic isotropic material.

    Attributes: ``youngs_modulus_Pa`` (Pa), ``density_kg_per_m3`` (kg/m^3),
    ``poissons_ratio`` (dimensionless, -1 < nu < 0.5).
    """

    youngs_modulus_Pa: float
    density_kg_per_m3: float
    poissons_ratio: float

    @classmethod
    def of(cls, plate: physics.Plate) -> Material:
        """The material of a plate link (its E [Pa], rho [kg/m^3], nu)."""
        return cls(plate.youngs_modulus_Pa, plate.density_kg_per_m3, plate.poisson_ratio)

    @property
    def shear_modulus_Pa(self) -> float:
        """G = E / (2 (1 + nu)), Pa."""
        return physics.shear_modulus_Pa(self.youngs_modulus_Pa, self.poissons_ratio)

    def check(self) -> None:
        """Raise :class:`SceneError` unless E > 0, rho > 0 and -1 < nu < 0.5."""
        if not self.youngs_modulus_Pa > 0:
            raise SceneError(f"youngs_modulus_Pa = {self.youngs_modulus_Pa!r}: must be > 0 Pa")
        if not self.density_kg_per_m3 > 0:
            raise SceneError(
                f"density_kg_per_m3 = {self.density_kg_per_m3!r}: must be > 0 kg/m^3")
        if not -1.0 < self.poissons_ratio < 0.5:
            raise SceneError(
                f"poissons_ratio = {self.poissons_ratio!r}: must lie in (-1, 0.5)")


THESIS_STEEL = Material(youngs_modulus_Pa=THESIS_YOUNGS_MODULUS_PA,
                        density_kg_per_m3=THESIS_DENSITY_KG_PER_M3, poissons_ratio=0.3)
"""Steel ASTM A36 of Cavezza 2012, Tables 6 and 8: E = 200 GPa, rho = 7850 kg/m^3. The thesis
does not state Poisson's ratio; nu = 0.3 is our assumption (it enters only through G: shear
deformation, torsion and 3D effects)."""


def check_choice(name: str, value: str, accepted: Sequence[str]) -> None:
    """Raise :class:`SceneError` unless ``value`` is one of ``accepted``."""
    if value not in accepted:
        raise SceneError(
            f"{name} = {value!r}: unknown; accepted: {', '.join(repr(a) for a in accepted)}")


def check_count(name: str, value: int, maximum: int = 200) -> None:
    """Raise :class:`SceneError` unless ``value`` is an integer from 1 to ``maximum``."""
    if not (isinstance(value, int | np.integer) and 1 <= value <= maximum):
        raise SceneError(f"{name} = {value!r}: must be an integer from 1 to {maximum}")


# ---------------------------------------------------------------------------------------------
# Beam theory
# ---------------------------------------------------------------------------------------------


def brent_root(function, lower: float, upper: float) -> float:
    """The root of ``function`` in [lower, upper] (scipy brentq, tolerances 1e-14)."""
    from scipy.optimize import brentq
    return float(brentq(function, lower, upper, xtol=1e-14, rtol=1e-14, maxiter=200))


def euler_bernoulli_beta_l(end_condition: str, mode_count: int = 5) -> np.ndarray:
    """Dimensionless wave numbers beta_n L of an Euler-Bernoulli beam, n = 1..mode_count.

    omega_n = (beta_n L)^2 / L^2 * sqrt(E I / (rho A)). The roots of
    :func:`flex.base.physics.euler_bernoulli_beta_l` (free-free and clamped-clamped 4.7300,
    7.8532, ...; pinned-pinned n pi; clamped-free 1.8751, 4.6941, ...; clamped-pinned
    3.9266, 7.0686, ...), inputs checked.
    """
    check_choice("end_condition", end_condition, BEAM_END_CONDITIONS)
    check_count("mode_count", mode_count)
    return np.array(physics.euler_bernoulli_beta_l(end_condition, int(mode_count)))


def euler_bernoulli_bending_rad_per_s(
        length_m: float, height_m: float, width_m: float, end_condition: str,
        mode_count: int = 5, material: Material = THESIS_STEEL) -> np.ndarray:
    """Euler-Bernoulli bending circular frequencies omega_n, rad/s, n = 1..mode_count.

    omega_n = (beta_n L)^2 / L^2 * sqrt(E I / (rho A)) with I = width height^3 / 12: bending
    displacement along ``height_m``. ``end_condition`` is one of :data:`BEAM_END_CONDITIONS`.
    Pinned-pinned n = 1 is the thesis's Table 5 "Frequency" with height = t, width = 0.01 m.
    Sizes in m.
    """
    check_positive(length_m=length_m, height_m=height_m, width_m=width_m)
    material.check()
    beta_l = euler_bernoulli_beta_l(end_condition, mode_count)
    return physics.euler_bernoulli_omega(beta_l, length_m, height_m,
                                         material.youngs_modulus_Pa, material.density_kg_per_m3)


def _timoshenko_state_matrix(frequency_parameter: float, slenderness_sq: float,
                             shear_flexibility: float, rotary: bool) -> np.ndarray:
    """Dimensionless first-order system d/dxi [w/L, psi, M L/EI, V L^2/EI] = A [...].

    frequency_parameter Omega^2 = rho A omega^2 L^4 / (E I); slenderness_sq r^2 = I/(A L^2);
    shear_flexibility s = E I / (kappa G A L^2). From rho A w_tt = V', V = kappa G A (w' - psi),
    rho I psi_tt = M' + V, M = E I psi'.
    """
    omega_sq = frequency_parameter
    rotary_term = omega_sq * slenderness_sq if rotary else 0.0
    return np.array([
        [0.0, 1.0, 0.0, shear_flexibility],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, -rotary_term, 0.0, -1.0],
        [-omega_sq, 0.0, 0.0, 0.0],
    ])


# Which state components are unknown at the first end and which must vanish at the second end,
# state = [w, psi, M, V]: free M = V = 0, pinned w = M = 0, clamped w = psi = 0.
_FREE_AT_START = {"free": [0, 1], "pinned": [1, 3], "clamped": [2, 3]}
_ZERO_AT_END = {"free": [2, 3], "pinned": [0, 2], "clamped": [0, 1]}


def _timoshenko_determinant(frequency_parameter: float, end_condition: str,
                            slenderness_sq: float, shear_flexibility: float,
                            rotary: bool) -> float:
    from scipy.linalg import expm

    first_end, second_end = end_condition.split("-")
    transfer = expm(_timoshenko_state_matrix(frequency_parameter, slenderness_sq,
                                             shear_flexibility, rotary))
    block = transfer[np.ix_(_ZERO_AT_END[second_end], _FREE_AT_START[first_end])]
    # Divide by the largest entry: keeps the sign, avoids overflow-sized numbers
    # (entries grow like cosh(beta L)^2).
    scale = max(np.abs(block).max(), 1e-300)
    return float(np.linalg.det(block / scale))


def timoshenko_bending_rad_per_s(
        length_m: float, height_m: float, width_m: float, end_condition: str,
        mode_count: int = 5, material: Material = THESIS_STEEL,
        shear_correction: float = SHEAR_CORRECTION_RECTANGLE, rotary_inertia: bool = True,
        shear_deformation: bool = True) -> np.ndarray:
    """Timoshenko-beam bending circular frequencies omega_n, rad/s, n = 1..mode_count.

    Shear deformation (kappa G A, ``shear_correction`` kappa = 5/6 for a rectangle) and rotary
    inertia (rho I) included; either can be switched off (both off = Euler-Bernoulli, used as
    a check). Bending displacement along ``height_m`` (I = width height^3 / 12), sizes in m.

    Pinned-pinned has a closed form (w ~ sin(k x), psi ~ cos(k x), k = n pi / L): the lower
    root omega^2 of rho A rho I omega^4 / (kappa G A) - omega^2 (rho A + rho I k^2
    + rho A E I k^2 / (kappa G A)) + E I k^4 = 0. The other end conditions are solved
    exactly from the transfer matrix of the Timoshenko equations (roots of a 2x2 determinant,
    bracketed below the Euler-Bernoulli frequency of the same mode, which Timoshenko never
    exceeds). ``end_condition`` is one of :data:`BEAM_END_CONDITIONS`.
    """
    check_positive(length_m=length_m, height_m=height_m, width_m=width_m,
                    shear_correction=shear_correction)
    check_choice("end_condition", end_condition, BEAM_END_CONDITIONS)
    check_count("mode_count", mode_count)
    material.check()
    section = rectangle_section(height_m, width_m)
    youngs_Pa, density = material.youngs_modulus_Pa, material.density_kg_per_m3
    area, inertia = section.area_m2, section.second_moment_m4
    shear_stiffness_N = shear_correction * material.shear_modulus_Pa * area
    eb_rad_per_s = euler_bernoulli_bending_rad_per_s(length_m, height_m, width_m,
                                                     end_condition, mode_count, material)
    if end_condition == "pinned-pinned":
        return _pinned_pinned_timoshenko_rad_per_s(
            length_m, mode_count, youngs_Pa, density, area, inertia,
            shear_stiffness_N if shear_deformation else None, rotary_inertia)

    slenderness_sq = inertia / (area * length_m**2)
    shear_flexibility = (youngs_Pa * inertia / (shear_stiffness_N * length_m**2)
                         if shear_deformation else 0.0)
    roots = _timoshenko_roots(end_condition, mode_count, slenderness_sq, shear_flexibility,
                              rotary_inertia)
    if len(roots) < mode_count:
        raise SceneError(
            f"Timoshenko {end_condition} beam L = {length_m} m, h = {height_m} m: found only "
            f"{len(roots)} of {mode_count} modes below the Euler-Bernoulli bound")
    parameter = np.array(roots)
    omega = parameter / length_m**2 * math.sqrt(youngs_Pa * inertia / (density * area))
    # Timoshenko <= Euler-Bernoulli mode by mode: a cheap guard against a missed root.
    if np.any(omega > eb_rad_per_s * (1.0 + 1e-9)):
        raise SceneError("Timoshenko root search lost a mode (frequency above Euler-Bernoulli)")
    return omega


def _pinned_pinned_timoshenko_rad_per_s(
        length_m: float, mode_count: int, youngs_Pa: float, density: float, area: float,
        inertia: float, shear_stiffness_N: float | None, rotary_inertia: bool) -> np.ndarray:
    """The closed form of a pinned-pinned Timoshenko beam (:func:`timoshenko_bending_rad_per_s`,
    :func:`flex.base.physics.timoshenko_pinned_pinned_omega`): omega_n, rad/s, n =
    1..mode_count; ``shear_stiffness_N`` kappa G A [N], None without shear deformation; SI
    units."""
    return physics.timoshenko_pinned_pinned_omega(
        np.arange(1, mode_count + 1), length_m, youngs_Pa * inertia,
        math.inf if shear_stiffness_N is None else shear_stiffness_N, density * area,
        density * inertia if rotary_inertia else 0.0)


def _timoshenko_roots(end_condition: str, mode_count: int, slenderness_sq: float,
                      shear_flexibility: float, rotary_inertia: bool) -> list[float]:
    """The lowest ``mode_count`` (fewer if the scan misses some) frequency parameters Omega =
    sqrt(rho A / E I) omega L^2 of a Timoshenko beam, roots of its transfer-matrix determinant
    (:func:`_timoshenko_determinant`) below the last Euler-Bernoulli value."""
    eb_parameter = euler_bernoulli_beta_l(end_condition, mode_count) ** 2

    def determinant(parameter: float) -> float:
        return _timoshenko_determinant(parameter**2, end_condition, slenderness_sq,
                                       shear_flexibility, rotary_inertia)

    # Scan Omega from near 0 (free-free has a double root at 0, rigid-body motion, which the
    # scan must not count) up to the last Euler-Bernoulli value.
    scan = np.linspace(0.05 * eb_parameter[0], eb_parameter[-1] * 1.0000001,
                       120 * mode_count + 1)
    values = np.array([determinant(p) for p in scan])
    roots: list[float] = []
    for index in range(len(scan) - 1):
        if values[index] == 0.0:
            roots.append(float(scan[index]))
        elif values[index] * values[index + 1] < 0.0:
            roots.append(brent_root(determinant, scan[index], scan[index + 1]))
        if len(roots) == mode_count:
            break
    return roots


def axial_rad_per_s(length_m: float, end_condition: str, mode_count: int = 5,
                    material: Material = THESIS_STEEL) -> np.ndarray:
    """Axial (rod) circular frequencies, rad/s: omega_n = n pi / L sqrt(E / rho).

    Free-free and fixed-fixed: n = 1, 2, ...; fixed-free: n - 1/2. Elementary rod theory (no
    lateral inertia). ``end_condition`` is one of :data:`ROD_END_CONDITIONS`; length in m.
    """
    check_positive(length_m=length_m)
    check_choice("end_condition", end_condition, ROD_END_CONDITIONS)
    check_count("mode_count", mode_count)
    material.check()
    modes = np.arange(1, mode_count + 1, dtype=float)
    if end_condition == "fixed-free":
        modes = modes - 0.5
    return physics.axial_omega(modes, length_m, material.youngs_modulus_Pa,
                               material.density_kg_per_m3)


def torsion_rad_per_s(length_m: float, height_m: float, width_m: float, end_condition: str,
                      mode_count: int = 5, material: Material = THESIS_STEEL) -> np.ndarray:
    """St-Venant torsion circular frequencies, rad/s: omega_n = n pi / L sqrt(G J / (rho I_p)).

    J: :func:`rectangle_torsion_constant_m4`; I_p = polar moment of area of the rectangle.
    Warping restraint at fixed ends is neglected (it stiffens short, stocky links slightly).
    Free-free and fixed-fixed: n = 1, 2, ...; fixed-free: n - 1/2. Sizes in m.
    """
    check_positive(length_m=length_m, height_m=height_m, width_m=width_m)
    check_choice("end_condition", end_condition, ROD_END_CONDITIONS)
    check_count("mode_count", mode_count)
    material.check()
    section = rectangle_section(height_m, width_m)
    modes = np.arange(1, mode_count + 1, dtype=float)
    if end_condition == "fixed-free":
        modes = modes - 0.5
    return physics.torsion_omega(modes, length_m, material.shear_modulus_Pa,
                                 section.torsion_constant_m4, section.polar_moment_m4,
                                 material.density_kg_per_m3)


@dataclass(frozen=True)
class BeamLinkModes:
    """Lowest modes of a link from beam theory, merged over the four mode kinds, ascending.

    ``frequencies_rad_per_s`` and ``frequencies_Hz`` (n,), ``mode_kinds`` (n,) names from
    :data:`MODE_KINDS`, ``mode_orders`` (n,) the order of each mode within its kind (1 = first
    in-plane bending, ...), ``theory`` "euler-bernoulli" or "timoshenko".
    """

    frequencies_rad_per_s: np.ndarray
    frequencies_Hz: np.ndarray
    mode_kinds: tuple[str, ...]
    mode_orders: np.ndarray
    theory: str


BEAM_THEORIES: tuple[str, ...] = ("euler-bernoulli", "timoshenko")

# For each link boundary condition: end conditions of in-plane bending, out-of-plane bending,
# torsion and axial motion. A revolute joint about z lets the end face rotate about z only:
# in-plane bending pinned, out-of-plane bending clamped, torsion fixed; a roller frees x.
_LINK_TO_BEAM_ENDS = {
    "free-free": ("free-free", "free-free", "free-free", "free-free"),
    "pinned-pinned": ("pinned-pinned", "clamped-clamped", "fixed-fixed", "fixed-fixed"),
    "pinned-roller": ("pinned-pinned", "clamped-clamped", "fixed-fixed", "fixed-free"),
}


def beam_link_modes(length_m: float, thickness_m: float, width_m: float,
                    boundary_condition: str, mode_count: int = 5,
                    theory: str = "timoshenko", material: Material = THESIS_STEEL,
                    shear_correction: float = SHEAR_CORRECTION_RECTANGLE) -> BeamLinkModes:
    """The first ``mode_count`` modes of a rectangular link from beam and rod theory.

    The link's counterpart of :func:`flex.experiments.thesis.fe_modes.plate_modes`: thickness (m)
    along y
    (in-plane bending height), width (m) along z. ``boundary_condition`` from
    :data:`LINK_BOUNDARY_CONDITIONS`: free-free uses free ends for every kind; pinned-pinned
    (revolute joints about z) uses pinned in-plane bending, clamped out-of-plane bending,
    fixed-fixed torsion and axial; pinned-roller the same with fixed-free axial modes.
    ``theory`` "euler-bernoulli" or "timoshenko" (bending only; rods are elementary).
    """
    check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m)
    check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    check_choice("theory", theory, BEAM_THEORIES)
    check_count("mode_count", mode_count)
    in_plane_end, out_of_plane_end, torsion_end, axial_end = _LINK_TO_BEAM_ENDS[
        boundary_condition]
    if theory == "timoshenko":
        def bending(height_m: float, other_m: float, end: str) -> np.ndarray:
            return timoshenko_bending_rad_per_s(length_m, height_m, other_m, end, mode_count,
                                                material, shear_correction)
    else:
        def bending(height_m: float, other_m: float, end: str) -> np.ndarray:
            return euler_bernoulli_bending_rad_per_s(length_m, height_m, other_m, end,
                                                     mode_count, material)
    families = {
        "in-plane bending": bending(thickness_m, width_m, in_plane_end),
        "out-of-plane bending": bending(width_m, thickness_m, out_of_plane_end),
        "torsion": torsion_rad_per_s(length_m, thickness_m, width_m, torsion_end, mode_count,
                                     material),
        "axial": axial_rad_per_s(length_m, axial_end, mode_count, material),
    }
    entries = sorted((omega, kind, order + 1) for kind, values in families.items()
                     for order, omega in enumerate(values))[:mode_count]
    omegas = np.array([entry[0] for entry in entries])
    return BeamLinkModes(frequencies_rad_per_s=omegas, frequencies_Hz=omegas / (2 * math.pi),
                         mode_kinds=tuple(entry[1] for entry in entries),
                         mode_orders=np.array([entry[2] for entry in entries]), theory=theory)


def weak_plane_bending_rad_per_s(length_m: float, thickness_m: float, width_m: float,
                                 material: Material) -> float:
    """Euler-Bernoulli pinned-pinned first bending frequency of the weaker plane, rad/s."""
    weak_m, strong_m = min(thickness_m, width_m), max(thickness_m, width_m)
    return float(euler_bernoulli_bending_rad_per_s(length_m, weak_m, strong_m,
                                                   "pinned-pinned", 1, material)[0])
