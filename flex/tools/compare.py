"""Compare the curves of two result files on a common time base (``python -m flex compare``).

Contract
--------
Each case has its own ``time`` dataset. Two curves are compared on the overlap of their time
ranges, sampled on the finer of the two grids (the one with more samples in the overlap);
the other curve is interpolated onto it (cubic spline by default, or linear). Identical grids
are compared sample by sample without interpolation. A two-column curve (x, y) is compared
column by column. A curve (or column) **passes** when

    max |a(t) - b(t)|  <=  atol + rtol * max |b(t)|      over the common samples,

``a`` from the first file (A, the run under test) and ``b`` from the second (B, the
reference). A NaN in either curve, different units, or time ranges that do not overlap fail.
The comparison must cover the reference's time span: a curve whose common time base does not
reach from B's first to its last sample (a run that stops early or starts late, a shifted
curve) or holds a single instant (a one-sample file, either way round) fails, its note and
the time-base line saying exactly which span was compared and what fraction of B's span it
is (:class:`flex.tools.timebase.TimeBase`); ``partial=True`` (``--partial``) compares the
overlap anyway and says so.
Datasets without a time axis (``/summary`` tables, scalars) are compared element by element
with the same rule; text must be equal. A case that failed (status ``"failed"``) in either
file, among the cases compared, is a failure of its own: its row reads ``case X failed in A:
<the case's message> (<file>)``, and a PATH into it selects nothing instead of being an error.

Which datasets: the PATHs given (see :func:`flex.data.results.select_datasets` for the forms,
including the case shorthand and wildcards). A PATH that names one dataset missing from
either file is an error (exit 2). A PATH naming a group compares the datasets both files
have below it and lists the rest as *only in A* / *only in B*. Without PATH, every curve of
every case both files have is compared (``/summary`` tables only when named, e.g.
``summary``); time bases and wall-clock timings (``*wall_time_s``) are never compared unless
named.

:func:`compare_files` returns a :class:`Comparison`; the tests compare against reference
curves through the same function, so ``python -m flex compare`` reruns any test by hand.
"""

from __future__ import annotations

import math
import shlex
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import FlexError
from flex.data.results import (
    ResultFileError,
    ResultPathError,
    case_names,
    list_datasets,
    parse_spec,
    reading,
    select_datasets,
    split_case_path,
)
from flex.tools.timebase import TimeBase, common_time_base, resample

__all__ = ["Comparison", "Deviation", "TimeBase", "common_time_base", "compare_arrays",
           "compare_files", "resample"]

DEFAULT_RTOL = 1e-6
DEFAULT_ATOL = 0.0
INTERPOLATIONS = ("cubic", "linear")
TIMING_SUFFIX = "wall_time_s"


@dataclass
class Deviation:
    """The comparison of one curve (or one column of a two-column curve).

    ``max_abs_deviation`` is ``max |a - b|`` in ``units`` (NaN when a value is NaN or the
    curves cannot be compared; then ``note`` says why); ``time_s`` is where it occurs
    (``None`` for datasets without time; then ``where`` gives the index); ``allowed`` is
    ``atol + rtol * max |b|``.
    """

    path: str
    path_b: str
    column: int | None
    units: str
    max_abs_deviation: float
    allowed: float
    passed: bool
    time_s: float | None = None
    where: str = ""
    note: str = ""

    @property
    def label(self) -> str:
        """The curve as ``path[column]``, with B's path too if it differs."""
        column = "" if self.column is None else f"[{self.column}]"
        other = "" if self.path_b == self.path else f" ~ {self.path_b}{column}"
        return f"{self.path}{column}{other}"

    @property
    def ratio(self) -> float:
        """``max_abs_deviation / allowed`` (inf for a failure against a zero tolerance)."""
        if math.isnan(self.max_abs_deviation):
            return math.inf
        if self.max_abs_deviation == 0:
            return 0.0
        return self.max_abs_deviation / self.allowed if self.allowed > 0 else math.inf

    def as_dict(self) -> dict[str, Any]:
        return {"path": self.path, "path_b": self.path_b, "column": self.column,
                "units": self.units, "max_abs_deviation": _json_number(self.max_abs_deviation),
                "time_s": self.time_s, "where": self.where,
                "allowed": _json_number(self.allowed), "passed": self.passed,
                "note": self.note}


