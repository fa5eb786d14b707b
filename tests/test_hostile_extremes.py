"""Physical extremes, long work, tolerances beyond reach and messages that must be right.

- Physical extremes end in a refusal naming the key and its range, or in a run, never in an
  internal error: a material density no solid has, a plate as thick as half its length,
  ``flex design`` with a spring that stores no energy.
- Long work says what it costs before it starts and how far it is while it runs: a
  reduction to many modes, an integration of tens of millions of steps, a tolerance no model
  is certified to, ``flex design``'s cases one by one.
- A quantity that did not happen within a run is missing, not the end time (``flex design``).
- Messages say what is true: the error estimate's companion steps, ``inspect`` with a
  ``[i]`` column as its help promises.
"""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
from hostile import check_refused, run_cli

from flex.base.progress import Progress, duration_text, heartbeat
from flex.config.settings import tolerance_beyond_reach
from flex.data.plates import estimate_mesh, modes_cost_factor
from flex.data.results import CaseResult, Dataset, write_results
from flex.data.scene import load_scene

PLATE = ['coupler.geometry="plate"', 'coupler.model="ffrf"']


def scene_argv(*sets: str) -> list[str]:
    argv = ["scene", "simulate"]
    for item in sets:
        argv += ["--set", item]
    return argv


# --- physical extremes ----------------------------------------------------------------------
DENSITIES = [(key, value) for key in ("coupler.density_kg_per_m3", "crank.density_kg_per_m3")
             for value in ("1e-3", "0.5", "2e5", "1e30")]


@pytest.mark.parametrize("key, value", DENSITIES, ids=[f"{k}={v}" for k, v in DENSITIES])
def test_a_density_no_solid_has_is_refused_with_its_range(key, value):
    link = key.split(".")[0]
    sets = {"coupler": PLATE, "crank": ['crank.geometry="plate"', 'crank.model="ffrf"']}[link]
    check_refused(scene_argv(*sets, f"{key}={value}"), [key, ">= 1", "<= 100000"])


def test_a_plate_as_thick_as_half_its_length_runs(tmp_path):
    outcome = run_cli(["run", "simulate", "--no-figures", "--out", str(tmp_path / "thick.h5"),
                       *[x for s in PLATE + ["coupler.thickness_m=0.04", "coupler.modes=1",
                                             "coupler.mesh_size_m=0.01",
                                             "simulation.end_time_s=0.0005",
                                             "simulation.step_s=1e-4",
                                             "simulation.error_estimate=false"]
                         for x in ("--set", s)]])
    assert outcome.status == 0 and "internal error" not in outcome.stderr, outcome.stderr


@pytest.mark.parametrize("argv, words", [
    (["--vary", "preload", "--peak-speed", "50", "--set", "drive.spring_stiffness_N_per_m=0"],
     ["--vary preload", "drive.spring_stiffness_N_per_m = 0", "no energy"]),
    (["--vary", "rate", "--peak-speed", "50", "--set", "drive.spring_preload_m=0"],
     ["--vary rate", "drive.spring_preload_m = 0", "no energy"]),
    (["--vary", "angle", "--final-angle", "60", "--set", 'drive.kind="constant_speed"',
      "--set", "drive.crank_speed_rad_per_s=6.28"], ["drive.kind", "spring"]),
])
def test_flex_design_refuses_a_spring_that_deploys_nothing(tmp_path, argv, words):
    out = tmp_path / "never.h5"
    check_refused(["design", *argv, "--out", str(out)], words, watch=[tmp_path])
    assert not out.exists()


def _fake_design_case(reached: bool):
    """A design case function whose deployment completes (or not) within the run."""
    def case(name, scene, *, cache_dir=None):
        values = {"peak_crank_speed": 40.0, "deployment_time": 0.02 if reached else math.nan,
                  "final_crank_angle": 1.5 if reached else math.nan,
                  "peak_coupler_stress": 1e6}
        return CaseResult(name, "[simulation]\nend_time_s = 0.01\n", {
            f"measures/{key}": Dataset(value, "1") for key, value in values.items()},
            attrs={"design_model": "rigid"})
    return case


@pytest.mark.parametrize("target, value", [("deployment_time", 0.025), ("final_angle", 10.0)])
def test_a_deployment_not_completed_is_not_an_answer(target, value):
    from flex.base.errors import FlexError
    from flex.experiments.design import question as dq

    scene = load_scene()
    question = dq.Question("preload", target, value)
    said: list[str] = []
    with pytest.raises(FlexError) as error:
        dq.answer(scene, question, None, _fake_design_case(False))
    assert "deployment did not complete" in str(error.value) and "\n" not in str(error.value)
    evaluate, _ = dq.evaluator(scene, question, None, _fake_design_case(False), said.append)
    assert evaluate(0.01).target_margin < 0 and "not reached" in said[0]
    found = dq.answer(scene, question, None, _fake_design_case(True))
    assert found.best.measures[dq.TARGETS[target][0]] < 100


