"""Damaged caches of every kind flex keeps, and cache locations that cannot be used.

flex keeps two caches (:mod:`flex.data.cache`): the reduction cache (Craig-Bampton
reductions of plate links, :mod:`flex.bodies.reduction`; the geometric stiffness beside them)
and a sweep's case files (:mod:`flex.sweep`). Anything loaded from them must prove its content
(a digest checked on load) or be rebuilt, with one line saying so; a location that cannot be
used gets one line naming the cache and how to move it (``FLEX_CACHE_DIR``), never a bare OS
error on a temporary file name, and the run goes on (a cache that cannot be written costs a
rebuild next time, not this run's result).

The reduction cases damage one small, quickly built entry (a 40 x 4 x 10 mm plate, 8 mm mesh,
one mode) in every way a file can be damaged while still opening, and check the loader refuses
it; a few go the whole way (rebuild, replace, one line).
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

import h5py
import numpy as np
import pytest

from flex.base.physics import Plate
from flex.bodies import reduction as red
from flex.bodies.reduction import cache as red_cache
from flex.data import cache as cache_module
from flex.data.cache import REDUCTION_CACHE, SWEEP_CASES, content_digest, store
from flex.data.results import CaseResult, Dataset
from flex.data.scene import load_scene
from flex.sweep import case_path, run_sweep

PLATE = (Plate(0.04, 0.004, 0.01, 2.1e11, 7850.0, 0.3), 0.008, 1)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """A small reduction, built once into its own cache folder."""
    return red.build_reduction(*PLATE, tmp_path_factory.mktemp("reductions"))


@pytest.fixture(scope="module")
def entry(built) -> tuple[Path, str, bytes]:
    """A whole reduction cache entry: its path, key and bytes."""
    return built.cache_file, built.key, built.cache_file.read_bytes()


def _scaled(path: str, factor: float):
    def damage(h5: h5py.File) -> None:
        value = h5[path][()] * factor
        attrs = dict(h5[path].attrs)
        del h5[path]
        h5[path] = value
        h5[path].attrs.update(attrs)
    return damage


def _replaced(path: str, value):
    def damage(h5: h5py.File) -> None:
        attrs = dict(h5[path].attrs)
        del h5[path]
        h5[path] = value
        h5[path].attrs.update(attrs)
    return damage


def _deleted(path: str):
    def damage(h5: h5py.File) -> None:
        del h5[path]
    return damage


#: damages of an entry that still opens as HDF5 (attributes kept: only the content lies)
REDUCTION_DAMAGES = {
    "stiffness_x1.5": _scaled("stiffnessMatrix/data", 1.5),
    "stiffness_x1000": _scaled("stiffnessMatrix/data", 1000.0),
    "mass_x1.5": _scaled("massMatrix/data", 1.5),
    "mode_basis_x1.5": _scaled("modeBasis/matrix", 1.5),
    "eigenvalues_x2": _scaled("eigenValues", 2.0),
    "node_positions_x1.01": _scaled("nodes/Position", 1.01),
    "stress_modes_x3": _scaled("postProcessingModes/matrix", 3.0),
    "node_weights_x2": _scaled("nodeSets/item_0/NodeWeights", 2.0),
    "meta_mass_x1.5": _scaled("metaData/flex/mass_kg", 1.5),
    "meta_frequency_x1.5": _scaled("metaData/flex/pinned_pinned_frequency_Hz", 1.5),
    "meta_elements_changed": _replaced("metaData/flex/n_elements", 12345),
    "meta_parameters_changed": _replaced("metaData/flex/parameters", "{}"),
    "digest_deleted": _deleted("metaData/flex/digest"),
    "meta_digest_deleted": _deleted("metaData/flex/meta_digest"),  # an older entry's layout
    "digest_forged": _replaced("metaData/flex/digest", "0" * 64),
    "key_of_another_entry": _replaced("metaData/flex/key", "0123456789abcdef01234567"),
    "mode_basis_deleted": _deleted("modeBasis/matrix"),
}


@pytest.mark.parametrize("name", list(REDUCTION_DAMAGES))
def test_a_damaged_reduction_entry_is_not_loaded_and_is_said_to_be_rebuilt(entry, tmp_path,
                                                                           capsys, name):
    path, key, good = entry
    damaged = tmp_path / path.name
    damaged.write_bytes(good)
    with h5py.File(damaged, "r+") as h5:
        REDUCTION_DAMAGES[name](h5)
    assert red_cache.load_cached(damaged, key) is None
    red_cache.say_unproven(damaged)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("flex: reduction cache: entry "), lines
    assert str(damaged) in lines[0] and "did not prove its content" in lines[0]


BROKEN_FILES = {
    "empty": b"",
    "text": b"not an HDF5 file\n",
    "random": bytes(range(256)) * 8,
    "truncated_half": None,  # filled from the good entry
    "truncated_end": None,
}


@pytest.mark.parametrize("name", list(BROKEN_FILES))
def test_a_broken_reduction_file_is_not_loaded(entry, tmp_path, capsys, name):
    path, key, good = entry
    content = BROKEN_FILES[name]
    if content is None:
        content = good[:len(good) // 2] if name == "truncated_half" else good[:-10]
    broken = tmp_path / path.name
    broken.write_bytes(content)
    assert red_cache.load_cached(broken, key) is None
    red_cache.say_unproven(broken)
    (line,) = capsys.readouterr().err.splitlines()
    assert "reduction cache" in line and str(broken) in line


@pytest.mark.parametrize("damage", ["truncated"])  # the loader cases above cover the rest
def test_a_damaged_entry_is_rebuilt_replaced_and_said_once(entry, tmp_path, capsys, damage):
    path, key, good = entry
    folder = tmp_path / "reductions"
    folder.mkdir()
    target = folder / path.name
    target.write_bytes(good if damage != "truncated" else good[:len(good) // 3])
    if damage != "truncated":
        with h5py.File(target, "r+") as h5:
            REDUCTION_DAMAGES[damage](h5)
    rebuilt = red.build_reduction(*PLATE, folder)
    err = capsys.readouterr().err.splitlines()
    assert not rebuilt.from_cache and len(err) == 1 and "building the reduction again" in err[0]
    assert red_cache.load_cached(target, key) is not None  # replaced by a whole entry
    again = red.build_reduction(*PLATE, folder)
    assert again.from_cache and capsys.readouterr().err == ""
    # no temporary left: the entry, and the FFRF interface made with it beside it
    assert sorted(p.name for p in folder.iterdir()) == sorted([path.name, f"{key}.ffrf.hdf5"])


def _assert_cache_line(err: str, *words: str) -> None:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, lines
    for word in ("reduction cache", "FLEX_CACHE_DIR", *words):
        assert word in lines[0], (word, lines[0])
    assert ".tmp" not in lines[0]  # named by the entry, not by a temporary file


def _fail_with(code: int):
    def mkstemp(*args, **kwargs):
        raise OSError(code, os.strerror(code))
    return mkstemp


LOCATIONS = ["file_in_place", "file_above", "folder_at_entry", "full_disk", "read_only",
             "write_fails_midway", "broken_link"]


@pytest.mark.parametrize("where", LOCATIONS)
def test_an_unusable_cache_location_is_named_and_the_run_goes_on(tmp_path, capsys, monkeypatch,
                                                                 where):
    folder = tmp_path / "cache" / "reductions"
    entry_path = folder / "0123456789abcdef01234567.hdf5"
    written: list[Path] = []

    def write(temporary: Path) -> None:
        written.append(temporary)
        temporary.write_bytes(b"entry")
        if where == "write_fails_midway":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    if where == "file_in_place":
        folder.parent.mkdir(parents=True)
        folder.write_text("a file")
    elif where == "file_above":
        folder.parent.parent.joinpath("cache").write_text("a file")
    elif where == "folder_at_entry":
        entry_path.mkdir(parents=True)
    elif where == "broken_link":
        folder.parent.mkdir(parents=True)
        folder.symlink_to(tmp_path / "gone")
    elif where in ("full_disk", "read_only"):
        code = errno.ENOSPC if where == "full_disk" else errno.EROFS
        monkeypatch.setattr(cache_module.tempfile, "mkstemp", _fail_with(code))
    before = sorted(str(p) for p in tmp_path.rglob("*") if not p.is_dir())
    assert store(entry_path, write, REDUCTION_CACHE) is False
    words = {"file_in_place": ["is a file"], "file_above": ["is a file"],
             "folder_at_entry": ["is a folder"], "full_disk": ["No space left"],
             "read_only": ["Read-only"], "write_fails_midway": ["No space left"],
             "broken_link": ["broken link"]}[where]
    _assert_cache_line(capsys.readouterr().err, str(entry_path), *words)
    # nothing left behind (the cache folder itself may have been created)
    assert sorted(str(p) for p in tmp_path.rglob("*") if not p.is_dir()) == before
    assert all(not p.exists() for p in written)


def test_flex_run_with_flex_cache_dir_on_a_file_warns_and_completes(tmp_path, monkeypatch):
    from hostile import run_cli

    blocker = tmp_path / "not-a-folder"
    blocker.write_text("x")
    monkeypatch.setenv("FLEX_CACHE_DIR", str(blocker))
    outcome = run_cli(["run", "simulate", "--no-figures", "--out", str(tmp_path / "r.h5"),
                       "--set", 'coupler.geometry="plate"', "--set", 'coupler.model="ffrf"',
                       "--set", "coupler.thickness_m=0.004", "--set", "coupler.modes=1",
                       "--set", "coupler.mesh_size_m=0.008", "--set",
                       "simulation.end_time_s=0.001", "--set", "simulation.step_s=1e-4",
                       "--set", "simulation.error_estimate=false"])
    assert outcome.status == 0, outcome.stderr
    cache_lines = [line for line in outcome.stderr.splitlines() if "reduction cache" in line]
    assert len(cache_lines) == 1 and "FLEX_CACHE_DIR" in cache_lines[0]
    assert "Traceback" not in outcome.stderr


# --- sweep case files ------------------------------------------------------------------------
def _case(name: str, scene) -> CaseResult:
    """A cheap case function: its curve follows the scene's preload."""
    preload = scene["drive"]["spring_preload_m"]
    time_s = np.linspace(0.0, 1.0, 5)
    return CaseResult(name, "", {"time": Dataset(time_s, "s", "time"),
                                 "x": Dataset(preload * time_s, "m", "travel")},
                      counters={"steps": 4}, attrs={"note": "made by a test"})


