"""Sweeps: many independent cases through one executor seam, one result file per case.

:func:`run_sweep` runs ``case_function(name, scene) -> CaseResult`` for every scene of a
sweep and returns the results. Contract:

- **one executor seam** (:func:`make_executor`): ``scheduler`` selects where cases run --
  ``None``/``"processes"`` (default): a local ``concurrent.futures.ProcessPoolExecutor`` on
  all cores (or ``workers``), no set-up; ``"local"``: a local Dask cluster
  (``LocalCluster``, one single-threaded worker process per core, loopback only);
  ``"tcp://host:8786"``: an existing Dask distributed scheduler; ``"serial"``: in this
  process, one case after the other (debugging). The case function and its arguments
  must be importable/picklable (a module-level function; ``flex`` installed on the workers).
- **pure cases, own files**: each case is a function of its scene alone; its result is
  written (by this process, atomically, :func:`flex.data.results.write_results`) to
  ``<folder>/cases/<name>.h5`` as soon as it arrives, with the hash of its scene and case
  function (a ``functools.partial``'s bound arguments count, except ``cache_dir``: where
  reductions are cached changes no result). A rerun **resumes**: cases whose file holds the
  same hash are read back, not run; ``retry_failed`` reruns the recorded failures too.
- **failures are data**: an exception in a case (a diverged run, a bug) or a dead worker
  process (crash, out of memory) is recorded as a ``failed`` case with its message and the
  sweep goes on. A case whose local worker dies is rerun alone in a fresh process to tell it
  from its innocent neighbours; if it kills that one too it is recorded as failed.
- **shared preparation**: ``prepare_key(scene)`` groups cases that need the same expensive
  preparation (e.g. a reduction per plate geometry, cached on disk); ``prepare(scene)`` runs
  once per group before its cases are submitted (a failed preparation fails its cases).
- **progress**: on stderr: a ``tqdm`` bar (cases done, failed, remaining) when stderr is
  a terminal; otherwise (a log, a pipe) plain lines without carriage returns, at most
  one per :data:`PROGRESS_MIN_INTERVAL_S` as cases finish, at least one per
  :data:`PROGRESS_MAX_SILENCE_S` while they run, and one at each phase change (start,
  every preparation done, end).

A sweep study gets its :class:`SweepSettings` as an argument. The command lines read them
once, at the edge (:func:`settings_from_environment` of the command line's environment):
``flex run kfit --scheduler ... --workers N --folder DIR --retry-failed``, each over the
environment's
``FLEX_SCHEDULER``, ``FLEX_WORKERS``, ``FLEX_SWEEP_DIR``, ``FLEX_RETRY_FAILED=1`` and
``FLEX_PROGRESS=0``. The reduction cache folder is read there too
(:func:`flex.bodies.reduction.reduction_cache_dir`) and reaches the case functions as their
``cache_dir`` argument (bound with ``functools.partial``).
"""

from __future__ import annotations

import pickle
import re
import sys
import time
from collections.abc import Callable, Hashable, Mapping
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from flex.base.errors import FlexError
from flex.base.progress import REPORT_INTERVAL_S
from flex.data.cache import SWEEP_CASES, folder_problem, say
from flex.data.results import CaseResult
from flex.data.scene import Scene, to_toml
from flex.sweep.case_files import (
    LOCATION_ARGUMENTS,
    SWEEP_FORMAT,
    case_content_digest,
    case_hash,
    case_path,
    read_case_file,
    write_case_file,
)
from flex.sweep.executors import (
    DaskExecutor,
    Executor,
    ProcessExecutor,
    SerialExecutor,
    check_scheduler,
    guarded_case,
    guarded_preparation,
    make_executor,
    simulate_scene_case,
)

CaseFunction = Callable[[str, Scene], CaseResult]
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")

