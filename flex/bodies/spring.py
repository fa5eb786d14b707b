"""The thesis's helical compression spring (sec. 6.1): rate, a consistent design, stresses,
surge (the finite-element check of the peak shear stress: :mod:`flex.bodies.spring_fe`).

All quantities are SI (m, N, Pa, kg, s, Hz) and every name carries its unit. The closed forms
are those of Shigley's Mechanical Engineering Design, 10th ed. (Budynas and Nisbett, 2015),
chapter 10 ("Shigley" below).

The thesis's spring data (Table 2, sec. 6.1) are not self-consistent: with G = 79.3 GPa,
d = 4.4 mm and N = 3 active coils, ``k = G d^4 / (8 D^3 N)`` gives 1500 N/m only for a mean
coil diameter D = 93.8 mm, while the stated "spring diameter" 0.150 m gives 367 N/m.
:func:`rate_reproduction_table` lists which single input would have to change, and
:data:`CONSISTENT_THESIS_SPRING` is the design flex uses (see its comment for the reasons).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from flex.base.errors import SceneError
from flex.base.physics import TWO_PI, n_values
from flex.base.spring_waves import spring_end_mass_wave_numbers
from flex.base.thesis import (
    THESIS_ACTIVE_COILS,
    THESIS_ANGLE_MAX_TIME_S,
    THESIS_DELTA_T_S,
    THESIS_FREE_LENGTH_M,
    THESIS_K,
    THESIS_MUSIC_WIRE_DENSITY_KG_PER_M3,
    THESIS_MUSIC_WIRE_YOUNGS_MODULUS_PA,
    THESIS_SPRING_DIAMETER_M,
    THESIS_SPRING_RATE_N_PER_M,
    THESIS_WIRE_DIAMETER_M,
)

# --- Material: music wire, ASTM A228 --------------------------------------------------------
#: Young's modulus, thesis Table 3 (206 842 710 000 Pa = 30.0 Mpsi).
MUSIC_WIRE_YOUNGS_MODULUS_PA = THESIS_MUSIC_WIRE_YOUNGS_MODULUS_PA
#: Density, thesis Table 3.
MUSIC_WIRE_DENSITY_KG_PER_M3 = THESIS_MUSIC_WIRE_DENSITY_KG_PER_M3
#: Shear modulus: 79.3 GPa (11.5 Mpsi), the steel value of the project's datasheet check.
#: Shigley table 10-5 lists 80-82.7 GPa for A228 depending on wire size; 79.3 GPa keeps the
#: datasheet's numbers (367 N/m, 94 mm) reproducible. Implied Poisson ratio E/(2G) - 1 = 0.304.
MUSIC_WIRE_SHEAR_MODULUS_PA = 79.3e9
#: Minimum tensile strength S_ut = A / d^m (d in mm): Shigley table 10-4, music wire A228,
#: A = 2211 MPa mm^m (201 kpsi in^m), m = 0.145, valid for d = 0.10 ... 6.5 mm.
A228_TENSILE_STRENGTH_INTERCEPT_MPA_MM_M = 2211.0
A228_TENSILE_STRENGTH_EXPONENT = 0.145
A228_WIRE_DIAMETER_RANGE_M = (0.10e-3, 6.5e-3)
#: Maximum allowable torsional stress of helical compression springs in static service as a
#: fraction of S_ut, Shigley table 10-6 (after Joerres), music wire and cold-drawn carbon
#: steel: 45 % before set is removed, 60-70 % after set is removed (the lower bound is used).
#: Shigley also gives the torsional yield strength S_sy = 0.45 S_ut for these wires (sec. 10-6,
#: after Joerres).
MUSIC_WIRE_ALLOWABLE_TORSION_FRACTION_SET_NOT_REMOVED = 0.45
MUSIC_WIRE_ALLOWABLE_TORSION_FRACTION_SET_REMOVED = 0.60

# --- The thesis's spring (sec. 6.1, Table 2) and its use -------------------------------------
# THESIS_SPRING_RATE_N_PER_M, THESIS_FREE_LENGTH_M, THESIS_WIRE_DIAMETER_M,
# THESIS_SPRING_DIAMETER_M, THESIS_ACTIVE_COILS, THESIS_COMPRESSION_M: see flex.base.thesis.
#: Deployment time used in the rigid-or-flexible criterion (sec. 6.2); its origin is unstated.
THESIS_DEPLOYMENT_TIME_S = THESIS_DELTA_T_S
#: Half swing of the spring-driven mechanism: crank angle maximum at ~0.0265 s (sec. 5.5.1).
MECHANISM_HALF_SWING_TIME_S = THESIS_ANGLE_MAX_TIME_S
#: Criterion constant of the thesis (Eq. 64-65): rigid if n = delta_t / T > 108.
THESIS_RIGID_CRITERION_RATIO = THESIS_K


EndType = Literal["plain", "plain_ground", "squared", "squared_ground"]
END_TYPES: tuple[str, ...] = ("plain", "plain_ground", "squared", "squared_ground")


def require_positive(name: str, value: float, unit: str) -> float:
    """Return ``float(value)`` or raise :class:`SceneError` unless it is finite and > 0."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not (math.isfinite(number) and number > 0.0):
        raise SceneError(f"spring {name} = {value!r}: must be a finite number > 0 ({unit})")
    return number


