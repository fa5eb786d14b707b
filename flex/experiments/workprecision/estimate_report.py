"""What the ``estimates`` study shows a reviewer: its findings in short Markdown, its tables
as data (:func:`flex.data.tables.findings_table`) and a figure per headline quantity.

:func:`estimate_findings` makes, from the pairs of
:func:`flex.experiments.workprecision.estimate_check.pair_rows`, the verdicts in a few bullets
and four findings tables: per quantity (pairs, judged, within the target, the range of true /
estimated), the certificates a known true error exceeds, every pair (short cells: the note a
few words) and each scene's reference. :func:`draw_ratio_figures` draws
``estimates-ratio-<quantity>.png``: true / estimated error of that quantity per scene, log
scale, the target band [1 / PESSIMISM, OPTIMISM] shaded.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.plotting import figure, legend_below
from flex.data.results import CaseResult, Dataset
from flex.data.tables import findings_table
from flex.experiments.workprecision.estimate_check import (
    FLAGGED_SHARE,
    OPTIMISM,
    PESSIMISM,
    pair_rows,
    verdicts,
)

#: a pair's note in a few words (the why of :func:`pair_rows`, by its first words)
SHORT_NOTES = {"every run agrees": "exact agreement",
               "reference not accurate": "reference too coarse",
               "noise floor": "below the noise floor", "a bound": "a bound, not judged",
               "flagged": "flagged (not asymptotic)"}
UNIT = "quantity's unit"
QUANTITY_COLUMNS = {
    "quantity": ("1", "headline quantity (its unit at the end of its name)"),
    "pairs": ("1", "scenes with an estimate and a true error", int),
    "judged": ("1", "pairs judged: true error known, above the noise floor, not flagged", int),
    "within": ("1", "judged pairs with true / estimated inside the target", int),
    "lowest": ("1", "smallest true / estimated of the judged pairs (pessimistic)", float),
    "highest": ("1", "largest true / estimated of the judged pairs (optimistic)", float)}
PAIR_COLUMNS = {
    "case": ("1", "scene"), "quantity": ("1", "headline quantity"),
    "estimated": (UNIT, "the run's estimated error (its budget's total)"),
    "true": (UNIT, "|run - reference|"),
    "ratio": ("1", "true / estimated (above 1: optimistic)"),
    "term": ("1", "the budget's largest term"),
    "note": ("1", "why the pair is not judged, or that it is outside the target")}
EXCEEDED_COLUMNS = {"case": ("1", "scene"), "quantity": ("1", "headline quantity"),
                    "true": (UNIT, "|run - reference|"),
                    "certificate": (UNIT, "the run's certificate (estimate x its factor)")}
REFERENCE_COLUMNS = {"case": ("1", "scene"),
                     "reference": ("1", "the next rung of the ladder the run is held against")}


def short_note(row: Mapping[str, Any], ratio: float) -> str:
    """A pair's note in a few words: why it is not judged, or ``outside`` the target; ``model
    unchecked`` where no higher rung computes the quantity."""
    why = str(row["why"])
    note = next((short for start, short in SHORT_NOTES.items() if why.startswith(start)), why)
    if not why and not 1 / PESSIMISM <= ratio <= OPTIMISM:
        note = "**outside**"
    return note + ("; model unchecked" if row["same_model"] else "")


def _quantity_rows(rows: list[dict[str, Any]], ratio: np.ndarray, found: Mapping[str, Any]
                   ) -> list[dict[str, Any]]:
    out = []
    for quantity in dict.fromkeys(row["quantity"] for row in rows):
        mine = np.array([row["quantity"] == quantity for row in rows])
        judged = mine & found["judged"]
        out.append({"quantity": quantity, "pairs": int(mine.sum()), "judged": int(judged.sum()),
                    "within": int((judged & found["inside"]).sum()),
                    "lowest": float(ratio[judged].min()) if judged.any() else np.nan,
                    "highest": float(ratio[judged].max()) if judged.any() else np.nan})
    return out


def _bullets(rows: list[dict[str, Any]], ratio: np.ndarray, found: Mapping[str, Any]
             ) -> list[str]:
    judged, flagged = found["judged"], found["flagged"]
    within = [scene for scene, flags in found["by_scene"].items() if all(flags)]
    lines = [f"- judged pairs within the target: {int((found['inside'] & judged).sum())} of "
             f"{int(judged.sum())}; scenes with every judged pair within: {len(within)} of "
             f"{len(found['by_scene'])}",
             f"- flagged outside the asymptotic range: {int(flagged.sum())} of {len(rows)} pairs "
             f"({100 * flagged.mean() if rows else 0:.0f} %; target at most "
             f"{100 * FLAGGED_SHARE:g} %)",
             f"- certificates exceeded by a known true error: {len(found['exceeded'])}",
             _not_judged_line(rows)]
    if found["bound"].any():
        spread = found["spread"]
        lines.append(f"- bounds (raw peaks: checked against their certificates, not "
                     f"judged): {int(found['bound'].sum())} pairs, "
                     f"{len(found['known_bounds'])} with a known true error"
                     + (f", true / bound {min(spread):.2g} to {max(spread):.2g}" if spread
                        else ""))
    if judged.any():
        lines.append(f"- true / estimated of the judged pairs: {ratio[judged].min():.3g} (most "
                     f"pessimistic) to {ratio[judged].max():.3g} (most optimistic)")
    return lines


def _not_judged_line(rows: list[dict[str, Any]]) -> str:
    """How many pairs are not judged, by why (:func:`pair_rows`' why, in few words); the
    references too coarse to decide the band or the certificate first (a target: none)."""
    counts: dict[str, int] = {}
    for row in rows:
        if row["why"]:
            note = short_note(row, 1.0).removesuffix("; model unchecked")
            note += " (a certificate)" if "certificate" in str(row["why"]) and \
                "reference" in str(row["why"]) else ""
            counts[note] = counts.get(note, 0) + 1
    coarse = sum(n for note, n in counts.items() if note.startswith("reference too coarse"))
    return (f"- reference not accurate enough to decide: {coarse} of {len(rows)} pairs (target: "
            f"none); every pair not judged, by why: "
            + ", ".join(f"{note} {n}" for note, n in sorted(counts.items(),
                                                            key=lambda item: -item[1])))


def estimate_findings(results: Mapping[str, CaseResult]) -> tuple[dict[str, Dataset], str]:
    """The findings tables (datasets under ``findings/``) and the findings (Markdown) of the
    estimates study's ``results`` (cases with ``true_error_*`` attributes)."""
    rows = pair_rows(results)
    ratio = np.array([r["true"] / r["estimated"] if r["estimated"] > 0 else np.inf
                      for r in rows])
    found = verdicts(rows, ratio)
    pairs = [{"case": r["case"], "quantity": r["quantity"], "estimated": r["estimated"],
              "true": r["true"], "ratio": float(value), "term": r["largest_term"],
              "note": short_note(r, float(value))} for r, value in zip(rows, ratio, strict=True)]
    references = [{"case": name, "reference": str(case.attrs["reference"])}
                  for name, case in results.items() if case.attrs.get("reference")]
    datasets = {
        **findings_table("quantities", "Per headline quantity", _quantity_rows(rows, ratio, found),
                         QUANTITY_COLUMNS, 0, {"lowest": "lowest true / estimated",
                                               "highest": "highest true / estimated"}),
        **findings_table("exceeded", "Certificates exceeded by a known true error",
                         [{key: r[key] for key in EXCEEDED_COLUMNS} for r in found["exceeded"]],
                         EXCEEDED_COLUMNS, 1),
        **findings_table("pairs", "Every pair (scene, quantity)", pairs, PAIR_COLUMNS, 2,
                         {"ratio": "true / estimated", "term": "largest term"}),
        **findings_table("references", "The reference of each scene", references,
                         REFERENCE_COLUMNS, 3)}
    text = [f"Error budgets: the stored total against the true error, {len(rows)} pairs "
            f"(scene, headline quantity) on {len(results)} scenes. Targets: true / estimated "
            f"within [1/{PESSIMISM:g}, {OPTIMISM:g}] for the judged pairs, at most "
            f"{100 * FLAGGED_SHARE:g} % of the pairs flagged, no certificate exceeded.", "",
            *_bullets(rows, ratio, found), "",
            "Figures: true / estimated per scene, one per quantity "
            "(`estimates-ratio-<quantity>.png`), and every pair against its estimate "
            "(`estimates-pairs.png`).", ""]
    return datasets, "\n".join(text)


def draw_ratio_figures(datasets: Mapping[str, Dataset], folder: Path) -> list[Path]:
    """``estimates-ratio-<quantity>.png`` per headline quantity of the ``pairs/*`` columns
    (:func:`flex.experiments.workprecision.estimate_check.estimate_summary`): true /
    estimated error per scene [-], log scale, the target band shaded; judged pairs filled,
    the others open; a pair with no finite ratio (true or estimated error 0) is named on its
    scene's label instead."""
    if "pairs/true" not in datasets or not len(datasets["pairs/true"].data):
        return []
    case = [str(v) for v in datasets["pairs/case"].data]
    quantity = [str(v) for v in datasets["pairs/quantity"].data]
    true = np.asarray(datasets["pairs/true"].data, dtype=float)
    estimated = np.asarray(datasets["pairs/estimated"].data, dtype=float)
    judged = np.asarray(datasets["pairs/judged"].data, dtype=bool)
    paths = []
    for name in dict.fromkeys(quantity):
        rows = [i for i, q in enumerate(quantity) if q == name]
        paths.append(_ratio_figure(folder / f"estimates-ratio-{name}.png", name,
                                   [case[i] for i in rows], true[rows], estimated[rows],
                                   judged[rows]))
    return paths


def _ratio_figure(path: Path, quantity: str, scenes: list[str], true: np.ndarray,
                  estimated: np.ndarray, judged: np.ndarray) -> Path:
    """One quantity's figure (:func:`draw_ratio_figures`)."""
    drawn = (true > 0) & (estimated > 0)
    ratio = np.where(drawn, true / np.where(estimated > 0, estimated, 1.0), np.nan)
    labels = [scene if ok else f"{scene} ({'true 0' if t == 0 else 'estimate 0'})"
              for scene, ok, t in zip(scenes, drawn, true, strict=True)]
    at = np.arange(len(scenes))[::-1]  # the first scene on top
    low = min(0.3, np.nanmin(ratio, initial=1.0) / 2)
    high = max(3.0, np.nanmax(ratio, initial=1.0) * 2)
    with figure(path, f"True / estimated error of {quantity} per scene (target band shaded)",
                "true / estimated error [-] (log scale; above 1: the estimate is optimistic)",
                "scene", size=(7.5, max(3.0, 1.6 + 0.3 * len(scenes)))) as ax:
        ax.axvspan(1 / PESSIMISM, OPTIMISM, color="0.88",
                   label=f"target [1/{PESSIMISM:g}, {OPTIMISM:g}]")
        ax.axvline(1.0, color="0.4", lw=1, label="true = estimated")
        for pick, style, label in ((drawn & judged, {"marker": "o", "color": "tab:blue"},
                                    "judged"),
                                   (drawn & ~judged, {"marker": "o", "mfc": "none",
                                                      "color": "0.45"},
                                    "not judged (reference, noise, bound or flagged)")):
            if pick.any():
                ax.plot(ratio[pick], at[pick], ls="none", label=label, **style)
        ax.set_xscale("log")
        ax.set_xlim(low, high)
        ax.set_yticks(at, labels, fontsize="small")
        ax.set_ylim(-0.7, len(scenes) - 0.3)
        legend_below(ax.figure)
    return path
