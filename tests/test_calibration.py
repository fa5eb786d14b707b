"""One calibration (flex.config.calibration): the fitted laws, the FFRF rule and the solver
defaults loaded as one value, passed as an argument, hashed as one and installed in one step."""

from __future__ import annotations

import dataclasses
import os
import pickle
import tomllib

import pytest
import tomli_w

from flex.base.errors import FlexError
from flex.config.calibration import (
    BUNDLED_FOLDER,
    FILES,
    install_calibration,
    load_calibration,
    main,
)
from flex.config.ffrf_rule import pick
from flex.config.settings import resolve_solver_settings, solver_defaults
from flex.data.scene import load_scene
from flex.fidelity.laws import criterion_of


def _copy(folder, **changed):
    folder.mkdir(exist_ok=True)
    for part, name in FILES.items():
        text = changed.get(part, (BUNDLED_FOLDER / name).read_text(encoding="utf-8"))
        (folder / name).write_text(text, encoding="utf-8")
    return folder


def test_the_bundled_calibration_is_the_four_files_of_flex_config():
    bundled = load_calibration("bundled")
    assert bundled.source == "bundled" and bundled.folder == BUNDLED_FOLDER
    for part, name in FILES.items():
        assert getattr(bundled, f"{part}_toml") == (BUNDLED_FOLDER / name).read_text("utf-8")
    assert solver_defaults() is bundled.solver_defaults  # None is the bundled one
    assert criterion_of().source == str(BUNDLED_FOLDER / "criteria_fit.toml")


def test_a_calibration_is_a_value_that_refuses_changes_and_pickles():
    bundled = load_calibration()
    with pytest.raises(TypeError):
        bundled.solver_defaults["rigid"]["step_s"] = 1.0  # type: ignore[index]
    with pytest.raises(dataclasses.FrozenInstanceError):
        bundled.ffrf_rule_toml = ""  # type: ignore[misc]
    again = pickle.loads(pickle.dumps(bundled))
    assert again == bundled and again.digest == bundled.digest
    assert dict(again.solver_defaults["rigid"]) == dict(bundled.solver_defaults["rigid"])


def test_a_folder_is_a_calibration_and_its_digest_follows_every_file(tmp_path):
    bundled = load_calibration()
    same = load_calibration(_copy(tmp_path / "same"))
    assert same.digest == bundled.digest and same.source == str(tmp_path / "same")
    digests = {bundled.digest}
    for part, name in FILES.items():
        text = (BUNDLED_FOLDER / name).read_text("utf-8") + "\n# changed\n"
        digests.add(load_calibration(_copy(tmp_path / part, **{part: text})).digest)
    assert len(digests) == 1 + len(FILES)


def test_a_calibration_passed_in_is_what_auto_resolves_from(tmp_path):
    scene = load_scene(None, ['coupler.geometry="plate"', 'coupler.model="ffrf"',
                              "coupler.thickness_m=0.001"])
    bundled_step = pick(scene, 0.01).step_s
    # the bundled rule with its steps law doubled: a finer step from the same scene
    constants = tomllib.loads((BUNDLED_FOLDER / "ffrf_rule.toml").read_text("utf-8"))
    for level in constants["levels"]:
        level["steps_coefficient"] *= 2.0
    other = load_calibration(_copy(tmp_path / "other", ffrf_rule=tomli_w.dumps(constants)))
    assert pick(scene, 0.01, calibration=other).step_s < bundled_step
    resolved, choice = resolve_solver_settings(load_scene(None, [
        'coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.001"]),
        other)
    assert choice is not None and resolved["simulation"]["step_s"] <= bundled_step


def test_bad_calibrations_are_refused_with_their_folder_or_file(tmp_path):
    with pytest.raises(FlexError, match="no such folder"):
        load_calibration(tmp_path / "missing")
    folder = _copy(tmp_path / "partial")
    (folder / "solver_defaults.toml").unlink()
    with pytest.raises(FlexError, match="has no solver_defaults.toml"):
        load_calibration(folder)
    broken = _copy(tmp_path / "broken", ffrf_rule="levels = [")
    with pytest.raises(FlexError, match="ffrf_rule.toml' is not valid TOML"):
        load_calibration(broken)
    lawless = _copy(tmp_path / "lawless")
    (lawless / "criteria_fit.toml").unlink()
    with pytest.raises(FlexError, match="make calibration-install"):
        criterion_of(load_calibration(lawless))


def test_install_copies_fits_from_up_to_date_runs_only(tmp_path, capsys):
    results, target = tmp_path / "results", _copy(tmp_path / "calibration")
    results.mkdir()
    law = results / "kfit-criterion.toml"
    bundled = (BUNDLED_FOLDER / "criteria_fit.toml").read_text()  # a law whose values hold
    fit_1, fit_2 = (bundled.replace("cases_fitted = ", f"cases_fitted = {n}") for n in (1, 2))
    law.write_text(fit_1)
    with pytest.raises(FlexError, match="no result file"):
        install_calibration([law], target)
    (results / "kfit.h5").write_text("run")
    assert install_calibration([law], target) == [f"cp {law} {target / 'criteria_fit.toml'}"]
    assert (target / "criteria_fit.toml").read_text() == fit_1
    assert "is already" in install_calibration([law], target)[0]
    failed = results / "kfit.failed.h5"
    failed.write_text("failed")
    os.utime(failed, (os.path.getmtime(law) + 10,) * 2)
    law.write_text(fit_2)
    with pytest.raises(FlexError, match="the last kfit run failed"):
        install_calibration([law], target)
    assert (target / "criteria_fit.toml").read_text() == fit_1  # nothing copied
    other = results / "notes.toml"
    other.write_text("")
    assert main(["install", "--into", str(target), str(other)]) == 2
    assert "not a fitted calibration file" in capsys.readouterr().err