# --- 1. Spring rate and its inversions -------------------------------------------------------

#: Shigley eq. 10-9, ``k = G d^4 / (8 D^3 N)``, as exponents: ``G d^4 D^-3 N^-1 k^-1 = 8``
_RATE_LAW: dict[str, tuple[int, str]] = {
    "shear_modulus_Pa": (1, "Pa"), "wire_diameter_m": (4, "m"),
    "mean_coil_diameter_m": (-3, "m"), "active_coils": (-1, "coils"),
    "rate_N_per_m": (-1, "N/m")}


def _solve_rate_law(unknown: str, **known: float) -> float:
    """The quantity ``unknown`` of :data:`_RATE_LAW` from the other four (each > 0)."""
    product = 1.0
    for name, value in known.items():
        exponent, unit = _RATE_LAW[name]
        product *= require_positive(name, value, unit) ** exponent
    return (8.0 / product) ** (1.0 / _RATE_LAW[unknown][0])


def helical_spring_rate_N_per_m(shear_modulus_Pa: float, wire_diameter_m: float,
                                mean_coil_diameter_m: float, active_coils: float) -> float:
    """Axial rate of a helical spring, ``k = G d^4 / (8 D^3 N)`` in N/m (Shigley eq. 10-9).

    ``shear_modulus_Pa`` G [Pa], ``wire_diameter_m`` d [m], ``mean_coil_diameter_m`` D [m],
    ``active_coils`` N [-]; all must be > 0.
    """
    return _solve_rate_law("rate_N_per_m", shear_modulus_Pa=shear_modulus_Pa,
                           wire_diameter_m=wire_diameter_m,
                           mean_coil_diameter_m=mean_coil_diameter_m, active_coils=active_coils)


def mean_coil_diameter_for_rate_m(rate_N_per_m: float, shear_modulus_Pa: float,
                                  wire_diameter_m: float, active_coils: float) -> float:
    """Mean coil diameter D [m] that gives ``rate_N_per_m``: ``D = (G d^4 / (8 k N))^(1/3)``."""
    return _solve_rate_law("mean_coil_diameter_m", rate_N_per_m=rate_N_per_m,
                           shear_modulus_Pa=shear_modulus_Pa, wire_diameter_m=wire_diameter_m,
                           active_coils=active_coils)


