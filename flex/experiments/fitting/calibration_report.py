"""Report, summary datasets and figures of the FFRF rule's calibration (``make calibrate``).

:func:`calibration_summary` fits the rule on the calibration scenes
(:func:`flex.experiments.fitting.calibration.fit_levels`), validates it on the others
(:func:`flex.experiments.fitting.calibration.validate`) and returns the datasets stored under
``/summary`` (``rule/toml``: the constants to install, ``levels/*``, ``validation/*``) and
the report text; :func:`draw_calibration` draws one work-precision panel per scene with the
rule's picks marked on the Pareto front of the grid.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.plotting import legend_below, log_ticks, panels
from flex.config.ffrf_rule import (
    holds_at,
    level_modes,
    rule_constants,
    steps_per_first_period,
    top_mode_ratio,
)
from flex.data.results import CaseResult, Dataset
from flex.data.scene import Scene
from flex.data.tables import findings_table, table_datasets
from flex.experiments.fitting.calibration import (
    LEVELS,
    MARGIN,
    SLOWDOWN_LIMIT,
    carried_levels,
    coupler_of,
    cross_validate,
    damping_of,
    family_bounds,
    fit_levels,
    grid_table,
    n_load_of,
    rule_toml,
    validate,
    widened_bounds,
)
from flex.experiments.fitting.rule_designs import TWIN_CLOSENESS, design_frontier, near_twins
from flex.experiments.workprecision.pareto import pareto_front


def calibration_summary(results: Mapping[str, CaseResult], calibration: Mapping[str, Scene],
                        validation: Mapping[str, Scene]) -> tuple[dict[str, Dataset], str]:
    """Fit on ``calibration``'s cases, validate on ``validation``'s (see module doc)."""
    fitted = fit_levels({name: results[name] for name in calibration if name in results})
    installed = rule_constants()
    carried = carried_levels(fitted, installed["levels"])
    bounds = family_bounds(calibration)
    if carried:
        bounds = widened_bounds(bounds, installed["family"])
    rows = validate({name: results[name] for name in validation if name in results}, fitted,
                    bounds)
    in_sample = validate({name: results[name] for name in calibration if name in results},
                         fitted)
    left_out = cross_validate({name: results[name] for name in calibration
                               if name in results})
    family = _within_family(results, {**calibration, **validation}, bounds)
    designs = design_frontier(family)
    twins = [{**row, "tolerance": level} for level in LEVELS for row in near_twins(family, level)]
    toml = rule_toml([*fitted, *carried], bounds, installed["mesh"])
    datasets = {"rule/toml": Dataset(toml, "1", "the rule's constants (make calibration-install)")}
    for index, level in enumerate(fitted):
        prefix = f"levels/{index}"
        datasets[f"{prefix}/damping"] = Dataset(level["damping"], "1", "damping class")
        datasets[f"{prefix}/tolerance"] = Dataset(level["tolerance"], "1", "level")
        datasets[f"{prefix}/modes"] = Dataset(level.get("modes") or -1, "1",
                                              "most in-plane modes a calibration scene got "
                                              "(-1: not calibrated)")
        datasets[f"{prefix}/steps_per_top_period"] = Dataset(
            level.get("steps_per_top_period", math.nan), "1",
            "steps per period of the highest retained mode, at least")
        datasets[f"{prefix}/mode_cutoff_ratio"] = Dataset(
            level.get("mode_cutoff_ratio", math.nan), "1",
            "in-plane modes kept up to this multiple of the first")
        datasets[f"{prefix}/mode_cutoff_load"] = Dataset(
            level.get("mode_cutoff_load", math.nan), "1",
            "and up to this multiple of 2 pi / t_load (cut-off max(ratio, this / n))")
        for end in ("min", "max"):
            datasets[f"{prefix}/n_load_{end}"] = Dataset(
                level.get(f"n_load_{end}", math.nan), "1",
                f"{end}imum n = t_load / T1 of the level's calibration scenes")
        datasets[f"{prefix}/steps_coefficient"] = Dataset(
            level.get("steps_coefficient", math.nan), "1", "C of N = C n^-B")
        datasets[f"{prefix}/steps_exponent"] = Dataset(
            level.get("steps_exponent", math.nan), "1", "B of N = C n^-B")
        datasets[f"{prefix}/worst_error"] = Dataset(level.get("worst_error", math.nan), "1",
                                                    "largest certified calibration error")
    datasets.update(_row_datasets("validation", rows))
    datasets.update(_row_datasets("cross_validation", left_out))
    datasets.update(_design_datasets(designs))
    datasets.update(_twin_datasets(twins))
    carried_classes = {level["damping"] for level in carried}
    levels = [*(level for level in fitted if level.get("modes") is not None
                or level["damping"] not in carried_classes), *carried]
    moved = moved_rows(installed["levels"], levels)
    datasets.update(findings_table("moved", "The rule refitted: what moved", moved,
                                   MOVED_COLUMNS, order=1))
    datasets.update(findings_table("levels", "Refitted levels", _level_rows(levels),
                                   LEVEL_COLUMNS, order=2))
    return datasets, _report(results, levels, rows, toml, in_sample, left_out,
                             [*_design_lines(designs), *_twin_lines(twins)])


#: the refitted levels' table (:func:`_level_rows`)
LEVEL_COLUMNS = {"damping": ("1", "damping class", object),
                 "tolerance": ("1", "level (relative error of the deployment peak)"),
                 "source": ("1", "refitted on stored references, or carried from the "
                                 "installed rule", object),
                 "scenes": ("1", "scenes the level rests on"),
                 "n_range": ("1", "n = t_load / T1 it holds over", object),
                 "modes": ("1", "most in-plane modes a scene gets (0: not calibrated)"),
                 "steps_law": ("1", "steps per first period, N = C n^-B", object),
                 "worst_error": ("1", "largest certified calibration error")}


def _level_rows(levels: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    rows = []
    for level in levels:
        fitted = level.get("modes") is not None
        rows.append({
            "damping": level["damping"], "tolerance": level["tolerance"],
            "source": "carried" if level.get("carried") else
            ("refitted" if fitted else f"not calibrated: {level.get('reason', '')}"),
            "scenes": len(level.get("scenes", ())),
            "n_range": (f"{level['n_load_min']:.3g}-{level['n_load_max']:.3g}" if fitted
                        else ""),
            "modes": level.get("modes") or 0,
            "steps_law": (f"{level['steps_coefficient']:.3g} n^-{level['steps_exponent']:.2f}"
                          if fitted else ""),
            "worst_error": level.get("worst_error", math.nan)})
    return rows


#: the "what moved" table (:func:`moved_rows`)
MOVED_COLUMNS = {"damping": ("1", "damping class", object),
                 "tolerance": ("1", "level"),
                 "before": ("1", "the installed level: modes, steps law, n range", object),
                 "after": ("1", "the refitted level", object),
                 "worst_error_before": ("1", "its largest certified calibration error"),
                 "worst_error_after": ("1", "the refit's")}


def moved_rows(installed: Sequence[Mapping[str, Any]], refitted: Sequence[Mapping[str, Any]]
               ) -> list[dict[str, Any]]:
    """Per (damping, level) in either rule: the installed level against the refitted one,
    in words (a level only one of them calibrates: "none")."""
    def text(level: Mapping[str, Any] | None) -> str:
        if level is None or level.get("modes", level.get("modes_max")) is None:
            return "none"
        return (f"{level.get('modes', level.get('modes_max'))} modes max (cut-off "
                f"{level['mode_cutoff_ratio']:g} x f1), N = {level['steps_coefficient']:.3g} "
                f"n^-{level['steps_exponent']:.2f}, n {level['n_load_min']:.3g}-"
                f"{level['n_load_max']:.3g}")

    def key(level: Mapping[str, Any]) -> tuple[str, float]:
        return (level.get("damping", "undamped"), float(level["tolerance"]))

    before = {key(level): level for level in installed}
    after = {key(level): level for level in refitted if level.get("modes") is not None}
    return [{"damping": damping, "tolerance": tolerance,
             "before": text(before.get((damping, tolerance))),
             "after": text(after.get((damping, tolerance))),
             "worst_error_before": before.get((damping, tolerance), {}).get("worst_error",
                                                                           math.nan),
             "worst_error_after": after.get((damping, tolerance), {}).get("worst_error",
                                                                         math.nan)}
            for damping, tolerance in sorted(before.keys() | after.keys())]


def _within_family(results: Mapping[str, CaseResult], scenes: Mapping[str, Scene],
                   bounds: Mapping[str, float]) -> dict[str, CaseResult]:
    """The measured cases of ``scenes`` whose coupler's slenderness lies within ``bounds``."""
    def inside(scene: Scene) -> bool:
        slenderness = scene["coupler"]["length_m"] / scene["coupler"]["thickness_m"]
        return bounds["slenderness_min"] <= slenderness <= bounds["slenderness_max"]

    return {name: results[name] for name, scene in scenes.items()
            if name in results and inside(scene)}


