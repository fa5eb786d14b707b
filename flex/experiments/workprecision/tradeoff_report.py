"""What the ``tradeoff`` study reports: per scene the run table, the reference and its
evidence, the recommendations, the defaults check, and the work-precision diagram.

:func:`summarize_work_precision` turns ``notes["runs"]`` of
:func:`flex.experiments.workprecision.tradeoff.run_work_precision` into datasets under
``<scene>/``: ``runs/...`` (the table of :func:`measurements_table`, with ``on_pareto_front``),
``reference/...`` (what it is and its convergence evidence), ``recommended/...`` (per accuracy
level 1 %, 0.1 %, 0.01 %), ``default/...`` and ``rule/...`` (the flex rule's picks,
:mod:`flex.experiments.workprecision.rule_check`), and into the report text.
:func:`tradeoff_findings` makes from those datasets what the report shows a reviewer: per
scene its Pareto front, the fastest flex setting per accuracy level and the rule's picks as
findings tables (:func:`flex.data.tables.findings_table`), a few bullets beside them.
:func:`work_precision_figures` draws, from those datasets, one diagram per scene: error against
wall time (log-log), the Pareto fronts, the rule's picks (open stars), the accuracy levels and
the band the reference cannot resolve.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.plotting import figure, legend_below
from flex.data.results import Dataset
from flex.data.scene import Scene
from flex.data.tables import findings_table, table_datasets
from flex.experiments.workprecision.defaults_check import ffrf_defaults_check, rigid_defaults_check
from flex.experiments.workprecision.measurement import Measurement, Reference, describe
from flex.experiments.workprecision.pareto import ACCURACY_LEVELS, fastest, pareto_front, recommend
from flex.experiments.workprecision.rule_check import rule_check
from flex.experiments.workprecision.tradeoff import SceneRuns

HEADER = ("work-precision (error = largest relative error of crank angle / swing, slider / "
          "travel, peak deflection / peak; wall = median integration time)")


#: ``/summary/<scene>/runs/<column>``: one row per measured setting (:func:`measurements_table`)
RUN_COLUMNS = {
    "label": ("1", "setting", object),
    "group": ("1", "sweep the setting belongs to", object),
    "knobs": ("1", "engine and scene overrides of the setting", object),
    "status": ("1", "ok | failed", object),
    "message": ("1", "why a run failed", object),
    "wall_time": ("s", "median integration wall time over the repeats", float),
    "repeats": ("1", "runs timed", int),
    "total_time": ("s", "median build + integration + output time", float),
    "steps": ("1", "time steps", int),
    "newton_iterations": ("1", "Newton iterations", int),
    "jacobian_updates": ("1", "Jacobian computations", int),
    "crank_angle_error": ("rad", "max |crank angle - reference|", float),
    "slider_position_error": ("m", "max |slider x - reference|", float),
    "peak_deflection_error": ("m", "|peak midpoint deflection - reference peak|", float),
    "error": ("1", "largest relative error (angle / swing, slider / travel, peak / peak)",
              float),
    "on_pareto_front": ("1", "not beaten in both wall time and error", bool),
}


def measurements_table(measurements: Sequence[Measurement], front: Iterable[int] = ()
                       ) -> dict[str, Dataset]:
    """Columns of the per-run table (stored under ``/summary/<scene>/runs/``,
    :data:`RUN_COLUMNS`)."""
    on_front = set(front)
    rows = [{"label": m.setting.label, "group": m.setting.group,
             "knobs": repr(m.setting.knobs()), "status": m.status, "message": m.message,
             "wall_time": m.wall_time_s, "repeats": len(m.wall_times_s),
             "total_time": m.total_time_s, "steps": m.steps,
             "newton_iterations": m.newton_iterations, "jacobian_updates": m.jacobian_updates,
             "crank_angle_error": m.errors.get("crank_angle_rad", np.nan),
             "slider_position_error": m.errors.get("slider_position_m", np.nan),
             "peak_deflection_error": m.errors.get("peak_deflection_m", np.nan),
             "error": m.error, "on_pareto_front": i in on_front}
            for i, m in enumerate(measurements)]
    return table_datasets(rows, RUN_COLUMNS)


def _evidence_column(evidence: Mapping[str, Mapping[str, Any]], key: str, default: Any
                     ) -> list[Any]:
    return [evidence[n].get(key, default) for n in evidence]


def evidence_datasets(prefix: str, evidence: Mapping[str, Mapping[str, Any]]
                      ) -> dict[str, Dataset]:
    """The reference's evidence
    (:attr:`flex.experiments.workprecision.measurement.Reference.evidence`) as columns under
    ``prefix``, one row per knob sequence or coarsening."""
    names = list(evidence)
    values = np.full((len(names), 3), np.nan)
    for i, n in enumerate(names):
        level_values = evidence[n].get("values", [])
        values[i, :len(level_values)] = level_values
    return {
        f"{prefix}/coarsening": Dataset(
            np.array(names, dtype=object), "1",
            "knob sequence (three levels), one-level coarsening of the reference, or its model "
            "term (a reference on another model: that model's own error bound)"),
        f"{prefix}/error": Dataset(
            np.array([evidence[n]["error"] for n in names]), "1",
            "estimated contribution to the reference's relative error (Richardson with "
            "safety factor for an asymptotic sequence, else the conservative fallback; the "
            "change itself for a one-level coarsening)"),
        f"{prefix}/order": Dataset(
            np.array(_evidence_column(evidence, "order", np.nan)), "1",
            "observed order of the governing measure (nan: one or two levels)"),
        f"{prefix}/change_fine": Dataset(
            np.array([evidence[n].get("change_fine", evidence[n]["error"]) for n in names]),
            "1", "relative change fine -> medium (or reference -> coarsening)"),
        f"{prefix}/change_coarse": Dataset(
            np.array(_evidence_column(evidence, "change_coarse", np.nan)), "1",
            "relative change medium -> coarse"),
        f"{prefix}/asymptotic": Dataset(
            np.array([bool(v) for v in _evidence_column(evidence, "asymptotic", False)]), "1",
            "monotone with observed order >= 1: Richardson estimate used"),
        f"{prefix}/governing": Dataset(
            np.array(_evidence_column(evidence, "governing", ""), dtype=object), "1",
            "error measure with the largest estimate"),
        f"{prefix}/values": Dataset(
            values, "m or rad", "peak midpoint deflection [m] (rigid: final crank angle "
            "[rad]) at the fine, medium, coarse level"),
        f"{prefix}/settings": Dataset(
            np.array(["; ".join(evidence[n].get("settings", [n])) for n in names],
                     dtype=object), "1", "the levels' settings, finest first"),
        f"{prefix}/wall_time": Dataset(
            np.array([sum(evidence[n].get("wall_times_s", [np.nan])) for n in names]), "s",
            "integration time of the levels (a run shared with the reference or another "
            "sequence is counted in each)"),
    }


def reference_datasets(group: str, reference: Reference, reference_time_s: float
                       ) -> dict[str, Dataset]:
    """``<group>/reference/...``: what the reference is, its accuracy and its evidence."""
    prefix = f"{group}/reference"
    out = {
        f"{prefix}/description": Dataset(reference.description, "1", "what the reference is"),
        f"{prefix}/knobs": Dataset(repr(reference.setting.knobs()), "1", "reference setting"),
        f"{prefix}/wall_time": Dataset(reference.wall_time_s, "s",
                                       "reference integration time"),
        f"{prefix}/accuracy": Dataset(reference.accuracy, "1",
                                      "estimated relative error: the sum of its evidence "
                                      "(knob estimates and, if any, its model term)"),
        f"{prefix}/tolerance": Dataset(reference.tolerance, "1", "claimed relative accuracy"),
        f"{prefix}/converged": Dataset(reference.converged, "1", "accuracy <= tolerance")}
    if reference.flexible:
        out[f"{prefix}/peak_deflection"] = Dataset(
            reference.peak_deflection_m, "m", "reference peak |midpoint deflection|")
    out.update(evidence_datasets(f"{prefix}/evidence", reference.evidence))
    out[f"{prefix}/total_time"] = Dataset(
        reference_time_s, "s", "wall time of the reference and all its evidence runs "
        "(including reduction builds)")
    return out


def reference_lines(scene_name: str, reference: Reference, reference_time_s: float
                    ) -> list[str]:
    """Report lines: the reference, its accuracy and each knob's evidence."""
    verdict = "converged" if reference.converged else "NOT converged"
    lines = ["", f"### {scene_name}", "", f"- reference {reference.description}; accuracy "
             f"{reference.accuracy:.1e} ({verdict} to {reference.tolerance:g}; "
             f"{reference_time_s:.0f} s in all); evidence:"]
    for n, e in reference.evidence.items():
        lines.append(f"  - {n}: estimate {e['error']:.2e}"
                     + (f", changes {e['change_fine']:.2e} / {e['change_coarse']:.2e}, "
                        f"order {e['order']:.2f}, "
                        f"{'asymptotic' if e['asymptotic'] else 'fallback'}"
                        if "change_coarse" in e and math.isfinite(e["change_coarse"])
                        else "")
                     + (f"; values {', '.join(f'{v:.7e}' for v in e['values'])}"
                        if "values" in e else "")
                     + (f"; failed: {e['failed'][:120]}" if "failed" in e else ""))
    return lines


