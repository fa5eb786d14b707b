"""Sweep engine: one file per case, resume, recorded failures and crashes, shared
preparation, the local process pool and a real local Dask cluster."""

import os

import h5py
import pytest

from flex.base.errors import FlexError
from flex.data.results import CaseResult, Dataset
from flex.data.scene import load_scene
from flex.sweep import (
    SerialExecutor,
    case_path,
    make_executor,
    read_case_file,
    run_sweep,
    simulate_scene_case,
)


def _rigid(angle_deg: float, *extra: str):
    """A cheap rigid deployment: 50 steps of 1e-4 s."""
    return load_scene(None, [f"crank.initial_angle_deg={angle_deg}", "simulation.step_s=1e-4",
                             "simulation.end_time_s=0.005", *extra])


def _scenes():
    return {"a30": _rigid(30.0), "a40": _rigid(40.0), "a50": _rigid(50.0)}


def failing_case(name: str, scene) -> CaseResult:
    """Raises for the case named ``bad``; otherwise the default case."""
    if name == "bad":
        raise RuntimeError("this case is broken on purpose")
    return simulate_scene_case(name, scene)



def failing_case_with(name: str, scene, constants) -> CaseResult:
    """:func:`failing_case` with bound ``constants`` (unused)."""
    return failing_case(name, scene)

def sleeping_case(pid_file: str, name: str, scene) -> CaseResult:
    """Writes its worker's process id to ``pid_file`` and sleeps a minute (a long eigen-solve
    that sees no signal)."""
    import time

    with open(pid_file, "w") as handle:
        handle.write(str(os.getpid()))
    time.sleep(60.0)
    return simulate_scene_case(name, scene)


def crashing_case(name: str, scene) -> CaseResult:
    """Kills its worker process for the case named ``crash`` (as a segfault would)."""
    if name == "crash":
        os._exit(3)
    return simulate_scene_case(name, scene)


def tagged_prepare(scene) -> dict:
    if scene["crank"]["initial_angle_deg"] > 45:
        raise ValueError("no reduction for this geometry")
    return {"ok": True}


def angle_key(scene) -> str:
    return "wide" if scene["crank"]["initial_angle_deg"] > 45 else "narrow"


def test_serial_sweep_writes_one_file_per_case_and_records_failures(tmp_path):
    scenes = {**_scenes(), "bad": _rigid(35.0)}
    outcome = run_sweep(scenes, tmp_path, failing_case, scheduler="serial", progress=False)
    assert list(outcome.results) == list(scenes)
    assert outcome.ran == 4 and outcome.failed == 1 and outcome.resumed == 0
    bad = outcome.results["bad"]
    assert bad.status == "failed"
    assert "RuntimeError: this case is broken on purpose" in bad.message
    for name in scenes:
        case, digest = read_case_file(case_path(tmp_path, name))
        assert case.status == outcome.results[name].status and len(digest) == 24
    good, _ = read_case_file(case_path(tmp_path, "a30"))
    assert good.datasets["crank/angle"].units == "rad"
    assert good.counters["steps"] >= 50 and good.counters["wall_time_s"] > 0
    with h5py.File(case_path(tmp_path, "bad")) as h5:
        assert h5["cases/bad"].attrs["status"] == "failed"


def test_resume_runs_only_missing_changed_or_retried_cases(tmp_path):
    scenes = {**_scenes(), "bad": _rigid(35.0)}
    run_sweep(scenes, tmp_path, failing_case, scheduler="serial", progress=False)
    again = run_sweep(scenes, tmp_path, failing_case, scheduler="serial", progress=False)
    assert again.ran == 0 and again.resumed == 4
    assert again.results["a40"].datasets["crank/angle"].data[0] == pytest.approx(
        0.6981317, abs=1e-6)
    case_path(tmp_path, "a40").unlink()  # an interrupted sweep: one file missing
    scenes["a50"] = _rigid(50.0, "drive.spring_stiffness_N_per_m=1600.0")  # changed scene
    partial = run_sweep(scenes, tmp_path, failing_case, scheduler="serial", progress=False)
    assert partial.ran == 2 and partial.resumed == 2
    assert partial.case_wall_time_s.keys() == {"a40", "a50"}
    retried = run_sweep(scenes, tmp_path, failing_case, scheduler="serial", progress=False,
                        retry_failed=True)
    assert retried.ran == 1 and retried.failed == 1  # only the failed case ran again
    case_path(tmp_path, "a30").write_bytes(b"truncated")  # a damaged file is rerun
    assert run_sweep(scenes, tmp_path, failing_case, scheduler="serial",
                     progress=False).ran == 1


