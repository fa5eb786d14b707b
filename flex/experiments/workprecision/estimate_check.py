"""Is a run's error budget honest? The stored total against the true error on many scenes.

:func:`check_one` runs a scene as a user would (its own settings, the error budget on:
:mod:`flex.fidelity.error_budget`) and builds its reference, the next rung of flex's ladder
converged in step, modes and mesh:

- the **model**: an FFRF coupler becomes the nonlinear FE coupler (an undamped one; the
  crank has no higher rung and stays FFRF, with :data:`REFERENCE_MODES` modes); a rigid plate
  link becomes the calibrated exact beam (:data:`REFERENCE_ELEMENTS` elements: the flexible
  truth its user gets, against which its budget's model term must hold); a lumped rigid link
  stays rigid (no plate: the budget leaves its elasticity out and says so);
- the **step**: the run's divided by :data:`REFINEMENT`; a second reference at twice that
  step gives the reference's own step accuracy (Richardson, the integrator's order);
- the **mesh**: the reference's value plus the change the FFRF model (with
  :data:`REFERENCE_MODES` modes, at the reference step) shows from the run's mesh to one
  :data:`MESH_REFINEMENT` times finer (the mesh error of the same elements in the nonlinear
  body, to leading order); a third of that change is counted in the reference's accuracy.

Per headline quantity it stores on the case, as attributes:

- ``true_error_<q>``: |run - reference| [the quantity's units];
- ``reference_accuracy_<q>``: the reference's own error (step + mesh, above);
- ``estimate_ratio_<q>``: estimated / true error (1: exact; below 1: optimistic).

A pair is *judged* only where the true error is known (at least 3x the reference's
accuracy) and above the solver's noise floor (:data:`NOISE_FLOOR` of the quantity's
scale); the others are stored and said, not judged. :func:`estimate_summary` makes the
table, the verdicts against the targets (true / estimated within [1 / :data:`PESSIMISM`,
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
from flex.config.knobs import integrator_order
from flex.config.settings import resolve_solver_settings
from flex.data.headlines import BUILTIN_HEADLINES
from flex.data.plates import is_damped
from flex.data.results import CaseResult, Dataset
from flex.data.scene import LINKS, Scene
from flex.data.scene_edit import derive_scene
from flex.data.tables import table_datasets
from flex.dynamics.link_models import EXACT_BEAM, FFRF, NONLINEAR_FE, RIGID
from flex.fidelity.error_estimate import richardson_error
from flex.fidelity.simulation import simulate_case
from flex.fidelity.stored_budget import CERTIFICATE_ATTR, PREFIX, STEP_BOUNDS_ATTR, named_quantities

#: the reference's step is the run's divided by this (order 2: 16x more accurate where the
#: run is asymptotic); a second reference at twice it measures the first's step error
REFINEMENT = 4
#: modes of an FFRF link that stays FFRF in the reference, and of the mesh correction
REFERENCE_MODES = 24
#: elements of the exact beam that stands for a rigid plate link in its reference (0.011 % of
#: the 0.7 mm plate's peak from its element limit, flex.config.ladder.EXACT_BEAM_COMPANIONS)
REFERENCE_ELEMENTS = 128
#: the mesh correction's finer mesh: the run's element size over this
MESH_REFINEMENT = 2.0
#: targets (issue 35): true / estimated within [1 / PESSIMISM, OPTIMISM] for every judged
#: pair in the asymptotic range; at most FLAGGED_SHARE of all pairs flagged outside it (a
#: step term that is a bound); no true error above its certificate
PESSIMISM, OPTIMISM = 2.0, 1.5
FLAGGED_SHARE = 0.10
#: below this fraction of a quantity's scale an error is solver noise (Newton tolerance)
NOISE_FLOOR = 1e-8
#: scale of each headline quantity for the noise floor: 1 rad, the slider travel ~0.1 m; a
#: peak or time: its own size
_SCALES = {"crank_angle_end_rad": 1.0, "slider_position_end_m": 0.1}

Progress = Callable[[str, int, int], None]


def _run(scene: Scene, name: str, overrides: list[str], cache_dir: Path | None) -> CaseResult:
    return simulate_case(derive_scene(scene, [*overrides, "simulation.output_step_s=0.0"]),
                         name, cache_dir=cache_dir)


def reference_overrides(scene: Scene) -> tuple[list[str], str]:
    """The overrides that lift a resolved scene's links to the reference's rung (see the
    module doc), and a phrase saying what the reference is."""
    overrides, parts = [], []
    for link in LINKS:
        values = scene[link]
        if values["model"] == RIGID and values["geometry"] == "plate":  # its elasticity
            overrides += [f'{link}.model="{EXACT_BEAM}"', f"{link}.elements={REFERENCE_ELEMENTS}"]
            parts.append(f"the calibrated exact beam {link} ({REFERENCE_ELEMENTS} elements: the "
                         f"flexible truth a user of the rigid {link} gets)")
            continue
        if values["model"] != FFRF:
            continue
        if link == "coupler" and not is_damped(values):
            overrides.append(f'coupler.model="{NONLINEAR_FE}"')
            parts.append("the nonlinear FE coupler")
        else:
            overrides.append(f"{link}.modes={REFERENCE_MODES}")
            parts.append(f"the FFRF {link} with {REFERENCE_MODES} modes (its top rung)")
    return overrides, ", ".join(parts) or "the same rigid model"


def _mesh_overrides(scene: Scene, fine: bool) -> list[str]:
    """The FFRF mesh-correction runs' overrides: every meshed link FFRF with
    :data:`REFERENCE_MODES` modes, on the run's mesh or one :data:`MESH_REFINEMENT` finer."""
    out = []
    for link in LINKS:
        if scene[link]["model"] == FFRF:
            size = float(scene[link]["mesh_size_m"]) / (MESH_REFINEMENT if fine else 1.0)
            out += [f"{link}.modes={REFERENCE_MODES}", f"{link}.mesh_size_m={size!r}"]
    return out


