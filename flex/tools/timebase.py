"""The time base two curves are compared on, and how much of the reference it covers.

Used by :mod:`flex.tools.compare`. Two cases' curves are compared on the overlap of their time
ranges, on the finer grid (:func:`common_time_base`), the other curve interpolated onto it
(:func:`resample`). A comparison must cover the reference's (B's) time span: a run that
stops early, starts late (a shifted curve) or holds one sample compares only part of it, or
a single instant. :class:`TimeBase` records the span compared and the reference's span, and
:meth:`TimeBase.shortfall` says what was not covered ("" when all of it was); ``compare``
fails such a curve unless told to accept a partial comparison (``--partial``). Times in s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class TimeBase:
    """The common time base of one pair of cases: the span compared, ``start_s`` ..
    ``end_s`` [s] in ``samples`` samples of ``source``'s grid (``"identical"``, ``"A"`` or
    ``"B"``), and each file's own span (``a_start_s`` .. ``a_end_s``, ``b_start_s`` ..
    ``b_end_s``; B is the reference)."""

    case_a: str
    case_b: str
    start_s: float
    end_s: float
    samples: int
    source: str
    a_start_s: float = 0.0
    a_end_s: float = 0.0
    b_start_s: float = 0.0
    b_end_s: float = 0.0

    @property
    def coverage(self) -> float:
        """Fraction of B's time span compared (1.0 for a whole span; 0.0 for a single
        instant of a longer span; 1.0 when B itself is a single sample that was compared)."""
        span = self.b_end_s - self.b_start_s
        if span <= 0:
            return 1.0 if self.samples else 0.0
        return max(0.0, min(1.0, (self.end_s - self.start_s) / span))

    def shortfall(self) -> str:
        """What of B's span the comparison does not cover ("" when it covers all of it with
        at least two samples): one phrase for a note."""
        slack = 1e-9 * max(abs(self.b_start_s), abs(self.b_end_s),
                           self.b_end_s - self.b_start_s, 1e-300)
        if self.samples < 2:
            only = "one sample" if self.b_end_s == self.b_start_s else "one common sample"
            return (f"{only} (t = {self.start_s:.6g} s): a single instant, not a curve "
                    f"({self.span_text()})")
        if self.start_s > self.b_start_s + slack or self.end_s < self.b_end_s - slack:
            return f"compared {self.span_text()}"
        return ""

    def span_text(self) -> str:
        """``0 .. 0.005 s of B's 0 .. 0.03 s (17 %)``."""
        return (f"{self.start_s:.6g} .. {self.end_s:.6g} s of B's {self.b_start_s:.6g} .. "
                f"{self.b_end_s:.6g} s ({100 * self.coverage:.3g} %; A: {self.a_start_s:.6g} "
                f".. {self.a_end_s:.6g} s)")

    def describe(self, interpolation: str) -> str:
        """One line for the report: the span, the samples and how they were matched."""
        case = self.case_a if self.case_a == self.case_b else f"{self.case_a} ~ {self.case_b}"
        if self.source == "identical":
            how = "identical grids, no interpolation"
        else:
            other = "B" if self.source == "A" else "A"
            how = f"{self.source}'s samples, {other} interpolated: {interpolation}"
        short = self.shortfall()
        cover = f"; NOT the whole reference: {short}" if short else "; covers B's whole span"
        return (f"time base {case}: {self.start_s:.6g} .. {self.end_s:.6g} s, "
                f"{self.samples} samples ({how}){cover}")

    def as_dict(self) -> dict[str, object]:
        """For ``compare --json``."""
        return {**self.__dict__, "coverage": self.coverage, "shortfall": self.shortfall()}


def common_time_base(time_a: np.ndarray, time_b: np.ndarray
                     ) -> tuple[np.ndarray, str, np.ndarray, np.ndarray] | None:
    """The samples two time grids are compared on, or ``None`` if they do not overlap.

    Returns ``(base, source, in_a, in_b)``: ``source`` is ``"identical"`` (same samples in
    the overlap), ``"A"`` or ``"B"`` (the grid with more samples in the overlap; ties take
    A); ``in_a``/``in_b`` are boolean masks of each grid's samples inside the overlap.
    """
    start, end = max(time_a[0], time_b[0]), min(time_a[-1], time_b[-1])
    if start > end:
        return None
    slack = 1e-9 * max(abs(start), abs(end), end - start, 1e-300)
    in_a = (time_a >= start - slack) & (time_a <= end + slack)
    in_b = (time_b >= start - slack) & (time_b <= end + slack)
    if in_a.sum() == in_b.sum() and np.array_equal(time_a[in_a], time_b[in_b]):
        return time_a[in_a], "identical", in_a, in_b
    if in_a.sum() >= in_b.sum():
        return time_a[in_a], "A", in_a, in_b
    return time_b[in_b], "B", in_a, in_b


def resample(time_s: np.ndarray, values: np.ndarray, base: np.ndarray,
             interpolation: str = "cubic") -> np.ndarray:
    """``values`` (n,) or (n, k) sampled at ``time_s`` (strictly increasing), at ``base``.

    ``interpolation``: ``"cubic"`` (not-a-knot cubic spline; linear below 4 samples) or
    ``"linear"``. ``base`` must lie within ``time_s``'s range (the overlap).
    """
    values = np.asarray(values, dtype=float)
    base = np.clip(base, time_s[0], time_s[-1])
    with np.errstate(all="ignore"):
        if interpolation == "cubic" and len(time_s) >= 4 and np.isfinite(values).all():
            from scipy.interpolate import CubicSpline

            try:
                return CubicSpline(time_s, values, axis=0)(base)
            except ValueError:  # slopes overflow (values near the float limit): linear
                pass
        # linear: a NaN or inf stays where it is, and the comparison reports it
        if values.ndim == 1:
            return np.interp(base, time_s, values)
        return np.stack([np.interp(base, time_s, column) for column in values.T], axis=1)
