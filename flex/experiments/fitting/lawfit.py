"""Fit a link's rigid-or-flexible error law and put it in force: one pipeline for any link.

The ``kfit`` (coupler) and ``crank`` studies run the same steps (thesis sec. 6.2, Eq. 64-65):

1. **fit cases**: scenes of the link over a range of n = delta_t / T, each run with the link
   rigid and flexible (what is measured is the link's own: :mod:`flex.experiments.fitting.kfit`,
   :mod:`flex.experiments.fitting.crank`);
2. **fit table -> laws**: one row per fit case (n, dimensionless errors); power laws
   ``e = floor + c n^-p`` per damping ratio, delta_t definition and measure
   (:func:`fit_laws`, by :func:`flex.fidelity.laws.fit_error_law`);
3. **criterion**: the laws of the primary delta_t as criterion TOML (:func:`criterion_toml`,
   the format of ``flex/config/criteria_fit.toml``), written to a file for ``make
   calibration-install`` to install;
4. **in force**: the validation cases get the law just fitted as a
   :class:`flex.fidelity.laws.Criterion` parsed from that text (:func:`simulate_with_law`),
   never the installed file;
5. **validation**: ``auto`` against the full flexible model (:data:`FULL_MODES` modes) on
   scenes outside the fit (:class:`Validation`, :func:`validation_lines`).

:func:`fit_then_validate` drives the steps on a :class:`CaseRunner`: :class:`SerialRunner`
(this process, one case after the other) or :class:`SweepRunner` (per-case files, resumed,
on an executor). The sweep engine is passed in by the study: this module sits below
:mod:`flex.sweep`.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from flex.base.caseloop import run_each
from flex.data.results import CaseResult
from flex.data.scene import Scene
from flex.dynamics.link_models import FFRF
from flex.fidelity.criteria import GOVERNING, PRIMARY_DELTA_T
from flex.fidelity.laws import Criterion, ErrorLaw, fit_error_law

#: modes of the full flexible model the validation holds ``auto`` against
FULL_MODES = 12
#: tolerances the reports tabulate k(tolerance) for
REPORT_TOLERANCES = (0.1, 0.01, 0.001)
#: the keyword of :func:`flex.fidelity.simulation.simulate` that carries a link's law
CRITERION_ARGUMENT = {"coupler": "criterion", "crank": "crank_criterion"}


def case_data(case: CaseResult) -> dict[str, np.ndarray]:
    """A case's datasets as arrays (result paths -> values)."""
    return {k: np.asarray(v.data) for k, v in case.datasets.items()}


def scalar(case: CaseResult, key: str) -> float:
    """A case's scalar dataset ``key`` as a float (NaN if the case lacks it)."""
    dataset = case.datasets.get(key)
    return float(np.asarray(dataset.data)) if dataset is not None else float("nan")


def simulate_with_law(scene: Scene, name: str, link: str, criterion_text: str | None,
                      source: str, raising: bool = False, *,
                      cache_dir: Path | None = None) -> CaseResult:
    """Simulate ``scene`` with ``link``'s ``auto`` decided by the law in ``criterion_text``
    (criterion TOML; None: the installed file). ``raising``: a failure raises
    (:func:`flex.fidelity.simulation.simulate`) instead of becoming a failed case.
    ``cache_dir``: the reduction cache folder (None: built in memory, no disk cache)."""
    from flex.fidelity.laws import (
        parse_criterion,
    )
    from flex.fidelity.simulation import simulate, simulate_case

    law = None if criterion_text is None else parse_criterion(criterion_text, source)
    run = simulate if raising else simulate_case
    return run(scene, name, cache_dir=cache_dir, **{CRITERION_ARGUMENT[link]: law})


