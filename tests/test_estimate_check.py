"""The estimates study's verdicts (flex.experiments.workprecision.estimate_check): a pair whose
step term is a bound is flagged, not judged; a known true error above its certificate is
reported by name."""

from __future__ import annotations

import pytest

from flex.data.results import CaseResult
from flex.experiments.workprecision.estimate_check import estimate_summary, pair_rows
from flex.fidelity.stored_budget import BOUNDS_ATTR, CERTIFICATE_ATTR, STEP_BOUNDS_ATTR

PEAK, END = "coupler_deployment_peak_deflection_m", "crank_angle_end_rad"


def _case(true_peak: float, bounded: str) -> CaseResult:
    attrs = {CERTIFICATE_ATTR: 1.25, STEP_BOUNDS_ATTR: bounded}
    for quantity, estimated, true in ((PEAK, 2e-7, true_peak), (END, 1e-4, 0.8e-4)):
        attrs.update({f"estimated_error_{quantity}": estimated,
                      f"true_error_{quantity}": true,
                      f"reference_accuracy_{quantity}": true / 100,
                      f"headline_{quantity}": 1.0 if quantity == END else 1e-4})
    return CaseResult("case", "", attrs=attrs)


def test_a_bounded_step_term_is_flagged_not_judged():
    rows = {row["quantity"]: row for row in pair_rows({"a": _case(1.5e-7, PEAK)})}
    assert rows[PEAK]["flagged"] and not rows[PEAK]["judged"]
    assert "flagged" in rows[PEAK]["why"]
    assert rows[END]["judged"] and not rows[END]["flagged"]


def test_a_true_error_above_its_certificate_is_named():
    _, report = estimate_summary({"a": _case(3e-7, "")})  # certificate 2.5e-7
    line = next(text for text in report.splitlines() if "certificates exceeded" in text)
    assert "exceeded by a known true error: 1" in line and PEAK in line
    _, report = estimate_summary({"a": _case(2e-7, "")})
    assert "exceeded by a known true error: 0" in report


def test_a_raw_peak_is_a_bound_checked_against_its_certificate_not_judged():
    case = _case(1e-9, "")  # 200x below its "estimate": pessimistic, as a bound may be
    case.attrs[BOUNDS_ATTR] = PEAK
    rows = {row["quantity"]: row for row in pair_rows({"a": case})}
    assert rows[PEAK]["bound"] and not rows[PEAK]["judged"] and "bound" in rows[PEAK]["why"]
    assert rows[END]["judged"] and not rows[END]["bound"]
    _, report = estimate_summary({"a": case})
    assert "bounds (raw peaks" in report and "1 pairs, 1 with a known" in report
    case.attrs[f"true_error_{PEAK}"] = 3e-7  # above its certificate: still named
    _, report = estimate_summary({"a": case})
    assert "exceeded by a known true error: 1" in report


def test_a_true_error_at_the_noise_floor_is_no_known_exceedance():
    """Two runs' round-off (1e-13 rad on a crank angle of order 1, below the study's noise
    floor) above a certificate of 3e-14 is not named; the same miss above the floor is."""
    case = _case(2e-7, "")
    case.attrs.update({f"estimated_error_{END}": 2.4e-14, f"true_error_{END}": 1e-13,
                       f"reference_accuracy_{END}": 1e-15})
    _, report = estimate_summary({"a": case})
    assert "exceeded by a known true error: 0" in report
    case.attrs.update({f"estimated_error_{END}": 2.4e-7, f"true_error_{END}": 1e-6,
                       f"reference_accuracy_{END}": 1e-8})
    _, report = estimate_summary({"a": case})
    assert "exceeded by a known true error: 1" in report and END in report


