"""Independent reference: the thesis's own method (sec. 4.2 and 5.3, Eq. 43).

Nine generalized coordinates ``q = [x1, y1, th1, x2, y2, th2, x3, y3, th3]`` (positions of
the centres of mass and angles of crank, coupler and slider), eight holonomic constraints
(revolute joints A, B, C and the prismatic joint, Eq. 16-23; a ninth driving constraint for a
constant-speed crank), and the Lagrange-multiplier system

    [M  Psi_q^T] [qdd   ]   [F_e  ]
    [Psi_q    0] [lambda] = [gamma]

solved for the accelerations at every evaluation and integrated with scipy's ``solve_ivp``
(DOP853). Reaction forces come from the multipliers: the generalized reaction on the bodies
is ``-Psi_q^T lambda``.

The constraint equations are derived here afresh rather than copied: the thesis's Eq. 25
(row 5, d/dq6 printed as -L2/2 cos q6 instead of -L2/2 sin q6) and Eq. 9-10 (sign of the
coupler angle) carry typos; see the README. This module shares no code with the Exudyn model
(:mod:`flex.dynamics.mechanism`) beyond the scene it reads, so the two check each other.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from flex.base.errors import SimulationError
from flex.base.kinematics import crank_pin, slider_crank
from flex.base.physics import cuboid_inertia_kgm2, cuboid_mass_kg
from flex.config.settings import resolved_simulation
from flex.data.plates import plate_mass_properties
from flex.data.scene import Scene


@dataclass
class ReferenceSolution:
    """Result of :func:`solve_reference`.

    ``time_s`` (n,), ``q`` (n, 9) [m, rad], ``q_dot`` (n, 9), ``q_ddot`` (n, 9),
    ``multipliers`` (n, m) [N or N m], ``constraint_norm_m`` (n,), ``status`` (solve_ivp
    message), ``function_evaluations``, ``wall_time_s``.
    """

    time_s: np.ndarray
    q: np.ndarray
    q_dot: np.ndarray
    q_ddot: np.ndarray
    multipliers: np.ndarray
    constraint_norm_m: np.ndarray
    status: str
    function_evaluations: int
    wall_time_s: float
    geometry: dict = field(default_factory=dict)

    def reaction_forces_N(self) -> dict[str, np.ndarray]:
        """Joint reaction forces (n, 2) [N] in global x, y, named like the result files."""
        lam = self.multipliers
        return {
            "A/force_on_crank": -lam[:, 0:2],
            "B/force_on_crank": -lam[:, 2:4],
            "B/force_on_coupler": lam[:, 2:4],
            "C/force_on_coupler": -lam[:, 4:6],
            "C/force_on_slider": lam[:, 4:6],
        }


def crank_mass_properties(scene: Scene) -> tuple[float, float, float]:
    """Mass [kg], inertia about the centre of mass [kg m^2] and distance of the centre of
    mass from A [m] of the crank, with the welded wing of ``[wing]`` if it is enabled.

    The wing is a plate in the mechanism plane from A along the crank (span), so both
    centres lie on the line A-B and the parallel-axis theorem combines them.
    """
    mass_kg, inertia_kgm2 = plate_mass_properties(scene, "crank")
    centre_m = scene["crank"]["length_m"] / 2
    wing = scene.get("wing", {})
    if not wing.get("enabled", False):
        return mass_kg, inertia_kgm2, centre_m
    wing_mass_kg = cuboid_mass_kg(wing["span_m"], wing["chord_m"], wing["thickness_m"],
                                  wing["density_kg_per_m3"])
    wing_inertia_kgm2 = cuboid_inertia_kgm2(wing_mass_kg, wing["span_m"], wing["chord_m"])
    total_kg = mass_kg + wing_mass_kg
    combined_m = (mass_kg * centre_m + wing_mass_kg * wing["span_m"] / 2) / total_kg
    inertia = (inertia_kgm2 + mass_kg * (centre_m - combined_m) ** 2 + wing_inertia_kgm2
               + wing_mass_kg * (wing["span_m"] / 2 - combined_m) ** 2)
    return total_kg, inertia, combined_m


class SliderCrankDAE:
    """Right-hand side of the 9-coordinate slider-crank DAE for one scene."""

    def __init__(self, scene: Scene):
        crank, slider, drive = scene["crank"], scene["slider"], scene["drive"]
        self.crank_length_m = crank["length_m"]
        self.coupler_length_m = scene["coupler"]["length_m"]
        self.offset_m = slider["offset_m"]
        coupler_mass_kg, coupler_inertia_kgm2 = plate_mass_properties(scene)
        crank_mass_kg, crank_inertia_kgm2, self.crank_centre_m = crank_mass_properties(scene)
        self.mass = np.diag([crank_mass_kg, crank_mass_kg, crank_inertia_kgm2,
                             coupler_mass_kg, coupler_mass_kg, coupler_inertia_kgm2,
                             slider["mass_kg"], slider["mass_kg"], slider["inertia_kgm2"]])
        self.constant_speed = drive["kind"] == "constant_speed"
        self.crank_speed_rad_per_s = drive["crank_speed_rad_per_s"] if self.constant_speed else 0.0
        self.stiffness_N_per_m = drive["spring_stiffness_N_per_m"] if not self.constant_speed else 0
        self.damping_Ns_per_m = drive["spring_damping_Ns_per_m"] if not self.constant_speed else 0
        self.preload_m = drive["spring_preload_m"]
        self.initial_crank_angle_rad = np.radians(crank["initial_angle_deg"])
        self.q0, self.q_dot0 = self.initial_state()
        self.n_constraints = 9 if self.constant_speed else 8

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Consistent positions and velocities at t = 0 (Eq. 54-63, with the crank speed)."""
        l1, l2 = self.crank_length_m, self.coupler_length_m
        th1, w1 = self.initial_crank_angle_rad, self.crank_speed_rad_per_s
        s = slider_crank(l1, l2, th1, w1, 0.0, self.offset_m)
        th2, w2 = float(s.coupler_angle_rad), float(s.coupler_angular_velocity_rad_per_s)
        b, vb = crank_pin(l1, th1, w1)
        c = np.array([float(s.slider_position_m), self.offset_m])
        vc = np.array([float(s.slider_velocity_m_per_s), 0.0])
        share = self.crank_centre_m / l1  # crank centre of mass on the line A-B
        q = np.array([b[0] * share, b[1] * share, th1, *(b + c) / 2, th2, *c, 0.0])
        q_dot = np.array([vb[0] * share, vb[1] * share, w1, *(vb + vc) / 2, w2, *vc, 0.0])
        return q, q_dot

    def constraints(self, t: float, q: np.ndarray) -> np.ndarray:
        """Constraint vector Psi(q, t) [m, rad]."""
        a1, h2 = self.crank_centre_m, self.coupler_length_m / 2
        b1 = self.crank_length_m - a1  # centre of mass to B
        x1, y1, th1, x2, y2, th2, x3, y3, th3 = q
        psi = [x1 - a1 * np.cos(th1), y1 - a1 * np.sin(th1),
               x1 + b1 * np.cos(th1) - (x2 - h2 * np.cos(th2)),
               y1 + b1 * np.sin(th1) - (y2 - h2 * np.sin(th2)),
               x2 + h2 * np.cos(th2) - x3, y2 + h2 * np.sin(th2) - y3,
               y3 - self.offset_m, th3]
        if self.constant_speed:
            psi.append(th1 - self.initial_crank_angle_rad - self.crank_speed_rad_per_s * t)
        return np.array(psi)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Constraint Jacobian Psi_q (m x 9)."""
        a1, h2 = self.crank_centre_m, self.coupler_length_m / 2
        b1 = self.crank_length_m - a1
        th1, th2 = q[2], q[5]
        s1, c1, s2, c2 = np.sin(th1), np.cos(th1), np.sin(th2), np.cos(th2)
        jac = np.zeros((self.n_constraints, 9))
        jac[0, [0, 2]] = [1, a1 * s1]
        jac[1, [1, 2]] = [1, -a1 * c1]
        jac[2, [0, 2, 3, 5]] = [1, -b1 * s1, -1, -h2 * s2]
        jac[3, [1, 2, 4, 5]] = [1, b1 * c1, -1, h2 * c2]
        jac[4, [3, 5, 6]] = [1, -h2 * s2, -1]
        jac[5, [4, 5, 7]] = [1, h2 * c2, -1]
        jac[6, 7] = 1
        jac[7, 8] = 1
        if self.constant_speed:
            jac[8, 2] = 1
        return jac

    def gamma(self, q: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
        """Right-hand side of the acceleration constraints, -(Psi_q q_dot)_q q_dot."""
        a1, h2 = self.crank_centre_m, self.coupler_length_m / 2
        b1 = self.crank_length_m - a1
        th1, th2, w1, w2 = q[2], q[5], q_dot[2], q_dot[5]
        c1, s1, c2, s2 = np.cos(th1), np.sin(th1), np.cos(th2), np.sin(th2)
        g = [-a1 * c1 * w1**2, -a1 * s1 * w1**2,
             b1 * c1 * w1**2 + h2 * c2 * w2**2, b1 * s1 * w1**2 + h2 * s2 * w2**2,
             h2 * c2 * w2**2, h2 * s2 * w2**2, 0.0, 0.0]
        if self.constant_speed:
            g.append(0.0)
        return np.array(g)

    def applied_forces(self, q: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
        """Generalized applied forces F_e [N, N m]: the spring and damper on the slider."""
        forces = np.zeros(9)
        compression_m = self.preload_m - (self.q0[6] - q[6])
        forces[6] = -self.stiffness_N_per_m * compression_m - self.damping_Ns_per_m * q_dot[6]
        return forces

    def accelerations(self, t: float, q: np.ndarray, q_dot: np.ndarray):
        """Solve Eq. 43 for (q_ddot, lambda)."""
        jac = self.jacobian(q)
        m = self.n_constraints
        system = np.zeros((9 + m, 9 + m))
        system[:9, :9] = self.mass
        system[:9, 9:] = jac.T
        system[9:, :9] = jac
        rhs = np.concatenate([self.applied_forces(q, q_dot), self.gamma(q, q_dot)])
        solution = np.linalg.solve(system, rhs)
        return solution[:9], solution[9:]

    def rhs(self, t: float, state: np.ndarray) -> np.ndarray:
        q, q_dot = state[:9], state[9:]
        q_ddot, _ = self.accelerations(t, q, q_dot)
        return np.concatenate([q_dot, q_ddot])


def solve_reference(scene: Scene, time_s: np.ndarray | None = None, rtol: float = 1e-12,
                    atol: float = 1e-14, method: str = "DOP853") -> ReferenceSolution:
    """Integrate the 9-coordinate DAE of ``scene`` (rigid coupler) with scipy's solve_ivp.

    ``time_s``: output times [s] (default: every ``simulation.output_step_s`` up to
    ``end_time_s``). Returns a :class:`ReferenceSolution`; raises
    :class:`~flex.base.errors.SimulationError` if the integrator fails.
    """
    dae = SliderCrankDAE(scene)
    sim = resolved_simulation(scene)
    if time_s is None:
        interval = sim["output_step_s"] or sim["step_s"]
        count = int(round(sim["end_time_s"] / interval))
        time_s = np.linspace(0.0, count * interval, count + 1)
    start = time.perf_counter()
    sol = solve_ivp(dae.rhs, (float(time_s[0]), float(time_s[-1])),
                    np.concatenate([dae.q0, dae.q_dot0]), method=method, t_eval=time_s,
                    rtol=rtol, atol=atol)
    wall = time.perf_counter() - start
    if not sol.success:
        raise SimulationError(f"reference DAE failed at t = {sol.t[-1]:.6g} s: {sol.message}")
    q, q_dot = sol.y[:9].T, sol.y[9:].T
    q_ddot = np.empty_like(q)
    lam = np.empty((len(sol.t), dae.n_constraints))
    norm = np.empty(len(sol.t))
    for i, t in enumerate(sol.t):
        q_ddot[i], lam[i] = dae.accelerations(t, q[i], q_dot[i])
        norm[i] = np.linalg.norm(dae.constraints(t, q[i]))
    return ReferenceSolution(sol.t, q, q_dot, q_ddot, lam, norm, sol.message, sol.nfev, wall,
                             {"x_slider0_m": dae.q0[6]})


def deviations_from_reference(scene: Scene, data: dict[str, np.ndarray]
                              ) -> tuple[ReferenceSolution, dict[str, tuple[float, str]]]:
    """The reference DAE of ``scene`` solved at a run's output times, and the run's largest
    deviations from it, ``{name: (max |run - reference|, unit)}``: ``crank_angle`` [rad],
    ``crank_angular_velocity`` [rad/s], ``slider_position`` [m] and ``joint_B_force`` (on
    the coupler) [N]. ``data``: the run's stored curves by name (``time``, ``crank/angle``,
    ``crank/angular_velocity``, ``slider/position``, ``joints/B/force_on_coupler``)."""
    reference = solve_reference(scene, data["time"])
    forces = reference.reaction_forces_N()
    return reference, {
        "crank_angle": (np.abs(data["crank/angle"] - reference.q[:, 2]).max(), "rad"),
        "crank_angular_velocity": (np.abs(data["crank/angular_velocity"]
                                          - reference.q_dot[:, 2]).max(), "rad/s"),
        "slider_position": (np.abs(data["slider/position"] - reference.q[:, 6]).max(), "m"),
        "joint_B_force": (np.abs(data["joints/B/force_on_coupler"]
                                 - forces["B/force_on_coupler"]).max(), "N"),
    }