#: ``/summary/<scene>/recommended/<column>``: one row per accuracy level
#: (:data:`flex.experiments.workprecision.pareto.ACCURACY_LEVELS`)
RECOMMENDED_COLUMNS = {"level": ("1", "relative accuracy level"),
                       "setting": ("1", "fastest flex setting within it", object),
                       "wall_time": ("s", "its median wall time"),
                       "error": ("1", "its relative error"),
                       "knobs": ("1", "its knobs, or why there is none", object)}


def recommendations(group: str, measurements: Sequence[Measurement], reference: Reference
                    ) -> tuple[dict[str, Dataset], list[str]]:
    """``<group>/recommended/...`` and report lines: per accuracy level the fastest certified
    flex (Exudyn) setting, or why there is none."""
    rows, lines = [], []
    for rec in recommend(measurements, reference,
                         eligible=lambda m: m.setting.engine == "exudyn"):
        m = rec.measurement
        rows.append({"level": rec.level, "setting": m.setting.label if m else "",
                     "wall_time": m.wall_time_s if m else np.nan,
                     "error": m.error if m else np.nan,
                     "knobs": rec.reason or repr(m.setting.knobs())})
        lines.append(f"- {rec.level * 100:g} %: {describe(m) if m else rec.reason}")
        if m is None and "certify" in rec.reason:
            unchecked = [c for c in measurements if c.ok and c.setting.engine == "exudyn"
                         and c.error <= rec.level]
            if unchecked:
                lines.append(f"  - (fastest within it if the reference were exact: "
                             f"{describe(fastest(unchecked))})")
    return table_datasets(rows, RECOMMENDED_COLUMNS, f"{group}/recommended"), lines