def test_a_run_is_compared_with_the_stored_reference_of_its_physics():
    """A value's true error is its difference to the stored value, a history's the largest
    difference of the curves (the stored one interpolated on the run's times); the stored
    accuracy travels with it."""
    import numpy as np

    from flex.data.reference_store import StoredReference
    from flex.data.results import Dataset
    from flex.experiments.workprecision.estimate_check import _compare

    time_s = np.linspace(0.0, 0.03, 31)
    run = CaseResult("run", "", datasets={
        "time": Dataset(time_s, "s"), "crank/angle": Dataset(np.sin(time_s * 10) + 1e-3, "rad")},
        attrs={f"estimated_error_{END}": 2e-3, "estimated_error_history_crank_angle": 2e-3})
    stored_time = np.linspace(0.0, 0.03, 301)
    reference = StoredReference(
        "ref", {}, "model", "evidence", {END: float(np.sin(0.3)) - 5e-4,
                                         "history_crank_angle": 1.0},
        {END: 1e-5, "history_crank_angle": 2e-5}, {END: "rad", "history_crank_angle": "rad"},
        {"time": stored_time, "crank/angle": np.sin(stored_time * 10)},
        {"time": "s", "crank/angle": "rad"})
    _compare(run, reference, "lifted")
    assert run.attrs[f"true_error_{END}"] == pytest.approx(1.5e-3, rel=1e-9)
    assert run.attrs[f"reference_accuracy_{END}"] == 1e-5
    # linear interpolation of the stored sine at the run's (common) samples: exact there
    assert run.attrs["true_error_history_crank_angle"] == pytest.approx(1e-3, rel=1e-6)
    assert run.attrs[f"estimate_ratio_{END}"] == pytest.approx(2e-3 / 1.5e-3)


def test_the_tolerance_table_counts_what_the_reference_can_decide():
    """tolerance_rows: per level and mode, the cases the reference decides, how many truly
    meet the tolerance, how many state it met, and those stating it met that miss it."""
    from flex.experiments.workprecision.tolerance_check import tolerance_rows

    def case(true, met, decided=True):
        return CaseResult("c", "", attrs={
            "tolerance_true_error": true, "tolerance_allowed": 1.0,
            "tolerance_truly_met": true <= 1.0, "tolerance_decided": decided,
            "tolerance_met": met})

    results = {"a--0.01--first": case(0.5, True), "b--0.01--first": case(2.0, True),
               "c--0.01--first": case(0.9, False, decided=False),
               "a--0.01--refined": case(0.2, True)}
    rows = {(r["tolerance"], r["mode"]): r for r in tolerance_rows(results)}
    first = rows[(0.01, "first")]
    assert first["decided"] == "2 of 3" and first["truly_met"] == 1
    assert first["stated_met"] == 2 and first["stated_but_missed"] == 1
    assert first["worst_true_over_allowed"] == 2.0
    assert rows[(0.01, "refined")]["truly_met"] == 1
    assert rows[(0.001, "first")]["decided"] == "0 of 0"


def test_a_pair_is_judged_when_no_error_of_the_reference_can_flip_its_verdict():
    """Estimate 1e-7: a true error 4e-9 +- 7e-9 (the 3 mm plate's deployment peak against its
    stored reference) lies wholly below 1/2 of it: judged, outside (pessimistic); 8e-8 +- 1e-8
    wholly inside [1/2, 1.5]: judged, within; 5.5e-8 +- 1e-8 straddles 1/2: not judged."""
    from flex.experiments.workprecision.estimate_check import reference_decides

    assert reference_decides(4e-9, 7e-9, 1e-7)
    assert reference_decides(8e-8, 1e-8, 1e-7)
    assert not reference_decides(5.5e-8, 1e-8, 1e-7)
    assert not reference_decides(1.45e-7, 1e-8, 1e-7)  # straddles 1.5
    assert reference_decides(1.7e-7, 1e-8, 1e-7)  # wholly above: optimistic
    assert not reference_decides(2.7e-5, 8e-5, 0.0)  # nothing estimated, nothing sure
    assert reference_decides(2.7e-5, 1e-5, 0.0)  # nothing estimated, surely an error
    case = _case(2e-7, "")
    case.attrs.update({f"true_error_{PEAK}": 4e-9, f"reference_accuracy_{PEAK}": 7e-9})
    rows = {row["quantity"]: row for row in pair_rows({"a": case})}
    assert rows[PEAK]["judged"]
    case.attrs[f"reference_accuracy_{PEAK}"] = 1e-7
    rows = {row["quantity"]: row for row in pair_rows({"a": case})}
    assert not rows[PEAK]["judged"] and rows[PEAK]["why"] == "reference not accurate enough"