def test_preparation_runs_once_per_key_and_a_failed_one_fails_its_cases(tmp_path):
    calls = []

    def prepare(scene):
        calls.append(angle_key(scene))
        return tagged_prepare(scene)

    scenes = {**_scenes(), "a35": _rigid(35.0), "a60": _rigid(60.0)}
    outcome = run_sweep(scenes, tmp_path, simulate_scene_case, prepare=prepare,
                        prepare_key=angle_key, executor=SerialExecutor(), progress=False)
    assert sorted(calls) == ["narrow", "wide"]
    assert outcome.prepared == 2
    assert {n for n, c in outcome.results.items() if c.status == "failed"} == {"a50", "a60"}
    assert "preparation failed: ValueError: no reduction" in outcome.results["a60"].message


def test_progress_bar_shows_done_failed_remaining(tmp_path, capsys):
    scenes = {"a30": _rigid(30.0), "bad": _rigid(35.0)}
    run_sweep(scenes, tmp_path, failing_case, scheduler="serial", study="demo")
    err = capsys.readouterr().err
    assert "demo" in err and "done=1" in err and "failed=1" in err and "remaining=0" in err


def test_bad_names_and_schedulers_are_refused(tmp_path):
    with pytest.raises(FlexError, match="case name"):
        run_sweep({"a/b": _rigid(30.0)}, tmp_path, scheduler="serial", progress=False)
    with pytest.raises(FlexError, match="scheduler 'nope'"):
        make_executor("nope")
    with pytest.raises(FlexError, match="workers"):
        make_executor("serial", workers=0)



def test_a_case_function_no_worker_can_receive_is_refused_before_any_case(tmp_path):
    # make calibrate bound a mappingproxy (the FFRF rule's mesh constants): every case failed
    # in its worker ("cannot pickle 'mappingproxy' object") and was kept as a failed case
    from functools import partial
    from types import MappingProxyType

    unsendable = partial(failing_case_with, constants=MappingProxyType({"a": 1.0}))
    with pytest.raises(FlexError, match="cannot be sent to a worker process.*mappingproxy"):
        run_sweep(_scenes(), tmp_path, unsendable, workers=2, progress=False)
    assert not any(tmp_path.rglob("*.h5"))  # nothing kept
    sendable = partial(failing_case_with, constants={"a": 1.0})
    outcome = run_sweep({"a30": _rigid(30.0)}, tmp_path, sendable, workers=2, progress=False)
    assert outcome.results["a30"].status == "ok"


def test_the_calibrate_studys_case_function_can_be_sent_to_a_worker():
    import pickle
    from functools import partial

    import studies.calibrate as calibrate
    from flex.config.ffrf_rule import rule_constants
    from flex.data.reference_store import bundled_store
    from flex.experiments.fitting.calibration import measure_case

    # as studies/calibrate.py binds it
    pickle.dumps(partial(measure_case, reference_store=bundled_store(),
                         reference_store_digest="0" * 64, repeats=calibrate.REPEATS,
                         cache_dir=None, mesh_rule=dict(rule_constants()["mesh"])))

def test_local_process_pool_survives_a_crashing_worker(tmp_path):
    scenes = {**_scenes(), "crash": _rigid(35.0)}
    outcome = run_sweep(scenes, tmp_path, crashing_case, workers=2, progress=False)
    assert outcome.executor == "local processes (2 workers)"
    statuses = {name: case.status for name, case in outcome.results.items()}
    assert statuses == {"a30": "ok", "a40": "ok", "a50": "ok", "crash": "failed"}
    assert "worker process died" in outcome.results["crash"].message
    assert read_case_file(case_path(tmp_path, "crash"))[0].status == "failed"


def test_real_local_dask_cluster_runs_a_sweep(tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None,
                                  silence_logs=40) as cluster:
        address = cluster.scheduler_address
        assert address.startswith("tcp://127.0.0.1:")
        scenes = {**_scenes(), "bad": _rigid(35.0)}
        outcome = run_sweep(scenes, tmp_path, failing_case, scheduler=address,
                            progress=False)
        assert outcome.executor == f"Dask scheduler {address} (2 workers)"
        assert outcome.ran == 4 and outcome.failed == 1
        assert outcome.results["a50"].status == "ok"
        assert "broken on purpose" in outcome.results["bad"].message
        # the same sweep again resumes entirely from the files
        again = run_sweep(scenes, tmp_path, failing_case, scheduler=address, progress=False)
        assert again.ran == 0 and again.resumed == 4


