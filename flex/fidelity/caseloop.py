"""Running a study's cases one after the other, reporting progress.

:func:`run_each` is the loop of a study's ``simulate_cases`` (:mod:`flex.study`): it calls
``progress(case, done, total)`` before each case and ``progress("done", total, total)`` at
the end, the protocol of :func:`flex.study.progress_printer`.
"""

from __future__ import annotations

from collections.abc import Callable

from flex.data.results import CaseResult
from flex.data.scene import Scene

Progress = Callable[[str, int, int], None]


def run_each(scenes: dict[str, Scene], run_one: Callable[[str, Scene], CaseResult],
             progress: Progress | None = None) -> dict[str, CaseResult]:
    """``{name: run_one(name, scene)}`` over ``scenes`` in order, reporting progress."""
    results = {}
    for index, (name, scene) in enumerate(scenes.items()):
        if progress:
            progress(name, index, len(scenes))
        results[name] = run_one(name, scene)
    if progress:
        progress("done", len(scenes), len(scenes))
    return results