def _damage_dataset(factor: float):
    def damage(h5: h5py.File) -> None:
        data = h5["cases/a/x"][()] * factor
        attrs = dict(h5["cases/a/x"].attrs)
        del h5["cases/a/x"]
        h5["cases/a/x"] = data
        h5["cases/a/x"].attrs.update(attrs)
    return damage


def _set_attr(path: str, key: str, value):
    def damage(h5: h5py.File) -> None:
        h5[path].attrs[key] = value
    return damage


def _del_attr(path: str, key: str):
    def damage(h5: h5py.File) -> None:
        del h5[path].attrs[key]
    return damage


SWEEP_DAMAGES = {
    "values_x1.5": _damage_dataset(1.5),
    "values_x1000": _damage_dataset(1000.0),
    "units_changed": _set_attr("cases/a/x", "units", "mm"),
    "status_flipped": _set_attr("cases/a", "status", "failed"),
    "message_added": _set_attr("cases/a", "message", "edited"),
    "counter_changed": _set_attr("cases/a", "counter_steps", 99),
    "attribute_changed": _set_attr("cases/a", "note", "edited"),
    "content_digest_removed": _del_attr("/", "sweep_content_digest"),  # an older file
    "content_digest_forged": _set_attr("/", "sweep_content_digest", "0" * 64),
}


