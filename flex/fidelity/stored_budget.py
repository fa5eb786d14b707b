"""A run's error budget as data: the budget in memory, its case attributes (writing), reading
them back from a stored case, checking and printing them -- one module for the stored budget,
apart from computing it (:mod:`flex.fidelity.error_budget`).

An :class:`ErrorBudget` holds each headline quantity's value and its terms (step, modes, mesh,
model) [the quantity's unit]; its total is their root-sum-square (:func:`combined`; a
bound's, their sum), its certificate the total times :data:`CERTIFICATE_FACTOR`.
:meth:`ErrorBudget.attrs` writes it as case attributes (``headline_<quantity>``,
``estimated_error_<quantity>``, ``..._<term>``, ...);
:func:`budget_rows` reads a stored case's attributes back as :class:`BudgetRow` s, checking each
(unknown, inconsistent, malformed); :meth:`ErrorBudget.rows` gives the same rows from memory
(what refinement decides on, with no round trip through the attributes);
:func:`headline_attrs` writes a run's headline values whether or not its budget is estimated.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from flex.data.headlines import BUILTIN_HEADLINES, Headline

#: case attribute prefix of an estimated error
PREFIX = "estimated_error_"

TERMS = ("step", "modes", "mesh", "model")
#: case attribute prefix of a headline quantity's value
HEADLINE_PREFIX = "headline_"
#: a budget's certificate over its estimate: the grid convergence index's safety factor for
#: a study whose order is known (Roache 1998: 1.25 with three or more grids in the asymptotic
#: range); a step term outside that range is already a bound (3x its larger difference) and
#: the mesh term's order 2 lies below the orders observed (4.1 on the 2 mm plate)
CERTIFICATE_FACTOR = 1.25
#: case attribute holding :data:`CERTIFICATE_FACTOR` as the budget applied it
CERTIFICATE_ATTR = f"{PREFIX}certificate_factor"



@dataclass
class ErrorBudget:
    """A run's error budget (see the module doc): ``terms[quantity][term]`` [its units],
    ``values[quantity]`` (the run's value), one sentence per term in ``methods``, what the
    budget leaves out, the step estimate's ``validity`` and the companions' wall time."""

    values: dict[str, float] = field(default_factory=dict)
    terms: dict[str, dict[str, float]] = field(default_factory=dict)
    methods: dict[str, str] = field(default_factory=dict)
    leaves_out: list[str] = field(default_factory=list)
    validity: str = ""
    companion_wall_time_s: float = 0.0
    #: a peak deflection's crest gap [m]: the second-largest crest's distance below it
    crest_gaps: dict[str, float] = field(default_factory=dict)
    #: each quantity's (unit, what): stored with the budget, so readers need no registry
    described: dict[str, tuple[str, str]] = field(default_factory=dict)
    #: why a term is unknown (NaN in ``terms``, making its quantities' totals unknown), one
    #: phrase per term that could not be measured
    unknown: list[str] = field(default_factory=list)
    #: the quantities whose step term is a bound (observed order outside the window)
    step_bounds: tuple[str, ...] = ()
    #: the quantities whose total is a bound, not an estimate: the raw peaks
    #: (:attr:`flex.data.headlines.Headline.bound`)
    bounds: tuple[str, ...] = ()
    #: the run whose values the budget states when it is not the run itself: the step's
    #: finest companion (:func:`flex.fidelity.error_estimate.estimate_step_error`'s
    #: ``finest``; a :class:`flex.data.results.CaseResult`), reported in the run's place
    reported_run: Any = field(default=None, repr=False, compare=False)

    def total(self, quantity: str) -> float:
        """The root-sum-square of the quantity's terms [its units] (module doc); a bound's
        (:attr:`bounds`) their sum."""
        return combined(self.terms[quantity].values(), quantity in self.bounds)

    def relative(self, quantity: str) -> float:
        """The total over the quantity's magnitude (NaN for a zero quantity)."""
        value = abs(self.values[quantity])
        return self.total(quantity) / value if value > 0 else math.nan

    def attrs(self) -> dict[str, Any]:
        """Case attributes: ``headline_<quantity>`` (the run's value, in the unit its name
        ends with), ``estimated_error_<quantity>`` (the total, same unit), ``..._<term>``
        per term, ``..._relative``; ``estimated_error_method`` (one sentence per term),
        ``_leaves_out``, ``_validity``, ``_companion_wall_time_s``; :data:`DESCRIBED`: each
        quantity's unit and what it is, one line each (tab-separated)."""
        out: dict[str, Any] = {}
        for quantity, terms in self.terms.items():
            out[f"{HEADLINE_PREFIX}{quantity}"] = self.values[quantity]
            out[f"{PREFIX}{quantity}"] = self.total(quantity)
            out[f"{PREFIX}{quantity}_relative"] = self.relative(quantity)
            out.update({f"{PREFIX}{quantity}_{term}": value for term, value in terms.items()})
        out[CERTIFICATE_ATTR] = CERTIFICATE_FACTOR
        out.update({f"{PREFIX}method": "; ".join(f"{term}: {text.rstrip('.')}" for term, text
                                                 in self.methods.items()) + ".",
                    f"{PREFIX}leaves_out": "; ".join(self.leaves_out) or "nothing flex knows of",
                    f"{PREFIX}validity": self.validity,
                    f"{PREFIX}companion_wall_time_s": self.companion_wall_time_s})
        out.update({f"{CREST_GAP_PREFIX}{quantity}": gap
                    for quantity, gap in self.crest_gaps.items()})
        if self.described:
            out[DESCRIBED] = "\n".join(f"{quantity}\t{unit}\t{what}" for quantity, (unit, what)
                                       in self.described.items())
        if self.unknown:
            out[UNKNOWN_ATTR] = "; ".join(self.unknown)
        out[STEP_BOUNDS_ATTR] = ", ".join(self.step_bounds)
        out[BOUNDS_ATTR] = ", ".join(self.bounds)
        return out

    def unknown_quantities(self) -> list[str]:
        """The quantities whose total is unknown (a term that could not be measured)."""
        return [name for name in self.terms if not math.isfinite(self.total(name))]

    def rows(self) -> list[BudgetRow]:
        """Its rows from memory, as :func:`budget_rows` reads them back from :meth:`attrs`
        (the same numbers, no round trip through the attributes), certified with
        :data:`CERTIFICATE_FACTOR`."""
        out = []
        for quantity, terms in self.terms.items():
            unit, what = self.described.get(quantity, ("", quantity))
            unmeasured = [term for term, value in terms.items() if math.isnan(value)]
            row = (BudgetRow(quantity, what, unit, self.values[quantity], math.nan, math.nan,
                             dict(terms), _not_measured(unmeasured)) if unmeasured else
                   BudgetRow(quantity, what, unit, self.values[quantity], self.total(quantity),
                             self.relative(quantity), dict(terms)))
            out.append(replace(row, certificate_factor=CERTIFICATE_FACTOR,
                               bound=quantity in self.bounds))
        return out


def _not_measured(terms: list[str]) -> str:
    """A row's problem when its ``terms`` could not be measured (NaN)."""
    return f"unknown ({', '.join(terms)} term not measured: see 'unknown')"


#: case attribute: what the tolerance covered, one ``quantity<TAB>status<TAB>certified
#: relative error`` line per quantity asked (status ``met``, ``missed``, ``unknown``: its
#: budget has no total, ``absent``: the run does not have it)
COVERAGE_ATTR = "tolerance_covered"


def tolerance_coverage(rows: list[BudgetRow], asked: tuple[str, ...], relative: float
                       ) -> list[tuple[str, str, float]]:
    """Each quantity ``asked``: its status against the tolerance ``relative`` [1] and its
    certified relative error (NaN where unknown or absent), from a budget's ``rows``."""
    by_name = {row.quantity: row for row in rows}
    out = []
    for name in asked:
        row = by_name.get(name)
        certified = row.certified_relative if row is not None else math.nan
        status = ("absent" if row is None else "unknown" if not math.isfinite(certified)
                  else "met" if certified <= relative else "missed")
        out.append((name, status, certified))
    return out


def coverage_attrs(coverage: list[tuple[str, str, float]], relative: float) -> dict[str, Any]:
    """Case attributes of :func:`tolerance_coverage`: :data:`COVERAGE_ATTR`,
    ``tolerance_relative`` [1] and ``tolerance_met`` (every quantity asked that the run has
    met: none missed, none unknown)."""
    return {COVERAGE_ATTR: "\n".join(f"{name}\t{status}\t{certified!r}"
                                     for name, status, certified in coverage),
            "tolerance_relative": relative,
            "tolerance_met": all(status in ("met", "absent") for _, status, _ in coverage)}


def coverage_text(coverage: list[tuple[str, str, float]], relative: float) -> str:
    """One line: the tolerance, then the quantities grouped by status with their certified
    relative errors (``"tolerance 0.1 % of each quantity: met: deployment_time_s (0.045 %);
    missed: coupler_deployment_peak_deflection_m (0.11 %)"``)."""
    groups: dict[str, list[str]] = {}
    for name, status, certified in coverage:
        shown = f" ({100 * certified:.2g} %)" if math.isfinite(certified) else ""
        groups.setdefault(status, []).append(name + shown)
    return (f"tolerance {100 * relative:g} % of each quantity (certified, relative to itself): "
            + "; ".join(f"{status}: {', '.join(names)}" for status, names in groups.items()))


def stored_coverage(attrs: Mapping[str, Any]) -> list[tuple[str, str, float]]:
    """:func:`tolerance_coverage` as a case stores it (none in a file written before)."""
    text = attrs.get(COVERAGE_ATTR, "")
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    out = []
    for line in str(text).splitlines():
        parts = line.split("\t")
        if len(parts) == 3:
            try:
                out.append((parts[0], parts[1], float(parts[2])))
            except ValueError:
                out.append((parts[0], parts[1], math.nan))
    return out


def headline_attrs(datasets: Mapping[str, Any],
                   headlines: Mapping[str, Headline] = BUILTIN_HEADLINES) -> dict[str, Any]:
    """A run's headline values as case attributes, ``headline_<quantity>`` [its unit], and
    :data:`DESCRIBED`, whether or not its budget is estimated (a quantity the run does not
    have is not written)."""
    values = {name: headline.read(datasets) for name, headline in headlines.items()}
    values = {name: value for name, value in values.items() if value is not None}
    out: dict[str, Any] = {f"{HEADLINE_PREFIX}{name}": value for name, value in values.items()}
    if values:
        out[DESCRIBED] = "\n".join(f"{name}\t{headlines[name].unit}\t{headlines[name].what}"
                                   for name in values)
    return out


def combined(terms: Any, bound: bool = False) -> float:
    """The total of independent error terms: their root-sum-square [their units]; of a
    bound's terms (a raw peak's: no independence to lean on) their sum."""
    if bound:
        return float(math.fsum(terms))
    return float(math.sqrt(math.fsum(value * value for value in terms)))


#: case attribute of a budget's quantities, one ``name<TAB>unit<TAB>what`` line each
DESCRIBED = "headlines_described"
#: case attribute saying why a budget's unknown terms (NaN) could not be measured
UNKNOWN_ATTR = f"{PREFIX}unknown"
#: the quantities whose step term is a bound, comma-separated ("" when every one is an estimate)
STEP_BOUNDS_ATTR = f"{PREFIX}step_bounds"
#: the quantities whose total is a bound, not an estimate (the raw peaks),
#: comma-separated
BOUNDS_ATTR = f"{PREFIX}bounds"
#: case attribute prefix of a peak's crest gap (:func:`flex.data.headlines.crest_gap`)
CREST_GAP_PREFIX = "crest_gap_"




@dataclass(frozen=True)
class BudgetRow:
    """One headline quantity of a stored case, for display: its name, what it is, units,
    value, total estimated error, relative error and the terms (from the case attributes);
    ``problem``: "" for a budget that holds, else why its total cannot be shown (``unknown:
    ...``, ``inconsistent: ...``, ``malformed: ...``; the total is then NaN)."""

    quantity: str
    what: str
    units: str
    value: float
    total: float
    relative: float
    terms: dict[str, float]
    problem: str = ""
    #: the certificate's factor over the estimate (NaN: a file written before certificates)
    certificate_factor: float = math.nan
    #: the total is a bound, not an estimate (a raw peak, :data:`BOUNDS_ATTR`)
    bound: bool = False
    #: why a stored certificate factor cannot be used ("" if it can, or none is stored)
    certificate_problem: str = ""

    @property
    def value_text(self) -> str:
        """The value with its units, or ``no value`` (not ``nan``) when none is stored."""
        return f"{self.value:.6g} {self.units}" if math.isfinite(self.value) else "no value"

    @property
    def certificate_text(self) -> str:
        """The certificate with its units, ``unknown (why)`` for a stored factor that cannot
        be used (it vanished without a word), or "" for a file written before them."""
        if math.isfinite(self.certificate):
            return f"{self.certificate:.2g} {self.units}"
        return f"unknown ({self.certificate_problem})" if self.certificate_problem else ""

    @property
    def certificate(self) -> float:
        """The certified bound [its units]: the estimate times its stored factor."""
        return self.certificate_factor * self.total

    @property
    def certified_relative(self) -> float:
        """The certificate over the quantity's magnitude (what refinement decides on; the
        estimate's relative error for a file written before certificates)."""
        factor = self.certificate_factor if math.isfinite(self.certificate_factor) else 1.0
        return factor * self.relative

    def text(self) -> str:
        """``what: value units +- total (relative %) [certificate c] = rss of step a, ...``,
        or ``what: value units +- unknown (why)`` for a budget with a problem."""
        terms = ", ".join(f"{term} {term_text(value)}" for term, value in self.terms.items())
        if self.problem:
            return (f"{self.what}: {self.value_text} +- {self.problem}"
                    + (f" (terms: {terms})" if terms else ""))
        relative = (f" ({100 * self.relative:.2g} %)" if math.isfinite(self.relative)
                    else "")
        certificate = (f", certificate {self.certificate_text}" if self.certificate_text
                       else "")
        kind = (f"a bound, not an estimate: {BOUND_TEXT}" if self.bound else "estimate")
        return (f"{self.what}: {self.value:.6g} {self.units} +- {self.total:.2g} "
                f"{self.units}{relative} ({kind}{certificate}; root-sum-square of {terms})")


def _described(attrs: Mapping[str, Any]) -> dict[str, tuple[str, str]]:
    """The quantities a stored budget describes (:data:`DESCRIBED`), else the built-in
    headlines (a file written before the budget described its quantities)."""
    if DESCRIBED not in attrs:
        return {name: (entry.unit, entry.what) for name, entry in BUILTIN_HEADLINES.items()}
    lines = (line.split("\t") for line in str(attrs[DESCRIBED]).splitlines())
    return {parts[0]: (parts[1], parts[2]) for parts in lines if len(parts) == 3}


def term_text(value: float) -> str:
    """A stored term for display: ``unknown`` for one not measured (NaN)."""
    return f"{value:.2g}" if math.isfinite(value) else "unknown"


#: why a raw peak's total is a bound (printed beside it)
BOUND_TEXT = ("a raw maximum races between the crests of the ringing and "
              "has no order of convergence; its terms are the largest mismatches of the "
              "companions' crests")
#: how far a stored total may lie from the root-sum-square of its stored terms (relative)
CONSISTENCY = 1e-6


def _number(attrs: dict[str, Any], key: str) -> tuple[float | None, str]:
    """The stored attribute ``key`` as a float (None: absent), or why it is malformed."""
    if key not in attrs:
        return None, ""
    value = attrs[key]
    try:
        if isinstance(value, bytes | str | bool | np.bool_) or np.ndim(value) != 0:
            raise TypeError(type(value).__name__)
        number = float(np.real_if_close(value))
    except (TypeError, ValueError):
        return math.nan, f"malformed: attribute {key} is not a real number ({_shown(value)})"
    if number < 0 or math.isinf(number):
        return math.nan, f"malformed: attribute {key} = {number:g} (an error is >= 0, finite)"
    return number, ""


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def budget_rows(attrs: Mapping[str, Any]) -> list[BudgetRow]:
    """The stored error budget of a case (its attributes; see :meth:`ErrorBudget.attrs`),
    one row per headline quantity it holds (a value ``headline_*`` or an error
    ``estimated_error_*``), in the order the budget describes them (:data:`DESCRIBED`; a file
    written before: the built-in headlines' order). A file written before budgets (a step
    estimate alone) gives rows with that one term. Each row is checked: a term not measured
    (NaN) or an error not stored makes it ``unknown``, a total that is not the
    root-sum-square of its terms ``inconsistent``, a value that is not a real number >= 0
    ``malformed`` (:attr:`BudgetRow.problem`)."""
    rows = []
    for quantity, (units, what) in _described(attrs).items():
        keys = [f"{PREFIX}{quantity}", f"{HEADLINE_PREFIX}{quantity}",
                *(f"{PREFIX}{quantity}_{term}" for term in TERMS)]
        if not any(key in attrs for key in keys):
            continue
        rows.append(_budget_row(attrs, quantity, units, what,
                                quantity in named_quantities(attrs)))
    factor, problem = _number(dict(attrs), CERTIFICATE_ATTR)
    if factor is not None and math.isfinite(factor) and factor >= 1.0:
        rows = [replace(row, certificate_factor=factor) for row in rows]
    elif factor is not None:  # stored but unusable: said, not dropped without a word
        problem = problem or f"malformed: attribute {CERTIFICATE_ATTR} = {factor:g} (< 1)"
        rows = [replace(row, certificate_problem=problem) for row in rows]
    bounds = named_quantities(attrs)
    return [replace(row, bound=True) if row.quantity in bounds else row for row in rows]


def named_quantities(attrs: Mapping[str, Any], key: str = BOUNDS_ATTR) -> frozenset[str]:
    """The quantities a stored budget lists under ``key``, :data:`BOUNDS_ATTR` (bounds) or
    :data:`STEP_BOUNDS_ATTR` (flagged); none in an older file or one whose value is no text."""
    value = attrs.get(key, "")
    if isinstance(value, bytes):
        value = value.decode("utf-8", "replace")
    return frozenset(name.strip() for name in value.split(",") if name.strip()) \
        if isinstance(value, str) else frozenset()


def _budget_row(attrs: dict[str, Any], quantity: str, units: str, what: str,
                bound: bool = False) -> BudgetRow:
    """:func:`budget_rows`' row of one quantity."""
    total, problem = _number(attrs, f"{PREFIX}{quantity}")
    terms, problems = {}, [problem] if problem else []
    for term in TERMS:
        value, problem = _number(attrs, f"{PREFIX}{quantity}_{term}")
        if value is not None:
            terms[term] = value
            problems += [problem] if problem else []
    raw = attrs.get(f"{HEADLINE_PREFIX}{quantity}", math.nan)
    try:
        value = float(raw) if not isinstance(raw, str | bytes) else math.nan
    except (TypeError, ValueError):
        value = math.nan
    if not terms and total is not None and math.isfinite(total):
        terms = {"step": total}
    unmeasured = [term for term, number in terms.items() if math.isnan(number)]
    if problems:
        problem = problems[0]
    elif not math.isfinite(value):  # it printed "nan m +- ..."
        problem = (f"unknown (no value stored: attribute {HEADLINE_PREFIX}{quantity} is "
                   f"missing or not a number)")
    elif total is None:
        problem = ("unknown (no estimated error stored)" if f"{PREFIX}method" in attrs else
                   "unknown (not estimated: the run had simulation.error_estimate = false)")
    elif unmeasured:
        problem = _not_measured(unmeasured)
    elif math.isnan(total):
        problem = "unknown (the stored total is not a number)"
    elif abs(total - combined(terms.values(), bound)) > CONSISTENCY * max(total, 1e-300):
        problem = (f"inconsistent (stored total {total:.3g} {units} is not the "
                   f"{'sum' if bound else 'root-sum-square'} of its terms, "
                   f"{combined(terms.values(), bound):.3g} {units})")
    if problem:
        return BudgetRow(quantity, what, units, value, math.nan, math.nan, terms, problem)
    stored, _ = _number(attrs, f"{PREFIX}{quantity}_relative")
    relative = (total / abs(value) if math.isfinite(value) and value != 0 else
                stored if stored is not None else math.nan)
    return BudgetRow(quantity, what, units, value, total, relative, terms)


__all__ = ["BOUNDS_ATTR", "BOUND_TEXT", "CERTIFICATE_ATTR", "CERTIFICATE_FACTOR", "CONSISTENCY",
           "COVERAGE_ATTR", "CREST_GAP_PREFIX", "DESCRIBED", "HEADLINE_PREFIX", "PREFIX",
           "STEP_BOUNDS_ATTR",
           "TERMS", "UNKNOWN_ATTR", "BudgetRow", "ErrorBudget", "budget_rows", "combined",
           "coverage_attrs", "coverage_text", "headline_attrs", "named_quantities",
           "stored_coverage", "term_text", "tolerance_coverage"]
