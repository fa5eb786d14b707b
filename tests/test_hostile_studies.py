"""Every study handed every structural key it does not honour; the cheap studies run with keys
their reports used to ignore.

A study either honours a key (its cases and report follow the scene it ran) or refuses it
(README "When something goes wrong"). The keys that change what a study simulates in kind
(:data:`flex.study.STRUCTURAL_KEYS`: the drive, the wing, the links' models and geometry, the
spring's model, the integrator) run with the study's own value unless the study ``HONOURS``
them: another value is refused before any case is built, in one line naming the key, the
study and what to run instead, and the earlier result file stays as it was. ``simulate``
honours them all (it runs the scene it is given). The runs below check that reports follow
the scene: the kinematics study's turns per second, the dynamics study's "why" column and a
deployment that did not complete within the run.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from hostile import check_refused, fingerprint, run_cli

from flex.data.results import CaseResult, Dataset, open_results, write_results
from flex.data.scene import SCHEMA
from flex.study import STRUCTURAL_KEYS, STUDIES, load_study, study_scene


def _values(name: str) -> list[object]:
    section, key = name.split(".")
    field = SCHEMA[section][key]
    return [True, False] if field.kind is bool else list(field.kind)


def _toml(value: object) -> str:
    return str(value).lower() if isinstance(value, bool) else f'"{value}"'


def _others() -> list[tuple[str, str, object]]:
    """(study, key, value): every structural value other than the study's own, for every
    study that does not honour the key."""
    out = []
    for study in STUDIES:
        module = load_study(study)
        honours = set(getattr(module, "HONOURS", ()))
        own = study_scene(module)
        for name in STRUCTURAL_KEYS:
            if name in honours:
                continue
            section, key = name.split(".")
            out += [(study, name, value) for value in _values(name)
                    if value != own[section][key]]
    return out


OTHERS = _others()


@pytest.fixture(scope="module")
def earlier(tmp_path_factory):
    """An earlier result file and its report (every refusal is checked to leave them)."""
    folder = tmp_path_factory.mktemp("earlier")
    path = write_results(folder / "earlier.h5", "simulate", [CaseResult("case", "", {
        "time": Dataset(np.linspace(0, 1, 5), "s")})])
    (folder / "reports").mkdir()
    (folder / "reports" / "earlier.md").write_text("the earlier report\n")
    return path


@pytest.mark.parametrize("study, name, value", OTHERS,
                         ids=[f"{s}-{n}={v}" for s, n, v in OTHERS])
def test_a_structural_key_a_study_does_not_honour_is_refused(earlier, study, name, value):
    outcome = check_refused(["run", study, "--no-figures", "--out", str(earlier), "--set",
                             f"{name}={_toml(value)}"], [name, f"study '{study}'",
                                                         "flex run simulate"],
                            watch=[earlier.parent])
    assert outcome.stdout == ""


STRUCTURAL_VALUES = [(name, value) for name in STRUCTURAL_KEYS for value in _values(name)]


@pytest.mark.parametrize("name, value", STRUCTURAL_VALUES,
                         ids=[f"{n}={v}" for n, v in STRUCTURAL_VALUES])
def test_simulate_honours_every_structural_value_or_names_what_it_needs(name, value):
    outcome = run_cli(["scene", "simulate", "--set", f"{name}={_toml(value)}"])
    assert "Traceback" not in outcome.stderr and "internal error" not in outcome.stderr
    if outcome.status == 0:
        section, key = name.split(".")
        assert tomllib.loads(outcome.stdout.split("\n", 1)[1] if outcome.stdout.startswith(
            "#") else outcome.stdout)[section][key] == value
    else:  # refused by the scene's own rules (e.g. an FFRF coupler needs a plate)
        assert outcome.status == 2 and len(outcome.error_lines()) == 1


def test_every_study_module_declares_only_structural_keys_it_honours():
    for study in STUDIES:
        honours = set(getattr(load_study(study), "HONOURS", ()))
        assert honours <= set(STRUCTURAL_KEYS), study
    assert set(load_study("simulate").HONOURS) == set(STRUCTURAL_KEYS)


# --- reports follow the scene they ran ---------------------------------------------------------
def _run(tmp_path, study: str, *sets: str):
    argv = ["run", study, "--no-figures", "--out", str(tmp_path / f"{study}.h5")]
    for item in sets:
        argv += ["--set", item]
    outcome = run_cli(argv)
    assert outcome.status == 0 and "Traceback" not in outcome.stderr, outcome.stderr
    return outcome


@pytest.mark.parametrize("sets, words", [
    (["drive.crank_speed_rad_per_s=100"], ["15.92 turn/s", "this run differs",
                                           "drive.crank_speed_rad_per_s = 100"]),
    (["simulation.end_time_s=0.5"], ["1 turn/s, 0.5 turns", "0.5 of a turn"]),
    (["crank.length_m=0.03"], ["1 turn/s, 1 turns", "crank.length_m = 0.03"]),
    ([], ["(Exudyn, 1 turn/s, 1 turns)"]),
])
def test_the_kinematics_report_follows_the_crank_it_ran(tmp_path, sets, words):
    outcome = _run(tmp_path, "kinematics", *sets)
    for word in words:
        assert word in outcome.stdout, (word, outcome.stdout)
    if not sets:
        assert "this run differs" not in outcome.stdout


def test_the_dynamics_why_column_follows_the_scene(tmp_path):
    thesis = _run(tmp_path, "dynamics", "simulation.error_estimate=false")
    assert "11 mm reproduces the stated 0.022 m travel" in thesis.stdout
    # the half-swing time is not called delta_t (auto's and docs/criterion.md's delta_t is
    # the time of the first crank angle maximum)
    row = next(line for line in thesis.stdout.splitlines() if line.startswith("| half-swing"))
    assert "flex's delta_t is the time of the crank angle maximum" in row
    other = _run(tmp_path, "dynamics", "drive.spring_stiffness_N_per_m=3000",
                 "simulation.error_estimate=false")
    assert "11 mm reproduces" not in other.stdout
    assert "differs from the thesis's in drive.spring_stiffness_N_per_m = 3000" in other.stdout
    with open_results(tmp_path / "dynamics.h5") as h5:
        reasons = [r.decode() if isinstance(r, bytes) else r
                   for r in h5["summary/thesis_comparison/reason"][()]]
    assert all("drive.spring_stiffness_N_per_m = 3000" in reason for reason in reasons)


def test_a_deployment_that_does_not_complete_is_not_reported_as_the_end_time(tmp_path):
    outcome = _run(tmp_path, "dynamics", "simulation.end_time_s=0.005",
                   "simulation.error_estimate=false")
    assert "not reached" in outcome.stdout
    assert "still rising at the end of the run" in outcome.stdout
    with open_results(tmp_path / "dynamics.h5") as h5:
        quantities = [q.decode() if isinstance(q, bytes) else q
                      for q in h5["summary/thesis_comparison/quantity"][()]]
        values = h5["summary/thesis_comparison/preload_22mm"][()]
    table = dict(zip(quantities, values, strict=True))
    assert np.isnan(table["time of crank angle maximum"]) and np.isnan(table["crank angle maximum"])
    assert table["crank speed maximum"] > 0  # what did happen is still reported


def test_a_refused_study_run_changes_nothing(earlier):
    before = fingerprint([earlier.parent])
    outcome = run_cli(["run", "dynamics", "--out", str(earlier), "--set",
                       'drive.kind="constant_speed"'])
    assert outcome.status == 2 and fingerprint([earlier.parent]) == before
    assert "internal error" not in outcome.stderr


def test_hostile_case_count():
    """This file's share of issue 26's hostile cases."""
    assert len(OTHERS) + len(STRUCTURAL_VALUES) + 4 + 3 >= 200, len(OTHERS)
