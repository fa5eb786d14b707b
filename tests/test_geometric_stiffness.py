"""Geometric stiffness of the FFRF coupler (flex.bodies.geometric_stiffness) against closed
forms: the axial stiffness and stretch geometry of the plate, Euler's load and the frequency
of a pinned-pinned beam under axial load, f(P) = f0 sqrt(1 - P / P_E) (Timoshenko & Gere,
Theory of Elastic Stability, ch. 2), the hinged column under a distributed axial load
((q L)_cr = 18.6 EI / L^2, ibid.), in the reduced matrices and in an Exudyn simulation; and,
slow, the deployment against the nonlinear FE coupler.
"""

from __future__ import annotations

import dataclasses
import math
import os

import numpy as np
import pytest

from flex.base.errors import SceneError
from flex.base.physics import Plate, euler_buckling_load_N
from flex.bodies.geometric_stiffness import (
    add_geometric_stiffness,
    compute_geometric_stiffness,
    geometric_stiffness,
    pinned_pinned_eigen,
)
from flex.bodies.reduction import build_reduction
from flex.config.usage import unused_keys
from flex.data.scene import load_scene

os.environ.setdefault("EXUDYN_NO_USER_SETTINGS", "1")

#: 80 x 10 mm steel plate, 1 mm thick, meshed at 2 mm, 6 in-plane fixed-interface modes
PLATE = dict(length_m=0.08, thickness_m=0.001, width_m=0.01, youngs_modulus_Pa=200e9,
             density_kg_per_m3=7850.0, poisson_ratio=0.3, mesh_size_m=0.002, modes=6)
#: Timoshenko & Gere: hinged column under a uniformly distributed axial load
HINGED_DISTRIBUTED_LOAD_FACTOR = 18.6


@pytest.fixture(scope="module")
def reduction(reduction_cache):
    sizes = {key: PLATE[key] for key in ("length_m", "thickness_m", "width_m",
                                         "youngs_modulus_Pa", "density_kg_per_m3",
                                         "poisson_ratio")}
    return build_reduction(Plate(**sizes), PLATE["mesh_size_m"], PLATE["modes"],
                           cache_dir=reduction_cache)


@pytest.fixture(scope="module")
def stiffness(reduction):
    return geometric_stiffness(reduction)


def euler_load_N() -> float:
    return euler_buckling_load_N(PLATE["length_m"], PLATE["thickness_m"], PLATE["width_m"],
                                 PLATE["youngs_modulus_Pa"])


def test_axial_mode_carries_the_links_axial_stiffness_and_no_rotation(stiffness):
    # a uniform stretch e of the link: N = E A e / L (rigid faces and the Poisson contraction
    # they hold add a fraction of a per cent); it turns no material line, so K_G (the
    # transverse rotations) hardly sees it (the Poisson contraction's slope near the faces)
    length, area = PLATE["length_m"], PLATE["thickness_m"] * PLATE["width_m"]
    mode = stiffness.axial_mode
    assert stiffness.axial_force_row_N_per_m[mode] == pytest.approx(
        PLATE["youngs_modulus_Pa"] * area / length, rel=0.01)
    assert abs(stiffness.matrix_per_N[mode, mode]) < 1e-2 / length


def test_bending_shortens_the_chord_as_the_beam(reduction, stiffness):
    # the first pinned-pinned mode with midpoint deflection a: chord shortening
    # int v'^2 / 2 dx = a^2 pi^2 / (4 L) for v = a sin(pi x / L)
    from scipy.linalg import eigh

    fem = reduction.fem
    basis = fem.modeBasis["matrix"]
    mass, elastic = (basis.T @ (matrix @ basis) for matrix in (fem.massMatrix,
                                                              fem.stiffnessMatrix))
    _, vectors = eigh(elastic, mass)
    first = vectors[:, 0]
    mid_y = np.asarray(reduction.weights_mid) @ basis.reshape(-1, 3, basis.shape[1])[
        reduction.nodes_mid][:, 1, :] @ first
    q = 1e-4 * first / mid_y  # 0.1 mm at the midpoint
    length = PLATE["length_m"]
    shortening = 0.5 * q @ stiffness.matrix_per_N @ q
    assert shortening == pytest.approx(1e-8 * math.pi**2 / (4 * length), rel=0.02)
    # the axial force counts it: a bent link at rest in its stretch carries k_a b
    axial = stiffness.axial_force_row_N_per_m[stiffness.axial_mode]
    assert stiffness.axial_force_N(q) == pytest.approx(
        q @ stiffness.axial_force_row_N_per_m + axial * shortening, rel=1e-12)


