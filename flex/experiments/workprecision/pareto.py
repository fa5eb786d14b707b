"""The Pareto front of measured settings and the setting recommended per accuracy level.

:func:`pareto_front` marks the settings no other setting beats in both wall time and error;
:func:`recommend` picks, per accuracy level, the fastest setting whose measured error plus
the reference's accuracy is within it (it lies on the front of the candidates), refusing
levels finer than the reference can certify
(:func:`~flex.experiments.workprecision.measurement.certifies`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from flex.experiments.workprecision.measurement import Measurement, Reference, certifies

#: relative accuracy levels for which a setting is recommended (1 %, 0.1 %, 0.01 %)
ACCURACY_LEVELS = (1e-2, 1e-3, 1e-4)
#: wall times within this fraction of the fastest count as a tie (broken by accuracy)
TIE_FRACTION = 0.1


def pareto_front(points: Sequence[tuple[float, float]]) -> list[int]:
    """Indices of the non-dominated (wall time, error) points, by increasing wall time.

    A point is dominated if another is no slower and no less accurate and better in one of
    the two. Points with a non-finite coordinate are never on the front.
    """
    finite = [i for i, (wall, error) in enumerate(points)
              if math.isfinite(wall) and math.isfinite(error)]
    finite.sort(key=lambda i: (points[i][0], points[i][1]))
    front: list[int] = []
    best_error = math.inf
    for i in finite:
        if points[i][1] < best_error:
            front.append(i)
            best_error = points[i][1]
    return front


@dataclass
class Recommendation:
    """The fastest measured setting within an accuracy ``level`` (relative), or why none."""

    level: float
    measurement: Measurement | None
    reason: str = ""


def recommend(measurements: Iterable[Measurement], reference: Reference,
              levels: Sequence[float] = ACCURACY_LEVELS,
              eligible: Callable[[Measurement], bool] | None = None) -> list[Recommendation]:
    """Per accuracy level the fastest ``ok`` measurement whose error is certified within it,
    ``error + reference.accuracy <= level`` (the reference's own error could add to the
    measured one; ties by :func:`fastest`).

    Levels finer than ``REFERENCE_MARGIN`` x the reference's own accuracy are refused (the
    reference cannot tell such errors apart). ``eligible`` filters the candidates (e.g. only
    settings of flex's Exudyn model, not the scipy reference). The chosen setting is on the
    Pareto front of the candidates.
    """
    candidates = [m for m in measurements if m.ok and (eligible is None or eligible(m))]
    out = []
    for level in levels:
        if not certifies(reference.accuracy, level):
            out.append(Recommendation(level, None, f"reference accurate to "
                                      f"{reference.accuracy:.1e} only: cannot certify "
                                      f"{level:.0e}"))
            continue
        # certified: the measured error plus the reference's own possible error
        within = [m for m in candidates if m.error + reference.accuracy <= level]
        if not within:
            out.append(Recommendation(level, None, "no measured setting reaches it"))
            continue
        out.append(Recommendation(level, fastest(within)))
    return out


def fastest(measurements: Sequence[Measurement]) -> Measurement:
    """The fastest measurement; settings within :data:`TIE_FRACTION` of its wall time count
    as equally fast (timing noise on a shared machine) and the most accurate of them wins.
    The pick is never dominated, so it lies on the Pareto front."""
    quickest = min(m.wall_time_s for m in measurements)
    ties = [m for m in measurements if m.wall_time_s <= quickest * (1 + TIE_FRACTION)]
    return min(ties, key=lambda m: (m.error, m.wall_time_s))