# ------------------------------------------------------------------------------------------
# running the cases of a phase
# ------------------------------------------------------------------------------------------
class CaseRunner(Protocol):
    """Runs the cases of one phase (``"fit"`` or ``"validation"``) and reports progress."""

    def run(self, phase: str, scenes: dict[str, Scene],
            criterion_text: str | None) -> dict[str, CaseResult]:
        """Results of ``scenes`` in their order; ``criterion_text``: the law in force for
        ``auto`` (None in the fit phase)."""

    def say(self, text: str) -> None:
        """A phase-change line (progress only)."""

    def close(self) -> None:
        """Release what the runner holds (workers)."""


def law_case(name: str, scene: Scene, *, link: str, criterion_text: str | None, source: str,
             cache_dir: Path | None = None) -> CaseResult:
    """:func:`simulate_with_law` as a case function ``(name, scene)`` (for
    :func:`flex.base.caseloop.run_each`; picklable as a ``functools.partial``)."""
    return simulate_with_law(scene, name, link, criterion_text, source, cache_dir=cache_dir)


@dataclass
class SerialRunner:
    """Every case in this process, one after the other (:func:`simulate_with_law`), or,
    given an ``executor`` (:mod:`flex.sweep`'s, passed in and closed by :meth:`close`), in
    parallel jobs of :func:`flex.base.caseloop.run_each`: the cases of one ``group`` key
    (``group(name, scene)``, e.g. those sharing a reduction) one after the other in one job;
    the results are the same. ``progress(case, done, total)`` counts over both phases;
    ``cache_dir``: the reduction cache folder (None: built in memory, no disk cache)."""

    link: str
    label: str
    total: int
    progress: Callable[[str, int, int], None] | None = None
    done: int = 0
    cache_dir: Path | None = None
    executor: Any = None
    group: Callable[[str, Scene], Any] | None = None

    def run(self, phase: str, scenes: dict[str, Scene],
            criterion_text: str | None) -> dict[str, CaseResult]:
        case = functools.partial(law_case, link=self.link, criterion_text=criterion_text,
                                 source=f"{self.label} (this run's fit)",
                                 cache_dir=self.cache_dir)
        results = run_each(scenes, case, self._counted, executor=self.executor,
                           group=self.group)
        self.done += len(results)
        return results

    def _counted(self, name: str, done: int, total: int) -> None:
        if self.progress and name != "done":  # counted over both phases
            self.progress(name, self.done + done, self.total)

    def say(self, text: str) -> None:
        if self.progress:
            self.progress(f"{self.label}: {text}", self.done, self.total)

    def close(self) -> None:
        if self.executor is not None:
            self.executor.close()


@dataclass(frozen=True)
class SweepPhase:
    """How one phase runs on the sweep engine: the case function (made from the criterion
    text in force, part of each case's identity), its preparation and its grouping key."""

    case_function: Callable[[str | None], Callable[[str, Scene], CaseResult]]
    prepare: Callable[[Scene], Any] | None
    prepare_key: Callable[[Scene], Any] | None
    title: str


@dataclass
class SweepRunner:
    """Each phase through ``run_sweep`` (:func:`flex.sweep.run_sweep`, passed in) on
    ``executor``: per-case files in ``folder``, resumed; executor figures, wall times and
    ran/resumed/failed counts accumulate in ``notes``."""

    run_sweep: Callable[..., Any]
    executor: Any
    folder: Path
    phases: Mapping[str, SweepPhase]
    label: str
    notes: dict[str, Any]
    retry_failed: bool = False
    progress: bool = True

    def run(self, phase: str, scenes: dict[str, Scene],
            criterion_text: str | None) -> dict[str, CaseResult]:
        spec = self.phases[phase]
        outcome = self.run_sweep(scenes, self.folder, spec.case_function(criterion_text),
                                 prepare=spec.prepare, prepare_key=spec.prepare_key,
                                 executor=self.executor, retry_failed=self.retry_failed,
                                 progress=self.progress, study=f"{self.label} {spec.title}")
        self.notes.setdefault("executor", self.executor.description)
        self.notes.setdefault("workers", self.executor.workers)
        self.notes[f"{phase}_wall_time_s"] = outcome.wall_time_s
        for key in ("ran", "resumed", "failed"):
            self.notes[key] = self.notes.get(key, 0) + getattr(outcome, key)
        return dict(outcome.results)

    def say(self, text: str) -> None:
        if self.progress:
            import sys

            print(f"{self.label}: {text}", file=sys.stderr, flush=True)

    def close(self) -> None:
        self.executor.close()