def active_coils_for_rate(rate_N_per_m: float, shear_modulus_Pa: float, wire_diameter_m: float,
                          mean_coil_diameter_m: float) -> float:
    """Number of active coils N [-] that gives ``rate_N_per_m``: ``N = G d^4 / (8 D^3 k)``."""
    return _solve_rate_law("active_coils", rate_N_per_m=rate_N_per_m,
                           shear_modulus_Pa=shear_modulus_Pa, wire_diameter_m=wire_diameter_m,
                           mean_coil_diameter_m=mean_coil_diameter_m)


def wire_diameter_for_rate_m(rate_N_per_m: float, shear_modulus_Pa: float,
                             mean_coil_diameter_m: float, active_coils: float) -> float:
    """Wire diameter d [m] that gives ``rate_N_per_m``: ``d = (8 k D^3 N / G)^(1/4)``."""
    return _solve_rate_law("wire_diameter_m", rate_N_per_m=rate_N_per_m,
                           shear_modulus_Pa=shear_modulus_Pa,
                           mean_coil_diameter_m=mean_coil_diameter_m, active_coils=active_coils)


def shear_modulus_for_rate_Pa(rate_N_per_m: float, wire_diameter_m: float,
                              mean_coil_diameter_m: float, active_coils: float) -> float:
    """Shear modulus G [Pa] that gives ``rate_N_per_m``: ``G = 8 k D^3 N / d^4``."""
    return _solve_rate_law("shear_modulus_Pa", rate_N_per_m=rate_N_per_m,
                           wire_diameter_m=wire_diameter_m,
                           mean_coil_diameter_m=mean_coil_diameter_m, active_coils=active_coils)


@dataclass(frozen=True)
class RateReproduction:
    """One row of "which inputs reproduce the rate": the input changed alone, others as stated.

    ``stated_value`` and ``value_for_rate`` are in ``unit``; ``ratio`` = value_for_rate / stated.
    """

    input_name: str
    unit: str
    stated_value: float
    value_for_rate: float

    @property
    def ratio(self) -> float:
        return self.value_for_rate / self.stated_value


def rate_reproduction_table(
        rate_N_per_m: float = THESIS_SPRING_RATE_N_PER_M,
        shear_modulus_Pa: float = MUSIC_WIRE_SHEAR_MODULUS_PA,
        wire_diameter_m: float = THESIS_WIRE_DIAMETER_M,
        mean_coil_diameter_m: float = THESIS_SPRING_DIAMETER_M,
        active_coils: float = THESIS_ACTIVE_COILS) -> list[RateReproduction]:
    """For each of D, N, d and G: the value that alone reproduces ``rate_N_per_m`` [N/m].

    The first row is the rate itself: stated rate versus the rate of the stated inputs.
    Defaults are the thesis's data (D = 0.150 m read as the mean coil diameter).
    """
    stated_rate = helical_spring_rate_N_per_m(shear_modulus_Pa, wire_diameter_m,
                                              mean_coil_diameter_m, active_coils)
    k = require_positive("rate_N_per_m", rate_N_per_m, "N/m")
    return [
        RateReproduction("spring rate k (of the stated inputs)", "N/m", k, stated_rate),
        RateReproduction("mean coil diameter D", "m", mean_coil_diameter_m,
                         mean_coil_diameter_for_rate_m(k, shear_modulus_Pa, wire_diameter_m,
                                                       active_coils)),
        RateReproduction("active coils N", "-", active_coils,
                         active_coils_for_rate(k, shear_modulus_Pa, wire_diameter_m,
                                               mean_coil_diameter_m)),
        RateReproduction("wire diameter d", "m", wire_diameter_m,
                         wire_diameter_for_rate_m(k, shear_modulus_Pa, mean_coil_diameter_m,
                                                  active_coils)),
        RateReproduction("shear modulus G", "Pa", shear_modulus_Pa,
                         shear_modulus_for_rate_Pa(k, wire_diameter_m, mean_coil_diameter_m,
                                                   active_coils)),
    ]


