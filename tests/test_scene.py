"""Scene validation: every bad input is refused with one clear message before any run."""

import subprocess
import sys

import pytest

from flex.base.errors import SceneError
from flex.data.plates import plate_mass_properties
from flex.data.scene import SCHEMA, load_scene, to_toml


def test_default_scene_is_the_thesis_parameter_set():
    scene = load_scene()
    assert scene["crank"]["length_m"] == 0.040
    assert scene["coupler"]["mass_kg"] == 0.07767
    assert scene["slider"]["inertia_kgm2"] == 2.112e-5
    assert set(scene) == set(SCHEMA)


@pytest.mark.parametrize("override, fragment", [
    ("crank.foo=1", "unknown key crank.foo"),
    ("wheels.radius_m=1", "unknown section [wheels]"),
    ('crank.mass_kg="heavy"', "crank.mass_kg = 'heavy': must be a finite number > 0"),
    ("crank.mass_kg=-1", "must be a finite number > 0"),
    ("coupler.thickness_m=0", "coupler.thickness_m = 0: must be a finite number > 0"),
    ("crank.mass_kg=nan", "crank.mass_kg = nan"),
    ("coupler.modes=2.5", "must be an integer"),
    ("coupler.modes=true", "must be an integer"),
    ("drive.kind=rocket", 'must be one of "spring", "constant_speed"'),
    ("crank.length_m=0.1", "crank.length_m = 0.1 must be shorter than coupler.length_m"),
    ("slider.offset_m=0.05", "off the reachable range"),
    ("simulation.step_s=1", "must be <= simulation.end_time_s"),
    ("coupler.model=ffrf", 'needs coupler.geometry = "plate"'),
    ("coupler.poisson_ratio=0.5", "< 0.5"),
    ("crank", "expected section.key=value"),
])
def test_bad_overrides_are_refused_with_the_key_and_range(override, fragment):
    with pytest.raises(SceneError, match=None) as info:
        load_scene(overrides=[override])
    assert fragment in str(info.value)


def test_scene_file_merges_over_defaults_and_round_trips(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text("[crank]\nlength_m = 0.03\n")
    scene = load_scene(path)
    assert scene["crank"]["length_m"] == 0.03 and scene["coupler"]["length_m"] == 0.08
    again = tmp_path / "again.toml"
    again.write_text(to_toml(scene))
    assert load_scene(again) == scene


@pytest.mark.parametrize("content, fragment", [
    (b"[crank\nlength_m = 1", "not valid TOML"),
    (b"\xff\xfe[crank]", "not UTF-8"),
    (b"crank = 3", "must be a [section] table"),
])
def test_broken_scene_files(tmp_path, content, fragment):
    path = tmp_path / "bad.toml"
    path.write_bytes(content)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert fragment in str(info.value)


def test_missing_scene_file():
    with pytest.raises(SceneError, match="does not exist"):
        load_scene("no/such/file.toml")


def test_plate_mass_properties_closed_form():
    scene = load_scene(overrides=['coupler.geometry="plate"', "coupler.thickness_m=0.001"])
    mass_kg, inertia_kgm2 = plate_mass_properties(scene)
    assert mass_kg == pytest.approx(7850 * 0.08 * 0.01 * 0.001)
    assert inertia_kgm2 == pytest.approx(mass_kg * (0.08**2 + 0.001**2) / 12)


def test_cli_prints_one_line_and_no_traceback(tmp_path):
    result = subprocess.run([sys.executable, "-m", "flex", "run", "simulate", "--set",
                             "crank.length_m=0.2", "--out", str(tmp_path / "x.h5")],
                            capture_output=True, text=True)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert result.stderr.strip().splitlines() == [
        "flex: error: linkage cannot assemble: crank.length_m = 0.2 must be shorter than "
        "coupler.length_m = 0.08"]
    assert not (tmp_path / "x.h5").exists()


def test_cli_scene_prints_resolved_toml():
    result = subprocess.run([sys.executable, "-m", "flex", "scene", "kinematics"],
                            capture_output=True, text=True, check=True)
    assert 'kind = "constant_speed"' in result.stdout
    assert "end_time_s = 1.0" in result.stdout
