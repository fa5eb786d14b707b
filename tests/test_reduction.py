"""Tests of flex.bodies.reduction: cache, FFRF coupler against beam theory, post-processing.

One coarse 3 mm plate (second-order tets, maxh 3 mm, 3.6k DOF, 6 fixed-interface modes) is
built once per module; Euler-Bernoulli references: I = w t^3 / 12 (bending height t in plane).
"""

from __future__ import annotations

import re
import shutil

import h5py
import numpy as np
import pytest

from flex.base.errors import SceneError
from flex.base.physics import Plate
from flex.bodies.reduction import (
    add_ffrf_link,
    bending_stress_history,
    build_reduction,
    midpoint_deflection,
)

LENGTH, THICKNESS, WIDTH = 0.08, 0.003, 0.01  # m
E, RHO, NU = 200e9, 7850.0, 0.3
MESH_SIZE, MODES = 0.003, 6
INERTIA = WIDTH * THICKNESS**3 / 12  # m^4
AREA = WIDTH * THICKNESS
ARGS = (Plate(LENGTH, THICKNESS, WIDTH, E, RHO, NU), MESH_SIZE, MODES)

# a pose that is neither axis-aligned nor at the origin, to catch frame mix-ups
POSITION_B = np.array([0.01, 0.02, 0.0])
ANGLE = 0.5
ROTATION = np.array([[np.cos(ANGLE), -np.sin(ANGLE), 0.0],
                     [np.sin(ANGLE), np.cos(ANGLE), 0.0],
                     [0.0, 0.0, 1.0]])


def pinned_pinned_Hz() -> float:
    return (np.pi / LENGTH) ** 2 * np.sqrt(E * INERTIA / (RHO * AREA)) / (2 * np.pi)


@pytest.fixture(scope="module")
def cache_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("reduction_cache")


@pytest.fixture(scope="module")
def reduction(cache_dir):
    return build_reduction(*ARGS, cache_dir=cache_dir)


def new_system():
    import exudyn as exu

    system_container = exu.SystemContainer()
    return system_container, system_container.AddSystem()


def static_settings():
    import exudyn as exu

    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.staticSolver.verboseMode = 0
    return settings


def dynamic_settings(end_time: float, step: float):
    import exudyn as exu

    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.timeIntegration.verboseMode = 0
    settings.timeIntegration.endTime = end_time
    settings.timeIntegration.numberOfSteps = int(round(end_time / step))
    settings.solution.sensors.writePeriod = step
    return settings


# ------------------------------------------------------------------------------------------
# inputs
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("index", "value", "words"), [
    (0, 0.0, "length_m"), (1, -0.001, "thickness_m"), (2, float("nan"), "width_m"),
    (3, 0.0, "youngs_modulus_Pa"), (4, -1.0, "density_kg_per_m3"),
    (5, 0.0, "(0, 0.5)"), (5, 0.5, "(0, 0.5)"), (6, 0.0, "mesh_size_m"),
    (6, 0.1, "<= length_m"), (7, 0, ">= 1"), (7, 2.5, ">= 1"),
])
def test_bad_inputs_raise_scene_error_naming_the_range(index, value, words, tmp_path):
    args = [LENGTH, THICKNESS, WIDTH, E, RHO, NU, MESH_SIZE, MODES]
    args[index] = value
    with pytest.raises(SceneError, match=re.escape(words)):
        build_reduction(Plate(*args[:6]), *args[6:], cache_dir=tmp_path)


# ------------------------------------------------------------------------------------------
# cache
# ------------------------------------------------------------------------------------------
def _assert_same_reduction(a, b, exact: bool):
    """Loaded entries are bit-identical; a rebuild differs by threaded round-off only."""
    same = (np.testing.assert_array_equal if exact
            else lambda x, y: np.testing.assert_allclose(x, y, rtol=1e-7,
                                                         atol=1e-7 * np.abs(y).max()))
    assert a.key == b.key
    same(a.fem.modeBasis["matrix"], b.fem.modeBasis["matrix"])
    same(a.fem.postProcessingModes["matrix"], b.fem.postProcessingModes["matrix"])
    for sparse_a, sparse_b in ((a.fem.massMatrix, b.fem.massMatrix),
                               (a.fem.stiffnessMatrix, b.fem.stiffnessMatrix)):
        difference = abs(sparse_a - sparse_b).max()
        assert difference <= (0 if exact else 1e-7 * abs(sparse_b).max())
    for name in ("nodes_end_a", "weights_end_a", "nodes_end_b", "weights_end_b",
                 "nodes_mid", "weights_mid", "fixed_interface_frequencies_Hz"):
        same(getattr(a, name), getattr(b, name))
    same(a.pinned_pinned_frequency_Hz, b.pinned_pinned_frequency_Hz)