@dataclass
class Comparison:
    """Everything ``python -m flex compare`` found; ``passed`` decides the exit status."""

    file_a: str
    file_b: str
    rtol: float
    atol: float
    interpolation: str
    specs: list[str]
    deviations: list[Deviation] = field(default_factory=list)
    time_bases: list[TimeBase] = field(default_factory=list)
    only_in_a: list[str] = field(default_factory=list)
    only_in_b: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    #: compare the overlap when A does not cover B's time span (``--partial``)
    partial: bool = False
    #: no ``--rtol`` given: a curve whose case states its history error
    #: (``estimated_error_history_<path>``, :mod:`flex.fidelity.stored_budget`) is allowed
    #: ``atol`` + the root-sum-square of the two files' stated errors instead
    stated: bool = False

    @property
    def failures(self) -> list[Deviation]:
        return [d for d in self.deviations if not d.passed]

    @property
    def passed(self) -> bool:
        """True when at least one curve was compared and every one is within tolerance."""
        return bool(self.deviations) and not self.failures

    def command(self) -> str:
        """The shell command that repeats this comparison."""
        return shlex.join(["python", "-m", "flex", "compare", self.file_a, self.file_b,
                           *([] if self.stated else ["--rtol", f"{self.rtol:g}"]),
                           "--atol", f"{self.atol:g}",
                           *(["--interp", self.interpolation]
                             if self.interpolation != "cubic" else []),
                           *(["--partial"] if self.partial else []), *self.specs])

    def format(self, limit: int = 20) -> str:
        """A table, largest deviation (relative to its tolerance) first.

        Every failure is shown; passing rows up to ``limit`` in all (0: every row).
        """
        if not isinstance(limit, int) or limit < 0:
            raise FlexError(f"--limit {limit}: must be a whole number >= 0 (0 shows every "
                            f"row)")
        lines = [f"A: {self.file_a}", f"B: {self.file_b}",
                 f"pass if max|a - b| <= atol + rtol * max|b| for each curve (and column): "
                 f"rtol = {self.rtol:g}, atol = {self.atol:g}"
                 + ("; a curve whose cases state their history errors: atol + their "
                    "root-sum-square (no --rtol given)" if self.stated else "")]
        lines += [base.describe(self.interpolation) for base in self.time_bases]
        rows = sorted(self.deviations, key=lambda d: (d.passed, -d.ratio))
        shown = [d for i, d in enumerate(rows) if not d.passed or limit <= 0 or i < limit]
        lines.append(f"{'result':6s}  {'max|a-b|':>10s}  {'at':14s}  {'allowed':>10s}  "
                     f"{'dev/allowed':>11s}  {'units':8s}  curve")
        for d in shown:
            where = (f"t={d.time_s:.6g} s" if d.time_s is not None else d.where
                     ) if d.max_abs_deviation != 0 else "-"
            ratio = "inf" if math.isinf(d.ratio) else f"{d.ratio:.3g}"
            note = f"  ({d.note})" if d.note else ""
            lines.append(f"{'PASS' if d.passed else 'FAIL':6s}  "
                         f"{_number(d.max_abs_deviation):>10s}  {where:14s}  "
                         f"{_number(d.allowed):>10s}  {ratio:>11s}  {d.units:8s}  "
                         f"{d.label}{note}")
        hidden = len(rows) - len(shown)
        if hidden:
            lines.append(f"... {hidden} more within tolerance (--limit 0 shows all)")
        failed = len(self.failures)
        partly = [base for base in self.time_bases if base.shortfall()]
        lines.append(f"{len(self.deviations)} compared: {len(self.deviations) - failed} pass, "
                     f"{failed} fail -> {'PASS' if self.passed else 'FAIL'}"
                     + (f" (partial: {len(partly)} time base(s) do not cover the reference's "
                        f"span{'; accepted by --partial' if self.partial else ''})"
                        if partly else ""))
        for label, names in (("only in A", self.only_in_a), ("only in B", self.only_in_b),
                             ("not compared", self.skipped)):
            if names:
                more = f", ... ({len(names)} in all)" if len(names) > 4 else ""
                lines.append(f"{label}: {', '.join(names[:4])}{more}")
        return "\n".join(lines)

    def as_dict(self) -> dict[str, Any]:
        return {"file_a": self.file_a, "file_b": self.file_b, "rtol": self.rtol,
                "atol": self.atol, "interpolation": self.interpolation,
                "passed": self.passed, "partial": self.partial, "command": self.command(),
                "time_bases": [base.as_dict() for base in self.time_bases],
                "deviations": [d.as_dict() for d in self.deviations],
                "only_in_a": self.only_in_a, "only_in_b": self.only_in_b,
                "not_compared": self.skipped}


