"""Running a study: its cases, its summary, its file and its figures.

A study is a module in ``studies/`` that declares what it runs and what it stores::

    NAME = "kinematics"
    DESCRIPTION = "one line"
    OVERRIDES = ["drive.kind=\"constant_speed\"", ...]   # applied to the base scene
    def cases(scene) -> dict[str, Scene]                   # the scenes it simulates
    def summarize(scene, results, run) -> Summary          # tables, report, findings
    def figures(results, summary, folder) -> list[Path]    # PNGs (optional)

Optionally ``def simulate_cases(scenes, run: StudyRun) -> dict[str, CaseResult]`` replaces
the default one-case-at-a-time simulation (the flexible study shares reductions that way;
what it measures beside its cases goes to ``run.notes``, which ``summarize`` gets), and
``EXPECTED_FAILURES`` names cases built to fail (the stability study's forced divergences):
a run succeeds (:attr:`StudyOutput.as_expected`, exit status 0) when exactly those failed.
:func:`execute` runs a study and returns its :class:`StudyOutput`; :func:`run_study` also
writes ``results/<study>.h5`` (atomically) and the figures.

Nothing here reads the environment: the reduction cache folder (``cache_dir``) and the
values of the environment variables a study declares in ``ENVIRONMENT`` (its run-time
switches, e.g. the bench study's ``FLEX_BENCH_MAKE``) are arguments, in :class:`StudyRun`.
The command lines and :mod:`flex.api` read them once (:func:`from_environment`).
"""

from __future__ import annotations

import functools
import importlib
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

from flex.base.caseloop import run_each
from flex.base.errors import FlexError, OutputError, ResultFileError, SceneError
from flex.config.usage import explicit_keys, unused_keys
from flex.data.outputs import (
    Staging,
    check_output,
    check_writable_folder,
    failed_path,
    figures_folder,
)
from flex.data.results import CaseResult, Dataset, write_results
from flex.data.scene import Scene, load_scene, to_toml
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel
from flex.fidelity.auto import check
from flex.fidelity.simulation import simulate_case
from flex.tools.report import default_report_path, figures_of, render_report

#: the one registry of studies (each a module ``studies/<name>.py``): what ``make all`` runs,
#: in its order; the long studies, each its own ``make`` target only; and ``simulate`` (one
#: scene, ``flex run simulate``). The Makefile's ``STUDIES`` and ``LONG``, the command line's
#: choices and the README's study table are checked against it (tests/test_make.py).
MAKE_ALL_STUDIES = ("kinematics", "dynamics", "modal", "flexible", "spring", "wing", "crank",
                    "kfit")
LONG_STUDIES = ("tradeoff", "stability", "bench", "estimates", "calibrate", "design",
                "validation", "ladder", "spring_mass", "references")
STUDIES = ("simulate", *MAKE_ALL_STUDIES, *LONG_STUDIES)
RESULTS_DIR = Path("results")
#: keys that change what a study simulates in kind, not in degree: the drive, the wing, the
#: links' models and geometry, the spring's model, the integrator. A study runs with its own
#: value of each (the bundled scene's, or its ``OVERRIDES``') unless it lists the key in
#: ``HONOURS`` (its cases and report follow any value); another value given by the user is
#: refused before any case is built (:func:`check_structure`), never run under a report
#: written for the study's own.
STRUCTURAL_KEYS = ("drive.kind", "wing.enabled", "crank.model", "crank.geometry",
                   "coupler.model", "coupler.geometry", "coupler.geometric_stiffness",
                   "drive.spring_model", "simulation.integrator")


@dataclass
class Summary:
    """Study-level outputs: datasets stored under ``/summary`` and the printed report."""

    datasets: dict[str, Dataset] = field(default_factory=dict)
    report: str = ""
    #: what the study's figures draw beyond the stored datasets (not written to the file)
    figure_data: dict[str, Any] = field(default_factory=dict)
    #: the findings in short Markdown (bullets, a line ``[[table:<name>]]`` where a findings
    #: table goes, :func:`flex.data.tables.findings_table`): root attribute
    #: ``summary_findings``, what the report shows instead of the printed ``report`` (kept in
    #: the file, folded in the report)
    findings: str = ""


