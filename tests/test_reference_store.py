"""Stored references (flex.data.reference_store, flex.experiments.workprecision.
stored_references): found by a scene's physics whatever its model and settings, written and
read back unchanged, refused with one message when missing, foreign or broken; a reference's
accuracy is the arithmetic its contract states, on runs made independently here; the bundled
store holds every scene make estimates and make calibrate judge."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from flex.base.errors import ResultFileError
from flex.data.headlines import BUILTIN_HEADLINES
from flex.data.reference_store import (
    MissingReferenceError,
    StoredReference,
    bundled_store,
    physics_identity,
    read_store,
    reference_for,
    write_store,
)
from flex.data.scene import default_scene
from flex.data.scene_edit import derive_scene


def _reference(scene, name="thesis") -> StoredReference:
    return StoredReference(name, physics_identity(scene), "the rigid mechanism", "evidence",
                           {"crank_angle_end_rad": 0.6}, {"crank_angle_end_rad": 1e-7},
                           {"crank_angle_end_rad": "rad"},
                           {"time": np.linspace(0, 0.03, 4), "crank/angle": np.arange(4.0)},
                           {"time": "s", "crank/angle": "rad"})


def test_a_scene_finds_its_physics_whatever_its_model_and_settings():
    base = derive_scene(default_scene(), ['coupler.geometry="plate"'])
    store = {"thesis": _reference(base)}
    ffrf = derive_scene(base, ['coupler.model="ffrf"', "coupler.mesh_size_m=0.003",
                               "simulation.step_s=2e-5", "coupler.modes=4",
                               "fidelity.tolerance=0.001"])
    assert reference_for(store, ffrf).name == "thesis"
    for physics in ("coupler.thickness_m=0.002", "drive.spring_preload_m=0.011",
                    "simulation.end_time_s=0.02"):
        with pytest.raises(MissingReferenceError, match="make references"):
            reference_for(store, derive_scene(base, [physics]))


def test_a_store_reads_back_what_was_written(tmp_path):
    path = tmp_path / "refs.h5"
    reference = _reference(default_scene())
    write_store(path, {"thesis": reference}, {"git_commit": "abc"})
    (back,) = read_store(path).values()
    assert back.values == reference.values and back.accuracies == reference.accuracies
    assert back.units == reference.units and back.digest == reference.digest
    np.testing.assert_array_equal(back.curves["crank/angle"], reference.curves["crank/angle"])
    assert back.curve_units["crank/angle"] == "rad"


def test_a_missing_foreign_or_broken_store_is_refused_with_one_message(tmp_path):
    with pytest.raises(ResultFileError, match="no reference store"):
        read_store(tmp_path / "none.h5")
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as h5:
        h5["x"] = 1.0
    with pytest.raises(ResultFileError, match="not a flex reference store"):
        read_store(foreign)
    text = tmp_path / "text.h5"
    text.write_text("not hdf5")
    with pytest.raises(ResultFileError, match="unreadable reference store"):
        read_store(text)


def test_a_rigid_reference_states_its_step_error_at_the_observed_order():
    """make_reference on the rigid thesis mechanism over 5 ms: the value is the run at the
    reference step, its accuracy Richardson's at the order independent runs at 2x and 4x the
    step show (within 0.5 of 2 here: the step's error, not a bound)."""
    import math

    from flex.experiments.workprecision.stored_references import (
        RIGID_REFERENCE_STEP_S,
        make_reference,
    )
    from flex.fidelity.simulation import simulate_case

    scene = derive_scene(default_scene(), ["simulation.end_time_s=0.005"])
    case = make_reference("rigid", scene)
    assert case.status == "ok", case.message
    angle = BUILTIN_HEADLINES["crank_angle_end_rad"]
    value = case.attrs["reference_value_crank_angle_end_rad"]
    coarse = [angle.read(simulate_case(derive_scene(scene, [
        f"simulation.step_s={k * RIGID_REFERENCE_STEP_S!r}", "simulation.error_estimate=false",
        "simulation.output_step_s=0.0"])).datasets) for k in (2, 4)]
    fine, coarser = abs(value - coarse[0]), abs(coarse[0] - coarse[1])
    order = math.log2(coarser / fine)
    assert abs(order - 2) <= 0.5
    assert case.attrs["reference_accuracy_crank_angle_end_rad"] == pytest.approx(
        fine / (2**order - 1), rel=1e-9)
    assert 0 < case.attrs["reference_accuracy_crank_angle_end_rad"] < 1e-6 * abs(value)


def test_the_bundled_store_holds_every_scene_make_estimates_and_make_calibrate_judge():
    from flex.study import study_scene
    from studies import calibrate, estimates

    store = read_store(bundled_store())
    scenes = estimates.cases(default_scene()) | calibrate.cases(study_scene(calibrate))
    for name, scene in scenes.items():
        reference = reference_for(store, scene)
        assert reference.values, name


def test_a_stored_curve_between_its_samples_states_its_interpolation_error():
    """A 1 kHz sine sampled every 1e-5 s (the store's spacing), read at the midpoints: the
    cubic spline's true error against the sine lies within [1/3, 3] of the stated one."""
    from flex.experiments.workprecision.stored_references import curve_at

    stored_s = np.arange(0.0, 0.01 + 1e-12, 1e-5)
    omega = 2 * np.pi * 1000.0
    reference = StoredReference("sine", {}, "", "", {}, {}, {},
                                {"time": stored_s, "x": np.sin(omega * stored_s)},
                                {"time": "s", "x": "m"})
    middle_s = stored_s[100:-100] + 5e-6
    values, stated = curve_at(reference, "x", middle_s)
    true = float(np.max(np.abs(values - np.sin(omega * middle_s))))
    assert 1 / 3 <= true / stated <= 3


def test_a_peak_that_moves_between_levels_is_a_bound():
    """The rigid thesis mechanism at 11 mm preload, first 0.2 ms: joint C's force peaks at
    release at 2.5e-6 s, and 1.5e-5 s later (the multiplier's Newton jitter) at 1.25e-6 s:
    not one feature converging, so its accuracy is a bound, 3x the larger change."""
    from flex.experiments.workprecision.stored_references import make_reference

    scene = derive_scene(default_scene(), ["drive.spring_preload_m=0.011",
                                           "simulation.end_time_s=0.0002"])
    case = make_reference("rigid", scene)
    assert case.status == "ok", case.message
    evidence = case.attrs["reference_evidence"]
    (force,) = [part for part in evidence.split("; ")
                if part.startswith("joint_C_deployment_peak_force_N:")]
    step_change = float(force.split("step ")[1].split(",")[0])
    assert step_change >= 3 * 4.5e-7 * 13.48 * 0.8  # 3x at least the 6e-6 N change


def _crests(frequency_Hz: float, step_s: float = 1.25e-6):
    from flex.data.results import CaseResult, Dataset

    time_s = np.arange(0.0, 0.02, step_s)
    deflection = np.sin(2 * np.pi * frequency_Hz * time_s) * (1 + 5 * time_s)  # last crest
    return CaseResult("run", "", {"time": Dataset(time_s, "s", "time"),
                                  "coupler/midpoint_deflection": Dataset(deflection, "m", "w")})


def test_a_late_crest_that_moves_as_the_frequency_converges_is_one_feature():
    """A crest near 20 ms of a link whose frequency converges at order 2 over three levels
    (1000 Hz x (1 + 1e-3 / 4^k)) moves by several steps, but its shift shrinks 4x: one feature.
    A peak that jumps to another crest between the two finest levels, after not moving
    between the coarser two, is not."""
    from flex.experiments.workprecision.stored_references import (
        PEAK_SHIFT_STEPS,
        _peak_moved,
        _peak_time_s,
    )

    headline = BUILTIN_HEADLINES["coupler_peak_deflection_m"]
    finest, coarse, coarser = (_crests(1000.0 * (1 + 1e-3 / 4**k)) for k in (2, 1, 0))
    shift_s = abs(_peak_time_s(headline, finest.datasets) - _peak_time_s(headline,
                                                                          coarse.datasets))
    assert shift_s > PEAK_SHIFT_STEPS * 1.25e-6  # it does move by more than two steps
    assert not _peak_moved(headline, finest, coarse, coarser)
    jumped = _crests(1000.0 * (1 + 5e-2))
    assert _peak_moved(headline, jumped, coarse, coarse)


def _plate_reference(scene, peak_m=1e-4, accuracy_m=2e-8) -> StoredReference:
    time_s = np.linspace(0.0, 0.03, 3001)
    curves = {"time": time_s, "crank/angle": 50.0 * time_s, "slider/position": 0.1 - time_s,
              "coupler/midpoint_deflection": peak_m * np.sin(2e3 * time_s)}
    quantity = "coupler_deployment_peak_deflection_m"
    return StoredReference("plate", physics_identity(scene), "the calibrated exact beam", "",
                           {quantity: peak_m}, {quantity: accuracy_m}, {quantity: "m"}, curves,
                           dict.fromkeys(curves, "1"))


def test_a_stored_reference_measures_a_run_by_its_curves_and_its_peak():
    """The calibration's grid against a stored reference: a run whose curves are offset by
    known amounts has exactly those errors; the reference's accuracy is the stored one
    relative to its peak."""
    from flex.experiments.workprecision.measurement import Observables, stored_as_reference

    stored = _plate_reference(derive_scene(default_scene(), ['coupler.geometry="plate"']))
    reference = stored_as_reference(stored)
    assert reference.accuracy == pytest.approx(2e-8 / 1e-4)
    time_s = np.linspace(0.0, 0.03, 1501)
    curves = stored.curves
    run = Observables(time_s, np.interp(time_s, curves["time"], curves["crank/angle"]) + 1e-3,
                      np.interp(time_s, curves["time"], curves["slider/position"]) - 2e-6,
                      np.zeros_like(time_s), 1.01e-4)
    errors = reference.errors(run)
    assert errors["crank_angle_rad"] == pytest.approx(1e-3, rel=1e-6)
    assert errors["slider_position_m"] == pytest.approx(2e-6, rel=1e-6)
    assert errors["peak_deflection_relative"] == pytest.approx(0.01)


def test_a_grid_case_refuses_a_changed_store_and_physics_it_lacks(tmp_path):
    from flex.data.reference_store import store_digest
    from flex.experiments.fitting.calibration import measure_case

    plate = derive_scene(default_scene(), ['coupler.geometry="plate"', 'coupler.model="ffrf"'])
    store = {"plate": _plate_reference(plate)}
    path = tmp_path / "refs.h5"
    write_store(path, store, {})
    changed = measure_case("p", plate, reference_store=path, reference_store_digest="0" * 64)
    assert changed.status == "failed" and "changed while the sweep ran" in changed.message
    thicker = derive_scene(plate, ["coupler.thickness_m=0.002"])
    lacking = measure_case("p", thicker, reference_store=path,
                           reference_store_digest=store_digest(read_store(path)))
    assert lacking.status == "failed" and "no stored reference" in lacking.message
