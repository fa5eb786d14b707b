"""The last silent numbers: a quantity that did not happen, or that round-off made, or that
no model bounds, is never stated as if it were measured.

- A crank held by its damper never deploys: no deployment time (it was 2.06e-5 s +- 66 %:
  a step-scale wiggle within a creep), wherever the first maximum is read.
- A deflection within the round-off of the positions it is a difference of is missing (an
  exact beam run for 1e-9 s stated 9e-17 m "+- 0.062 %").
- A coupler compressed beyond its Euler load: an exact beam (or any body that buckles) gets
  a validity warning and no certificate on its own quantities; a rigid plate coupler no
  predicted bending ("nan +- nan" with raw scipy warnings) and a warning.
- A stored budget whose value is missing says so (it printed "nan m +- ..."); a stored
  certificate factor that cannot be used says so (the certificate vanished without a word).
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from hostile import assert_no_traceback, run_cli

from flex.base.errors import EXIT_OK
from flex.data.headlines import BUILTIN_HEADLINES, first_maximum_index
from flex.data.results import Dataset

SHORT = ["--set", "simulation.end_time_s=0.004"]


def _run(tmp_path: Path, *sets: str, name: str = "run") -> tuple[dict, str]:
    out = tmp_path / f"{name}.h5"
    argv = ["run", "simulate", "--out", str(out), "--no-figures", "--quiet"]
    for item in sets:
        argv += ["--set", item]
    outcome = run_cli(argv)
    assert_no_traceback(outcome)
    assert outcome.status == EXIT_OK, outcome.stderr
    assert "Warning" not in outcome.stderr, outcome.stderr  # no raw numpy/scipy warnings
    with h5py.File(out) as h5:
        attrs = dict(h5["cases/case"].attrs)
    inspect = run_cli(["inspect", str(out)])
    assert inspect.status == EXIT_OK and " nan " not in inspect.stdout, inspect.stdout
    return attrs, inspect.stdout


# --- a crank that never deploys ---------------------------------------------------------------
@pytest.mark.parametrize("damping", ["1e8", "1e9", "1e11"])
def test_a_crank_held_by_its_damper_has_no_deployment_time(tmp_path, damping):
    attrs, text = _run(tmp_path, f"drive.spring_damping_Ns_per_m={damping}",
                       "simulation.end_time_s=0.01")
    assert "headline_deployment_time_s" not in attrs
    assert "deployment time" not in text


def _creep_with_wiggle(samples: int = 400, amplitude: float = 1e-9, creep: float = 3e-8,
                       seed: int = 0) -> np.ndarray:
    """A crank held by its damper: a creep with an alternating step-scale wiggle on top."""
    rng = np.random.default_rng(seed)
    wiggle = amplitude * (-1.0) ** np.arange(samples) * np.exp(-np.arange(samples) / 20.0)
    return 0.5967 + np.linspace(0.0, creep, samples) + wiggle * rng.uniform(0.5, 1.5)


@pytest.mark.parametrize("seed", range(4))
def test_a_wiggle_on_a_creep_is_no_first_maximum(seed):
    assert first_maximum_index(_creep_with_wiggle(seed=seed)) is None


@pytest.mark.parametrize("wiggle", [0.0, 1e-5, 1e-4])
def test_a_deployment_keeps_its_first_maximum(wiggle):
    t = np.linspace(0.0, 1.0, 1001)
    angle = 0.6 + np.sin(np.pi * t / 0.6) + wiggle * np.sin(2 * np.pi * 40 * t)
    top = first_maximum_index(angle)
    assert top is not None and abs(t[top] - 0.3) < 0.02


# --- a deflection at round-off ----------------------------------------------------------------
@pytest.mark.parametrize("deflection, kept", [(9e-17, False), (1e-15, False), (1e-12, True),
                                              (1e-6, True)])
@pytest.mark.parametrize("name", ["coupler_deployment_peak_deflection_m",
                                  "coupler_first_crest_deflection_m", "coupler_peak_deflection_m"])
def test_a_deflection_within_round_off_is_missing(name, deflection, kept):
    time = np.linspace(0.0, 1e-3, 11)
    datasets = {"time": Dataset(time, "s"),
                "coupler/midpoint_position": Dataset(np.full((11, 2), 0.1), "m"),
                "coupler/midpoint_deflection": Dataset(deflection * np.sin(3e3 * time), "m")}
    value = BUILTIN_HEADLINES[name].read(datasets)
    assert (value is not None) is kept


@pytest.mark.parametrize("end", ["1e-9", "3e-9"])
def test_an_exact_beam_run_for_nanoseconds_states_no_deflection(tmp_path, end):
    attrs, text = _run(tmp_path, 'coupler.model="exact_beam"', 'coupler.geometry="plate"',
                       "coupler.elements=8", f"simulation.end_time_s={end}")
    assert not any("deflection" in key for key in attrs if key.startswith("headline_"))
    assert "midpoint deflection of the coupler over" not in text


# --- beyond the Euler load --------------------------------------------------------------------
@pytest.mark.parametrize("thickness", ["0.0003", "0.0002"])
def test_an_exact_beam_beyond_its_euler_load_is_warned_and_uncertified(tmp_path, thickness):
    attrs, text = _run(tmp_path, 'coupler.model="exact_beam"', 'coupler.geometry="plate"',
                       f"coupler.thickness_m={thickness}", "coupler.elements=8", *SHORT[1:])
    assert "Euler load" in attrs["validity_warning"] and "buckles" in attrs["validity_warning"]
    for name in ("coupler_deployment_peak_deflection_m", "coupler_deployment_peak_von_mises_Pa"):
        assert math.isnan(attrs[f"estimated_error_{name}"]), name
    assert "Euler load" in attrs["estimated_error_unknown"]
    assert "WARNING" in text and "certificate" not in text.split("deflection of the coupler "
                                                                 "over the deployment")[1][:200]


def test_an_exact_beam_below_its_euler_load_is_certified(tmp_path):
    attrs, _ = _run(tmp_path, 'coupler.model="exact_beam"', 'coupler.geometry="plate"',
                    "coupler.thickness_m=0.002", "coupler.elements=8", *SHORT[1:])
    assert "validity_warning" not in attrs
    assert math.isfinite(attrs["estimated_error_coupler_deployment_peak_deflection_m"])


@pytest.mark.parametrize("thickness", ["0.0003", "0.00025", "0.0001"])
def test_a_rigid_plate_beyond_its_euler_load_predicts_no_bending(tmp_path, thickness):
    attrs, text = _run(tmp_path, 'coupler.geometry="plate"', f"coupler.thickness_m={thickness}",
                       *SHORT[1:])
    assert not [key for key in attrs if key.startswith("predicted_coupler")]
    assert "buckle" in attrs["validity_warning"]
    assert "predicted coupler" not in text
    # its model term is the difference to an exact beam that buckles: not certified
    assert math.isnan(attrs["estimated_error_crank_angle_end_rad_model"])


def test_a_rigid_plate_below_its_euler_load_keeps_its_prediction(tmp_path):
    attrs, _ = _run(tmp_path, 'coupler.geometry="plate"', "coupler.thickness_m=0.002",
                    *SHORT[1:])
    assert math.isfinite(attrs["predicted_coupler_peak_deflection_m"])
    assert "validity_warning" not in attrs


# --- a stored budget that lacks a value or a usable certificate --------------------------------
@pytest.fixture(scope="module")
def budgeted(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("budget")
    _run(folder, "simulation.end_time_s=0.002")
    return folder / "run.h5"


def _edited(budgeted: Path, tmp_path: Path, **attrs) -> Path:
    path = Path(shutil.copy(budgeted, tmp_path / "edited.h5"))
    with h5py.File(path, "r+") as h5:
        case = h5["cases/case"].attrs
        for key, value in attrs.items():
            if value is None:
                del case[key]
            else:
                case[key] = value
    return path


@pytest.mark.parametrize("command", ["inspect", "report"])
def test_a_missing_headline_value_is_said_not_printed_as_nan(budgeted, tmp_path, command):
    path = _edited(budgeted, tmp_path, headline_crank_angle_end_rad=None)
    out = tmp_path / "r.md"
    outcome = run_cli([command, str(path), *(["--out", str(out)] if command == "report"
                                            else [])])
    assert outcome.status == EXIT_OK, outcome.stderr
    text = outcome.stdout if command == "inspect" else out.read_text()
    line = next(line for line in text.splitlines() if "crank angle at the end time" in line)
    assert "nan" not in line and "no value" in line, line


@pytest.mark.parametrize("factor", ["x", 0.5, -1.0, np.inf, np.array([1.25, 2.0])],
                         ids=["text", "below-1", "negative", "infinite", "array"])
@pytest.mark.parametrize("command", ["inspect", "report"])
def test_a_malformed_certificate_factor_is_said(budgeted, tmp_path, command, factor):
    path = _edited(budgeted, tmp_path, estimated_error_certificate_factor=factor)
    out = tmp_path / "r.md"
    outcome = run_cli([command, str(path), *(["--out", str(out)] if command == "report"
                                            else [])])
    assert_no_traceback(outcome)
    assert outcome.status == EXIT_OK, outcome.stderr
    text = outcome.stdout if command == "inspect" else out.read_text()
    assert "certificate_factor" in text and "unknown (malformed" in text


@pytest.mark.parametrize("sets, link, why", [
    (['coupler.geometry="plate"', "drive.spring_preload_m=0"], "coupler", "round-off"),
    (['coupler.geometry="plate"', "drive.spring_stiffness_N_per_m=0"], "coupler", "round-off"),
    (['crank.geometry="plate"', "crank.thickness_m=0.0001"], "crank", "buckles"),
    (['crank.geometry="plate"', "crank.thickness_m=0.00005",
      'coupler.geometry="plate"', "coupler.thickness_m=0.0002"], "crank", "buckles")],
    ids=["no-preload", "no-spring", "thin-crank", "thin-both"])
def test_a_rigid_link_s_prediction_is_none_where_it_would_mean_nothing(tmp_path, sets, link,
                                                                      why):
    attrs, text = _run(tmp_path, *sets, *SHORT[1:])
    assert not [key for key in attrs if key.startswith(f"predicted_{link}_")]
    assert f"none for the rigid {link}: " in text and why in text