def test_results_round_trip_keeps_units_and_attributes(tmp_path):
    case = CaseResult("x", "[crank]\n", {"measures/e": Dataset(0.5, "1", "an error"),
                                         "curves/t": Dataset([0.0, 1.0], "s", "time")},
                      counters={"wall_time_s": 1.5}, attrs={"fidelity_coupler_model": "rigid"})
    outcome = run_sweep({"x": _rigid(30.0)}, tmp_path,
                        lambda name, scene: case, scheduler="serial", progress=False)
    assert outcome.results["x"].status == "ok"
    loaded, _ = read_case_file(case_path(tmp_path, "x"))
    assert loaded.datasets["measures/e"].units == "1"
    assert list(loaded.datasets["curves/t"].data) == [0.0, 1.0]
    assert loaded.attrs["fidelity_coupler_model"] == "rigid"
    assert loaded.counters["wall_time_s"] == 1.5


@pytest.mark.slow
def test_kfit_study_small_end_to_end(tmp_path, monkeypatch, reduction_cache):
    """A shrunken kfit (3 thicknesses, 1 stiffness family, 1 validation scene) through the
    study runner and the local process pool: cases, fit, criterion file, validation."""
    import studies.kfit as kfit
    from flex.experiments.fitting.kfit_law import analyse
    from flex.study import run_study

    monkeypatch.setattr(kfit, "THICKNESSES_M", (1e-3, 3e-3, 10e-3))
    monkeypatch.setattr(kfit, "STIFFNESS_THICKNESSES_M", (1e-3,))
    monkeypatch.setattr(kfit, "STIFFNESSES_N_PER_M", (500.0, 5000.0))
    monkeypatch.setattr(kfit, "PRELOAD_THICKNESSES_M", ())
    monkeypatch.setattr(kfit, "DAMPING_RATIOS", (0.0,))
    monkeypatch.setattr(kfit, "VALIDATION", {"val_t7mm_tol1pct": (
        ["coupler.thickness_m=0.007"], 0.01)})
    from flex.sweep import SweepSettings

    sweep = SweepSettings(folder=tmp_path / "cases", progress=False)
    output = run_study("kfit", out=tmp_path / "kfit.h5", figures=True, quiet=True, sweep=sweep,
                       cache_dir=reduction_cache)
    assert all(c.status == "ok" for c in output.results.values())
    law = analyse(output.results)["fits"][(0.0, "stop", "deflection")]
    assert 1.5 < law.exponent < 3.0  # quasi-static expectation: 2
    assert (tmp_path / "kfit-criterion.toml").exists()
    validation = output.results["val_t7mm_tol1pct"]
    assert validation.attrs["fidelity_coupler_model"] == "rigid"
    assert validation.datasets["errors/governing"].data <= 0.01
    with h5py.File(tmp_path / "kfit.h5") as h5:
        assert "summary/k/zeta_0/stop/governing/central_thesis" in h5
        assert h5["summary/table/measures/deflection"].attrs["units"] == "1"
    assert {p.name for p in output.figures} >= {"kfit-error-vs-n.png",
                                                 "kfit-k-vs-tolerance.png"}  # named after kfit.h5


def test_case_hash_follows_the_case_function_s_version(monkeypatch):
    # a case function that stores more (its case_version bumped) must not resume old files
    import functools

    from flex.experiments.fitting import kfit
    from flex.sweep import case_hash

    scene = load_scene()
    bound = functools.partial(kfit.fit_case, cache_dir=None)
    before = case_hash(scene, bound)
    monkeypatch.setattr(kfit.fit_case, "case_version", kfit.fit_case.case_version + 1)
    assert case_hash(scene, bound) != before


def _calibration_copy(folder, **changed):
    """A calibration folder: the bundled files, ``changed`` ones (part -> text) replaced."""
    from flex.config.calibration import BUNDLED_FOLDER, FILES, load_calibration

    folder.mkdir(exist_ok=True)
    for part, name in FILES.items():
        text = changed.get(part, (BUNDLED_FOLDER / name).read_text(encoding="utf-8"))
        (folder / name).write_text(text, encoding="utf-8")
    return load_calibration(folder)