#: the columns of the rule designs' comparison (flex.experiments.fitting.rule_designs)
DESIGN_COLUMNS = (("judged", "pairs"), ("no_pick", "no pick"),
                  ("over_level", "over the level"), ("not_robust", "not robustly within"),
                  ("slower", f"robust, > {SLOWDOWN_LIMIT:g}x slower"),
                  ("meets", "meet the target"))


def _design_datasets(designs: Sequence[Mapping[str, Any]]) -> dict[str, Dataset]:
    """:func:`flex.experiments.fitting.rule_designs.design_frontier`'s tallies as
    ``design_frontier/*``."""
    columns = {key: ("1", f"(scene, level) pairs: {text}") for key, text in DESIGN_COLUMNS}
    columns |= {"design": ("1", "rule design", object),
                "worst_ratio": ("1", "largest certified error of a pick / its level")}
    return table_datasets(designs, columns, "design_frontier")


#: ``near_twins/<column>``: one row per pair of near twins (:func:`_twin_datasets`)
TWIN_COLUMNS = {"scene_a": ("1", "first scene of the pair", object),
                "scene_b": ("1", "second scene", object),
                "tolerance": ("1", "level"),
                "slowdown": ("1", "least worse-of-the-two modelled slowdown of a grid pair "
                                  "robust on both (inf: none)")}