__all__ = ["LOCATION_ARGUMENTS", "SWEEP_FORMAT", "CaseFunction", "DaskExecutor", "Executor",
           "ProcessExecutor", "SerialExecutor", "SweepOutcome", "SweepSettings",
           "case_content_digest", "case_hash", "case_path", "make_executor",
           "read_case_file", "run_sweep", "settings_from_environment",
           "simulate_scene_case", "write_case_file"]


# ------------------------------------------------------------------------------------------
# the sweep
# ------------------------------------------------------------------------------------------
@dataclass
class SweepOutcome:
    """What a sweep produced: every case (run now or read back) and how it went."""

    results: dict[str, CaseResult]
    folder: Path
    executor: str
    workers: int
    ran: int = 0
    resumed: int = 0
    failed: int = 0
    prepared: int = 0
    wall_time_s: float = 0.0
    case_wall_time_s: dict[str, float] = field(default_factory=dict)


@dataclass
class _Job:
    kind: str  # "prepare" or "case"
    key: Any
    function: Callable[..., Any]
    args: tuple
    affected: int = 0  # pool breaks this job was caught in
    started: float = 0.0


#: plain progress lines (stderr not a terminal): at most one per this many seconds as cases
#: finish, and at least one per PROGRESS_MAX_SILENCE_S while the sweep runs
PROGRESS_MIN_INTERVAL_S = 5.0
PROGRESS_MAX_SILENCE_S = REPORT_INTERVAL_S


def _is_terminal(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):  # no isatty, or a closed stream
        return False


def duration_text(seconds: float) -> str:
    """``40 s``, ``4 min``, ``1.5 h``: a rounded duration for progress lines."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 90 * 60:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


class _Progress:
    """Cases done, failed and remaining on stderr: a ``tqdm`` bar on a terminal, plain lines
    otherwise (see the module doc); nothing when not ``enabled``."""

    def __init__(self, total: int, resumed: int, description: str, enabled: bool) -> None:
        self.done = self.failed = 0
        self.total = total
        self.prepared = self.to_prepare = 0
        self.bar = None
        self.description = description
        self.stream = sys.stderr
        self.plain = enabled and not _is_terminal(self.stream)
        self.start = self.last_line = time.monotonic()
        if enabled and not self.plain:
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc=description, unit="case", file=self.stream,
                            mininterval=0.5, dynamic_ncols=True, leave=True)
            if resumed:
                self.bar.write(f"{description}: {resumed} cases resumed from their files, "
                               f"{total} to run")
        elif self.plain:
            self._line(f"{description}: {total} cases to run"
                       + (f", {resumed} resumed from their files" if resumed else ""))
        self._update()

    def _counts(self) -> str:
        shared = (f" prepared={self.prepared}/{self.to_prepare}" if self.to_prepare else "")
        return (f"done={self.done} failed={self.failed} "
                f"remaining={self.total - self.done - self.failed}" + shared)

    def _update(self) -> None:
        if self.bar is not None:
            self.bar.set_postfix_str(self._counts(), refresh=False)

    def _line(self, text: str) -> None:
        print(text, file=self.stream, flush=True)
        self.last_line = time.monotonic()

    def _status(self, final: str = "") -> None:
        """One plain line: cases finished of all, the counts, time elapsed and left (or
        ``final``: how the sweep ended)."""
        finished = self.done + self.failed
        elapsed = time.monotonic() - self.start
        text = (f"{self.description}: {finished}/{self.total} cases ({self._counts()}), "
                f"{duration_text(elapsed)} elapsed")
        if final:
            text += f", {final}"
        elif finished:
            text += f", ~{duration_text(elapsed / finished * (self.total - finished))} left"
        self._line(text)

    def case(self, ok: bool) -> None:
        if ok:
            self.done += 1
        else:
            self.failed += 1
        if self.bar is not None:
            self._update()
            self.bar.update(1)
        elif (self.plain and self.done + self.failed < self.total  # the last: close() says it
              and time.monotonic() - self.last_line >= PROGRESS_MIN_INTERVAL_S):
            self._status()

    def preparation(self, done: bool = False) -> None:
        if done:
            self.prepared += 1
        else:
            self.to_prepare += 1
        if self.bar is not None:
            self._update()
            self.bar.refresh()
        elif self.plain and done and self.prepared == self.to_prepare:
            self._status()  # a phase change: every shared preparation is done

    def tick(self) -> None:
        """Called while waiting: a plain line if none was printed for a while."""
        if self.plain and time.monotonic() - self.last_line >= PROGRESS_MAX_SILENCE_S:
            self._status()

    def note(self, text: str) -> None:
        if self.bar is not None:
            self.bar.write(text)
        elif self.plain:
            self._line(text)

    def close(self, how: str = "finished") -> None:
        """The last line: ``how`` the sweep ended (finished, interrupted, stopped by an
        error): an interrupted sweep's last line said "0/56 cases ... finished"."""
        if self.bar is not None:
            if how != "finished":
                self.bar.write(f"{self.description}: {how}")
            self.bar.close()
        elif self.plain:
            self._status(final=how)


