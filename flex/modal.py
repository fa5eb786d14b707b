"""Modal study of plate links: 3D finite elements, beam theory and the thesis's tables.

Reproduces and checks sections 6.2-6.3 of Cavezza (2012), *Flexibility and Transient Dynamic
Analysis of a Slider-Crank Deployment Mechanism* (West Virginia University, MS thesis):
Table 5 (four steel plate couplers and the rigid-or-flexible number ``n = delta_t / T``) and
Tables 7 and 9 (ANSYS BEAM188 crank and coupler frequencies).

Geometry and axes are those of :mod:`flex.plate`: x along the link (0..L), y across the
thickness t (in the mechanism plane: t is the height of in-plane bending), z across the width
(out of the mechanism plane). All quantities are SI: metres, seconds, kilograms,
pascals; circular frequencies in rad/s, cyclic ones in Hz. Names carry their unit.

Mode kinds (:data:`MODE_KINDS`), named for the link in the mechanism:

- ``"in-plane bending"``: displacement along y, bending in the mechanism plane (x-y);
- ``"out-of-plane bending"``: displacement along z;
- ``"torsion"``: rotation of the cross-sections about x;
- ``"axial"``: displacement along x (and anything else symmetric in both y and z).

Link boundary conditions (:data:`LINK_BOUNDARY_CONDITIONS`):

- ``"free-free"``: unsupported; the six rigid-body modes are skipped.
- ``"pinned-pinned"``: the coupler between its two revolute joints. Each end face keeps a
  zero mean displacement (x, y and z) and a zero mean rotation about x and y, but may rotate
  freely about the z axis through its centre. See :func:`plate_modes` for how this is imposed
  and why it is the simply supported end of in-plane bending.
- ``"pinned-roller"``: as pinned-pinned, but ``end_b`` may slide along x (the textbook simply
  supported beam: pin and roller). Bending and torsion are those of pinned-pinned; the axial
  modes become fixed-free. This is the support that reproduces the thesis's ANSYS Tables 7
  and 9 (see :func:`thesis_link_modal_reproduction`).

No plotting and no file output here: a study calls these functions and stores what they
return.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from . import physics
from .errors import SceneError
from .physics import BEAM_END_CONDITIONS  # noqa: F401 - part of this module's face
from .thesis import (  # noqa: F401 - part of this module's face
    THESIS_COUPLER_LENGTH_M,
    THESIS_CRANK_LENGTH_M,
    THESIS_DELTA_T_S,
    THESIS_DENSITY_KG_PER_M3,
    THESIS_K,
    THESIS_K_COUPLER,
    THESIS_K_CRANK,
    THESIS_TABLE5,
    THESIS_TABLE5_WIDTH_M,
    THESIS_TABLE7_CRANK,
    THESIS_TABLE9_COUPLER,
    THESIS_YOUNGS_MODULUS_PA,
)

# ---------------------------------------------------------------------------------------------
# Constants and thesis data
# ---------------------------------------------------------------------------------------------

MODE_KINDS: tuple[str, ...] = ("axial", "in-plane bending", "out-of-plane bending", "torsion")
"""Kinds of link modes; also the column order of :attr:`PlateModes.kind_shares`."""

LINK_BOUNDARY_CONDITIONS: tuple[str, ...] = ("free-free", "pinned-pinned", "pinned-roller")
"""Boundary conditions of a whole link (3D FE model and :func:`beam_link_modes`)."""

ROD_END_CONDITIONS: tuple[str, ...] = ("free-free", "fixed-fixed", "fixed-free")
"""End conditions of axial and torsional (rod) vibration."""

DEPLOYMENT_TIME_S = THESIS_DELTA_T_S
"""Deployment time delta_t of the thesis's criterion, s (:data:`flex.thesis.THESIS_DELTA_T_S`)."""

SHEAR_CORRECTION_RECTANGLE = 5.0 / 6.0
"""Timoshenko shear correction factor of a rectangular cross-section (Poisson-independent
textbook value; Cowper's 10(1+nu)/(12+11 nu) = 0.850 at nu = 0.3 would raise the Timoshenko
frequencies slightly)."""


@dataclass(frozen=True)
class Material:
    """Linear elastic isotropic material.

    Attributes: ``youngs_modulus_Pa`` (Pa), ``density_kg_per_m3`` (kg/m^3),
    ``poissons_ratio`` (dimensionless, -1 < nu < 0.5).
    """

    youngs_modulus_Pa: float
    density_kg_per_m3: float
    poissons_ratio: float

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

# The thesis's lengths, Tables 5, 7 and 9 and their k's live in flex.thesis (imported above).
THESIS_K_CRITERION = int(THESIS_K)
"""Cavezza 2012, sec. 6.2: the k chosen for the criterion (model 1 of Table 5), 108."""


# ---------------------------------------------------------------------------------------------
# Input checks
# ---------------------------------------------------------------------------------------------


def _check_positive(**sizes: float) -> None:
    for name, value in sizes.items():
        if not (isinstance(value, int | float | np.floating | np.integer) and value > 0
                and math.isfinite(value)):
            raise SceneError(f"{name} = {value!r}: must be a positive finite number")


def _check_choice(name: str, value: str, accepted: Sequence[str]) -> None:
    if value not in accepted:
        raise SceneError(
            f"{name} = {value!r}: unknown; accepted: {', '.join(repr(a) for a in accepted)}")


def _check_count(name: str, value: int, maximum: int = 200) -> None:
    if not (isinstance(value, int | np.integer) and 1 <= value <= maximum):
        raise SceneError(f"{name} = {value!r}: must be an integer from 1 to {maximum}")


# ---------------------------------------------------------------------------------------------
# Beam theory
# ---------------------------------------------------------------------------------------------


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


def rectangle_torsion_constant_m4(height_m: float, width_m: float, series_terms: int = 50
                                  ) -> float:
    """St-Venant torsion constant J of a solid rectangle, m^4: the series of
    :func:`flex.physics.rectangle_torsion_constant_m4` (Timoshenko & Goodier), sizes checked.
    """
    _check_positive(height_m=height_m, width_m=width_m)
    return physics.rectangle_torsion_constant_m4(height_m, width_m, series_terms)


def rectangle_section(height_m: float, width_m: float) -> RectangleSection:
    """Area, second moments, polar moment and torsion constant of a height x width rectangle.

    Inputs in m; see :class:`RectangleSection` for the outputs and their units.
    """
    _check_positive(height_m=height_m, width_m=width_m)
    area_m2 = height_m * width_m
    second_moment_m4 = width_m * height_m**3 / 12.0
    second_moment_other_m4 = height_m * width_m**3 / 12.0
    return RectangleSection(
        height_m=height_m, width_m=width_m, area_m2=area_m2,
        second_moment_m4=second_moment_m4, second_moment_other_m4=second_moment_other_m4,
        polar_moment_m4=physics.rectangle_polar_moment_m4(height_m, width_m),
        torsion_constant_m4=rectangle_torsion_constant_m4(height_m, width_m))


def _brent_root(function, lower: float, upper: float) -> float:
    from scipy.optimize import brentq
    return float(brentq(function, lower, upper, xtol=1e-14, rtol=1e-14, maxiter=200))