# --- cost estimates and progress ------------------------------------------------------------
def test_a_reduction_to_many_modes_is_estimated_and_announced(capsys):
    from flex.dynamics.link_models import announce_mesh

    few = estimate_mesh(0.08, 0.001, 0.01, 0.002, 6).build_time_s
    many = estimate_mesh(0.08, 0.001, 0.01, 0.002, 100).build_time_s
    assert many > 60 * few and modes_cost_factor(6) == 1.0
    values = load_scene(overrides=PLATE + ["coupler.modes=100"])["coupler"]
    values["mesh_size_m"] = 0.002
    announce_mesh("coupler", values, "reduction with 100 modes", 100)
    (line,) = capsys.readouterr().err.splitlines()
    assert "100 modes" in line and "min" in line and "estimate" in line


@pytest.mark.parametrize("sets, announced", [
    (["simulation.end_time_s=400", "simulation.step_s=1e-5"], True),  # 4e7 rigid steps
    (["simulation.end_time_s=0.03"], False),
    (PLATE + ["coupler.modes=40", "coupler.mesh_size_m=0.002", "simulation.end_time_s=0.1",
              "simulation.step_s=1e-6"], True),
])
def test_a_long_integration_is_announced_before_it_starts(capsys, sets, announced):
    from flex.config.settings import resolve_solver_settings
    from flex.dynamics.runtime import announce_integration

    scene, _ = resolve_solver_settings(load_scene(overrides=sets))
    announce_integration(scene, "case", {})
    err = capsys.readouterr().err
    assert (("steps of" in err and "estimate" in err) if announced else err == ""), err


def test_exudyns_step_lines_become_progress_lines(capsys):
    from flex.dynamics.runtime import SolverOutput

    output = SolverOutput("case", 5.0)
    output.progress.first_s = output.progress.interval_s = 0.0
    output.write("+++++\nEXUDYN V1.13 solver: implicit\nSTEP1631, t = 1.631s, timeToGo = ")
    output.write("4.1s, Nit/step = 1.0\nNewton did not converge\n")
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("flex: integrating case: t = 1.631 of 5 s (32.6 %")
    assert "~4.1 s to go" in line
    assert output.getvalue() == "Newton did not converge\n"  # kept for a failure's message


def test_progress_is_throttled_and_the_heartbeat_beats():
    stream = io.StringIO()
    progress = Progress("work", first_s=0.0, interval_s=3600.0, stream=stream)
    assert progress.update("one") and not progress.update("two")
    assert stream.getvalue() == "flex: work: one\n"
    import threading

    class Beats(io.StringIO):  # says when the first beat was written: no clock in the test
        written = threading.Event()

        def write(self, text: str) -> int:
            self.written.set()
            return super().write(text)

    beats = Beats()
    with heartbeat("meshing", interval_s=0.01, stream=beats):
        assert beats.written.wait(timeout=60)  # the timeout only guards against a hang
    assert "flex: meshing: still running after" in beats.getvalue()
    assert duration_text(90) == "90 s" and duration_text(600) == "10 min"


@pytest.mark.slow
def test_a_run_of_a_few_seconds_prints_progress(tmp_path):
    outcome = run_cli(["run", "simulate", "--no-figures", "--out", str(tmp_path / "p.h5"),
                       "--set", "simulation.end_time_s=6", "--set", "simulation.step_s=1e-5",
                       "--set", "simulation.output_step_s=1e-3", "--set",
                       "simulation.error_estimate=false"])
    assert outcome.status == 0 and "flex: integrating case: t = " in outcome.stderr


# --- tolerances beyond reach ----------------------------------------------------------------
@pytest.mark.parametrize("sets, beyond", [
    (PLATE[:1] + ['coupler.model="auto"', "fidelity.tolerance=1e-9"], True),
    (PLATE[:1] + ['coupler.model="auto"', "fidelity.tolerance=1e-5"], True),
    (PLATE[:1] + ['coupler.model="auto"', "fidelity.tolerance=1e-4"], False),
    (PLATE[:1] + ['coupler.model="auto"', "fidelity.tolerance=0.01"], False),
    (['crank.model="auto"', "fidelity.tolerance=1e-9"], True),
    (['drive.spring_model="auto"', "fidelity.tolerance=1e-9"], True),
    (PLATE + ["fidelity.tolerance=1e-9"], True),  # auto solver keys of an FFRF coupler
    (["fidelity.tolerance=1e-9"], False),  # a rigid scene does not read it
])
def test_a_tolerance_no_model_is_certified_to_is_said(sets, beyond):
    text = tolerance_beyond_reach(load_scene(overrides=sets))
    assert bool(text) is beyond
    if beyond:
        assert "beyond reach" in text and "fidelity.tolerance" in text and "\n" not in text