def _twin_datasets(twins: Sequence[Mapping[str, Any]]) -> dict[str, Dataset]:
    """:func:`flex.experiments.fitting.rule_designs.near_twins`' rows as ``near_twins/*``."""
    return table_datasets(({"scene_a": row["scenes"][0], "scene_b": row["scenes"][1], **row}
                           for row in twins), TWIN_COLUMNS, "near_twins")


def _twin_lines(twins: Sequence[Mapping[str, Any]]) -> list[str]:
    """The near twins in a few lines: how many, and those one setting cannot serve within
    the slowdown limit."""
    apart = [row for row in twins if row["slowdown"] > SLOWDOWN_LIMIT]
    lines = ["", f"Near twins (same damping class, n and L / t within "
             f"{TWIN_CLOSENESS:.0%} of each other, where a rule of (n, L / t) gives nearly "
             f"the same settings): {len(twins)} (scene, scene, level) triples; "
             f"{len(apart)} of them no grid pair serves both within their level at most "
             f"{SLOWDOWN_LIMIT:g}x slower than each one's fastest (modelled times)"
             + (":" if apart else ".")]
    if apart:
        lines.append("")
    for row in apart:
        lines.append(f"- {row['scenes'][0]} and {row['scenes'][1]} at {row['tolerance']:g}: "
                     f"{row['shared_pair'] or 'no shared pair'}, {row['slowdown']:.2g}x "
                     f"slower on one of them")
    return lines