def _number(value: float) -> str:
    return "nan" if math.isnan(value) else f"{value:.3g}"


def _json_number(value: float) -> float | None:
    return None if math.isnan(value) or math.isinf(value) else float(value)


def allowed_deviation(reference: np.ndarray, rtol: float, atol: float) -> float:
    """The tolerance of one curve: ``atol + rtol * max |reference|`` (NaNs ignored)."""
    magnitude = np.abs(np.asarray(reference, dtype=float))
    finite = magnitude[np.isfinite(magnitude)]
    return atol + rtol * (float(finite.max()) if finite.size else 0.0)


def compare_arrays(a: np.ndarray, b: np.ndarray, rtol: float, atol: float,
                   time_s: np.ndarray | None = None, column_names: Sequence[int | None] = (None,)
                   ) -> list[tuple[int | None, float, float, bool, float | None, str, str]]:
    """Compare ``a`` with ``b`` (same shape) column by column.

    ``time_s`` (when given) labels the rows of ``a``/``b`` (n,) or (n, k). Returns per column
    ``(column, max_abs_deviation, allowed, passed, time_s_of_max, where, note)``.
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if time_s is not None and a.ndim == 2:
        pairs = [(c, a[:, c], b[:, c]) for c in range(a.shape[1])]
    else:
        pairs = [(column_names[0], a.reshape(-1), b.reshape(-1))]
    out = []
    for column, col_a, col_b in pairs:
        allowed = allowed_deviation(col_b, rtol, atol)
        deviation = np.abs(col_a - col_b)
        if deviation.size == 0:
            out.append((column, math.nan, allowed, False, None, "", "no samples"))
            continue
        bad = ~np.isfinite(deviation)
        if bad.any():
            index = int(np.argmax(bad))
            whose = [name for name, v in (("A", col_a[index]), ("B", col_b[index]))
                     if not np.isfinite(v)]
            note = f"non-finite value in {' and '.join(whose) or 'the difference'}"
            value = math.inf if np.isinf(deviation[index]) and whose != ["A", "B"] else math.nan
            out.append((column, value, allowed, False, _time_at(time_s, index),
                        _index_at(a, index, time_s), note))
            continue
        index = int(np.argmax(deviation))
        worst = float(deviation[index])
        out.append((column, worst, allowed, worst <= allowed, _time_at(time_s, index),
                    _index_at(a, index, time_s), ""))
    return out


def _time_at(time_s: np.ndarray | None, index: int) -> float | None:
    return None if time_s is None else float(time_s[index])


def _index_at(array: np.ndarray, flat_index: int, time_s: np.ndarray | None) -> str:
    if time_s is not None or array.ndim == 0:
        return ""
    index = np.unravel_index(flat_index, array.shape)
    return "index " + ",".join(str(int(i)) for i in index)


@dataclass
class _Side:
    """One file's view of a dataset: values, units, and (for a curve) its case time."""

    path: str
    values: Any
    units: str
    time_s: np.ndarray | None
    case: str | None
    #: the curve's stated history error [its units] (None: its case states none)
    stated_error: float | None = None


