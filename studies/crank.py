"""Study ``crank``: the flexible (FFRF) crank, and whether ``crank.model = "auto"`` holds.

The thesis models only the coupler as flexible. flex also meshes the crank (a steel plate
A-B, ``[crank] geometry = "plate"``, reduced like the coupler) and lets ``auto`` choose
rigid or FFRF for it from a fitted criterion, with the crank's first in-plane elastic
frequency in the assembled mechanism (:func:`flex.criteria.crank_elastic_omega`). Without a
wing that is the plate's pinned-pinned frequency; with the wing welded at A the crank is a
cantilever from the wing carrying coupler and slider at B, an order of magnitude softer.

The kfit law, fitted on couplers, under-predicts the error of a rigid crank that carries
the wing (measured about 2x at equal n: at the same n the wing makes the crank a cantilever
under a larger quasi-static load). So the crank gets its own law. Phase 1 (fit): crank
thicknesses 0.8-5 mm x two spring rates, all with the wing (the harder case; cranks without
a wing err less at equal n, so the law is conservative for them), each run rigid and as the
full model, an FFRF crank with :data:`FULL_MODES` modes; the governing error against n is
fitted by :func:`flex.criteria.fit_error_law` and written to
``results/crank-criterion.toml`` (``make crank-criterion`` installs it as
``flex/crank_criteria_fit.toml``, which ``auto`` reads). Phase 2 (validation): scenes not in
the fit (other thicknesses, with and without the wing, tolerances 1 % and 0.1 %) run
``auto`` with the law just fitted and the full model.

Errors (of rigid or auto against the full model, over the deployment: to the first
crank-angle maximum of the full run) are the kfit measures with the crank in the coupler's
place: crank midpoint deflection / L1, crank angle / swing, slider position / travel; the
largest (governing) is fitted and held against the tolerance.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from flex import criteria
from flex.plotting import MICRO, decade_ticks, legend_below, log_ticks, panels
from flex.results import CaseResult, Dataset
from flex.scene import Scene, apply_overrides
from flex.settings import pinned_overrides
from flex.simulation import simulate_case
from flex.study import RESULTS_DIR, StudyRun, Summary
from flex.thesis import THESIS_SPRING_RATE_N_PER_M

NAME = "crank"
DESCRIPTION = "flexible FFRF crank against auto's choice, with and without the wing"
OVERRIDES = pinned_overrides() + ['crank.geometry="plate"', "simulation.step_s=2e-5",
             "simulation.end_time_s=0.05"]
# keys the study reads itself (its fit grid), beside what its cases simulate
READS = ("crank.length_m", "crank.thickness_m", "drive.spring_stiffness_N_per_m")
FULL_MODES = 12

#: fit scenes (all with the wing): (crank thickness [mm], spring rate [N/m]). Every
#: thickness with both springs except 0.8 mm at 6000 N/m: that full FFRF run fails Newton at
#: 17.9 ms (h = 2e-5 s), a failed case that would stop `make all`
FIT_CASES = ((0.8, THESIS_SPRING_RATE_N_PER_M),
             *((t, k) for t in (1.2, 1.8, 2.5, 3.5, 5.0)
               for k in (THESIS_SPRING_RATE_N_PER_M, 6000.0)))
#: validation scenes (not in the fit): name -> (overrides, fidelity tolerance)
SCENES: dict[str, tuple[list[str], float]] = {
    "wing_t1mm_tol1pct": (["crank.thickness_m=0.001", "wing.enabled=true"], 0.01),
    "wing_t1p5mm_tol1pct": (["crank.thickness_m=0.0015", "wing.enabled=true"], 0.01),
    "wing_t2mm_tol1pct": (["crank.thickness_m=0.002", "wing.enabled=true"], 0.01),
    "wing_t3mm_tol0p1pct": (["crank.thickness_m=0.003", "wing.enabled=true"], 0.001),
    "wing_t4p56mm_tol0p1pct": (["wing.enabled=true"], 0.001),
    "t1mm_tol0p1pct": (["crank.thickness_m=0.001"], 0.001),
}


def fit_scenes(scene: Scene) -> dict[str, Scene]:
    """``fit_t<mm>_k<N/m>`` scenes with the wing (rigid crank model; see :func:`cases`)."""
    out = {}
    for thickness_mm, spring in FIT_CASES:
        name = f"fit_t{thickness_mm:g}mm_k{spring:g}".replace(".", "p")
        out[name] = apply_overrides(scene, [f"crank.thickness_m={thickness_mm * 1e-3!r}",
                                            f"drive.spring_stiffness_N_per_m={spring!r}",
                                            "wing.enabled=true"])
    return out


def cases(scene: Scene) -> dict[str, Scene]:
    """Fit scenes as ``__rigid`` and ``__full`` cases; validation scenes as ``__auto`` and
    ``__full`` cases (run after the fit, see :func:`simulate_cases`)."""
    out = {}
    for name, base in fit_scenes(scene).items():
        out[f"{name}__rigid"] = base
        out[f"{name}__full"] = apply_overrides(base, ['crank.model="ffrf"',
                                                     f"crank.modes={FULL_MODES}"])
    for name, (changes, tolerance) in SCENES.items():
        base = apply_overrides(scene, changes)
        out[f"{name}__auto"] = apply_overrides(base, ['crank.model="auto"',
                                                     f"fidelity.tolerance={tolerance!r}"])
        out[f"{name}__full"] = apply_overrides(base, ['crank.model="ffrf"',
                                                     f"crank.modes={FULL_MODES}"])
    return out


def errors(run: dict[str, np.ndarray], full: dict[str, np.ndarray],
           crank_length_m: float) -> dict[str, float]:
    """Errors of ``run`` against ``full`` with the crank's deflection (see the module doc)."""
    return criteria.errors_against_full(run, full, "crank", crank_length_m)