def check_one(name: str, scene: Scene, cache_dir: Path | None) -> CaseResult:
    """The run of ``scene`` with its error budget, compared with its reference (see the
    module doc); a failed run or reference makes a failed case."""
    run = _run(scene, name, ["simulation.error_estimate=true"], cache_dir)
    if run.status != "ok":
        return run
    resolved, _ = resolve_solver_settings(scene)
    step = float(resolved["simulation"]["step_s"])
    lift, what = reference_overrides(resolved)
    quiet = ["simulation.error_estimate=false"]
    runs = {"best": (lift, step / REFINEMENT), "other": (lift, 2 * step / REFINEMENT)}
    if any(resolved[link]["model"] == FFRF for link in LINKS):
        runs["mesh"] = (_mesh_overrides(resolved, False), step / REFINEMENT)
        runs["mesh_other"] = (_mesh_overrides(resolved, False), 2 * step / REFINEMENT)
        runs["fine_mesh"] = (_mesh_overrides(resolved, True), step / REFINEMENT)
    done = {}
    for key, (overrides, h) in runs.items():
        done[key] = _run(resolved, f"{name}_{key}", [*overrides, *quiet,
                                                     f"simulation.step_s={h!r}"], cache_dir)
        if done[key].status != "ok":
            return CaseResult(name, run.scene_toml, status="failed",
                              message=f"reference ({key}) failed: {done[key].message}")
    run.attrs["reference"] = (f"{what}, step {step / REFINEMENT:g} s"
                              + (f", mesh corrected by the FFRF model from the run's mesh to "
                                 f"one {MESH_REFINEMENT:g}x finer" if "mesh" in done else ""))
    _compare(run, done, step, integrator_order(resolved["simulation"]))
    return run