def _sweep(folder: Path) -> dict[str, CaseResult]:
    scenes = {"a": load_scene(overrides=["drive.spring_preload_m=0.01"]),
              "b": load_scene(overrides=["drive.spring_preload_m=0.02"])}
    return run_sweep(scenes, folder, _case, scheduler="serial", progress=False,
                     study="test").results


@pytest.mark.parametrize("name", list(SWEEP_DAMAGES))
def test_a_damaged_sweep_case_file_is_run_again_and_said_so(tmp_path, capsys, name):
    first = _sweep(tmp_path)
    path = case_path(tmp_path, "a")
    with h5py.File(path, "r+") as h5:
        SWEEP_DAMAGES[name](h5)
    capsys.readouterr()
    again = _sweep(tmp_path)
    lines = [line for line in capsys.readouterr().err.splitlines() if "sweep case" in line]
    assert len(lines) == 1 and str(path) in lines[0] and "running case a again" in lines[0]
    assert np.array_equal(again["a"].datasets["x"].data, first["a"].datasets["x"].data)
    assert again["a"].datasets["x"].units == "m" and again["a"].status == "ok"
    capsys.readouterr()
    _sweep(tmp_path)  # the rewritten file proves its content: resumed silently
    assert "sweep case" not in capsys.readouterr().err


