"""The planar rigid build (flex.dynamics.planar) against the 3D build and the reference DAE.

Equality with the 3D build. Both builds integrate the same equations of motion with the
same generalized-alpha steps; they differ in their coordinates (7 against 18), hence in
round-off and in where each step's Newton iteration stops (residual 1e-8 of the first).
Positions and angles then agree to ``DQ`` = 1e-12 m or rad (measured: 1e-13 and below).
Index-3 generalized-alpha gets velocities from positions with the factor gamma / (beta h)
and accelerations and Lagrange multipliers with 1 / (beta h^2) (rho = 0.9: beta = 0.277,
gamma = 0.553), so a quantity's tolerance is ``DQ`` times the factor of its time-derivative
order, times a mass ``MASS`` (0.2 kg, bounding the 0.12-0.16 kg of moving links) for forces,
times a lever ``LEVER`` (0.1 m; crank 0.04 m) too for moments, and times ``MASS`` and a speed
``SPEED`` (10 m/s; peak wing tip 5.1 m/s) for energies. At the default h = 1e-5 s that is
1e-12 m, 2e-7 m/s, 0.036 m/s^2, 7e-3 N (peaks ~25 N: a sign or frame error is ~1000 times
larger); measured differences are 10 to 1000 times below.

Agreement with the reference DAE (flex.dynamics.reference, DOP853 at rtol 1e-12). The
spring scenes at h = 2.5e-6 s: generalized-alpha is second order, the thesis crank-angle
error is 1.56e-7 rad at 1e-5 s, hence ~1e-8 rad here (tolerance 3e-8 rad; slider 3e-9 m).
Forces: index-3 multipliers carry the round-off of the positions amplified by 1 / (beta h^2)
and a start-up error that the numerical damping removes; measured 1e-5 to 6e-5 of the peak
at 2e-6 s, tolerance 2e-4 of the peak. The constant-speed drive turns the crank slowly
(6.3 rad/s): h = 1e-4 s (6e-4 rad per step) is its small step; measured force errors 3e-4
of the peak in the first steps (the start-up error), tolerance 3e-3.
"""

from __future__ import annotations

import numpy as np
import pytest

from flex.base.errors import SceneError
from flex.config.settings import resolve_solver_settings
from flex.data.scene import load_scene
from flex.dynamics.collect import collect
from flex.dynamics.mechanism import build_mechanism
from flex.dynamics.planar import is_planar
from flex.dynamics.reference import solve_reference
from flex.dynamics.solver import run

#: position-level agreement of the two builds [m, rad] (module docstring)
DQ = 1e-12
MASS, LEVER, SPEED = 0.2, 0.1, 10.0  # kg, m, m/s: bounds of the scenes' links and motion
#: generalized-alpha at spectral radius 0.9 (Chung-Hulbert)
ALPHA_M, ALPHA_F = 0.8 / 1.9, 0.9 / 1.9
GAMMA, BETA = 0.5 - ALPHA_M + ALPHA_F, 0.25 * (1 - ALPHA_M + ALPHA_F) ** 2

SCENES = {
    "thesis": [],
    "soft_spring": ["drive.spring_stiffness_N_per_m=300.0",
                    "drive.spring_damping_Ns_per_m=0.2", "slider.offset_m=0.003"],
    "wing": ["wing.enabled=true"],
    "constant_speed": ['drive.kind="constant_speed"', "simulation.end_time_s=0.5",
                       "simulation.step_s=1e-4"],
}
#: the reference comparison's small step of the spring scenes [s]
SMALL_STEP_S = 2.5e-6


def scene_of(overrides: list[str]):
    return resolve_solver_settings(load_scene(overrides=overrides))[0]


def both_builds(scene) -> dict[bool, dict]:
    """``{planar: datasets}`` of one scene, built in 3D (False) and planar (True)."""
    out = {}
    for planar in (False, True):
        mech = build_mechanism(scene, planar=planar)
        assert mech.planar is planar
        run(mech)
        out[planar] = collect(mech)
    return out


def tolerance(units: str, step_s: float) -> float:
    """Allowed planar-3D difference of a dataset in ``units`` (module docstring)."""
    velocity = DQ * GAMMA / (BETA * step_s)
    acceleration = DQ / (BETA * step_s**2)
    return {"s": 0.0, "m": DQ, "rad": DQ, "m/s": velocity, "rad/s": velocity,
            "deg/s": np.degrees(velocity), "m/s^2": acceleration, "rad/s^2": acceleration,
            "N": MASS * acceleration, "N m": MASS * LEVER * acceleration,
            "J": MASS * SPEED * velocity}[units]


