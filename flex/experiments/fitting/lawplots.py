"""Figures of the rigid-or-flexible law fits (:mod:`flex.experiments.fitting.lawfit`): the
coupler's (``kfit``) errors and k against n and tolerance, the crank's law, its validation and
deflections."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from flex.base.physics import TWO_PI
from flex.base.plotting import (
    MICRO,
    decade_ticks,
    figure,
    legend_below,
    log_ticks,
    panels,
    save,
    wrap,
)
from flex.data.results import CaseResult
from flex.dynamics.link_models import RIGID
from flex.experiments.fitting.kfit import THESIS_MODELS, label
from flex.experiments.fitting.kfit_law import PREDICTOR_BAND, predictor_ratios
from flex.experiments.fitting.lawfit import FULL_MODES, REPORT_TOLERANCES
from flex.fidelity.criteria import GOVERNING

#: the coupler fit's case families spelt out (see :func:`flex.experiments.fitting.kfit.fit_cases`)
FAMILY_NAMES = {"thk": "thickness sweep", "stf": "spring stiffness sweep",
                "pre": "preload sweep"}
#: the error measures as axis labels (definitions: flex.fidelity.criteria.MEASURES)
MEASURE_LABELS = {GOVERNING: "governing error = largest of\ndeflection, angle, slider [-]",
                  "deflection": "peak deflection\n/ coupler length L2 [-]",
                  "crank_angle": "crank angle error\n/ crank swing [-]",
                  "slider_position": "slider position error\n/ slider travel [-]",
                  "stress_amplification": "|stress amplification\n\u2212 1| [-]"}
#: damping ratio -> colour in the coupler figures
COLOURS = {0.0: "tab:blue", 0.02: "tab:orange"}
_DAMPING_ENTRIES = [("colour: undamped (\u03b6 = 0)",
                     {"marker": "s", "color": "tab:blue", "ms": 7}),
                    ("colour: 2 % modal damping (\u03b6 = 0.02)",
                     {"marker": "s", "color": "tab:orange", "ms": 7})]


def _thesis_entry(thesis_k: float) -> tuple[str, dict]:
    return (f"thesis threshold k = 108 (model 1) = n {thesis_k:.3g}", {"linestyle": "--"})


# ------------------------------------------------------------------------------------------
# the coupler (kfit)
# ------------------------------------------------------------------------------------------
def coupler_figures(analysis: dict[str, Any], folder: Path) -> list[Path]:
    """``kfit-error-vs-n.png`` and ``kfit-k-vs-tolerance.png`` from an analysis of
    :func:`flex.experiments.fitting.kfit_law.analyse` (none without fits)."""
    if not analysis["fits"]:
        return []
    return [_error_vs_n(analysis, folder / "kfit-error-vs-n.png"),
            _k_vs_tolerance(analysis, folder / "kfit-k-vs-tolerance.png"),
            *_predictors(analysis, folder / "kfit-predictors.png")]


def _predictors(analysis: dict[str, Any], path: Path) -> list[Path]:
    """Predicted against measured deflection error of the rigid model, log-log: the n-law and
    the load-based predictor, with the target band."""
    data = analysis["table"]
    if "predictor/deflection" not in data or not np.isfinite(data["predictor/deflection"]).any():
        return []
    measured = data["measures/deflection"]
    ratios = predictor_ratios(data, analysis["fits"])
    with figure(path, "Rigid model's deflection error: predicted against measured (FFRF "
                "with geometric stiffness), per kfit case",
                "measured peak deflection / L2 [-] (log)",
                "predicted peak deflection / L2 [-] (log)", size=(6.8, 6.0)) as ax:
        finite = measured[np.isfinite(measured) & (measured > 0)]
        line = np.array([finite.min() / 3, finite.max() * 3])
        ax.fill_between(line, line * PREDICTOR_BAND[0], line * PREDICTOR_BAND[1], color="0.9",
                        label=f"target {PREDICTOR_BAND[0]:g}-{PREDICTOR_BAND[1]:g} x measured")
        ax.plot(line, line, color="0.4", lw=1, label="predicted = measured")
        for key, style, text in (("n_law", dict(marker="s", color="tab:orange"),
                                  "n-law (central fit)"),
                                 ("loads", dict(marker="o", color="tab:blue"),
                                  "rigid run's loads (oscillator)")):
            ax.plot(measured, ratios[key] * measured, ls="none", ms=4, label=text, **style)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(*line)
    return [path]


def _error_panel(ax, data: dict[str, np.ndarray], fits: dict, measure: str,
                 grid: np.ndarray, thesis_k: float) -> None:
    n_all, values = data["n_physical/stop"], data[f"measures/{measure}"]
    for fam, marker in {"thk": "o", "stf": "s", "pre": "^"}.items():
        for zeta, color in COLOURS.items():
            rows = (data["family"] == fam) & np.isclose(data["parameters/damping_ratio"], zeta)
            if rows.any():
                ax.loglog(n_all[rows], np.abs(values[rows]), marker, color=color,
                          mfc="none" if fam != "thk" else color, ms=5, alpha=0.8)
    excluded = ~data["fitted"]
    if excluded.any():
        ax.loglog(n_all[excluded], np.abs(values[excluded]), "x", color="red", ms=7)
    for zeta, color in COLOURS.items():
        law = fits.get((zeta, "stop", measure))
        if law is None:
            continue
        lower, upper = law.band(grid, kind="prediction")
        ax.loglog(grid, law.predict(grid), "-", color=color,
                  label=f"fit \u03b6 = {zeta:g}: p = {law.exponent:.2f}")
        ax.fill_between(grid, lower, upper, color=color, alpha=0.12)
    for model, thickness in THESIS_MODELS.items():
        rows = data["name"] == f"thk_t{label(thickness, 1e3)}mm_z0"
        if rows.any():
            ax.loglog(n_all[rows], np.abs(values[rows]), "*", color="k", ms=12)
            ax.annotate(model.replace("model", "model "), (n_all[rows][0], abs(values[rows][0])),
                        fontsize=7, xytext=(4, 4), textcoords="offset points")
    if math.isfinite(thesis_k):
        ax.axvline(thesis_k, color="k", ls="--", lw=1)
    ax.set_ylabel(MEASURE_LABELS.get(measure, measure.replace("_", " ") + " [-]"))
    ax.grid(True, which="major", alpha=0.3)
    decade_ticks(ax, "y")
    floor = any(law.with_floor for (_, d, m), law in fits.items() if d == "stop" and m == measure)
    ax.legend(fontsize="x-small", loc="lower left", title_fontsize="x-small",
              title="error law $e = $" + ("floor + " if floor else "") + "$c\\,n^{-p}$")


def _error_vs_n(analysis: dict[str, Any], path: Path) -> Path:
    data, fits = analysis["table"], analysis["fits"]
    thesis_k = analysis["thesis_k_physical"]["stop"]
    measures = [GOVERNING, "deflection", "crank_angle", "slider_position", "stress_amplification"]
    fig, axes = plt.subplots(len(measures), 1, figsize=(8.5, 2.9 * len(measures) + 2.2),
                             layout="constrained", sharex=True)
    n_all = data["n_physical/stop"]
    grid = np.geomspace(max(n_all.min() / 2, 1e-2), n_all.max() * 2, 200)
    for ax, measure in zip(axes, measures, strict=True):
        _error_panel(ax, data, fits, measure, grid, thesis_k)
    secondary = axes[0].secondary_xaxis("top", functions=(lambda n: n * TWO_PI,
                                                          lambda n: n / TWO_PI))
    secondary.set_xlabel("n in the thesis convention = \u0394t \u00b7 \u03c9 [-]")
    decade_ticks(axes[-1], "x")
    fig.suptitle(wrap("Rigid-coupler error against n = \u0394t / T (\u0394t: time to the first "
                      "crank-angle maximum; bands: 95 % prediction)", 8.5))
    axes[-1].set_xlabel("n = \u0394t / T [-], T = 2\u03c0 / \u03c9 (period of the coupler's "
                        "first bending mode)")
    legend_below(fig, [(f"{FAMILY_NAMES[fam]} ({shape})",
                        {"marker": marker, "mfc": "k" if fam == "thk" else "none", "ms": 6})
                       for fam, marker, shape in (("thk", "o", "filled circles"),
                                                  ("stf", "s", "open squares"),
                                                  ("pre", "^", "open triangles"))]
                 + [*_DAMPING_ENTRIES,
                    ("not fitted: deflection > 5 % of L2 or compression > 0.25 Euler "
                     "buckling load", {"marker": "x", "color": "red", "ms": 7}),
                    ("thesis Table 5 models 0-3 (t = 1, 3, 5, 10 mm, undamped)",
                     {"marker": "*", "ms": 10}),
                    _thesis_entry(thesis_k)], ncol=2, collect=False)
    return save(fig, path)


def _k_vs_tolerance(analysis: dict[str, Any], path: Path) -> Path:
    fits, thesis_k = analysis["fits"], analysis["thesis_k_physical"]["stop"]
    tolerances = np.geomspace(1e-5, 0.2, 60)
    fig, ax = plt.subplots(figsize=(8.5, 6.8), layout="constrained")
    measure_styles = ((GOVERNING, "-"), ("deflection", "--"), ("crank_angle", ":"),
                      ("slider_position", "-."),
                      ("stress_amplification", (0, (6, 2, 1, 2, 1, 2))))
    entries, floors = [], []
    for measure, style in measure_styles:
        entries.append((MEASURE_LABELS[measure].replace("\n", " ").replace(" [-]", ""),
                        {"linestyle": style, "lw": 2 if measure == GOVERNING else 1.2}))
        for zeta, color in COLOURS.items():
            law = fits.get((zeta, "stop", measure))
            if law is None:
                continue
            ks = np.array([law.k(t) for t in tolerances])
            finite = np.isfinite(ks)
            ax.loglog(tolerances[finite], ks[finite], linestyle=style, color=color,
                      lw=2 if measure == GOVERNING else 1)
            if law.with_floor:
                floors.append((f"stress amplification, \u03b6 = {zeta:g}: no k below its "
                               f"error floor {law.floor:.2g}", {"linestyle": "none"}))
            if measure == GOVERNING:
                upper = [law.k(t, bound="upper") for t in tolerances]
                ax.loglog(tolerances, upper, linestyle=style, color=color, alpha=0.4, lw=5)
    if math.isfinite(thesis_k):
        ax.axhline(thesis_k, color="k", ls="--", lw=1)
    for tolerance in REPORT_TOLERANCES:
        ax.axvline(tolerance, color="grey", lw=0.5)
    ax.set_xlabel("tolerance on the error measure [-]")
    ax.set_ylabel("threshold k: smallest n = \u0394t / T for a rigid coupler [-]")
    secondary = ax.secondary_yaxis("right", functions=(lambda n: n * TWO_PI,
                                                       lambda n: n / TWO_PI))
    secondary.set_ylabel("k in the thesis convention, \u0394t \u00b7 \u03c9 [-]")
    ax.set_title(wrap("Threshold k against tolerance, per error measure (\u0394t: time to the "
                      "first crank-angle maximum)", 8.5))
    ax.grid(True, which="major", alpha=0.3)
    decade_ticks(ax)
    legend_below(fig, [*entries,
                       ("governing, conservative (95 % prediction band)",
                        {"linestyle": "-", "lw": 5, "alpha": 0.4}),
                       *_DAMPING_ENTRIES, _thesis_entry(thesis_k),
                       (f"tolerances tabulated in the report "
                        f"({', '.join(f'{t:g}' for t in REPORT_TOLERANCES)})",
                        {"linestyle": "-", "color": "grey", "lw": 0.5}),
                       *floors], ncol=2)
    return save(fig, path)


# ------------------------------------------------------------------------------------------
# the crank
# ------------------------------------------------------------------------------------------
def scene_label(name: str) -> str:
    """``wing_t1p5mm_tol0p1pct`` -> ``wing, t = 1.5 mm, tol. 0.1 %`` (legends spell names)."""
    parts = name.replace("p", ".").split("_")
    words = ["with wing" if part == "wing" else
             f"t = {part[1:-2]} mm" if part.startswith("t") and part.endswith("mm") else
             f"tolerance {part[3:-3]} %" if part.startswith("tol") else part
             for part in parts]
    if "with wing" not in words:
        words.insert(0, "no wing")
    return ", ".join(words)


def crank_figures(results: dict[str, CaseResult], summary: Any, scenes: list[str],
                  folder: Path) -> list[Path]:
    """``crank-deflection.png`` (the full crank's midpoint deflection per validation scene
    of ``scenes``) and ``crank-validation.png`` (the law and auto's errors), from the
    results and the summary's datasets."""
    drawn = [name for name in scenes if results.get(f"{name}__full") is not None
             and results[f"{name}__full"].status == "ok"]
    return [_crank_deflection(results, drawn, folder / "crank-deflection.png"),
            _crank_validation(summary.datasets, scenes, folder / "crank-validation.png")]


def _crank_deflection(results: dict[str, CaseResult], drawn: list[str], path: Path) -> Path:
    # one panel per scene: the peaks differ by two orders of magnitude (700 um for the 1 mm
    # crank carrying the wing, a few um for the thick ones)
    rows = max(1, (len(drawn) + 1) // 2)
    with panels(path, f"Elastic midpoint deflection of the full FFRF crank "
                f"({FULL_MODES} modes): one panel, with its own scale, per validation scene",
                rows=rows, cols=2, size=(10.0, 1.2 + 2.1 * rows), sharex=True) as (_, axes):
        for index, (ax, name) in enumerate(zip(axes, drawn, strict=False)):
            full = results[f"{name}__full"]
            values = np.asarray(full.datasets["crank/midpoint_deflection"].data) * 1e6
            ax.plot(np.asarray(full.datasets["time"].data) * 1e3, values, color=f"C{index}",
                    lw=1.0)
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_title(f"{scene_label(name)}: peak {np.abs(values).max():.3g} {MICRO}m",
                         fontsize="small")
            ax.set_ylabel(f"deflection [{MICRO}m]")
        for ax in axes[len(drawn):]:
            ax.set_visible(False)
        for ax in axes[-2:]:
            ax.set_xlabel("time [ms]")
            ax.xaxis.set_tick_params(labelbottom=True)
    return path


def _crank_validation(data: dict[str, Any], scenes: list[str], path: Path) -> Path:
    with panels(path, "Crank error law (fit: rigid crank carrying the wing) and the "
                "validation of auto's rigid-or-FFRF choice on scenes outside the fit",
                size=(8.5, 6.2)) as (fig, (ax,)):
        if "fit/n" in data:
            n_fit = np.asarray(data["fit/n"].data)
            ax.loglog(n_fit, data["fit/governing"].data, ".", color="0.5", ms=7,
                      label="fit cases: rigid crank against the full FFRF crank")
            grid = np.geomspace(n_fit.min(), n_fit.max(), 50)
            exponent = float(data["fit/exponent"].data)
            coefficient = float(data["fit/coefficient"].data)
            ax.loglog(grid, coefficient * grid ** -exponent, "-", color="0.5",
                      label=f"crank law (central fit): e = {coefficient:.3g} "
                            f"$n^{{-{exponent:.3g}}}$")
        tolerances, numbered = set(), []
        for name in scenes:
            key = f"validation/{name}"
            if f"{key}/n_physical" not in data:
                continue
            n = float(data[f"{key}/n_physical"].data)
            error = max(float(data[f"{key}/errors/governing"].data), 1e-9)
            tolerance = float(data[f"{key}/tolerance"].data)
            tolerances.add(tolerance)
            rigid = str(data[f"{key}/choice"].data) == RIGID
            ax.loglog([n], [error], "o" if rigid else "s", ms=8,
                      color="C0" if error <= tolerance else "C3")
            numbered.append((scene_label(name), {"marker": f"${len(numbered) + 1}$", "ms": 7}))
            ax.annotate(str(len(numbered)), (n, error), fontsize=8, xytext=(6, 5),
                        textcoords="offset points", fontweight="bold")
        for tolerance, style in zip(sorted(tolerances, reverse=True), ("--", ":", "-."),
                                    strict=False):
            ax.axhline(tolerance, color="k", lw=0.8, ls=style,
                       label=f"tolerance {tolerance:.2g} ({tolerance * 100:g} %)")
        ax.margins(x=0.12, y=0.15)
        decade_ticks(ax, "y")
        log_ticks(ax, "x")
        ax.set_xlabel("n = \u0394t / T [-] (T: period of the crank's first in-plane elastic "
                      "mode in the mechanism)")
        ax.set_ylabel("governing relative error against the full FFRF crank [-]")
        legend_below(fig, [("auto chose rigid", {"marker": "o", "color": "0.3", "ms": 7}),
                           ("auto chose FFRF", {"marker": "s", "color": "0.3", "ms": 7}),
                           ("blue: within the scene's tolerance",
                            {"marker": "o", "color": "C0", "ms": 7}),
                           ("red: above the scene's tolerance",
                            {"marker": "o", "color": "C3", "ms": 7}), *numbered])
    return path