@dataclass
class StudyRun:
    """What a study's ``simulate_cases`` gets beside its scenes, and hands on to
    ``summarize(scene, results, run)``: the progress callback, the sweep settings (sweep
    studies: :class:`flex.sweep.SweepSettings`, None for their defaults), and ``notes``: what
    the run measured beside its cases (references, verdicts, executor figures). One per run:
    nothing is kept in a study module.

    ``cache_dir``: the reduction cache folder, passed on to everything that builds a
    reduction (None: reductions are built in memory, with no disk cache; the command lines
    and :mod:`flex.api` pass the user's folder). ``environment``: the values of the
    environment variables the study declares in ``ENVIRONMENT``, as the edge read them
    (:func:`from_environment`; a variable that was not set is absent)."""

    progress: Callable[[str, int, int], None] | None = None
    sweep: Any = None
    notes: dict[str, Any] = field(default_factory=dict)
    cache_dir: Path | None = None
    environment: Mapping[str, str] = field(default_factory=dict)


@dataclass
class StudyOutput:
    """Everything a study run produced (before or after it was written)."""

    name: str
    scene: Scene
    results: dict[str, CaseResult]
    summary: Summary
    wall_time_s: float
    path: Path | None = None
    figures: list[Path] = field(default_factory=list)
    report: Path | None = None
    expected_failures: frozenset[str] = frozenset()

    def unexpected(self) -> list[str]:
        """Cases that failed without being expected to, or were expected to fail and did
        not (names)."""
        return [name for name, case in self.results.items()
                if (case.status != "ok") != (name in self.expected_failures)]

    @property
    def as_expected(self) -> bool:
        """Whether every case ended as the study declares (ok, or failed if expected)."""
        return not self.unexpected()


def from_environment(name: str, environ: Mapping[str, str]) -> dict[str, Any]:
    """What an edge (a command line, :mod:`flex.api`) reads from ``environ`` (its
    ``os.environ``) for study ``name``, as keyword arguments of :func:`run_study` and
    :func:`execute`: ``cache_dir``, the user's reduction cache folder
    (:func:`flex.bodies.reduction.reduction_cache_dir`), and ``environment``, the values of
    the variables the study declares in ``ENVIRONMENT`` that are set."""
    from flex.bodies.reduction import reduction_cache_dir

    declared = getattr(load_study(name), "ENVIRONMENT", ())
    return {"cache_dir": reduction_cache_dir(environ),
            "environment": {key: environ[key] for key in declared if key in environ}}


def load_study(name: str) -> ModuleType:
    """Import ``studies.<name>``; unknown names get a message listing the studies."""
    if name not in STUDIES:
        raise FlexError(f"unknown study '{name}'; accepted: {', '.join(STUDIES)}")
    try:
        return importlib.import_module(f"studies.{name}")
    except ModuleNotFoundError as exc:
        if exc.name == f"studies.{name}":
            raise FlexError(f"study '{name}' is not available in this installation") from None
        raise


def study_scene(module: ModuleType, source: str | Path | None = None,
                overrides: list[str] | None = None) -> Scene:
    """The study's resolved base scene: bundled or user scene, the study's own overrides,
    then the user's ``--set`` overrides (which win)."""
    return load_scene(source, list(getattr(module, "OVERRIDES", [])) + list(overrides or []))


def progress_printer(study: str = "", stream=None) -> Callable[[str, int, int], None]:
    """A progress callback printing ``[done/total] study: case`` lines (to stderr by
    default): the study named, so that the log of two studies run side by side (``make
    all`` runs two at a time) says whose case each line is."""
    stream = stream or sys.stderr
    label = f"{study}: " if study else ""

    def report(case: str, done: int, total: int) -> None:
        print(f"  [{done}/{total}] {label}{case}", file=stream, flush=True)

    return report