def format_rate_reproduction_table(rows: list[RateReproduction]) -> str:
    """Plain-text table of :func:`rate_reproduction_table` rows (the study prints it)."""
    lines = [f"{'input':<38} {'unit':<4} {'stated':>12} {'for rate':>12} {'ratio':>7}"]
    for row in rows:
        lines.append(f"{row.input_name:<38} {row.unit:<4} {row.stated_value:>12.5g} "
                     f"{row.value_for_rate:>12.5g} {row.ratio:>7.3f}")
    return "\n".join(lines)


# --- 2. Geometry of the coil ends and a consistent design ------------------------------------

def total_coils(active_coils: float, end_type: EndType) -> float:
    """Total coils N_t [-] for ``active_coils`` N_a and the end type (Shigley table 10-1).

    plain: N_a; plain_ground: N_a + 1; squared and squared_ground: N_a + 2.
    """
    n = require_positive("active_coils", active_coils, "coils")
    if end_type not in END_TYPES:
        raise SceneError(f"spring end_type = {end_type!r}: must be one of {', '.join(END_TYPES)}")
    return n + {"plain": 0.0, "plain_ground": 1.0, "squared": 2.0, "squared_ground": 2.0}[end_type]


def solid_length_m(wire_diameter_m: float, active_coils: float, end_type: EndType) -> float:
    """Solid length L_s [m] (Shigley table 10-1): ``d (N_t + 1)`` for plain and squared ends,
    ``d N_t`` for ground ends (plain_ground, squared_ground)."""
    d = require_positive("wire_diameter_m", wire_diameter_m, "m")
    n_total = total_coils(active_coils, end_type)
    return d * n_total if end_type.endswith("_ground") else d * (n_total + 1.0)


def pitch_m(free_length_m: float, wire_diameter_m: float, active_coils: float,
            end_type: EndType) -> float:
    """Coil pitch p [m] from the free length (Shigley table 10-1): plain (L0 - d)/N_a,
    plain_ground L0/(N_a + 1), squared (L0 - 3d)/N_a, squared_ground (L0 - 2d)/N_a."""
    length = require_positive("free_length_m", free_length_m, "m")
    d = require_positive("wire_diameter_m", wire_diameter_m, "m")
    n = require_positive("active_coils", active_coils, "coils")
    if end_type not in END_TYPES:
        raise SceneError(f"spring end_type = {end_type!r}: must be one of {', '.join(END_TYPES)}")
    pitch = {"plain": (length - d) / n, "plain_ground": length / (n + 1.0),
             "squared": (length - 3.0 * d) / n, "squared_ground": (length - 2.0 * d) / n}[end_type]
    if not pitch > d:
        raise SceneError(f"spring free_length_m = {free_length_m!r}: the pitch {pitch:.4g} m "
                         f"must exceed the wire diameter {d:.4g} m (coils would overlap)")
    return pitch


