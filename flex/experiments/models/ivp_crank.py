"""The flexible slider-crank of the IVP test set ("crank"), re-implemented independently.

Source of the benchmark: F. Mazzia, C. Magherini et al., *Test Set for IVP Solvers*,
University of Bari (https://archimede.uniba.it/~testset/), problem "crank" (file
``crank.f``, B. Simeon 1995/1998, model of B. Simeon, "Modelling a flexible slider crank
mechanism by a mixed system of DAEs and PDEs", Math. Modelling of Systems 2, 1-18, 1996).
Crank A-B (length L1 = 0.15 m) turned at Omega = 150 rad/s (``phi1 = Omega t``), steel
connecting rod B-C (L2 = 0.3 m, 8 x 8 mm, E = 200 GPa, rho = 7870 kg/m^3), slider C of
0.075552 kg on the line through A; no gravity, undamped, linear stiffness in the default
variant. The rod is a floating frame at B along the chord B-C with, in that frame,

- lateral deflection ``v = sum_k q_k sin(k pi xi)`` (the test set: k = 1, 2), zero at both
  ends: ``v(L2/2) = q_1`` is the midpoint deflection from the chord;
- axial displacement ``u = q_a 4 xi (1 - xi) + q_e xi (2 xi - 1)`` (one quadratic element;
  ``q_e`` is the end's displacement, so the chord is ``L2 + q_e``), ``xi = x / L2``.

This module does not port the published residual: the rod's matrices are integrals of
these shape functions (Gauss-Legendre, :func:`rod_matrices`), the mass matrix is the
rod's kinetic energy in the floating frame, and the velocity-dependent forces follow from
it by Lagrange's equations (:func:`quadratic_velocity_force`); the crank angle and the
chord closure are Lagrange-multiplier constraints, integrated as an index-1 DAE with
scipy's ``solve_ivp`` (Baumgarte terms keep the drift at round-off). Any number of lateral
modes can be kept. The published model has two deliberate choices and one inconsistency,
each a switch here:

- ``axial_mass_factor``: the published axial mass block is ``rho A L2 [[8, 1], [1, 2]]``;
  the shape functions above give ``rho A L2 [[8, 1], [1, 2]] / 15`` (their stiffness,
  ``EA/L2 [[16/3, -8/3], [-8/3, 7/3]]``, and their first moments in the coupling terms
  are the consistent ones). 15 reproduces the published numbers, 1 is the physics;
- ``geometric_stiffening``: the nonlinear strain ``u' + v'^2 / 2`` of the rod axis.
  ``"published"``: only its cross term ``EA/2 int u' v'^2`` (the test set's ``IPAR(1) = 1``,
  off in its reference solution), which stiffens bending with the axial force but, without
  the quartic term ``EA/8 int v'^4``, also softens it by the foreshortening ``v'^2 / 2`` that
  the axial coordinate takes up; ``"consistent"``: both terms (the full strain energy of
  the axis, ``EA/2 int (u' + v'^2 / 2)^2``); ``"none"``: linear, as the reference run.
  With the published single quadratic axial element the consistent energy locks: ``v'^2``
  of a sine holds ``cos(2 pi xi)``, which a linear ``u'`` cannot take up, so an inextensible
  bend stores membrane energy (spurious hardening). ``axial_bubbles`` adds axial shape
  functions ``sin(j pi xi)`` (zero at both ends; j up to twice the lateral modes absorbs
  every term of ``v'^2``);
- ``pi_as_published``: the test set's truncated ``PI = 3.1415927`` in the stiffness.

Three more ``geometric_stiffening`` variants explain flex's FFRF rod (its frame is the B
face, tangent to the rod at B; :func:`tangent_frame_membrane_force`): ``"lateral_only"``, the
consistent cross term's force on the lateral coordinates only (a geometric stiffness of the
axial force, no foreshortening pull on the axial coordinates); ``"tangent_frame"``, the
strain linear in the tangent frame; ``"tangent_frame_geometric"``, that plus the geometric
stiffness in that frame (flex's ``coupler.geometric_stiffness``).

Units: SI throughout (m, kg, s, rad, N).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

#: geometric stiffening variants (module doc)
STIFFENING = ("none", "published", "consistent", "lateral_only", "tangent_frame",
              "tangent_frame_geometric")
#: the test set's truncated pi (crank.f, ``PI = 3.1415927D0``)
PUBLISHED_PI = 3.1415927


@dataclass(frozen=True)
class CrankBenchmark:
    """Parameters of the test set's flexible slider-crank (crank.f data set), SI units."""

    crank_length_m: float = 0.15
    rod_length_m: float = 0.30
    rod_width_m: float = 0.008     # BB, out of plane
    rod_height_m: float = 0.008    # HH, bending height in the mechanism plane
    youngs_modulus_Pa: float = 0.20e12
    poisson_ratio: float = 0.30    # NUE: declared, unused by the beam model
    density_kg_per_m3: float = 7870.0
    crank_mass_kg: float = 0.36    # M1: irrelevant at prescribed crank speed
    crank_inertia_about_A_kgm2: float = 0.002727  # J1: irrelevant at prescribed speed
    rod_mass_kg: float = 0.151104  # M2 = rho b h L2
    #: J2, about B: M2 (L2^2 / 3 + h^2 / 12) (the section's own rotary inertia included)
    rod_inertia_about_B_kgm2: float = 0.0045339259
    slider_mass_kg: float = 0.075552
    crank_speed_rad_per_s: float = 150.0

    @property
    def area_m2(self) -> float:
        return self.rod_width_m * self.rod_height_m


