"""Does a run meet the tolerance asked? First guesses and refined settings on held-out scenes.

For each scene (an FFRF plate coupler whose physics the reference store holds and which no
calibration fitted), each tolerance of :data:`LEVELS` asked on :data:`QUANTITY` (the
coupler's deployment peak deflection, on the headline channel) and each way of running it,
the **first guess** (``fidelity.refine = false``: the settings ``auto`` picks) and the
**refined** settings (``fidelity.refine = true``: refinement until the budget meets the
tolerance), :func:`check_tolerance` runs the scene and compares the quantity with the stored
reference (:mod:`flex.data.reference_store`). Stored per case as attributes:
``tolerance_true_error`` and ``tolerance_reference_accuracy`` [m], ``tolerance_allowed`` [m]
(the tolerance times the reference value), ``tolerance_truly_met`` (true error within it),
``tolerance_decided`` (the true error lies farther from the allowed one than the reference's
accuracy: no error of the reference can flip the verdict; otherwise nobody can tell)
and the run's own ``tolerance_met`` (what it states of itself).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from flex.data.headlines import BUILTIN_HEADLINES
from flex.data.reference_store import MissingReferenceError, StoredReference, reference_for
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.data.scene_edit import derive_scene
from flex.fidelity.simulation import simulate_case

#: the tolerances asked (relative)
LEVELS = (0.01, 0.003, 0.001)
#: the quantity asked: the one the FFRF settings rule is calibrated on
QUANTITY = "coupler_deployment_peak_deflection_m"
#: how each level is run: the first guess and the refined settings
MODES = {"first": False, "refined": True}
#: a case name's separator between scene, level and mode
SEPARATOR = "--"
#: the keys a user asking a tolerance leaves to flex (``"auto"``): a study that pins them for
#: its own runs (calibrate's grid) sets them back for its tolerance runs
USER_KEYS = ('coupler.model="auto"', 'coupler.modes="auto"', 'coupler.mesh_size_m="auto"',
             'simulation.step_s="auto"', 'simulation.spectral_radius="auto"',
             'simulation.newton="auto"', 'simulation.newton_relative_tolerance="auto"')


def tolerance_scenes(scenes: Mapping[str, Scene]) -> dict[str, Scene]:
    """Every scene at every level of :data:`LEVELS` in every mode of :data:`MODES`, named
    ``<scene>--<level>--<mode>``, asking for :data:`QUANTITY` alone."""
    out = {}
    for name, scene in scenes.items():
        for level in LEVELS:
            for mode, refine in MODES.items():
                out[SEPARATOR.join((name, f"{level:g}", mode))] = derive_scene(scene, [
                    f"fidelity.tolerance={level!r}", f"fidelity.refine={str(refine).lower()}",
                    f'fidelity.quantities=["{QUANTITY}"]', "simulation.error_estimate=true",
                    "simulation.output_step_s=0.0"])
    return out


def check_tolerance(name: str, scene: Scene, cache_dir: Path | None,
                    store: Mapping[str, StoredReference]) -> CaseResult:
    """Run ``scene`` and compare its :data:`QUANTITY` with the stored reference (module doc);
    a failed run, or physics the store lacks, makes a failed case."""
    run = simulate_case(scene, name, cache_dir=cache_dir)
    if run.status != "ok":
        return run
    try:
        reference = reference_for(store, scene)
    except MissingReferenceError as exc:
        return CaseResult(name, run.scene_toml, status="failed", message=str(exc))
    value = BUILTIN_HEADLINES[QUANTITY].read(run.datasets)
    truth = reference.values[QUANTITY]
    allowed = float(scene["fidelity"]["tolerance"]) * abs(truth)
    true = abs(value - truth) if value is not None else float("inf")
    accuracy = reference.accuracies[QUANTITY]
    run.attrs.update(tolerance_true_error=true, tolerance_reference_accuracy=accuracy,
                     tolerance_allowed=allowed, tolerance_truly_met=bool(true <= allowed),
                     tolerance_decided=bool(abs(true - allowed) > accuracy))
    return run


#: the findings table's columns (:func:`tolerance_findings`)
COLUMNS = {"tolerance": ("1", "relative tolerance asked on the deployment peak deflection"),
           "mode": ("1", "first guess (refine off) or refined settings"),
           "decided": ("1", "cases the reference can decide (|true - allowed| above its "
                            "accuracy)"),
           "truly_met": ("1", "of those, cases whose true error is within the tolerance"),
           "stated_met": ("1", "cases whose own budget states the tolerance met"),
           "stated_but_missed": ("1", "decided cases stating it met whose true error misses"),
           "worst_true_over_allowed": ("1", "largest true error / allowed error")}


def tolerance_rows(results: Mapping[str, CaseResult]) -> list[dict[str, Any]]:
    """One row per (level, mode) over the scenes (module doc)."""
    rows = []
    for level in LEVELS:
        for mode in MODES:
            cases = [case for name, case in results.items() if case.status == "ok"
                     and name.split(SEPARATOR)[1:] == [f"{level:g}", mode]]
            decided = [c for c in cases if c.attrs.get("tolerance_decided")]
            ratios = [c.attrs["tolerance_true_error"] / c.attrs["tolerance_allowed"]
                      for c in cases if c.attrs.get("tolerance_allowed")]
            rows.append({
                "tolerance": level, "mode": mode, "decided": f"{len(decided)} of {len(cases)}",
                "truly_met": sum(bool(c.attrs["tolerance_truly_met"]) for c in decided),
                "stated_met": sum(bool(c.attrs.get("tolerance_met")) for c in cases),
                "stated_but_missed": sum(bool(c.attrs.get("tolerance_met"))
                                         and not c.attrs["tolerance_truly_met"]
                                         for c in decided),
                "worst_true_over_allowed": max(ratios, default=float("nan"))})
    return rows


def check_tolerances(scenes: Mapping[str, Scene], store: Mapping[str, StoredReference],
                     cache_dir: Path | None = None, progress: Any = None,
                     executor: Any = None) -> dict[str, CaseResult]:
    """:func:`check_tolerance` for every scene (in this process, or on ``executor``)."""
    import functools

    from flex.base.caseloop import run_each

    return run_each(dict(scenes), functools.partial(check_tolerance, cache_dir=cache_dir,
                                                    store=store), progress, executor=executor)


def tolerance_findings(results: Mapping[str, CaseResult]) -> tuple[dict[str, Any], str, str]:
    """The findings table (``/summary/findings/tolerances``), its findings lines and the
    printed report's lines, over the tolerance cases of ``results`` (names with
    :data:`SEPARATOR`)."""
    from flex.data.tables import findings_table

    asked = {name: case for name, case in results.items() if SEPARATOR in name}
    rows = tolerance_rows(asked)
    failed = [name for name, case in asked.items() if case.status != "ok"]
    lines = [f"- the tolerance asked on {QUANTITY}, on {len(asked) // 6} held-out scenes: how "
             f"often it is truly met against the stored reference, first guess and refined"
             + (f"; failed runs: {', '.join(failed)}" if failed else ""),
             "", "[[table:tolerances]]"]
    report = "\n".join([lines[0]] + [
        f"- {row['tolerance']:g} {row['mode']}: decided {row['decided']}, truly met "
        f"{row['truly_met']}, stated met {row['stated_met']}, stated but missed "
        f"{row['stated_but_missed']}, worst true/allowed {row['worst_true_over_allowed']:.3g}"
        for row in rows])
    table = findings_table("tolerances", "The tolerance asked, met? (held-out scenes)", rows,
                           COLUMNS, order=3)
    return table, "\n".join(lines), report


__all__ = ["COLUMNS", "LEVELS", "MODES", "QUANTITY", "SEPARATOR", "USER_KEYS", "check_tolerance",
           "check_tolerances", "tolerance_findings", "tolerance_rows", "tolerance_scenes"]