def _data(case: CaseResult) -> dict[str, np.ndarray]:
    return {k: np.asarray(v.data) for k, v in case.datasets.items()}


def fit_table(scenes: dict[str, Scene], results: dict[str, CaseResult]
              ) -> dict[str, dict[str, float]]:
    """Per fit scene: n (delta_t of the rigid run x the crank's in-mechanism frequency /
    2 pi) and the errors of the rigid crank against the full one."""
    table = {}
    for name, scene in fit_scenes_of(scenes).items():
        rigid, full = results.get(f"{name}__rigid"), results.get(f"{name}__full")
        if rigid is None or full is None or rigid.status != "ok" or full.status != "ok":
            continue
        rigid_data = _data(rigid)
        times = criteria.deployment_times(rigid_data["time"], rigid_data["crank/angle"],
                                          rigid_data["crank/angular_velocity"])
        omega = criteria.crank_elastic_omega(scene)
        row = errors(rigid_data, _data(full), scene["crank"]["length_m"])
        row.update(n=criteria.n_values(times["stop"], omega)["physical"], omega=omega,
                   thickness=scene["crank"]["thickness_m"],
                   spring=scene["drive"]["spring_stiffness_N_per_m"])
        table[name] = row
    return table


def fit_scenes_of(scenes: dict[str, Scene]) -> dict[str, Scene]:
    """The fit scenes behind the ``fit_*__rigid`` cases of ``scenes``."""
    return {n[:-len("__rigid")]: s for n, s in scenes.items()
            if n.startswith("fit_") and n.endswith("__rigid")}


def fit_law(table: dict[str, dict[str, float]]) -> criteria.ErrorLaw:
    """Power law of the governing error against n over the fit table."""
    n = [row["n"] for row in table.values()]
    error = [row[criteria.GOVERNING] for row in table.values()]
    return criteria.fit_error_law(n, error)


def criterion_toml(law: criteria.ErrorLaw, cases_fitted: int) -> str:
    """The crank law as a criterion file (format of ``flex/criteria_fit.toml``)."""
    header = ("# Fitted rigid-or-flexible law of the crank, read by crank.model = \"auto\".\n"
              "# Generated by `make crank` (results/crank-criterion.toml); `make\n"
              "# crank-criterion` copies it here. e(n) = exp(log_coefficient) n^-exponent,\n"
              "# n = delta_t / T, T = 2 pi / omega with omega the crank's first in-plane\n"
              "# elastic frequency in the mechanism; fitted on cranks carrying the wing.\n")
    meta = {"omega": "crank_first_in_plane_elastic_mode_in_mechanism",
            "source": "make crank (studies/crank.py); copy with make crank-criterion",
            "cases_fitted": cases_fitted}
    return criteria.Criterion({(0.0, criteria.GOVERNING): law}, criteria.PRIMARY_DELTA_T,
                              meta=meta).to_toml(header)