def check_structure(module: ModuleType, given: dict[str, object] | None) -> None:
    """Refuse (:class:`SceneError`) a value the user gave (``given``, as for
    :func:`check_cases`) for one of :data:`STRUCTURAL_KEYS` that differs from the study's
    own, unless the study ``HONOURS`` the key. Cheap: call it before the study's cases are
    built."""
    honours = set(getattr(module, "HONOURS", ()))
    own = None
    for name, value in (given or {}).items():
        if name not in STRUCTURAL_KEYS or name in honours:
            continue
        own = own or study_scene(module)
        section, key = name.split(".", 1)
        if value != own[section][key]:
            raise SceneError(f"{name} = {_toml(value)}: study '{module.NAME}' runs with {name} "
                             f"= {_toml(own[section][key])} ({module.DESCRIPTION}); its cases and "
                             f"report are made for that and do not follow another value; use "
                             f"'flex run simulate' to run a scene of your own")


def _toml(value: object) -> str:
    """A scene value as a scene file writes it (``false``, ``"spring"``, ``0.01``)."""
    import tomli_w

    try:
        return tomli_w.dumps({"v": value}).strip().removeprefix("v = ")
    except (TypeError, ValueError):
        return repr(value)


def check_outputs(path: Path, figures: bool) -> None:
    """Refuse (:class:`~flex.base.errors.OutputError`) before anything runs an output of a
    run to ``path`` that could not be written: its figures folder, its report (not a
    folder, in a writable folder), for ``path`` and for the ``.failed.h5`` a failed run
    would go to."""
    for target in (path, failed_path(path)):
        if figures:
            check_writable_folder(figures_folder(target), f"figures of '{target}'")
        report = default_report_path(target)
        if report.is_dir():
            raise OutputError(f"report of '{target}': '{report}' is a folder; move it away "
                              f"or choose another --out")
        check_writable_folder(report.parent, f"report of '{target}'")