def _design_lines(designs: Sequence[Mapping[str, Any]]) -> list[str]:
    """The rule designs' comparison: a table and what it shows."""
    if not designs:
        return []
    scenes = {row["scene"] for row in designs[0]["rows"]}
    lines = ["", "## Rule designs compared (leave-one-out over every measured scene)", "",
             "Each calibration and validation scene in turn is left out, and each design, "
             "built from the others, picks its settings (`flex.experiments.fitting.rule_designs`). "
             f"Every design is judged on the same {len(designs[0]['rows'])} (scene, level) "
             f"pairs, from {len(scenes)} scenes. The validation scenes are spent here only "
             "for comparing designs, not for choosing the installed one. A design with no "
             "pick falls back, visibly.", "",
             "| design | " + " | ".join(text for _, text in DESIGN_COLUMNS)
             + " | worst error / level |",
             "|---|" + "---|" * (len(DESIGN_COLUMNS) + 1)]
    for row in designs:
        lines.append(f"| {row['design']} | "
                     + " | ".join(str(row[key]) for key, _ in DESIGN_COLUMNS)
                     + f" | {row['worst_ratio']:.2g} |")
    safe = [row for row in designs if row["over_level"] == 0]
    fastest = max(designs, key=lambda row: row["meets"])
    if safe:
        best_safe = max(safe, key=lambda row: row["meets"])
        lines += ["", f"Of the designs whose every pick keeps its left-out pair within the "
                  f"level, the best meets the target on {best_safe['meets']} of "
                  f"{best_safe['judged']} pairs ({best_safe['design']})."]
    else:
        lines += ["", "Every design puts some left-out pair over its level."]
    lines.append(f"The most pairs meeting the target: {fastest['meets']} of "
                 f"{fastest['judged']} ({fastest['design']}), with {fastest['over_level']} "
                 f"over the level (worst {fastest['worst_ratio']:.2g} x).")
    return lines


#: ``<group>/<column>``: one row per judged (scene, level) pair (:func:`_row_datasets`)
JUDGED_COLUMNS = {"rule_error": ("1", "certified error of the rule's pick"),
                  "rule_time_s": ("s", "time of the rule's pick"),
                  "best_time_s": ("s", "fastest grid pair within the level"),
                  "slowdown": ("1", "rule / fastest"),
                  "tolerance": ("1", "level"),
                  "certifiable": ("1", "the scene's reference can certify the level"),
                  "meets": ("1", "within the level and the slowdown limit"),
                  "scene": ("1", "scene", object)}


def _row_datasets(group: str, rows: Sequence[Mapping[str, Any]]) -> dict[str, Dataset]:
    """The judged rows of :func:`flex.experiments.fitting.calibration.validate` as ``group/*``."""
    judged = [row for row in rows if "failed" not in row and "outside" not in row]
    return table_datasets(judged, JUDGED_COLUMNS, group)


