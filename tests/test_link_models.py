"""The link-model registry (flex.dynamics.link_models) from outside: a toy model added by a
registry of one's own runs through the public API; the contract is enforced (unknown names,
links a model does not model, a model's own check); the registry is immutable; the scene
schema's built-in names are the registry's; no module of flex names the nonlinear FE model
except its entry and the schema."""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest

import flex
from flex.base.errors import SceneError
from flex.data.scene import BUILTIN_LINK_SCHEMAS, LinkSchema
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel

FLEX = Path(__file__).resolve().parent.parent / "flex"
TOY = "stiff"
#: a short run of the bundled scene (the spring deployment starts)
SHORT = {"simulation.end_time_s": 0.005}


def _toy_check(link: str, scene: dict) -> None:
    if scene[link]["geometry"] != "lumped":
        raise SceneError(f'{link}.model = "{TOY}" is a lumped coupler; accepted: '
                         f'{link}.geometry = "lumped"')


def _toy_datasets(mech, link, time_s):
    out = BUILTIN_LINK_MODELS["rigid"].datasets(mech, link, time_s)
    if link == "coupler":  # the toy's own dataset: proves its hook ran
        out["coupler/toy_marker"] = _dataset(time_s)
    return out


def _dataset(time_s):
    from flex.data.results import Dataset

    return Dataset(np.ones_like(time_s), "1", "the toy model's marker (1 at every sample)")


#: the toy: the rigid coupler under another name, with its own check and one more dataset
TOY_MODEL = dataclasses.replace(BUILTIN_LINK_MODELS["rigid"], name=TOY, links=("coupler",),
                                label="toy stiff coupler", auto_choice=False,
                                check=_toy_check, datasets=_toy_datasets)
REGISTRY = MappingProxyType({**BUILTIN_LINK_MODELS, TOY: TOY_MODEL})


def test_a_toy_model_runs_through_the_public_api_as_the_rigid_model_it_copies(reduction_cache):
    toy_scene = flex.load_scene(overrides={**SHORT, "coupler.model": TOY},
                                link_models=REGISTRY)
    toy = flex.simulate(toy_scene, "toy", cache_dir=reduction_cache, link_models=REGISTRY)
    rigid = flex.simulate(flex.load_scene(overrides=SHORT), "rigid", cache_dir=reduction_cache)
    assert toy.status == rigid.status == "ok"
    assert 'model = "stiff"' in toy.scene_toml
    np.testing.assert_array_equal(toy.datasets["coupler/toy_marker"].data, 1.0)
    assert "coupler/toy_marker" not in rigid.datasets
    # the same bodies, joints and solver: the same motion (the built-in rigid run is the
    # independent reference; an entry not used to build would fail here or before)
    for name in ("crank/angle", "slider/position", "joints/C/force_on_coupler",
                 "coupler/angle", "energy/total"):
        np.testing.assert_allclose(toy.datasets[name].data, rigid.datasets[name].data,
                                   rtol=1e-9, atol=1e-12, err_msg=name)
    assert toy.attrs["solver_defaults_entry"] == "rigid"  # its rigid flag chose the entry


def test_an_unknown_model_is_refused_naming_the_accepted_ones():
    with pytest.raises(SceneError, match='coupler.model = \'stiff\': must be one of "rigid", '
                                         '"ffrf", "nonlinear_fe", "exact_beam", '
                                         '"auto"'):
        flex.load_scene(overrides={"coupler.model": TOY})
    scene = flex.load_scene(overrides={"coupler.model": TOY}, link_models=REGISTRY)
    with pytest.raises(SceneError, match="must be one of"):
        flex.simulate(scene)  # the built-in registry: the toy is unknown there
    with pytest.raises(SceneError, match='crank.model = \'stiff\': must be one of "rigid", '
                                         '"ffrf", "exact_beam", "auto"'):
        flex.load_scene(overrides={"crank.model": TOY}, link_models=REGISTRY)


def test_a_models_own_check_is_enforced():
    with pytest.raises(SceneError, match='coupler.model = "stiff" is a lumped coupler'):
        flex.load_scene(overrides={"coupler.model": TOY, "coupler.geometry": "plate"},
                        link_models=REGISTRY)


def test_the_registry_and_its_entries_are_immutable():
    with pytest.raises(TypeError):
        BUILTIN_LINK_MODELS[TOY] = TOY_MODEL  # type: ignore[index]
    with pytest.raises(dataclasses.FrozenInstanceError):
        BUILTIN_LINK_MODELS["rigid"].name = TOY  # type: ignore[misc]
    assert TOY not in BUILTIN_LINK_MODELS


def test_the_schemas_built_in_names_are_the_registrys():
    assert list(BUILTIN_LINK_SCHEMAS) == list(BUILTIN_LINK_MODELS)
    for name, model in BUILTIN_LINK_MODELS.items():
        assert isinstance(model, LinkModel) and model.name == name
        assert {f.name: getattr(model, f.name) for f in dataclasses.fields(LinkSchema)} \
            == dataclasses.asdict(BUILTIN_LINK_SCHEMAS[name])


def _strings_outside_docstrings(path: Path) -> list[tuple[int, str]]:
    tree = ast.parse(path.read_text())
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef
                                | ast.AsyncFunctionDef)
                  and node.body and isinstance(node.body[0], ast.Expr)
                  and isinstance(node.body[0].value, ast.Constant)}
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and id(node) not in docstrings]


def test_only_the_registry_and_the_schema_name_the_nonlinear_fe_model():
    allowed = {FLEX / "dynamics" / "link_models.py", FLEX / "data" / "scene.py"}
    found = [f"{path.relative_to(FLEX.parent)}:{line}"
             for path in sorted(FLEX.rglob("*.py")) if path not in allowed
             for line, text in _strings_outside_docstrings(path) if "nonlinear_fe" in text]
    assert not found, f"model name written outside the registry: {found}"


def test_stored_motion_is_read_back_through_the_entrys_reader():
    """The contract's point 10: each entry names its reader of stored motion; flex.tools.motion
    calls through it and names no kind."""
    from flex.dynamics.link_outputs import MotionReader

    for model in BUILTIN_LINK_MODELS.values():
        assert isinstance(model.stored_motion, MotionReader)
    assert BUILTIN_LINK_MODELS["rigid"].stored_motion.kind == "rigid"
    assert BUILTIN_LINK_MODELS["ffrf"].stored_motion.kind == "modal"
    with pytest.raises(ValueError, match="MotionReader"):
        dataclasses.replace(BUILTIN_LINK_MODELS["rigid"], stored_motion="modal")
    text = (FLEX / "tools" / "motion.py").read_text()
    assert not any(f'"{kind}"' in text for kind in ("modal", "nodal", "none"))