#: the published initial state "close to smooth motion" (crank.f INIT; the test set's
#: reference run starts here): phi1, phi2 [rad], x3 [m], q1..q4 [m]; then their rates
PUBLISHED_INITIAL = np.array([
    0.0, 0.0, 0.450016933, 0.0, 0.0, 0.103339863e-04, 0.169327969e-04,
    150.0, -74.9957670, -0.268938672e-05, 0.444896105, 0.463434311e-02, -0.178591076e-05,
    -0.268938672e-05])
#: the published reference solution at t = 0.1 s (crank.f SOLN, components 1-14: phi1,
#: phi2 [rad], x3 [m], q1, q2, q3, q4 [m], then their rates), linear stiffness, no damping
PUBLISHED_AT_0P1S = np.array([
    1.500000000000000e+01, -3.311734987910881e-01, 1.697373326718410e-01,
    1.893192460247178e-04, 2.375751865617931e-05, -5.323907988763734e-06,
    -8.363283141616840e-06, 1.500000000000000e+02, 6.025346682645789e+01,
    -8.753116989887888e+00, -3.005536801092212e-02, -5.500488291932075e-03,
    4.978243404809343e-04, 1.104933470696396e-03])
PUBLISHED_TIME_S = 0.1


@dataclass(frozen=True)
class RodMatrices:
    """The rod's matrices in its floating frame, coordinates ``q = (q_1..q_n lateral, axial
    bubbles if any, q_a axial mid, q_e axial end)`` [m]: mass [kg], stiffness [N/m], the
    first moments ``c1 = A int u-shapes``, ``c2 = A int v-shapes``, ``c12 = A int x u-shapes``,
    ``c21 = A int x v-shapes`` [m^2, m^3] (times rho: kg), the gyroscopic coupling ``B = A
    int (u_i v_j - v_i u_j)`` [m^3], ``stiffening[i, j, k]`` [N/m^2]: the generalized force
    of the cross strain term is ``-stiffening @ q @ q``, and ``quartic[i, j, k, l]``
    [N/m^3], over the lateral coordinates only: that of the quartic term is ``-quartic @ v @
    v @ v`` (``v = q[:lateral modes]``)."""

    mass: np.ndarray
    stiffness: np.ndarray
    c1: np.ndarray
    c2: np.ndarray
    c12: np.ndarray
    c21: np.ndarray
    gyroscopic: np.ndarray
    stiffening: np.ndarray
    quartic: np.ndarray
    axial_slope: np.ndarray
    lateral_slope: np.ndarray
    lateral_slope_at_B: np.ndarray
    quadrature_weight_m: np.ndarray