@dataclass(frozen=True)
class SpringDesign:
    """A helical compression spring; lengths in m, G in Pa, density in kg/m^3."""

    wire_diameter_m: float
    mean_coil_diameter_m: float
    active_coils: float
    free_length_m: float
    end_type: EndType = "plain_ground"
    shear_modulus_Pa: float = MUSIC_WIRE_SHEAR_MODULUS_PA
    density_kg_per_m3: float = MUSIC_WIRE_DENSITY_KG_PER_M3

    def __post_init__(self) -> None:
        for name, unit in (("wire_diameter_m", "m"), ("mean_coil_diameter_m", "m"),
                           ("active_coils", "coils"), ("free_length_m", "m"),
                           ("shear_modulus_Pa", "Pa"), ("density_kg_per_m3", "kg/m^3")):
            require_positive(name, getattr(self, name), unit)
        if self.end_type not in END_TYPES:
            raise SceneError(f"spring end_type = {self.end_type!r}: must be one of "
                             f"{', '.join(END_TYPES)}")
        if not self.mean_coil_diameter_m > self.wire_diameter_m:
            raise SceneError(f"spring mean_coil_diameter_m = {self.mean_coil_diameter_m!r}: must "
                             f"exceed the wire diameter {self.wire_diameter_m!r} m (index C > 1)")

    @property
    def rate_N_per_m(self) -> float:
        return helical_spring_rate_N_per_m(self.shear_modulus_Pa, self.wire_diameter_m,
                                           self.mean_coil_diameter_m, self.active_coils)

    @property
    def spring_index(self) -> float:
        """C = D / d [-]."""
        return spring_index(self.mean_coil_diameter_m, self.wire_diameter_m)

    @property
    def outside_diameter_m(self) -> float:
        return self.mean_coil_diameter_m + self.wire_diameter_m

    @property
    def total_coils(self) -> float:
        return total_coils(self.active_coils, self.end_type)

    @property
    def solid_length_m(self) -> float:
        return solid_length_m(self.wire_diameter_m, self.active_coils, self.end_type)

    @property
    def deflection_to_solid_m(self) -> float:
        """Free length minus solid length [m] (negative: the free length is below solid)."""
        return self.free_length_m - self.solid_length_m

    @property
    def pitch_m(self) -> float:
        return pitch_m(self.free_length_m, self.wire_diameter_m, self.active_coils, self.end_type)

    @property
    def helix_angle_rad(self) -> float:
        """Pitch angle of the coil, ``atan(p / (pi D))`` [rad]."""
        return math.atan(self.pitch_m / (math.pi * self.mean_coil_diameter_m))

    @property
    def active_mass_kg(self) -> float:
        return active_coil_mass_kg(self.density_kg_per_m3, self.wire_diameter_m,
                                   self.mean_coil_diameter_m, self.active_coils)

    def fractional_overrun_to_closure(self, working_deflection_m: float) -> float:
        """xi = (L0 - L_s) / y - 1 [-]; Shigley sec. 10-7 recommends xi >= 0.15."""
        y = require_positive("working_deflection_m", working_deflection_m, "m")
        return self.deflection_to_solid_m / y - 1.0


#: The design flex uses: keep k = 1500 N/m, d = 4.4 mm, N_a = 3 and L0 = 43 mm; solve D.
#: Why D: (a) 1500 N/m is the rate every dynamic study uses; (b) the datasheet calls 0.150 m
#: "D_max", which reads as the optimisation's upper bound on the coil diameter, and
#: D = 93.8 mm (outside 98.2 mm) respects it; (c) changing anything else alone fails: keeping
#: D = 150 mm needs N_a = 0.73 (under one coil), or d = 6.26 mm whose solid length
#: (>= 4 d = 25 mm) leaves less than the 22 mm press within 43 mm.
#: Ends: plain-and-ground (N_t = N_a + 1 = 4, L_s = d N_t = 17.6 mm) leaves 25.4 mm of travel,
#: i.e. the 22 mm press with a fractional overrun of 0.155 >= 0.15 (Shigley sec. 10-7), and
#: L_s + 1.15 * 22 mm = 42.9 mm is the stated free length: the source design evidently used
#: L_s = d (N_a + 1). Squared-and-ground ends (L_s = (N_a + 2) d = 22.0 mm) would leave only
#: 21.0 mm: the 22 mm press would close the spring solid.
#: Caveat: C = D/d = 21.3 lies outside Shigley's recommended 4 <= C <= 12 (a flat,
#: "pancake" spring; L0/D = 0.46, so buckling is no concern).
CONSISTENT_THESIS_SPRING = SpringDesign(
    wire_diameter_m=THESIS_WIRE_DIAMETER_M,
    mean_coil_diameter_m=mean_coil_diameter_for_rate_m(
        THESIS_SPRING_RATE_N_PER_M, MUSIC_WIRE_SHEAR_MODULUS_PA, THESIS_WIRE_DIAMETER_M,
        THESIS_ACTIVE_COILS),
    active_coils=THESIS_ACTIVE_COILS, free_length_m=THESIS_FREE_LENGTH_M,
    end_type="plain_ground")


