"""docs/example.py runs as users run it, and the public face (flex.__all__) keeps its word."""

import runpy
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import flex
from flex.base.errors import SceneError

EXAMPLE = Path(__file__).resolve().parents[1] / "docs" / "example.py"


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    saved = tempfile.tempdir  # the example's tempfile.mkdtemp() lands in pytest's tmp tree
    tempfile.tempdir = str(tmp_path_factory.mktemp("example"))
    try:
        return runpy.run_path(str(EXAMPLE), run_name="__main__")
    finally:
        tempfile.tempdir = saved


def test_example_peaks_match_the_reference_dae(example):
    from flex.dynamics.reference import solve_reference

    for label, scene in (("22 mm", example["scene"]), ("11 mm", example["soft"])):
        reference = solve_reference(scene).q_dot[:, 2].max()  # independent 9-coordinate DAE
        assert example["peaks"][label] == pytest.approx(reference, abs=0.1), label
    # thesis-datasheet.md checks: 60.7 rad/s (22 mm preload), 32.4 rad/s (11 mm)
    assert example["peaks"]["22 mm"] == pytest.approx(60.7, abs=0.05)
    assert example["peaks"]["11 mm"] == pytest.approx(32.4, abs=0.05)


def test_example_result_file_opens_as_xarray(example):
    ds = example["ds"]
    assert ds["crank/angular_velocity"].attrs["units"] == "rad/s"
    assert float(ds["crank/angular_velocity"].max()) == pytest.approx(
        example["peaks"]["11 mm"], abs=1e-9)  # the file holds the run simulate() made
    assert ds["time"].attrs["units"] == "s" and float(ds["time"][-1]) == pytest.approx(0.03)


def test_import_flex_is_light():
    code = ("import sys, flex; heavy = [m for m in ('exudyn', 'ngsolve', 'h5py', 'scipy', "
            "'flex.dynamics.solver', 'flex.study') if m in sys.modules]; print(heavy)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


def test_public_names_have_contracts():
    for name in flex.__all__:
        value = getattr(flex, name)
        if name != "__version__":
            assert value.__doc__ and len(value.__doc__) > 40, name
    for name in ("load_scene", "derive_scene", "simulate", "run_study", "open_result"):
        doc = getattr(flex, name).__doc__
        assert "Inputs:" in doc and "Output:" in doc and "Errors:" in doc, name
    with pytest.raises(AttributeError):
        flex.no_such_name  # noqa: B018


def test_derive_scene_list_and_dict_agree_and_leave_the_input_alone():
    scene = flex.load_scene()
    by_list = flex.derive_scene(scene, ["drive.spring_preload_m=0.011", "coupler.model=ffrf",
                                        "coupler.geometry=plate"])
    by_dict = flex.derive_scene(scene, {"drive.spring_preload_m": np.float64(0.011),
                                        "coupler": {"model": "ffrf", "geometry": "plate"}})
    assert by_list == by_dict
    assert by_list["drive"]["spring_preload_m"] == 0.011
    assert scene["drive"]["spring_preload_m"] == 0.022 and scene["coupler"]["model"] == "rigid"


@pytest.mark.parametrize("overrides, message", [
    ({"crank.length_m": 0.2}, "linkage cannot assemble"),
    ({"drive.no_such_key": 1.0}, "unknown key"),
    ({"drive.spring_preload_m": float("nan")}, "spring_preload_m"),
    ({"preload": 0.01}, "section.key"),
    (["drive.spring_preload_m"], "section.key=value"),
])
def test_derive_scene_refuses_bad_overrides(overrides, message):
    with pytest.raises(SceneError, match=message):
        flex.derive_scene(flex.load_scene(), overrides)


def test_derive_scene_wants_a_list_or_dict():
    with pytest.raises(TypeError):
        flex.derive_scene(flex.load_scene(), "drive.spring_preload_m=0.011")
