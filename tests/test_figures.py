"""Every study's figures render: readable PNGs that pass the house-style review.

Each study's ``figures(results, summary, folder)`` is called and every PNG it returns must
exist, be non-empty, decode as a PNG (``matplotlib.image.imread``) of a sensible size, and
pass :func:`flex.base.plotting.review` (a title; every numeric axis labelled with a unit; no
colliding tick labels; no text cut at the figure's edge), checked on each figure as it is
saved.

- cheap studies (simulate, kinematics, dynamics, spring, wing) run in-process with short
  settings (:func:`flex.study.execute`);
- expensive or long studies (modal, flexible, crank, kfit, tradeoff, stability, bench) draw
  small synthetic inputs of the shape their ``figures`` reads, so their drawing code runs on
  every ``pytest``; the real runs of modal, flexible, crank and kfit are ``slow`` (``make
  test-slow``).
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.figure
import matplotlib.image
import numpy as np
import pytest

from flex.base.plotting import review
from flex.data.results import CaseResult, Dataset
from flex.fidelity import criteria, laws
from flex.study import Summary, execute, load_study, study_scene

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def reviewed(monkeypatch):
    """Run :func:`flex.base.plotting.review` on every figure saved during the test; the list of
    problems found (``"<file>: <problem>"``) is yielded and must end empty."""
    problems: list[str] = []
    save = matplotlib.figure.Figure.savefig

    def checked(self, path, *args, **kwargs):
        problems.extend(f"{Path(str(path)).name}: {p}" for p in review(self))
        return save(self, path, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", checked)
    yield problems
    assert not problems, "\n".join(problems)


def check_pngs(paths, folder: Path, expected: set[str] | None = None) -> None:
    """Every path is a real, decodable PNG in ``folder``; ``expected``: exactly these names."""
    paths = [Path(p) for p in paths]
    assert paths, "figures() returned no figure"
    names = {p.name for p in paths}
    assert len(names) == len(paths), f"a figure is returned twice: {sorted(names)}"
    if expected is not None:
        assert names == expected
    for path in paths:
        assert path.parent == folder, path
        assert path.is_file() and path.stat().st_size > 1000, path
        assert path.read_bytes()[:8] == PNG_SIGNATURE, path
        image = matplotlib.image.imread(path)
        assert image.ndim == 3 and image.shape[0] >= 300 and image.shape[1] >= 400, (
            path, image.shape)
        assert np.ptp(image[..., :3]) > 0.5, f"{path}: blank image"


def run_and_draw(name: str, overrides: list[str], folder: Path, cache_dir: Path | None = None):
    module = load_study(name)
    output = execute(module, study_scene(module, None, overrides), cache_dir=cache_dir)
    assert output.as_expected, output.unexpected()
    if name == "wing":  # its auto decisions are for the links it simulated (issue 26)
        assert "crank as simulated" in output.summary.report
        assert "coupler as a 3 mm" not in output.summary.report
    return module.figures(output.results, output.summary, folder)


# ------------------------------------------------------------------------------------------
# cheap studies, run in-process
# ------------------------------------------------------------------------------------------
CHEAP = {
    "simulate": (["simulation.end_time_s=0.01"], {"simulate-crank-angle.png"}),
    "kinematics": (["simulation.end_time_s=0.25"],
                   {"kinematics-slider-position.png", "kinematics-slider-velocity.png",
                    "kinematics-slider-acceleration.png", "kinematics-crank-midpoint.png",
                    "kinematics-constraint-norm.png"}),
    "dynamics": (["simulation.end_time_s=0.01"],
                 {f"dynamics-{name}.png" for name in (
                     "crank-angle", "crank-speed", "crank-acceleration", "constraint-norm",
                     "crank-midpoint", "slider-position", "force-A-on-crank",
                     "force-B-on-crank", "force-B-on-coupler", "force-B-modulus", "energy")}),
    "spring": ([], {"spring-stress.png"}),
    "wing": (["simulation.end_time_s=0.01"],
             {"wing-angle.png", "wing-angular-velocity.png", "wing-loads.png"}),
}


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
@pytest.mark.parametrize("name", list(CHEAP))
def test_cheap_study_figures(name, tmp_path, reviewed, reduction_cache):
    overrides, expected = CHEAP[name]
    check_pngs(run_and_draw(name, overrides, tmp_path, reduction_cache), tmp_path, expected)


# ------------------------------------------------------------------------------------------
# expensive and long studies: synthetic inputs of the shape their figures read
# ------------------------------------------------------------------------------------------
def case(name: str, **datasets) -> CaseResult:
    return CaseResult(name, "", {key.replace("__", "/"): Dataset(np.asarray(value), "1")
                                 for key, value in datasets.items()})


def summary(**datasets) -> Summary:
    return Summary({key: value if isinstance(value, Dataset) else Dataset(value, "1")
                    for key, value in datasets.items()})


TIME = np.linspace(0.0, 0.03, 301)


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_modal_figures_synthetic(tmp_path, reviewed):
    from studies import modal

    thickness = np.array([1e-3, 3e-3, 5e-3, 10e-3])
    x, z = np.meshgrid(np.linspace(0, 0.08, 41), np.linspace(-0.005, 0.005, 11))
    face = np.column_stack([x.ravel(), np.zeros(x.size), z.ravel()])
    nodes = np.vstack([face + [0, 5e-4, 0], face - [0, 5e-4, 0]])
    shapes = np.zeros((5, len(nodes), 3))
    for mode in range(5):
        bending = np.sin((mode + 1) * np.pi * nodes[:, 0] / 0.08)
        shapes[mode, :, 1] = bending if mode != 3 else nodes[:, 2] / 0.005 * bending
    data = {"table5/coupler_thickness_m": thickness,
            "table5/euler_bernoulli_frequency_Hz": 358.0 * thickness / 1e-3,
            "table5/timoshenko_frequency_Hz": 358.0 * thickness / 1e-3 * (1 - thickness),
            "table5/fe_frequency_Hz": 358.0 * thickness / 1e-3 * (1 - 0.9 * thickness),
            "links/coupler_t1mm/pinned-pinned/node_coordinates": nodes,
            "links/coupler_t1mm/pinned-pinned/mode_shapes": shapes,
            "links/coupler_t1mm/pinned-pinned/fe_mode_kinds": np.array(
                ["in-plane bending"] * 3 + ["torsion", "in-plane bending"], dtype=object),
            "links/coupler_t1mm/pinned-pinned/fe_frequencies": np.array(
                [358.0, 1433.0, 3231.0, 3786.0, 5755.0])}
    for t in (1, 3, 5, 10):
        group = f"convergence/coupler_t{t}mm"
        sizes = np.array([8, 4, 2, 1]) * 1e-3
        frequency = 358.0 * t * (1 + 0.5 * sizes**2 / 1e-5)
        data |= {f"{group}/dof": 1e3 / sizes**0.5, f"{group}/frequency": frequency,
                 f"{group}/mesh_size": sizes, f"{group}/production_mesh_size": 2e-3}
        data[f"{group}/reference_frequency"] = Dataset(
            frequency[-1] if t in (3, 5) else 358.0 * t, "Hz",
            "finest" if t in (3, 5) else "richardson")
    paths = modal.figures({}, summary(**data), tmp_path)
    check_pngs(paths, tmp_path, {"modal-table5.png", "modal-mode-shapes.png",
                                 "modal-convergence.png"})


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_flexible_figures_synthetic(tmp_path, reviewed):
    from studies import flexible

    results, data = {}, {}
    for index, (model, (thickness, _)) in enumerate(flexible.MODELS.items()):
        amplitude = 1.8e-4 / (thickness / 1e-3) ** 2.4
        deflection = amplitude * np.sin(2 * np.pi * (300 + 500 * index) * TIME)
        acceleration = np.column_stack([800 * np.sin(200 * TIME), 400 * np.cos(200 * TIME)])
        results[f"{model}_ffrf"] = case(f"{model}_ffrf", time=TIME,
                                        coupler__midpoint_deflection=deflection,
                                        coupler__midpoint_acceleration=acceleration * 1.1)
        results[f"{model}_rigid"] = case(f"{model}_rigid", time=TIME,
                                         coupler__midpoint_deflection=0 * TIME,
                                         coupler__midpoint_acceleration=acceleration)
        data[f"models/{model}/peak_midpoint_deflection"] = amplitude
        data[f"models/{model}/thickness_m"] = thickness
    for model in list(flexible.MODELS)[:2]:  # two plates with a reference
        ffrf = results[f"{model}_ffrf"].datasets["coupler/midpoint_deflection"].data
        results[f"{model}_linear"] = case(f"{model}_linear", time=TIME,
                                          coupler__midpoint_deflection=ffrf * 0.97)
        data[f"reference/{model}/curve_time"] = TIME[::2]
        data[f"reference/{model}/curve_midpoint_deflection"] = ffrf[::2] * 1.05
    paths = flexible.figures(results, summary(**data), tmp_path)
    check_pngs(paths, tmp_path, {"flexible-midpoint-deflection.png",
                                 "flexible-stored-reference.png",
                                 "flexible-peak-deflection.png"}
               | {f"flexible-midpoint-acceleration-{m}.png" for m in flexible.MODELS})


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_crank_figures_synthetic(tmp_path, reviewed):
    from studies import crank

    time = np.linspace(0.0, 0.05, 501)
    results, data = {}, {}
    n_fit = np.geomspace(1.8, 29.0, 11)
    data |= {"fit/n": n_fit, "fit/governing": 0.36 * n_fit**-1.95, "fit/exponent": 1.95,
             "fit/coefficient": 0.36}
    for index, name in enumerate(crank.SCENES):
        results[f"{name}__full"] = case(
            f"{name}__full", time=time,
            crank__midpoint_deflection=7e-4 / 3**index * np.sin(400 * (index + 1) * time))
        tolerance = crank.SCENES[name][1]
        group = f"validation/{name}"
        data |= {f"{group}/n_physical": 2.0 + 7 * index,
                 f"{group}/errors/governing": tolerance * (0.5 if index else 2.0),
                 f"{group}/tolerance": tolerance,
                 f"{group}/choice": np.array("rigid" if index % 2 else "ffrf/6")}
    paths = crank.figures(results, summary(**data), tmp_path)
    check_pngs(paths, tmp_path, {"crank-deflection.png", "crank-validation.png"})


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_kfit_figures_synthetic(tmp_path, reviewed):
    from flex.experiments.fitting.kfit import label
    from studies import kfit

    rng = np.random.default_rng(1)
    names, family, zeta, n = [], [], [], []
    for fam, count in (("thk", 12), ("stf", 8), ("pre", 6)):
        for z in kfit.DAMPING_RATIOS:
            values = np.geomspace(1.0, 100.0, count)
            n += list(values)
            family += [fam] * count
            zeta += [z] * count
            names += [f"{fam}_{i}_z{z:g}" for i in range(count)]
    for model, thickness in kfit.THESIS_MODELS.items():
        names[list(kfit.THESIS_MODELS).index(model) * 3] = (
            f"thk_t{label(thickness, 1e3)}mm_z0")
    n = np.array(n)
    table = {"name": np.array(names, dtype=object), "family": np.array(family, dtype=object),
             "parameters/damping_ratio": np.array(zeta), "n_physical/stop": n,
             "fitted": n > 1.5}
    fits = {}
    for measure in ("deflection", "crank_angle", "slider_position", "stress_amplification",
                    criteria.GOVERNING):
        floor = measure == "stress_amplification"
        error = 0.2 * n**-1.9 * np.exp(rng.normal(0, 0.3, len(n))) + (0.5 if floor else 0)
        table[f"measures/{measure}"] = error
        for z in kfit.DAMPING_RATIOS:
            rows = np.isclose(table["parameters/damping_ratio"], z) & table["fitted"]
            fits[(z, "stop", measure)] = laws.fit_error_law(n[rows], error[rows],
                                                                floor=floor)
    deflection = table["measures/deflection"]
    table["predictor/deflection"] = deflection * np.exp(rng.normal(0, 0.1, len(n)))
    table["predictor/load_factor_deflection"] = 0.7 * deflection
    analysis = {"table": table, "fits": fits, "thesis_k_physical": {"stop": 108 / 2 / math.pi}}
    paths = kfit.figures({}, Summary({}, "", {"analysis": analysis}), tmp_path)
    check_pngs(paths, tmp_path, {"kfit-error-vs-n.png", "kfit-k-vs-tolerance.png",
                                 "kfit-predictors.png"})
    from flex.experiments.fitting.kfit_law import predictor_lines

    datasets: dict = {}
    lines = predictor_lines(table, fits, datasets)
    assert "from the rigid twin's loads (oscillator)" in "\n".join(lines)
    np.testing.assert_allclose(datasets["predictors/load_factor_ratio"].data, 0.7)


def test_tradeoff_figures_synthetic(tmp_path, reviewed):
    from studies import tradeoff

    count = 12
    wall = np.geomspace(1e-3, 1.0, count)
    knobs = ["{'engine': 'scipy'}"] * 3 + ["{'integrator': 'explicit_penalty'}"] * 3 \
        + ["{'step_s': 1e-4}"] * 6
    runs = {"label": np.array([f"setting {i}" for i in range(count)], dtype=object),
            "group": np.array(["scipy rtol"] * 3 + ["explicit"] * 3 + ["step"] * 6,
                              dtype=object),
            "knobs": np.array(knobs, dtype=object),
            "status": np.array(["ok"] * (count - 1) + ["failed"], dtype=object),
            "wall_time": wall, "error": 1e-6 / wall,
            "on_pareto_front": np.arange(count) % 2 == 0}
    data = {f"rigid/runs/{key}": value for key, value in runs.items()}
    data["rigid/reference/accuracy"] = 1e-7
    paths = tradeoff.figures({}, summary(**data), tmp_path)
    check_pngs(paths, tmp_path, {"tradeoff-rigid.png"})


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_stability_figures_synthetic(tmp_path, reviewed):
    from studies import stability

    steps = [1e-3, 1e-4, 1e-5]
    names = [f"step_rigid_h{h:g}" for h in steps] + [f"step_ffrf1mm_h{h:g}" for h in steps]
    data = {"runs/name": np.array(names, dtype=object),
            "runs/status": np.array(["ok"] * len(names), dtype=object),
            "runs/parameter": np.array(steps * 2),
            "runs/error": np.array([1e-2, 1e-4, 1e-6, 3e-2, 3e-4, 3e-6])}
    time = np.linspace(0.0, 1.0, 1001)
    results = {name: case(name, time=time, energy__total=0.36 * (1 + scale * np.sin(9 * time)))
               for name, scale in (("long_rigid_rho0.9", 1e-9), ("long_ffrf1mm", 1e-3),
                                   ("long_ffrf1mm_h1e-5", 1e-5), ("long_ffrf10mm", 0.0))}
    paths = stability.figures(results, summary(**data), tmp_path)
    check_pngs(paths, tmp_path, {"stability-step.png", "stability-energy.png"})


@pytest.mark.slow  # make test-slow: the default suite stays within 3 min
def test_bench_figures_synthetic(tmp_path, reviewed):
    from studies import bench

    data = {"rigid/flex_untuned/wall_time": 0.9, "rigid/flex_tuned/wall_time": 0.2,
            "rigid/scipy/wall_time": 0.05, "ffrf_1mm/untuned/wall_time": 3.0,
            "ffrf_1mm/tuned/wall_time": 0.4, "ffrf_1mm/default/wall_time": 0.45,
            "ffrf_1mm/nonlinear/wall_time_h2e-4": 40.0}
    for part in ("rigid", "ffrf_1mm"):
        for which, scale in (("profile_untuned", 1.0), ("profile_tuned", 0.8)):
            for phase, share in (("newton", 40.0), ("jacobian", 30.0), ("output", 10.0)):
                data[f"{part}/{which}/exudyn_{phase}_percent"] = share * scale
    from flex.experiments.workprecision.benchmark_report import _step_cost_rows

    step_cost: dict = {}
    rows = _step_cost_rows([
        {"mesh_size_m": mesh, "modes": modes, "mesh_nodes": nodes,
         "fewest_ms_per_step": 0.02 * modes ** 0.8, "fewest_newton_per_step": 6.3,
         "all_face_nodes_ms_per_step": 0.02 * modes ** 0.8 + nodes * 3e-4,
         "all_face_nodes_newton_per_step": 6.3}
        for mesh, nodes in ((0.004, 1080), (0.002, 3209), (0.001, 11935))
        for modes in (6, 12, 24)], step_cost)
    assert len(rows) == 9 and "x)" in rows[0][2]
    np.testing.assert_allclose(step_cost["step_cost/speedup"].data[:3],
                               [1 + 1080 * 3e-4 / (0.02 * m ** 0.8) for m in (6, 12, 24)])
    paths = bench.figures({}, summary(**data, **step_cost), tmp_path)
    check_pngs(paths, tmp_path, {"bench-times.png", "bench-profile-rigid.png",
                                 "bench-profile-ffrf_1mm.png", "bench-step-cost.png"})


def test_estimates_figure_and_summary_synthetic(tmp_path, reviewed):
    from flex.study import StudyRun
    from studies import estimates

    results = {}
    for index, (validity, ratio) in enumerate([("asymptotic", 0.95), ("asymptotic", 1.2),
                                               ("outside the asymptotic range for x", 0.01)]):
        true = 10.0 ** -(5 + index)
        results[f"s{index}"] = CaseResult(f"s{index}", "", attrs={
            "estimated_error_crank_angle_end_rad": ratio * true,
            "true_error_crank_angle_end_rad": true,
            "reference_accuracy_crank_angle_end_rad": true / 100,
            "estimated_error_validity": validity})
    result = estimates.summarize({}, results, StudyRun())
    # true / estimated: 1/0.95 and 1/1.2 within [1/3, 1.5], 100 (optimistic) outside
    assert "2 of 3 judged pairs within the target" in result.report
    assert "most optimistic true/estimated 100" in result.report
    assert "scenes with every judged pair within: 2 of 3" in result.report
    paths = estimates.figures(results, result, tmp_path)
    check_pngs(paths, tmp_path, {"estimates-pairs.png",
                                 "estimates-ratio-crank_angle_end_rad.png"})


def test_estimates_ratio_figure_per_quantity_synthetic(tmp_path, reviewed, monkeypatch):
    """One figure per quantity: a row per scene (named; a pair with no ratio says why), the
    ratios on a log axis, the target band [1/2, 1.5] shaded."""
    from flex.experiments.workprecision.estimate_check import OPTIMISM, PESSIMISM
    from flex.study import StudyRun
    from studies import estimates

    drawn = []
    save = matplotlib.figure.Figure.savefig
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig",
                        lambda self, path, *a, **k: (drawn.append((Path(path).name, self)),
                                                     save(self, path, *a, **k))[1])
    quantities = ("crank_angle_end_rad", "slider_position_end_m", "deployment_time_s")
    results = {}
    for index, ratio in enumerate((0.9, 1.3, 40.0)):
        attrs = {}
        for k, quantity in enumerate(quantities):
            true = 0.0 if (index, k) == (1, 2) else 10.0 ** -(4 + k)
            attrs |= {f"estimated_error_{quantity}": 10.0 ** -(4 + k) / ratio,
                      f"true_error_{quantity}": true,
                      f"reference_accuracy_{quantity}": 1e-9}
        results[f"scene_{index}"] = CaseResult(f"scene_{index}", "", attrs=attrs)
    summary = estimates.summarize({}, results, StudyRun())
    paths = estimates.figures(results, summary, tmp_path)
    check_pngs(paths, tmp_path, {"estimates-pairs.png"}
               | {f"estimates-ratio-{q}.png" for q in quantities})
    figures = dict(drawn)
    for quantity in quantities:
        ax = figures[f"estimates-ratio-{quantity}.png"].axes[0]
        assert ax.get_xscale() == "log" and quantity in figures[
            f"estimates-ratio-{quantity}.png"].get_suptitle()
        names = [label.get_text() for label in ax.get_yticklabels()]
        expected = ["scene_0", "scene_1 (true 0)" if quantity == quantities[2] else "scene_1",
                    "scene_2"]
        assert names == expected and list(ax.get_yticks()) == [2, 1, 0]  # the first on top
        (band,) = [patch for patch in ax.patches if patch.get_label().startswith("target")]
        low, high = band.get_x(), band.get_x() + band.get_width()
        assert (low, high) == pytest.approx((1 / PESSIMISM, OPTIMISM))
        points = np.concatenate([line.get_xdata() for line in ax.get_lines()
                                 if line.get_marker() == "o"])
        assert sorted(points) == pytest.approx(sorted(
            r for i, r in enumerate((0.9, 1.3, 40.0))
            if not (quantity == quantities[2] and i == 1)))


# ------------------------------------------------------------------------------------------
# expensive studies, real runs (make test-slow)
# ------------------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("name", ["modal", "flexible", "crank", "kfit"])
def test_expensive_study_figures(name, tmp_path, monkeypatch, reviewed, reduction_cache):
    monkeypatch.chdir(tmp_path)  # crank and kfit write results/... beside the run
    folder = tmp_path / "figures"
    folder.mkdir()
    check_pngs(run_and_draw(name, [], folder, reduction_cache), folder)
