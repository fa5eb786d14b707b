"""The knobs and rungs as data, checked against what they declare (flex.config.knobs,
flex.config.ladder): parametrized over the registries, so a new knob or rung is checked by
adding its cheap scene here (docs/extending.md).

- Each knob's declared order of convergence is observed on a cheap scene: three runs, the
  knob turned twice (scikit-fem's test_convergence.py: the observed order, not a bound). A
  knob whose declared order is deliberately low (a mesh: the budget extrapolates with 2, the
  plates show more) must not converge slower than it declares; a knob whose difference is
  taken whole (the modes) must fall by at least its declared prior fall per turn.
- Each rung's declared bound holds on a cheap scene against the rung above that measures it.
"""

from __future__ import annotations

import math

import pytest

from flex.api import simulate
from flex.base.physics import Plate
from flex.config.knobs import ELEMENTS, KNOBS, MESH, MODES, STEP, Knob
from flex.config.ladder import EXACT_BEAM_RUNG, FFRF_RUNG, LINEAR_FFRF_RUNG
from flex.data.headlines import BUILTIN_HEADLINES
from flex.data.scene import apply_overrides, load_scene
from flex.fidelity.criteria import euler_load_ratio

QUIET = ["simulation.error_estimate=false"]
PLATE = ['coupler.geometry="plate"']

#: per knob: the scene it is turned on, the link (None: the scene's step), its first value,
#: the quantity observed and whether the run is slow (a reduction per value)
CASES = {
    STEP.name: (["simulation.end_time_s=0.02", "simulation.newton_relative_tolerance=1e-10"],
                "", 4e-5, "crank_angle_end_rad", False),
    ELEMENTS.name: ([*PLATE, 'coupler.model="exact_beam"', "coupler.thickness_m=0.002",
                     "simulation.end_time_s=0.012", "simulation.step_s=1e-5"],
                    "coupler", 8, "coupler_first_crest_deflection_m", False),
    MODES.name: ([*PLATE, 'coupler.model="ffrf"', "coupler.thickness_m=0.002",
                  "coupler.mesh_size_m=0.003", "simulation.end_time_s=0.012",
                  "simulation.step_s=1e-5"], "coupler", 1, "coupler_first_crest_deflection_m",
                 True),
    MESH.name: ([*PLATE, 'coupler.model="ffrf"', "coupler.thickness_m=0.003", "coupler.modes=2",
                 "simulation.end_time_s=0.012", "simulation.step_s=1e-5"], "coupler", 0.012,
                "coupler_first_crest_deflection_m", True),
}


def test_every_knob_has_its_cheap_scene():
    assert set(CASES) == set(KNOBS)


def _values(knob: Knob, first):
    second = knob.finer(first)
    return [first, second, knob.finer(second)]


def _observed(knob: Knob, reduction_cache) -> tuple[float, float, float]:
    """The knob's quantity at three turns: (observed order at its ratio, first difference
    over the second)."""
    overrides, link, first, quantity, _ = CASES[knob.name]
    scene = load_scene(overrides=[*overrides, *QUIET])
    values = []
    for value in _values(knob, first):
        run = simulate(apply_overrides(scene, [knob.override(link, value)]), "knob",
                       cache_dir=reduction_cache)
        values.append(BUILTIN_HEADLINES[quantity].read(run.datasets))
    first_difference, second_difference = abs(values[0] - values[1]), abs(values[1] - values[2])
    fall = first_difference / second_difference
    return math.log(fall) / math.log(knob.ratio), fall, first_difference


@pytest.mark.parametrize("name", [
    pytest.param(name, marks=pytest.mark.slow) if CASES[name][4] else name for name in CASES])
def test_each_knob_converges_as_it_declares(name, reduction_cache):
    knob = KNOBS[name]
    order, fall, difference = _observed(knob, reduction_cache)
    assert difference > 0  # the knob moves the quantity: its term is measurable
    if knob.order is None:  # taken whole: it must fall at least as refinement predicts
        assert fall >= knob.prior_fall
    elif knob.per_headline_order:  # extrapolated with the quantity's order (2 here), which
        assert order >= knob.order - 0.25  # the plates exceed (4.1 at 2 mm): it leans safe
    else:
        assert order == pytest.approx(knob.order, abs=0.25)


def _peak(overrides, reduction_cache) -> float:
    run = simulate(load_scene(overrides=[*PLATE, *overrides, *QUIET]), "rung",
                   cache_dir=reduction_cache)
    return BUILTIN_HEADLINES["coupler_deployment_peak_deflection_m"].read(run.datasets)


#: a rung: the scene it is checked on (plate and step), its link's model there, the rung
#: above that measures it, and whether the check is slow (each takes 5-6 s: make test-slow)
RUNGS = {
    FFRF_RUNG.name: (FFRF_RUNG, ["coupler.thickness_m=0.001", "simulation.end_time_s=0.03",
                                 "simulation.step_s=1e-5"],
                     ['coupler.model="ffrf"', "coupler.modes=6", "coupler.mesh_size_m=0.002"],
                     ['coupler.model="exact_beam"', "coupler.elements=128"], True),
    LINEAR_FFRF_RUNG.name: (LINEAR_FFRF_RUNG, [
        "coupler.thickness_m=0.001", "simulation.end_time_s=0.03", "simulation.step_s=1e-5"],
        ['coupler.model="ffrf"', "coupler.modes=6", "coupler.mesh_size_m=0.002",
         "coupler.geometric_stiffness=false"],
        ['coupler.model="exact_beam"', "coupler.elements=128"], True),
    EXACT_BEAM_RUNG.name: (EXACT_BEAM_RUNG, [
        "coupler.thickness_m=0.003", "simulation.end_time_s=0.01", "simulation.step_s=1e-5"],
        ['coupler.model="exact_beam"', "coupler.elements=64"],
        ['coupler.model="nonlinear_fe"', "coupler.mesh_size_m=0.003"], True),
}


@pytest.mark.parametrize("name", [
    pytest.param(name, marks=pytest.mark.slow) if RUNGS[name][4] else name for name in RUNGS])
def test_each_bounded_rung_holds_its_bound_against_the_rung_above(name, reduction_cache):
    rung, scene, own, above, _ = RUNGS[name]
    rigid = simulate(load_scene(overrides=[*PLATE, *scene, *QUIET]), "rigid").datasets
    plate = load_scene(overrides=[*PLATE, *scene])["coupler"]
    load_ratio = euler_load_ratio(*(rigid[path].data for path in (
        "joints/B/force_on_coupler", "joints/C/force_on_coupler", "coupler/angle")),
        Plate.of(plate))
    mine = _peak([*scene, *own], reduction_cache)
    other = _peak([*scene, *above], reduction_cache)
    assert abs(mine - other) / other <= rung.bound(plate, load_ratio, reduction_cache)