@pytest.fixture(scope="module")
def builds():
    """``builds(name)`` -> (scene, both builds' datasets) of ``SCENES[name]``, run once."""
    cache: dict[str, tuple] = {}

    def get(name: str) -> tuple:
        if name not in cache:
            scene = scene_of(SCENES[name])
            cache[name] = scene, both_builds(scene)
        return cache[name]
    return get


def test_planar_is_chosen_for_rigid_implicit_scenes_only():
    assert is_planar(load_scene())
    assert build_mechanism(scene_of([])).planar
    assert build_mechanism(scene_of(["wing.enabled=true"])).planar
    for overrides in (['coupler.model="ffrf"', 'coupler.geometry="plate"'],
                      ['crank.model="ffrf"', 'crank.geometry="plate"'],
                      ['simulation.integrator="explicit_penalty"']):
        assert not is_planar(load_scene(overrides=overrides))
    penalty = scene_of(['simulation.integrator="explicit_penalty"', "simulation.step_s=1e-6",
                        "simulation.end_time_s=1e-5"])
    assert not build_mechanism(penalty).planar
    with pytest.raises(SceneError, match="planar build"):
        build_mechanism(penalty, planar=True)


@pytest.mark.parametrize("name", list(SCENES))
def test_planar_datasets_equal_the_3d_ones(builds, name):
    scene, data = builds(name)
    step_s = scene["simulation"]["step_s"]
    three_d, planar = data[False], data[True]
    assert set(planar) == set(three_d)
    for name, expected in three_d.items():
        got = planar[name]
        assert (got.units, got.description) == (expected.units, expected.description), name
        assert np.shape(got.data) == np.shape(expected.data), name
        difference = np.abs(np.asarray(got.data) - np.asarray(expected.data)).max()
        assert difference <= tolerance(expected.units, step_s), (name, difference)


def test_index2_formulation_equals_the_3d_one():
    scene = scene_of(['simulation.formulation="index2"', "simulation.end_time_s=0.01"])
    data = both_builds(scene)
    for name, expected in data[False].items():
        difference = np.abs(np.asarray(data[True][name].data) - np.asarray(expected.data)).max()
        assert difference <= tolerance(expected.units, 1e-5), (name, difference)


def reference_deviations(data: dict, scene) -> dict[str, float]:
    """Largest deviations of a run from the reference DAE: crank angle [rad], crank speed
    [rad/s], slider [m], and the joint forces as a fraction of their peak."""
    reference = solve_reference(scene, data["time"].data)
    out = {"angle": np.abs(data["crank/angle"].data - reference.q[:, 2]).max(),
           "speed": np.abs(data["crank/angular_velocity"].data - reference.q_dot[:, 2]).max(),
           "slider": np.abs(data["slider/position"].data - reference.q[:, 6]).max()}
    forces = reference.reaction_forces_N()
    # the slide line (constraint y3 = offset) on the slider: minus its multiplier, across
    forces["P/force_on_slider"] = np.column_stack([0.0 * reference.multipliers[:, 6],
                                                   -reference.multipliers[:, 6]])
    for name, expected in forces.items():
        out[name] = (np.abs(data[f"joints/{name}"].data - expected).max()
                     / np.abs(expected).max())
    return out


@pytest.mark.parametrize("name", ["thesis", pytest.param("soft_spring", marks=pytest.mark.slow),
                                  pytest.param("wing", marks=pytest.mark.slow)])
def test_both_builds_agree_with_the_reference_at_a_small_step(name):
    scene = scene_of(SCENES[name] + [f"simulation.step_s={SMALL_STEP_S!r}",
                                     f"simulation.output_step_s={10 * SMALL_STEP_S!r}"])
    for planar, data in both_builds(scene).items():
        deviations = reference_deviations(data, scene)
        label = (name, "planar" if planar else "3D", deviations)
        assert deviations.pop("angle") < 3e-8, label
        assert deviations.pop("slider") < 3e-9, label
        assert deviations.pop("speed") < 1e-5, label
        assert max(deviations.values()) < 2e-4, label


def test_constant_speed_agrees_with_the_reference(builds):
    scene, data = builds("constant_speed")
    for planar, run_data in data.items():
        deviations = reference_deviations(run_data, scene)
        assert deviations.pop("angle") < 1e-10, planar  # the drive holds it
        assert deviations.pop("slider") < 1e-10, planar
        assert max(deviations.values()) < 3e-3, (planar, deviations)
    # the crank passes pi: the angle stays on its branch in both builds
    assert data[True]["crank/angle"].data[-1] > np.pi