def test_flex_design_says_a_tolerance_is_beyond_reach_before_it_starts(tmp_path):
    outcome = run_cli(["design", "--vary", "preload", "--peak-speed", "50", "--set",
                       "fidelity.tolerance=1e-9", "--set", "drive.spring_stiffness_N_per_m=0",
                       "--out", str(tmp_path / "x.h5")])
    # refused (no energy) before any case: the warning is not even needed, no case ran
    assert outcome.status == 2 and "flex: design: case" not in outcome.stderr


# --- messages that are right ----------------------------------------------------------------
@pytest.mark.parametrize("step, end, scales, companions", [
    (1e-3, 2e-3, [], [5e-4]),               # every time scale resolved: one finer companion
    (1e-3, 3e-3, [], [5e-4]),
    (1e-5, 0.03, [], [5e-6]),
    (2e-3, 2e-3, [], [1e-3]),
    (1e-3, 4e-3, [(4e-3, 20.0, "a mode")], [5e-4, 2.5e-4]),  # unresolved: the order observed
])
def test_the_error_estimate_names_its_companion_steps_truly(step, end, scales, companions):
    from flex.fidelity.error_estimate import estimate_step_error

    scene = load_scene(overrides=[f"simulation.step_s={step}", f"simulation.end_time_s={end}",
                                  "simulation.spectral_radius=0.9",
                                  'simulation.newton="full"',
                                  "simulation.newton_relative_tolerance=1e-8"])
    ran: list[float] = []

    def companion(scene):
        ran.append(scene["simulation"]["step_s"])
        return CaseResult("c", "", {"time": Dataset(np.array([0.0, end]), "s")})

    result = CaseResult("c", "", {"time": Dataset(np.array([0.0, end]), "s")})
    estimate = estimate_step_error(scene, result, companion, scales)
    assert ran == pytest.approx(companions)
    assert step not in ran
    shown = ", ".join(f"{h:g}" for h in companions)
    assert f"at h = {shown} s (the run: {step:g} s)" in estimate.method


@pytest.fixture(scope="module")
def two_column(tmp_path_factory):
    time_s = np.linspace(0.0, 1.0, 11)
    return write_results(tmp_path_factory.mktemp("inspect") / "two.h5", "demo", [CaseResult(
        "case", "", {"time": Dataset(time_s, "s"), "crank/angle": Dataset(time_s, "rad"),
                     "crank/midpoint_position": Dataset(np.stack([time_s, -time_s], axis=1),
                                                        "m", "x y")})])


@pytest.mark.parametrize("spec, status, words", [
    ("crank/midpoint_position[0]", 0, ["crank/midpoint_position[0]", "max 1"]),
    ("crank/midpoint_position[1]", 0, ["crank/midpoint_position[1]", "min -1"]),
    ("case/crank/midpoint_position[1]", 0, ["[1]"]),
    ("crank/midpoint_position[2]", 2, ["[2]", "no such column", "(11, 2)"]),
    ("crank/angle[0]", 2, ["crank/angle[0]", "no such column", "'crank/angle' without it"]),
    ("crank/nothing[1]", 2, ["crank/nothing"]),
])
def test_inspect_takes_the_column_its_help_promises(two_column, spec, status, words):
    for extra in ([], ["--json"]):
        outcome = check_refused(["inspect", str(two_column), spec, *extra],
                                words if status else [], watch=[two_column], status=status)
        if status == 0:
            for word in words[:1]:
                assert word in outcome.stdout
            if not extra:
                for word in words[1:]:
                    assert word in outcome.stdout
        else:  # the message suggests no path that has the same problem
            assert f"{spec}?" not in outcome.stderr


def test_inspect_help_still_promises_the_column():
    outcome = run_cli(["inspect", "--help"])
    assert outcome.status == 0 and "[i] suffix picks one column" in " ".join(
        outcome.stdout.split())


def test_hostile_case_count():
    """This file's share of issue 26's hostile cases."""
    # densities, thick plate, design refusals, incomplete deployments, reduction estimate,
    # long integrations, step lines, throttling, tolerances, design tolerance, companion
    # steps, inspect columns (text and --json), inspect help
    count = len(DENSITIES) + 1 + 3 + 2 + 1 + 3 + 1 + 1 + 8 + 1 + 6 + 2 * 6 + 1
    assert count >= 40, count
