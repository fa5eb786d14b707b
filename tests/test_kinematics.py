"""Constant-speed kinematics: Exudyn against the closed-form slider-crank."""

import numpy as np
import pytest

from flex.base.kinematics import slider_crank
from flex.data.scene import load_scene
from flex.fidelity.simulation import simulate


def test_closed_form_is_self_consistent():
    # velocity and acceleration are the time derivatives of position (finite differences)
    time_s = np.linspace(0.0, 1.0, 200001)
    omega = 2 * np.pi
    for offset_m in (0.0, 0.01):
        state = slider_crank(0.04, 0.08, 0.3 + omega * time_s, omega, 0.0, offset_m)
        step = time_s[1] - time_s[0]
        velocity_fd = np.gradient(state.slider_position_m, step)
        acceleration_fd = np.gradient(state.slider_velocity_m_per_s, step)
        assert np.abs(velocity_fd - state.slider_velocity_m_per_s)[1:-1].max() < 1e-8
        assert np.abs(acceleration_fd - state.slider_acceleration_m_per_s2)[1:-1].max() < 1e-6


def test_closed_form_matches_the_data_sheet_check():
    # data sheet: omega = 2 pi gives stroke 0.080 m, velocity +-0.2823, accel +1.198/-2.369
    state = slider_crank(0.04, 0.08, np.linspace(0, 2 * np.pi, 100001), 2 * np.pi)
    assert np.ptp(state.slider_position_m) == pytest.approx(0.080, abs=1e-12)
    assert state.slider_velocity_m_per_s.max() == pytest.approx(0.2823, abs=1e-4)
    assert state.slider_acceleration_m_per_s2.max() == pytest.approx(1.198, abs=1e-3)
    assert state.slider_acceleration_m_per_s2.min() == pytest.approx(-2.369, abs=1e-3)


@pytest.mark.parametrize("offset_m", [0.0, 0.015])
def test_exudyn_constant_speed_matches_closed_form(offset_m):
    scene = load_scene(overrides=[
        'drive.kind="constant_speed"', "crank.initial_angle_deg=20", "simulation.end_time_s=0.5",
        "simulation.step_s=1e-4", "simulation.output_step_s=1e-3", f"slider.offset_m={offset_m}"])
    data = {k: v.data for k, v in simulate(scene).datasets.items()}
    omega = scene["drive"]["crank_speed_rad_per_s"]
    theta = np.radians(20) + omega * data["time"]
    exact = slider_crank(0.04, 0.08, theta, omega, 0.0, offset_m)
    assert np.abs(data["crank/angle"] - theta).max() < 1e-9
    assert np.abs(data["slider/position"] - exact.slider_position_m).max() < 1e-9
    assert np.abs(data["slider/velocity"] - exact.slider_velocity_m_per_s).max() < 1e-6
    # generalized-alpha accelerations: second order in the step
    assert np.abs(data["slider/acceleration"] - exact.slider_acceleration_m_per_s2).max() < 1e-2
    radius = np.hypot(*data["crank/midpoint_position"].T)
    assert np.abs(radius - 0.02).max() < 1e-12
    assert data["constraint_norm"].max() < 1e-12


def test_chord_components_of_forces_along_and_across_a_turned_link():
    from flex.base.kinematics import chord_components

    angle = np.array([0.3, 0.3, 2.0])
    along = np.column_stack([np.cos(angle), np.sin(angle)]) * [[2.0], [0.0], [-1.5]]
    across = np.column_stack([-np.sin(angle), np.cos(angle)]) * [[0.0], [3.0], [0.5]]
    axial, transverse = chord_components(along + across, angle)
    np.testing.assert_allclose(axial, [2.0, 0.0, -1.5], atol=1e-15)
    np.testing.assert_allclose(transverse, [0.0, 3.0, 0.5], atol=1e-15)