@pytest.mark.parametrize("name", ["empty", "text", "truncated", "folder"])
def test_a_broken_sweep_case_file_is_run_again(tmp_path, capsys, name):
    _sweep(tmp_path)
    path = case_path(tmp_path, "b")
    good = path.read_bytes()
    if name == "folder":
        path.unlink()
        path.mkdir()
        (path / "inside").write_text("x")
    else:
        path.write_bytes({"empty": b"", "text": b"x,y\n", "truncated": good[:200]}[name])
    capsys.readouterr()
    if name == "folder":  # cannot be replaced: the sweep says so instead of writing over it
        with pytest.raises(Exception) as error:
            _sweep(tmp_path)
        assert "b.h5" in str(error.value) and "\n" not in str(error.value)
        return
    again = _sweep(tmp_path)
    assert again["b"].status == "ok"
    assert sum("sweep case" in line for line in capsys.readouterr().err.splitlines()) == 1


@pytest.mark.parametrize("where", ["file_in_place", "file_above"])
def test_a_sweep_folder_that_is_a_file_is_refused_before_any_case_runs(tmp_path, where):
    from flex.base.errors import CacheError

    blocked = tmp_path / "sweep"
    if where == "file_in_place":
        blocked.mkdir()
        (blocked / "cases").write_text("x")
    else:
        blocked.write_text("x")
    ran: list[str] = []

    def case(name, scene):
        ran.append(name)
        return _case(name, scene)

    with pytest.raises(CacheError) as error:
        run_sweep({"a": load_scene()}, blocked, case, scheduler="serial", progress=False)
    assert "sweep case folder" in str(error.value) and "--folder" in str(error.value)
    assert ran == []


def test_content_digest_reads_like_a_loader():
    """The digest of written and read-back values agrees (int vs float, str vs bytes), and
    differs for any changed number or text."""
    assert content_digest([("x", [1, 2, 3])]) == content_digest([("x", np.array([1.0, 2, 3]))])
    assert content_digest([("t", "abc")]) == content_digest([("t", b"abc")])
    assert content_digest([("x", [1.0, 2.0])]) != content_digest([("x", [1.0, 2.0000001])])
    assert content_digest([("x", 1.0)]) != content_digest([("y", 1.0)])
    assert content_digest([("t", np.array(["a", "b"], dtype=object))]) == content_digest(
        [("t", np.array([b"a", b"b"]))])


@pytest.mark.slow
def test_a_damaged_geometric_stiffness_entry_is_not_trusted(built, capsys):
    from flex.bodies.geometric_stiffness import geometric_stiffness

    first = geometric_stiffness(built)
    entry = next(built.cache_file.parent.glob("*.geometric.hdf5"))
    with h5py.File(entry, "r+") as h5:
        for name in list(h5):
            if isinstance(h5[name], h5py.Dataset) and h5[name].dtype.kind == "f":
                _scaled(name, 1.5)(h5)
    capsys.readouterr()
    again = geometric_stiffness(built)
    assert not again.from_cache and "geometric" in capsys.readouterr().err
    del first


def test_hostile_case_count():
    """This file's share of issue 26's hostile cases."""
    count = (len(REDUCTION_DAMAGES) + len(BROKEN_FILES) + 1 + len(LOCATIONS) + 1
             + len(SWEEP_DAMAGES) + 4 + 2)
    assert count >= 45, count


def test_no_cache_module_state():
    """The cache helpers keep nothing between calls (flex's rule: no module-level state)."""
    assert REDUCTION_CACHE.label == "reduction cache" and SWEEP_CASES.label.startswith("sweep")
    assert not [name for name, value in vars(cache_module).items()
                if isinstance(value, list | dict | set) and not name.startswith("__")]