def compare_files(file_a: str | Path, file_b: str | Path, specs: Sequence[str] = (),
                  rtol: float | None = None, atol: float = DEFAULT_ATOL,
                  interpolation: str = "cubic", partial: bool = False) -> Comparison:
    """Compare the datasets ``specs`` name (all common ones when empty) of two result files.

    See the module documentation for the rule; ``partial``: compare a curve that does not
    cover B's time span on the overlap (else it fails). ``rtol`` None: a curve whose cases
    state their history errors is allowed ``atol`` + their root-sum-square, any other
    :data:`DEFAULT_RTOL`. Raises
    :class:`~flex.base.errors.FlexError` (:class:`ResultFileError` for a bad file or a
    missing path) when nothing can be compared.
    """
    stated, rtol = rtol is None, DEFAULT_RTOL if rtol is None else rtol
    for name, value in (("rtol", rtol), ("atol", atol)):
        if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
            raise FlexError(f"--{name} = {value!r}: must be a finite number >= 0")
    if interpolation not in INTERPOLATIONS:
        raise FlexError(f"--interp {interpolation!r}: must be one of {', '.join(INTERPOLATIONS)}")
    report = Comparison(str(file_a), str(file_b), float(rtol), float(atol), interpolation,
                        list(specs), partial=bool(partial), stated=stated)
    with reading(file_a) as h5a, reading(file_b) as h5b:
        pairs = _pairs(h5a, h5b, report, specs)
        if not pairs and not report.deviations:
            raise ResultPathError(f"nothing to compare: '{file_a}' and '{file_b}' have no "
                                  f"dataset in common" + (f" under {', '.join(specs)}"
                                                          if specs else ""))
        bases: dict[tuple[str, str], Any] = {}
        for path_a, path_b, column in pairs:
            side_a = _load(h5a, path_a, column, report.file_a)
            side_b = _load(h5b, path_b, column, report.file_b)
            report.deviations += _compare_sides(side_a, side_b, column, report, bases)
    return report


def _pairs(h5a, h5b, report: Comparison, specs: Sequence[str]
           ) -> list[tuple[str, str, int | None]]:
    """Pair A's datasets with B's; unpaired ones go to ``report.only_in_a``/``only_in_b``."""
    pairs: list[tuple[str, str, int | None]] = []
    if not specs:
        groups = [(_comparable(h5a, report), _comparable(h5b, report), None, False)]
        _case_status(h5a, h5b, report, case_names(h5a) + case_names(h5b))
    else:
        groups = []
        for spec in specs:
            path, column = parse_spec(spec)
            named = _cases_named(h5a, path) + _cases_named(h5b, path)
            failed = _failed_cases(h5a, named) | _failed_cases(h5b, named)
            in_a = _select(h5a, path, report.file_a, failed)
            in_b = _select(h5b, path, report.file_b, failed)
            _case_status(h5a, h5b, report, named)
            groups.append((in_a, in_b, column, len(in_a) == 1 and len(in_b) == 1))
    for in_a, in_b, column, single in groups:
        cases_a = {split_case_path(p)[0] for p in in_a}
        cases_b = {split_case_path(p)[0] for p in in_b}
        remap = (len(cases_a) == 1 and len(cases_b) == 1 and cases_a != cases_b
                 and None not in cases_a | cases_b)
        by_key = {(split_case_path(p)[1] if remap else p): p for p in in_b}
        used = set()
        unpaired_a = []
        for path_a in in_a:
            key = split_case_path(path_a)[1] if remap else path_a
            if key in by_key:
                pairs.append((path_a, by_key[key], column))
                used.add(by_key[key])
            else:
                unpaired_a.append(path_a)
        unpaired_b = [p for p in in_b if p not in used]
        if single and (unpaired_a or unpaired_b):
            raise ResultPathError(f"cannot pair {in_a[0]} in '{report.file_a}' with "
                                  f"{in_b[0]} in '{report.file_b}'")
        report.only_in_a += [p for p in unpaired_a if p not in report.only_in_a]
        report.only_in_b += [p for p in unpaired_b if p not in report.only_in_b]
    return pairs


def _comparable(h5, report: Comparison) -> list[str]:
    """Every dataset of a file's cases except the time bases and wall-clock timings."""
    out = []
    for path in list_datasets(h5):
        case, rel = split_case_path(path)
        if case is None or rel == "time":
            continue
        if path.endswith(TIMING_SUFFIX):
            if path not in report.skipped:
                report.skipped.append(path)
            continue
        out.append(path)
    return out