def _front_lines(measurements: Sequence[Measurement], front: Sequence[int]) -> list[str]:
    """The Pareto front as a Markdown table (fastest first), and what failed."""
    failed = [m for m in measurements if not m.ok]
    return (["", "| Pareto front: setting | wall time [ms] | relative error |", "|---|---:|---:|"]
            + [f"| {measurements[i].setting.label} | {measurements[i].wall_time_s * 1e3:.1f} | "
               f"{measurements[i].error:.1e} |" for i in front]
            + ["", f"- {len(measurements)} settings, {len(failed)} failed"]
            + [f"  - failed {m.setting.label}: {m.message[:160]}" for m in failed])


def summarize_work_precision(runs: Mapping[str, SceneRuns], scenes: Mapping[str, Scene],
                             ffrf_default_scene: str | None = None,
                             rigid_default_scene: str | None = "rigid", name: str = "tradeoff"
                             ) -> tuple[dict[str, Dataset], str]:
    """Datasets and report text of every scene's runs (see the module doc). ``scenes``: the
    case scenes by name; the defaults are checked on ``ffrf_default_scene`` (the plate the
    ``ffrf_coupler`` entry is for) and on ``rigid_default_scene``."""
    datasets: dict[str, Dataset] = {}
    lines = [f"{name}: {HEADER}"]
    for scene_name, (reference, measurements, reference_time) in runs.items():
        points = [(m.wall_time_s, m.error) if m.ok else (np.nan, np.nan) for m in measurements]
        front = pareto_front(points)
        datasets.update({f"{scene_name}/runs/{key}": value
                         for key, value in measurements_table(measurements, front).items()})
        datasets.update(reference_datasets(scene_name, reference, reference_time))
        lines += reference_lines(scene_name, reference, reference_time)
        recommended, text = recommendations(scene_name, measurements, reference)
        datasets.update(recommended)
        lines += text + _front_lines(measurements, front)
        checks = [rule_check(scene_name, measurements, reference, front,
                             scenes.get(scene_name))]
        if scene_name == ffrf_default_scene:
            checks.append(ffrf_defaults_check(scene_name, measurements, reference,
                                              scenes[scene_name]))
        if scene_name == rigid_default_scene:
            checks.append(rigid_defaults_check(scene_name, measurements, scenes[scene_name]))
        for check_datasets, check_lines in checks:
            datasets.update(check_datasets)
            lines += check_lines
        scipy = [m for m in measurements if m.ok and m.setting.engine == "scipy"]
        if scipy:
            lines.append("- scipy reference DAE: " + "; ".join(
                f"{m.setting.label}: {m.wall_time_s * 1e3:.1f} ms, {m.error:.1e}"
                for m in scipy))
    return datasets, "\n".join(lines)