def test_the_frame_is_the_chord(reduction):
    # chord frame: no mode moves the centre of end_a, nor the centre of end_b across the x
    # axis; end_a turns about z (its static mode), end_b moves along x and turns
    from flex.bodies.geometric_stiffness import face_mean_displacement

    scale = np.abs(reduction.fem.modeBasis["matrix"]).max(axis=0)
    np.testing.assert_allclose(face_mean_displacement(reduction, "end_a") / scale, 0.0,
                               atol=1e-9)
    np.testing.assert_allclose(face_mean_displacement(reduction, "end_b")[1:] / scale, 0.0,
                               atol=1e-9)


def test_reduced_link_buckles_at_the_closed_form_loads(reduction, stiffness):
    # Euler (end loads) and the hinged column under a distributed axial load; the 3D plate
    # with its shear and rigid end faces departs from the beam by O((t / L)^2)
    ei = PLATE["youngs_modulus_Pa"] * PLATE["width_m"] * PLATE["thickness_m"] ** 3 / 12
    _, uniform = pinned_pinned_eigen(reduction, stiffness, 0.0)
    _, rising = pinned_pinned_eigen(reduction, stiffness, 0.0, rising=True)
    assert uniform == pytest.approx(euler_load_N(), rel=0.01)
    assert rising == pytest.approx(HINGED_DISTRIBUTED_LOAD_FACTOR * ei / PLATE["length_m"] ** 2,
                                   rel=0.01)



def test_a_linear_tetrahedra_reduction_gets_its_geometric_stiffness(reduction_cache):
    # K_G is assembled on a mesh remade from the reduction's arguments, tetrahedra order
    # included: the work-precision study's "linear tets" setting stopped with a traceback
    # when the remade mesh was quadratic ("the remade mesh differs from the reduction's")
    sizes = {key: PLATE[key] for key in ("length_m", "thickness_m", "width_m",
                                         "youngs_modulus_Pa", "density_kg_per_m3",
                                         "poisson_ratio")}
    linear = build_reduction(Plate(**sizes), PLATE["mesh_size_m"], PLATE["modes"],
                             cache_dir=reduction_cache, mesh_order=1)
    assert linear.mesh_order == 1
    stiffness = geometric_stiffness(linear)
    length, area = PLATE["length_m"], PLATE["thickness_m"] * PLATE["width_m"]
    assert stiffness.axial_force_row_N_per_m[stiffness.axial_mode] == pytest.approx(
        PLATE["youngs_modulus_Pa"] * area / length, rel=0.01)
    _, load_N = pinned_pinned_eigen(linear, stiffness, 0.0)
    # linear tetrahedra lock in bending: stiffer than the beam, never softer
    assert load_N > 0.99 * euler_load_N()

def test_the_builds_own_mesh_gives_what_a_remade_mesh_gives():
    # a reduction built in this process assembles K_G on its own mesh (no meshing again); one
    # loaded from the cache remakes the mesh from its arguments: the same matrices
    sizes = {key: PLATE[key] for key in ("length_m", "width_m", "youngs_modulus_Pa",
                                         "density_kg_per_m3", "poisson_ratio")}
    built = build_reduction(Plate(**sizes, thickness_m=0.003), 0.005, 2, cache_dir=None)
    assert built._mesh is not None
    own = compute_geometric_stiffness(built)
    remade = compute_geometric_stiffness(dataclasses.replace(built, _mesh=None))
    np.testing.assert_array_equal(own.matrix_per_N, remade.matrix_per_N)
    np.testing.assert_array_equal(own.axial_force_row_N_per_m, remade.axial_force_row_N_per_m)


@pytest.mark.parametrize("load_ratio", [-0.5, 0.25, 0.5, 0.75])
def test_bending_frequency_follows_the_axial_load(reduction, stiffness, load_ratio):
    # f(P) = f0 sqrt(1 - P / P_E); tension (negative) stiffens; f0 is the reduction's own
    # pinned-pinned frequency from Exudyn's constrained eigenvalue solver
    f0, _ = pinned_pinned_eigen(reduction, stiffness, 0.0)
    assert f0 == pytest.approx(reduction.pinned_pinned_frequency_Hz, rel=1e-3)
    loaded, _ = pinned_pinned_eigen(reduction, stiffness, load_ratio * euler_load_N())
    assert loaded / f0 == pytest.approx(math.sqrt(1 - load_ratio), rel=5e-3)