def rod_matrices(bench: CrankBenchmark, lateral_modes: int = 2, axial_mass_factor: float = 1.0,
                 pi_value: float = math.pi, points: int = 40, axial_bubbles: int = 0
                 ) -> RodMatrices:
    """The rod's matrices (:class:`RodMatrices`) by Gauss-Legendre quadrature of the shape
    functions (module doc) with ``points`` points; ``axial_mass_factor`` multiplies the
    axial mass block (15: as published); ``pi_value`` is used in the lateral stiffness
    only (the published code's truncated pi enters there)."""
    length, area = bench.rod_length_m, bench.area_m2
    nodes, weights = np.polynomial.legendre.leggauss(points)
    xi, w = (nodes + 1.0) / 2.0, weights / 2.0
    k = np.arange(1, lateral_modes + 1)[:, None]
    n = lateral_modes + axial_bubbles + 2
    shape_u, shape_v = np.zeros((n, xi.size)), np.zeros((n, xi.size))
    slope_u, slope_v = np.zeros((n, xi.size)), np.zeros((n, xi.size))  # d/dxi
    shape_v[:lateral_modes] = np.sin(k * np.pi * xi)
    slope_v[:lateral_modes] = k * np.pi * np.cos(k * np.pi * xi)
    curvature = -(k * pi_value) ** 2 * np.sin(k * np.pi * xi)  # d2/dxi2
    j = np.arange(1, axial_bubbles + 1)[:, None]
    shape_u[lateral_modes:-2] = np.sin(j * np.pi * xi)
    slope_u[lateral_modes:-2] = j * np.pi * np.cos(j * np.pi * xi)
    shape_u[-2], shape_u[-1] = 4 * xi * (1 - xi), xi * (2 * xi - 1)
    slope_u[-2], slope_u[-1] = 4 - 8 * xi, 4 * xi - 1

    def integral(*factors: np.ndarray) -> np.ndarray:
        return np.einsum("...q,q->...", np.prod(np.broadcast_arrays(*factors), axis=0), w)

    mass = bench.density_kg_per_m3 * area * length * (
        np.einsum("iq,jq,q->ij", shape_u, shape_u, w) + np.einsum("iq,jq,q->ij", shape_v,
                                                                  shape_v, w))
    mass[-2:, -2:] *= axial_mass_factor
    second_moment = bench.rod_width_m * bench.rod_height_m**3 / 12.0
    stiffness = np.zeros((n, n))
    stiffness[:lateral_modes, :lateral_modes] = (
        bench.youngs_modulus_Pa * second_moment / length**3
        * np.einsum("iq,jq,q->ij", curvature, curvature, w))
    axial = slice(lateral_modes, n)
    stiffness[axial, axial] = (bench.youngs_modulus_Pa * area / length
                               * np.einsum("iq,jq,q->ij", slope_u[axial], slope_u[axial], w))
    # strain energy EA/2 int u' v'^2 dx = EA / (2 L^2) int u_xi v_xi^2 dxi: its gradient
    # is stiffening @ q @ q with stiffening symmetric in its last two indices
    half = bench.youngs_modulus_Pa * area / (2 * length**2)
    stiffening = half * (np.einsum("iq,jq,kq,q->ijk", slope_u, slope_v, slope_v, w)
                         + 2 * np.einsum("iq,jq,kq,q->ijk", slope_v, slope_u, slope_v, w))
    stiffening = (stiffening + stiffening.transpose(0, 2, 1)) / 2
    # EA/8 int v'^4 dx = EA / (8 L^3) int v_xi^4 dxi: gradient quartic @ q @ q @ q
    lateral = slope_v[:lateral_modes]
    quartic = bench.youngs_modulus_Pa * area / (2 * length**3) * np.einsum(
        "iq,jq,kq,lq,q->ijkl", lateral, lateral, lateral, lateral, w)
    gyroscopic = area * length * (np.einsum("iq,jq,q->ij", shape_u, shape_v, w)
                                  - np.einsum("iq,jq,q->ij", shape_v, shape_u, w))
    return RodMatrices(mass, stiffness, area * length * integral(shape_u),
                       area * length * integral(shape_v),
                       area * length**2 * integral(shape_u, xi),
                       area * length**2 * integral(shape_v, xi), gyroscopic, stiffening,
                       quartic, slope_u / length, slope_v / length,
                       np.concatenate([np.pi * k[:, 0], np.zeros(n - lateral_modes)]) / length,
                       w * length)


