"""The model ladder and the headline quantities as data (flex.config.ladder,
flex.data.headlines), from outside the library.

- A toy rung (an FFRF body under another name, its own registry entry and ladder row,
  between the FFRF rung and the nonlinear FE coupler) gets, touching no flex module: a
  model term in the budget (its own fraction of the same elastic difference the FFRF run
  measures: the two runs are the same physics, so the terms stand in the fractions' ratio),
  its "leaves out" line, its place in ``auto``'s climb (at a tolerance its bound meets and
  the FFRF body's does not, ``auto`` takes it where the built-ins take the nonlinear FE
  coupler), the refinement's knob (the next rung up from FFRF), and export and animation of
  its stored motion (read back by meshio).
- A toy headline quantity (one registry entry) appears in the budget (every term, its
  value the reader's), ``inspect`` and the report.
- One test per built-in rung checks its place (scikit-fem's ``test_convergence`` style: one
  row per rung).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import MappingProxyType

import meshio
import numpy as np
import pytest

import flex
from flex.base.errors import FlexError
from flex.config.ladder import (
    EXACT_BEAM_RUNG,
    FFRF_RUNG,
    LINEAR_FFRF_RUNG,
    LUMPED_RIGID_RUNG,
    NONLINEAR_FE_RUNG,
    RIGID_RUNG,
    Rung,
    climb,
    next_rung,
)
from flex.config.settings import pinned_overrides
from flex.data.headlines import BUILTIN_HEADLINES, Headline
from flex.data.results import write_results
from flex.data.scene import load_scene
from flex.dynamics.exact_beam_link import CALIBRATED_BEAM_RUNG
from flex.dynamics.link_models import BUILTIN_LINK_MODELS
from flex.fidelity.stored_budget import budget_rows

# a coarse 5 mm plate (maxh 5 mm, 4 modes), 2 ms at the rigid 1e-5 s step
PLATE = [*pinned_overrides(), 'coupler.geometry="plate"', "coupler.thickness_m=0.005",
         "coupler.mesh_size_m=0.005", "coupler.modes=4", "simulation.end_time_s=0.002",
         "simulation.output_step_s=1e-4"]
TOY = "toy_beam"
TOY_BOUND = 0.0005
TOY_RUNG = Rung(3, "toy beam", bound=lambda values, load_ratio, cache_dir: TOY_BOUND,
                own_fraction=0.002,
                motion_fraction=0.05, measured_by="toy beam against the rung above: 0.002 "
                "of its own quantities, 0.05 of the motion's elastic part",
                leaves_out="the toy beam's idealization of the {links}")
TOY_MODEL = dataclasses.replace(BUILTIN_LINK_MODELS["ffrf"], name=TOY, label="toy beam",
                                rung=lambda values: TOY_RUNG)
REGISTRY = MappingProxyType({**BUILTIN_LINK_MODELS, TOY: TOY_MODEL})
QUANTITY = "coupler_mean_deflection_m"
DEFLECTION = "coupler/midpoint_deflection"


def _mean_deflection(datasets):
    if DEFLECTION not in datasets or not np.any(datasets[DEFLECTION].data):
        return None
    return float(np.mean(np.abs(datasets[DEFLECTION].data)))


TOY_HEADLINE = Headline(QUANTITY, "m", "mean |midpoint deflection| of the coupler (toy)",
                        _mean_deflection, link="coupler")
HEADLINES = MappingProxyType({**BUILTIN_HEADLINES, QUANTITY: TOY_HEADLINE})


@pytest.fixture(scope="module")
def runs(reduction_cache):
    """The plate as the built-in FFRF body and as the toy rung, with their budgets (the toy
    run also budgets the toy headline)."""
    ffrf = flex.simulate(load_scene(overrides=[*PLATE, 'coupler.model="ffrf"']), "ffrf",
                         cache_dir=reduction_cache)
    toy_scene = load_scene(overrides=[*PLATE, f'coupler.model="{TOY}"'], link_models=REGISTRY)
    toy = flex.simulate(toy_scene, "toy", cache_dir=reduction_cache, link_models=REGISTRY,
                        headlines=HEADLINES)
    return ffrf, toy


@pytest.fixture(scope="module")
def toy_file(runs, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("toy") / "toy.h5"
    return write_results(path, "simulate", [runs[1]], runs[1].scene_toml)


def test_the_toy_rung_gets_its_model_term_and_leaves_out_line(runs):
    ffrf, toy = runs
    quantity = "coupler_peak_deflection_m"
    term = "estimated_error_" + quantity + "_model"
    assert ffrf.attrs[term] > 0
    # a rung measured by fractions: its own fraction of the elastic difference to a rigid
    # twin, which has no deflection: the whole peak (the FFRF rung measures against the beam)
    assert toy.attrs[term] == pytest.approx(
        TOY_RUNG.own_fraction * toy.attrs["headline_" + quantity], rel=1e-9)
    assert FFRF_RUNG.measured_against_text.split("(")[0] in ffrf.attrs[
        "estimated_error_method"]
    assert toy.attrs["estimated_error_joint_C_peak_force_N_model"] > 0
    assert "the toy beam's idealization of the coupler" in toy.attrs[
        "estimated_error_leaves_out"]
    assert TOY_RUNG.measured_by in toy.attrs["estimated_error_method"]


def test_a_model_on_no_rung_says_its_model_error_is_left_out():
    from flex.fidelity.error_budget import _model_term  # noqa: PLC2701 - the term alone

    offladder = dataclasses.replace(TOY_MODEL, rung=lambda values: None)
    registry = MappingProxyType({**BUILTIN_LINK_MODELS, TOY: offladder})
    scene = load_scene(overrides=[*PLATE, f'coupler.model="{TOY}"'], link_models=registry)
    leaves_out: list[str] = []
    terms, how, measured = _model_term(scene, None, None, leaves_out, registry)
    assert terms == {} and how == "no flexible link below the top rung" and not measured
    assert any("stands on no rung of the ladder" in line for line in leaves_out)


def test_auto_climbs_onto_the_toy_rung_below_the_builtins_choice():
    """At 0.1 % the FFRF body's bound (0.5 %) fails; the toy's (0.05 %, level 3) meets it
    before the exact beam's (level 5: 0.05 t / L, 0.0625 % at 1 mm), which the built-ins
    take."""
    from flex.fidelity.auto import resolve

    overrides = ['coupler.geometry="plate"', "coupler.thickness_m=0.001",
                 'coupler.model="auto"', "fidelity.tolerance=0.001"]
    builtin = resolve(load_scene(overrides=overrides), quiet=True)
    toy = resolve(load_scene(overrides=overrides, link_models=REGISTRY), quiet=True,
                  link_models=REGISTRY)
    assert builtin.scene["coupler"]["model"] == "exact_beam"
    # the exact beam's first guess at 0.1 % (EXACT_BEAM_SETTINGS: measured to state 0.067 %
    # on the 0.7 mm plate's first crest)
    assert builtin.scene["coupler"]["elements"] == 64
    assert builtin.scene["simulation"]["step_s"] == pytest.approx(5e-6)
    assert toy.scene["coupler"]["model"] == TOY
    reason = next(d.reason for d in toy.decisions if d.link == "coupler")
    assert f"toy beam model error {TOY_BOUND:g} of the deflection" in reason


def test_the_refinement_climbs_to_the_next_rung_up():
    values = load_scene(overrides=PLATE)["coupler"] | {"model": "ffrf"}
    assert next_rung("coupler", values, BUILTIN_LINK_MODELS) == "exact_beam"
    assert next_rung("coupler", values, REGISTRY) == TOY
    assert next_rung("coupler", values | {"model": TOY}, REGISTRY) == "exact_beam"
    assert next_rung("coupler", values | {"model": "exact_beam"}, REGISTRY) == "nonlinear_fe"
    assert next_rung("coupler", values | {"model": "nonlinear_fe"}, REGISTRY) is None
    # a rigid link has no model term to refine: the refinement does not climb from it
    assert next_rung("crank", load_scene()["crank"] | {"model": "rigid"}, REGISTRY) is None


def test_the_toy_rungs_motion_exports_and_animates(toy_file, tmp_path, reduction_cache):
    from flex.tools.animate import animate_case
    from flex.tools.export import export_case

    with pytest.raises(FlexError, match="not in the registry of link models"):
        export_case(toy_file, "toy", tmp_path / "refused", cache_dir=reduction_cache,
                    progress=None)
    out = export_case(toy_file, "toy", tmp_path / "out", cache_dir=reduction_cache,
                      progress=None, link_models=REGISTRY)
    with meshio.xdmf.TimeSeriesReader(str(out.xdmf)) as reader:
        points, cells = reader.read_points_cells()
        assert reader.num_steps == 21
        assert len(points) > 0 and cells[0].type == "tetra10"
    frame = animate_case(toy_file, "toy", tmp_path / "frame.png", cache_dir=reduction_cache,
                         link_models=REGISTRY)
    assert Path(frame.path).stat().st_size > 0


def test_the_toy_headline_is_in_the_budget_inspect_and_the_report(runs, toy_file, capsys):
    from flex.cli import main

    toy = runs[1]
    rows = {row.quantity: row for row in budget_rows(toy.attrs)}
    assert rows[QUANTITY].what == TOY_HEADLINE.what and rows[QUANTITY].units == "m"
    assert rows[QUANTITY].value == pytest.approx(_mean_deflection(toy.datasets), rel=1e-12)
    assert set(rows[QUANTITY].terms) == {"step", "modes", "mesh", "model"}
    assert rows[QUANTITY].terms["model"] > 0  # the link's own quantity: the rung's fraction
    assert main(["inspect", str(toy_file)]) == 0
    assert TOY_HEADLINE.what in capsys.readouterr().out
    from flex.tools.report import render_report

    # the report's table escapes the bars of |deflection|
    assert TOY_HEADLINE.what.replace("|", "\\|") in render_report(toy_file)


@pytest.mark.parametrize("rung, model, values", [
    (RIGID_RUNG, "rigid", {"geometry": "plate"}),
    (LUMPED_RIGID_RUNG, "rigid", {"geometry": "lumped"}),
    (LINEAR_FFRF_RUNG, "ffrf", {"geometric_stiffness": False}),
    (FFRF_RUNG, "ffrf", {"geometric_stiffness": True}),
    (CALIBRATED_BEAM_RUNG, "exact_beam", {}),
    (NONLINEAR_FE_RUNG, "nonlinear_fe", {}),
])
def test_each_builtin_model_stands_on_its_rung(rung, model, values):
    assert BUILTIN_LINK_MODELS[model].rung(values) is rung
    # the measured bounds: the FFRF bodies' and the exact beam's
    assert rung.bounded == (model in ("ffrf", "exact_beam"))


def test_the_ladder_orders_the_builtin_rungs_and_climbs_by_their_bounds(reduction_cache):
    levels = [RIGID_RUNG.level, LINEAR_FFRF_RUNG.level, FFRF_RUNG.level,
              CALIBRATED_BEAM_RUNG.level, NONLINEAR_FE_RUNG.level]
    assert levels == sorted(levels)
    plate = load_scene(overrides=['coupler.geometry="plate"'])["coupler"] | {"model": "ffrf"}
    thin, thick = plate | {"thickness_m": 0.001}, plate | {"thickness_m": 0.003}
    values = {"geometric_stiffness": True, **thin}
    assert climb("coupler", values, 0.1, 0.01, BUILTIN_LINK_MODELS).model == "ffrf"
    # 0.1 %: the calibrated beam's idealization, measured on each plate's 3-D reference
    # (~4e-5 at 1 mm, ~1.4e-5 at 3 mm), meets it on both; the uncalibrated beam's bound
    # 0.05 t / L (0.19 % at 3 mm) would not
    for plate_values in (values, values | thick):
        assert climb("coupler", plate_values, 0.1, 0.001, BUILTIN_LINK_MODELS,
                     reduction_cache).model == "exact_beam"
    assert EXACT_BEAM_RUNG.bound(thick, 0.1, None) > 0.001
    assert climb("coupler", values, 0.1, 1e-6, BUILTIN_LINK_MODELS,
                 reduction_cache).model == "nonlinear_fe"
    linear = thin | {"geometric_stiffness": False}  # 0.005 + 1.0 x load ratio
    assert climb("coupler", linear, 0.004, 0.01, BUILTIN_LINK_MODELS).model == "ffrf"
    assert climb("coupler", linear, 0.006, 0.01, BUILTIN_LINK_MODELS).model == "exact_beam"
