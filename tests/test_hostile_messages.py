"""Messages that say what happened, and arguments that are refused rather than ignored.

- ``--out ''`` (export, plot) is refused, not the current folder or the default figure;
  ``animate --time`` for an animation (it picks a .png's one frame) is refused, not ignored.
- A time axis relabelled (``units = "ms"``) is a malformed result file for every reader.
- A wing of a density no solid has is refused, as a plate's is.
- From Python: a registry entry under another name, a toy model whose datasets replace the
  mechanism's (``crank/angle``), a calibration or criterion of the wrong kind, a calibration
  or criterion file that is not UTF-8: FlexError (ArgumentError), not a run that is "ok" or
  a Python exception from inside.
- ``run --animate`` that no case can use is refused before anything runs (it wrote the
  result, figure and report, then exited 2); a case it skips is named; the animation phase
  is announced and heartbeats.
- A divergence with flex's own settings does not say "check the solver settings"; a full
  disk while drawing figures names where; a Dask scheduler without workers is said, then
  refused.
"""

from __future__ import annotations

import dataclasses
import errno
import os
import shutil
from pathlib import Path
from types import MappingProxyType

import h5py
import numpy as np
import pytest
from hostile import check_refused, earlier_run

import flex
from flex.base.errors import ArgumentError, FlexError
from flex.data.results import Dataset
from flex.data.scene import load_scene

QUICK = ["simulation.end_time_s=0.002", "simulation.error_estimate=false"]


def _sets(*items: str) -> list[str]:
    return [arg for item in items for arg in ("--set", item)]


# --- arguments refused rather than ignored ----------------------------------------------------
@pytest.mark.parametrize("out", ["", " "])
def test_export_to_an_empty_folder_name_is_refused(tiny_ffrf_file, tmp_path, monkeypatch, out):
    monkeypatch.chdir(tmp_path)
    check_refused(["export", str(tiny_ffrf_file), "--out", out], ["--out", "empty"],
                  bystanders=[tmp_path])
    assert list(tmp_path.iterdir()) == []