# --- 3. Designer checks: index, curvature factors, stress, strength ---------------------------

def spring_index(mean_coil_diameter_m: float, wire_diameter_m: float) -> float:
    """Spring index C = D / d [-]."""
    D = require_positive("mean_coil_diameter_m", mean_coil_diameter_m, "m")
    d = require_positive("wire_diameter_m", wire_diameter_m, "m")
    return D / d


def _require_index_above_one(spring_index_: float) -> float:
    c = require_positive("spring_index", spring_index_, "-")
    if not c > 1.0:
        raise SceneError(f"spring spring_index = {spring_index_!r}: must be > 1 (D > d)")
    return c


def wahl_factor(spring_index_: float) -> float:
    """Wahl stress-correction factor ``K_W = (4C - 1)/(4C - 4) + 0.615/C`` (Shigley eq. 10-4),
    for spring index C > 1. K_W(10) = 1.1448."""
    c = _require_index_above_one(spring_index_)
    return (4.0 * c - 1.0) / (4.0 * c - 4.0) + 0.615 / c


def bergstrasser_factor(spring_index_: float) -> float:
    """Bergstrasser stress-correction factor ``K_B = (4C + 2)/(4C - 3)`` (Shigley eq. 10-5),
    for spring index C > 1. K_B(10) = 42/37 = 1.1351."""
    c = _require_index_above_one(spring_index_)
    return (4.0 * c + 2.0) / (4.0 * c - 3.0)


def direct_shear_factor(spring_index_: float) -> float:
    """Direct-shear factor ``K_s = (2C + 1)/(2C)`` (Shigley eq. 10-2): torsion + direct shear
    without curvature, for spring index C > 1."""
    c = _require_index_above_one(spring_index_)
    return (2.0 * c + 1.0) / (2.0 * c)


def nominal_torsional_shear_stress_Pa(force_N: float, mean_coil_diameter_m: float,
                                      wire_diameter_m: float) -> float:
    """Torsion-only shear stress at the wire surface, ``8 F D / (pi d^3)`` [Pa]."""
    f = require_positive("force_N", force_N, "N")
    D = require_positive("mean_coil_diameter_m", mean_coil_diameter_m, "m")
    d = require_positive("wire_diameter_m", wire_diameter_m, "m")
    return 8.0 * f * D / (math.pi * d**3)


def a228_minimum_tensile_strength_Pa(wire_diameter_m: float) -> float:
    """Minimum tensile strength of ASTM A228 music wire, ``S_ut = A / d^m`` [Pa] with d in mm,
    A = 2211 MPa mm^m, m = 0.145 (Shigley table 10-4), for d = 0.10 ... 6.5 mm."""
    d = require_positive("wire_diameter_m", wire_diameter_m, "m")
    low, high = A228_WIRE_DIAMETER_RANGE_M
    if not low <= d <= high:
        raise SceneError(f"spring wire_diameter_m = {wire_diameter_m!r}: the A228 strength fit "
                         f"holds for {low:g} ... {high:g} m (Shigley table 10-4)")
    d_mm = d * 1e3
    return A228_TENSILE_STRENGTH_INTERCEPT_MPA_MM_M / d_mm**A228_TENSILE_STRENGTH_EXPONENT * 1e6


def music_wire_allowable_torsional_stress_Pa(wire_diameter_m: float,
                                             set_removed: bool = False) -> float:
    """Allowable static torsional stress of A228 music wire [Pa] (Shigley table 10-6):
    0.45 S_ut before set is removed (default), 0.60 S_ut after set removal."""
    fraction = (MUSIC_WIRE_ALLOWABLE_TORSION_FRACTION_SET_REMOVED if set_removed
                else MUSIC_WIRE_ALLOWABLE_TORSION_FRACTION_SET_NOT_REMOVED)
    return fraction * a228_minimum_tensile_strength_Pa(wire_diameter_m)