class TwoModeCrank:
    """The benchmark's equations of motion, coordinates ``p = (phi1, phi2, x3, q)``
    [rad, rad, m, m...]; ``rates`` are their time derivatives."""

    def __init__(self, bench: CrankBenchmark, rod: RodMatrices,
                 geometric_stiffening: str = "none", baumgarte_rad_per_s: float = 1e3) -> None:
        if geometric_stiffening not in STIFFENING:
            raise ValueError(f"geometric_stiffening = {geometric_stiffening!r}: one of "
                             f"{', '.join(STIFFENING)}")
        self.bench, self.rod = bench, rod
        self.stiffening = geometric_stiffening
        self.baumgarte = baumgarte_rad_per_s
        self.nq = rod.mass.shape[0]
        self.n = 3 + self.nq
        # the strictly lower triangle, filled from the upper one (made once: the right-hand
        # side runs ~10^5-10^6 times per run)
        self._lower = np.tril_indices(self.n, -1)

    def mass_matrix(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The mass matrix M(p) [kg, kg m, kg m^2] and its derivatives dM/dp_k, (n, n, n)."""
        b, rod, rho = self.bench, self.rod, self.bench.density_kg_per_m3
        q, l1 = p[3:], b.crank_length_m
        s12, c12_ = math.sin(p[0] - p[1]), math.cos(p[0] - p[1])
        m = np.zeros((self.n, self.n))
        dm = np.zeros((self.n, self.n, self.n))
        m[0, 0] = b.crank_inertia_about_A_kgm2 + b.rod_mass_kg * l1**2
        m[2, 2] = b.slider_mass_kg
        m[0, 1] = (0.5 * l1 * b.rod_length_m * b.rod_mass_kg * c12_
                   + rho * l1 * (s12 * rod.c2 @ q + c12_ * rod.c1 @ q))
        d01 = (-0.5 * l1 * b.rod_length_m * b.rod_mass_kg * s12
               + rho * l1 * (c12_ * rod.c2 @ q - s12 * rod.c1 @ q))  # d/d(phi1 - phi2)
        m[1, 1] = b.rod_inertia_about_B_kgm2 + q @ rod.mass @ q + 2 * rho * rod.c12 @ q
        m[0, 3:] = rho * l1 * (-s12 * rod.c1 + c12_ * rod.c2)
        d0q = rho * l1 * (-c12_ * rod.c1 - s12 * rod.c2)
        m[1, 3:] = rho * rod.c21 + rho * rod.gyroscopic.T @ q
        m[3:, 3:] = rod.mass
        for k, sign in ((0, 1.0), (1, -1.0)):
            dm[k, 0, 1] = sign * d01
            dm[k, 0, 3:] = sign * d0q
        dm[3:, 0, 1] = rho * l1 * (s12 * rod.c2 + c12_ * rod.c1)
        dm[3:, 1, 1] = 2 * rod.mass @ q + 2 * rho * rod.c12
        dm[3:, 1, 3:] = rho * rod.gyroscopic
        rows, columns = self._lower
        m[rows, columns] = m[columns, rows]
        dm[:, rows, columns] = dm[:, columns, rows]
        return m, dm

    def constraints(self, t: float, p: np.ndarray, rates: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Position residuals g [m, m, rad], their Jacobian G, velocity residuals G p',
        and gamma = (d/dt G) p' (so that G p'' + gamma = 0): rod end at the slider, crank
        angle Omega t."""
        b = self.bench
        l1, chord = b.crank_length_m, b.rod_length_m + p[-1]
        s1, c1, s2, c2 = math.sin(p[0]), math.cos(p[0]), math.sin(p[1]), math.cos(p[1])
        w1, w2, qe = rates[0], rates[1], rates[-1]
        g = np.array([l1 * s1 + chord * s2, p[2] - l1 * c1 - chord * c2,
                      p[0] - b.crank_speed_rad_per_s * t])
        jac = np.zeros((3, self.n))
        jac[0, [0, 1, -1]] = l1 * c1, chord * c2, s2
        jac[1, [0, 1, 2, -1]] = l1 * s1, chord * s2, 1.0, -c2
        jac[2, 0] = 1.0
        velocity = jac @ rates - np.array([0.0, 0.0, b.crank_speed_rad_per_s])
        gamma = np.array([-l1 * s1 * w1**2 + 2 * qe * w2 * c2 - chord * s2 * w2**2,
                          l1 * c1 * w1**2 + 2 * qe * w2 * s2 + chord * c2 * w2**2, 0.0])
        return g, jac, velocity, gamma

    def accelerations(self, t: float, p: np.ndarray, rates: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
        """Accelerations p'' and the multipliers [N m, N, N...] of the index-1 system."""
        m, dm = self.mass_matrix(p)
        force = quadratic_velocity_force(dm, rates)
        q = p[3:]
        force[3:] -= self.rod.stiffness @ q
        if self.stiffening in ("published", "consistent"):
            force[3:] -= self.rod.stiffening @ q @ q
        if self.stiffening == "consistent":
            lateral = q[:self.rod.quartic.shape[0]]
            force[3:3 + lateral.size] -= self.rod.quartic @ lateral @ lateral @ lateral
        if self.stiffening == "lateral_only":
            lateral_modes = self.rod.quartic.shape[0]
            force[3:3 + lateral_modes] -= (self.rod.stiffening @ q @ q)[:lateral_modes]
        if self.stiffening.startswith("tangent_frame"):
            force[3:] -= tangent_frame_membrane_force(
                self.bench, self.rod, q, self.stiffening == "tangent_frame_geometric")
        g, jac, velocity, gamma = self.constraints(t, p, rates)
        a = self.baumgarte
        system = np.zeros((self.n + 3, self.n + 3))
        system[:self.n, :self.n], system[:self.n, self.n:], system[self.n:, :self.n] = (
            m, jac.T, jac)
        rhs = np.concatenate([force, -gamma - 2 * a * velocity - a**2 * g])
        solution = np.linalg.solve(system, rhs)
        return solution[:self.n], solution[self.n:]

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """First-order right-hand side of the state ``(p, p')``."""
        p, rates = y[:self.n], y[self.n:]
        return np.concatenate([rates, self.accelerations(t, p, rates)[0]])


def tangent_frame_membrane_force(bench: CrankBenchmark, rod: RodMatrices, q: np.ndarray,
                                 frame_geometric: bool = False) -> np.ndarray:
    """The membrane force [N per m of coordinate] of a rod that is linear elastic in a frame
    tangent to it at B (flex's FFRF coupler: frame on the B face), beyond the linear axial
    stiffness already in ``rod.stiffness``.

    In that frame the linear strain of the axis is the chord-frame ``e = u' + theta v' -
    theta^2 / 2`` with ``theta = v'(0)`` (the frame's turn against the chord), instead of the
    true ``u' + v'^2 / 2``: the gradient of ``EA/2 int e^2 dx`` minus its linear part ``EA
    int u' du'``. Exact to second order in the deflection for the axial force's work; the
    turn's axial shift ``-theta v(x)`` needs axial bubbles to be represented
    (:func:`rod_matrices`). ``frame_geometric``: add the geometric stiffness of the axial
    force ``N = EA e`` on the deflection measured in that frame, ``w' = v' - theta``
    (``int N w' dw'``, N held: no pull on the axial coordinates), as flex's
    ``coupler.geometric_stiffness`` adds it to the FFRF rod."""
    axial, lateral = rod.axial_slope.T @ q, rod.lateral_slope.T @ q
    theta = rod.lateral_slope_at_B @ q
    strain = axial + theta * lateral - theta**2 / 2
    d_strain = (rod.axial_slope + theta * rod.lateral_slope
                + np.outer(rod.lateral_slope_at_B, lateral - theta))
    stretch = bench.youngs_modulus_Pa * bench.area_m2
    force = stretch * (d_strain @ (rod.quadrature_weight_m * strain)
                       - rod.axial_slope @ (rod.quadrature_weight_m * axial))
    if frame_geometric:
        d_slope = rod.lateral_slope - rod.lateral_slope_at_B[:, None]
        force += stretch * d_slope @ (rod.quadrature_weight_m * strain * (lateral - theta))
    return force


def quadratic_velocity_force(dm: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """Lagrange's velocity terms of ``T = p'^T M(p) p' / 2``: ``-(dM/dt) p' + dT/dp``
    (generalized force, N or N m), from ``dm[k] = dM/dp_k``."""
    m_dot = np.einsum("kij,k->ij", dm, rates)
    return -m_dot @ rates + 0.5 * np.einsum("i,kij,j->k", rates, dm, rates)


def rigid_initial_state(bench: CrankBenchmark, lateral_modes: int, axial_bubbles: int = 0
                        ) -> np.ndarray:
    """The state at t = 0 on the rigid motion (the test set's second initial value, INIT2):
    crank and rod along +x, undeformed and at rest in the rod frame."""
    n = 3 + lateral_modes + axial_bubbles + 2
    y = np.zeros(2 * n)
    y[2] = bench.crank_length_m + bench.rod_length_m
    y[n] = bench.crank_speed_rad_per_s
    y[n + 1] = -bench.crank_speed_rad_per_s * bench.crank_length_m / bench.rod_length_m
    return y


def published_initial_state(lateral_modes: int, axial_bubbles: int = 0) -> np.ndarray:
    """The published initial state (:data:`PUBLISHED_INITIAL`) in a model with
    ``lateral_modes`` lateral modes (the higher ones start at rest, undeformed)."""
    n = 3 + lateral_modes + axial_bubbles + 2
    y = np.zeros(2 * n)
    for offset, source in ((0, PUBLISHED_INITIAL[:7]), (n, PUBLISHED_INITIAL[7:])):
        y[offset:offset + 3] = source[:3]
        y[offset + 3:offset + 3 + min(2, lateral_modes)] = source[3:3 + min(2, lateral_modes)]
        y[offset + n - 2:offset + n] = source[5:7]
    return y


@dataclass(frozen=True)
class CrankSolution:
    """A run of :class:`TwoModeCrank`: ``time_s`` (m,), ``state`` (m, 2n) as ``(p, p')``,
    the largest constraint residual [m], the solver's function evaluations and the wall
    time [s]."""

    time_s: np.ndarray
    state: np.ndarray
    lateral_modes: int
    constraint_residual_m: float
    evaluations: int
    wall_time_s: float

    @property
    def slider_position_m(self) -> np.ndarray:
        return self.state[:, 2]

    @property
    def midpoint_deflection_m(self) -> np.ndarray:
        """Lateral deflection of the rod's midpoint from the chord B-C, ``v(L2/2)``."""
        k = np.arange(1, self.lateral_modes + 1)
        return self.state[:, 3:3 + self.lateral_modes] @ np.sin(k * np.pi / 2)

    @property
    def chord_change_m(self) -> np.ndarray:
        """Change of the distance B-C, the axial end coordinate ``q_e``."""
        return self.state[:, self.state.shape[1] // 2 - 1]


def solve(bench: CrankBenchmark = CrankBenchmark(), lateral_modes: int = 2,
          axial_mass_factor: float = 1.0, geometric_stiffening: str = "none",
          initial: str = "published", end_time_s: float = PUBLISHED_TIME_S,
          output_step_s: float = 1e-4, rtol: float = 1e-10, atol: float = 1e-13,
          pi_value: float = math.pi, axial_bubbles: int = 0, method: str = "DOP853"
          ) -> CrankSolution:
    """Integrate the benchmark (scipy ``DOP853``) from ``initial`` = ``"published"`` (the
    test set's INIT) or ``"rigid"`` (INIT2, undeformed on the rigid motion) to
    ``end_time_s`` [s], sampled every ``output_step_s`` [s]; ``axial_bubbles``: axial
    shape functions ``sin(j pi xi)``, j = 1..``axial_bubbles``, added to the published
    quadratic element (module doc)."""
    rod = rod_matrices(bench, lateral_modes, axial_mass_factor, pi_value,
                       axial_bubbles=axial_bubbles)
    model = TwoModeCrank(bench, rod, geometric_stiffening)
    y0 = (published_initial_state(lateral_modes, axial_bubbles) if initial == "published"
          else rigid_initial_state(bench, lateral_modes, axial_bubbles))
    start = time.perf_counter()
    samples = int(round(end_time_s / output_step_s))
    times = np.linspace(0.0, end_time_s, samples + 1)
    out = solve_ivp(model.rhs, (0.0, end_time_s), y0, method=method, t_eval=times,
                    rtol=rtol, atol=atol)
    if not out.success:
        raise RuntimeError(f"IVP crank: {out.message}")
    state = out.y.T
    residual = max(float(np.max(np.abs(model.constraints(t, y[:model.n], y[model.n:])[0][:2])))
                   for t, y in zip(times, state, strict=True))
    return CrankSolution(times, state, lateral_modes, residual, int(out.nfev),
                         time.perf_counter() - start)
