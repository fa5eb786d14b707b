"""Input the checks accept never ends in an internal error (exit 3).

- A budget's companion one rung up is a scene no check has seen: an exact-beam crank under
  a wing (the companion of an FFRF crank) failed deep in the builder ("marker 2
  (NodePosition) has no frame"); it is a SceneError now, and the budget says the model term
  was not measured and takes the measured fractions instead.
- A stubby exact beam (thickness half its length or more, which the range check accepts)
  had no element "away from the end faces" ("zero-size array"): the middle elements are.
- ``flex export`` / ``flex animate`` of a case whose motion series are missing or are not
  one finite row per stored time (``KeyError: 'time'``, broadcasting errors): refused in
  one line naming the dataset, as plot, compare and inspect refuse it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from hostile import assert_no_traceback, check_refused, run_cli

from flex.base.errors import EXIT_OK, SceneError


# --- a companion no check has seen ------------------------------------------------------------
def test_a_beam_crank_under_a_wing_is_a_scene_error_wherever_it_is_built():
    from flex.data.scene import apply_overrides, load_scene
    from flex.dynamics.mechanism import build_mechanism

    scene = apply_overrides(load_scene(), [  # what a companion gets: past every check
        'crank.model="exact_beam"', 'crank.geometry="plate"', 'coupler.model="exact_beam"',
        'coupler.geometry="plate"', "wing.enabled=true"])
    with pytest.raises(SceneError, match="carries no wing"):
        build_mechanism(scene)


@pytest.mark.parametrize("extra", [[], pytest.param(
    ["coupler.model=\"ffrf\"", "coupler.geometry=\"plate\"", "coupler.modes=2",
     "coupler.mesh_size_m=0.005", "coupler.thickness_m=0.005"], marks=pytest.mark.slow)],
    ids=["rigid-coupler", "ffrf-coupler"])
def test_an_ffrf_crank_with_a_wing_gets_its_budget_without_an_internal_error(tmp_path, extra):
    out = tmp_path / "run.h5"
    outcome = run_cli(["run", "simulate", "--out", str(out), "--no-figures", "--quiet",
                       "--set", 'crank.model="ffrf"', "--set", 'crank.geometry="plate"',
                       "--set", "crank.modes=2", "--set", "wing.enabled=true",
                       "--set", "simulation.end_time_s=0.002",
                       *[arg for item in extra for arg in ("--set", item)]])
    assert_no_traceback(outcome)
    assert outcome.status == EXIT_OK, outcome.stderr
    with h5py.File(out) as h5:
        method = str(h5["cases/case"].attrs["estimated_error_method"])
    assert "model: not measured on the scene" in method and "carries no wing" in method


# --- a stubby exact beam ----------------------------------------------------------------------
@pytest.mark.parametrize("elements", [1, 2, 3, 4, 7, 32])
@pytest.mark.parametrize("ratio", [0.3, 0.5, 0.5 + 1e-12, 0.7, 0.99])
def test_a_stubby_beam_has_its_stress_away_from_the_ends(elements, ratio):
    from flex.bodies.exact_beam import ExactBeamSection, section_datasets

    length = 0.08
    thickness, width = ratio * length, 0.01
    area, inertia = thickness * width, width * thickness**3 / 12
    section = ExactBeamSection(length, thickness, width, area, inertia, 2.1e11 * area,
                               2.1e11 * inertia, 8e10 * area, 7850 * area, 7850 * inertia)
    rng = np.random.default_rng(elements)
    force, moment = rng.normal(size=(5, elements, 2)), rng.normal(size=(5, elements))
    out = section_datasets("coupler", section, force, moment)
    peak = out["coupler/peak_von_mises_stress"].data
    assert peak.shape == (5,) and np.isfinite(peak).all() and (peak > 0).all()
    position = out["coupler/peak_von_mises_position"].data
    assert ((position > 0) & (position < length)).all()


def test_a_stubby_exact_beam_coupler_runs(tmp_path):
    outcome = run_cli(["run", "simulate", "--out", str(tmp_path / "run.h5"), "--no-figures",
                       "--quiet", "--set", 'coupler.model="exact_beam"', "--set",
                       'coupler.geometry="plate"', "--set", "coupler.thickness_m=0.04",
                       "--set", "coupler.elements=6", "--set", "simulation.end_time_s=0.002"])
    assert_no_traceback(outcome)
    assert outcome.status == EXIT_OK, outcome.stderr


# --- export and animate of an edited case -----------------------------------------------------
@pytest.fixture
def source(tiny_ffrf_file, tmp_path) -> Path:
    return Path(shutil.copy(tiny_ffrf_file, tmp_path / "plate.h5"))


def _edit(path: Path, name: str, how: str) -> None:
    with h5py.File(path, "r+") as h5:
        group = h5["cases/case"]
        old = group[name][()]
        del group[name]
        if how == "missing":
            return
        new = {"nan": lambda a: np.where(np.arange(a.size).reshape(a.shape) == 1, np.nan, a),
               "stacked": lambda a: np.stack([a, a], axis=-1),
               "text": lambda a: np.array([b"x"] * len(a)),
               "scalar": lambda a: a.flat[0]}[how](old)
        group.create_dataset(name, data=new)


@pytest.mark.parametrize("command", ["export", "animate"])
@pytest.mark.parametrize("name, how", [
    ("time", "missing"), ("crank/angle", "missing"), ("coupler/angle", "missing"),
    ("time", "nan"), ("crank/angle", "text"), ("coupler/frame_position", "stacked"),
    ("coupler/frame_position", "nan"), ("coupler/frame_angle", "stacked"),
    ("coupler/frame_angle", "scalar"), ("coupler/chord_change", "text"),
    ("coupler/modal_coordinates", "nan")])
def test_an_edited_case_is_refused_naming_the_dataset(source, tmp_path, command, name, how):
    _edit(source, name, how)
    out = tmp_path / ("out" if command == "export" else "a.gif")
    check_refused([command, str(source), "--out", str(out)], [name], watch=[source])
    assert not out.exists()