@dataclass(frozen=True)
class SpringStressCheck:
    """Static stress check of a spring at one deflection (SI units; factors dimensionless)."""

    deflection_m: float
    force_N: float
    spring_index: float
    wahl_factor: float
    bergstrasser_factor: float
    nominal_shear_stress_Pa: float
    wahl_shear_stress_Pa: float
    bergstrasser_shear_stress_Pa: float
    tensile_strength_Pa: float
    allowable_shear_stress_Pa: float

    @property
    def safety_factor(self) -> float:
        """Allowable stress over the Wahl-corrected stress [-]."""
        return self.allowable_shear_stress_Pa / self.wahl_shear_stress_Pa


def spring_stress_check(design: SpringDesign, deflection_m: float,
                        set_removed: bool = False) -> SpringStressCheck:
    """Shear stress of ``design`` compressed by ``deflection_m`` [m] (force F = k y) against
    the A228 allowable (:func:`music_wire_allowable_torsional_stress_Pa`)."""
    y = require_positive("deflection_m", deflection_m, "m")
    force = design.rate_N_per_m * y
    c = design.spring_index
    nominal = nominal_torsional_shear_stress_Pa(force, design.mean_coil_diameter_m,
                                                design.wire_diameter_m)
    return SpringStressCheck(
        deflection_m=y, force_N=force, spring_index=c,
        wahl_factor=wahl_factor(c), bergstrasser_factor=bergstrasser_factor(c),
        nominal_shear_stress_Pa=nominal,
        wahl_shear_stress_Pa=wahl_factor(c) * nominal,
        bergstrasser_shear_stress_Pa=bergstrasser_factor(c) * nominal,
        tensile_strength_Pa=a228_minimum_tensile_strength_Pa(design.wire_diameter_m),
        allowable_shear_stress_Pa=music_wire_allowable_torsional_stress_Pa(
            design.wire_diameter_m, set_removed))


# --- 4. Surge (longitudinal) frequencies and the thesis's criterion --------------------------

def active_coil_mass_kg(density_kg_per_m3: float, wire_diameter_m: float,
                        mean_coil_diameter_m: float, active_coils: float) -> float:
    """Mass of the active coils, ``rho (pi d^2 / 4) (pi D N)`` [kg] (Shigley sec. 10-8)."""
    rho = require_positive("density_kg_per_m3", density_kg_per_m3, "kg/m^3")
    d = require_positive("wire_diameter_m", wire_diameter_m, "m")
    D = require_positive("mean_coil_diameter_m", mean_coil_diameter_m, "m")
    n = require_positive("active_coils", active_coils, "coils")
    return rho * math.pi * d**2 / 4.0 * math.pi * D * n


def surge_frequency_fixed_fixed_Hz(rate_N_per_m: float, active_mass_kg: float) -> float:
    """First surge frequency, both ends fixed: ``f = (1/2) sqrt(k / m)`` [Hz] (Shigley
    sec. 10-8). Equivalent to a bar with wave speed c: f = c / (2 L), k = EA/L, m = rho A L."""
    k = require_positive("rate_N_per_m", rate_N_per_m, "N/m")
    m = require_positive("active_mass_kg", active_mass_kg, "kg")
    return 0.5 * math.sqrt(k / m)


def surge_frequency_fixed_free_Hz(rate_N_per_m: float, active_mass_kg: float) -> float:
    """First surge frequency, one end fixed and one free: ``f = (1/4) sqrt(k / m)`` [Hz]
    (Shigley sec. 10-8)."""
    k = require_positive("rate_N_per_m", rate_N_per_m, "N/m")
    m = require_positive("active_mass_kg", active_mass_kg, "kg")
    return 0.25 * math.sqrt(k / m)


