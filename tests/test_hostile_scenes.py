"""Hostile scenes: every bad scene is refused up front with one line, nothing is lost or silent.

Each refusal runs the command line in process (:mod:`tests.hostile`): no traceback, exit
status 2, exactly one ``flex: error:`` line naming the key (or file) at fault and no watched
file changed. Most cases go through ``flex scene simulate --set ...`` (no simulation); some
through ``flex run simulate`` with an earlier result file that must stay as it was.

Classes: every scene key with a wrong type; out of range; NaN, inf and huge numbers;
impossible geometry; settings that cannot mean anything once ``"auto"`` is resolved (step
count, irregular samples, an aliased crank); meshed plates that make no sense or that this
machine cannot mesh (estimated before any meshing); malformed scene files. Then what a run
that is not refused must not hide: honest divergence advice, the linear-FFRF validity
warning, keys a scene's models do not use (:mod:`flex.config.usage`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hostile import check_refused, run_cli

from flex.base.errors import SceneError, SimulationError
from flex.config.usage import explicit_keys, unused_keys
from flex.data.plates import estimate_mesh
from flex.data.results import CaseResult, Dataset, write_results
from flex.data.scene import SCHEMA, load_scene
from flex.dynamics.advice import VALIDITY_WARNING, check_finite, divergence_advice, validity_warning
from flex.fidelity.auto import check as check_runnable
from flex.fidelity.simulation import simulate_case

PLATE = ["--set", 'coupler.geometry="plate"', "--set", 'coupler.model="ffrf"']


def scene_cmd(*sets: str) -> list[str]:
    argv = ["scene", "simulate"]
    for item in sets:
        argv += ["--set", item]
    return argv


# ------------------------------------------------------------------------------------------
# every key with a wrong type
# ------------------------------------------------------------------------------------------
def _wrong_type(field) -> str:
    if isinstance(field.kind, tuple):
        return '"Rigid-ish"' if "rigid" in field.kind else "1"
    if field.kind is bool:
        return '"yes"'
    if field.kind is int:
        return "2.5"
    return '"0.04"'


WRONG_TYPES = [(f"{section}.{key}", _wrong_type(field))
               for section, fields in SCHEMA.items() for key, field in fields.items()]


@pytest.mark.parametrize("name, value", WRONG_TYPES, ids=[n for n, _ in WRONG_TYPES])
def test_every_key_with_a_wrong_type_is_refused(name, value):
    outcome = check_refused(scene_cmd(f"{name}={value}"), [name, "must be"])
    assert "true or false" in outcome.stderr or "one of" in outcome.stderr \
        or "integer" in outcome.stderr or "finite number" in outcome.stderr \
        or "a list of one or more" in outcome.stderr


# ------------------------------------------------------------------------------------------
# out of range, NaN, inf, huge numbers
# ------------------------------------------------------------------------------------------
def _out_of_range(field) -> str:
    if field.positive:
        return "0"
    if field.minimum is not None:
        return repr(field.minimum - 1.0)
    if field.maximum is not None:
        return repr(field.maximum * 2 + 1)
    if field.below is not None:
        return repr(field.below)
    return "inf"


NUMERIC = [(f"{section}.{key}", field) for section, fields in SCHEMA.items()
           for key, field in fields.items() if field.kind in (float, int)]
OUT_OF_RANGE = [(name, _out_of_range(field)) for name, field in NUMERIC]
#: (key, value): non-finite and absurd numbers, cycled over the numeric keys
ABSURD_VALUES = ["nan", "-inf", "1e999", "9" * 400, "-" + "9" * 400, "-nan", "+inf",
                 "9" * 5000]
ABSURD = [(name, ABSURD_VALUES[index % len(ABSURD_VALUES)])
          for index, (name, _) in enumerate(NUMERIC)]


@pytest.mark.parametrize("name, value", OUT_OF_RANGE, ids=[n for n, _ in OUT_OF_RANGE])
def test_every_number_out_of_range_is_refused_with_the_range(name, value):
    outcome = check_refused(scene_cmd(f"{name}={value}"), [name, "must be"])
    assert any(word in outcome.stderr for word in (">", "<", "finite", "integer"))


@pytest.mark.parametrize("name, value", ABSURD, ids=[f"{n}={v[:6]}" for n, v in ABSURD])
def test_non_finite_and_huge_numbers_are_refused(name, value):
    outcome = check_refused(scene_cmd(f"{name}={value}"), [name])
    assert len(outcome.stderr) < 1500  # a 5000-digit value is not echoed in full


@pytest.mark.parametrize("override, names", [
    ("crank", ["section.key=value"]),
    ("=1", ["section.key=value"]),
    (".length_m=1", ["unknown section"]),
    ("crank.=1", ["unknown key"]),
    ("crank.length_m.extra=1", ["crank.length_m.extra"]),
    ("crank.length_m=[0.04, 0.05]", ["crank.length_m"]),
    ("crank.length_m={a = 1}", ["crank.length_m"]),
    ("crank.length_m=1979-05-27", ["crank.length_m"]),
    ("crank.length_m=0x7fffffff", ["crank.length_m"]),
    ('crank.model="rigid\\n"', ["crank.model"]),
    ("wheels.radius_m=1", ["wheels"]),
    ("simulation.step_s=AUTO", ["simulation.step_s", "auto"]),
])
def test_malformed_overrides_are_refused(override, names):
    check_refused(scene_cmd(override), names)


# ------------------------------------------------------------------------------------------
# impossible geometry and incompatible choices
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("sets, names", [
    (["crank.length_m=0.08"], ["crank.length_m", "coupler.length_m"]),
    (["crank.length_m=0.2"], ["crank.length_m", "shorter"]),
    (["slider.offset_m=0.045"], ["slider.offset_m"]),
    (["slider.offset_m=-0.04"], ["slider.offset_m"]),
    (['coupler.model="ffrf"'], ["coupler.geometry"]),
    (['coupler.model="nonlinear_fe"'], ["coupler.geometry"]),
    (['coupler.model="auto"'], ["coupler.geometry"]),
    (['crank.model="ffrf"'], ["crank.geometry"]),
    (['crank.geometry="plate"', 'crank.model="ffrf"', 'drive.kind="constant_speed"'],
     ["crank.model", "drive.kind"]),
    (['crank.model="auto"', 'drive.kind="constant_speed"'], ["crank.model", "drive.kind"]),
    (['coupler.geometry="plate"', 'coupler.model="nonlinear_fe"', "coupler.damping_ratio=0.1"],
     ["coupler.damping_ratio"]),
    (['simulation.integrator="explicit_penalty"', 'coupler.geometry="plate"',
      'coupler.model="ffrf"'], ["simulation.integrator"]),
    (['simulation.integrator="explicit_penalty"', 'drive.kind="constant_speed"'],
     ["simulation.integrator"]),
    (['coupler.geometry="plate"', "coupler.thickness_m=0.08"], ["coupler.thickness_m"]),
    (['crank.geometry="plate"', "crank.thickness_m=0.05"], ["crank.thickness_m"]),
    (["simulation.step_s=0.1"], ["simulation.step_s", "end_time_s"]),
    (["simulation.step_s=1e-4", "simulation.output_step_s=1e-5"],
     ["simulation.output_step_s", "simulation.step_s"]),
])
def test_impossible_geometry_and_choices_are_refused(sets, names):
    check_refused(scene_cmd(*sets), names)


# ------------------------------------------------------------------------------------------
# meaningless settings: step count, irregular samples, aliased crank (explicit step)
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("sets, names", [
    (["simulation.end_time_s=1e6", "simulation.step_s=1e-5"],
     ["simulation.end_time_s", "steps", "5e+07", "end_time_s <= 500"]),
    (["simulation.end_time_s=1e3", "simulation.step_s=1e-6"], ["simulation.end_time_s"]),
    (["simulation.step_s=1e-5", "simulation.output_step_s=2.5e-5"],
     ["simulation.output_step_s", "multiple", "2e-05", "3e-05"]),
    (["simulation.step_s=4e-4", "simulation.output_step_s=1e-3"],
     ["simulation.output_step_s", "0.0008", "0.0012"]),
    (["simulation.step_s=3e-5", "simulation.output_step_s=1e-4"],
     ["simulation.output_step_s", "9e-05", "0.00012"]),
    (['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=1e6",
      "simulation.step_s=1e-5"], ["drive.crank_speed_rad_per_s", "0.1 rad per step"]),
    (['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=-2e4",
      "simulation.step_s=1e-5"], ["drive.crank_speed_rad_per_s", "aliased"]),
    (['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=100",
      "simulation.step_s=1e-4", "simulation.output_step_s=0.01"],
     ["simulation.output_step_s", "aliased"]),
])
def test_meaningless_step_settings_are_refused(sets, names):
    check_refused(scene_cmd(*sets), names)


@pytest.mark.parametrize("sets, names", [
    (["simulation.end_time_s=1e6"], ["simulation.end_time_s", "step_s = \"auto\""]),
    (["simulation.output_step_s=2.5e-5"], ["simulation.output_step_s", "2e-05", "3e-05"]),
    (['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=1e6"],
     ["drive.crank_speed_rad_per_s", "0.1 rad"]),
    (['coupler.geometry="plate"', 'coupler.model="auto"', "simulation.end_time_s=1e4"],
     ["simulation.end_time_s", "auto"]),
])
def test_auto_resolved_settings_are_refused_by_check_runnable(sets, names):
    scene = load_scene(overrides=sets)  # valid as written: "auto" is resolved later
    with pytest.raises(SceneError) as error:
        check_runnable(scene)
    for name in names:
        assert name in str(error.value)
    assert "\n" not in str(error.value)


def test_check_runnable_passes_the_bundled_scene_and_the_studies_cases():
    from studies import crank, flexible, kfit, stability

    check_runnable(load_scene())
    for module in (stability, kfit, flexible, crank):
        base = load_scene(None, list(getattr(module, "OVERRIDES", [])))
        for case in module.cases(base).values():
            check_runnable(case)


def test_auto_model_refused_only_when_every_choice_fails():
    # the certified FFRF plate runs at 4e-4 s, the rigid model at 1e-5 s: an output
    # interval of 1e-3 s suits only... neither (2.5 steps of 4e-4), 1e-4 suits the rigid one
    auto = ['coupler.geometry="plate"', 'coupler.model="auto"']
    check_runnable(load_scene(overrides=auto + ["simulation.output_step_s=1e-4"]))
    with pytest.raises(SceneError, match="for every model"):
        check_runnable(load_scene(overrides=auto + ["simulation.output_step_s=1.5e-5"]))


# ------------------------------------------------------------------------------------------
# meshed plates: meaningless or beyond this machine, refused before any meshing
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("sets, names", [
    (["coupler.thickness_m=1e-6", "coupler.mesh_size_m=0.002"],
     ["coupler.thickness_m", "8e-05"]),
    (["coupler.thickness_m=5e-5"], ["coupler.thickness_m", "foil"]),
    (["coupler.thickness_m=0.0001", "coupler.mesh_size_m=0.005"],
     ["coupler.mesh_size_m", "20 x", "0.002"]),
    (["coupler.width_m=5e-5", "coupler.mesh_size_m=0.002"],
     ["coupler.mesh_size_m", "coupler.width_m"]),
    (["coupler.thickness_m=0.045", "coupler.mesh_size_m=0.01"],
     ["coupler.thickness_m", "0.04"]),
    (["coupler.mesh_size_m=1.0"], ["coupler.mesh_size_m", "coupler.length_m"]),
    (["coupler.mesh_size_m=1e-6"], ["coupler.mesh_size_m", "GiB", "DOF"]),
    (["coupler.mesh_size_m=1e-5"], ["coupler.mesh_size_m", "GiB"]),
    (["coupler.width_m=10"], ["coupler.mesh_size_m", "GiB", "10 m"]),
    (["coupler.width_m=1", "coupler.length_m=0.5", "coupler.mesh_size_m=0.001"],
     ["coupler.mesh_size_m", "GiB"]),
])
def test_meshed_plates_that_mean_nothing_or_cannot_be_meshed_are_refused(sets, names):
    sets = [s for pair in zip(["--set"] * len(sets), sets, strict=True) for s in pair]
    check_refused(["scene", "simulate", *PLATE, *sets], names)


@pytest.mark.parametrize("sets, names", [
    (['coupler.geometry="plate"', 'coupler.model="nonlinear_fe"', "coupler.mesh_size_m=2e-5"],
     ["coupler.mesh_size_m", "nonlinear_fe"]),
    (['coupler.geometry="plate"', 'coupler.model="auto"', "coupler.mesh_size_m=2e-5"],
     ["coupler.mesh_size_m", "auto"]),
    (['crank.model="auto"', "crank.mesh_size_m=1e-5"], ["crank.mesh_size_m", "auto"]),
    (['crank.model="auto"', "crank.mass_kg=1e-6"], ["crank.mass_kg", "auto"]),
    (['crank.geometry="plate"', 'crank.model="ffrf"', "crank.thickness_m=0.00001"],
     ["crank.thickness_m"]),
])
def test_every_meshed_link_is_checked(sets, names):
    check_refused(scene_cmd(*sets), names)


def test_mesh_estimate_matches_its_calibration():
    # measured (MeshEstimate docstring): 1 x 10 mm plates at 2, 1, 0.5 mm; 3 x 10 at 0.7 mm
    for thickness, mesh, dof in ((1e-3, 2e-3, 9627), (1e-3, 1e-3, 35805),
                                 (1e-3, 5e-4, 143670), (3e-3, 7e-4, 175212)):
        estimate = estimate_mesh(0.08, thickness, 0.01, mesh)
        assert 0.8 < estimate.dof / dof < 1.3, (thickness, mesh, estimate)
    assert estimate_mesh(0.08, 1e-3, 0.01, 2e-3).memory_bytes < 0.5e9
    assert estimate_mesh(0.08, 1e-3, 10.0, 2e-3).memory_bytes > 16 * 2**30


@pytest.mark.slow
def test_mesh_estimate_against_a_fresh_netgen_mesh():
    from flex.bodies.plate import plate_mesh

    for thickness, width, mesh in ((0.002, 0.01, 0.0015), (0.0005, 0.03, 0.003)):
        elements = plate_mesh(0.08, thickness, width, mesh).ne
        estimate = estimate_mesh(0.08, thickness, width, mesh).elements
        assert 0.5 < estimate / elements < 2.0, (thickness, width, mesh, elements, estimate)


# ------------------------------------------------------------------------------------------
# malformed scene files
# ------------------------------------------------------------------------------------------
FILES = {
    "binary": (bytes(range(256)) * 3, ["binary.toml", "UTF-8"]),
    "utf16": ("[crank]\nlength_m = 0.03\n".encode("utf-16"), ["utf16.toml", "UTF-8"]),
    "bom_inside": (b"[crank]\nlength_m = 0.03\xef\xbb\xbf\n", ["bom_inside.toml", "TOML"]),
    "nul": (b"[crank]\nlength_m = 0.03\x00\n", ["nul.toml", "TOML"]),
    "duplicate_key": (b"[crank]\nlength_m = 0.03\nlength_m = 0.02\n",
                      ["duplicate_key.toml", "TOML"]),
    "duplicate_table": (b"[crank]\nlength_m = 0.03\n[crank]\nmass_kg = 1.0\n",
                        ["duplicate_table.toml", "TOML"]),
    "array_for_number": (b"[crank]\nlength_m = [0.03]\n", ["crank.length_m"]),
    "table_for_number": (b"[crank]\nlength_m = {value = 0.03}\n", ["crank.length_m"]),
    "nested_table": (b"[crank.sub]\nx = 1\n", ["crank.sub"]),
    "array_of_tables": (b"[[crank]]\nlength_m = 0.03\n", ["crank", "section"]),
    "top_level_value": (b'title = "mine"\n', ["title", "section"]),
    "unknown_section": (b"[wheels]\nradius_m = 0.1\n", ["wheels"]),
    "unknown_key": (b"[crank]\nlength_mm = 40\n", ["crank.length_mm"]),
    "control_key": (b'[crank]\n"a\\u001b[31mb" = 1\n', ["unknown key"]),
    "deep_nesting": (b"[crank]\nlength_m = " + b"[" * 5000 + b"]" * 5000 + b"\n",
                     ["deep_nesting.toml"]),
    "syntax": (b"[crank\nlength_m = 0.03\n", ["syntax.toml", "TOML"]),
    "string_number": (b'[simulation]\nend_time_s = "0.03"\n', ["simulation.end_time_s"]),
    "nan": (b"[simulation]\nend_time_s = nan\n", ["simulation.end_time_s"]),
    "bad_choice": (b'[coupler]\nmodel = "FFRF"\n', ["coupler.model"]),
    "geometry": (b"[crank]\nlength_m = 0.1\n", ["crank.length_m"]),
    "aliased": (b'[drive]\nkind = "constant_speed"\ncrank_speed_rad_per_s = 1e5\n'
                b"[simulation]\nstep_s = 1e-4\n", ["drive.crank_speed_rad_per_s"]),
    "foil": (b'[coupler]\ngeometry = "plate"\nmodel = "ffrf"\nthickness_m = 1e-6\n',
             ["coupler.thickness_m"]),
}


@pytest.mark.parametrize("label", list(FILES))
def test_malformed_scene_files_are_refused(tmp_path, label):
    content, names = FILES[label]
    path = tmp_path / f"{label}.toml"
    path.write_bytes(content)
    check_refused(["scene", "simulate", "--scene", str(path)], names, watch=[path])


def test_scene_file_problems_without_content(tmp_path):
    check_refused(["scene", "simulate", "--scene", str(tmp_path / "missing.toml")],
                  ["missing.toml", "does not exist"])
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    check_refused(["scene", "simulate", "--scene", str(folder)], ["folder.toml"])
    check_refused(["scene", "simulate", "--scene", "no_such_parameter_set"],
                  ["no_such_parameter_set", "bundled"])


def test_a_utf8_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf[crank]\nlength_m = 0.03\n")
    assert load_scene(path)["crank"]["length_m"] == 0.03


# ------------------------------------------------------------------------------------------
# refused by flex run: the earlier result file stays as it was
# ------------------------------------------------------------------------------------------
@pytest.fixture
def previous(tmp_path) -> Path:
    path = tmp_path / "x.h5"
    case = CaseResult("case", "", {"time": Dataset(np.linspace(0.0, 1.0, 11), "s", "time")})
    write_results(path, "simulate", [case])
    return path


RUN_REFUSED = [
    (["crank.length_m=nan"], ["crank.length_m"]),
    (['coupler.model="ffrf"'], ["coupler.geometry"]),
    (["simulation.end_time_s=1e6", "simulation.step_s=1e-5"], ["simulation.end_time_s"]),
    (["simulation.step_s=1e-5", "simulation.output_step_s=2.5e-5"],
     ["simulation.output_step_s"]),
    (['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=1e6",
      "simulation.step_s=1e-5"], ["drive.crank_speed_rad_per_s"]),
    (['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.mesh_size_m=1e-6"],
     ["coupler.mesh_size_m", "GiB"]),
    (['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.width_m=10"],
     ["coupler.mesh_size_m", "GiB"]),
    (['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=1e-6"],
     ["coupler.thickness_m"]),
]
RUN_REFUSED_AFTER_AUTO = [
    (["simulation.end_time_s=1e6"], ["simulation.end_time_s", "steps"]),
    (["simulation.output_step_s=2.5e-5"], ["simulation.output_step_s"]),
    (['drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=1e6"],
     ["drive.crank_speed_rad_per_s"]),
    (['coupler.geometry="plate"', 'coupler.model="auto"', "simulation.end_time_s=1e4"],
     ["simulation.end_time_s"]),
]


def _run_argv(out: Path, sets: list[str]) -> list[str]:
    argv = ["run", "simulate", "--no-figures", "--out", str(out)]
    for item in sets:
        argv += ["--set", item]
    return argv


@pytest.mark.parametrize("sets, names", RUN_REFUSED, ids=[s[-1] for s, _ in RUN_REFUSED])
def test_run_refuses_up_front_and_keeps_the_result_file(previous, sets, names):
    check_refused(_run_argv(previous, sets), names, watch=[previous.parent])


@pytest.mark.parametrize("sets, names", RUN_REFUSED_AFTER_AUTO,
                         ids=[s[-1] for s, _ in RUN_REFUSED_AFTER_AUTO])
def test_run_refuses_what_auto_resolution_makes_meaningless(previous, sets, names):
    check_refused(_run_argv(previous, sets), names, watch=[previous.parent])


# ------------------------------------------------------------------------------------------
# a run that is not refused hides nothing: divergence advice, validity warning
# ------------------------------------------------------------------------------------------
def _diverged(sets: list[str]) -> str:
    case = simulate_case(load_scene(overrides=["simulation.end_time_s=0.01", *sets]), "c")
    assert case.status == "failed" and not case.datasets
    assert "\n" not in case.message
    return case.message


def test_an_absurd_input_is_named_not_the_step():
    message = _diverged(["simulation.newton_relative_tolerance=1e-16"])
    assert "smaller simulation.step_s is unlikely to help" in message
    assert "try a smaller" not in message
    assert "simulation.newton_relative_tolerance = 1e-16" in message


def test_an_unresolved_time_scale_asks_for_a_smaller_step_and_names_the_cause():
    message = _diverged(["drive.spring_stiffness_N_per_m=1e15"])
    assert "try a smaller simulation.step_s" in message
    assert "drive.spring_stiffness_N_per_m = 1e+15" in message


def test_massless_links_are_named():
    message = _diverged(["slider.mass_kg=1e-12", "coupler.mass_kg=1e-12",
                         "coupler.inertia_kgm2=1e-18", "crank.mass_kg=1e-12",
                         "crank.inertia_kgm2=1e-18"])
    assert "extreme inputs:" in message and "inertia_kgm2 = 1e-18" in message


def test_check_finite_advice_follows_the_scene():
    scene = load_scene(overrides=["simulation.step_s=1e-5"])
    time_s = np.arange(11) * 1e-5
    data = {"time": Dataset(time_s, "s"), "constraint_norm": Dataset(np.full(11, 1.0), "m")}
    with pytest.raises(SimulationError) as error:
        check_finite(data, {"step_s": 1e-5}, scene)
    assert "unlikely to help" in str(error.value)
    assert "no input is 100x" in str(error.value)
    coarse = load_scene(overrides=["simulation.step_s=0.01", "simulation.end_time_s=0.03"])
    assert divergence_advice(coarse).startswith("try a smaller simulation.step_s")
    rho1 = load_scene(overrides=["simulation.step_s=1e-5", "simulation.spectral_radius=1.0"])
    assert "spectral_radius = 1" in divergence_advice(rho1)


def test_linear_ffrf_beyond_its_validity_is_flagged():
    scene = load_scene(overrides=['coupler.geometry="plate"', 'coupler.model="ffrf"'])
    small = {"coupler/midpoint_deflection": Dataset(np.array([0.0, 1e-4, -5e-4]), "m")}
    large = {"coupler/midpoint_deflection": Dataset(np.array([0.0, 1e-4, -1.2e-3]), "m")}
    assert validity_warning(scene, small) == ""
    warning = validity_warning(scene, large)
    assert "coupler" in warning and "1.5 %" in warning and "nonlinear_fe" in warning
    rigid = load_scene()
    assert validity_warning(rigid, large) == ""
    assert VALIDITY_WARNING == "validity_warning"


@pytest.mark.slow
def test_a_thin_ffrf_plate_run_carries_the_validity_warning(reduction_cache):
    # 0.3 mm plate: its deflection reaches ~4 x its thickness, 1.5 % of the length
    scene = load_scene(overrides=['coupler.geometry="plate"', 'coupler.model="ffrf"',
                                  "coupler.thickness_m=0.0003", "coupler.mesh_size_m=0.006",
                                  "simulation.end_time_s=0.01", "simulation.step_s=1e-5"])
    case = simulate_case(scene, "thin", cache_dir=reduction_cache)
    assert case.status == "ok"
    warning = case.attrs[VALIDITY_WARNING]  # the deflection beyond the body's trusted range
    assert "beyond the 1 % within which the FFRF body" in warning
    assert 'coupler.model = "nonlinear_fe"' in warning


# ------------------------------------------------------------------------------------------
# keys the models do not use, keys the user gave
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("sets, unused, used", [
    ([], ["coupler.thickness_m", "crank.mesh_size_m", "wing.span_m",
          "drive.crank_speed_rad_per_s", "simulation.penalty_stiffness_N_per_m"],
     ["coupler.mass_kg", "drive.spring_preload_m", "fidelity.tolerance"]),
    # the tolerance is read by every run's budget (what it covered), not without one
    (["simulation.error_estimate=false"], ["fidelity.tolerance", "fidelity.quantities"], []),
    (['coupler.geometry="plate"'], ["coupler.mass_kg", "coupler.youngs_modulus_Pa"],
     ["coupler.thickness_m", "coupler.density_kg_per_m3"]),
    (['coupler.geometry="plate"', 'coupler.model="ffrf"'], ["coupler.inertia_kgm2"],
     ["coupler.modes", "coupler.mesh_size_m", "fidelity.tolerance"]),
    (['coupler.geometry="plate"', 'coupler.model="nonlinear_fe"'],
     ["coupler.modes", "coupler.damping_ratio"], ["coupler.mesh_size_m"]),
    (['coupler.geometry="plate"', 'coupler.model="auto"'], ["coupler.modes"],
     ["coupler.damping_ratio", "fidelity.tolerance"]),
    (['crank.model="auto"'], ["crank.thickness_m", "crank.modes"],
     ["crank.mass_kg", "crank.mesh_size_m", "crank.density_kg_per_m3"]),
    (['drive.kind="constant_speed"'], ["drive.spring_stiffness_N_per_m"],
     ["drive.crank_speed_rad_per_s"]),
    (['simulation.integrator="explicit_penalty"'],
     ["simulation.spectral_radius", "simulation.newton_relative_tolerance"],
     ["simulation.explicit_method", "simulation.penalty_stiffness_N_per_m"]),
    (["wing.enabled=true"], ["wing.youngs_modulus_Pa"], ["wing.span_m", "wing.enabled"]),
])
def test_unused_keys_name_what_would_use_them(sets, unused, used):
    keys = unused_keys(load_scene(overrides=sets))
    for name in unused:
        assert name in keys and keys[name], name
    for name in used:
        assert name not in keys, name
    assert set(keys) <= {f"{s}.{k}" for s, fields in SCHEMA.items() for k in fields}


def test_a_study_may_declare_the_keys_it_reads():
    scene = load_scene()
    assert "coupler.thickness_m" in unused_keys(scene)
    assert "coupler.thickness_m" not in unused_keys(scene, {"coupler.thickness_m"})


def test_explicit_keys_are_the_set_keys_and_the_file_changes(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text("[crank]\nlength_m = 0.03\nmass_kg = 0.01432\n[drive]\nkind = \"spring\"\n")
    given = explicit_keys(path, ["coupler.thickness_m=0.003", "crank.model=rigid",
                                 "coupler.thickness_m=0.004"])
    assert given == {"crank.length_m": 0.03, "coupler.thickness_m": 0.004,
                     "crank.model": "rigid"}
    assert explicit_keys() == {} and explicit_keys("cavezza2012", []) == {}
    assert math.isclose(explicit_keys(None, ["simulation.step_s=1e-5"])["simulation.step_s"],
                        1e-5)


def test_hostile_case_count():
    count = (len(WRONG_TYPES) + len(OUT_OF_RANGE) + len(ABSURD) + len(FILES)
             + len(RUN_REFUSED) + len(RUN_REFUSED_AFTER_AUTO))
    assert count >= 120, count


def test_flex_scene_still_prints_a_valid_scene():
    outcome = run_cli(["scene", "simulate", "--set", "simulation.step_s=1e-5",
                       "--set", "simulation.output_step_s=3e-5"])
    assert outcome.status == 0 and "output_step_s = 3e-05" in outcome.stdout
