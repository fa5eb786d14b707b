"""What the benchmark reports: its table and its bar charts.

:func:`bench_summary` turns the notes of :func:`flex.experiments.workprecision.benchmark.run_bench`
into datasets -- ``rigid/...``, ``ffrf_1mm/...`` (times [s], errors, ratios, each run's profile),
``step_cost/...``, ``reduction/...``, ``make_all/...`` -- the printed table (``table/what``,
``table/value``, ``table/detail``) and the findings, a table per section.
:func:`bench_figures` draws the integration times at equal accuracy, the Exudyn CPU shares of
the untuned and tuned runs, and the FFRF cost per step against mesh and modes (before and
after the cheap joint markers).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.plotting import figure
from flex.data.results import Dataset
from flex.experiments.workprecision.benchmark import BenchPlan

Row = tuple[str, str, str]


def _put(datasets: dict[str, Dataset], key: str, value: Any, units: str, text: str) -> None:
    datasets[key] = Dataset(value, units, text)


def _times(datasets: dict[str, Dataset], prefix: str, m: Any) -> None:
    """Median integration and total time [s] and the setting of measurement ``m``."""
    _put(datasets, f"{prefix}/wall_time", m.wall_time_s, "s", "median integration time")
    _put(datasets, f"{prefix}/total_time", m.total_time_s, "s",
         "median build + integration + output")
    _put(datasets, f"{prefix}/setting", m.setting.label, "1", "setting")


def _rigid_rows(rigid: Mapping[str, Any], datasets: dict[str, Dataset]) -> list[Row]:
    tuned, untuned, scipy = rigid["tuned"], rigid["untuned"], rigid["scipy"]
    ratio = tuned.wall_time_s / scipy.wall_time_s
    ratio_total = tuned.total_time_s / scipy.total_time_s
    _put(datasets, "rigid/reference_accuracy", rigid["reference"].accuracy, "1",
         "largest relative change of the reference under coarsening")
    for name, m in (("flex_tuned", tuned), ("flex_untuned", untuned), ("scipy", scipy)):
        _times(datasets, f"rigid/{name}", m)
        _put(datasets, f"rigid/{name}/crank_angle_error",
             m.errors.get("crank_angle_rad", np.nan), "rad", "max |crank angle - reference|")
    _put(datasets, "rigid/ratio_flex_over_scipy", ratio, "1", "integration time ratio, same run")
    _put(datasets, "rigid/ratio_flex_over_scipy_total", ratio_total, "1",
         "end-to-end ratio (build + integration + output), same run")
    _put(datasets, "rigid/speedup_tuning", untuned.wall_time_s / tuned.wall_time_s, "1",
         "untuned / tuned integration time at the same step")
    return [
        ("rigid 1e-7 rad: flex tuned", f"{tuned.wall_time_s * 1e3:.0f} ms",
         f"{tuned.setting.label}, error {tuned.errors['crank_angle_rad']:.1e} rad, "
         f"{tuned.steps} steps, {tuned.newton_iterations} Newton iterations"),
        ("rigid 1e-7 rad: flex untuned", f"{untuned.wall_time_s * 1e3:.0f} ms",
         f"{untuned.setting.label}, {untuned.newton_iterations} Newton iterations"),
        ("rigid 1e-7 rad: scipy DAE", f"{scipy.wall_time_s * 1e3:.1f} ms",
         f"{scipy.setting.label}, error {scipy.errors['crank_angle_rad']:.1e} rad "
         f"(end to end {scipy.total_time_s * 1e3:.0f} ms)"),
        ("rigid: flex / scipy", f"{ratio:.1f}", f"integration; end to end {ratio_total:.1f}"),
    ]


def _ffrf_rows(ffrf: Mapping[str, Any], plan: BenchPlan, datasets: dict[str, Dataset]
               ) -> list[Row]:
    tuned, untuned, default = ffrf["tuned"], ffrf["untuned"], ffrf["default"]
    target = plan.ffrf_target_s
    _put(datasets, "ffrf_1mm/reference_accuracy", ffrf["reference"].accuracy, "1",
         "largest relative change of the reference under coarsening")
    _put(datasets, "ffrf_1mm/reference_peak_deflection", ffrf["reference"].peak_deflection_m,
         "m", "reference peak |midpoint deflection|")
    for name, m in (("tuned", tuned), ("untuned", untuned), ("default", default)):
        _times(datasets, f"ffrf_1mm/{name}", m)
        _put(datasets, f"ffrf_1mm/{name}/peak_deflection_error",
             m.errors.get("peak_deflection_relative", np.nan), "1",
             "relative peak deflection error")
    _put(datasets, "ffrf_1mm/target_met", bool(tuned.wall_time_s < target), "1",
         f"tuned integration under {target} s")
    _put(datasets, "ffrf_1mm/speedup_tuning", untuned.wall_time_s / tuned.wall_time_s, "1",
         "untuned / tuned integration time")
    return [
        ("FFRF 1 mm 1 %: tuned", f"{tuned.wall_time_s:.3f} s",
         f"{tuned.setting.label}, peak error "
         f"{tuned.errors['peak_deflection_relative'] * 100:.2f} %, {tuned.steps} steps, "
         f"end to end {tuned.total_time_s:.2f} s; target < {target} s: "
         f"{'met' if tuned.wall_time_s < target else 'NOT met'}"),
        ("FFRF 1 mm: untuned first set-up", f"{untuned.wall_time_s:.2f} s",
         f"{untuned.setting.label}, peak error "
         f"{untuned.errors.get('peak_deflection_relative', np.nan) * 100:.3f} %"),
        ("FFRF 1 mm: untuned / tuned", f"{untuned.wall_time_s / tuned.wall_time_s:.1f}",
         "integration time"),
        ("FFRF 1 mm: flex defaults", f"{default.wall_time_s:.3f} s",
         f"the scene's \"auto\" solver keys, 2 mm mesh, 6 modes: peak error "
         f"{default.errors.get('peak_deflection_relative', np.nan) * 100:.2f} %, "
         f"{default.steps} steps; target < {target} s: "
         f"{'met' if default.wall_time_s < target else 'NOT met'}"),
    ] + _nonlinear_rows(ffrf, plan, datasets)


def _nonlinear_rows(ffrf: Mapping[str, Any], plan: BenchPlan, datasets: dict[str, Dataset]
                    ) -> list[Row]:
    nonlinear = ffrf.get("nonlinear")
    if nonlinear is None:
        why = ffrf.get("nonlinear_failed", "not run (not installed or FLEX_BENCH_NONLINEAR=0)")
        return [("FFRF 1 mm: nonlinear FE", "-", why[:150])]
    coarse = nonlinear["coarse"]
    if not coarse.ok:
        return [("FFRF 1 mm: nonlinear FE", "failed", coarse.message[:120])]
    own_error = coarse.errors["peak_deflection_relative"]
    coarse_pick = own_error <= plan.ffrf_accuracy
    pick_wall = coarse.wall_time_s if coarse_pick else nonlinear["fine_wall_time_s"]
    ratio = pick_wall / ffrf["tuned"].wall_time_s
    model = nonlinear["model_difference"]["peak_deflection_relative"]
    _put(datasets, "ffrf_1mm/nonlinear/wall_time_h2e-4", coarse.wall_time_s, "s", "integration")
    _put(datasets, "ffrf_1mm/nonlinear/wall_time_h1e-4", nonlinear["fine_wall_time_s"], "s",
         "integration")
    _put(datasets, "ffrf_1mm/nonlinear/peak_change_h2e-4_to_h1e-4", own_error, "1",
         "its own time-discretization error estimate at h = 2e-4 s")
    _put(datasets, "ffrf_1mm/nonlinear/peak_difference_to_reference", model, "1",
         "the stored reference's peak (the calibrated exact beam) against the nonlinear FE "
         "peak (h = 1e-4 s)")
    _put(datasets, "ffrf_1mm/ratio_nonlinear_over_tuned", ratio, "1",
         "integration time ratio at 1 % (each model against its own finer run)")
    return [("FFRF 1 mm: nonlinear FE / tuned FFRF", f"{ratio:.0f}",
             f"nonlinear FE {pick_wall:.0f} s at h = {'2e-4' if coarse_pick else '1e-4'} s "
             f"(peak changes {own_error * 100:.2f} % when the step halves); the models differ "
             f"by {model * 100:.1f} % in peak deflection")]


def _profile_rows(part: str, data: Mapping[str, Any], datasets: dict[str, Dataset]
                  ) -> list[Row]:
    rows = []
    for which in ("profile_untuned", "profile_tuned"):
        for key, value in data[which].items():
            units = "%" if key.endswith("_percent") else ("s" if key.endswith("_s") else "1")
            _put(datasets, f"{part}/{which}/{key}", value, units, "profile of one run")
    for which in ("untuned", "tuned"):
        prof = data[f"profile_{which}"]
        top = sorted(((v, k) for k, v in prof.items()
                      if k.endswith("_percent") and not k.startswith("exudyn___")),
                     reverse=True)[:4]
        rows.append((f"{part}: {which} profile", f"{prof['phase_integration_s']:.2f} s",
                     ", ".join(f"{k[7:-8]} {v:.0f} %" for v, k in top)
                     + f"; {prof['newton_iterations'] / max(prof['steps'], 1):.1f} Newton "
                     f"iterations and {prof['jacobian_updates'] / max(prof['steps'], 1):.2f}"
                     f" Jacobians per step"))
    return rows


def _cache_rows(notes: Mapping[str, Any], datasets: dict[str, Dataset]) -> list[Row]:
    rows: list[Row] = []
    reduction = notes.get("reduction")
    if reduction:
        _put(datasets, "reduction/cold", reduction["cold_s"], "s",
             "build, empty cache (median of 2)")
        _put(datasets, "reduction/cached", reduction["cached_s"], "s",
             "load from cache (median of 6)")
        _put(datasets, "reduction/ffrf_interface", reduction["ffrf_interface_s"], "s",
             "projection of the loaded reduction for its first mechanism")
        rows += [("reduction 1 mm plate: cold", f"{reduction['cold_s']:.2f} s", "empty cache"),
                 ("reduction 1 mm plate: from cache", f"{reduction['cached_s']:.3f} s",
                  f"+ {reduction['ffrf_interface_s']:.2f} s projection at the first build")]
    make_all = notes.get("make_all", {})
    for label in ("cold", "warm"):
        if f"{label}_s" in make_all:
            _put(datasets, f"make_all/{label}", make_all[f"{label}_s"], "s",
                 f"make all, {label} cache")
            _put(datasets, f"make_all/{label}_returncode", make_all[f"{label}_returncode"], "1",
                 "exit status")
            status = ("ok" if make_all[f"{label}_returncode"] == 0
                      else f"FAILED: {make_all.get(f'{label}_error', '')[-120:]}")
            rows.append((f"make all, {label} reduction cache",
                         f"{make_all[f'{label}_s']:.0f} s", status))
    if "skipped" in make_all:
        rows.append(("make all", "-", make_all["skipped"]))
    return rows


def _step_cost_rows(rows: list[Mapping[str, Any]], datasets: dict[str, Dataset]) -> list[Row]:
    """``step_cost/...`` columns (one entry per mesh and mode count) and a table row each."""
    if not rows:
        return []
    columns = {
        "mesh_size_m": ("m", "coupler mesh size"),
        "modes": ("1", "fixed-interface eigenmodes (the body has 6 static modes more)"),
        "mesh_nodes": ("1", "mesh nodes of the reduction"),
        "fewest_ms_per_step": ("ms", "wall time per step, joint markers on the fewest nodes "
                               "(now), median"),
        "all_face_nodes_ms_per_step": ("ms", "wall time per step, joint markers on every face "
                                       "node (before), median"),
        "fewest_newton_per_step": ("1", "Newton iterations per step (now)"),
        "all_face_nodes_newton_per_step": ("1", "Newton iterations per step (before)")}
    for key, (units, text) in columns.items():
        _put(datasets, f"step_cost/{key}", np.array([r[key] for r in rows]), units, text)
    speedup = np.array([r["all_face_nodes_ms_per_step"] / r["fewest_ms_per_step"] for r in rows])
    _put(datasets, "step_cost/speedup", speedup, "1",
         "time per step before / now (both measured in this run)")
    return [(f"FFRF 1 mm step: mesh {r['mesh_size_m'] * 1e3:g} mm, {r['modes']} modes",
             f"{r['fewest_ms_per_step']:.3f} ms",
             f"all face nodes {r['all_face_nodes_ms_per_step']:.3f} ms ({ratio:.1f}x); "
             f"{r['mesh_nodes']} nodes; {r['fewest_newton_per_step']:.1f} Newton it/step")
            for r, ratio in zip(rows, speedup, strict=True)]


def _newton_rows(rows: list[Mapping[str, Any]], datasets: dict[str, Dataset]) -> list[Row]:
    """``newton/...`` columns (one entry per Newton variant) and a table row each."""
    if not rows:
        return []
    for key, units, text in (("label", "1", "Newton variant and relative tolerance"),
                             ("ms_per_step", "ms", "wall time per step, median"),
                             ("newton_per_step", "1", "Newton iterations per step")):
        _put(datasets, f"newton/{key}", np.array([r[key] for r in rows],
                                                 dtype=object if key == "label" else float),
             units, text)
    return [(f"FFRF 1 mm step, Newton {r['label']}", f"{r['ms_per_step']:.3f} ms",
             f"{r['newton_per_step']:.2f} iterations per step (mesh {r['mesh_size_m'] * 1e3:g} "
             f"mm, {r['modes']} modes)") for r in rows]


def _plates_rows(rows: list[Mapping[str, Any]], datasets: dict[str, Dataset]) -> list[Row]:
    """``plates/...`` columns (one entry per plate and tolerance) and a table row each: flex's
    own settings, their time against the target and their error against the reference."""
    if not rows:
        return []
    error = np.array([r["measurement"].errors.get("peak_deflection_relative", np.nan)
                      for r in rows])
    certified = error + np.array([r["reference_accuracy"] for r in rows])
    total = np.array([r["measurement"].total_time_s for r in rows])
    columns = {"plate": (np.array([r["plate"] for r in rows], dtype=object), "1", "plate"),
               "tolerance": (np.array([r["tolerance"] for r in rows]), "1",
                             "fidelity.tolerance (relative peak deflection)"),
               "entry": (np.array([r["entry"] for r in rows], dtype=object), "1",
                         "what set the solver keys (ffrf_rule or flexible_fallback)"),
               "step_s": (np.array([r["step_s"] for r in rows]), "s", "step flex chose"),
               "modes": (np.array([r["modes"] for r in rows]), "1", "in-plane modes chosen"),
               "total_time": (total, "s", "median build + integration + output, in process, "
                                          "reduction in memory"),
               "error": (error, "1", "peak-deflection error against the reference"),
               "certified_error": (certified, "1", "error + the reference's accuracy"),
               "certifiable": (np.array([r["certifiable"] for r in rows]), "1",
                               "the reference is accurate to a third of the tolerance"),
               "target": (np.array([r["target_s"] for r in rows]), "s", "time target")}
    for key, (value, units, text) in columns.items():
        _put(datasets, f"plates/{key}", value, units, text)
    out = []
    for r, err, cert, seconds in zip(rows, error, certified, total, strict=True):
        within = ("within" if cert <= r["tolerance"] else "NOT within") if r["certifiable"] \
            else "reference cannot certify it"
        timing = "met" if seconds <= r["target_s"] else "missed"
        out.append((f"plate {r['plate']} at {r['tolerance'] * 100:g} %", f"{seconds:.3f} s",
                    f"{r['entry']}: h={r['step_s']:.3g} s, {r['modes']} modes, mesh "
                    f"{r['mesh_size_m'] * 1e3:g} mm; error {err:.2e} (+ reference "
                    f"{r['reference_accuracy']:.1e}): {within}; target "
                    f"{r['target_s']:g} s {timing}"))
    return out


def _budget_rows(notes: Mapping[str, Any], datasets: dict[str, Dataset]) -> list[Row]:
    """``budget/...`` (per plate: the run alone, with its budget, their ratio) and
    ``command_line/...``, and a table row each."""
    out: list[Row] = []
    for r in notes.get("budget", []):
        for key, units, text in (("run_s", "s", "median in-process run without its budget"),
                                 ("budget_s", "s", "median in-process run with its budget"),
                                 ("ratio", "1", "with its budget / without")):
            _put(datasets, f"budget/{r['plate']}/{key}", r[key], units, text)
        out.append((f"budget at 1 %: {r['plate']}", f"{r['ratio']:.1f}x",
                    f"run {r['run_s']:.3f} s, with its error budget {r['budget_s']:.3f} s "
                    f"(in process, warm; medians)"))
    line = notes.get("command_line")
    if line:
        for key, units, text in (("command_s", "s", "median whole-process command line, "
                                  "warm, with its figures"),
                                 ("in_process_s", "s", "median in-process run, same scene"),
                                 ("ratio", "1", "command line / in process")):
            _put(datasets, f"command_line/{key}", line[key], units, text)
        out.append((f"command line: {line['plate']}", f"{line['command_s']:.2f} s",
                    f"flex run simulate, whole process with figures, warm; in process "
                    f"{line['in_process_s']:.2f} s ({line['ratio']:.1f}x)"))
    return out


#: the findings tables' columns (:func:`bench_findings`): one row per measurement
BENCH_COLUMNS = {"measurement": ("1", "what was timed or measured", object),
                 "value": ("see measurement", "its median time, ratio or count, as printed",
                           object),
                 "how": ("1", "the setting, its error and what the value is against",
                         object)}


def _sections(notes: Mapping[str, Any], plan: BenchPlan, datasets: dict[str, Dataset]
              ) -> list[tuple[str, str, list[Row]]]:
    """The benchmark's rows by section: (table name, title, rows); each row also fills its
    datasets."""
    speed = []
    if notes.get("rigid"):
        speed += _rigid_rows(notes["rigid"], datasets)
    if notes.get("ffrf_1mm"):
        speed += _ffrf_rows(notes["ffrf_1mm"], plan, datasets)
    profiles = [row for part in ("rigid", "ffrf_1mm") if notes.get(part)
                for row in _profile_rows(part, notes[part], datasets)]
    return [("speed", "Time to a stated accuracy (integration medians; ratios from this run)",
             speed),
            ("profiles", "Where the time goes (Exudyn's CPU shares)", profiles),
            ("step_cost", "The cost of an FFRF step", _step_cost_rows(
                notes.get("step_cost", []), datasets) + _newton_rows(notes.get("newton", []),
                                                                      datasets)),
            ("plates", "Plates at flex's own settings, against their stored references",
             _plates_rows(notes.get("plates", []), datasets)),
            ("budget", "The 1 % answer's cost", _budget_rows(notes, datasets)),
            ("cache", "Reductions and make all", _cache_rows(notes, datasets)),
            ("failed", "Parts that failed", [(key, "failed", value[:150])
                                             for key, value in notes.items()
                                             if key.endswith("_failed")])]


def bench_summary(notes: Mapping[str, Any], plan: BenchPlan
                  ) -> tuple[dict[str, Dataset], str, str]:
    """Datasets, the printed table and the findings (a table per section,
    :func:`flex.data.tables.findings_table`) of a benchmark run (see the module doc)."""
    from flex.data.tables import findings_table

    datasets: dict[str, Dataset] = {}
    sections = [section for section in _sections(notes, plan, datasets) if section[2]]
    rows = [row for _, _, part in sections for row in part]
    _put(datasets, "table/what", np.array([r[0] for r in rows], dtype=object), "1",
         "measurement")
    _put(datasets, "table/value", np.array([r[1] for r in rows], dtype=object), "see value",
         "result")
    _put(datasets, "table/detail", np.array([r[2] for r in rows], dtype=object), "1", "how")
    findings = ["- every number is measured by this run, on whatever else the machine was "
                "doing: times are medians of repeats, each ratio is of two times measured here"]
    for order, (name, title, part) in enumerate(sections):
        datasets |= findings_table(name, title, [
            {"measurement": what, "value": value, "how": detail}
            for what, value, detail in part], BENCH_COLUMNS, order)
        findings.append(f"[[table:{name}]]")
    width = max((len(r[0]) for r in rows), default=10)
    lines = ["bench (medians of repeats; ratios from this run)"]
    lines += [f"  {what:{width}s}  {value:>10s}  {detail}" for what, value, detail in rows]
    return datasets, "\n".join(lines), "\n\n".join(findings)


def _times_figure(data: Mapping[str, Dataset], folder: Path, target_s: float) -> list[Path]:
    bars = [(label, data[key].data) for label, key in (
        ("rigid 1e-7 rad: flex untuned", "rigid/flex_untuned/wall_time"),
        ("rigid 1e-7 rad: flex tuned", "rigid/flex_tuned/wall_time"),
        ("rigid 1e-7 rad: scipy DAE", "rigid/scipy/wall_time"),
        ("FFRF 1 mm 1 %: untuned", "ffrf_1mm/untuned/wall_time"),
        ("FFRF 1 mm 1 %: tuned", "ffrf_1mm/tuned/wall_time"),
        ("FFRF 1 mm: flex defaults", "ffrf_1mm/default/wall_time"),
        ("FFRF 1 mm 1 %: nonlinear FE (h = 2e-4 s)", "ffrf_1mm/nonlinear/wall_time_h2e-4"),
    ) if key in data]
    if not bars:
        return []
    path = folder / "bench-times.png"
    with figure(path, "Integration wall time at equal accuracy (median of repeats, log "
                "scale)", "integration wall time [s]", "run (model, accuracy: settings)",
                size=(8.5, 4.2)) as ax:
        ax.barh([b[0] for b in bars], [b[1] for b in bars], color="tab:blue")
        ax.set_xscale("log")
        ax.axvline(target_s, color="grey", ls=":", label=f"FFRF target {target_s:g} s")
        for index, (_, seconds) in enumerate(bars):
            ax.annotate(f"{float(seconds):.3g} s", (float(seconds), index), xytext=(3, 0),
                        textcoords="offset points", va="center", fontsize="x-small")
        times = [float(b[1]) for b in bars] + [target_s]
        ax.set_xlim(min(times) / 3, max(times) * 4)  # room for the value labels
        ax.invert_yaxis()
    return [path]


def _profile_figure(data: Mapping[str, Dataset], folder: Path, part: str) -> list[Path]:
    shares = {}
    for which in ("profile_untuned", "profile_tuned"):
        prefix = f"{part}/{which}/exudyn_"
        shares[which] = {key[len(prefix):-len("_percent")]: value.data
                         for key, value in data.items()
                         if key.startswith(prefix) and key.endswith("_percent")
                         and not key[len(prefix):].startswith("__")}
    names = sorted(set(shares["profile_untuned"]) | set(shares["profile_tuned"]),
                   key=lambda n: -shares["profile_untuned"].get(n, 0.0))
    if not names:
        return []
    path = folder / f"bench-profile-{part}.png"
    model = {"rigid": "rigid links", "ffrf_1mm": "FFRF coupler t = 1 mm"}.get(part, part)
    with figure(path, f"Exudyn CPU share per solver phase, {model}: untuned against "
                "tuned settings", "share of the Exudyn CPU time [%]", "solver phase",
                size=(8.0, 4.5)) as ax:
        y = np.arange(len(names))
        for offset, which in ((-0.2, "profile_untuned"), (0.2, "profile_tuned")):
            ax.barh(y + offset, [shares[which].get(n, 0.0) for n in names], height=0.4,
                    label=which.replace("profile_", "") + " settings")
        ax.set_yticks(y, names)
        ax.invert_yaxis()
    return [path]


def _step_cost_figure(data: Mapping[str, Dataset], folder: Path) -> list[Path]:
    if "step_cost/modes" not in data:
        return []
    modes = np.asarray(data["step_cost/modes"].data)
    nodes = np.asarray(data["step_cost/mesh_nodes"].data)
    path = folder / "bench-step-cost.png"
    with figure(path, "FFRF coupler t = 1 mm: wall time per step against mesh size, joint "
                "markers on every face node (before, dashed) and on the fewest nodes (now, "
                "solid)", "mesh nodes of the reduction [-] (log)", "wall time per step [ms] (log)",
                size=(8.0, 4.8)) as ax:
        for index, count in enumerate(sorted(set(modes.tolist()))):
            pick = np.flatnonzero(modes == count)
            pick = pick[np.argsort(nodes[pick])]
            color = f"C{index}"
            ax.plot(nodes[pick], np.asarray(data["step_cost/fewest_ms_per_step"].data)[pick],
                    "o-", color=color, label=f"{count} modes, now")
            ax.plot(nodes[pick],
                    np.asarray(data["step_cost/all_face_nodes_ms_per_step"].data)[pick],
                    "s--", color=color, label=f"{count} modes, before")
        ax.set_xscale("log")
        ax.set_yscale("log")
    return [path]


def bench_figures(datasets: Mapping[str, Dataset], folder: Path, target_s: float
                  ) -> list[Path]:
    """``bench-times.png`` (integration times at equal accuracy, log scale, the FFRF target
    ``target_s`` [s] marked) and ``bench-profile-<part>.png`` (Exudyn CPU shares per solver
    phase, untuned against tuned)."""
    return (_times_figure(datasets, folder, target_s)
            + _profile_figure(datasets, folder, "rigid")
            + _profile_figure(datasets, folder, "ffrf_1mm")
            + _step_cost_figure(datasets, folder))