def test_plot_to_an_empty_file_name_is_refused(tiny_ffrf_file, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    check_refused(["plot", str(tiny_ffrf_file), "crank/angle", "--out", ""], ["--out"],
                  bystanders=[tiny_ffrf_file.parent])
    assert not (tiny_ffrf_file.parent / "figures").exists()


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
@pytest.mark.parametrize("time", ["0", "0.0005", "1e9"])
def test_animate_time_for_an_animation_is_refused(tiny_ffrf_file, tmp_path, suffix, time):
    out = tmp_path / f"a{suffix}"
    check_refused(["animate", str(tiny_ffrf_file), "--out", str(out), "--time", time],
                  ["--time", ".png"], watch=[tiny_ffrf_file])
    assert not out.exists() and not out.with_suffix(".gif").exists()


@pytest.mark.parametrize("units", ["ms", "min", b"ms", "S"])
@pytest.mark.parametrize("command", ["compare", "inspect", "plot", "export"])
def test_a_relabelled_time_axis_is_refused(tiny_ffrf_file, tmp_path, command, units):
    edited = Path(shutil.copy(tiny_ffrf_file, tmp_path / "ms.h5"))
    with h5py.File(edited, "r+") as h5:
        h5["cases/case/time"].attrs["units"] = units
    argv = {"compare": ["compare", str(edited), str(tiny_ffrf_file), "crank/angle"],
            "inspect": ["inspect", str(edited)],
            "plot": ["plot", str(edited), "crank/angle", "--out", str(tmp_path / "p.png")],
            "export": ["export", str(edited), "--out", str(tmp_path / "e")]}[command]
    check_refused(argv, ["units", "time"], watch=[edited, tiny_ffrf_file])


@pytest.mark.parametrize("density", ["1e-3", "0.5", "1e6"])
def test_a_wing_of_no_solid_s_density_is_refused(tmp_path, density):
    check_refused(["run", "simulate", "--out", str(tmp_path / "r.h5"),
                   *_sets("wing.enabled=true", f"wing.density_kg_per_m3={density}")],
                  ["wing.density_kg_per_m3"], bystanders=[tmp_path])


# --- the Python API -------------------------------------------------------------------------
def _registry(**entries):
    from flex.dynamics.link_models import BUILTIN_LINK_MODELS

    return MappingProxyType({**BUILTIN_LINK_MODELS, **entries})


def test_a_registry_entry_under_another_name_is_refused():
    from flex.dynamics.link_models import BUILTIN_LINK_MODELS

    registry = _registry(mine=BUILTIN_LINK_MODELS["ffrf"])
    with pytest.raises(ArgumentError, match="mine"):
        flex.load_scene(overrides=['coupler.model="mine"'], link_models=registry)
    with pytest.raises(ArgumentError, match="mine"):
        flex.simulate(load_scene(overrides=QUICK), link_models=registry)


@pytest.mark.parametrize("written", ["crank/angle", "slider/position", "time", "crank/toy",
                                     "joints/B/force_modulus"])
def test_a_toy_model_that_replaces_the_mechanism_s_datasets_is_refused(written):
    from flex.dynamics.link_models import BUILTIN_LINK_MODELS

    rigid = BUILTIN_LINK_MODELS["rigid"]

    def datasets(mech, link, time_s):
        return {**rigid.datasets(mech, link, time_s), written: Dataset(np.zeros_like(time_s),
                                                                        "1")}

    toy = dataclasses.replace(rigid, name="toy", datasets=datasets)
    registry = _registry(toy=toy)
    scene = flex.load_scene(overrides=[*QUICK, 'coupler.model="toy"'], link_models=registry)
    with pytest.raises(FlexError, match=written.replace("/", ".")):
        flex.simulate(scene, link_models=registry)


@pytest.mark.parametrize("option, value", [("calibration", 123), ("calibration", b"bundled"),
                                           ("calibration", ["bundled"]),
                                           ("calibration", True), ("criterion", "law.toml"),
                                           ("crank_criterion", 1.0)])
def test_an_option_of_the_wrong_kind_is_an_argument_error(option, value):
    with pytest.raises(ArgumentError, match=option):
        flex.simulate(load_scene(overrides=QUICK), **{option: value})


def test_a_calibration_file_that_is_not_utf8_is_a_flex_error(tmp_path):
    from flex.config.calibration import FILES

    source = Path(flex.__file__).parent / "config"
    for name in FILES.values():
        if (source / name).exists():
            shutil.copy(source / name, tmp_path / name)
    path = tmp_path / FILES["coupler_criterion"]
    path.write_bytes(path.read_bytes() + b"\xff\xfe")
    with pytest.raises(FlexError, match="cannot be read"):
        flex.simulate(load_scene(overrides=QUICK), calibration=tmp_path)


def test_a_criterion_file_that_is_not_utf8_is_a_flex_error(tmp_path):
    from flex.fidelity.laws import load_criterion

    path = tmp_path / "law.toml"
    path.write_bytes(b"k = 1\n\xff")
    with pytest.raises(FlexError, match="cannot be read"):
        load_criterion(path)


# --- run --animate -------------------------------------------------------------------------
@pytest.mark.parametrize("sets", [
    ['coupler.model="exact_beam"', 'coupler.geometry="plate"'],
    ['coupler.model="exact_beam"', 'coupler.geometry="plate"', 'crank.model="exact_beam"',
     'crank.geometry="plate"'],
    []], ids=["beam-coupler", "beam-crank-and-coupler", "rigid"])
def test_run_animate_that_no_case_can_use_is_refused_before_running(tmp_path, sets):
    earlier = earlier_run(tmp_path)
    check_refused(["run", "simulate", "--out", str(earlier), "--animate", *_sets(*sets)],
                  ["--animate"], watch=[tmp_path])


def test_animate_results_names_its_phase_and_the_cases_it_skips(tiny_ffrf_file, tmp_path,
                                                               monkeypatch, capsys):
    import flex.tools.animate as animate
    from flex.data.results import write_results

    beam = flex.simulate(load_scene(overrides=[*QUICK, 'coupler.model="exact_beam"',
                                               'coupler.geometry="plate"']), "beam")
    with h5py.File(tiny_ffrf_file) as h5:
        assert h5["cases/case"].attrs["status"] == "ok"
    both = tmp_path / "both.h5"
    shutil.copy(tiny_ffrf_file, both)
    write_results(tmp_path / "beam.h5", "simulate", [beam])
    made = []
    monkeypatch.setattr(animate, "animate_case", lambda result, name, path, **kw:
                        made.append(name) or animate.Animation(path, 2, 960, 540, 25, 1.0))
    assert [a.path.name for a in animate.animate_results(both)] == ["both-case.mp4"]
    assert list(animate.animate_results(tmp_path / "beam.h5")) == []
    err = capsys.readouterr().err
    assert "flex: animating case case -> " in err
    assert "case beam is not animated: the geometrically exact beam coupler" in err


# --- messages ---------------------------------------------------------------------------------
def test_a_divergence_with_flex_s_own_settings_blames_no_setting_of_the_user_s():
    from flex.config.settings import resolve_solver_settings
    from flex.dynamics.advice import divergence_advice

    scene, _ = resolve_solver_settings(load_scene())
    advice = divergence_advice(scene)
    assert "check the solver settings" not in advice and "report" in advice, advice


def test_a_full_disk_while_drawing_figures_names_where(tmp_path, monkeypatch):
    import flex.base.plotting as plotting

    def full(fig, path):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))  # no file name, as PIL

    monkeypatch.setattr(plotting, "save", full)
    earlier = earlier_run(tmp_path)
    outcome = check_refused(["run", "simulate", "--out", str(earlier), *_sets(*QUICK)],
                            [str(tmp_path / "figures"), "No space left"], watch=[tmp_path])
    assert "cannot access:" not in outcome.stderr


@pytest.mark.slow  # a Dask scheduler of its own: a few seconds
def test_a_dask_scheduler_without_workers_is_said_then_refused(monkeypatch, capsys):
    from distributed import LocalCluster

    import flex.sweep.executors as executors

    monkeypatch.setattr(executors, "WORKER_WAIT_S", 1.0)
    with LocalCluster(n_workers=0, processes=True, host="127.0.0.1", dashboard_address=None,
                      scheduler_port=0) as cluster:
        with pytest.raises(FlexError, match="no worker joined"):
            executors.make_executor(cluster.scheduler_address)
    assert "has no worker yet: waiting" in capsys.readouterr().err