def run_sweep(scenes: Mapping[str, Scene], folder: str | Path,
              case_function: CaseFunction = simulate_scene_case, *,
              prepare: Callable[[Scene], Any] | None = None,
              prepare_key: Callable[[Scene], Hashable | None] | None = None,
              scheduler: str | None = None, workers: int | None = None,
              executor: Executor | None = None, retry_failed: bool = False,
              progress: bool = True, study: str = "sweep") -> SweepOutcome:
    """Run (or resume) a sweep; return every case's result. See the module doc.

    ``scenes`` maps case names (letters, digits, ``_.+-``; they become file names) to
    validated scenes. ``executor`` (if given) is used and not closed; otherwise one is made
    from ``scheduler``/``workers`` and closed at the end. Results come back in the order of
    ``scenes``.
    """
    start = time.perf_counter()
    folder = Path(folder)
    for name in scenes:
        if not _NAME.match(name):
            raise FlexError(f"sweep case name {name!r}: use letters, digits and _ . + - only "
                            f"(it becomes a file name)")
    problem = folder_problem(case_path(folder, "case").parent)
    if problem:  # refused before any case runs: no case could be kept
        raise SWEEP_CASES.error(folder, problem)
    own_executor = executor is None
    executor = executor or make_executor(scheduler, workers)
    if executor.pickles:  # the cases run in other processes
        try:
            _check_sendable(case_function)
        except FlexError:
            if own_executor:
                executor.close()
            raise
    digests = {name: case_hash(scene, case_function) for name, scene in scenes.items()}
    results = _resumable(scenes, folder, digests, retry_failed)
    run = _SweepRun(scenes, folder, case_function, digests, results, executor, study,
                    progress)
    how = "stopped by an error"
    try:
        run.submit_all(prepare, prepare_key)
        run.drain()
        how = "finished"
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM: the running cases are abandoned
        how = "interrupted"
        executor.abort()
        raise
    finally:
        run.bar.close(how)
        if own_executor:
            executor.close()
    outcome = run.outcome
    outcome.results = {name: results[name] for name in scenes if name in results}
    outcome.wall_time_s = time.perf_counter() - start
    return outcome


def _check_sendable(case_function: CaseFunction) -> None:
    """Refuse, before any case runs, a case function that cannot be sent to a worker process
    (pickled): every case would fail alike and be kept as failed (``make calibrate`` bound
    a ``mappingproxy`` and stored 56 failed cases in a second)."""
    try:
        pickle.dumps(case_function)
    except Exception as exc:  # pickling raises TypeError, AttributeError, PicklingError...
        raise FlexError(f"the sweep's case function {case_function!r} cannot be sent to a "
                        f"worker process ({type(exc).__name__}: {exc}); bind plain values "
                        f"(a dict, not a mappingproxy; module-level functions)") from None