def test_case_hash_follows_the_calibration_of_auto_scenes(tmp_path):
    # a resumed sweep must not reuse cases run with other solver defaults (or rule, or law):
    # the calibration is one argument of the case function, hashed as one
    import functools

    import flex.config.settings as settings
    from flex.config.calibration import BUNDLED_FOLDER, load_calibration
    from flex.fidelity.simulation import simulate_case
    from flex.sweep import case_hash

    auto = load_scene()
    pinned = load_scene(None, settings.pinned_overrides())
    bundled = functools.partial(simulate_case, calibration=load_calibration("bundled"))
    before = case_hash(auto, simulate_case), case_hash(pinned, simulate_case)
    assert case_hash(auto, bundled) == before[0]  # None is the bundled calibration
    same = _calibration_copy(tmp_path / "same")
    assert case_hash(auto, functools.partial(simulate_case, calibration=same)) == before[0]
    defaults = (BUNDLED_FOLDER / "solver_defaults.toml").read_text(encoding="utf-8")
    other = _calibration_copy(tmp_path / "other",
                              solver_defaults=defaults.replace("1.0e-5", "2.0e-5"))
    assert other.digest != same.digest
    with_other = functools.partial(simulate_case, calibration=other)
    assert case_hash(auto, with_other) != before[0]
    assert case_hash(pinned, with_other) == before[1]  # nothing of it is "auto"


def test_case_hash_follows_the_criterion_of_auto_links(tmp_path):
    import functools

    import flex.config.settings as settings
    from flex.fidelity.laws import criterion_of
    from flex.fidelity.simulation import simulate_case
    from flex.sweep import case_hash

    auto = load_scene(None, ['coupler.geometry="plate"', 'coupler.model="auto"'])
    # nothing "auto": no calibration read (the bundled scene's solver keys are "auto")
    rigid = load_scene(None, ['coupler.geometry="plate"', *settings.pinned_overrides()])
    before = case_hash(auto, simulate_case), case_hash(rigid, simulate_case)
    # a re-fit installed as the calibration's criterion file
    from flex.config.calibration import BUNDLED_FOLDER, FILES

    bundled = (BUNDLED_FOLDER / FILES["coupler_criterion"]).read_text(encoding="utf-8")
    refit = _calibration_copy(tmp_path / "refit",  # the same law, another file: a re-fit
                              coupler_criterion="# another fit\n" + bundled)
    with_refit = functools.partial(simulate_case, calibration=refit)
    assert case_hash(auto, with_refit) != before[0]
    assert case_hash(rigid, with_refit) == before[1]
    # a law passed as an argument is part of the case function's identity
    with_law = functools.partial(simulate_case, criterion=criterion_of())
    assert case_hash(auto, with_law) != case_hash(auto, simulate_case)


def test_run_each_on_an_executor_gives_the_serial_results_in_order():
    """A study's case loop on local processes (jobs grouped by a key, longest first) returns
    what it returns in this process, in the order of the scenes, and reports every case."""
    from flex.base.caseloop import run_each

    scenes = {"a50": _rigid(50.0), "a30": _rigid(30.0), "a40": _rigid(40.0)}
    serial = run_each(scenes, simulate_scene_case)
    seen = []
    executor = make_executor(workers=2)
    try:
        parallel = run_each(scenes, simulate_scene_case, lambda *args: seen.append(args),
                            executor=executor,
                            group=lambda name, scene: None if name == "a50" else "narrow",
                            cost=lambda name, scene: scene["crank"]["initial_angle_deg"])
    finally:
        executor.close()
    assert list(parallel) == list(scenes)
    for name, case in serial.items():
        assert case.status == parallel[name].status == "ok"
        assert set(case.datasets) == set(parallel[name].datasets)
        for key, dataset in case.datasets.items():
            assert (dataset.data == parallel[name].datasets[key].data).all(), key
    assert sorted(args[0] for args in seen) == sorted([*scenes, "done"])
    assert seen[-1] == ("done", 3, 3)


def test_an_aborted_process_pool_leaves_no_worker_running(tmp_path):
    # an interrupt ends a sweep with abort(): the workers are terminated, not joined (an
    # interrupted make calibrate waited minutes for its workers' eigen-solves)
    import time
    from functools import partial

    executor = make_executor(workers=1)
    pid_file = tmp_path / "pid"
    executor.submit(partial(sleeping_case, str(pid_file)), "slow", _rigid(30.0))
    for _ in range(600):  # the worker has started its case
        if pid_file.exists() and pid_file.read_text():
            break
        time.sleep(0.1)
    pid = int(pid_file.read_text())
    executor.abort()
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)
    executor.close()


def test_an_interrupt_aborts_the_executor_of_a_case_loop():
    from flex.base.caseloop import run_each

    class Interrupted(SerialExecutor):
        aborted = False

        def wait_first(self, futures, timeout=None):
            raise KeyboardInterrupt

        def abort(self):
            self.aborted = True

    executor = Interrupted()
    with pytest.raises(KeyboardInterrupt):
        run_each({"a30": _rigid(30.0)}, simulate_scene_case, executor=executor)
    assert executor.aborted