#: colours of the rule's picks: inside its calibrated family, and its fallback
RULE_COLOURS = {False: "crimson", True: "darkorange"}


def _rule_picks(ax: Any, rule: Mapping[str, np.ndarray], walls: np.ndarray) -> None:
    """The rule's picks (``<scene>/rule/...`` columns) as large open stars labelled ``rule 1
    %`` (``(fallback)`` where so) on top of the fronts; ``walls`` [s]: every run's wall time
    (a label near the slow end is set to the left of its star)."""
    finite = walls[np.isfinite(walls) & (walls > 0)]
    span = np.log(finite.max() / finite.min()) if finite.size > 1 else 0.0
    for level, wall, error, fallback in zip(rule["level"], rule["wall_time"], rule["error"],
                                            rule["fallback"], strict=True):
        if not (math.isfinite(wall) and math.isfinite(error)):
            continue
        fallback = bool(fallback)
        colour = RULE_COLOURS[fallback]
        ax.loglog([wall], [error], "*", ms=20, mfc="none", mec=colour, mew=1.6, zorder=5,
                  label="flex rule pick (fallback)" if fallback else "flex rule pick")
        left = span > 0 and np.log(wall / finite.min()) > 0.75 * span
        ax.annotate(f"rule {float(level) * 100:g} %{' (fallback)' if fallback else ''}",
                    (wall, error), xytext=(-10 if left else 10, 7),
                    textcoords="offset points", ha="right" if left else "left", fontsize=7,
                    fontweight="bold", color=colour, zorder=6)