def _case_status(h5a, h5b, report: Comparison, cases: Sequence[str]) -> set[str]:
    """A case that failed in A or in B is a row of its own (not a missing dataset): a
    failure when it failed in one file only, a passing row when it failed in both.

    Adds one failed :class:`Deviation` per such case among ``cases``, its note naming the
    case, the file and the case's message (``case X failed in A: <message> (file)``);
    returns the names of the failed cases (each reported once per comparison).
    """
    failed = set()
    for case in dict.fromkeys(cases):
        notes: list[str] = []
        sides = 0
        for side, h5, label in (("A", h5a, report.file_a), ("B", h5b, report.file_b)):
            if case not in _failed_cases(h5, [case]):
                continue
            sides += 1
            attrs = h5[f"cases/{case}"].attrs
            message = " ".join(_text(attrs.get("message", "")).split()) or "no message"
            if notes and notes[0].endswith(f": {message} ({report.file_a})"):
                notes.append(f"and in B ({label})")
            else:
                notes.append(f"case {case} failed in {side}: {message} ({label})")
        if not notes:
            continue
        failed.add(case)
        path = f"cases/{case}"
        if any(d.path == path and d.units == "" and d.note.startswith(f"case {case} failed")
               for d in report.deviations):
            continue
        # failed in both files: the same outcome, not a difference (a stability file
        # compared with itself passes); failed in one only: a difference
        report.deviations.append(Deviation(path, path, None, "", math.nan, 0.0, sides == 2,
                                           note="; ".join(notes)))
    return failed


def _failed_cases(h5, cases: Sequence[str]) -> set[str]:
    """Those of ``cases`` that are in ``h5`` with a status other than ``"ok"``."""
    present = set(case_names(h5))
    return {case for case in cases if case in present
            and _text(h5[f"cases/{case}"].attrs.get("status", "ok")) != "ok"}


def _cases_named(h5, spec: str) -> list[str]:
    """The cases of ``h5`` a PATH (without ``[column]``) refers to, in the forms of
    :func:`select_datasets`: ``cases/<case>/...``, ``<case>/...`` (wildcards allowed),
    every case for an empty PATH or ``cases``, or the only case for a path inside it."""
    import fnmatch

    cases = case_names(h5)
    spec = spec.strip().strip("/")
    parts = spec.split("/")
    if not spec or spec == "cases":
        return cases
    wild = any(char in spec for char in "*?")
    if parts[0] == "cases":
        pattern = parts[1]
    elif not wild and _contains(h5, spec):
        return []  # a path outside the cases (/summary/...)
    else:
        pattern = parts[0]
    named = [case for case in cases if fnmatch.fnmatchcase(case, pattern)]
    if not named and len(cases) == 1 and parts[0] != "cases":
        return cases  # the one-case shorthand: crank/angle
    return named


def _contains(h5, path: str) -> bool:
    try:
        return path in h5
    except (KeyError, ValueError, TypeError):
        return False


def _select(h5, path: str, label: str, failed: set[str]) -> list[str]:
    """:func:`select_datasets`, except that a PATH into a failed case (named without
    wildcards) selects nothing, instead of raising: the failure is reported instead."""
    try:
        return select_datasets(h5, path, label)
    except ResultPathError:
        if not any(char in path for char in "*?") and failed & set(_cases_named(h5, path)):
            return []
        raise


def _text(value: Any) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def _load(h5, path: str, column: int | None, label: str) -> _Side:
    dataset = h5[path]
    values = dataset[()]
    units = _text(dataset.attrs.get("units", ""))
    if column is not None:
        if np.ndim(values) != 2 or column >= np.shape(values)[1]:
            raise ResultPathError(f"{path}[{column}] in '{label}': no such column (shape "
                                  f"{np.shape(values)})")
        values = values[:, column]
    case, rel = split_case_path(path)
    time_s = None
    if case is not None and rel != "time" and f"cases/{case}/time" in h5:
        candidate = np.asarray(h5[f"cases/{case}/time"][()], dtype=float)
        if (candidate.ndim == 1 and np.ndim(values) in (1, 2)
                and np.shape(values)[0] == len(candidate) and len(candidate) > 0
                and _numeric(values)):
            if len(candidate) > 1 and not np.all(np.diff(candidate) > 0):
                raise ResultFileError(f"result file '{label}': cases/{case}/time is not "
                                      f"strictly increasing")
            time_s = candidate
    stated = None
    if time_s is not None and column is None:
        value = h5[f"cases/{case}"].attrs.get(f"estimated_error_history_{rel.replace('/', '_')}")
        stated = float(value) if isinstance(value, int | float | np.floating) and \
            math.isfinite(value) and value >= 0 else None
    return _Side(path, values, units, time_s, case, stated)