def _compare(run: CaseResult, references: dict[str, CaseResult], step: float, order: int
             ) -> None:
    """``true_error_*``, ``reference_accuracy_*`` and ``estimate_ratio_*`` on ``run``. A
    quantity the lifted reference does not compute (the nonlinear FE coupler's stress) is
    measured against the FFRF one (:data:`REFERENCE_MODES` modes, mesh-corrected): its model
    term is then not checked (``reference_rung_<q>``)."""
    h = step / REFINEMENT
    for quantity, headline in BUILTIN_HEADLINES.items():
        values = {key: headline.read(case.datasets) for key, case in references.items()}
        ours = headline.read(run.datasets)
        if ours is None or f"{PREFIX}{quantity}" not in run.attrs:
            continue
        base, other = ("best", "other") if values["best"] is not None else ("mesh", "mesh_other")
        if values.get(base) is None or values.get(other) is None:
            continue
        correction = (values["fine_mesh"] - values["mesh"]
                      if values.get("mesh") is not None and values.get("fine_mesh") is not None
                      else 0.0)
        true = abs(ours - (values[base] + correction))
        run.attrs[f"true_error_{quantity}"] = true
        run.attrs[f"reference_accuracy_{quantity}"] = richardson_error(
            values[base], values[other], h, 2 * h, order) + abs(correction) / 3.0
        run.attrs[f"reference_rung_{quantity}"] = "lifted" if base == "best" else "same model"
        run.attrs[f"estimate_ratio_{quantity}"] = (
            run.attrs[f"{PREFIX}{quantity}"] / true if true > 0 else math.inf)


def check_estimates(scenes: Mapping[str, Scene], cache_dir: Path | None = None,
                    progress: Progress | None = None, executor: Any = None
                    ) -> dict[str, CaseResult]:
    """:func:`check_one` for every scene: in order in this process, or on ``executor``
    (:mod:`flex.sweep`'s, passed in) in parallel, the costliest first (:func:`_cost`)."""
    return run_each(dict(scenes), functools.partial(check_one, cache_dir=cache_dir), progress,
                    executor=executor, cost=_cost)


def _cost(name: str, scene: Scene) -> float:
    """A scene's rough cost for ordering the jobs [arbitrary units]: an FFRF coupler's
    reference is the nonlinear FE coupler at a quarter of the step (its steps cost ~1 mm /
    thickness x 0.1 s), an FFRF crank's a 24-mode FFRF run; a rigid scene is cheap."""
    if scene["coupler"]["model"] == "ffrf":
        return 10.0 + 1e-3 / float(scene["coupler"]["thickness_m"])
    return 5.0 if scene["crank"]["model"] == "ffrf" else 1.0


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
            known = true >= 3 * accuracy and true > 0  # 0: every run agrees exactly
            above_noise = max(true, estimated) > NOISE_FLOOR * scale
            terms = {term: float(case.attrs.get(f"{PREFIX}{quantity}_{term}", 0.0))
                     for term in ("step", "modes", "mesh", "model")}
            flagged = quantity in named_quantities(case.attrs, STEP_BOUNDS_ATTR)
            bound = quantity in named_quantities(case.attrs)
            factor = float(case.attrs.get(CERTIFICATE_ATTR, 1.0))
            rows.append({"case": name, "quantity": quantity, "estimated": estimated,
                         "certificate": factor * estimated, "flagged": flagged,
                         "bound": bound, "true": true, "reference_accuracy": accuracy,
                         "above_noise": above_noise,
                         "judged": known and above_noise and not flagged and not bound,
                         "largest_term": max(terms, key=terms.get),
                         "why": "" if known and above_noise and not flagged and not bound else
                         ("every run agrees exactly" if true == 0 else
                          "reference not accurate enough" if not known else
                          "noise floor" if not above_noise else
                          "a bound (raw whole-run peak): its certificate checked, not judged"
                          if bound else
                          "flagged: outside the asymptotic range (its step term a bound)"),
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
                "bound": ("1", "a raw whole-run peak: its total is a bound, not an estimate"),
                "judged": ("1", "true error known, above the noise floor, not flagged"),
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
            "exceeded": [r for r in rows if r["true"] > r["certificate"]
                         and r["true"] >= 3 * r["reference_accuracy"]
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
        lines.append(f"- bounds (raw whole-run peaks, no order of convergence: checked "
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