# ------------------------------------------------------------------------------------------
# the pipeline
# ------------------------------------------------------------------------------------------
def fit_then_validate(scenes: dict[str, Scene], is_fit: Callable[[str], bool],
                      runner: CaseRunner, fit: Callable[[dict[str, CaseResult]], Any],
                      criterion: Callable[[Any, bool], str], path: Path,
                      ) -> tuple[dict[str, CaseResult], Any]:
    """Fit cases; ``fit`` them (-> the analysis); write ``criterion(analysis, True)`` (with
    provenance) to ``path``; validation cases with ``criterion(analysis, False)`` in force.

    Returns every result (fit cases first, each phase in the order of ``scenes``) and the
    analysis. The text in force leaves out the provenance so that it depends on the fit
    alone (it is part of the validation cases' identity: a rerun resumes them).
    """
    fit_scenes = {n: s for n, s in scenes.items() if is_fit(n)}
    validation = {n: s for n, s in scenes.items() if not is_fit(n)}
    try:
        results = runner.run("fit", fit_scenes, None)
        runner.say(f"fitting the error laws to {len(results)} fit cases")
        analysis = fit(results)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(criterion(analysis, True), encoding="utf-8")
        runner.say(f"wrote {path}" + (f"; next: {len(validation)} validation cases"
                                      if validation else ""))
        if validation:
            results.update(runner.run("validation", validation, criterion(analysis, False)))
    finally:
        runner.close()
    runner.say("cases done; next: the summary and the figures")
    return results, analysis


def fit_laws(n: Mapping[str, np.ndarray], measures: Mapping[str, np.ndarray],
             groups: Mapping[float, np.ndarray], floor: tuple[str, ...] = ()
             ) -> dict[tuple[float, str, str], ErrorLaw]:
    """Error laws keyed ``(damping_ratio, delta_t definition, measure)``.

    ``n``: n_physical per delta_t definition, ``measures``: dimensionless errors per
    measure, both one value per fit-table row; ``groups``: damping ratio -> boolean mask of
    the rows fitted together. Measures in ``floor`` get ``e = floor + c n^-p``. A group
    with too few usable points has no law.
    """
    fits = {}
    for zeta, rows in groups.items():
        for definition, values in n.items():
            for measure, errors in measures.items():
                try:
                    fits[(zeta, definition, measure)] = fit_error_law(
                        values[rows], errors[rows], floor=measure in floor)
                except ValueError:
                    continue
    return fits


def criterion_toml(fits: Mapping[tuple[float, str, str], ErrorLaw], header: str,
                   meta: Mapping[str, Any], provenance: bool = False) -> str:
    """The laws of the primary delta_t definition as criterion TOML (what ``auto`` reads).

    ``header``: comment lines; ``meta``: the ``[criterion]`` entries beside the format
    (``source``, ``cases_fitted``, ...); ``provenance`` adds the creation time and the git
    commit.
    """
    laws = {(zeta, measure): law for (zeta, definition, measure), law in fits.items()
            if definition == PRIMARY_DELTA_T}
    meta = dict(meta)
    if provenance:
        from flex.data.results import provenance as code_provenance

        info = code_provenance()
        meta.update(created_utc=info["created_utc"], git_commit=info["git_commit"],
                    git_dirty=info["git_dirty"])
    return Criterion(laws, PRIMARY_DELTA_T, meta=meta).to_toml(header)