def check_cases(module: ModuleType, scenes: dict[str, Scene],
                given: dict[str, object] | None = None, *,
                link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> None:
    """Refuse (:class:`SceneError`), before any case runs, a case scene that cannot run or
    would mean nothing (:func:`flex.fidelity.auto.check`), and a value the user gave
    (``given``: ``{"section.key": value}``, :func:`flex.config.usage.explicit_keys`) that no case
    uses: one the study sets itself in each case (also a key it declares in ``READS``: a study
    that sets a key in every case does not read the user's), or one no case's models read
    (:func:`flex.config.usage.unused_keys`, minus the keys the study declares it reads itself in
    ``READS``). ``link_models``: the registry of the scenes' link models."""
    for scene in scenes.values():
        check(scene, link_models=link_models)
    reads = set(getattr(module, "READS", ()))
    for name, value in (given or {}).items():
        section, key = name.split(".", 1)
        values = [case[section][key] for case in scenes.values()]
        if values and all(case_value != value for case_value in values):  # READS or not
            shown = ", ".join(dict.fromkeys(f"{v:g}" if isinstance(v, float) else repr(v)
                                            for v in values))
            raise SceneError(f"{name} = {value!r}: study '{module.NAME}' sets this key itself "
                             f"in each of its cases ({shown}), so the value given would be "
                             f"ignored; use 'flex run simulate' to run a scene of your own")
        if name in reads:
            continue
        reasons = [unused_keys(case, link_models=link_models).get(name)
                   for case in scenes.values()]
        if all(reasons):
            why = reasons[0] if reasons else f"study '{module.NAME}' runs no simulation"
            raise SceneError(f"{name} = {value!r} would be ignored: {why}")


def simulate_each(scenes: dict[str, Scene], run: StudyRun, executor: Any = None,
                  group: Callable[[str, Scene], Any] | None = None,
                  cost: Callable[[str, Scene], float] | None = None) -> dict[str, CaseResult]:
    """The default ``simulate_cases``: each case on its own
    (:func:`flex.fidelity.simulation.simulate_case`, reductions cached in ``run.cache_dir``);
    on ``executor`` (:mod:`flex.sweep`'s) in parallel jobs, ``group`` and ``cost`` as
    :func:`flex.base.caseloop.run_each` takes them."""
    return run_each(scenes, functools.partial(simulate_named, cache_dir=run.cache_dir),
                    run.progress, executor=executor, group=group, cost=cost)


def simulate_named(name: str, scene: Scene, cache_dir: Path | None = None) -> CaseResult:
    """:func:`flex.fidelity.simulation.simulate_case` of ``scene`` as case ``name`` (the
    argument order of :func:`flex.base.caseloop.run_each`; picklable, for an executor)."""
    return simulate_case(scene, name, cache_dir=cache_dir)


def execute(module: ModuleType, scene: Scene,
            progress: Callable[[str, int, int], None] | None = None,
            scenes: dict[str, Scene] | None = None, sweep: Any = None, *,
            cache_dir: Path | None = None,
            environment: Mapping[str, str] | None = None) -> StudyOutput:
    """Run every case of a study and summarize; nothing is written. ``scenes``: the cases
    (default ``module.cases(scene)``); ``sweep``: where and how a sweep study (``SWEEP =
    True``) runs its cases (:class:`flex.sweep.SweepSettings`; None: its defaults);
    ``cache_dir`` and ``environment``: as :class:`StudyRun` (None: no disk cache, no
    declared variable set)."""
    start = time.perf_counter()
    scenes = module.cases(scene) if scenes is None else scenes
    run = StudyRun(progress, sweep, cache_dir=cache_dir, environment=dict(environment or {}))
    simulate_cases = getattr(module, "simulate_cases", simulate_each)
    results = simulate_cases(scenes, run)
    summary = module.summarize(scene, results, run)
    return StudyOutput(module.NAME, scene, results, summary, time.perf_counter() - start)


def run_study(name: str, source: str | Path | None = None, overrides: list[str] | None = None,
              out: str | Path | None = None, figures: bool = True, quiet: bool = False,
              sweep: Any = None, *, cache_dir: Path | None = None,
              environment: Mapping[str, str] | None = None) -> StudyOutput:
    """Run study ``name``, write its HDF5 file (default ``results/<name>.h5``) and figures
    (``figures/<file stem>-*.png`` beside it) and its report (``reports/<file stem>.md``
    beside it, generated from the file: :func:`flex.tools.report.render_report`), print the
    study's report, and return the output.
    ``sweep``: where and how a sweep study runs (:class:`flex.sweep.SweepSettings`);
    ``cache_dir``: the reduction cache folder (None: reductions built in memory, no disk
    cache); ``environment``: the study's declared variables (:class:`StudyRun`); the edges
    pass both from :func:`from_environment`.

    Nothing is lost: a key the study does not honour (:func:`check_structure`) and every
    output (:func:`flex.data.outputs.check_output`, :func:`check_outputs`) are checked before
    any case runs; the result file, the figures and the report are written under private
    names and moved into place together (:class:`flex.data.outputs.Staging`), so an error or
    an interrupt before that changes no file; a run that does not end as the study declares
    (an unexpected failed case) does not replace an existing result file but is written
    beside it (:func:`flex.data.outputs.failed_path`); figures are drawn only for a run that
    ended as declared. Failed cases are reported on stderr, also with ``quiet``. An interrupt
    raises :class:`Interrupted` saying which files were already in place.
    """
    module = load_study(name)
    given = explicit_keys(source, overrides)
    check_structure(module, given)
    scene = study_scene(module, source, overrides)
    path = check_output(RESULTS_DIR / f"{name}.h5" if out is None else out,
                        [source] if source is not None and Path(str(source)).exists() else [])
    draw = figures and hasattr(module, "figures")
    check_outputs(path, draw)
    scenes = module.cases(scene)
    check_cases(module, scenes, given)
    staging: Staging | None = None
    try:
        output = execute(module, scene, None if quiet else progress_printer(name), scenes,
                         sweep, cache_dir=cache_dir, environment=environment)
        output.expected_failures = frozenset(getattr(module, "EXPECTED_FAILURES", ()))
        target = path if output.as_expected or not path.exists() else failed_path(path)
        with Staging(target, default_report_path(target), name) as staging:
            try:
                _write_output(output, staging.result, scene)
            except ResultFileError as exc:  # named by its private name: name the target
                raise ResultFileError(str(exc).replace(str(staging.result), str(target))
                                      ) from None
            if draw and output.as_expected:
                _draw(module, output, staging.figures(), target)
            planned = staging.planned_figures()
            text = render_report(staging.result, staging.report_target.parent,
                                 shown_as=target,
                                 figures=sorted(set(figures_of(target)) | set(planned)))
            _write_text(staging.report, text, staging.report_target)
            staging.commit()  # result, figures, report: each renamed into place
        output.path, output.figures, output.report = target, planned, staging.report_target
    except KeyboardInterrupt as exc:
        raise Interrupted(staging.placed if staging else [], type(exc)) from None
    except Exception as exc:  # an interrupt inside a C extension surfaces as another error
        exc.written = staging.placed if staging else []  # for the CLI's message
        raise
    _report(output, path, quiet)
    return output


def _write_text(path: Path, text: str, target: Path) -> None:
    """Write a staged text output (``target``'s private name); a full disk or a refused
    write is an OutputError: nothing has been replaced yet."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise OutputError(f"cannot write report '{target}': {exc.strerror or exc}; nothing "
                          f"was changed") from None


class Interrupted(KeyboardInterrupt):
    """An interrupt (SIGINT or SIGTERM) during a run; ``written`` lists the files the run had
    already written (the rest were left as they were)."""

    def __init__(self, written: list[Path], kind: type = KeyboardInterrupt) -> None:
        super().__init__()
        self.written = written
        self.kind = kind


def _write_output(output: StudyOutput, target: Path, scene: Scene) -> Path:
    """Write the run's result file to ``target`` (its staged name)."""
    failed = [case for case in output.results.values() if case.status != "ok"]
    return write_results(target, output.name, list(output.results.values()), to_toml(scene),
                         output.summary.datasets,
                         {"wall_time_s": output.wall_time_s, "failed_cases": len(failed),
                          "summary_report": output.summary.report,
                          **({"summary_findings": output.summary.findings}
                             if output.summary.findings else {})})


def _draw(module: ModuleType, output: Any, folder: Path, target: Path) -> None:
    """The study's figures into ``folder`` (staged); a write the system refuses (a full
    disk) names where they go (it said "cannot access: No space left on device")."""
    try:
        module.figures(output.results, output.summary, folder)
    except OSError as exc:
        raise OutputError(f"cannot write the figures of '{target}' (in "
                          f"{target.parent / 'figures'}): {exc.strerror or exc}; the previous "
                          f"result file, figures and report (if any) are unchanged") from None


def _report(output: StudyOutput, path: Path, quiet: bool) -> None:
    """The report and the written files on stdout; failed cases and a kept file on stderr."""
    failed = [case for case in output.results.values() if case.status != "ok"]
    if not quiet:
        print(output.summary.report)
    for case in failed:
        expected = case.name in output.expected_failures
        if not (quiet and expected):
            print(f"flex: FAILED{' (expected)' if expected else ''} case {case.name}: "
                  f"{case.message}", file=sys.stderr)
    for case in output.results.values():
        if case.status == "ok" and case.attrs.get("validity_warning"):
            print(f"flex: WARNING case {case.name}: {case.attrs['validity_warning']}",
                  file=sys.stderr)
    for name in output.unexpected():
        if output.results[name].status == "ok":
            print(f"flex: NOT FAILED case {name}: it was built to fail (EXPECTED_FAILURES)",
                  file=sys.stderr)
    if output.path != path:
        print(f"flex: {len(output.unexpected())} case(s) did not end as the study declares: "
              f"'{path}' was kept as it was (the last good run); this run was written to "
              f"'{output.path}'", file=sys.stderr)
    if quiet:
        return
    expected = len([c for c in failed if c.name in output.expected_failures])
    print(f"wrote {output.path} ({len(output.results)} cases, {len(failed)} failed"
          + (f", {expected} of them as expected" if expected else "")
          + f", {output.wall_time_s:.1f} s)")
    for figure in output.figures:
        print(f"wrote {figure}")
    if output.report is not None:
        print(f"wrote {output.report}")