def _pinned_vibration_Hz(reduction, stiffness, compression_N: float, geometric: bool,
                         step_s: float = 2e-5, end_time_s: float = 0.03) -> float:
    """Free vibration of the FFRF plate pinned at both end faces in Exudyn, ``compression_N``
    applied at end_b along the link: released from the static deflection under a small
    midpoint load; frequency from the upward zero crossings of the midpoint [Hz]."""
    import exudyn as exu
    import exudyn.itemInterface as eii

    mbs = exu.SystemContainer().AddSystem()
    added = reduction.ffrf_interface().AddObjectFFRFreducedOrder(mbs, positionRef=[0., 0., 0.])
    body, modal = added["oFFRFreducedOrder"], added["nGenericODE2"]
    ground = mbs.AddObject(eii.ObjectGround())
    # end_a: pinned about z; end_b: held across the link only (in-plane modes move nothing
    # else there), free along it
    faces = []
    for face, x, axes in (("end_a", 0.0, [1, 1, 1, 1, 1, 0]),
                          ("end_b", reduction.length_m, [0, 1, 0, 0, 0, 0])):
        faces.append(mbs.AddMarker(eii.MarkerSuperElementRigid(
            bodyNumber=body, meshNodeNumbers=getattr(reduction, f"nodes_{face}"),
            weightingFactors=getattr(reduction, f"weights_{face}"))))
        support = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=ground, localPosition=[x, 0, 0]))
        mbs.AddObject(eii.GenericJoint(markerNumbers=[support, faces[-1]], constrainedAxes=axes))
    mbs.AddLoad(eii.LoadForceVector(markerNumber=faces[1], loadVector=[-compression_N, 0, 0]))
    mid = mbs.AddMarker(eii.MarkerSuperElementPosition(
        bodyNumber=body, meshNodeNumbers=reduction.nodes_mid,
        weightingFactors=reduction.weights_mid))
    kick = mbs.AddLoad(eii.LoadForceVector(markerNumber=mid, loadVector=[0, 0.01, 0]))
    sensor = mbs.AddSensor(eii.SensorMarker(markerNumber=mid, storeInternal=True,
                                            outputVariableType=exu.OutputVariableType.Position))
    if geometric:
        add_geometric_stiffness(mbs, modal, stiffness)
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = round(end_time_s / step_s)
    settings.timeIntegration.endTime = end_time_s
    settings.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    settings.timeIntegration.verboseMode = 0
    settings.staticSolver.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = step_s
    mbs.SolveStatic(settings, updateInitialValues=True)
    mbs.SetLoadParameter(kick, "loadVector", [0, 0, 0])
    mbs.SolveDynamic(settings)
    data = mbs.GetSensorStoredData(sensor)
    time_s, y = data[:, 0], data[:, 2] - data[:, 2].mean()
    up = np.flatnonzero((y[:-1] < 0) & (y[1:] >= 0))
    crossings = time_s[up] - y[up] * (time_s[up + 1] - time_s[up]) / (y[up + 1] - y[up])
    return (len(crossings) - 1) / (crossings[-1] - crossings[0])


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_exudyn_body_with_geometric_force_vibrates_at_the_closed_form(reduction, stiffness):
    # the ObjectGenericODE2 on the modal coordinates, integrated with the FFRF body: the
    # measured frequency follows sqrt(1 - P / P_E); without it the linear body in its chord
    # frame is blind to the load (the load acts along the frame's axis): unloaded frequency
    f0 = _pinned_vibration_Hz(reduction, stiffness, 0.0, geometric=True)
    assert f0 == pytest.approx(reduction.pinned_pinned_frequency_Hz, rel=2e-3)
    load = 0.5 * euler_load_N()
    assert _pinned_vibration_Hz(reduction, stiffness, load, geometric=True) / f0 == \
        pytest.approx(math.sqrt(0.5), rel=5e-3)
    assert _pinned_vibration_Hz(reduction, stiffness, load, geometric=False) / f0 == \
        pytest.approx(1.0, rel=5e-3)


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_geometric_stiffness_is_cached_beside_its_reduction(reduction, stiffness, tmp_path):
    moved = dataclasses.replace(reduction, cache_file=tmp_path / f"{reduction.key}.hdf5")
    built = geometric_stiffness(moved)
    assert not built.from_cache
    loaded = geometric_stiffness(moved)
    assert loaded.from_cache
    np.testing.assert_array_equal(loaded.matrix_per_N, built.matrix_per_N)
    entry = next(tmp_path.glob("*.geometric.hdf5"))
    entry.write_bytes(entry.read_bytes()[:100])  # truncated: rebuilt, not trusted
    assert not geometric_stiffness(moved).from_cache


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_an_edited_geometric_stiffness_entry_is_rebuilt(reduction, stiffness, tmp_path, capfd):
    # matrices scaled by 1.5 with every attribute kept: the content digest catches it
    import h5py

    moved = dataclasses.replace(reduction, cache_file=tmp_path / f"{reduction.key}.hdf5")
    geometric_stiffness(moved)
    entry = next(tmp_path.glob("*.geometric.hdf5"))
    with h5py.File(entry, "r+") as h5:
        h5["matrix_per_N"][...] = 1.5 * h5["matrix_per_N"][()]
    rebuilt = geometric_stiffness(moved)
    assert not rebuilt.from_cache
    # rebuilt on a remade mesh (the fixture's came with its build): equal to round-off, and
    # far from the 1.5x edit
    np.testing.assert_allclose(rebuilt.matrix_per_N, stiffness.matrix_per_N, rtol=1e-12,
                               atol=1e-12 * np.abs(stiffness.matrix_per_N).max())
    assert "did not prove its content" in capfd.readouterr().err
    assert geometric_stiffness(moved).from_cache  # the rebuilt entry replaced it