def euler_bernoulli_beta_l(end_condition: str, mode_count: int = 5) -> np.ndarray:
    """Dimensionless wave numbers beta_n L of an Euler-Bernoulli beam, n = 1..mode_count.

    omega_n = (beta_n L)^2 / L^2 * sqrt(E I / (rho A)). The roots of
    :func:`flex.physics.euler_bernoulli_beta_l` (free-free and clamped-clamped 4.7300,
    7.8532, ...; pinned-pinned n pi; clamped-free 1.8751, 4.6941, ...; clamped-pinned
    3.9266, 7.0686, ...), inputs checked.
    """
    _check_choice("end_condition", end_condition, BEAM_END_CONDITIONS)
    _check_count("mode_count", mode_count)
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
    _check_positive(length_m=length_m, height_m=height_m, width_m=width_m)
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
    _check_positive(length_m=length_m, height_m=height_m, width_m=width_m,
                    shear_correction=shear_correction)
    _check_choice("end_condition", end_condition, BEAM_END_CONDITIONS)
    _check_count("mode_count", mode_count)
    material.check()
    section = rectangle_section(height_m, width_m)
    youngs_Pa, density = material.youngs_modulus_Pa, material.density_kg_per_m3
    area, inertia = section.area_m2, section.second_moment_m4
    shear_stiffness_N = shear_correction * material.shear_modulus_Pa * area
    eb_rad_per_s = euler_bernoulli_bending_rad_per_s(length_m, height_m, width_m,
                                                     end_condition, mode_count, material)
    if end_condition == "pinned-pinned":
        wave_number = np.arange(1, mode_count + 1) * math.pi / length_m
        rotary_density = density * inertia if rotary_inertia else 0.0
        shear_term = (1.0 / shear_stiffness_N) if shear_deformation else 0.0
        # Divide the determinant by kappa G A (finite form when shear is switched off):
        # rho A rho I s w^4 - w^2 (rho I k^2 + rho A + rho A E I k^2 s) + E I k^4 = 0.
        quartic = density * area * rotary_density * shear_term
        quadratic = (rotary_density * wave_number**2 + density * area
                     + density * area * youngs_Pa * inertia * wave_number**2 * shear_term)
        constant = youngs_Pa * inertia * wave_number**4
        if quartic == 0.0:
            omega_sq = constant / quadratic
        else:
            # Lower root, written to avoid cancellation.
            discriminant = np.sqrt(quadratic**2 - 4.0 * quartic * constant)
            omega_sq = 2.0 * constant / (quadratic + discriminant)
        return np.sqrt(omega_sq)

    slenderness_sq = inertia / (area * length_m**2)
    shear_flexibility = (youngs_Pa * inertia / (shear_stiffness_N * length_m**2)
                         if shear_deformation else 0.0)
    eb_parameter = euler_bernoulli_beta_l(end_condition, mode_count) ** 2

    def determinant(parameter: float) -> float:
        return _timoshenko_determinant(parameter**2, end_condition, slenderness_sq,
                                       shear_flexibility, rotary_inertia)

    # Scan Omega = sqrt(rho A / E I) omega L^2 from near 0 (free-free has a double root at 0,
    # rigid-body motion, which the scan must not count) up to the last Euler-Bernoulli value.
    scan = np.linspace(0.05 * eb_parameter[0], eb_parameter[-1] * 1.0000001,
                       120 * mode_count + 1)
    values = np.array([determinant(p) for p in scan])
    roots: list[float] = []
    for index in range(len(scan) - 1):
        if values[index] == 0.0:
            roots.append(float(scan[index]))
        elif values[index] * values[index + 1] < 0.0:
            roots.append(_brent_root(determinant, scan[index], scan[index + 1]))
        if len(roots) == mode_count:
            break
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