def test_second_build_is_a_fast_identical_cache_hit(reduction, cache_dir):
    assert not reduction.from_cache
    assert reduction.cache_file.parent == cache_dir and reduction.cache_file.is_file()
    assert not list(cache_dir.glob("*.tmp.hdf5"))  # temporary file renamed away
    again = build_reduction(*ARGS, cache_dir=cache_dir)
    assert again.from_cache  # read, not rebuilt (no timed assertion: make bench times it)
    assert again.cold_build_time_s == reduction.cold_build_time_s
    _assert_same_reduction(reduction, again, exact=True)


def test_key_depends_on_every_argument(reduction, tmp_path):
    from flex.bodies.reduction.cache import cache_key

    base = {"length_m": LENGTH, "modes": MODES}
    assert cache_key(base) == cache_key(dict(base))
    assert cache_key(base) != cache_key({**base, "modes": MODES + 1})
    assert cache_key(base) != cache_key({**base, "length_m": LENGTH * (1 + 1e-12)})


def _copy_entry(reduction, directory):
    target = directory / reduction.cache_file.name
    shutil.copyfile(reduction.cache_file, target)
    return target


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_truncated_entry_is_rebuilt_and_replaced(reduction, tmp_path):
    entry = _copy_entry(reduction, tmp_path)
    entry.write_bytes(entry.read_bytes()[: entry.stat().st_size // 2])
    rebuilt = build_reduction(*ARGS, cache_dir=tmp_path)
    assert not rebuilt.from_cache
    _assert_same_reduction(reduction, rebuilt, exact=False)
    assert build_reduction(*ARGS, cache_dir=tmp_path).from_cache  # the entry is whole again


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_entry_of_another_key_is_not_trusted(reduction, tmp_path):
    entry = _copy_entry(reduction, tmp_path)
    with h5py.File(entry, "r+") as h5:
        key = h5["metaData"]["flex"]["key"]
        key[()] = "0" * 24
    assert not build_reduction(*ARGS, cache_dir=tmp_path).from_cache


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_damaged_data_in_a_readable_entry_is_rebuilt(reduction, tmp_path):
    entry = _copy_entry(reduction, tmp_path)
    with h5py.File(entry, "r+") as h5:
        basis = h5["modeBasis"]["matrix"]
        basis[0, 0] = basis[0, 0] + 1.0
    rebuilt = build_reduction(*ARGS, cache_dir=tmp_path)
    assert not rebuilt.from_cache
    _assert_same_reduction(reduction, rebuilt, exact=False)


# ------------------------------------------------------------------------------------------
# reduction against beam theory
# ------------------------------------------------------------------------------------------
def test_mesh_stats_node_sets_and_mass(reduction):
    assert reduction.n_dof == 3 * reduction.n_nodes > 1000
    assert reduction.n_modal_coordinates == 3 + MODES  # in-plane static modes of end_b
    assert len(reduction.fixed_interface_frequencies_Hz) == MODES
    assert reduction.mass_kg == pytest.approx(RHO * LENGTH * AREA, rel=1e-9)
    np.testing.assert_allclose(reduction.centre_end_a, [0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(reduction.centre_end_b, [LENGTH, 0, 0], atol=1e-12)
    np.testing.assert_allclose(reduction.centre_mid, [LENGTH / 2, 0, 0], atol=1e-9)
    for weights in (reduction.weights_end_a, reduction.weights_end_b):
        assert weights.sum() == pytest.approx(1.0) and np.all(weights > 0)
    # the mid-span marker reads the section mean of the mesh's quadratic field: exact for the
    # mean of y^2 and z^2 over the t x w section (t^2 / 12, w^2 / 12), which a slab of mesh
    # nodes read up to 2x and 1.3x off
    weights, nodes = reduction.weights_mid, reduction.fem.GetNodePositionsAsArray()[
        reduction.nodes_mid]
    assert weights.sum() == pytest.approx(1.0)
    thickness, width = reduction.thickness_m, reduction.width_m
    assert weights @ nodes[:, 1] ** 2 == pytest.approx(thickness**2 / 12, rel=1e-9)
    assert weights @ nodes[:, 2] ** 2 == pytest.approx(width**2 / 12, rel=1e-9)


def test_frequencies_match_euler_bernoulli(reduction):
    # L/t = 27: shear and rotary inertia < 0.5 %; the coarse mesh is stiff by ~1 %
    assert reduction.pinned_pinned_frequency_Hz == pytest.approx(pinned_pinned_Hz(), rel=0.02)
    clamped_clamped = 4.730**2 / np.pi**2 * pinned_pinned_Hz()
    assert reduction.fixed_interface_frequencies_Hz[0] == pytest.approx(clamped_clamped,
                                                                       rel=0.03)


def test_cantilever_tip_load_deflection_and_stress(reduction):
    import exudyn as exu
    import exudyn.itemInterface as eii

    _, mbs = new_system()
    coupler = add_ffrf_link(mbs, reduction, POSITION_B, ANGLE)
    np.testing.assert_allclose(coupler["position_C"], POSITION_B + ROTATION @ [LENGTH, 0, 0],
                               atol=1e-15)
    ground = mbs.AddObject(eii.ObjectGround())
    clamp = mbs.AddMarker(eii.MarkerBodyRigid(
        bodyNumber=ground, localHT=exu.HT(rotation=ROTATION, translation=list(POSITION_B))))
    mbs.AddObject(eii.GenericJoint(markerNumbers=[clamp, coupler["marker_B"]],
                                   constrainedAxes=[1] * 6))
    force = 1.0  # N, along the body's +y
    mbs.AddLoad(eii.LoadForceVector(markerNumber=coupler["marker_C"],
                                    loadVector=list(ROTATION @ [0, force, 0])))
    mbs.Assemble()
    mbs.SolveStatic(static_settings())

    tip = mbs.GetMarkerOutput(coupler["marker_C"], exu.OutputVariableType.Position)
    tip_local = ROTATION.T @ (tip - coupler["position_C"])
    # the 3D clamp (rigid face) restrains Poisson contraction: ~1 % stiffer than the beam
    assert tip_local[1] == pytest.approx(force * LENGTH**3 / (3 * E * INERTIA), rel=0.03)

    modal = mbs.GetNodeOutput(coupler["node_modal"], exu.OutputVariableType.Coordinates)
    mid_stress = bending_stress_history(reduction, modal, (0.495 * LENGTH, 0.505 * LENGTH))
    # sigma = M c / I at x = 0.495 L (the window's largest moment)
    expected = force * 0.505 * LENGTH * (THICKNESS / 2) / INERTIA
    assert mid_stress.shape == (1,)
    assert mid_stress[0] == pytest.approx(expected, rel=0.03)


def _pinned_pinned_step_response(reduction, damping_ratio: float):
    """Pinned at B (revolute about z), C held in x and y, unit step force at the midpoint."""
    import exudyn as exu
    import exudyn.itemInterface as eii

    _, mbs = new_system()
    coupler = add_ffrf_link(mbs, reduction, POSITION_B, ANGLE, damping_ratio=damping_ratio)
    ground = mbs.AddObject(eii.ObjectGround())
    mbs.CreateRevoluteJoint(itemNumbers=[ground, coupler["marker_B"]], position=[],
                            axis=[0, 0, 1])
    mbs.CreateSphericalJoint(itemNumbers=[ground, coupler["marker_C"]], position=[],
                             constrainedAxes=[1, 1, 0])
    mbs.AddLoad(eii.LoadForceVector(markerNumber=coupler["marker_mid"],
                                    loadVector=list(ROTATION @ [0, 1.0, 0])))
    sensors = {name: mbs.AddSensor(eii.SensorMarker(
        markerNumber=coupler[name], outputVariableType=exu.OutputVariableType.Position,
        storeInternal=True)) for name in ("marker_B", "marker_C", "marker_mid")}
    mbs.Assemble()
    mbs.SolveDynamic(dynamic_settings(end_time=4e-3, step=1e-5))
    tracks = {name: mbs.GetSensorStoredData(sensor) for name, sensor in sensors.items()}
    time = tracks["marker_B"][:, 0]
    deflection = midpoint_deflection(*(tracks[name][:, 1:4]
                                       for name in ("marker_B", "marker_C", "marker_mid")))
    return time, deflection, coupler


def test_step_load_at_midpoint_oscillates_at_the_pinned_pinned_frequency(reduction):
    time, deflection, _ = _pinned_pinned_step_response(reduction, damping_ratio=0.0)
    static = LENGTH**3 / (48 * E * INERTIA)  # m per N
    transverse = deflection.transverse_m
    # undamped step response of the first mode: 0 .. 2 x static
    assert transverse.max() == pytest.approx(2 * static, rel=0.03)
    assert np.abs(deflection.chord_change_m).max() < 1e-3 * static
    oscillation = transverse - 0.5 * (transverse.max() + transverse.min())
    upward = time[1:][(oscillation[:-1] < 0) & (oscillation[1:] >= 0)]
    assert len(upward) >= 3
    assert 1 / np.diff(upward).mean() == pytest.approx(pinned_pinned_Hz(), rel=0.02)


def test_damping_ratio_sets_the_first_overshoot(reduction):
    zeta = 0.05
    _, deflection, coupler = _pinned_pinned_step_response(reduction, damping_ratio=zeta)
    assert coupler["stiffness_proportional_damping_s"] == pytest.approx(
        2 * zeta / (2 * np.pi * reduction.pinned_pinned_frequency_Hz))
    static = LENGTH**3 / (48 * E * INERTIA)
    overshoot_sdof = 1 + np.exp(-zeta * np.pi / np.sqrt(1 - zeta**2))
    assert deflection.transverse_m.max() / static == pytest.approx(overshoot_sdof, rel=0.02)


def test_initial_angular_velocity_turns_the_frame(reduction):
    import exudyn as exu
    import exudyn.itemInterface as eii

    omega = 20.0  # rad/s about z, the coupler swinging about its pin at B
    _, mbs = new_system()
    coupler = add_ffrf_link(mbs, reduction, POSITION_B, ANGLE,
                               initial_angular_velocity_rad_per_s=omega)
    ground = mbs.AddObject(eii.ObjectGround())
    mbs.CreateRevoluteJoint(itemNumbers=[ground, coupler["marker_B"]], position=[],
                            axis=[0, 0, 1])
    mbs.Assemble()
    end_time = 0.01
    mbs.SolveDynamic(dynamic_settings(end_time=end_time, step=1e-4))
    tip = mbs.GetMarkerOutput(coupler["marker_C"], exu.OutputVariableType.Position)
    chord = tip - POSITION_B
    assert np.arctan2(chord[1], chord[0]) == pytest.approx(ANGLE + omega * end_time, abs=1e-5)


# ------------------------------------------------------------------------------------------
# pure post-processing
# ------------------------------------------------------------------------------------------
def _rigid_pose(angle, shift, points_local):
    c, s = np.cos(angle), np.sin(angle)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return points_local @ rotation.T + shift


def test_rigidly_moving_straight_link_has_no_deflection():
    angles = np.linspace(0.0, 2.5, 7)
    shifts = np.column_stack([np.linspace(0, 0.1, 7), np.linspace(0, -0.05, 7), np.zeros(7)])
    local = np.array([[0.0, 0.0, 0.0], [0.08, 0.0, 0.0], [0.04, 0.0, 0.0]])
    poses = np.array([_rigid_pose(a, s, local) for a, s in zip(angles, shifts, strict=True)])
    result = midpoint_deflection(poses[:, 0], poses[:, 1], poses[:, 2])
    np.testing.assert_allclose(result.transverse_m, 0.0, atol=1e-15)
    np.testing.assert_allclose(result.chord_change_m, 0.0, atol=1e-15)


def test_bow_of_known_sagitta_and_stretch():
    # circular bow through B and C, bulging to the chord's left (+n); radius R, chord 2a
    radius, half_chord = 0.5, 0.04
    sagitta = radius - np.sqrt(radius**2 - half_chord**2)
    stretch = 1e-5
    straight = np.array([[0.0, 0.0, 0.0], [0.08, 0.0, 0.0], [0.04, 0.0, 0.0]])
    bowed = np.array([[0.0, 0.0, 0.0], [0.08 + stretch, 0.0, 0.0],
                      [0.04 + stretch / 2, sagitta, 0.0]])
    turned = _rigid_pose(2.0, np.array([0.3, -0.2, 0.0]), bowed)  # same bow, other pose
    poses = np.array([straight, bowed, turned])
    result = midpoint_deflection(poses[:, 0], poses[:, 1], poses[:, 2])
    np.testing.assert_allclose(result.transverse_m, [0.0, sagitta, sagitta], rtol=1e-12)
    np.testing.assert_allclose(result.chord_change_m, [0.0, stretch, stretch], rtol=1e-9)
    # the mirror bow is negative
    mirrored = poses * np.array([1.0, -1.0, 1.0])
    flipped = midpoint_deflection(mirrored[:, 0], mirrored[:, 1], mirrored[:, 2])
    assert flipped.transverse_m[1] == pytest.approx(-sagitta)


def test_midpoint_deflection_rejects_bad_shapes():
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        midpoint_deflection(np.zeros((4, 2)), np.zeros((4, 2)), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="shapes differ"):
        midpoint_deflection(np.zeros((4, 3)), np.ones((3, 3)), np.zeros((4, 3)))


def test_bending_stress_history_checks_columns(reduction):
    with pytest.raises(ValueError, match="columns"):
        bending_stress_history(reduction, np.zeros((3, reduction.n_modal_coordinates + 1)))
    assert np.all(bending_stress_history(
        reduction, np.zeros((3, reduction.n_modal_coordinates))) == 0.0)


def test_the_channel_stress_is_the_field_of_the_low_passed_modal_coordinates(reduction):
    """The first fixed-interface mode bending at 100 Hz with the second ringing at 20 kHz
    (its stress 5 % of the first's): on a 1 kHz channel the peak bending and von Mises
    stresses are those of the first mode alone (within the filter's 1e-3), while the
    low-passed peak series keeps the rectified ringing above them
    (:func:`flex.dynamics.link_outputs.channel_stress_datasets`)."""
    from flex.base.channel import channel_filter
    from flex.bodies.stress import region_nodes, von_mises_history
    from flex.dynamics.link_outputs import channel_stress_datasets, stress_window_m

    window = stress_window_m(reduction)
    time_s = np.arange(0.0, 0.02, 2e-6)
    unit = np.zeros((2, reduction.n_modal_coordinates))
    unit[0, 6], unit[1, 7] = 1.0, 1.0  # the first two eigenmodes after the six static modes
    first, second = bending_stress_history(reduction, unit, window)
    modal = np.zeros((time_s.size, reduction.n_modal_coordinates))
    modal[:, 6] = np.sin(2 * np.pi * 100 * time_s) / first
    modal[:, 7] = 0.05 * np.sin(2 * np.pi * 20_000 * time_s) / second
    out = channel_stress_datasets("coupler", reduction, modal, time_s, 1000.0)
    slow = modal.copy()
    slow[:, 7] = 0.0
    middle = slice(2000, -2000)  # away from the channel's padded ends
    field = out["channel/coupler/peak_bending_stress"].data
    assert np.max(field[middle]) == pytest.approx(
        np.max(bending_stress_history(reduction, slow, window)), rel=1e-3)
    von_mises = out["channel/coupler/peak_von_mises_stress"].data
    away = region_nodes(reduction)["away"]
    assert np.max(von_mises[middle]) == pytest.approx(
        np.max(von_mises_history(reduction, slow, away)[0]), rel=1e-3)
    envelope = channel_filter(time_s, 1000.0)(bending_stress_history(reduction, modal, window))
    assert np.max(envelope[middle]) > np.max(field[middle]) * 1.005  # measured 1.013
    assert channel_stress_datasets("coupler", reduction, modal, time_s, None) == {}


@pytest.mark.slow
@pytest.mark.parametrize(("thickness", "mesh_size", "low", "high"), [
    (0.001, 0.002, 0.999, 1.003), (0.003, 0.003, 0.995, 1.002),
    (0.005, 0.005, 0.990, 1.000), (0.010, 0.005, 0.970, 0.985),  # t = 10: shear, -2.4 %
])
def test_thesis_plates_pinned_pinned_frequency(thickness, mesh_size, low, high, tmp_path):
    """The four Table 5 plates at the recommended mesh sizes against Euler-Bernoulli."""
    reduction = build_reduction(Plate(LENGTH, thickness, WIDTH, E, RHO, NU), mesh_size, MODES,
                                cache_dir=tmp_path)
    inertia, area = WIDTH * thickness**3 / 12, WIDTH * thickness
    euler_bernoulli = (np.pi / LENGTH) ** 2 * np.sqrt(E * inertia / (RHO * area)) / (2 * np.pi)
    assert low < reduction.pinned_pinned_frequency_Hz / euler_bernoulli < high


# ------------------------------------------------------------------------------------------
# joint markers: as cheap as the basis allows, the same motion as on every face node
# ------------------------------------------------------------------------------------------
def test_joint_markers_use_the_frame_node_and_four_corners_of_the_rigid_face(reduction):
    from flex.bodies.reduction.body import _face_corners, _rigid_face_motions

    basis = reduction.fem.modeBasis["matrix"]
    basis = basis.reshape(-1, 3, basis.shape[1])
    positions = reduction.fem.GetNodePositionsAsArray()
    # chord frame: end_a only turns about z about its centre (the frame's origin), so a pin
    # at B may use the frame node; end_b moves rigidly (along x, turning about z)
    end_a = np.asarray(reduction.nodes_end_a)
    turns = _rigid_face_motions(positions[end_a], basis[end_a], reduction.centre_end_a)
    assert turns is not None and not np.any(turns[:, :5]) and np.any(turns[:, 5])
    end_b = np.asarray(reduction.nodes_end_b)
    assert _rigid_face_motions(positions[end_b], basis[end_b]) is not None
    corners = _face_corners(positions, end_b)
    yz = positions[corners][:, 1:]
    assert len(corners) == 4
    np.testing.assert_allclose(np.sort(np.abs(yz), axis=0),
                               np.tile([THICKNESS / 2, WIDTH / 2], (4, 1)), rtol=1e-12)
    # a bent face is not rigid: the check must say so
    bent = basis[end_b].copy()
    bent[:, 0, -1] += positions[end_b][:, 1] ** 2
    assert _rigid_face_motions(positions[end_b], bent) is None


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
@pytest.mark.parametrize("link", ["coupler", "crank"])
def test_fewest_joint_markers_give_the_motion_of_all_face_nodes(reduction, cache_dir, link):
    """The thesis deployment's first 2 ms with the plate as coupler (or crank): every output
    of the cheap markers equals the all-node markers' to the Newton tolerance (1e-5 of each
    curve's range; measured up to ~4e-8 for positions and forces, ~2e-6 for accelerations)."""
    from flex.data.scene import apply_overrides, default_scene
    from flex.dynamics.collect import collect
    from flex.dynamics.link_models import reduction_for_scene
    from flex.dynamics.mechanism import build_mechanism
    from flex.dynamics.solver import run

    scene = apply_overrides(default_scene(), [
        f'{link}.geometry="plate"', f'{link}.model="ffrf"', f"{link}.thickness_m={THICKNESS}",
        f"{link}.mesh_size_m={MESH_SIZE}", f"{link}.modes={MODES}", "simulation.step_s=1e-5",
        "simulation.end_time_s=0.002", 'simulation.newton="modified"',
        'simulation.spectral_radius=0.9', "simulation.newton_relative_tolerance=1e-8"])
    reductions = {"reduction": reduction} if link == "coupler" else {  # the crank's length
        "crank_reduction": reduction_for_scene(scene, "crank", cache_dir=cache_dir)}
    curves = {}
    for markers in ("fewest", "all_face_nodes"):
        mech = build_mechanism(scene, ffrf_joint_markers=markers, **reductions)
        run(mech)
        curves[markers] = {k: np.asarray(v.data) for k, v in collect(mech).items()}
    for key, full in curves["all_face_nodes"].items():
        if full.dtype.kind != "f" or not full.size or key == "constraint_norm":
            continue
        if np.max(np.abs(full)) < 1e-15:  # round-off of a zero (a crank frame's origin at A)
            continue
        scale = max(np.ptp(full), np.max(np.abs(full)) * 1e-12, 1e-300)
        assert np.max(np.abs(curves["fewest"][key] - full)) <= 1e-5 * scale, key


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_in_plane_selection_keeps_the_in_plane_modes_of_the_full_basis(reduction):
    """The default reduction (in-plane modes) holds exactly the in-plane members of a basis of
    any kind computed with enough modes: the same fixed-interface frequencies (to the
    eigensolver's accuracy: a fixed 40-step PINVIT, measured within 1e-5) and the 3 in-plane
    static modes of end_b."""
    from flex.bodies.reduction.basis import _mirror_antisymmetry

    full = build_reduction(*ARGS[:-1], 3 * MODES + 4, None, mode_selection="all")
    score = _mirror_antisymmetry(full.fem.GetNodePositionsAsArray(),
                                 full.fem.modeBasis["matrix"])
    # pure modes on this mesh, up to a near-degenerate pair the mode count may cut (mixed)
    pure = (score < 0.05) | (score > 1.95)
    first_mixed = np.flatnonzero(~pure)[0] if not pure.all() else len(score)
    in_plane = np.flatnonzero(score[6:first_mixed] < 0.05)
    assert len(in_plane) >= MODES and list(np.flatnonzero(score[:6] < 0.05)) == [0, 1, 5]
    np.testing.assert_allclose(reduction.fixed_interface_frequencies_Hz,
                               full.fixed_interface_frequencies_Hz[in_plane[:MODES]], rtol=1e-4)
    assert reduction.mode_selection == "in_plane" and full.n_modal_coordinates == 6 + 22


def test_mirror_comparison_falls_back_when_exact_pairs_miss_a_mode():
    """A mode that vanishes at every exactly mirrored node (found on a crank plate of the
    crank study) is compared at all moving nodes instead of breaking the symmetric
    subspace's eigenproblem."""
    from scipy.linalg import eigh

    from flex.bodies.reduction.basis import _mirror_antisymmetry, _mirror_parts

    rng = np.random.default_rng(1)
    pairs = rng.uniform(-1, 1, (20, 3)) * [0.04, 0.001, 0.005]
    loose = np.array([[0.01, 0.0002, 0.0031], [0.01, 0.0002, -0.0030]])  # near mirrors
    positions = np.vstack([pairs, pairs * [1, 1, -1], loose])
    symmetric = np.zeros((len(positions), 3))
    symmetric[:20] = rng.normal(size=(20, 3))
    symmetric[20:40] = symmetric[:20] * [1, 1, -1]
    hidden = np.zeros((len(positions), 3))
    hidden[40:] = [[1.0, 0.5, 0.2], [1.0, 0.5, -0.2]]  # in plane, only off the exact pairs
    basis = np.column_stack([symmetric.ravel(), hidden.ravel()])
    score = _mirror_antisymmetry(positions, basis)
    assert np.all(np.isfinite(score)) and np.all(score < 0.05)
    share, _ = eigh(*_mirror_parts(positions, basis))  # needs a positive definite Gram
    assert np.all(share < 0.05)


def test_a_build_does_not_depend_on_the_builds_before_it():
    """NGsolve's eigensolver starts from random vectors of one process-wide generator; the
    builder seeds it, so a plate's basis is the same whatever was built before it in the
    process (without the seed: ~3e-7 of the basis on a 5 mm plate)."""
    from flex.base.physics import Plate
    from flex.bodies.reduction import build_reduction

    plate = Plate(0.08, 0.005, 0.01, 200e9, 7850.0, 0.3)
    first = build_reduction(plate, 0.008, 2, None)
    build_reduction(Plate(0.08, 0.003, 0.01, 200e9, 7850.0, 0.3), 0.008, 3, None)
    again = build_reduction(plate, 0.008, 2, None)
    assert np.array_equal(np.asarray(first.fem.modeBasis["matrix"]),
                          np.asarray(again.fem.modeBasis["matrix"]))


def test_the_shortened_eigensolve_is_converged(monkeypatch):
    """The in-plane basis's fixed eigensolver iterations (EIGENSOLVER_ITERATIONS, fewer than
    Exudyn's default 40) give the 40-iteration frequencies and span: a converged reference
    (measured 1e-10 ... 6e-8 on the thesis plates; a count cut to 3 fails here)."""
    from flex.base.physics import Plate
    from flex.bodies.reduction import basis, build_reduction

    plate = Plate(0.08, 0.003, 0.01, 200e9, 7850.0, 0.3)
    short = build_reduction(plate, 0.006, 12, None)
    monkeypatch.setattr(basis, "EIGENSOLVER_ITERATIONS", 40)
    converged = build_reduction(plate, 0.006, 12, None)
    np.testing.assert_allclose(short.fixed_interface_frequencies_Hz,
                               converged.fixed_interface_frequencies_Hz, rtol=1e-6)
    span_short, _ = np.linalg.qr(np.asarray(short.fem.modeBasis["matrix"]))
    span_converged, _ = np.linalg.qr(np.asarray(converged.fem.modeBasis["matrix"]))
    cosines = np.linalg.svd(span_short.T @ span_converged, compute_uv=False)
    assert 1 - cosines.min() < 1e-6


def test_a_truncated_solve_is_the_direct_solve_of_fewer_modes(tmp_path):
    """One 12-mode eigen-solve serves 4 modes by truncation (``solve_modes``): its own cache
    entry, never the direct 4-mode one, and the same reduction: frequencies, span, the
    pinned-pinned frequency and a simulated response. Not to round-off: on a mesh that is not
    mirror-symmetric the in-plane modes are a Rayleigh-Ritz pick from the computed vectors,
    which differ (measured on this coarse 3 mm plate: frequencies 2e-5, span 2e-5, the
    pinned-pinned frequency 2e-7, the response 5e-6; on the 1 mm plate at 2 mm all 2e-8)."""
    plate = Plate(0.08, 0.003, 0.01, 200e9, 7850.0, 0.3)
    truncated = build_reduction(plate, 0.006, 4, tmp_path, solve_modes=12)
    direct = build_reduction(plate, 0.006, 4, tmp_path)
    solved = build_reduction(plate, 0.006, 12, tmp_path)
    assert (truncated.solve_modes, direct.solve_modes) == (12, None)
    assert len({truncated.key, direct.key, solved.key}) == 3
    assert not direct.from_cache and solved.from_cache  # the truncation stored its solve
    assert truncated.fem.metaData["flex"]["solve_key"] == solved.key
    assert build_reduction(plate, 0.006, 4, tmp_path, solve_modes=12).from_cache
    kept = truncated.n_modal_coordinates
    assert kept == direct.n_modal_coordinates == solved.n_modal_coordinates - 8
    np.testing.assert_array_equal(truncated.fem.modeBasis["matrix"],
                                  solved.fem.modeBasis["matrix"][:, :kept])
    np.testing.assert_array_equal(truncated.fem.postProcessingModes["matrix"],
                                  solved.fem.postProcessingModes["matrix"][:, :6 * kept])
    np.testing.assert_allclose(truncated.fixed_interface_frequencies_Hz,
                               direct.fixed_interface_frequencies_Hz, rtol=1e-4)
    span_truncated, _ = np.linalg.qr(np.asarray(truncated.fem.modeBasis["matrix"]))
    span_direct, _ = np.linalg.qr(np.asarray(direct.fem.modeBasis["matrix"]))
    cosines = np.linalg.svd(span_truncated.T @ span_direct, compute_uv=False)
    assert 1 - cosines.min() < 1e-4
    assert truncated.pinned_pinned_frequency_Hz == pytest.approx(
        direct.pinned_pinned_frequency_Hz, rel=2e-6)
    assert truncated.pinned_pinned_frequency_Hz > solved.pinned_pinned_frequency_Hz
    responses = [_pinned_pinned_step_response(r, 0.0)[1].transverse_m
                 for r in (truncated, direct)]
    assert np.abs(responses[0] - responses[1]).max() < 3e-5 * np.abs(responses[1]).max()
    with pytest.raises(SceneError, match="solve_modes"):
        build_reduction(plate, 0.006, 4, None, solve_modes=2)