@pytest.mark.parametrize("link", ["coupler", "crank"])
def test_scene_key_defaults_on_and_is_checked(link):
    assert load_scene()[link]["geometric_stiffness"] is True
    with pytest.raises(SceneError, match=f"{link}.geometric_stiffness = 1: must be true or "
                                         f"false"):
        load_scene(overrides=[f"{link}.geometric_stiffness=1"])
    rigid = load_scene(overrides=[f"{link}.geometric_stiffness=false"])
    assert f"{link}.geometric_stiffness" in unused_keys(rigid)
    flexible = load_scene(overrides=[f'{link}.geometry="plate"', f'{link}.model="ffrf"',
                                     f"{link}.geometric_stiffness=false"])
    assert f"{link}.geometric_stiffness" not in unused_keys(flexible)


@pytest.mark.slow
def test_deployment_peak_matches_the_nonlinear_fe_coupler(reduction_cache):
    # 1 mm plate, thesis deployment over ~1.7 first bending periods: the linear FFRF peak
    # is ~3 % below the nonlinear FE one (compression 0.08 of the Euler load; measured
    # -3.2 %); with the geometric stiffness within 0.5 % (measured +0.05 %)
    from flex.config.settings import pinned_overrides
    from flex.experiments.models.ladder import ladder_rung

    base = load_scene(overrides=pinned_overrides())
    rung = ladder_rung(base, 0.001, 0.002, 1e-4, 0.005, reduction_cache)
    assert not rung.failures
    assert rung.difference_to_reference["linear"] < -0.02
    assert abs(rung.difference_to_reference["ffrf"]) < 0.005


def test_the_ladder_takes_ffrf_when_its_model_error_meets_the_tolerance():
    from flex.config.ladder import (
        GEOMETRIC_FFRF_ERROR,
        LINEAR_FFRF_ERROR_FLOOR,
        LINEAR_FFRF_ERROR_PER_LOAD,
    )
    from flex.fidelity.criteria import flexible_rung

    load_ratio = 0.1  # the rigid probe's compression / Euler load
    linear = LINEAR_FFRF_ERROR_FLOOR + LINEAR_FFRF_ERROR_PER_LOAD * load_ratio
    assert GEOMETRIC_FFRF_ERROR < linear
    assert flexible_rung(load_ratio, GEOMETRIC_FFRF_ERROR) == ("ffrf", GEOMETRIC_FFRF_ERROR)
    assert flexible_rung(load_ratio, 0.99 * GEOMETRIC_FFRF_ERROR)[0] == "nonlinear_fe"
    assert flexible_rung(load_ratio, linear, geometric_stiffness=False) == ("ffrf", linear)
    assert flexible_rung(load_ratio, 0.99 * linear, False)[0] == "nonlinear_fe"


def test_auto_reads_the_tolerance_against_the_deflection_past_rigid():
    # 1 mm plate: the rigid probe predicts ~0.2 % of the length (rigid at 1 %); at 1e-3 rigid
    # is refused and the FFRF body's model error (0.5 % of the deflection, measured up to
    # 0.35 %) does not meet 0.1 % of the deflection; the calibrated exact beam's (measured on
    # the plate's 3-D reference: ~4e-5) does
    from flex.fidelity.auto import decide_links

    def scene(tolerance: float):
        return load_scene(overrides=['coupler.geometry="plate"', 'coupler.model="auto"',
                                     f"fidelity.tolerance={tolerance!r}"])

    tight, (decision,) = decide_links(scene(1e-3))
    assert tight["coupler"]["model"] == decision.model == "exact_beam"
    assert ("ladder: exact_beam (FFRF model error 0.005 of the deflection, make ladder's "
            "measured bound, > tolerance 0.001; exact beam (calibrated) model error "
            in decision.reason)
    loose, (decision,) = decide_links(scene(1e-2))
    assert loose["coupler"]["model"] == "rigid"
