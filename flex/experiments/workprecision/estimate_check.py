"""Is a run's error budget honest? The stored total against the true error on many scenes.

:func:`check_one` runs a scene as a user would (its own settings, the error budget on:
:mod:`flex.fidelity.error_budget`) and compares it with the **stored reference** of its
physics (:mod:`flex.data.reference_store`, made once by ``make references``: the calibrated
exact beam for a plate link, the rigid mechanism at a fine step for lumped links,
:mod:`flex.experiments.workprecision.stored_references`). Nothing is computed for the
reference inside the run: a scene whose physics the store lacks fails with the command that
makes it.

Per headline quantity it stores on the case, as attributes:

- ``true_error_<q>``: |run - reference| [the quantity's units]; a history's the largest
  difference of the run's curve to the stored one (sampled every 1e-5 s, a cubic spline at
  the run's times: :func:`flex.experiments.workprecision.stored_references.curve_at`);
- ``reference_accuracy_<q>``: the reference's own error, as stored (a history's plus its
  interpolation's);
- ``estimate_ratio_<q>``: estimated / true error (1: exact; below 1: optimistic).

A pair is *judged* only where the reference decides its verdict (:func:`reference_decides`:
true +- the reference's accuracy, over the estimate, wholly inside or wholly outside the
band), it lies above the solver's noise floor (:data:`NOISE_FLOOR` of the quantity's
scale; :data:`JOINT_FORCE_NOISE_FLOOR` for a joint force), and its total is an estimate; a
bound (a raw peak) or a flagged estimate (its step term a bound) is asked only
whether its certificate holds, and its reference is accurate enough when it decides that
(:func:`certificate_decided`). The others are stored and said, not judged, each with why
(:func:`_why_not_judged`). :func:`estimate_summary` makes the table, the verdicts against
the targets (true / estimated within [1 / :data:`PESSIMISM`,
:data:`OPTIMISM`]) and the figure data.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.caseloop import run_each
from flex.base.plotting import figure
from flex.data.headlines import BUILTIN_HEADLINES, Headline, channel_curve
from flex.data.reference_store import MissingReferenceError, StoredReference, reference_for
from flex.data.results import CaseResult, Dataset
from flex.data.scene import LINKS, Scene
from flex.data.scene_edit import derive_scene
from flex.data.tables import table_datasets
from flex.dynamics.advice import CHANNEL_DETERMINED
from flex.experiments.workprecision.stored_references import curve_at
from flex.fidelity.simulation import simulate_case
from flex.fidelity.stored_budget import CERTIFICATE_ATTR, PREFIX, STEP_BOUNDS_ATTR, named_quantities

#: targets (issue 35): true / estimated within [1 / PESSIMISM, OPTIMISM] for every judged
#: pair in the asymptotic range; at most FLAGGED_SHARE of all pairs flagged outside it (a
#: step term that is a bound); no true error above its certificate
PESSIMISM, OPTIMISM = 2.0, 1.5
FLAGGED_SHARE = 0.10
#: below this fraction of a quantity's scale an error is solver noise (Newton tolerance)
NOISE_FLOOR = 1e-8
#: a joint force's noise floor (relative to its peak): the index-3 multipliers' Newton noise
#: grows as the step shrinks (an error of the residual over h^2). Measured on the rigid thesis
#: mechanism: at the stored reference's step, 1.25e-6 s, tightening Newton from 1e-8 to 1e-10
#: moved joint A's and B's deployment peaks by 8.3e-5 and 8.2e-5 N (1.3e-5 and 1.0e-5 of
#: 6.4 and 8.5 N); at 6.25e-7 s joint C's by 3.9e-4 N; index 2 converged at first order
#: instead (``/tmp/s12/rigid2.py``, session 12). A rigid run's joint-force error (1-3e-6 of
#: the peak) lies below what any reference made so can resolve
JOINT_FORCE_NOISE_FLOOR = 2e-5
#: scale of each headline quantity for the noise floor: 1 rad, the slider travel ~0.1 m; a
#: peak or time: its own size
_SCALES = {"crank_angle_end_rad": 1.0, "slider_position_end_m": 0.1}

Progress = Callable[[str, int, int], None]


def _run(scene: Scene, name: str, overrides: list[str], cache_dir: Path | None) -> CaseResult:
    return simulate_case(derive_scene(scene, [*overrides, "simulation.output_step_s=0.0"]),
                         name, cache_dir=cache_dir)


def check_one(name: str, scene: Scene, cache_dir: Path | None,
              store: Mapping[str, StoredReference]) -> CaseResult:
    """The run of ``scene`` with its error budget, compared with the stored reference of its
    physics (module doc); a failed run, or physics the store lacks, makes a failed case."""
    run = _run(scene, name, ["simulation.error_estimate=true"], cache_dir)
    if run.status != "ok":
        return run
    try:
        reference = reference_for(store, scene)
    except MissingReferenceError as exc:
        return CaseResult(name, run.scene_toml, status="failed", message=str(exc))
    run.attrs["reference"] = f"stored {reference.name}: {reference.model}"
    same_model = not any(scene[link]["geometry"] == "plate" for link in LINKS)
    _compare(run, reference, "same model" if same_model else "lifted")
    return run


def _compare(run: CaseResult, reference: StoredReference, rung: str) -> None:
    """``true_error_*``, ``reference_accuracy_*``, ``reference_rung_*`` and
    ``estimate_ratio_*`` on ``run`` for each quantity both have."""
    for quantity, headline in BUILTIN_HEADLINES.items():
        ours = headline.read(run.datasets)
        if (ours is None or f"{PREFIX}{quantity}" not in run.attrs
                or quantity not in reference.values):
            continue
        accuracy = reference.accuracies[quantity]
        if headline.kind == "history":
            true, sampling = _history_error(run, reference, headline)
            accuracy += sampling
        else:
            true = abs(ours - reference.values[quantity])
        run.attrs[f"true_error_{quantity}"] = true
        run.attrs[f"reference_accuracy_{quantity}"] = accuracy
        run.attrs[f"reference_rung_{quantity}"] = rung
        run.attrs[f"estimate_ratio_{quantity}"] = (
            run.attrs[f"{PREFIX}{quantity}"] / true if true > 0 else math.inf)


def _history_error(run: CaseResult, reference: StoredReference, headline: Headline
                   ) -> tuple[float, float]:
    """A history's true error: the largest difference of the run's curve to the stored one,
    both on the headline channel where the history is read so, over the times both
    determine; and the stored curve's interpolation error [the curve's unit]."""
    time_s, ours = channel_curve(run.datasets, headline.series)
    path, end_s = headline.series, float(reference.curves["time"][-1])
    if headline.series in headline.channel and f"channel/{path}" in reference.curves:
        path = f"channel/{path}"
        determined = np.count_nonzero(reference.curves.get(CHANNEL_DETERMINED, [1]))
        end_s = float(reference.curves["time"][max(determined, 1) - 1])
    inside = time_s <= end_s
    theirs, sampling = curve_at(reference, path, time_s[inside])
    return float(np.max(np.abs(ours[inside] - theirs))), sampling


def check_estimates(scenes: Mapping[str, Scene], store: Mapping[str, StoredReference],
                    cache_dir: Path | None = None, progress: Progress | None = None,
                    executor: Any = None) -> dict[str, CaseResult]:
    """:func:`check_one` for every scene against ``store``: in order in this process, or on
    ``executor`` (:mod:`flex.sweep`'s, passed in) in parallel, the costliest first
    (:func:`_cost`)."""
    return run_each(dict(scenes), functools.partial(check_one, cache_dir=cache_dir,
                                                    store=store),
                    progress, executor=executor, cost=_cost)


def _cost(name: str, scene: Scene) -> float:
    """A scene's rough cost for ordering the jobs [arbitrary units]: a meshed link's run
    (its reductions and budget companions) before a rigid one; thinner plates first."""
    return sum(10.0 + 1e-3 / float(scene[link]["thickness_m"]) for link in LINKS
               if scene[link]["model"] == "ffrf")


def reference_decides(true: float, accuracy: float, estimated: float) -> bool:
    """Whether a reference of ``accuracy`` decides where a pair's true / estimated lies
    against the target band: the whole interval [true - accuracy, true + accuracy] /
    estimated [each in the quantity's unit] lies inside [1 / PESSIMISM, OPTIMISM], or wholly
    outside it (a verdict no error of the reference can flip; the earlier rule, accuracy
    within a third of the true error, left pairs 20x outside the band undecided)."""
    if estimated <= 0:  # an estimate of nothing: wrong only where the error surely is not
        return true - accuracy > 0
    low, high = max(true - accuracy, 0.0) / estimated, (true + accuracy) / estimated
    return (1 / PESSIMISM <= low and high <= OPTIMISM) or high < 1 / PESSIMISM or low > OPTIMISM


def certificate_decided(true: float, accuracy: float, certificate: float) -> bool:
    """Whether a reference of ``accuracy`` decides a certificate check: the interval
    [true - accuracy, true + accuracy] lies wholly below ``certificate`` or wholly above it
    [each in the quantity's unit]."""
    return true + accuracy <= certificate or true - accuracy > certificate


def _why_not_judged(true: float, known: bool, above_noise: bool, bound: bool,
                    flagged: bool) -> str:
    """Why a pair is not judged, in the order the checks decide: two runs that agree
    exactly, an error below the solver's noise floor (no reference need decide it), a
    reference that cannot decide what the pair is asked, a bound, a flagged estimate."""
    if true == 0:
        return "every run agrees exactly"
    if not above_noise:
        return "noise floor"
    if not known:
        return "reference not accurate enough" + (" to check its certificate"
                                                  if bound or flagged else "")
    if bound:
        return "a bound (a raw peak): its certificate checked, not judged"
    return ("flagged: outside the asymptotic range (its step term a bound), its certificate "
            "checked")


def pair_rows(results: Mapping[str, CaseResult]) -> list[dict[str, Any]]:
    """One row per (case, quantity) with an estimate and a true error."""
    rows = []
    for name, case in results.items():
        for quantity in BUILTIN_HEADLINES:
            if f"true_error_{quantity}" not in case.attrs:
                continue
            estimated = float(case.attrs[f"{PREFIX}{quantity}"])
            true = float(case.attrs[f"true_error_{quantity}"])
            accuracy = float(case.attrs[f"reference_accuracy_{quantity}"])
            scale = _SCALES.get(quantity) or abs(float(case.attrs.get(
                f"headline_{quantity}", max(true, estimated))))
            floor = (JOINT_FORCE_NOISE_FLOOR if BUILTIN_HEADLINES[quantity].unit == "N"
                     else NOISE_FLOOR)
            above_noise = max(true, estimated) > floor * scale
            terms = {term: float(case.attrs.get(f"{PREFIX}{quantity}_{term}", 0.0))
                     for term in ("step", "modes", "mesh", "model")}
            flagged = quantity in named_quantities(case.attrs, STEP_BOUNDS_ATTR)
            bound = quantity in named_quantities(case.attrs)
            factor = float(case.attrs.get(CERTIFICATE_ATTR, 1.0))
            # a bound or a flagged pair is asked one thing, whether its certificate holds;
            # an estimate whether true / estimated lies in the band
            known = true > 0 and (certificate_decided(true, accuracy, factor * estimated)
                                  if bound or flagged else
                                  reference_decides(true, accuracy, estimated))
            judged = known and above_noise and not flagged and not bound
            rows.append({"case": name, "quantity": quantity, "estimated": estimated,
                         "certificate": factor * estimated, "flagged": flagged,
                         "bound": bound, "true": true, "reference_accuracy": accuracy,
                         "above_noise": above_noise, "judged": judged,
                         "largest_term": max(terms, key=terms.get),
                         "why": "" if judged else _why_not_judged(true, known, above_noise,
                                                                   bound, flagged),
                         "same_model": case.attrs.get(f"reference_rung_{quantity}")
                         == "same model"})
    return rows


#: ``/summary/pairs/<column>``: one row per (case, headline quantity) with a true error
PAIR_COLUMNS = {"case": ("1", "case"), "quantity": ("1", "headline quantity (units in name)"),
                "estimated": ("see quantity", "the run's estimated error (its budget's total)"),
                "true": ("see quantity", "|run - reference|"),
                "reference_accuracy": ("see quantity", "the reference's own error"),
                "certificate": ("see quantity", "the run's certificate (estimate x its factor)"),
                "flagged": ("1", "outside the asymptotic range: the step term is a bound"),
                "bound": ("1", "a raw peak: its total is a bound, not an estimate"),
                "judged": ("1", "the reference decides the verdict (reference_decides), above "
                                "the noise floor, not flagged"),
                "largest_term": ("1", "the budget's largest term")}


def estimate_summary(results: Mapping[str, CaseResult]) -> tuple[dict[str, Dataset], str]:
    """``/summary`` datasets (one entry per case and quantity) and the report."""
    rows = pair_rows(results)
    datasets = table_datasets(rows, PAIR_COLUMNS, "pairs")
    ratio = np.array([r["true"] / r["estimated"] if r["estimated"] > 0 else np.inf
                      for r in rows])
    datasets["pairs/true_over_estimated"] = Dataset(ratio, "1", "true / estimated (above 1: "
                                                    "optimistic)")
    references = {name: case.attrs.get("reference", "") for name, case in results.items()}
    return datasets, _report(rows, ratio, references)


def verdicts(rows: list[dict[str, Any]], ratio: np.ndarray) -> dict[str, Any]:
    """The verdicts against the targets of the pairs ``rows`` (:func:`pair_rows`) with their
    true / estimated ``ratio``: ``judged``, ``inside`` (the target band), ``flagged`` and
    ``bound`` (boolean arrays per pair), ``known_bounds`` and ``exceeded`` (the rows of the
    bounds with a known true error and of the certificates a known true error exceeds),
    ``spread`` (true / bound of the known bounds) and ``by_scene`` (scene -> whether each of
    its judged pairs is inside)."""
    judged = np.array([r["judged"] for r in rows], dtype=bool)
    inside = (ratio >= 1 / PESSIMISM) & (ratio <= OPTIMISM)
    known_bounds = [r for r in rows if r["bound"] and r["true"] > 0
                    and r["true"] >= 3 * r["reference_accuracy"]]
    by_scene: dict[str, list[bool]] = {}
    for row, is_judged, is_inside in zip(rows, judged, inside, strict=True):
        if is_judged:
            by_scene.setdefault(row["case"], []).append(bool(is_inside))
    return {"judged": judged, "inside": inside,
            "flagged": np.array([r["flagged"] for r in rows], dtype=bool),
            "bound": np.array([r["bound"] for r in rows], dtype=bool),
            "known_bounds": known_bounds,
            # a true error below the solver's noise floor is no known exceedance (as it is
            # no judged pair): two runs' round-off, not the run's error
            # exceeded beyond what the reference's own error could explain
            "exceeded": [r for r in rows
                         if r["true"] - r["reference_accuracy"] > r["certificate"]
                         and r.get("above_noise", True)],
            "spread": [r["true"] / r["estimated"] for r in known_bounds if r["estimated"] > 0],
            "by_scene": by_scene}


def _report(rows: list[dict[str, Any]], ratio: np.ndarray, references: dict[str, str]) -> str:
    found = verdicts(rows, ratio)
    judged, inside, flagged = found["judged"], found["inside"], found["flagged"]
    exceeded, spread = found["exceeded"], found["spread"]
    lines = [f"error budgets: the stored total against the true error ({len(rows)} pairs, "
             f"{int(judged.sum())} judged; targets: true / estimated within "
             f"[1/{PESSIMISM:g}, {OPTIMISM:g}] for judged pairs, at most "
             f"{100 * FLAGGED_SHARE:g} % flagged, no certificate exceeded)", "",
             f"- flagged outside the asymptotic range: {int(flagged.sum())} of {len(rows)} "
             f"pairs ({100 * flagged.mean() if rows else 0:.0f} %); certificates exceeded by "
             f"a known true error: {len(exceeded)}"
             + "".join(f"; {r['case']} {r['quantity']} (true {r['true']:.3g}, certificate "
                       f"{r['certificate']:.3g})" for r in exceeded)]
    if found["bound"].any():
        lines.append(f"- bounds (raw peaks, no order of convergence: checked "
                     f"against their certificates, not judged as estimates): "
                     f"{int(found['bound'].sum())} pairs, {len(found['known_bounds'])} with a "
                     f"known true error"
                     + (f", true / bound {min(spread):.2g} to {max(spread):.2g}"
                        if spread else ""))
    if judged.any():
        by_scene = found["by_scene"]
        within = [scene for scene, flags in by_scene.items() if all(flags)]
        lines.append(f"- {int((inside & judged).sum())} of {int(judged.sum())} judged pairs "
                     f"within the target; most optimistic true/estimated "
                     f"{ratio[judged].max():.3g}, most pessimistic {ratio[judged].min():.3g}; "
                     f"scenes with every judged pair within: {len(within)} of "
                     f"{len(by_scene)}")
    lines += ["", "| case | quantity | estimated | true | true / estimated | largest term | note |",
              "|---|---|---:|---:|---:|---|---|"]
    for row, value in zip(rows, ratio, strict=True):
        note = row["why"] or ("" if 1 / PESSIMISM <= value <= OPTIMISM else "**outside**")
        if row["same_model"]:
            note += " (the model term unchecked: no higher rung computes it)"
        lines.append(f"| {row['case']} | {row['quantity']} | {row['estimated']:.3g} | "
                     f"{row['true']:.3g} | {value:.3g} | {row['largest_term']} | {note} |")
    lines.append("")
    lines.append("- references: " + "; ".join(f"{name}: {text}" for name, text in
                                              references.items() if text))
    return "\n".join(lines)


def draw_estimates(datasets: Mapping[str, Dataset], folder: Path) -> list[Path]:
    """``estimates-pairs.png``: true over estimated error of every pair against the estimated
    error's relative size, the target band shaded; judged pairs filled."""
    if "pairs/true" not in datasets or not len(datasets["pairs/true"].data):
        return []
    true = np.asarray(datasets["pairs/true"].data, dtype=float)
    estimated = np.asarray(datasets["pairs/estimated"].data, dtype=float)
    judged = np.asarray(datasets["pairs/judged"].data, dtype=bool)
    path = folder / "estimates-pairs.png"
    with figure(path, "True / estimated error of each headline quantity (log-log)",
                "estimated error, the budget's total [the quantity's unit: rad, m, s, N, Pa]",
                "true / estimated error [1]", size=(6.8, 6.0)) as ax:
        positive = (true > 0) & (estimated > 0)
        ratio = np.where(positive, true / np.where(estimated > 0, estimated, 1), np.nan)
        ax.axhspan(1 / PESSIMISM, OPTIMISM, color="0.9",
                   label=f"target [1/{PESSIMISM:g}, {OPTIMISM:g}]")
        ax.axhline(1.0, color="0.4", lw=1, label="true = estimated")
        for pick, style, label in (
                (judged & positive, dict(marker="o", color="tab:blue"), "judged"),
                (~judged & positive, dict(marker="x", color="0.5"),
                 "not judged (reference or noise)")):
            if pick.any():
                ax.plot(estimated[pick], ratio[pick], ls="none", label=label, **style)
        ax.set_xscale("log")
        ax.set_yscale("log")
    return [path]
