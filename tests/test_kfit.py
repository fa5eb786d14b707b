"""The kfit study's cases and report parts that need no simulation: the FFRF reference with
geometric stiffness, the cases left out beyond the Euler load limit (against the closed-form
Euler load), and the prediction margin the report sets beside the installed one."""

import math

import numpy as np
import pytest

from flex.experiments.fitting import kfit, kfit_law, lawfit
from flex.fidelity.criteria import (
    EULER_LOAD_LIMIT,
)
from flex.fidelity.laws import (
    load_criterion,
)
from flex.fidelity.predictor import PREDICTION_MARGIN
from flex.study import study_scene
from studies import kfit as kfit_study


@pytest.fixture(scope="module")
def study():
    scene = study_scene(kfit_study)
    return scene, kfit_study.cases(scene)


def test_every_reference_has_geometric_stiffness_and_auto_keeps_the_default(study):
    scene, cases = study
    fit = {n: s for n, s in cases.items() if not n.startswith("val_")}
    validation = {n: s for n, s in cases.items() if n.startswith("val_")}
    assert fit and validation
    assert all(s["coupler"]["geometric_stiffness"] is True for s in fit.values())
    assert all(s["coupler"]["model"] == "ffrf" for s in fit.values())
    for s in validation.values():  # auto is validated as a user gets it (key at default)
        assert s["coupler"]["model"] == "auto" and s["coupler"]["geometric_stiffness"] is True
        full = kfit.full_scene(s)
        assert full["coupler"]["model"] == "ffrf"
        assert full["coupler"]["geometric_stiffness"] is True
        assert full["coupler"]["modes"] == lawfit.FULL_MODES


def _closed_form_ratio(scene, thickness_m, spring_N_per_m, preload_m):
    c = scene["coupler"]
    euler_N = (math.pi**2 * c["youngs_modulus_Pa"] * c["width_m"] * thickness_m**3 / 12
               / c["length_m"] ** 2)
    return kfit.COMPRESSION_SHARE * spring_N_per_m * preload_m / euler_N


def test_cases_beyond_the_euler_load_limit_are_left_out_and_named(study):
    scene, cases = study
    left_out = kfit.left_out_cases(scene, *kfit_study._grid())
    assert not set(left_out) & set(cases)
    for name, ratio in left_out.items():
        assert ratio > EULER_LOAD_LIMIT, name
    # every generated fit case is within the limit by the same estimate, in closed form
    for name, s in cases.items():
        if name.startswith("val_"):
            continue
        ratio = _closed_form_ratio(scene, s["coupler"]["thickness_m"],
                                   s["drive"]["spring_stiffness_N_per_m"],
                                   s["drive"]["spring_preload_m"])
        assert ratio <= EULER_LOAD_LIMIT, name
    # the grid's candidates at the thesis preload (22 mm): 0.5 mm at the thesis spring (est.
    # 0.33 P_E, rigid twin 0.33), 1 mm at 15000 N/m (0.41; 0.49), and everything stiffer
    expected = {f"{stem}_z{z}" for z in (0, 2) for stem in (
        "thk_t0p5mm", "stf_t0p5mm_k5000", "stf_t0p5mm_k15000", "stf_t0p5mm_k50000",
        "stf_t1mm_k15000", "stf_t1mm_k50000")}
    assert set(left_out) == expected
    assert left_out["thk_t0p5mm_z0"] == pytest.approx(
        _closed_form_ratio(scene, 0.5e-3, 1500.0, 0.022), rel=1e-12)
    assert left_out["thk_t0p5mm_z0"] == pytest.approx(0.329, abs=1e-3)
    assert "thk_t0p591mm_z0" in cases  # 0.199 P_E estimated: kept


def _table(measured, predicted, fitted, ratio=None, names=None):
    count = len(measured)
    return {"name": np.array(names or [f"c{i}" for i in range(count)], dtype=object),
            "measures/deflection": np.asarray(measured, float),
            "predictor/deflection": np.asarray(predicted, float),
            "measures/euler_load_ratio": np.asarray(ratio if ratio is not None
                                                    else [0.1] * count, float),
            "fitted": np.asarray(fitted, bool)}


def test_prediction_margin_is_the_quantile_of_measured_over_predicted_fitted_cases():
    measured = np.linspace(1.0, 2.0, 21)
    data = _table(np.r_[measured, 50.0, np.nan], np.r_[np.ones(21), 1.0, 1.0],
                  [True] * 21 + [False, True])  # the outlier is not fitted, NaN is skipped
    assert kfit_law.prediction_margin(data) == pytest.approx(1.95)  # 95 % of 1..2
    assert math.isnan(kfit_law.prediction_margin(_table([1.0], [1.0], [False])))


def test_report_names_every_case_not_in_the_fit_and_why():
    data = _table([0.001, 0.08, 0.002], [0.001, 0.05, 0.002], [True, False, False],
                  ratio=[0.1, 0.4, 0.3], names=["ok_case", "bent_case", "loaded_case"])
    datasets: dict = {}
    lines = "\n".join(kfit_law.exclusion_lines(data, {"never_run": 0.41}, datasets))
    assert "never_run (0.41)" in lines and "not generated (1)" in lines
    assert "bent_case (0.40 P_E)" in lines and "deflection > 5% of L2" in lines
    assert "loaded_case (0.30 P_E)" in lines and "compression > 0.25" in lines
    assert "ok_case" not in lines
    assert list(datasets["excluded/not_generated/name"].data) == ["never_run"]


def test_installed_criterion_is_fitted_against_geometric_ffrf_and_margin_covers_it():
    criterion = load_criterion()
    assert "geometric_stiffness = true" in criterion.meta["reference"]
    # PREDICTION_MARGIN (flex.fidelity.predictor) covers the 95 % quantile of measured /
    # predicted deflection error of the run the installed law came from
    assert criterion.meta["prediction_margin_measured"] <= PREDICTION_MARGIN