def _resumable(scenes: Mapping[str, Scene], folder: Path, digests: dict[str, str],
               retry_failed: bool) -> dict[str, CaseResult]:
    """The cases whose files in ``folder`` hold this scene and case function (and, with
    ``retry_failed``, succeeded): they are not run again."""
    results: dict[str, CaseResult] = {}
    for name in scenes:
        path = case_path(folder, name)
        if not (path.exists() or path.is_symlink()):
            continue
        try:
            case, digest = read_case_file(path)
        except FlexError as exc:  # damaged or foreign: run again (replaced atomically)
            say(SWEEP_CASES, f"{' '.join(str(exc).split())[:300]}; running case {name} again")
            continue
        if digest == digests[name] and (case.status == "ok" or not retry_failed):
            results[name] = case
    return results


class _SweepRun:
    """One sweep's jobs on one executor: preparations, their cases, loose cases, and the
    cases suspected of killing a worker (rerun alone)."""

    def __init__(self, scenes: Mapping[str, Scene], folder: Path,
                 case_function: CaseFunction, digests: dict[str, str],
                 results: dict[str, CaseResult], executor: Executor, study: str,
                 progress: bool) -> None:
        self.scenes, self.folder, self.case_function = scenes, folder, case_function
        self.digests, self.results, self.executor, self.study = digests, results, executor, study
        todo = [name for name in scenes if name not in results]
        self.outcome = SweepOutcome({}, folder, executor.description, executor.workers,
                                    resumed=len(results))
        self.bar = _Progress(len(todo), len(results), study, progress)
        self.todo = todo
        self.groups: dict[Hashable, list[str]] = {}
        self.pending: dict[Any, _Job] = {}
        self.suspects: list[_Job] = []

    def submit(self, job: _Job, where: Executor) -> None:
        job.started = time.perf_counter()
        pending = self.pending
        pending[where.submit(*((guarded_preparation, job.function) if job.kind == "prepare"
                               else (guarded_case, job.function)), *job.args)] = job

    def case_job(self, name: str) -> _Job:
        return _Job("case", name, self.case_function, (name, self.scenes[name]))

    def submit_all(self, prepare: Callable[[Scene], Any] | None,
                   prepare_key: Callable[[Scene], Hashable | None] | None) -> None:
        """One preparation per group of cases sharing a key (its cases follow it), then
        the cases that need none."""
        loose: list[str] = []
        for name in self.todo:
            key = prepare_key(self.scenes[name]) if (prepare and prepare_key) else None
            if key is None:
                loose.append(name)
            else:
                self.groups.setdefault(key, []).append(name)
        for key, names in self.groups.items():
            self.submit(_Job("prepare", key, prepare, (self.scenes[names[0]],)), self.executor)
            self.bar.preparation()
        for name in loose:
            self.submit(self.case_job(name), self.executor)

    def record(self, name: str, case: CaseResult, seconds: float) -> None:
        write_case_file(self.folder, case, self.digests[name], self.study)
        self.results[name] = case
        self.outcome.case_wall_time_s[name] = seconds
        self.outcome.ran += 1
        self.outcome.failed += case.status != "ok"
        self.bar.case(case.status == "ok")

    def finish(self, job: _Job, value: Any) -> None:
        seconds = time.perf_counter() - job.started
        if job.kind == "case":
            self.record(job.key, value, seconds)
            return
        ok, detail = value
        self.outcome.prepared += 1
        self.bar.preparation(done=True)
        for name in self.groups[job.key]:
            if ok:
                self.submit(self.case_job(name), self.executor)
            else:
                self.record(name, CaseResult(name, to_toml(self.scenes[name]), status="failed",
                                             message=f"preparation failed: {detail}"), 0.0)

    def drain(self) -> None:
        """Wait for every job; a dead worker's jobs are resubmitted or, when suspected,
        rerun alone."""
        while self.pending:
            # who was running before this wait: if the pool breaks now, they are the suspects
            running = {id(job) for future, job in self.pending.items()
                       if _is_running(future)}
            done = self.executor.wait_first(list(self.pending), timeout=0.5)
            self.bar.tick()
            broken: list[_Job] = []
            for future in done:
                job = self.pending.pop(future)
                try:
                    value = future.result()
                except BrokenProcessPool:
                    broken.append(job)
                    continue
                except Exception as exc:  # noqa: BLE001 - e.g. Dask KilledWorker
                    value = _lost(job, self.scenes, f"{type(exc).__name__}: {exc}")
                self.finish(job, value)
            if broken:
                self._restart_after(broken, running)
            if not self.pending and self.suspects:
                _run_isolated(self.suspects, self.executor, self.scenes, self.finish)
                self.suspects.clear()

    def _restart_after(self, broken: list[_Job], running: set[int]) -> None:
        # a worker process died: every queued future of the pool failed with it
        for future, job in list(self.pending.items()):
            broken.append(job)
            del self.pending[future]
        self.executor.restart()
        seen = [job for job in broken if id(job) in running]
        for job in broken:
            job.affected += 1
            if id(job) in running or job.affected >= 2 or not seen:
                self.suspects.append(job)
            else:
                self.submit(job, self.executor)
        self.bar.note(f"{self.study}: a worker process died; {len(self.suspects)} suspect "
                      f"case(s) will be rerun alone")