#: where phase 1 writes the fitted crank law
CRITERION_PATH = RESULTS_DIR / "crank-criterion.toml"


def simulate_cases(scenes: dict[str, Scene], run: StudyRun) -> dict[str, CaseResult]:
    """Phase 1: fit cases; fit the law, write :data:`CRITERION_PATH`; phase 2: validation
    cases, ``auto`` reading the law just fitted (passed as an argument)."""
    progress = run.progress
    results: dict[str, CaseResult] = {}
    names = list(scenes)
    fit_names = [n for n in names if n.startswith("fit_")]

    def simulate_batch(batch: list[str], law: criteria.Criterion | None = None) -> None:
        for name in batch:
            if progress:
                progress(name, len(results), len(names))
            results[name] = simulate_case(scenes[name], name, crank_criterion=law)

    simulate_batch(fit_names)
    table = run.notes["fit_table"] = fit_table(scenes, results)  # summarize reuses it
    text = criterion_toml(fit_law(table), len(table))
    CRITERION_PATH.parent.mkdir(parents=True, exist_ok=True)
    CRITERION_PATH.write_text(text, encoding="utf-8")
    law = criteria.parse_criterion(text, "crank (this run's fit)")
    simulate_batch([n for n in names if not n.startswith("fit_")], law)
    if progress:
        progress("done", len(results), len(names))
    return results


def summarize(scene: Scene, results: dict[str, CaseResult],
              notes: dict[str, Any] | None = None) -> Summary:
    datasets: dict[str, Dataset] = {}
    lines = _fit_report(cases(scene), results, datasets, (notes or {}).get("fit_table"))
    lines += ["crank: auto against a full FFRF crank (12 modes); errors over the deployment",
             f"  {'scene':24s} {'tol':>6s} {'choice':>8s} {'omega':>9s} {'n':>6s} {'k':>6s} "
             f"{'predicted':>9s} {'error':>9s} {'ok':>3s} {'auto s':>7s} {'full s':>7s}"]
    failures = []
    for name, (_, tolerance) in SCENES.items():
        auto, full = results[f"{name}__auto"], results[f"{name}__full"]
        if auto.status != "ok" or full.status != "ok":
            lines.append(f"  {name:24s} failed: {auto.message or full.message}")
            continue
        data = {label: {k: np.asarray(v.data) for k, v in case.datasets.items()}
                for label, case in (("auto", auto), ("full", full))}
        measured = errors(data["auto"], data["full"], scene["crank"]["length_m"])
        attrs = auto.attrs
        model = str(attrs["fidelity_crank_model"])
        choice = model + (f"/{attrs['fidelity_crank_modes']}" if model == "ffrf" else "")
        ok = measured[criteria.GOVERNING] <= tolerance
        if not ok:
            failures.append(name)
        group = f"validation/{name}"
        for key in ("deflection", "crank_angle", "slider_position", criteria.GOVERNING):
            datasets[f"{group}/errors/{key}"] = Dataset(measured[key], "1",
                                                        f"auto against full: {key}")
        datasets[f"{group}/tolerance"] = Dataset(tolerance, "1", "fidelity.tolerance")
        datasets[f"{group}/within_tolerance"] = Dataset(int(ok), "1", "1 if error <= tol")
        datasets[f"{group}/choice"] = Dataset(np.array(choice), "1", "auto's choice")
        datasets[f"{group}/reason"] = Dataset(np.array(str(attrs["fidelity_crank_reason"])),
                                              "1", "auto's reason")
        for key, units in (("omega_rad_per_s", "rad/s"), ("n_physical", "1"),
                           ("k_physical", "1"), ("predicted_error", "1")):
            datasets[f"{group}/{key}"] = Dataset(float(attrs[f"fidelity_crank_{key}"]), units,
                                                 f"auto decision: {key}")
        datasets[f"{group}/delta_t"] = Dataset(measured["delta_t"], "s",
                                               criteria.DELTA_T_DEFINITIONS["stop"])
        for label, case in (("auto", auto), ("full", full)):
            datasets[f"{group}/wall_time/{label}"] = Dataset(
                case.counters["wall_time_s"], "s", f"integration of the {label} model")
        datasets[f"{group}/peak_crank_deflection"] = Dataset(
            float(np.abs(data["full"]["crank/midpoint_deflection"]).max()), "m",
            "full model: peak |crank midpoint deflection|")
        numbers = [attrs[f"fidelity_crank_{key}"] for key in
                   ("omega_rad_per_s", "n_physical", "k_physical", "predicted_error")]
        lines.append(
            f"  {name:24s} {tolerance:6g} {choice:>8s} {numbers[0]:9.4g} {numbers[1]:6.3g} "
            f"{numbers[2]:6.3g} {numbers[3]:9.2e} {measured[criteria.GOVERNING]:9.2e} "
            f"{'yes' if ok else 'NO':>3s} {auto.counters['wall_time_s']:7.2f} "
            f"{full.counters['wall_time_s']:7.2f}")
    datasets["failures"] = Dataset(len(failures), "1",
                                   "validation scenes whose auto error exceeds the tolerance")
    if failures:
        lines.append(f"  NOT within tolerance: {', '.join(failures)}")
    else:
        lines.append("  every auto choice within its tolerance")
    return Summary(datasets, "\n".join(lines))