def _diagram(ax: Any, table: dict[str, np.ndarray], accuracy: float | None,
             rule: Mapping[str, np.ndarray] | None = None) -> None:
    """One work-precision diagram on ``ax`` from a scene's run table (and the rule's picks,
    ``<scene>/rule/...`` columns)."""
    import matplotlib

    colours = matplotlib.colormaps["tab20"]
    ok = table["status"] == "ok"
    scipy = np.array(["'scipy'" in str(k) for k in table["knobs"]])
    explicit = np.array(["explicit_penalty" in str(k) for k in table["knobs"]])
    wall, error, label = table["wall_time"], table["error"], table["label"]
    groups = sorted({g for g, good in zip(table["group"], ok, strict=True) if good})
    for index, group_name in enumerate(groups):
        mask = ok & (table["group"] == group_name)
        marker = "s" if (mask & scipy).any() else "^" if (mask & explicit).any() else "o"
        ax.loglog(wall[mask], error[mask], marker, ms=4.5, color=colours(index % 20),
                  label=group_name, alpha=0.8)
    front = table["on_pareto_front"].astype(bool)
    order = np.argsort(wall[front])
    ax.loglog(wall[front][order], error[front][order], "k-", lw=1.0,
              label="Pareto front, all runs")
    own = [i for i in range(len(ok)) if ok[i] and not scipy[i]]
    own_front = [own[i] for i in pareto_front([(wall[i], error[i]) for i in own])]
    ax.loglog(wall[own_front], error[own_front], "k--", lw=1.0,
              label="Pareto front, flex settings")
    for rank, i in enumerate(own_front):  # alternate sides: neighbours overlap
        ax.annotate(str(label[i]), (wall[i], error[i]), fontsize=6,
                    xytext=(4, -9 if rank % 2 == 0 else 4), textcoords="offset points")
    if rule:
        _rule_picks(ax, rule, wall)
    for level in ACCURACY_LEVELS:
        ax.axhline(level, color="grey", lw=0.6, ls=":")
    ax.plot([], [], color="grey", lw=0.6, ls=":",
            label=f"accuracy levels {', '.join(f'{v:g}' for v in ACCURACY_LEVELS)}")
    if accuracy is not None and np.isfinite(accuracy):
        # errors below the reference's own accuracy are not resolved by it
        ax.axhspan(ax.get_ylim()[0], accuracy, color="grey", alpha=0.12, lw=0,
                   label=f"below the reference's accuracy ({accuracy:.1e})")
    legend_below(ax.figure, [
        ("o: Exudyn, implicit generalized-alpha (colour: sweep)", {"marker": "o"}),
        ("s: scipy DAE (reference solver)", {"marker": "s"}),
        ("^: Exudyn, explicit Runge-Kutta + joint springs", {"marker": "^"})], ncol=2)


def work_precision_figures(datasets: Mapping[str, Dataset], folder: Path) -> list[Path]:
    """``tradeoff-<scene>.png`` per scene with a run table: every ok run (colour: sweep;
    marker: engine), the Pareto front of all runs (solid) and of flex's own settings (dashed,
    labelled), and the flex rule's picks (open stars, ``<scene>/rule/...``)."""
    paths = []
    for scene_name in dict.fromkeys(key.split("/runs/")[0] for key in datasets
                                    if "/runs/" in key):
        table = {key.split("/runs/")[1]: value.data for key, value in datasets.items()
                 if key.startswith(f"{scene_name}/runs/")}
        accuracy = datasets.get(f"{scene_name}/reference/accuracy")
        rule = {key.split("/rule/")[1]: np.asarray(value.data)
                for key, value in datasets.items() if key.startswith(f"{scene_name}/rule/")}
        path = folder / f"tradeoff-{scene_name}.png"
        with figure(path, f"Work-precision diagram, scene {scene_name} (0.03 s deployment): "
                    "error against integration time of every setting",
                    "wall time of the integration [s] (median of repeats)",
                    "largest relative error against the reference [-]",
                    size=(9.0, 7.5)) as ax:
            _diagram(ax, table, None if accuracy is None else float(accuracy.data), rule)
        paths.append(path)
    return paths


# ------------------------------------------------------------------------------------------
# the findings: short Markdown and tables of data (what the report shows a reviewer)
# ------------------------------------------------------------------------------------------
FRONT_COLUMNS = {"setting": ("1", "setting on the Pareto front of the scene's runs (fastest "
                             "first)", object),
                 "wall_time": ("s", "median integration wall time", float),
                 "error": ("1", "largest relative error against the reference", float)}
LEVEL_COLUMNS = {"level": ("1", "relative accuracy level", float),
                 "setting": ("1", "fastest certified flex setting within it, or why none",
                             object),
                 "wall_time": ("s", "its median integration wall time", float),
                 "error": ("1", "its largest relative error", float)}
RULE_PICK_COLUMNS = {"level": ("1", "fidelity.tolerance flex was asked for", float),
                     "setting": ("1", "the rule setting", object),
                     "wall_time": ("s", "median integration wall time", float),
                     "error": ("1", "largest relative error", float),
                     "on_pareto_front": ("1", "not beaten in both wall time and error", bool),
                     "slowdown": ("1", "wall time / the fastest run within the level's",
                                  float)}


def _columns(datasets: Mapping[str, Dataset], prefix: str) -> dict[str, np.ndarray]:
    return {key[len(prefix):]: np.asarray(value.data) for key, value in datasets.items()
            if key.startswith(prefix) and "/" not in key[len(prefix):]}