def test_a_bound_or_flagged_pair_needs_its_reference_only_to_decide_its_certificate():
    """A raw peak (a bound) or a flagged estimate is asked whether its certificate holds:
    true 1.5e-7 +- 2e-8 against a certificate of 2.5e-7 is decided (surely within), though
    the same interval over the estimate straddles 1/2 and 1.5 of the band; 2.4e-7 +- 2e-8 is
    not. An error below the solver's noise floor needs no reference at all."""
    from flex.experiments.workprecision.estimate_check import certificate_decided

    assert certificate_decided(1.5e-7, 2e-8, 2.5e-7)
    assert certificate_decided(3e-7, 2e-8, 2.5e-7)  # surely exceeded
    assert not certificate_decided(2.4e-7, 2e-8, 2.5e-7)
    for bounded in (PEAK, ""):
        case = _case(1.5e-7, bounded)  # flagged (a bounded step term), or a raw-peak bound
        case.attrs[f"reference_accuracy_{PEAK}"] = 2e-8
        if not bounded:
            case.attrs[BOUNDS_ATTR] = PEAK
        row = {row["quantity"]: row for row in pair_rows({"a": case})}[PEAK]
        assert not row["judged"] and "certificate checked" in row["why"]
        case.attrs[f"true_error_{PEAK}"] = 2.4e-7
        row = {row["quantity"]: row for row in pair_rows({"a": case})}[PEAK]
        assert row["why"] == "reference not accurate enough to check its certificate"
    case = _case(2e-7, "")
    case.attrs.update({f"estimated_error_{END}": 2.4e-14, f"true_error_{END}": 1e-13,
                       f"reference_accuracy_{END}": 1e-12})  # reference noisier than both
    row = {row["quantity"]: row for row in pair_rows({"a": case})}[END]
    assert row["why"] == "noise floor"


def test_the_findings_count_the_pairs_no_reference_could_decide():
    from flex.experiments.workprecision.estimate_report import estimate_findings

    case = _case(2e-7, "")
    case.attrs[f"reference_accuracy_{PEAK}"] = 1.5e-7  # straddles the band: undecided
    _, findings = estimate_findings({"a": case})
    line = next(text for text in findings.splitlines() if "not accurate enough" in text)
    assert "to decide: 1 of 2 pairs (target: none)" in line
    assert "reference too coarse 1" in line


def test_a_joint_force_error_below_the_multipliers_noise_is_the_noise_floor():
    """A rigid run's joint-force peak 1.6e-5 N off a 6.4 N reference whose own Newton noise is
    8e-5 N (the index-3 multipliers at 1.25e-6 s): below JOINT_FORCE_NOISE_FLOOR, not a
    reference too coarse; the same error on a 0.1 N peak is above it."""
    from flex.experiments.workprecision.estimate_check import JOINT_FORCE_NOISE_FLOOR

    force = "joint_A_deployment_peak_force_N"
    for peak_N, why in ((6.4, "noise floor"), (0.1, "reference not accurate enough")):
        case = CaseResult("case", "", attrs={
            f"estimated_error_{force}": 2.5e-6, f"true_error_{force}": 1.6e-5,
            f"reference_accuracy_{force}": 6.9e-5, f"headline_{force}": peak_N})
        row = pair_rows({"a": case})[0]
        assert row["why"] == why
    assert 1.6e-5 / 6.4 < JOINT_FORCE_NOISE_FLOOR < 1.6e-5 / 0.1


def test_a_stored_bound_adds_its_terms_and_says_it_is_a_bound():
    """A quantity the budget names a bound (a ``peak`` headline's raw maximum; no built-in
    is one): its total is the sum of its terms, not their root-sum-square, and its line says
    it is a bound, not an estimate."""
    from flex.fidelity.stored_budget import budget_rows

    terms = {"step": 3e-7, "modes": 0.0, "mesh": 1e-7, "model": 2e-7}
    attrs = {f"headline_{PEAK}": 1e-4, f"estimated_error_{PEAK}": sum(terms.values()),
             f"estimated_error_{PEAK}_relative": sum(terms.values()) / 1e-4,
             **{f"estimated_error_{PEAK}_{term}": value for term, value in terms.items()},
             BOUNDS_ATTR: PEAK}
    row = next(row for row in budget_rows(attrs) if row.quantity == PEAK)
    assert row.bound and not row.problem
    assert row.total == pytest.approx(6e-7, rel=1e-12)
    assert "a bound, not an estimate" in row.text()