def _fit_report(scenes: dict[str, Scene], results: dict[str, CaseResult],
                datasets: dict[str, Dataset], table: Any = None) -> list[str]:
    """Fit table (``table``: the one the run fitted, else built again), the crank law and
    k(tolerance) beside the coupler law's."""
    table = fit_table(scenes, results) if table is None else table
    if len(table) < 3:
        return [f"crank: only {len(table)} fit cases succeeded; no law"]
    law = fit_law(table)
    names = list(table)
    for key, units in (("n", "1"), ("omega", "rad/s"), ("thickness", "m"),
                       ("spring", "N/m"), (criteria.GOVERNING, "1"), ("deflection", "1"),
                       ("crank_angle", "1"), ("slider_position", "1")):
        datasets[f"fit/{key}"] = Dataset(np.array([table[n][key] for n in names]), units,
                                         f"fit cases (rigid crank against full FFRF): {key}")
    datasets["fit/names"] = Dataset(np.array(names, dtype=object), "1", "fit case names")
    datasets["fit/exponent"] = Dataset(law.exponent, "1", "e = c n^-p: p")
    datasets["fit/coefficient"] = Dataset(law.coefficient, "1", "e = c n^-p: c")
    datasets["fit/r_squared"] = Dataset(law.r_squared, "1", "fit quality (log space)")
    coupler = criteria.load_criterion().law(0.0)[1]
    lines = [f"crank law (fit: {len(table)} cranks with the wing, rigid against 12-mode FFRF): "
             f"e = {law.coefficient:.3g} n^-{law.exponent:.3g}, R^2 = {law.r_squared:.3f}",
             "  tolerance   k crank (upper band)   k coupler law (upper band)"]
    for tolerance in (0.1, 0.01, 0.001):
        k_crank = law.k(tolerance, bound="upper")
        k_coupler = coupler.k(tolerance, bound="upper")
        datasets[f"fit/k_upper/{tolerance:g}"] = Dataset(k_crank, "1",
                                                         f"crank k for tolerance {tolerance:g}")
        lines.append(f"  {tolerance:9g}   {k_crank:20.3g}   {k_coupler:26.3g}")
    ratio = [table[n][criteria.GOVERNING] / float(coupler.predict(table[n]["n"])) for n in names]
    datasets["fit/error_over_coupler_law"] = Dataset(np.array(ratio), "1",
                                                     "crank error / coupler law (central)")
    lines.append(f"  crank error / coupler law at equal n: {min(ratio):.2f}-{max(ratio):.2f} "
                 f"(median {np.median(ratio):.2f})")
    lines.append(f"wrote {CRITERION_PATH} (install with make crank-criterion)")
    return lines