def _front(runs: Mapping[str, np.ndarray]) -> np.ndarray:
    """The rows of a run table on its Pareto front, fastest first."""
    front = np.flatnonzero(runs["on_pareto_front"].astype(bool))
    return front[np.argsort(runs["wall_time"][front], kind="stable")]


def _scene_tables(scene: str, datasets: Mapping[str, Dataset], order: int
                  ) -> dict[str, Dataset]:
    """One scene's findings tables: its Pareto front, the fastest flex setting per accuracy
    level and (FFRF) the rule's picks, ordered after the previous scenes' (``order``)."""
    runs = _columns(datasets, f"{scene}/runs/")
    tables = findings_table(f"front_{scene}", f"Pareto front, scene {scene}",
                            [{"setting": str(runs["label"][i]),
                              "wall_time": runs["wall_time"][i], "error": runs["error"][i]}
                             for i in _front(runs)], FRONT_COLUMNS, 3 * order,
                            {"wall_time": "wall time"})
    levels = _columns(datasets, f"{scene}/recommended/")
    if levels:
        rows = [{"level": level, "setting": str(setting) or f"none: {knobs}",
                 "wall_time": wall, "error": error} for level, setting, wall, error, knobs
                in zip(levels["level"], levels["setting"], levels["wall_time"], levels["error"],
                       levels["knobs"], strict=True)]
        tables |= findings_table(f"levels_{scene}", f"Fastest flex setting per accuracy "
                                 f"level, scene {scene}", rows, LEVEL_COLUMNS,
                                 3 * order + 1, {"wall_time": "wall time"})
    rule = _columns(datasets, f"{scene}/rule/")
    if rule:
        rows = [{key: rule[key][i] for key in RULE_PICK_COLUMNS}
                for i in range(len(rule["level"]))]
        tables |= findings_table(f"rule_{scene}", f"The flex rule's picks, scene {scene}", rows,
                                 RULE_PICK_COLUMNS, 3 * order + 2,
                                 {"wall_time": "wall time", "on_pareto_front": "on the front"})
    return tables


def _scene_bullets(scene: str, datasets: Mapping[str, Dataset]) -> list[str]:
    """One scene's heading and bullets: its reference, how many runs (failed, on the front),
    the bundled defaults' verdict."""
    runs = _columns(datasets, f"{scene}/runs/")
    ok = runs["status"] == "ok"
    reference = _columns(datasets, f"{scene}/reference/")
    lines = ["", f"### {scene}", "",
             f"- reference: {reference.get('description') or '-'}; accuracy "
             f"{float(reference.get('accuracy', np.nan)):.1e} "
             f"({'converged' if reference.get('converged') else 'NOT converged'} to "
             f"{float(reference.get('tolerance', np.nan)):g})",
             f"- {len(ok)} settings, {int((~ok).sum())} failed; {len(_front(runs))} on the "
             f"Pareto front"]
    default = _columns(datasets, f"{scene}/default/")
    if "matches_table" in default:
        verdict = "confirmed" if default["matches_table"] else "NOT confirmed"
        lines.append(f"- bundled solver defaults: {verdict} (the fastest run within their "
                     f"tolerance: {default.get('setting') or '-'})")
    return [*lines, ""]


def tradeoff_findings(datasets: Mapping[str, Dataset]) -> tuple[dict[str, Dataset], str]:
    """The findings tables (datasets under ``findings/``: per scene its Pareto front, the
    fastest flex setting per accuracy level, the rule's picks) and the findings (Markdown:
    per scene its reference, counts and the defaults' verdict), read from the datasets of
    :func:`summarize_work_precision`."""
    tables: dict[str, Dataset] = {}
    lines = [f"Work-precision of every knob. {HEADER[len('work-precision ('):-1].capitalize()}."]
    scenes = dict.fromkeys(key.split("/runs/")[0] for key in datasets if "/runs/" in key)
    for order, scene in enumerate(scenes):
        scene_tables = _scene_tables(scene, datasets, order)
        tables |= scene_tables
        lines += _scene_bullets(scene, datasets)
        lines += [f"[[table:{key.split('/')[1]}]]" for key in dict.fromkeys(
            key.rsplit("/", 1)[0] for key in scene_tables)]
    return tables, "\n".join(lines)
