"""The geometrically exact beam coupler (``coupler.model = "exact_beam"``,
:mod:`flex.bodies.exact_beam`): its section against the closed forms, its pinned-pinned
bending frequency against Timoshenko's, the thesis deployment against the default FFRF
coupler, the order of its element convergence, a beam crank against an FFRF crank, and the
refusal of bad ``elements`` and of a beam crank on a 3D coupler.

Measured 2026-11-28 (h = 1e-5 s, modified Newton, relative / absolute Newton tolerance 1e-7 /
1e-6), bundled scene with a 1 mm plate coupler, 0.03 s:

- peak |midpoint deflection| 0.17041 / 0.17072 / 0.17193 mm at 16 / 32 / 64 elements, the
  default FFRF coupler's 0.17149 mm (-0.63 / -0.45 / +0.26 %); crank-angle maximum 3.3e-5 /
  1.7e-5 / 1.3e-5 rad above the FFRF's;
- the first crest after a zero-phase 2 kHz low-pass (the ~10 kHz ripple of the release
  races between sub-crests otherwise): 0.095001, 0.096669, 0.097091, 0.097198, 0.097224 mm
  at 8 ... 128 elements: observed order 1.98, 1.99, 2.0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import flex
from flex.base import physics
from flex.base.errors import SceneError
from flex.base.physics import SHEAR_CORRECTION_RECTANGLE, Plate
from flex.bodies.exact_beam import (
    add_exact_beam_link,
    exact_beam_section,
    section_datasets,
    section_stress_peaks,
)
from flex.data.headlines import BUILTIN_HEADLINES, first_peak_index
from flex.experiments.thesis.beams import Material, timoshenko_bending_rad_per_s

#: the thesis's coupler plate (Table 5, model 0): L, t, w [m], E [Pa], rho [kg/m^3], nu
PLATE = dict(length_m=0.08, thickness_m=0.001, width_m=0.01, youngs_modulus_Pa=200e9,
             density_kg_per_m3=7850.0, poisson_ratio=0.3)
BEAM = {"coupler.model": "exact_beam", "coupler.geometry": "plate",
        "simulation.error_estimate": False}


def _observed_order(coarse: float, middle: float, fine: float) -> float:
    """Order of convergence from three values at h, h/2, h/4."""
    return math.log2(abs(coarse - middle) / abs(middle - fine))


def test_section_is_the_plates_closed_forms():
    section = exact_beam_section(physics.Plate(**PLATE))
    length, t, w = PLATE["length_m"], PLATE["thickness_m"], PLATE["width_m"]
    e, rho, nu = PLATE["youngs_modulus_Pa"], PLATE["density_kg_per_m3"], PLATE["poisson_ratio"]
    mass = physics.cuboid_mass_kg(length, t, w, rho)
    assert section.mass_per_length_kg_per_m == pytest.approx(mass / length, rel=1e-12)
    assert section.axial_stiffness_N == pytest.approx(e * t * w, rel=1e-12)
    assert section.bending_stiffness_Nm2 == pytest.approx(e * w * t**3 / 12, rel=1e-12)
    assert section.shear_stiffness_N == pytest.approx(
        SHEAR_CORRECTION_RECTANGLE * physics.shear_modulus_Pa(e, nu) * t * w, rel=1e-12)
    # rotary inertia per length: rho I, i.e. the mass per length times t^2 / 12
    assert section.rotary_inertia_kg_m == pytest.approx(mass / length * t**2 / 12, rel=1e-12)
    # the section gives the library's pinned-pinned frequency (pi / L)^2 sqrt(EI / rho A)
    omega = (math.pi / length) ** 2 * math.sqrt(section.bending_stiffness_Nm2
                                               / section.mass_per_length_kg_per_m)
    assert omega == pytest.approx(physics.pinned_pinned_omega(length, t, e, rho), rel=1e-12)


def test_section_stresses_are_the_outer_fibres_and_the_neutral_axis():
    section = exact_beam_section(physics.Plate(**PLATE))
    area, inertia, c = section.area_m2, section.second_moment_m4, 0.5 * PLATE["thickness_m"]
    axial, shear, moment = np.array([[20.0, -5.0]]), np.array([[0.0, 40.0]]), \
        np.array([[-0.1, 0.0]])
    normal, von_mises = section_stress_peaks(section, axial, shear, moment)
    np.testing.assert_allclose(normal, [[20 / area + 0.1 * c / inertia, 5 / area]], rtol=1e-12)
    # pure bending + tension: the outer fibre; pure shear + compression: the neutral axis
    np.testing.assert_allclose(von_mises[0, 0], normal[0, 0], rtol=1e-12)
    np.testing.assert_allclose(von_mises[0, 1], math.hypot(5 / area, math.sqrt(3) * 1.5 * 40
                                                           / area), rtol=1e-12)


def test_the_channel_stress_is_the_low_passed_field_not_the_low_passed_envelope():
    """Two elements bending at 100 Hz (outer fibre 100 MPa) with a 20 kHz ringing of 5 MPa
    in opposite phase: the largest stress over the link at each instant rides on the
    rectified ringing, and a low-pass of that envelope keeps its mean (2 / pi x 5 MPa above);
    the channel low-passes each element's section forces first, so its peak is the bending
    crest's, 100 MPa (within the filter's 1e-3)."""
    from flex.base.channel import channel_filter

    section = exact_beam_section(physics.Plate(**PLATE))
    scale = section.second_moment_m4 / section.outer_fibre_m  # moment per Pa at the fibre
    time_s = np.arange(0.0, 0.02, 2e-6)
    bending = 100e6 * np.abs(np.sin(2 * np.pi * 100 * time_s))
    ringing = 5e6 * np.sin(2 * np.pi * 20_000 * time_s)
    moment = scale * np.stack([bending + ringing, bending - ringing], axis=1)
    force = np.zeros(moment.shape + (2,))
    low_pass = channel_filter(time_s, 1000.0)
    out = section_datasets("coupler", section, force, moment, low_pass, "on the channel")
    field = out["channel/coupler/peak_bending_stress"].data
    envelope = low_pass(out["coupler/peak_bending_stress"].data)
    middle = slice(2000, -2000)  # away from the channel's padded ends
    assert np.max(field[middle]) == pytest.approx(100e6, rel=1e-3)
    assert np.max(envelope[middle]) - 100e6 == pytest.approx(2 / np.pi * 5e6, rel=0.1)
    assert out["channel/coupler/peak_bending_stress"].description.endswith("on the channel")


def _pinned_frequency(thickness_m: float, elements: int) -> float:
    """First pinned-pinned bending circular frequency [rad/s] of the beam (Exudyn's
    eigenvalues with both end nodes' x and y held)."""
    import exudyn as exu

    system = exu.SystemContainer()
    mbs = system.AddSystem()
    plate = physics.Plate(**dict(PLATE, thickness_m=thickness_m))
    add_exact_beam_link(mbs, exact_beam_section(plate),
                        elements, [0.01, 0.02], 0.6)  # turned: frame-independent
    mbs.Assemble()
    held = [0, 1, 3 * elements, 3 * elements + 1]
    values, _ = mbs.ComputeODE2Eigenvalues(constrainedCoordinates=held)
    return math.sqrt(abs(values[0]))


def test_static_end_moment_gives_the_closed_form_deflection_and_section_forces():
    """A pinned-pinned beam (16 elements) under a moment M at its first end: midpoint
    deflection M L^2 / (16 E I) (:func:`flex.base.physics.
    pinned_beam_end_moment_midpoint_deflection_m`; measured 7e-8 off: the elements are
    nodally exact for a linear moment, the constant shear strain of V = M / L moves the
    supports' chord only), bending moment M (1 - x / L) and shear force M / L in the elements
    the stresses are read from."""
    import exudyn as exu
    import exudyn.itemInterface as eii

    elements, moment_Nm = 16, 0.01
    section = exact_beam_section(physics.Plate(**PLATE))
    system = exu.SystemContainer()  # holds the system: kept while it is used
    mbs = system.AddSystem()
    beam = add_exact_beam_link(mbs, section, elements, [0.0, 0.0], 0.0)
    ground = mbs.AddMarker(eii.MarkerNodeCoordinate(
        nodeNumber=mbs.AddNode(eii.NodePointGround()), coordinate=0))
    for node, coordinates in ((beam.nodes[0], (0, 1)), (beam.nodes[-1], (1,))):
        for coordinate in coordinates:  # pin and roller
            held = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=node,
                                                          coordinate=coordinate))
            mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[ground, held]))
    mbs.AddLoad(eii.LoadCoordinate(load=moment_Nm, markerNumber=mbs.AddMarker(
        eii.MarkerNodeCoordinate(nodeNumber=beam.nodes[0], coordinate=2))))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.staticSolver.newton.relativeTolerance = 1e-8
    settings.staticSolver.newton.absoluteTolerance = 1e-10
    settings.staticSolver.verboseMode = 0
    settings.solution.file.write = False  # no solution/ folder in the cwd
    mbs.SolveStatic(settings)
    deflection = mbs.GetNodeOutput(beam.midpoint_node, exu.OutputVariableType.Position)[1]
    assert deflection == pytest.approx(physics.pinned_beam_end_moment_midpoint_deflection_m(
        moment_Nm, PLATE["length_m"], PLATE["thickness_m"], PLATE["width_m"],
        PLATE["youngs_modulus_Pa"]), rel=1e-5)
    for index in (0, elements // 2, elements - 1):
        element = beam.elements[index]
        bending = mbs.GetObjectOutputBody(element, exu.OutputVariableType.TorqueLocal,
                                          [0.0, 0.0, 0.0])[2]
        shear = mbs.GetObjectOutputBody(element, exu.OutputVariableType.ForceLocal,
                                        [0.0, 0.0, 0.0])[1]
        centre = (index + 0.5) / elements
        assert abs(bending) == pytest.approx(moment_Nm * (1 - centre), rel=1e-5)
        assert abs(shear) == pytest.approx(moment_Nm / PLATE["length_m"], rel=1e-5)


@pytest.mark.parametrize("thickness_m", [0.001, 0.010])
def test_pinned_pinned_frequency_converges_to_timoshenko(thickness_m):
    """Measured: +1.96 / +0.48 / +0.12 % at 8 / 16 / 32 elements (1 mm; 10 mm: +1.89 /
    +0.47 / +0.12 %), order 2. The 10 mm plate (L / t = 8) is 2.6 % below Euler-Bernoulli:
    shear and rotary inertia are in the beam."""
    material = Material(PLATE["youngs_modulus_Pa"], PLATE["density_kg_per_m3"],
                        PLATE["poisson_ratio"])
    timoshenko = timoshenko_bending_rad_per_s(PLATE["length_m"], thickness_m, PLATE["width_m"],
                                              "pinned-pinned", 1, material)[0]
    omegas = [_pinned_frequency(thickness_m, elements) for elements in (8, 16, 32)]
    assert omegas[-1] == pytest.approx(timoshenko, rel=2e-3)
    assert 1.9 <= _observed_order(*omegas) <= 2.1
    if thickness_m == 0.010:
        euler_bernoulli = physics.pinned_pinned_omega(PLATE["length_m"], thickness_m,
                                                      PLATE["youngs_modulus_Pa"],
                                                      PLATE["density_kg_per_m3"])
        assert omegas[-1] < 0.98 * euler_bernoulli


def test_thesis_deployment_follows_the_default_ffrf_coupler(reduction_cache):
    """1 mm plate, ``elements = "auto"`` (32), the bundled deployment (0.03 s) against the
    default FFRF coupler (its own step and modes). Measured: peak |midpoint deflection|
    0.17072 mm against 0.17149 (-0.45 %); crank angle within 1.7e-5 rad of the FFRF's at its
    maximum; peak strain energy 2.395e-4 J against 2.357e-4 (+1.6 %); peak bending stress
    28.51 MPa against 28.46 (+0.2 %; the FFRF's from its stress modes). The total energy
    drifts by 6.9e-4 of the peak strain energy (the FFRF's by 2.6e-2): the pins at B and C
    neither add nor take work. The nonlinear FE coupler (10.6 min): peak 0.17161 mm."""
    common = {"coupler.geometry": "plate", "simulation.error_estimate": False}
    beam = flex.simulate(flex.load_scene(overrides=BEAM), "beam", cache_dir=reduction_cache)
    ffrf = flex.simulate(flex.load_scene(overrides={**common, "coupler.model": "ffrf"}),
                         "ffrf", cache_dir=reduction_cache)
    assert beam.status == ffrf.status == "ok"
    assert "elements = 32" in beam.scene_toml
    peak = {name: np.abs(run.datasets["coupler/midpoint_deflection"].data).max()
            for name, run in (("beam", beam), ("ffrf", ffrf))}
    assert peak["beam"] == pytest.approx(peak["ffrf"], rel=0.01)
    crank = {name: run.datasets["crank/angle"].data.max()
             for name, run in (("beam", beam), ("ffrf", ffrf))}
    assert abs(crank["beam"] - crank["ffrf"]) < 1e-4
    strain = {name: run.datasets["energy/strain"].data.max()
              for name, run in (("beam", beam), ("ffrf", ffrf))}
    assert strain["beam"] == pytest.approx(strain["ffrf"], rel=0.03)
    total = beam.datasets["energy/total"].data
    assert np.abs(total - total[0]).max() < 5e-3 * strain["beam"]
    stress = {name: run.datasets["coupler/peak_bending_stress"].data.max()
              for name, run in (("beam", beam), ("ffrf", ffrf))}
    assert stress["beam"] == pytest.approx(stress["ffrf"], rel=0.05)
    assert beam.datasets["coupler/peak_von_mises_stress"].data.max() >= stress["beam"]


@pytest.mark.parametrize("crank_elements", [None, 2])
def test_the_beam_joins_the_mechanism_without_redundant_or_free_constraints(crank_elements):
    """Exudyn's count of the built mechanism (constraint Jacobian rank): one freedom of the
    mechanism plus 3 (nodes - 1) elastic ones per beam, no redundant constraint: the pins at
    A, B and C hold x and y of the planar nodes, nothing in z is left free or held twice."""
    from exudyn.solver import ComputeSystemDegreeOfFreedom

    from flex.dynamics.mechanism import build_mechanism

    overrides = {**BEAM, "coupler.elements": 4}
    if crank_elements:
        overrides.update({"crank.model": "exact_beam", "crank.geometry": "plate",
                          "crank.elements": crank_elements})
    scene = flex.load_scene(overrides=overrides)
    # the plates' uncalibrated sections: the count does not depend on the stiffness, and a
    # build without prepared sections would compute each plate's 3-D reference first
    sections = [exact_beam_section(Plate.of(scene[link])) if scene[link]["model"] ==
                "exact_beam" else None for link in ("coupler", "crank")]
    mech = build_mechanism(scene, *sections)
    mech.mbs.Assemble()
    count = ComputeSystemDegreeOfFreedom(mech.mbs, verbose=False)
    elastic = 3 * 4 + 3 * (crank_elements or 0)
    assert count["redundantConstraints"] == 0
    assert count["degreeOfFreedom"] == 1 + elastic


def _filtered_first_crest(result) -> float:
    """The first crest of the midpoint deflection after a zero-phase 4th-order Butterworth
    low-pass at 2 kHz (the release's ~10 kHz ripple races between sub-crests otherwise)."""
    from scipy.signal import butter, sosfiltfilt

    time = result.datasets["time"].data
    deflection = result.datasets["coupler/midpoint_deflection"].data
    filtered = sosfiltfilt(butter(4, 2000.0, fs=1.0 / (time[1] - time[0]), output="sos"),
                           deflection)
    return float(abs(filtered[first_peak_index(filtered)]))


def test_first_crest_converges_at_second_order_under_element_doubling():
    """8 / 16 / 32 elements, first 3 ms (the crest is at 1.33 ms). Measured on the
    uncalibrated beam 0.095001 / 0.096669 / 0.097091 mm: observed order 1.98; the beam
    calibrated on the 3-D plate (E I_eff / E I, stored with the run) is that much stiffer:
    its crest is the uncalibrated one over the factor (bending carries 99.96 % of the 1 mm
    plate's deflection)."""
    crests = []
    for elements in (8, 16, 32):
        scene = flex.load_scene(overrides={**BEAM, "coupler.elements": elements,
                                           "simulation.end_time_s": 0.003})
        run = flex.simulate(scene, f"beam{elements}")
        crests.append(_filtered_first_crest(run))
    assert 1.7 <= _observed_order(*crests) <= 2.3
    factor = run.attrs["coupler_beam_bending_stiffness_factor"]
    assert factor == pytest.approx(1.00118, abs=2e-5)  # the reference notes' 3-D factor
    assert crests[-1] == pytest.approx(0.0970914e-3 / factor, rel=1e-3)


def test_the_deployment_peak_stress_converges_at_second_order_under_element_doubling():
    """The 1 mm plate's deployment peak bending stress on the headline channel (the
    low-passed field, :mod:`flex.base.channel`) at 32 / 64 / 128 elements, h = 1e-5 s:
    measured 26.773 / 26.825 / 26.838 MPa, observed order 2.0 (the outer fibre's stress is the
    element's constant moment, sampled at the element centres). The envelope low-passed
    moved without order (27.12 / 27.42 / 27.13 MPa)."""
    stress = BUILTIN_HEADLINES["coupler_deployment_peak_bending_stress_Pa"]
    peaks = []
    for elements in (32, 64, 128):
        scene = flex.load_scene(overrides={**BEAM, "coupler.elements": elements,
                                           "simulation.step_s": 1e-5,
                                           "simulation.end_time_s": 0.02})
        peaks.append(stress.read(flex.simulate(scene, f"beam{elements}").datasets))
    assert 1.6 <= _observed_order(*peaks) <= 2.4
    assert peaks[-1] == pytest.approx(26.838e6, rel=2e-3)


def test_the_error_budget_covers_the_elements_error_of_the_first_crest():
    """A run's own estimate (the error budget's mesh term: a companion with twice the
    elements at the run's step, extrapolated at order 2) against the first crest's distance
    between 32 and 128 elements at that step, first 3 ms, both on the headline channel."""
    scene = flex.load_scene(overrides={**BEAM, "simulation.error_estimate": True,
                                       "simulation.end_time_s": 0.003})
    run = flex.simulate(scene, "beam32")
    runs = [flex.simulate(flex.derive_scene(scene, {"coupler.elements": elements,
                                                    "simulation.error_estimate": False}),
                          f"beam{elements}") for elements in (32, 128)]
    crest = [BUILTIN_HEADLINES["coupler_first_crest_deflection_m"].read(r.datasets)
             for r in runs]  # on the headline channel, as the budget reads it
    estimate = run.attrs["estimated_error_coupler_first_crest_deflection_m_mesh"]
    assert 1.0 <= estimate / abs(crest[1] - crest[0]) <= 3.0


def test_refine_names_the_set_elements_when_they_dominate():
    """``fidelity.refine`` on an 8-element beam, first 3 ms, tolerance 2 %: measured 3.28 %
    estimated on the peak deflection, the elements' term dominant; the 8 elements were set in
    the scene, and refinement never changes a value the user set: it stops and says which
    value blocks and what it would take (16 elements: 1.65 %, met, when they are free)."""
    scene = flex.load_scene(overrides={**BEAM, "simulation.end_time_s": 0.003,
                                       "coupler.elements": 8, "fidelity.refine": True,
                                       "simulation.error_estimate": True,
                                       "fidelity.tolerance": 0.02})
    run = flex.simulate(scene, "refined")
    status = run.attrs["refine_status"]
    assert "coupler.elements = 8 was set" in status and "coupler.elements=16" in status
    assert "coupler exact_beam, 8 elements" in run.attrs["refine_attempts"]
    assert "elements = 8" in run.scene_toml


@pytest.mark.parametrize("value", [1, 0, -4, 2.5, "many", True, 2000])
def test_bad_elements_are_refused_in_one_line(value):
    with pytest.raises(SceneError) as refused:
        flex.load_scene(overrides={**BEAM, "coupler.elements": value})
    message = str(refused.value)
    assert "\n" not in message
    assert message.startswith("coupler.elements = ")
    assert message.endswith('must be an integer >= 2 and <= 1024 or "auto"')


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_a_beam_crank_follows_an_ffrf_crank(reduction_cache):
    """Crank and coupler plates (the bundled crank plate: 40 x 4.56 x 10 mm), beam coupler,
    crank as a beam (32 elements, the default) or as the default FFRF body. Measured: crank
    midpoint deflection 1.0400 against 1.0345 um (+0.53 %), its peak bending stress 3.0169
    against 3.0158 MPa (+0.04 %), crank-angle maximum 2.2e-7 rad apart."""
    common = {**BEAM, "crank.geometry": "plate"}
    runs = {model: flex.simulate(flex.load_scene(overrides={**common, "crank.model": model}),
                                 model, cache_dir=reduction_cache)
            for model in ("exact_beam", "ffrf")}
    beam, ffrf = (runs[model].datasets for model in ("exact_beam", "ffrf"))
    deflection = [np.abs(run["crank/midpoint_deflection"].data).max() for run in (beam, ffrf)]
    assert deflection[0] == pytest.approx(deflection[1], rel=0.02)
    stress = [run["crank/peak_bending_stress"].data.max() for run in (beam, ffrf)]
    assert stress[0] == pytest.approx(stress[1], rel=0.05)
    assert abs(beam["crank/angle"].data.max() - ffrf["crank/angle"].data.max()) < 1e-5
    total = beam["energy/total"].data
    assert np.abs(total - total[0]).max() < 5e-3 * beam["energy/strain"].data.max()


def test_a_beam_crank_needs_a_beam_coupler_and_no_wing():
    crank = {**BEAM, "crank.geometry": "plate", "crank.model": "exact_beam"}
    with pytest.raises(SceneError, match='crank.model = "exact_beam" needs coupler.model = '
                                         '"exact_beam"'):
        flex.load_scene(overrides={**crank, "coupler.model": "ffrf"})
    with pytest.raises(SceneError, match="accepted: wing.enabled = false"):
        flex.load_scene(overrides={**crank, "wing.enabled": True})


def test_the_beam_needs_a_plate_and_other_models_do_not_read_elements():
    with pytest.raises(SceneError, match='coupler.model = "exact_beam" needs '
                                         'coupler.geometry = "plate"'):
        flex.load_scene(overrides={"coupler.model": "exact_beam"})
    scene = flex.load_scene(overrides={"coupler.model": "ffrf", "coupler.geometry": "plate",
                                       "coupler.elements": 64})
    with pytest.raises(SceneError, match="coupler.elements") as refused:
        flex.simulate(scene)
    assert '"exact_beam"' in str(refused.value)


def test_a_beam_stops_newton_on_its_increment_and_a_stall_is_run_again_and_says_so():
    """The 3 mm plate driven at 60 rad/s as a 128-element beam at 5e-6 s stalled Newton on
    its residual 0.68 ms in (the residual's round-off floor; the beam companion of a 0.3 %
    run): stopping on the increment at 1e-4 of the run's tolerance it runs through, no retry.
    A stall up to 1e-8 is run again at 4x the error it stalled at and the case says so; a
    stall above it, or a run without a beam, stays a divergence."""
    from flex.data.scene import load_scene
    from flex.dynamics.link_models import BUILTIN_LINK_MODELS
    from flex.dynamics.solver import NEWTON_RETRY_ATTR, _newton_floor_retry, solver_settings
    from flex.fidelity.simulation import simulate_case

    beam = load_scene(None, ['coupler.geometry="plate"', "coupler.thickness_m=0.003",
                             'drive.kind="constant_speed"', "drive.crank_speed_rad_per_s=60.0",
                             'coupler.model="exact_beam"', "coupler.elements=128",
                             "simulation.step_s=5e-6", "simulation.end_time_s=0.0008",
                             "simulation.error_estimate=false"])
    case = simulate_case(beam, "floor")
    assert case.status == "ok", case.message
    assert NEWTON_RETRY_ATTR not in case.attrs
    from flex.config.settings import resolve_solver_settings

    concrete, _ = resolve_solver_settings(beam)
    settings = solver_settings(concrete, BUILTIN_LINK_MODELS)
    assert settings["newton_on_increment"] and settings["newton_relative_tolerance"] == 1e-12
    stalled = "Newton failed (... relative error = {} ...)"
    retry = _newton_floor_retry(concrete, stalled.format("3e-12"), BUILTIN_LINK_MODELS)
    assert retry and "round-off floor" in retry[1]
    assert retry[0]["simulation"]["newton_relative_tolerance"] == pytest.approx(1.2e-7)
    # on the increment a stall up to 1e-8 is a converged solution's round-off: run again at
    # 4x the stall (the scene's tolerance scaled alike); beyond it a divergence
    again = _newton_floor_retry(concrete, stalled.format("1e-10"), BUILTIN_LINK_MODELS)
    assert again[0]["simulation"]["newton_relative_tolerance"] == pytest.approx(4e-6)
    assert _newton_floor_retry(concrete, stalled.format("2e-8"), BUILTIN_LINK_MODELS) is None
    assert _newton_floor_retry(concrete, stalled.format("nan"), BUILTIN_LINK_MODELS) is None
    rigid, _ = resolve_solver_settings(load_scene(None, []))
    assert _newton_floor_retry(rigid, stalled.format("3e-8"), BUILTIN_LINK_MODELS) is None