def surge_frequency_fixed_end_mass_Hz(rate_N_per_m: float, active_mass_kg: float,
                                      end_mass_kg: float) -> float:
    """First frequency [Hz] of a spring (rate k, distributed mass m) fixed at one end and
    carrying a point mass M at the other: ``beta tan(beta) = m / M``
    (:func:`flex.base.spring_waves.spring_end_mass_wave_numbers`), ``omega = beta sqrt(k / m)``
    (a bar with a tip mass). M -> 0 gives the fixed-free value."""
    k = require_positive("rate_N_per_m", rate_N_per_m, "N/m")
    m = require_positive("active_mass_kg", active_mass_kg, "kg")
    big_m = require_positive("end_mass_kg", end_mass_kg, "kg")
    beta = float(spring_end_mass_wave_numbers(m / big_m, 1)[0])
    return beta * math.sqrt(k / m) / (2.0 * math.pi)


def rigid_or_flexible_ratio(event_duration_s: float, frequency_Hz: float,
                            period_convention: Literal["physical", "thesis"]) -> float:
    """The thesis's ratio n = delta_t / T (Eq. 64-65) for an event of ``event_duration_s``.

    ``physical``: T = 1/f [s]. ``thesis``: T = 1/omega = 1/(2 pi f), the thesis's own
    (2 pi too small) period, which makes n 2 pi times larger. The thesis calls a body rigid if
    n > 108 (:data:`THESIS_RIGID_CRITERION_RATIO`).
    """
    dt = require_positive("event_duration_s", event_duration_s, "s")
    f = require_positive("frequency_Hz", frequency_Hz, "Hz")
    if period_convention in ("physical", "thesis"):
        return n_values(dt, TWO_PI * f)[period_convention]
    raise SceneError(f"spring period_convention = {period_convention!r}: must be "
                     "'physical' (T = 1/f) or 'thesis' (T = 1/omega)")


@dataclass(frozen=True)
class SurgeCheck:
    """Surge frequencies [Hz] of a design and the thesis's ratio n for one event [s]."""

    event_duration_s: float
    active_mass_kg: float
    fixed_fixed_Hz: float
    fixed_free_Hz: float
    n_fixed_fixed_physical: float
    n_fixed_fixed_thesis: float
    n_fixed_free_physical: float
    n_fixed_free_thesis: float

    @property
    def flexible_by_thesis_criterion(self) -> bool:
        """True if even the largest n (fixed-fixed, thesis convention) is below 108."""
        return self.n_fixed_fixed_thesis < THESIS_RIGID_CRITERION_RATIO


def surge_check(design: SpringDesign,
                event_duration_s: float = THESIS_DEPLOYMENT_TIME_S) -> SurgeCheck:
    """Surge frequencies of ``design`` and n = delta_t / T in both period conventions.

    n of order 1 means the release lasts about one surge period: the spring's own
    longitudinal waves are excited and a massless-spring model misses them.
    """
    mass = design.active_mass_kg
    rate = design.rate_N_per_m
    f_ff = surge_frequency_fixed_fixed_Hz(rate, mass)
    f_f0 = surge_frequency_fixed_free_Hz(rate, mass)
    return SurgeCheck(
        event_duration_s=event_duration_s, active_mass_kg=mass,
        fixed_fixed_Hz=f_ff, fixed_free_Hz=f_f0,
        n_fixed_fixed_physical=rigid_or_flexible_ratio(event_duration_s, f_ff, "physical"),
        n_fixed_fixed_thesis=rigid_or_flexible_ratio(event_duration_s, f_ff, "thesis"),
        n_fixed_free_physical=rigid_or_flexible_ratio(event_duration_s, f_f0, "physical"),
        n_fixed_free_thesis=rigid_or_flexible_ratio(event_duration_s, f_f0, "thesis"))
