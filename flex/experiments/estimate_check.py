"""Is a run's error estimate honest? Estimated against true step error on many scenes.

:func:`check_estimates` runs each scene as a user would (its own step, the error estimate
on: :mod:`flex.fidelity.error_estimate`) and two references of the same model at
``REFINEMENT`` and twice ``REFINEMENT`` times smaller steps. Per headline quantity it stores
on the case, as attributes:

- ``true_error_<q>``: |run - finest reference| [the quantity's units];
- ``reference_accuracy_<q>``: the finest reference's own error, Richardson from the two
  references (order of the integrator);
- ``estimate_ratio_<q>``: estimated / true error (1: exact; below 1: optimistic).

A pair is *judged* only where the true error is known (at least 3x the reference's
accuracy) and above the solver's noise floor (:data:`NOISE_FLOOR` of the quantity's
scale); the others are stored and said, not judged. :func:`estimate_summary` makes the
table, the verdicts against the targets (within a factor :data:`WITHIN`, never optimistic by
more than :data:`OPTIMISM`) and the figure data.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.plotting import figure
from flex.config.settings import resolve_solver_settings
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene, apply_overrides
from flex.fidelity.error_estimate import HEADLINES, PREFIX, integrator_order, richardson_error
from flex.fidelity.simulation import simulate_case

#: the references' steps are the run's divided by this and by twice this (order 2: the
#: finer reference is ~64x more accurate than the run where the run is asymptotic)
REFINEMENT = 4
#: targets: estimated / true within [1 / WITHIN, WITHIN], true / estimated at most OPTIMISM
WITHIN, OPTIMISM = 3.0, 1.5
#: below this fraction of a quantity's scale an error is solver noise (Newton tolerance)
NOISE_FLOOR = 1e-8
#: scale of each headline quantity for the noise floor: 1 rad, the slider travel ~0.1 m,
#: the peak deflection itself
_SCALES = {"crank_angle_end_rad": 1.0, "slider_position_end_m": 0.1}

Progress = Callable[[str, int, int], None]


def _run(scene: Scene, name: str, step_s: float | None, estimate: bool,
         cache_dir: Path | None) -> CaseResult:
    overrides = [f"simulation.error_estimate={'true' if estimate else 'false'}"]
    if step_s is not None:
        overrides += [f"simulation.step_s={step_s!r}", "simulation.output_step_s=0.0"]
    return simulate_case(apply_overrides(scene, overrides), name, cache_dir=cache_dir)


def check_one(name: str, scene: Scene, cache_dir: Path | None) -> CaseResult:
    """The run of ``scene`` with its estimate, compared with its two references (see the
    module doc); a failed run or reference makes a failed case."""
    run = _run(scene, name, None, True, cache_dir)
    if run.status != "ok":
        return run
    resolved, _ = resolve_solver_settings(scene)
    step = float(resolved["simulation"]["step_s"])
    fine = _run(resolved, f"{name}_ref", step / (2 * REFINEMENT), False, cache_dir)
    coarse = _run(resolved, f"{name}_ref", step / REFINEMENT, False, cache_dir)
    for reference in (fine, coarse):
        if reference.status != "ok":
            return CaseResult(name, run.scene_toml, status="failed",
                              message=f"reference failed: {reference.message}")
    order = integrator_order(resolved["simulation"])
    for quantity, (_, _, read) in HEADLINES.items():
        ours, best, other = (read(r.datasets) for r in (run, fine, coarse))
        if None in (ours, best, other) or f"{PREFIX}{quantity}" not in run.attrs:
            continue
        true = abs(ours - best)
        run.attrs[f"true_error_{quantity}"] = true
        run.attrs[f"reference_accuracy_{quantity}"] = richardson_error(
            best, other, step / (2 * REFINEMENT), step / REFINEMENT, order)
        run.attrs[f"estimate_ratio_{quantity}"] = (
            run.attrs[f"{PREFIX}{quantity}"] / true if true > 0 else float("inf"))
    return run


def check_estimates(scenes: Mapping[str, Scene], cache_dir: Path | None = None,
                    progress: Progress | None = None) -> dict[str, CaseResult]:
    """:func:`check_one` for every scene, in order."""
    results = {}
    for index, (name, scene) in enumerate(scenes.items()):
        if progress:
            progress(name, index, len(scenes))
        results[name] = check_one(name, scene, cache_dir)
    if progress:
        progress("done", len(scenes), len(scenes))
    return results


def _rows(results: Mapping[str, CaseResult]) -> list[dict[str, Any]]:
    """One row per (case, quantity) with an estimate and a true error."""
    rows = []
    for name, case in results.items():
        for quantity in HEADLINES:
            if f"true_error_{quantity}" not in case.attrs:
                continue
            estimated = float(case.attrs[f"{PREFIX}{quantity}"])
            true = float(case.attrs[f"true_error_{quantity}"])
            accuracy = float(case.attrs[f"reference_accuracy_{quantity}"])
            scale = _SCALES.get(quantity) or max(true, estimated)  # a peak: its own size
            known = true >= 3 * accuracy
            above_noise = max(true, estimated) > NOISE_FLOOR * scale
            asymptotic = str(case.attrs.get(f"{PREFIX}validity", "")).startswith("asymptotic")
            rows.append({"case": name, "quantity": quantity, "estimated": estimated,
                         "true": true, "reference_accuracy": accuracy,
                         "judged": known and above_noise, "asymptotic": asymptotic,
                         "why": "" if known and above_noise else
                         ("reference not accurate enough" if not known else "noise floor")})
    return rows


def estimate_summary(results: Mapping[str, CaseResult]) -> tuple[dict[str, Dataset], str]:
    """``/summary`` datasets (one entry per case and quantity) and the report."""
    rows = _rows(results)
    datasets: dict[str, Dataset] = {}
    columns = {"case": ("1", "case"), "quantity": ("1", "headline quantity (units in name)"),
               "estimated": ("see quantity", "estimated step error of the run"),
               "true": ("see quantity", "|run - finest reference|"),
               "reference_accuracy": ("see quantity", "the finest reference's own error"),
               "judged": ("1", "true error known and above the noise floor"),
               "asymptotic": ("1", "every time scale resolved (>= 10 steps per period)")}
    for key, (units, text) in columns.items():
        values = [row[key] for row in rows]
        data = np.array(values, dtype=object if isinstance(values[0], str) else None) \
            if values else np.array([])
        datasets[f"pairs/{key}"] = Dataset(data, units, text)
    ratio = np.array([r["estimated"] / r["true"] if r["true"] > 0 else np.inf for r in rows])
    datasets["pairs/ratio"] = Dataset(ratio, "1", "estimated / true (below 1: optimistic)")
    return datasets, _report(rows, ratio)


def _report(rows: list[dict[str, Any]], ratio: np.ndarray) -> str:
    judged = np.array([r["judged"] for r in rows], dtype=bool)
    lines = [f"error estimates: estimated against true step error ({len(rows)} pairs, "
             f"{int(judged.sum())} judged; target: within {WITHIN:g}x, never optimistic by "
             f"more than {OPTIMISM:g}x)"]
    for group, pick in (("asymptotic", [r["asymptotic"] for r in rows]),
                        ("under-resolved", [not r["asymptotic"] for r in rows])):
        chosen = judged & np.array(pick, dtype=bool)
        if chosen.any():
            within = np.mean((ratio[chosen] >= 1 / WITHIN) & (ratio[chosen] <= WITHIN))
            lines.append(f"  {group} runs: {int(chosen.sum())} pairs, {within:.0%} within "
                         f"{WITHIN:g}x, most optimistic true/estimated "
                         f"{1 / ratio[chosen].min():.3g}, most pessimistic "
                         f"{ratio[chosen].max():.3g}")
    lines.append(f"  {'case':24s} {'quantity':28s} {'estimated':>10s} {'true':>10s} "
                 f"{'ratio':>8s}  note")
    for row, value in zip(rows, ratio, strict=True):
        note = row["why"] or ("" if row["asymptotic"] else "under-resolved")
        lines.append(f"  {row['case']:24s} {row['quantity']:28s} {row['estimated']:10.3g} "
                     f"{row['true']:10.3g} {value:8.3g}  {note}")
    return "\n".join(lines)


def draw_estimates(datasets: Mapping[str, Dataset], folder: Path) -> list[Path]:
    """``estimates.png``: estimated against true step error, log-log, the factor-3 band and
    the 1.5x optimism line; judged pairs filled, by validity."""
    if "pairs/true" not in datasets or not len(datasets["pairs/true"].data):
        return []
    true = np.asarray(datasets["pairs/true"].data, dtype=float)
    estimated = np.asarray(datasets["pairs/estimated"].data, dtype=float)
    judged = np.asarray(datasets["pairs/judged"].data, dtype=bool)
    asymptotic = np.asarray(datasets["pairs/asymptotic"].data, dtype=bool)
    path = folder / "estimates.png"
    with figure(path, "Estimated against true step error of each headline quantity (log-log)",
                "true error [rad or m]", "estimated error [rad or m]", size=(6.8, 6.0)) as ax:
        positive = (true > 0) & (estimated > 0)
        low = float(min(true[positive].min(), estimated[positive].min())) / 3
        high = float(max(true[positive].max(), estimated[positive].max())) * 3
        line = np.array([low, high])
        ax.fill_between(line, line / WITHIN, line * WITHIN, color="0.9",
                        label=f"within {WITHIN:g}x")
        ax.plot(line, line, color="0.4", lw=1, label="estimated = true")
        ax.plot(line, line / OPTIMISM, color="tab:red", ls=":", lw=1,
                label=f"optimistic by {OPTIMISM:g}x")
        for pick, style, label in (
                (judged & asymptotic, dict(marker="o", color="tab:blue"), "judged, asymptotic"),
                (judged & ~asymptotic, dict(marker="s", color="tab:orange"),
                 "judged, under-resolved modes"),
                (~judged, dict(marker="x", color="0.5"), "not judged (reference or noise)")):
            pick = pick & positive
            if pick.any():
                ax.plot(true[pick], estimated[pick], ls="none", label=label, **style)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(low, high)
        ax.set_ylim(low, high)
    return [path]