def _is_running(future: Any) -> bool:
    probe = getattr(future, "running", None)  # Dask futures have no running()
    return bool(probe()) if callable(probe) else False


def _lost(job: _Job, scenes: Mapping[str, Scene], message: str) -> Any:
    if job.kind == "prepare":
        return False, message
    return CaseResult(job.key, to_toml(scenes[job.key]), status="failed", message=message)


def _run_isolated(jobs: list[_Job], executor: Executor, scenes: Mapping[str, Scene],
                  finish: Callable[[_Job, Any], None]) -> None:
    """Rerun suspect jobs one at a time, each in a fresh single-worker process."""
    for job in jobs:
        alone = executor.isolated()
        try:
            job.started = time.perf_counter()
            future = alone.submit(*((guarded_preparation, job.function) if job.kind == "prepare"
                                    else (guarded_case, job.function)), *job.args)
            try:
                value = future.result()
            except BrokenProcessPool:
                value = _lost(job, scenes, "worker process died while running this case "
                              "(crash: e.g. a segmentation fault or out of memory)")
            except Exception as exc:  # noqa: BLE001
                value = _lost(job, scenes, f"{type(exc).__name__}: {exc}")
        finally:
            if alone is not executor:
                alone.close()
        finish(job, value)


# ------------------------------------------------------------------------------------------
# settings from the environment, and the old ``python -m flex.sweep`` entry
# ------------------------------------------------------------------------------------------
@dataclass
class SweepSettings:
    """Where and how a study's sweep runs (from the environment, see the module doc)."""

    scheduler: str | None = None
    workers: int | None = None
    folder: Path | None = None
    retry_failed: bool = False
    progress: bool = True


def settings_from_environment(environ: Mapping[str, str]) -> SweepSettings:
    """The sweep settings an edge reads from ``environ`` (its ``os.environ``):
    ``FLEX_SCHEDULER``, ``FLEX_WORKERS``, ``FLEX_SWEEP_DIR``, ``FLEX_RETRY_FAILED`` (1: rerun
    failed cases), ``FLEX_PROGRESS`` (0 hides the bar)."""
    workers = environ.get("FLEX_WORKERS") or None
    try:
        count = int(workers) if workers else None
    except ValueError:
        raise FlexError(f"FLEX_WORKERS = {workers!r}: must be an integer >= 1") from None
    folder = environ.get("FLEX_SWEEP_DIR") or None
    scheduler = environ.get("FLEX_SCHEDULER") or None
    try:
        check_scheduler(scheduler)
    except FlexError as exc:
        raise FlexError(f"FLEX_SCHEDULER: {exc}") from None
    return SweepSettings(scheduler=scheduler, workers=count,
                         folder=Path(folder) if folder else None,
                         retry_failed=environ.get("FLEX_RETRY_FAILED", "") == "1",
                         progress=environ.get("FLEX_PROGRESS", "1") != "0")