# ------------------------------------------------------------------------------------------
# validation of auto against the full model
# ------------------------------------------------------------------------------------------
@dataclass
class Validation:
    """One validation scene: ``auto``'s choice for ``link`` and its error against the full
    model. ``errors``: :func:`flex.fidelity.laws.errors_against_full` (dimensionless, and
    ``delta_t`` [s]); ``attrs``: the auto run's ``fidelity_<link>_*`` attributes;
    ``timings``: report column -> wall time [s]."""

    name: str
    link: str
    tolerance: float
    errors: dict[str, float]
    attrs: Mapping[str, Any]
    timings: dict[str, float] = field(default_factory=dict)

    @property
    def error(self) -> float:
        """The governing error of the auto run against the full model."""
        return self.errors[GOVERNING]

    @property
    def ok(self) -> bool:
        """Whether the governing error is within the tolerance."""
        return self.error <= self.tolerance

    def decision(self, key: str) -> float:
        """A number of auto's decision (``n_physical``, ``k_physical``, ...; NaN if absent)."""
        return float(self.attrs.get(f"fidelity_{self.link}_{key}", math.nan))

    @property
    def choice(self) -> str:
        """``rigid``, or ``ffrf/<modes>``."""
        model = str(self.attrs.get(f"fidelity_{self.link}_model", "?"))
        modes = int(self.attrs.get(f"fidelity_{self.link}_modes", -1))
        return model + (f"/{modes}" if model == FFRF else "")


def against_full(name: str, link: str, tolerance: float, auto: Mapping[str, np.ndarray],
                 full: Mapping[str, np.ndarray], length_m: float, attrs: Mapping[str, Any],
                 timings: dict[str, float] | None = None) -> Validation:
    """The :class:`Validation` of an auto run's series against the full model's, with
    ``link``'s deflection over ``length_m`` [m]."""
    from flex.fidelity.laws import (
        errors_against_full,
    )

    return Validation(name, link, float(tolerance),
                      errors_against_full(auto, full, link, length_m), attrs, timings or {})


def validation_lines(rows: list[Validation | tuple[str, str]], full: str) -> list[str]:
    """The report's validation table: per scene tolerance, auto's choice, omega [rad/s],
    n, k, the n-law's predicted error, the rigid model's error predicted from the loads
    (``loads``, where predicted), the measured governing error, within tolerance, wall times
    [s]; a failed scene is ``(name, message)``. ``full``: what the full model is."""
    timing = next((list(r.timings) for r in rows if isinstance(r, Validation)), [])
    lines = [f"  auto validation (scenes not in the fit; governing error of auto's choice "
             f"against {full}; wall times in s):",
             f"    {'scene':28s} {'tol':>6s} {'choice':>8s} {'omega':>9s} {'n':>7s} "
             f"{'k':>7s} {'n-law':>9s} {'loads':>9s} {'error':>9s} {'ok':>3s} "
             + " ".join(f"{t:>9s}" for t in timing)]
    for row in rows:
        if not isinstance(row, Validation):
            lines.append(f"    {row[0]:28s} failed: {row[1]}")
            continue
        numbers = [row.decision(k) for k in ("omega_rad_per_s", "n_physical", "k_physical",
                                             "predicted_error", "predicted_rigid_error")]
        lines.append(f"    {row.name:28s} {row.tolerance:6g} {row.choice:>8s} "
                     f"{numbers[0]:9.4g} {numbers[1]:7.3g} {numbers[2]:7.3g} "
                     f"{numbers[3]:9.2e} {numbers[4]:9.2e} {row.error:9.2e} "
                     f"{'yes' if row.ok else 'NO':>3s} "
                     + " ".join(f"{row.timings[t]:9.2f}" for t in timing))
    failures = [r.name for r in rows if isinstance(r, Validation) and not r.ok]
    lines.append(f"  NOT within tolerance: {', '.join(failures)}" if failures
                 else "  every auto choice within its tolerance")
    return lines
