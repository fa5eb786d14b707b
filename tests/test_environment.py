"""The environment is read at the edges only: values travel as arguments.

The command line (``flex/cli.py``) and the public
API (``flex/api.py``) read ``os.environ`` once and pass what they read on (the reduction cache
folder, a study's declared variables); no other library function reads it.
"""

from __future__ import annotations

import ast
import os
from pathlib import Path

import pytest

from flex.bodies.reduction import reduction_cache_dir

FLEX = Path(__file__).resolve().parent.parent / "flex"
#: (module, enclosing function) allowed to touch the process environment, and why
EDGES = {
    ("cli.py", "main"): "FLEX_DEBUG: show the traceback of an internal error",
    ("cli.py", "_run"): "flex run: the reduction cache folder and the study's variables",
    ("cli.py", "_design"): "flex design: the reduction cache folder",
    ("cli.py", "_view_tool"): "flex export / animate: the reduction cache folder",
    ("api.py", "_cache_dir"): "flex.simulate / flex.run_study: the user's cache folder",
    ("api.py", "run_study"): "flex.run_study: the study's declared variables",
    # configures Exudyn itself (no user settings file) before it is imported
    ("dynamics/builder.py", "<module>"): "os.environ.setdefault('EXUDYN_NO_USER_SETTINGS')",
    # the environment of a child `make` process (with its own FLEX_CACHE_DIR)
    ("experiments/workprecision/benchmark.py", "bench_make_all"): "the child make's environment",
    ("experiments/workprecision/budget_cost.py", "_command_line"):
        "the timed command line's environment (the cache folder set)",
}


def _environment_uses(tree: ast.AST) -> list[tuple[str, int]]:
    """(enclosing function or ``<module>``, line) of every ``os.environ`` / ``getenv`` /
    ``putenv`` use and every ``from os import environ``."""
    found: list[tuple[str, int]] = []

    def visit(node: ast.AST, where: str) -> None:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            where = node.name if where == "<module>" else where
        if isinstance(node, ast.Attribute) and node.attr in ("environ", "getenv", "putenv",
                                                             "environb", "unsetenv"):
            found.append((where, node.lineno))
        if isinstance(node, ast.ImportFrom) and node.module == "os" and any(
                alias.name in ("environ", "getenv", "putenv") for alias in node.names):
            found.append((where, node.lineno))
        for child in ast.iter_child_nodes(node):
            visit(child, where)

    visit(tree, "<module>")
    return found


def test_only_the_edges_read_the_environment():
    offenders = []
    for path in sorted(FLEX.rglob("*.py")):
        module = path.relative_to(FLEX).as_posix()
        for where, line in _environment_uses(ast.parse(path.read_text(encoding="utf-8"))):
            if (module, where) not in EDGES:
                offenders.append(f"flex/{module}:{line} ({where})")
    assert not offenders, ("the library reads the environment outside its edges (pass the "
                           "value as an argument instead): " + ", ".join(offenders))


def test_the_reduction_cache_folder_follows_its_three_rules():
    home = {"HOME": "/home/u"}
    assert reduction_cache_dir({**home, "FLEX_CACHE_DIR": "/big/disk",
                                "XDG_CACHE_HOME": "/xdg"}) == Path("/big/disk/reductions")
    assert reduction_cache_dir({**home, "FLEX_CACHE_DIR": "~/c"}) == Path("/home/u/c/reductions")
    assert reduction_cache_dir({**home, "XDG_CACHE_HOME": "/xdg"}) == Path(
        "/xdg/flex/reductions")
    assert reduction_cache_dir(home) == Path("/home/u/.cache/flex/reductions")
    # empty values count as unset, as they did when read from the environment
    assert reduction_cache_dir({**home, "FLEX_CACHE_DIR": "", "XDG_CACHE_HOME": ""}) == Path(
        "/home/u/.cache/flex/reductions")


def test_the_reduction_cache_folder_reads_only_the_mapping_it_gets(monkeypatch):
    monkeypatch.setenv("FLEX_CACHE_DIR", "/from/the/process")
    monkeypatch.setenv("XDG_CACHE_HOME", "/from/the/process/xdg")
    assert reduction_cache_dir({"HOME": "/h"}) == Path("/h/.cache/flex/reductions")
    assert reduction_cache_dir(os.environ) == Path("/from/the/process/reductions")


def test_the_edges_pass_the_cache_folder_and_the_study_variables(monkeypatch, tmp_path):
    from flex.study import from_environment

    monkeypatch.setenv("FLEX_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv("FLEX_BENCH_MAKE", "0")
    monkeypatch.delenv("FLEX_BENCH_NONLINEAR", raising=False)
    edge = from_environment("bench", os.environ)
    assert edge == {"cache_dir": tmp_path / "reductions",
                    "environment": {"FLEX_BENCH_MAKE": "0"}}
    assert from_environment("simulate", os.environ)["environment"] == {}  # declares none


def test_the_cache_folder_is_not_part_of_a_sweep_case(tmp_path):
    import functools
    import pickle

    from flex.data.scene import load_scene
    from flex.experiments.fitting import kfit
    from flex.sweep import case_hash, simulate_scene_case

    scene = load_scene()
    plain = case_hash(scene, simulate_scene_case)
    for folder in (tmp_path, None):
        bound = functools.partial(simulate_scene_case, cache_dir=folder)
        assert case_hash(scene, bound) == plain
    # kfit's cases keep the identity they had before the folder became an argument
    phases = kfit.sweep_phases(tmp_path)
    fit = phases["fit"].case_function(None)
    assert case_hash(scene, fit) == case_hash(scene, kfit.fit_case)
    validation = phases["validation"].case_function("law")
    assert case_hash(scene, validation) == case_hash(
        scene, functools.partial(kfit.validation_case, criterion_toml="law"))
    assert case_hash(scene, validation) != case_hash(
        scene, phases["validation"].case_function("another law"))
    assert pickle.loads(pickle.dumps(fit)).keywords == {"cache_dir": tmp_path}  # to workers


COARSE_FFRF = ['coupler.geometry="plate"', 'coupler.model="ffrf"', "coupler.thickness_m=0.005",
               "coupler.mesh_size_m=0.005", "coupler.modes=2", "simulation.end_time_s=0.001"]


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_the_api_reads_the_cache_folder_and_a_study_run_passes_it_on(tmp_path, monkeypatch):
    import flex
    from flex.study import execute, load_study, study_scene

    monkeypatch.setenv("FLEX_CACHE_DIR", str(tmp_path))
    assert flex.simulate(flex.load_scene(overrides=COARSE_FFRF)).status == "ok"
    # the API's default: the user's (the run's reduction, its geometric stiffness and FFRF
    # interface beside it; at 1 % the budget's modes and mesh companions do not run: the
    # exact beam's model term holds them)
    entries = sorted(path.name for path in (tmp_path / "reductions").glob("*.hdf5"))
    assert len(entries) == 3 and {name.split(".", 1)[1] for name in entries} == {
        "hdf5", "geometric.hdf5", "ffrf.hdf5"}
    monkeypatch.delenv("FLEX_CACHE_DIR")
    module, given = load_study("simulate"), tmp_path / "given"
    output = execute(module, study_scene(module, None, COARSE_FFRF), cache_dir=given)
    assert output.as_expected
    assert sorted(path.name for path in given.glob("*.hdf5")) == entries