def _scene_label(name: str) -> str:
    """``wing_t1p5mm_tol0p1pct`` -> ``wing, t = 1.5 mm, tol. 0.1 %`` (legends spell names)."""
    parts = name.replace("p", ".").split("_")
    words = ["with wing" if part == "wing" else
             f"t = {part[1:-2]} mm" if part.startswith("t") and part.endswith("mm") else
             f"tolerance {part[3:-3]} %" if part.startswith("tol") else part
             for part in parts]
    if "with wing" not in words:
        words.insert(0, "no wing")
    return ", ".join(words)


def figures(results: dict[str, CaseResult], summary: Summary, folder: Path) -> list[Path]:
    drawn = [name for name in SCENES if results.get(f"{name}__full") is not None
             and results[f"{name}__full"].status == "ok"]
    deflection = folder / "crank-deflection.png"
    # one panel per scene: the peaks differ by two orders of magnitude (700 um for the 1 mm
    # crank carrying the wing, a few um for the thick ones)
    rows = max(1, (len(drawn) + 1) // 2)
    with panels(deflection, f"Elastic midpoint deflection of the full FFRF crank "
                f"({FULL_MODES} modes): one panel, with its own scale, per validation scene",
                rows=rows, cols=2, size=(10.0, 1.2 + 2.1 * rows), sharex=True) as (_, axes):
        for index, (ax, name) in enumerate(zip(axes, drawn, strict=False)):
            full = results[f"{name}__full"]
            values = np.asarray(full.datasets["crank/midpoint_deflection"].data) * 1e6
            ax.plot(np.asarray(full.datasets["time"].data) * 1e3, values, color=f"C{index}",
                    lw=1.0)
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_title(f"{_scene_label(name)}: peak {np.abs(values).max():.3g} {MICRO}m",
                         fontsize="small")
            ax.set_ylabel(f"deflection [{MICRO}m]")
        for ax in axes[len(drawn):]:
            ax.set_visible(False)
        for ax in axes[-2:]:
            ax.set_xlabel("time [ms]")
            ax.xaxis.set_tick_params(labelbottom=True)
    validation = folder / "crank-validation.png"
    with panels(validation, "Crank error law (fit: rigid crank carrying the wing) and the "
                "validation of auto's rigid-or-FFRF choice on scenes outside the fit",
                size=(8.5, 6.2)) as (fig, (ax,)):
        if "fit/n" in summary.datasets:
            n_fit = np.asarray(summary.datasets["fit/n"].data)
            ax.loglog(n_fit, summary.datasets["fit/governing"].data, ".", color="0.5", ms=7,
                      label="fit cases: rigid crank against the full FFRF crank")
            grid = np.geomspace(n_fit.min(), n_fit.max(), 50)
            exponent = float(summary.datasets["fit/exponent"].data)
            coefficient = float(summary.datasets["fit/coefficient"].data)
            ax.loglog(grid, coefficient * grid ** -exponent, "-", color="0.5",
                      label=f"crank law (central fit): e = {coefficient:.3g} "
                            f"$n^{{-{exponent:.3g}}}$")
        tolerances, numbered = set(), []
        for name in SCENES:
            key = f"validation/{name}"
            if f"{key}/n_physical" not in summary.datasets:
                continue
            n = float(summary.datasets[f"{key}/n_physical"].data)
            error = max(float(summary.datasets[f"{key}/errors/governing"].data), 1e-9)
            tolerance = float(summary.datasets[f"{key}/tolerance"].data)
            tolerances.add(tolerance)
            rigid = str(summary.datasets[f"{key}/choice"].data) == "rigid"
            ax.loglog([n], [error], "o" if rigid else "s", ms=8,
                      color="C0" if error <= tolerance else "C3")
            numbered.append((_scene_label(name),
                             {"marker": f"${len(numbered) + 1}$", "ms": 7}))
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
    return [deflection, validation]