def _report(results: Mapping[str, CaseResult], fitted: Sequence[Mapping[str, Any]],
            rows: Sequence[Mapping[str, Any]], toml: str,
            in_sample: Sequence[Mapping[str, Any]] = (),
            left_out: Sequence[Mapping[str, Any]] = (), comparison: Sequence[str] = ()
            ) -> str:
    lines = ["# FFRF settings rule: calibration and validation", "",
             "Error: relative error of the elastic midpoint deflection's deployment peak (on "
             "the headline channel) against the stored reference of each scene's physics "
             "(make references), plus the reference's own accuracy (certified). "
             f"A level is fitted on the calibration scenes whose reference can certify it, "
             f"within {MARGIN:g} x the level on every one.", "",
             "## References", "", "| scene | first period T1 [s] | reference accuracy | "
             "peak deflection [m] |", "|---|---|---|---|"]
    for name, case in results.items():
        if case.status != "ok":
            lines.append(f"| {name} | failed: {case.message[:120]} | | |")
            continue
        lines.append(f"| {name} | {case.attrs['first_period_s']:.3g} | "
                     f"{case.attrs['reference_accuracy']:.2g} | "
                     f"{case.attrs['reference_peak_deflection_m']:.4g} |")
    lines += ["", "## Fitted levels", ""]
    for level in fitted:
        if level.get("modes") is None:
            lines.append(f"- {level['damping']}, {level['tolerance']:g}: not calibrated "
                         f"({level['reason']}; "
                         f"scenes: {', '.join(level['scenes']) or 'none'})"
                         + _beyond_text(level))
            continue
        lines.append(f"- {level['damping']}, {level['tolerance']:g}, for n = t_load / T1 in "
                     f"[{level['n_load_min']:.3g}, {level['n_load_max']:.3g}]: in-plane modes "
                     f"up to max({level['mode_cutoff_ratio']:g}, "
                     f"{level['mode_cutoff_load']:g} / n) x the first (at most "
                     f"{level['modes']} on these scenes), N = {level['steps_coefficient']:.3g} "
                     f"n^-"
                     f"{level['steps_exponent']:.2f} steps per first period and at least "
                     f"{level['steps_per_top_period']:g} per period of the highest retained "
                     f"mode (rounded up to the grid); worst certified error "
                     f"{level['worst_error']:.2g} over "
                     f"{len(level['scenes'])} scenes ({', '.join(level['scenes'])})"
                     + _beyond_text(level)
                     + ("; carried from the installed rule, not refitted" if level.get("carried")
                        else ""))
    lines += ["", "## Validation (scenes not used in the fit)", "",
              "| scene | n = t_load / T1 | level | certifiable | rule pick | rule error | rule "
              "time [s] | fastest within [s] (pair) | slowdown | meets |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        if "failed" in row or "outside" in row:
            why = f"failed: {row['failed'][:100]}" if "failed" in row else row["outside"]
            lines.append(f"| {row['scene']} | {why} | | | | | | | | |")
            continue
        lines.append(f"| {row['scene']} | {row['n_load']:.3g} | {row['tolerance']:g} | "
                     f"{row['certifiable']} | {row['rule_pair']} | "
                     f"{row['rule_error']:.2g} | {row['rule_time_s']:.3g} | "
                     f"{row['best_time_s']:.3g} ({row['best_pair'] or 'none'}) | "
                     f"{row['slowdown']:.2g} | {row['meets']} |")
    lines += _target_lines([*rows, *({**row, "scene": f"{row['scene']} (calibration)"}
                                     for row in in_sample)])
    lines += ["", f"Validation: {_tally(_certifiable_rows(rows))}.",
              *_cross_lines(left_out), *comparison,
              "", "## Rule constants (make calibration-install)", "", "```toml",
              toml.strip(), "```"]
    return "\n".join(lines)


def _certifiable_rows(rows: Sequence[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """The judged rows of :func:`flex.experiments.fitting.calibration.validate` whose reference can
    certify their level."""
    return [row for row in rows if "failed" not in row and "outside" not in row
            and row["certifiable"]]


def _tally(judged: Sequence[Mapping[str, Any]]) -> str:
    """How many certifiable pairs meet the target, and how many are within their level."""
    within = [row for row in judged if row["rule_error"] <= row["tolerance"]]
    worst = max((row["rule_error"] / row["tolerance"] for row in judged), default=math.nan)
    return (f"{sum(row['meets'] for row in judged)} of {len(judged)} certifiable (scene, "
            f"level) pairs meet their level at most {SLOWDOWN_LIMIT:g}x slower than the "
            f"fastest grid pair; {len(within)} of {len(judged)} within their level (worst "
            f"{worst:.2g} x the level)")


def _cross_lines(rows: Sequence[Mapping[str, Any]]) -> list[str]:
    """The leave-one-out cross-validation in a few lines: counts and the misses."""
    judged = _certifiable_rows(rows)
    if not judged:
        return []
    misses = [f"{row['scene']} at {row['tolerance']:g}: {row['rule_pair']}, error "
              f"{row['rule_error'] / row['tolerance']:.2g} x the level, {row['slowdown']:.2g}x "
              f"slower" for row in judged if not row["meets"]]
    return ["", "## Cross-validation (each calibration scene left out of the fit in turn)", "",
            f"{_tally(judged)}. The misses:", "", *(f"- {miss}" for miss in misses)]


#: issue 15's time targets for the rule's picks [s] per level (in process, warm reduction)
TIME_TARGETS_S = {0.01: 0.3, 0.001: 2.0}


def _target_lines(rows: Sequence[Mapping[str, Any]]) -> list[str]:
    """The rule's picks against the time targets, per validation scene and level."""
    lines = ["", "Time targets (in process, reduction in memory; "
             + ", ".join(f"{level:g}: at most {limit:g} s" for level, limit in
                         TIME_TARGETS_S.items()) + "):", ""]
    for row in rows:
        if "failed" in row or "outside" in row or row["tolerance"] not in TIME_TARGETS_S:
            continue
        limit = TIME_TARGETS_S[row["tolerance"]]
        verdict = "met" if row["rule_time_s"] <= limit else "missed"
        lines.append(f"- {row['scene']} at {row['tolerance']:g}: {row['rule_time_s']:.3g} s "
                     f"({verdict}), certified error {row['rule_error']:.2g}")
    return lines


def _beyond_text(level: Mapping[str, Any]) -> str:
    """The level's certifiable scenes outside its n range (no grid pair meets one of them,
    :func:`flex.experiments.fitting.calibration.reachable_run`)."""
    beyond = level.get("beyond_grid") or []
    return (f"; left out, the grid cannot meet the level on, or beyond, "
            f"{', '.join(beyond)}" if beyond else "")


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def draw_calibration(results: Mapping[str, CaseResult], datasets: Mapping[str, Dataset],
                     folder: Path) -> list[Path]:
    """``calibrate-work-precision.png``: per scene, certified error against time of every
    grid pair (log-log), the grid's Pareto front, the levels, and the rule's picks for the
    scene's damping class (from the fitted ``levels/*`` summary datasets)."""
    cases = {name: case for name, case in results.items() if case.status == "ok"}
    if not cases:
        return []
    levels = fitted_levels(datasets)
    family = tomllib.loads(_text(datasets["rule/toml"].data))["family"] \
        if "rule/toml" in datasets else {}
    cols = 4
    rows = math.ceil(len(cases) / cols)
    path = folder / "calibrate-work-precision.png"
    with panels(path, "FFRF grid per scene: certified error of the peak deflection against "
                "run time; Pareto front (line), levels (dotted), the rule's picks (stars)",
                rows, cols, size=(13.0, 1.6 + 2.6 * rows)) as (fig, axes):
        for ax, (name, case) in zip(axes, cases.items(), strict=False):
            coupler = coupler_of(case)
            n_load = n_load_of(case)
            slender = coupler["length_m"] / coupler["thickness_m"]
            inside = family.get("slenderness_min", 0.0) <= slender <= family.get(
                "slenderness_max", math.inf)
            picks = {} if not inside else {level["tolerance"]: (level_modes(level, coupler, n_load),
                                          steps_per_first_period(level, n_load, top_mode_ratio(
                                              level, coupler, n_load)))
                     for level in levels
                     if level["damping"] == damping_of(case)
                     and holds_at(level, n_load)}
            _panel(ax, name, grid_table(case), sorted({lv["tolerance"] for lv in levels}),
                   picks)
        for ax in axes[len(cases):]:
            ax.set_visible(False)
        legend_below(fig, ncol=6)
    return [path]


def _panel(ax: Any, name: str, table: Mapping[str, np.ndarray], levels: Sequence[float],
           picks: Mapping[float, tuple[int, float | None]]) -> None:
    time, error = table["total_time"], table["certified"]
    ok = np.isfinite(time) & np.isfinite(error) & (error > 0)
    ax.set_title(name, fontsize="small")
    if not ok.any():  # every grid run failed (a deflection beyond the linear FFRF body's)
        ax.text(0.5, 0.5, "no grid run finished", ha="center", va="center",
                transform=ax.transAxes, fontsize="small")
        ax.set_xticks([])
        ax.set_yticks([])
        return
    for modes, marker in zip((1, 2, 4, 8), "o^sD", strict=False):
        chosen = ok & (table["modes"] == modes)
        ax.plot(time[chosen], error[chosen], marker, ms=3, ls="none", label=f"{modes} modes")
    front = pareto_front(list(zip(time[ok], error[ok], strict=True)))
    ax.plot(time[ok][front], error[ok][front], color="0.3", lw=1)
    for level in levels:
        ax.axhline(level, color="tab:red", lw=0.8, ls=":")
    for level, (modes, per) in picks.items():
        index = np.flatnonzero((table["modes"] == modes)
                               & np.isclose(table["steps_per_first_period"], per or -1))
        if index.size and ok[index[0]]:
            ax.plot(time[index[0]], error[index[0]], "*", ms=11, color="tab:red",
                    label=f"rule's pick at {level:g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    log_ticks(ax, "x")
    log_ticks(ax, "y")
    ax.set_xlabel("run time [s]")
    ax.set_ylabel("certified error [1]")


def fitted_levels(datasets: Mapping[str, Dataset]) -> list[dict[str, Any]]:
    """The calibrated levels (damping, tolerance, modes, steps law) from the summary."""
    out = []
    index = 0
    while f"levels/{index}/tolerance" in datasets:
        def value(key: str, at: int = index) -> Any:
            data = datasets[f"levels/{at}/{key}"].data
            return data.decode() if isinstance(data, bytes) else data
        if int(value("modes")) > 0:
            out.append({"damping": str(value("damping")),
                        "tolerance": float(value("tolerance")), "modes": int(value("modes")),
                        "mode_cutoff_ratio": float(value("mode_cutoff_ratio")),
                        **{key: float(value(key)) for key in (
                            "mode_cutoff_load", "n_load_min", "n_load_max")
                           if f"levels/{index}/{key}" in datasets},
                        "steps_per_top_period": float(value("steps_per_top_period")),
                        "steps_coefficient": float(value("steps_coefficient")),
                        "steps_exponent": float(value("steps_exponent"))})
        index += 1
    return out


def extract_rule(result_path: Path, rule_path: Path) -> str:
    """Write the fitted rule of a ``calibrate`` result file to ``rule_path`` (atomically;
    ``results/calibrate-rule.toml``, which ``make calibration-install`` installs:
    :func:`flex.config.calibration.install_calibration`); return what was done. Raises
    :class:`flex.base.errors.FlexError` for a file that is not a finished calibrate result or a
    rule without any calibrated level."""
    import os
    import tempfile
    import tomllib

    from flex.base.errors import FlexError
    from flex.data.results import open_results

    with open_results(result_path) as h5:
        if h5.attrs.get("study") != "calibrate":
            raise FlexError(f"'{result_path}' holds study {h5.attrs.get('study')!r}, not "
                            f"calibrate: run make calibrate first")
        if "summary/rule/toml" not in h5:
            raise FlexError(f"'{result_path}' has no /summary/rule/toml (a failed run?)")
        text = h5["summary/rule/toml"][()]
    text = text.decode() if isinstance(text, bytes) else str(text)
    if not tomllib.loads(text).get("levels"):
        raise FlexError(f"'{result_path}': the fit calibrated no level; "
                        f"{rule_path} is left as it is")
    if rule_path.exists() and rule_path.read_text("utf-8") == text:
        return f"{rule_path} is already the rule of {result_path}"
    handle, staged = tempfile.mkstemp(dir=rule_path.parent, prefix=".rule-")
    with os.fdopen(handle, "w", encoding="utf-8") as stream:
        stream.write(text)
    os.replace(staged, rule_path)
    return f"wrote the rule of {result_path} to {rule_path}"


if __name__ == "__main__":
    import sys

    from flex.base.errors import FlexError

    if len(sys.argv) != 3:
        print("usage: python -m flex.experiments.fitting.calibration_report RESULT.h5 RULE.toml "
              "(write a calibrate run's fitted FFRF rule, for make calibration-install)",
              file=sys.stderr)
        raise SystemExit(2)
    try:
        print(extract_rule(Path(sys.argv[1]), Path(sys.argv[2])))
    except FlexError as exc:
        print(f"flex: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