def _numeric(values: Any) -> bool:
    return isinstance(values, np.ndarray) and values.dtype.kind in "biuf"


def _compare_sides(a: _Side, b: _Side, column: int | None, report: Comparison,
                   bases: dict[tuple[str, str], Any]) -> list[Deviation]:
    def failed(note: str) -> list[Deviation]:
        return [Deviation(a.path, b.path, column, a.units, math.nan, 0.0, False, note=note)]

    if a.units != b.units:
        return failed(f"units differ: {a.units!r} in A, {b.units!r} in B")
    if not _numeric(np.asarray(a.values)) or not _numeric(np.asarray(b.values)):
        text_a, text_b = _as_text(a.values), _as_text(b.values)
        if text_a == text_b:
            return [Deviation(a.path, b.path, column, a.units, 0.0, 0.0, True, note="text")]
        return failed("text differs")
    if (a.time_s is None) != (b.time_s is None):
        return failed("a curve in one file, not in the other (no matching time base)")
    short = ""
    if a.time_s is None:
        values_a, values_b = np.asarray(a.values), np.asarray(b.values)
        if values_a.shape != values_b.shape:
            return failed(f"shapes differ: {values_a.shape} in A, {values_b.shape} in B")
        rows = compare_arrays(values_a, values_b, report.rtol, report.atol,
                              column_names=(column,))
    else:
        key = (a.case or "", b.case or "")
        if key not in bases:
            bases[key] = common_time_base(a.time_s, b.time_s)
            if bases[key] is not None:
                base, source, _, _ = bases[key]
                report.time_bases.append(TimeBase(
                    key[0], key[1], float(base[0]), float(base[-1]), len(base), source,
                    float(a.time_s[0]), float(a.time_s[-1]), float(b.time_s[0]),
                    float(b.time_s[-1])))
        if bases[key] is None:
            return failed(f"time ranges do not overlap: {a.time_s[0]:g}..{a.time_s[-1]:g} s "
                          f"in A, {b.time_s[0]:g}..{b.time_s[-1]:g} s in B")
        base, source, in_a, in_b = bases[key]
        short = next(t for t in report.time_bases if (t.case_a, t.case_b) == key).shortfall()
        if short and not report.partial:
            return failed(f"not the whole reference: {short}; --partial compares the "
                          f"overlap only")
        values_a = np.asarray(a.values, dtype=float)
        values_b = np.asarray(b.values, dtype=float)
        if values_a.shape[1:] != values_b.shape[1:]:
            return failed(f"columns differ: {values_a.shape} in A, {values_b.shape} in B")
        on_a = values_a[in_a] if source in ("identical", "A") else resample(
            a.time_s, values_a, base, report.interpolation)
        on_b = values_b[in_b] if source in ("identical", "B") else resample(
            b.time_s, values_b, base, report.interpolation)
        rows = compare_arrays(on_a, on_b, report.rtol, report.atol, time_s=base,
                              column_names=(column,))
    if a.time_s is not None and short:
        rows = [(*row[:6], "; ".join(filter(None, [row[6], f"partial: {short}"])))
                for row in rows]
    if report.stated and a.time_s is not None and (a.stated_error, b.stated_error) != (None,
                                                                                      None):
        allowed = report.atol + math.hypot(a.stated_error or 0.0, b.stated_error or 0.0)
        rows = [(col, worst, allowed, worst <= allowed, time_s, where,
                 "; ".join(filter(None, [note, "allowed: the stated history errors"])))
                for col, worst, _, _, time_s, where, note in rows]
    return [Deviation(a.path, b.path, col, a.units, worst, allowed, passed, time_s, where, note)
            for col, worst, allowed, passed, time_s, where, note in rows]


def _as_text(values: Any) -> list[str]:
    array = np.asarray(values, dtype=object).reshape(-1)
    return [_text(v) for v in array]
