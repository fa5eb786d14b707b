"""Running a study's cases, one after the other or on an executor, reporting progress.

:func:`run_each` is the loop of a study's ``simulate_cases`` (:mod:`flex.study`): it calls
``progress(case, done, total)`` for each case and ``progress("done", total, total)`` at the
end, the protocol of :func:`flex.study.progress_printer`. Given an ``executor`` (one of
:mod:`flex.sweep`'s: ``submit(function, *args)``, ``wait_first(futures, timeout)`` and
``abort()``, called when an interrupt ends the loop; the
study passes it in, this module sits below the sweep engine) the cases run in parallel, in
jobs: the cases of one ``group`` key run one after the other in one job, in their order
(cases that share a reduction: it is built once, as when they run in this process), and the
jobs are submitted longest first when a ``cost`` is given. The results are the same, in the
order of ``scenes``; ``run_one`` must then be picklable (a module-level function or a
``functools.partial`` of one).
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Any

#: a scene (flex.data.scene.Scene; this module sits below it): sections of keys and values
Scene = dict[str, dict[str, Any]]

Progress = Callable[[str, int, int], None]


def run_each(scenes: dict[str, Scene], run_one: Callable[[str, Scene], Any],
             progress: Progress | None = None, *, executor: Any = None,
             group: Callable[[str, Scene], Hashable | None] | None = None,
             cost: Callable[[str, Scene], float] | None = None) -> dict[str, Any]:
    """``{name: run_one(name, scene)}`` over ``scenes`` in order, reporting progress;
    with an ``executor``, in parallel jobs (module doc): ``group(name, scene)`` keys the
    cases that run together (None: a job of its own), ``cost(name, scene)`` orders the jobs
    (the largest summed cost first; default: the order of ``scenes``)."""
    if executor is None:
        results = {}
        for index, (name, scene) in enumerate(scenes.items()):
            if progress:
                progress(name, index, len(scenes))
            results[name] = run_one(name, scene)
    else:
        results = _run_jobs(scenes, run_one, progress, executor, group, cost)
    if progress:
        progress("done", len(scenes), len(scenes))
    return {name: results[name] for name in scenes}


def run_job(run_one: Callable[[str, Scene], Any], cases: list[tuple[str, Scene]]
            ) -> list[tuple[str, Any]]:
    """One job of :func:`run_each` (on a worker): its cases one after the other."""
    return [(name, run_one(name, scene)) for name, scene in cases]


def _run_jobs(scenes: dict[str, Scene], run_one: Callable[[str, Scene], Any],
              progress: Progress | None, executor: Any,
              group: Callable[[str, Scene], Hashable | None] | None,
              cost: Callable[[str, Scene], float] | None) -> dict[str, Any]:
    jobs: dict[Hashable, list[tuple[str, Scene]]] = {}
    for index, (name, scene) in enumerate(scenes.items()):
        key = group(name, scene) if group else None
        jobs.setdefault(("case", index) if key is None else ("group", key), []).append(
            (name, scene))
    ordered = list(jobs.values())
    if cost is not None:  # longest first: the last job to start is a short one
        ordered.sort(key=lambda cases: -sum(cost(name, scene) for name, scene in cases))
    pending = {executor.submit(run_job, run_one, cases): cases for cases in ordered}
    results: dict[str, Any] = {}
    try:
        while pending:
            for future in executor.wait_first(list(pending), timeout=None):
                pending.pop(future)
                for name, value in future.result():
                    if progress:
                        progress(name, len(results), len(scenes))
                    results[name] = value
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM: the running jobs are abandoned
        executor.abort()
        raise
    return results