def axial_rad_per_s(length_m: float, end_condition: str, mode_count: int = 5,
                    material: Material = THESIS_STEEL) -> np.ndarray:
    """Axial (rod) circular frequencies, rad/s: omega_n = n pi / L sqrt(E / rho).

    Free-free and fixed-fixed: n = 1, 2, ...; fixed-free: n - 1/2. Elementary rod theory (no
    lateral inertia). ``end_condition`` is one of :data:`ROD_END_CONDITIONS`; length in m.
    """
    _check_positive(length_m=length_m)
    _check_choice("end_condition", end_condition, ROD_END_CONDITIONS)
    _check_count("mode_count", mode_count)
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
    _check_positive(length_m=length_m, height_m=height_m, width_m=width_m)
    _check_choice("end_condition", end_condition, ROD_END_CONDITIONS)
    _check_count("mode_count", mode_count)
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

    The link's counterpart of :func:`plate_modes`: thickness (m) along y (in-plane bending
    height), width (m) along z. ``boundary_condition`` from :data:`LINK_BOUNDARY_CONDITIONS`:
    free-free uses free ends for every kind; pinned-pinned (revolute joints about z) uses
    pinned in-plane bending, clamped out-of-plane bending, fixed-fixed torsion and axial;
    pinned-roller the same with fixed-free axial modes.
    ``theory`` "euler-bernoulli" or "timoshenko" (bending only; rods are elementary).
    """
    _check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m)
    _check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    _check_choice("theory", theory, BEAM_THEORIES)
    _check_count("mode_count", mode_count)
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


# ---------------------------------------------------------------------------------------------
# Mode classification
# ---------------------------------------------------------------------------------------------


def parity_kind_shares(displacement: np.ndarray, displacement_at_mirror_y: np.ndarray,
                       displacement_at_mirror_z: np.ndarray,
                       displacement_at_mirror_yz: np.ndarray) -> np.ndarray:
    """Shares of a displacement field in the four symmetry classes of a rectangular link.

    Inputs are (n_points, 3) arrays of displacement (any unit) sampled at points p_i, at
    their mirror images (x, -y, z), (x, y, -z) and (x, -y, -z) respectively, in the same
    order. The link's symmetry group {1, R_y, R_z, R_y R_z} (R_y flips the y component)
    splits any field into four orthogonal parts with u(R p) = +-R u(p) under each
    reflection:

    - even in y and z: axial (and extensional/breathing) motion;
    - odd in y, even in z: in-plane bending (u_y(x), with u_x = -y w');
    - even in y, odd in z: out-of-plane bending;
    - odd in y and z: torsion (u_y = -theta z, u_z = theta y).

    Returns the four shares (sum 1) of the squared sampled norm, ordered as
    :data:`MODE_KINDS`. For the shares to be energy-like the sample points should be spread
    evenly over the body (e.g. mesh vertices).
    """
    arrays = [np.asarray(a, dtype=float) for a in (
        displacement, displacement_at_mirror_y, displacement_at_mirror_z,
        displacement_at_mirror_yz)]
    if any(a.shape != arrays[0].shape or a.ndim != 2 or a.shape[1] != 3 for a in arrays):
        raise SceneError("parity_kind_shares: all four arrays must have the same shape (n, 3)")
    flip_y = np.array([1.0, -1.0, 1.0])
    flip_z = np.array([1.0, 1.0, -1.0])
    u, u_y, u_z, u_yz = arrays
    reflected_y = u_y * flip_y          # R_y u(R_y p)
    reflected_z = u_z * flip_z          # R_z u(R_z p)
    reflected_yz = u_yz * flip_y * flip_z
    # Projector onto the class with characters (s_y, s_z): (u + s_y Ry + s_z Rz + s_y s_z Ryz)/4
    parts = {
        "axial": u + reflected_y + reflected_z + reflected_yz,
        "in-plane bending": u - reflected_y + reflected_z - reflected_yz,
        "out-of-plane bending": u + reflected_y - reflected_z - reflected_yz,
        "torsion": u - reflected_y - reflected_z + reflected_yz,
    }
    norms = np.array([np.sum(parts[kind] ** 2) for kind in MODE_KINDS])
    total = norms.sum()
    if total == 0.0:
        raise SceneError("parity_kind_shares: the displacement field is zero everywhere")
    return norms / total


def classify_kind_shares(kind_shares: np.ndarray, minimum_share: float = 0.8) -> str:
    """Name of the dominant kind of :data:`MODE_KINDS`, or ``"mixed"`` below minimum_share.

    ``kind_shares``: four shares in :data:`MODE_KINDS` order (e.g. from
    :func:`parity_kind_shares`); ``minimum_share`` dimensionless in (0.25, 1].
    """
    shares = np.asarray(kind_shares, dtype=float)
    if shares.shape != (len(MODE_KINDS),):
        raise SceneError(f"kind_shares must have {len(MODE_KINDS)} entries, got {shares.shape}")
    if not 0.25 < minimum_share <= 1.0:
        raise SceneError(f"minimum_share = {minimum_share!r}: must lie in (0.25, 1]")
    best = int(np.argmax(shares))
    return MODE_KINDS[best] if shares[best] >= minimum_share else "mixed"


# ---------------------------------------------------------------------------------------------
# 3D finite elements
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlateModes:
    """Modes of a plate link from 3D second-order tetrahedra (see :func:`plate_modes`).

    Attributes:

    - ``length_m``, ``thickness_m``, ``width_m``, ``mesh_size_m``: the plate and netgen maxh, m.
    - ``boundary_condition``: one of :data:`LINK_BOUNDARY_CONDITIONS`.
    - ``frequencies_Hz``, ``frequencies_rad_per_s``: (n_modes,) ascending, rigid modes removed.
    - ``mode_kinds``: (n_modes,) names from :data:`MODE_KINDS` or ``"mixed"``.
    - ``kind_shares``: (n_modes, 4) symmetry-class shares in :data:`MODE_KINDS` order
      (:func:`parity_kind_shares` at the mesh vertices).
    - ``kinetic_energy_shares_xyz``: (n_modes, 3) share of the modal kinetic energy carried by
      the x, y and z displacement components (exact, from the consistent mass matrix).
    - ``node_coordinates_m``: (n_nodes, 3) mesh vertex positions, m.
    - ``mode_shapes``: (n_modes, n_nodes, 3) vertex displacements, dimensionless, each mode
      scaled to a largest vertex displacement magnitude of 1 (sign: largest component > 0).
    - ``surface_triangles``: (n_triangles, 3) vertex indices of the boundary triangles.
    - ``element_count`` (tetrahedra), ``node_count`` (vertices), ``dof_count`` (unknowns of
      the order-2 vector H1 space), ``constraint_count`` (linear constraints imposed).
    - ``max_relative_residual``: max over modes of |K phi - lambda M phi - C^T mu| / |K phi|,
      the check that the eigensolver converged.
    - ``rigid_body_frequencies_Hz``: the skipped free-free rigid-body frequencies, Hz (should be
      ~0; empty for the supported links).
    - ``wall_time_s``: mesh + assembly + eigensolution time, s.
    """

    length_m: float
    thickness_m: float
    width_m: float
    mesh_size_m: float
    boundary_condition: str
    frequencies_Hz: np.ndarray
    frequencies_rad_per_s: np.ndarray
    mode_kinds: tuple[str, ...]
    kind_shares: np.ndarray
    kinetic_energy_shares_xyz: np.ndarray
    node_coordinates_m: np.ndarray
    mode_shapes: np.ndarray
    surface_triangles: np.ndarray
    element_count: int
    node_count: int
    dof_count: int
    constraint_count: int
    max_relative_residual: float
    rigid_body_frequencies_Hz: np.ndarray = field(default_factory=lambda: np.zeros(0))
    wall_time_s: float = 0.0

    def first_of_kind(self, kind: str) -> int:
        """Index of the lowest mode of ``kind`` (one of :data:`MODE_KINDS`).

        Raises :class:`SceneError` if none of the computed modes is of that kind.
        """
        _check_choice("kind", kind, MODE_KINDS)
        for index, name in enumerate(self.mode_kinds):
            if name == kind:
                return index
        raise SceneError(f"none of the {len(self.mode_kinds)} computed modes is {kind!r} "
                         f"(kinds: {', '.join(self.mode_kinds)}); compute more modes")


def _end_face_constraints(mesh, fes, boundary_condition: str) -> np.ndarray:
    """Rows of the joint constraints C u = 0, shape (10, ndof) or (9, ndof) for a roller.

    Per end face (centre on the x axis): the integrals over the face of u_x, u_y, u_z,
    (y u_z - z u_y) and z u_x. The first three fix the mean displacement; the last two the
    mean rotation about x and about y (u_x = theta_y z on the face). Rotation about z
    (integral of y u_x) stays free; a roller at ``end_b`` also leaves its mean u_x free.
    """
    import ngsolve as ngs

    rows = []
    test = fes.TestFunction()
    for face in ("end_a", "end_b"):
        on_face = ngs.ds(definedon=mesh.Boundaries(face))
        integrands = [test[0], test[1], test[2], ngs.y * test[2] - ngs.z * test[1],
                      ngs.z * test[0]]
        if face == "end_b" and boundary_condition == "pinned-roller":
            integrands = integrands[1:]
        for integrand in integrands:
            form = ngs.LinearForm(fes)
            form += integrand * on_face
            form.Assemble()
            rows.append(form.vec.FV().NumPy().copy())
    return np.array(rows)


def _weak_plane_estimate_rad_per_s(length_m: float, thickness_m: float, width_m: float,
                              material: Material) -> float:
    """Euler-Bernoulli pinned-pinned first bending frequency of the weaker plane, rad/s."""
    weak_m, strong_m = min(thickness_m, width_m), max(thickness_m, width_m)
    return float(euler_bernoulli_bending_rad_per_s(length_m, weak_m, strong_m,
                                                   "pinned-pinned", 1, material)[0])


def plate_modes(length_m: float, thickness_m: float, width_m: float, mesh_size_m: float,
                boundary_condition: str = "free-free", mode_count: int = 5,
                material: Material = THESIS_STEEL, element_order: int = 2,
                minimum_share: float = 0.8, mesh=None) -> PlateModes:
    """First ``mode_count`` elastic modes of a box link from 3D linear elasticity.

    Inputs: plate ``length_m`` (x), ``thickness_m`` (y, in the mechanism plane), ``width_m``
    (z), netgen ``mesh_size_m`` (maxh), all in m; ``boundary_condition`` from
    :data:`LINK_BOUNDARY_CONDITIONS`; ``mode_count`` elastic modes wanted (1..200);
    ``material``; ``element_order`` of the vector H1 space (2 = second-order tetrahedra; 1 is
    allowed to show shear locking); ``minimum_share`` for :func:`classify_kind_shares`;
    ``mesh`` an already built ``ngsolve.Mesh`` of the same plate (from
    :func:`flex.plate.plate_mesh`) to skip meshing. Returns :class:`PlateModes`.

    Method: stiffness K and consistent mass M of the order-``element_order`` vector H1 space
    (NGsolve), generalized eigenproblem K phi = omega^2 M phi solved by Lanczos (ARPACK,
    ``scipy.sparse.linalg.eigsh``) in shift-invert mode about a negative shift
    sigma = -(omega_est/2)^2 (omega_est the Euler-Bernoulli pinned-pinned frequency of the
    weak plane): K - sigma M is then positive definite even for a free body, so NGsolve's
    sparse Cholesky factorises it, and the eigenvalues nearest sigma are the lowest ones.
    Free-free: the six lowest (rigid-body, ~0 Hz) modes are skipped; they are returned in
    ``rigid_body_frequencies_Hz`` so their smallness can be checked.

    Pinned-pinned (the coupler between its revolute joints): ten linear constraints C u = 0
    on the two end faces, from :func:`_end_face_constraints`: over each end face the
    integrals of u_x, u_y, u_z vanish (no mean translation of the joint), and so do the
    mean rotations about x (integral of y u_z - z u_y) and about y (integral of z u_x); the
    mean rotation about z stays free. This is a distributing ("RBE3") coupling of the face to
    a joint at its centre, like Exudyn's ``MarkerSuperElementRigid`` on the face nodes, not a
    rigid face: its reaction is the constraint row times a multiplier, i.e. a uniform traction
    over the face for each force component and a linearly varying traction for the moments
    about x and y. So the pinned end of in-plane bending carries a transverse force (uniform
    shear traction) but no moment about z, with the face's mean deflection zero: exactly the
    simply supported end of beam theory (w = 0, M = 0). Out-of-plane bending is clamped and
    torsion fixed, as a revolute joint about z requires. Pinning instead the line of nodes
    along z through each face centre puts a line load into a 3D continuum, whose displacement
    is logarithmically singular, so the frequency keeps falling under refinement (measured,
    t = 10 mm: 3489.0, 3484.9, 3480.1, 3478.0 Hz at maxh 10, 5, 2.5, 1.77 mm, while the face
    coupling gives 3503.0, 3490.2, 3488.4, 3488.3 Hz, Timoshenko 3486.0).

    Pinned-roller drops the mean u_x constraint of ``end_b`` (nine constraints). The
    constraints are imposed exactly inside the shift-invert operator with a Schur complement
    of the multipliers:
    x = A^-1 y - Z S^-1 C A^-1 y, Z = A^-1 C^T, S = C Z, A = K - sigma M.

    Classification: parity shares (:func:`parity_kind_shares`) from the mode evaluated at the
    vertices and at their mirror images. Exactly degenerate eigenvalues (a square section has
    equal in-plane and out-of-plane bending) come out of any solver as an arbitrary basis of
    the eigenspace (and a coarse mesh splits them slightly, still mixed); clusters of mixed
    modes closer than 1 % in frequency are rotated to parity-pure shapes first.

    Raises :class:`SceneError` for non-positive sizes, an unknown boundary condition or a
    failed convergence check (relative residual above 1e-6).
    """
    _check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m,
                    mesh_size_m=mesh_size_m)
    _check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    _check_count("mode_count", mode_count)
    if element_order not in (1, 2, 3):
        raise SceneError(f"element_order = {element_order!r}: must be 1, 2 or 3")
    material.check()
    start_s = time.perf_counter()

    import ngsolve as ngs
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from .plate import plate_mesh

    if mesh is None:
        mesh = plate_mesh(length_m, thickness_m, width_m, mesh_size_m)
    fes = ngs.VectorH1(mesh, order=element_order)
    dof_count = fes.ndof
    trial, test = fes.TnT()
    youngs_Pa, nu = material.youngs_modulus_Pa, material.poissons_ratio
    shear_Pa = youngs_Pa / (2.0 * (1.0 + nu))
    lame_Pa = youngs_Pa * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))

    def strain(w):
        return ngs.Sym(ngs.Grad(w))

    def stress(w):
        return 2.0 * shear_Pa * strain(w) + lame_Pa * ngs.Trace(strain(w)) * ngs.Id(3)

    omega_est = _weak_plane_estimate_rad_per_s(length_m, thickness_m, width_m, material)
    shift = (0.5 * omega_est) ** 2  # sigma = -shift
    # No ngs.TaskManager: on a shared 2-core machine its spinning worker threads made assembly
    # and solves 2x slower than sequential code (measured).
    stiffness = ngs.BilinearForm(fes, symmetric=True)
    stiffness += ngs.InnerProduct(stress(trial), strain(test)) * ngs.dx
    stiffness.Assemble()
    mass = ngs.BilinearForm(fes, symmetric=True)
    mass += material.density_kg_per_m3 * trial * test * ngs.dx
    mass.Assemble()
    shifted = stiffness.mat.CreateMatrix()
    shifted.AsVector().data = stiffness.mat.AsVector() + shift * mass.mat.AsVector()
    shifted_inverse = shifted.Inverse(inverse="sparsecholesky")
    # ngsolve's CSR export of a symmetric-storage matrix is the full matrix (checked).
    stiffness_csr = sp.csr_matrix(stiffness.mat.CSR())
    mass_csr = sp.csr_matrix(mass.mat.CSR())

    rhs_vector = shifted_inverse.CreateRowVector()
    sol_vector = shifted_inverse.CreateColVector()

    def solve_shifted(right_hand_side: np.ndarray) -> np.ndarray:
        rhs_vector.FV().NumPy()[:] = right_hand_side
        sol_vector.data = shifted_inverse * rhs_vector
        return sol_vector.FV().NumPy().copy()

    if boundary_condition != "free-free":
        constraints = _end_face_constraints(mesh, fes, boundary_condition)
        constrained_solutions = np.column_stack([solve_shifted(row) for row in constraints])
        schur = constraints @ constrained_solutions

        def apply_inverse(right_hand_side: np.ndarray) -> np.ndarray:
            unconstrained = solve_shifted(np.ravel(right_hand_side))
            multipliers = np.linalg.solve(schur, constraints @ unconstrained)
            return unconstrained - constrained_solutions @ multipliers
        rigid_count = 0
    else:
        constraints = np.zeros((0, dof_count))
        apply_inverse = solve_shifted
        rigid_count = 6

    operator = spla.LinearOperator((dof_count, dof_count), matvec=apply_inverse, dtype=float)
    # Deterministic start vector, mapped into the constrained space by one operator step.
    start_vector = apply_inverse(
        mass_csr @ np.random.default_rng(12345).standard_normal(dof_count))
    eigenvalues, eigenvectors = spla.eigsh(
        stiffness_csr, k=mode_count + rigid_count, M=mass_csr, sigma=-shift,
        OPinv=operator, which="LM", v0=start_vector)
    order = np.argsort(eigenvalues)
    eigenvalues, eigenvectors = eigenvalues[order], eigenvectors[:, order]
    rigid_Hz = np.sqrt(np.abs(eigenvalues[:rigid_count])) / (2.0 * math.pi)
    eigenvalues, eigenvectors = eigenvalues[rigid_count:], eigenvectors[:, rigid_count:]

    # Convergence check: residual of the (constrained) eigen equation.
    residuals = []
    for index in range(eigenvectors.shape[1]):
        vector = eigenvectors[:, index]
        stiffness_times = stiffness_csr @ vector
        residual = stiffness_times - eigenvalues[index] * (mass_csr @ vector)
        if constraints.shape[0]:
            multipliers = np.linalg.lstsq(constraints.T, residual, rcond=None)[0]
            residual = residual - constraints.T @ multipliers
        residuals.append(np.linalg.norm(residual) / np.linalg.norm(stiffness_times))
    max_relative_residual = float(max(residuals))
    if max_relative_residual > 1e-6:
        raise SceneError(f"eigensolver did not converge: relative residual "
                         f"{max_relative_residual:.1e} > 1e-6 (plate {length_m} x {thickness_m}"
                         f" x {width_m} m, maxh {mesh_size_m} m, {boundary_condition})")

    # Vertex coordinates, sample fields at vertices and mirrored vertices.
    coordinates_m = np.array(mesh.ngmesh.Coordinates(), dtype=float)
    node_count = coordinates_m.shape[0]
    scalar_dofs = dof_count // 3
    grid_function = ngs.GridFunction(fes)
    mirrors = [np.array([1.0, -1.0, 1.0]), np.array([1.0, 1.0, -1.0]),
               np.array([1.0, -1.0, -1.0])]
    mirror_points = [mesh(*(coordinates_m * flip).T) for flip in mirrors]

    def sampled(vector: np.ndarray) -> list[np.ndarray]:
        # The vertex unknowns of the hierarchical H1 basis are the vertex values; the vector
        # space stores the components as three consecutive blocks.
        at_vertices = np.column_stack([vector[c * scalar_dofs:c * scalar_dofs + node_count]
                                       for c in range(3)])
        grid_function.vec.FV().NumPy()[:] = vector
        return [at_vertices] + [np.asarray(grid_function(points)) for points in mirror_points]

    samples = [sampled(eigenvectors[:, i]) for i in range(eigenvectors.shape[1])]
    eigenvalues, eigenvectors, samples = _align_degenerate_modes(
        eigenvalues, eigenvectors, samples, stiffness_csr)

    kind_shares = np.array([parity_kind_shares(*sample) for sample in samples])
    kinds = tuple(classify_kind_shares(shares, minimum_share) for shares in kind_shares)
    energy_shares = np.zeros((eigenvectors.shape[1], 3))
    for index in range(eigenvectors.shape[1]):
        vector = eigenvectors[:, index]
        mass_times = mass_csr @ vector  # the mass matrix has no coupling between components
        for component in range(3):
            block = slice(component * scalar_dofs, (component + 1) * scalar_dofs)
            energy_shares[index, component] = vector[block] @ mass_times[block]
        energy_shares[index] /= energy_shares[index].sum()

    shapes = np.array([sample[0] for sample in samples])
    for index in range(shapes.shape[0]):
        magnitudes = np.linalg.norm(shapes[index], axis=1)
        peak = int(np.argmax(magnitudes))
        component = int(np.argmax(np.abs(shapes[index, peak])))
        sign = 1.0 if shapes[index, peak, component] >= 0.0 else -1.0
        shapes[index] *= sign / magnitudes[peak]

    triangles = np.array([[vertex.nr - 1 for vertex in element.vertices]
                          for element in mesh.ngmesh.Elements2D()], dtype=np.int64)
    omegas = np.sqrt(np.maximum(eigenvalues, 0.0))
    return PlateModes(
        length_m=float(length_m), thickness_m=float(thickness_m), width_m=float(width_m),
        mesh_size_m=float(mesh_size_m), boundary_condition=boundary_condition,
        frequencies_Hz=omegas / (2.0 * math.pi), frequencies_rad_per_s=omegas,
        mode_kinds=kinds, kind_shares=kind_shares, kinetic_energy_shares_xyz=energy_shares,
        node_coordinates_m=coordinates_m, mode_shapes=shapes, surface_triangles=triangles,
        element_count=int(mesh.ne), node_count=int(node_count), dof_count=int(dof_count),
        constraint_count=int(constraints.shape[0]),
        max_relative_residual=max_relative_residual, rigid_body_frequencies_Hz=rigid_Hz,
        wall_time_s=time.perf_counter() - start_s)


def _align_degenerate_modes(eigenvalues: np.ndarray, eigenvectors: np.ndarray,
                            samples: list[list[np.ndarray]], stiffness_csr,
                            relative_gap: float = 2e-2, pure_share: float = 0.99):
    """Rotate clusters of nearly equal eigenvalues to symmetry-pure modes.

    A cluster: consecutive eigenvalues omega^2 closer than ``relative_gap`` (2 %, i.e. 1 % in
    frequency) that contain a mode with no kind share above ``pure_share``. A square section
    has equal in-plane and out-of-plane bending frequencies; a mesh that is not symmetric
    splits them by up to ~0.7 % (coarse meshes) and returns diagonal, mixed bending modes.
    The cluster's M-orthonormal eigenvectors Phi are replaced by Phi Q, Q orthogonal from the
    eigenvectors of sum_k k P_k (P_k the Gram matrices of the sampled parity projections), so
    each new mode lies in one symmetry class; its eigenvalue becomes its Rayleigh quotient.
    """
    eigenvalues = eigenvalues.copy()
    eigenvectors = eigenvectors.copy()
    samples = [list(sample) for sample in samples]
    start = 0
    count = len(eigenvalues)
    while start < count:
        stop = start + 1
        while stop < count and (eigenvalues[stop] - eigenvalues[stop - 1]
                                <= relative_gap * abs(eigenvalues[stop])):
            stop += 1
        impure = any(parity_kind_shares(*samples[index]).max() < pure_share
                     for index in range(start, stop))
        if stop - start > 1 and impure:
            members = range(start, stop)
            flip_y, flip_z = np.array([1.0, -1.0, 1.0]), np.array([1.0, 1.0, -1.0])
            projections = []
            for index in members:
                u, u_y, u_z, u_yz = samples[index]
                ry, rz, ryz = u_y * flip_y, u_z * flip_z, u_yz * flip_y * flip_z
                projections.append([u + ry + rz + ryz, u - ry + rz - ryz,
                                    u + ry - rz - ryz, u - ry - rz + ryz])
            size = stop - start
            weighted = np.zeros((size, size))
            for kind_index in range(len(MODE_KINDS)):
                for i in range(size):
                    for j in range(size):
                        weighted[i, j] += kind_index * np.sum(
                            projections[i][kind_index] * projections[j][kind_index])
            _, rotation = np.linalg.eigh(weighted)
            block = slice(start, stop)
            eigenvectors[:, block] = eigenvectors[:, block] @ rotation
            old_samples = samples[start:stop]
            for new_index in range(size):
                samples[start + new_index] = [
                    sum(rotation[old, new_index] * old_samples[old][part] for old in range(size))
                    for part in range(4)]
                vector = eigenvectors[:, start + new_index]
                eigenvalues[start + new_index] = vector @ (stiffness_csr @ vector)
            order = np.argsort(eigenvalues[block]) + start
            eigenvalues[block] = eigenvalues[order]
            eigenvectors[:, block] = eigenvectors[:, order]
            samples[start:stop] = [samples[i] for i in order]
        start = stop
    return eigenvalues, eigenvectors, samples


# ---------------------------------------------------------------------------------------------
# Beam finite elements (an emulation of the thesis's ANSYS BEAM188 models)
# ---------------------------------------------------------------------------------------------

# Per boundary condition: local DOFs [ux, uy, uz, rot_x, rot_y, rot_z] fixed at the first node
# (x = 0) and at the last node (x = L). Rotation about z (the joint axis) is always free.
_BEAM_FIXED_DOFS = {
    "free-free": ((), ()),
    "pinned-pinned": ((0, 1, 2, 3, 4), (0, 1, 2, 3, 4)),
    "pinned-roller": ((0, 1, 2, 3, 4), (1, 2, 3, 4)),
}


def beam_element_modes(length_m: float, thickness_m: float, width_m: float,
                       boundary_condition: str, element_count: int = 8, mode_count: int = 5,
                       material: Material = THESIS_STEEL,
                       shear_correction: float = SHEAR_CORRECTION_RECTANGLE,
                       torsion_constant_m4: float | None = None) -> BeamLinkModes:
    """Modes of a link from 3D two-node linear Timoshenko beam elements (BEAM188-like).

    The element is what ANSYS documents for BEAM188 with its default KEYOPT(3) = 0 (ANSYS
    Theory Reference, BEAM188): linear interpolation of the three displacements and three
    rotations, stiffness integrated with one point along the length (reduced integration: no
    shear locking), consistent mass with rotary (rho I) and torsional (rho I_p) inertia.
    ``element_count`` equal elements along the link; thickness (m) along y, width (m) along z,
    length (m) along x. ``boundary_condition`` from :data:`LINK_BOUNDARY_CONDITIONS`: the end
    nodes have x, y, z translations and rotations about x and y fixed, rotation about z free;
    pinned-roller frees x at the last node. ``torsion_constant_m4`` overrides the series value
    of :func:`rectangle_torsion_constant_m4`. Free-free: the six rigid modes are skipped.

    Returns :class:`BeamLinkModes`; kinds from the kinetic-energy shares of ux (axial), uy
    (in-plane bending), uz (out-of-plane bending) and rot_x (torsion); ``mode_orders`` counts
    within each kind.
    """
    import scipy.sparse as sp
    from scipy.linalg import eigh
    from scipy.sparse.linalg import eigsh

    _check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m,
                    shear_correction=shear_correction)
    _check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    _check_count("element_count", element_count, 2000)
    _check_count("mode_count", mode_count)
    material.check()
    section = rectangle_section(thickness_m, width_m)
    torsion_constant = (section.torsion_constant_m4 if torsion_constant_m4 is None
                        else torsion_constant_m4)
    _check_positive(torsion_constant_m4=torsion_constant)
    youngs_Pa, shear_Pa = material.youngs_modulus_Pa, material.shear_modulus_Pa
    density = material.density_kg_per_m3
    area = section.area_m2
    inertia_y_bending = section.second_moment_m4        # uy deflection, rotation about z
    inertia_z_bending = section.second_moment_other_m4  # uz deflection, rotation about y
    element_length = length_m / element_count
    node_count = element_count + 1
    dof_count = 6 * node_count
    # Element matrices are collected as (rows, cols, values) and summed by the sparse
    # constructor: long converged models (hundreds of elements) stay cheap.
    triplets: dict[str, list[np.ndarray]] = {"rows": [], "cols": [], "stiffness": [],
                                              "mass": []}

    def scatter(dofs: list[int], element_stiffness: np.ndarray,
                element_mass: np.ndarray) -> None:
        rows, cols = np.meshgrid(dofs, dofs, indexing="ij")
        triplets["rows"].append(rows.ravel())
        triplets["cols"].append(cols.ravel())
        triplets["stiffness"].append(element_stiffness.ravel())
        triplets["mass"].append(element_mass.ravel())

    rod_stiffness = np.array([[1.0, -1.0], [-1.0, 1.0]]) / element_length
    rod_mass = np.array([[2.0, 1.0], [1.0, 2.0]]) * element_length / 6.0
    # Shear strain at the element midpoint (one-point rule) for [w1, psi1, w2, psi2], with
    # gamma = w' - psi.
    shear_strain = np.array([-1.0 / element_length, -0.5, 1.0 / element_length, -0.5])
    curvature = np.array([0.0, -1.0, 0.0, 1.0]) / element_length
    for element in range(element_count):
        first = 6 * element
        for component, axial_rigidity, inertia_per_length in (
                (0, youngs_Pa * area, density * area),
                (3, shear_Pa * torsion_constant, density * section.polar_moment_m4)):
            scatter([first + component, first + 6 + component],
                    axial_rigidity * rod_stiffness, inertia_per_length * rod_mass)
        # In-plane bending: w = uy, psi = rot_z. Out-of-plane: w = uz, psi = -rot_y (a
        # positive rotation about y tilts the section against +z).
        for deflection, rotation, sign, inertia in ((1, 5, 1.0, inertia_y_bending),
                                                    (2, 4, -1.0, inertia_z_bending)):
            dofs = [first + deflection, first + rotation, first + 6 + deflection,
                    first + 6 + rotation]
            signs = np.diag([1.0, sign, 1.0, sign])
            element_stiffness = (youngs_Pa * inertia * element_length
                                 * np.outer(curvature, curvature)
                                 + shear_correction * shear_Pa * area * element_length
                                 * np.outer(shear_strain, shear_strain))
            element_mass = np.zeros((4, 4))
            element_mass[np.ix_([0, 2], [0, 2])] = density * area * rod_mass
            element_mass[np.ix_([1, 3], [1, 3])] = density * inertia * rod_mass
            scatter(dofs, signs @ element_stiffness @ signs, signs @ element_mass @ signs)
    fixed_first, fixed_last = _BEAM_FIXED_DOFS[boundary_condition]
    fixed = list(fixed_first) + [6 * element_count + dof for dof in fixed_last]
    free = np.setdiff1d(np.arange(dof_count), fixed)
    rows, cols = np.concatenate(triplets["rows"]), np.concatenate(triplets["cols"])
    stiffness = sp.csr_matrix((np.concatenate(triplets["stiffness"]), (rows, cols)),
                              shape=(dof_count, dof_count))
    mass = sp.csr_matrix((np.concatenate(triplets["mass"]), (rows, cols)),
                         shape=(dof_count, dof_count))
    stiffness_free = stiffness[free][:, free]
    mass_free = mass[free][:, free]
    rigid_count = 6 if boundary_condition == "free-free" else 0
    wanted = rigid_count + mode_count
    if free.size <= wanted:
        raise SceneError(f"element_count = {element_count}: too few elements for "
                         f"{mode_count} modes")
    if free.size <= 600:
        eigenvalues, vectors = eigh(stiffness_free.toarray(), mass_free.toarray())
    else:
        # Shift-invert about a negative shift (positive definite even when free), scaled by
        # the Euler-Bernoulli pinned-pinned frequency of the weak plane.
        shift = 0.25 * _weak_plane_estimate_rad_per_s(length_m, thickness_m, width_m,
                                                 material) ** 2
        eigenvalues, vectors = eigsh(stiffness_free.tocsc(), k=wanted, M=mass_free.tocsc(),
                                     sigma=-shift, which="LM")
        order = np.argsort(eigenvalues)
        eigenvalues, vectors = eigenvalues[order], vectors[:, order]
    eigenvalues = eigenvalues[rigid_count:rigid_count + mode_count]
    vectors = vectors[:, rigid_count:rigid_count + mode_count]
    kinds: list[str] = []
    orders: list[int] = []
    kind_of_component = {0: "axial", 1: "in-plane bending", 2: "out-of-plane bending",
                         3: "torsion"}
    for index in range(mode_count):
        full = np.zeros(dof_count)
        full[free] = vectors[:, index]
        kinetic = full * (mass @ full)
        energy = [kinetic[component::6].sum() for component in range(4)]
        kind = kind_of_component[int(np.argmax(energy))]
        kinds.append(kind)
        orders.append(kinds.count(kind))
    omegas = np.sqrt(np.maximum(eigenvalues, 0.0))
    return BeamLinkModes(frequencies_rad_per_s=omegas, frequencies_Hz=omegas / (2 * math.pi),
                         mode_kinds=tuple(kinds), mode_orders=np.array(orders),
                         theory=f"linear Timoshenko beam elements, {element_count} elements")


# ---------------------------------------------------------------------------------------------
# Mesh convergence
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class MeshSelection:
    """Outcome of :func:`select_production_mesh`.

    ``reference_frequency`` (unit of the input frequencies) is the Richardson extrapolation
    of the three finest levels when they converge monotonically with an observed order in
    [0.5, 12] (``reference_method`` "richardson", ``observed_order`` set), else the finest
    value ("finest", order NaN). ``relative_errors`` (n_levels,) = |f - f_ref| / f_ref.
    ``selected_index`` is the coarsest level whose error and every finer level's error are
    within ``relative_tolerance``, or None if even the finest is not.
    """

    reference_frequency: float
    reference_method: str
    observed_order: float
    relative_errors: np.ndarray
    relative_tolerance: float
    selected_index: int | None


def select_production_mesh(mesh_sizes_m: Sequence[float], frequencies: Sequence[float],
                           relative_tolerance: float = 0.005) -> MeshSelection:
    """Pick the coarsest mesh whose frequency lies within ``relative_tolerance`` of converged.

    ``mesh_sizes_m`` strictly decreasing (m), ``frequencies`` (any one unit) per level,
    ``relative_tolerance`` dimensionless in (0, 1). The converged value is estimated by
    Richardson extrapolation f(h) = f_ref + C h^p through the three finest levels (p solved
    for, so the sizes need not form a geometric sequence); if those levels are not monotone
    with shrinking steps, the finest value is the reference. Pure function (no FE), so the
    selection logic can be tested on synthetic data.
    """
    sizes = np.asarray(mesh_sizes_m, dtype=float)
    values = np.asarray(frequencies, dtype=float)
    if sizes.ndim != 1 or sizes.shape != values.shape or sizes.size < 1:
        raise SceneError("mesh_sizes_m and frequencies must be 1D sequences of equal length")
    if np.any(sizes <= 0) or np.any(np.diff(sizes) >= 0):
        raise SceneError("mesh_sizes_m must be positive and strictly decreasing (coarse first)")
    if np.any(~np.isfinite(values)) or np.any(values <= 0):
        raise SceneError("frequencies must be positive finite numbers")
    if not 0.0 < relative_tolerance < 1.0:
        raise SceneError(f"relative_tolerance = {relative_tolerance!r}: must lie in (0, 1)")
    reference, method, order = float(values[-1]), "finest", float("nan")
    if sizes.size >= 3:
        (h1, h2, h3), (f1, f2, f3) = sizes[-3:], values[-3:]
        step_coarse, step_fine = f1 - f2, f2 - f3
        if step_coarse * step_fine > 0 and abs(step_fine) < abs(step_coarse):
            ratio = step_coarse / step_fine

            def mismatch(p: float) -> float:
                return (h1**p - h2**p) / (h2**p - h3**p) - ratio

            low, high = 0.5, 12.0
            if mismatch(low) * mismatch(high) < 0:
                order = _brent_root(mismatch, low, high)
                coefficient = step_fine / (h2**order - h3**order)
                reference, method = float(f3 - coefficient * h3**order), "richardson"
    errors = np.abs(values - reference) / reference
    within = errors <= relative_tolerance
    selected: int | None = None
    for index in range(sizes.size):
        if np.all(within[index:]):
            selected = index
            break
    return MeshSelection(reference_frequency=reference, reference_method=method,
                         observed_order=order, relative_errors=errors,
                         relative_tolerance=relative_tolerance, selected_index=selected)


@dataclass(frozen=True)
class MeshConvergence:
    """Per-level results of :func:`mesh_convergence` and the production-mesh choice.

    Arrays (n_levels,): ``mesh_sizes_m`` (m), ``element_counts``, ``dof_counts``,
    ``frequencies_Hz`` (Hz, first mode of ``mode_kind``), ``wall_times_s`` (s, whole
    :func:`plate_modes` call), ``cpu_times_s`` (s, process CPU time of the call).
    ``selection``: :class:`MeshSelection`. ``production_mesh_size_m``: the selected size (m),
    or None. ``mode_kind`` and ``boundary_condition`` as requested.
    """

    length_m: float
    thickness_m: float
    width_m: float
    boundary_condition: str
    mode_kind: str
    mesh_sizes_m: np.ndarray
    element_counts: np.ndarray
    dof_counts: np.ndarray
    frequencies_Hz: np.ndarray
    wall_times_s: np.ndarray
    cpu_times_s: np.ndarray
    selection: MeshSelection
    production_mesh_size_m: float | None


def default_mesh_sizes_m(thickness_m: float, width_m: float) -> np.ndarray:
    """Default refinement levels, m: 4 s, 2.83 s, 2 s, 1.41 s, s, ..., s / 16, with s the
    smaller of thickness and width; ratio sqrt(2) per level. :func:`mesh_convergence` stops
    at its DOF budget long before the finest: a 1 mm plate stops at about s, a 10 mm plate
    (mesh limited by the 10 mm box, so its coarse levels are pre-asymptotic) near s / 4.
    """
    _check_positive(thickness_m=thickness_m, width_m=width_m)
    smallest_m = min(thickness_m, width_m)
    return smallest_m * 2.0 ** (np.arange(4, -9, -1) / 2.0)


def mesh_convergence(length_m: float, thickness_m: float, width_m: float,
                     boundary_condition: str = "pinned-pinned",
                     mode_kind: str = "in-plane bending",
                     mesh_sizes_m: Sequence[float] | None = None,
                     relative_tolerance: float = 0.005, max_dof_count: int = 60_000,
                     mode_count: int = 5, material: Material = THESIS_STEEL
                     ) -> MeshConvergence:
    """Refine ``mesh_size_m`` and track the first mode of ``mode_kind``; pick the production mesh.

    Sizes in m; ``mesh_sizes_m`` strictly decreasing, default :func:`default_mesh_sizes_m`
    (from 4 t down by sqrt(2) per level). Refinement stops at the first level whose
    DOF count, estimated from the previous level as DOF * (h_prev / h)^3, would exceed
    ``max_dof_count`` (memory and time of the sparse Cholesky factorisation grow fast with
    3D meshes). ``mode_count`` modes are computed per level; raise it if ``mode_kind`` is not
    among them. Selection: :func:`select_production_mesh` with ``relative_tolerance``
    (default 0.5 %). Returns :class:`MeshConvergence`.
    """
    _check_positive(length_m=length_m, thickness_m=thickness_m, width_m=width_m)
    _check_choice("mode_kind", mode_kind, MODE_KINDS)
    _check_choice("boundary_condition", boundary_condition, LINK_BOUNDARY_CONDITIONS)
    sizes = (default_mesh_sizes_m(thickness_m, width_m) if mesh_sizes_m is None
             else np.asarray(mesh_sizes_m, dtype=float))
    if sizes.ndim != 1 or sizes.size < 1 or np.any(np.diff(sizes) >= 0):
        raise SceneError("mesh_sizes_m must be a non-empty, strictly decreasing sequence")
    _check_positive(**{f"mesh_sizes_m[{i}]": float(h) for i, h in enumerate(sizes)})
    rows: list[tuple[float, int, int, float, float, float]] = []
    for size_m in sizes:
        if rows:
            previous_size_m, previous_dofs = rows[-1][0], rows[-1][2]
            if previous_dofs * (previous_size_m / size_m) ** 3 > max_dof_count:
                break
        wall_start, cpu_start = time.perf_counter(), time.process_time()
        modes = plate_modes(length_m, thickness_m, width_m, float(size_m), boundary_condition,
                            mode_count, material)
        wall_s, cpu_s = time.perf_counter() - wall_start, time.process_time() - cpu_start
        frequency_Hz = float(modes.frequencies_Hz[modes.first_of_kind(mode_kind)])
        rows.append((float(size_m), modes.element_count, modes.dof_count, frequency_Hz,
                     wall_s, cpu_s))
    table = np.array(rows)
    selection = select_production_mesh(table[:, 0], table[:, 3], relative_tolerance)
    production = (None if selection.selected_index is None
                  else float(table[selection.selected_index, 0]))
    return MeshConvergence(
        length_m=float(length_m), thickness_m=float(thickness_m), width_m=float(width_m),
        boundary_condition=boundary_condition, mode_kind=mode_kind, mesh_sizes_m=table[:, 0],
        element_counts=table[:, 1].astype(int), dof_counts=table[:, 2].astype(int),
        frequencies_Hz=table[:, 3], wall_times_s=table[:, 4], cpu_times_s=table[:, 5],
        selection=selection, production_mesh_size_m=production)


# ---------------------------------------------------------------------------------------------
# The thesis's tables
# ---------------------------------------------------------------------------------------------

TABLE5_FE_MESH_SIZES_M: tuple[float, ...] = (0.002, 0.003, 0.0025, 0.0035)
"""Production netgen maxh (m) of the four Table 5 plates, t = 1, 3, 5, 10 mm, from
:func:`mesh_convergence` (pinned-pinned, first in-plane bending): each lies within 0.05 % of the
Richardson-extrapolated (or finest) frequency and costs at most ~10k DOF."""


def _periods_and_counts(prefix: str, omega_rad_per_s: np.ndarray, deployment_time_s: float,
                        criterion_k: float) -> dict[str, np.ndarray]:
    """Both period conventions for circular frequencies omega: the thesis's T = 1/omega and
    the physical T = 2 pi / omega; n = delta_t / T; verdict "rigid" if n > k (Eq. 64-65)."""
    period_thesis_s = 1.0 / omega_rad_per_s
    period_physical_s = 2.0 * math.pi / omega_rad_per_s
    n = physics.n_values(deployment_time_s, omega_rad_per_s)
    n_thesis, n_physical = n["thesis"], n["physical"]
    return {
        f"{prefix}_period_thesis_convention_s": period_thesis_s,
        f"{prefix}_period_physical_s": period_physical_s,
        f"{prefix}_n_thesis_convention": n_thesis,
        f"{prefix}_n_physical": n_physical,
        f"{prefix}_verdict_thesis_convention": np.where(n_thesis > criterion_k, "rigid",
                                                        "flexible"),
        f"{prefix}_verdict_physical": np.where(n_physical > criterion_k, "rigid", "flexible"),
    }


def thesis_table5_reproduction(mesh_sizes_m: Sequence[float] | None = TABLE5_FE_MESH_SIZES_M,
                               material: Material = THESIS_STEEL,
                               deployment_time_s: float = DEPLOYMENT_TIME_S,
                               criterion_k: float = THESIS_K_CRITERION
                               ) -> dict[str, np.ndarray]:
    """Table 5 of Cavezza 2012 recomputed: four plate couplers 0.08 x 0.01 x t m.

    t = 1, 3, 5, 10 mm (bending height t in the mechanism plane, y), steel E = 200 GPa,
    rho = 7850 kg/m^3 (thesis) and nu = 0.3 (ours) unless ``material`` says otherwise. For
    each model: the first pinned-pinned in-plane bending circular frequency from
    Euler-Bernoulli (the thesis's "Frequency"), Timoshenko and 3D FE (:func:`plate_modes`,
    pinned-pinned, netgen maxh ``mesh_sizes_m[i]`` m; None skips the FE columns), then for
    Euler-Bernoulli and FE both period conventions and the counts n = delta_t / T with
    ``deployment_time_s`` (s), and the verdicts of the criterion with k = ``criterion_k``
    ("rigid" if n > k, Eq. 64-65).

    Returns a dict of numpy arrays, one entry per model (index 0..3), with units in the keys:
    ``model``, ``coupler_{length,width,thickness}_m``, ``thesis_frequency_as_published``,
    ``thesis_period_as_published_s``, ``thesis_n_as_published``,
    ``thesis_verdict_as_published``; ``euler_bernoulli_omega_rad_per_s``,
    ``euler_bernoulli_frequency_Hz``, ``timoshenko_omega_rad_per_s``,
    ``timoshenko_frequency_Hz``, ``euler_bernoulli_vs_thesis_relative``; ``fe_omega_rad_per_s``,
    ``fe_frequency_Hz``, ``fe_mesh_size_m``, ``fe_element_count``, ``fe_dof_count``,
    ``fe_vs_euler_bernoulli_relative``, ``fe_vs_timoshenko_relative``; for prefix
    ``euler_bernoulli`` and ``fe``: ``{prefix}_period_thesis_convention_s`` (1/omega),
    ``{prefix}_period_physical_s`` (2 pi/omega), ``{prefix}_n_thesis_convention``,
    ``{prefix}_n_physical``, ``{prefix}_verdict_thesis_convention``,
    ``{prefix}_verdict_physical``; and 0-d arrays ``deployment_time_s``, ``criterion_k``.
    Relative differences are (a - b) / b.
    """
    _check_positive(deployment_time_s=deployment_time_s, criterion_k=criterion_k)
    thickness_m = THESIS_TABLE5["coupler_thickness_m"]
    length_m, width_m = THESIS_COUPLER_LENGTH_M, THESIS_TABLE5_WIDTH_M
    eb = np.array([euler_bernoulli_bending_rad_per_s(length_m, t, width_m, "pinned-pinned", 1,
                                                     material)[0] for t in thickness_m])
    timoshenko = np.array([timoshenko_bending_rad_per_s(length_m, t, width_m, "pinned-pinned",
                                                        1, material)[0] for t in thickness_m])
    table: dict[str, np.ndarray] = {
        "model": THESIS_TABLE5["model"].copy(),
        "coupler_length_m": np.full(4, length_m),
        "coupler_width_m": np.full(4, width_m),
        "coupler_thickness_m": thickness_m.copy(),
        "thesis_frequency_as_published": THESIS_TABLE5["frequency_as_published"].copy(),
        "thesis_period_as_published_s": THESIS_TABLE5["period_as_published_s"].copy(),
        "thesis_n_as_published": THESIS_TABLE5["n_as_published"].copy(),
        "thesis_verdict_as_published": THESIS_TABLE5["verdict_as_published"].copy(),
        "euler_bernoulli_omega_rad_per_s": eb,
        "euler_bernoulli_frequency_Hz": eb / (2 * math.pi),
        "timoshenko_omega_rad_per_s": timoshenko,
        "timoshenko_frequency_Hz": timoshenko / (2 * math.pi),
        "euler_bernoulli_vs_thesis_relative":
            eb / THESIS_TABLE5["frequency_as_published"] - 1.0,
    }
    table.update(_periods_and_counts("euler_bernoulli", eb, deployment_time_s, criterion_k))
    if mesh_sizes_m is not None:
        sizes = np.asarray(mesh_sizes_m, dtype=float)
        if sizes.shape != (4,):
            raise SceneError("mesh_sizes_m: give four sizes (m), one per Table 5 model")
        fe, elements, dofs = [], [], []
        for t, size_m in zip(thickness_m, sizes, strict=True):
            modes = plate_modes(length_m, float(t), width_m, float(size_m), "pinned-pinned",
                                5, material)
            fe.append(modes.frequencies_rad_per_s[modes.first_of_kind("in-plane bending")])
            elements.append(modes.element_count)
            dofs.append(modes.dof_count)
        fe_omega = np.array(fe)
        table.update({
            "fe_omega_rad_per_s": fe_omega,
            "fe_frequency_Hz": fe_omega / (2 * math.pi),
            "fe_mesh_size_m": sizes,
            "fe_element_count": np.array(elements),
            "fe_dof_count": np.array(dofs),
            "fe_vs_euler_bernoulli_relative": fe_omega / eb - 1.0,
            "fe_vs_timoshenko_relative": fe_omega / timoshenko - 1.0,
        })
        table.update(_periods_and_counts("fe", fe_omega, deployment_time_s, criterion_k))
    table["deployment_time_s"] = np.array(deployment_time_s)
    table["criterion_k"] = np.array(criterion_k)
    return table


THESIS_ANSYS_SECTION_SIDE_M = 0.010
"""Our reading of the cross-section of the thesis's BEAM188 links (Tables 7 and 9): a solid
10 mm x 10 mm square (the thesis does not state it). See :func:`thesis_link_modal_reproduction`."""

THESIS_ANSYS_ELEMENT_COUNT = 8
"""Our reading of the BEAM188 mesh of Tables 7 and 9: 8 linear elements per link."""

THESIS_ANSYS_BOUNDARY_CONDITION = "pinned-roller"
"""Our reading of the supports of Tables 7 and 9: pin at one end, roller (axially free) at the
other, rotation about z free, out-of-plane rotations and twist held at both ends."""

THESIS_LINKS: tuple[str, ...] = ("crank", "coupler")


def thesis_link_modal_reproduction(
        link: str, fe_mesh_size_m: float | None = None,
        section_side_m: float = THESIS_ANSYS_SECTION_SIDE_M,
        element_count: int = THESIS_ANSYS_ELEMENT_COUNT,
        boundary_condition: str = THESIS_ANSYS_BOUNDARY_CONDITION,
        material: Material = THESIS_STEEL,
        deployment_time_s: float = DEPLOYMENT_TIME_S) -> dict[str, np.ndarray]:
    """Tables 7 (crank) and 9 (coupler) of Cavezza 2012 next to our models of them.

    The thesis gives five BEAM188 "TIME/FREQ" values per link with no unit, section or
    supports. Our reading, found by fitting (rms 0.4 %, worst 0.7 % over all ten values with
    nothing tuned but the discrete choices): values in Hz (cyclic), a solid square section
    ``section_side_m`` = 10 mm (Table 5's model 3), ``element_count`` = 8 linear BEAM188
    elements per link, supports ``boundary_condition`` = "pinned-roller" (x free at the second
    end). The evidence: (1) the coupler's 4th value 15799 and the crank's 3rd 31598 are the
    fixed-free axial modes c / (4 L) = 15774 and 31547 Hz (c = sqrt(E / rho)), both +0.16 %,
    which is the consistent-mass error of 8 linear rod elements; (2) coupler 18215 and crank
    36431 differ by exactly 2 = L2 / L1, so they are rod (torsion) modes; the St-Venant torsion
    frequency of any square section is c_t sqrt(J / I_p) / (2 L) = 17968 Hz for the coupler at
    nu = 0.3, and the 8-element model gives 18084 (-0.7 % from the thesis); (3) the bending
    values follow from a 10 mm square with in-plane bending pinned and out-of-plane bending
    clamped. Read as rad/s, the axial modes would need a wave speed 2 pi too large.

    ``link``: "crank" (L1 = 0.04 m) or "coupler" (L2 = 0.08 m). ``fe_mesh_size_m``: netgen
    maxh (m) for a 3D FE column (:func:`plate_modes`, same supports), None to skip.
    ``deployment_time_s``: delta_t (s).

    Returns a dict of numpy arrays (per mode 1..5 unless 0-d): ``mode``,
    ``thesis_value_as_published``, ``thesis_period_as_published_s``, ``thesis_n_reading_Hz``
    (delta_t * value: T = 1/value, the thesis's convention, physical if the values are Hz),
    ``thesis_n_reading_rad_per_s`` (delta_t * value / (2 pi)); for each model prefix
    ``beam188_emulation`` (:func:`beam_element_modes`), ``timoshenko`` and
    ``euler_bernoulli`` (:func:`beam_link_modes`), and ``fe`` if requested:
    ``{prefix}_frequency_Hz``, ``{prefix}_kind``, ``{prefix}_vs_thesis_relative``
    ((model - thesis) / thesis, mode by mode), ``{prefix}_period_s`` (1 / f); 0-d:
    ``thesis_k_as_published`` (733 or 299, from the rounded 5th period),
    ``k_reading_Hz`` (delta_t * value_5), ``k_reading_rad_per_s`` (delta_t * value_5 / (2 pi)),
    ``{prefix}_k`` (delta_t * f_5), ``link_length_m``, ``section_side_m``, ``element_count``,
    ``boundary_condition``, ``deployment_time_s``.
    """
    _check_choice("link", link, THESIS_LINKS)
    _check_positive(section_side_m=section_side_m, deployment_time_s=deployment_time_s)
    if link == "crank":
        length_m, published, thesis_k = (THESIS_CRANK_LENGTH_M, THESIS_TABLE7_CRANK,
                                         THESIS_K_CRANK)
    else:
        length_m, published, thesis_k = (THESIS_COUPLER_LENGTH_M, THESIS_TABLE9_COUPLER,
                                         THESIS_K_COUPLER)
    values = published["frequency_as_published"]
    mode_count = values.size
    table: dict[str, np.ndarray] = {
        "mode": published["mode"].copy(),
        "thesis_value_as_published": values.copy(),
        "thesis_period_as_published_s": published["period_as_published_s"].copy(),
        "thesis_n_reading_Hz": deployment_time_s * values,
        "thesis_n_reading_rad_per_s": physics.n_values(deployment_time_s,
                                                       values)["physical"],
        "thesis_k_as_published": np.array(thesis_k),
        "k_reading_Hz": np.array(deployment_time_s * values[-1]),
        "k_reading_rad_per_s": np.array(physics.n_values(deployment_time_s,
                                                         values[-1])["physical"]),
    }
    models: dict[str, tuple[np.ndarray, tuple[str, ...]]] = {}
    emulation = beam_element_modes(length_m, section_side_m, section_side_m,
                                   boundary_condition, element_count, mode_count, material)
    models["beam188_emulation"] = (emulation.frequencies_Hz, emulation.mode_kinds)
    for theory, prefix in (("timoshenko", "timoshenko"),
                           ("euler-bernoulli", "euler_bernoulli")):
        beam = beam_link_modes(length_m, section_side_m, section_side_m, boundary_condition,
                               mode_count, theory, material)
        models[prefix] = (beam.frequencies_Hz, beam.mode_kinds)
    if fe_mesh_size_m is not None:
        modes = plate_modes(length_m, section_side_m, section_side_m, fe_mesh_size_m,
                            boundary_condition, mode_count, material)
        models["fe"] = (modes.frequencies_Hz, modes.mode_kinds)
        table["fe_mesh_size_m"] = np.array(fe_mesh_size_m)
        table["fe_dof_count"] = np.array(modes.dof_count)
    for prefix, (frequencies_Hz, kinds) in models.items():
        table[f"{prefix}_frequency_Hz"] = frequencies_Hz
        table[f"{prefix}_kind"] = np.array(kinds)
        table[f"{prefix}_vs_thesis_relative"] = frequencies_Hz / values - 1.0
        table[f"{prefix}_period_s"] = 1.0 / frequencies_Hz
        table[f"{prefix}_k"] = np.array(deployment_time_s * frequencies_Hz[-1])
    table.update({
        "link_length_m": np.array(length_m),
        "section_side_m": np.array(section_side_m),
        "element_count": np.array(element_count),
        "boundary_condition": np.array(boundary_condition),
        "deployment_time_s": np.array(deployment_time_s),
    })
    return table
