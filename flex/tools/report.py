"""Markdown reports generated from a result file (``flex report FILE.h5 [--out REPORT.md]``).

Every number in a report is read from the HDF5 file it names; nothing is typed by hand. A
report holds, in this order:

1. the study (root attribute ``study``), the file, and the study's own report
   (:mod:`flex.tools.report_findings`): its findings (root attribute ``summary_findings``)
   and findings tables (``/summary/findings/...``), its printed report (root attribute
   ``summary_report``) folded; without findings the printed report as written (Markdown)
   or as a fenced block;
2. provenance: flex version, git commit (and whether the tree was dirty), engine versions,
   Python, platform, creation time, command, wall time, failed cases; other root attributes;
3. the cases: status, samples, time range, solver counters, validity warnings, what
   ``"auto"`` chose (fidelity, solver defaults), failure messages; other case attributes;
4. every other dataset under ``/summary`` (and any other top-level group), grouped by its parent
   group, with units and descriptions: scalars as rows, 1-D arrays of one length as the
   columns of one table, other short arrays as lists, small 2-D arrays as tables, arrays of
   more than :data:`LARGE` elements as shape, minimum and maximum;
5. every figure ``figures/<stem>-*.png`` beside the file, linked relative to the report;
6. the resolved scene (root attribute ``scene_toml``), folded.

Numbers are shown with 4 significant digits (:func:`format_value`); integers and booleans
as they are. A table cell longer than a few words is a note below its table (one note per
distinct text), a table wider than a line is split into tables repeating the row names, and
prose is wrapped to short lines (:func:`flex.tools.markdown.table`,
:func:`flex.tools.markdown.wrap_markdown`). A study run writes ``reports/<stem>.md`` beside
its result file (:func:`default_report_path`, :func:`write_report`).
"""

from __future__ import annotations

import math
import os
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import quote

import numpy as np

from flex.base.errors import OutputError
from flex.data.outputs import RESULT_SUFFIXES, check_writable_folder, figures_folder
from flex.data.results import atomic_path, attribute_value, case_names, reading
from flex.tools.inspect import stress_lines
from flex.tools.markdown import (
    cell,
    code,
    fenced,
    format_value,
    note_lines,
    noted,
    table,
    with_unit,
    wrap_markdown,
)
from flex.tools.report_findings import columns_legend, is_findings_column, study_report_lines

REPORT_SUFFIX = ".md"
#: arrays with more elements than this are summarised (shape, minimum, maximum)
LARGE = 50
ENGINES = ("exudyn", "ngsolve", "h5py", "numpy", "scipy")
PROVENANCE_KEYS = ("flex_format", "study", "flex_version", "git_commit", "git_dirty",
                   *(f"{engine}_version" for engine in ENGINES), "python_version",
                   "platform", "created_utc", "command", "wall_time_s", "failed_cases")
#: root attributes shown in their own sections (not in the table of other attributes)
SHOWN_ELSEWHERE = ("scene_toml", "summary_report", "summary_findings")
CASE_KNOWN = ("status", "message", "scene_toml", "solver_settings_toml", "validity_warning")
#: a case's note longer than this is shown below the cases table, once for the cases that
#: share it [characters]
CASE_NOTE = 100
#: a budget cell (beside the quantity's name) longer than this is shown below the budget
#: table, once for the rows sharing it [characters]
BUDGET_CELL = 60
#: a scalar's value or description longer than this is shown below its table [characters]
DESCRIPTION = 160
COUNTER_TITLES = {"steps": "steps", "newton_iterations": "Newton iterations",
                  "jacobian_updates": "Jacobian updates", "wall_time_s": "wall time [s]"}


@dataclass
class _Item:
    """One dataset outside ``/cases``: its path below the top-level group ``top``, units,
    description and values (a numpy array; text as an object array of ``str``)."""

    top: str
    path: str
    units: str
    description: str
    data: np.ndarray
    #: its other attributes (a findings table's title and column: flex.data.tables)
    attrs: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.path.rsplit("/", 1)[-1]

    @property
    def group(self) -> str:
        """The full HDF5 path of the parent group (``/summary/energy``)."""
        parent = self.path.rsplit("/", 1)[0] if "/" in self.path else ""
        return "/" + "/".join(part for part in (self.top, parent) if part)

    @property
    def is_text(self) -> bool:
        return self.data.dtype.kind == "O"


def figures_of(path: str | Path) -> list[Path]:
    """The figures a result file's report lists: ``figures/<stem>-*.png`` beside it."""
    return _figures_of(Path(path))


def default_report_path(path: str | Path) -> Path:
    """Where a result file's report goes: ``reports/<stem>.md`` beside it
    (``results/dynamics.h5`` -> ``results/reports/dynamics.md``)."""
    path = Path(path)
    return path.parent / "reports" / f"{path.stem}{REPORT_SUFFIX}"


def render_report(path: str | Path, report_folder: str | Path | None = None, *,
                  shown_as: str | Path | None = None,
                  figures: list[Path] | None = None) -> str:
    """The Markdown report of the result file ``path``.

    ``report_folder`` is where the report will be saved (default: that of
    :func:`default_report_path`); links to the result file and its figures are relative to
    it. ``shown_as``: the name the file will have (a run renders its report from the file
    still under its private name, :class:`flex.data.outputs.Staging`); ``figures``: its
    figures (default: those beside it). Raises :class:`~flex.base.errors.ResultFileError`
    for a missing or malformed file.
    """
    path = Path(path)
    shown = Path(shown_as) if shown_as is not None else path
    folder = Path(report_folder) if report_folder is not None else default_report_path(
        shown).parent
    root, cases, items = _read(path)
    lines = _title_section(shown, folder, root, items)
    lines += _provenance_section(root)
    lines += _cases_section(cases)
    lines += _data_section(items)
    lines += _figures_section(shown, folder, figures)
    lines += _scene_section(str(root.get("scene_toml") or ""))
    return "\n".join(lines).rstrip("\n") + "\n"


def write_report(path: str | Path, out: str | Path | None = None) -> Path:
    """Write the report of the result file ``path`` to ``out`` (default
    :func:`default_report_path`) atomically (a temporary file renamed into place, the folder
    created) and return where it went.

    Refuses with :class:`~flex.base.errors.OutputError`, writing nothing, an output that is the
    result file itself, does not end in ``.md``, is a folder or cannot be written; a bad
    result file raises :class:`~flex.base.errors.ResultFileError`, also before anything is
    written.
    """
    path = Path(path)
    target = default_report_path(path) if out is None else Path(out)
    label = f"report '{target}'"
    if _same_file(target, path):
        raise OutputError(f"{label} is the result file it reports on; choose another name "
                          f"ending in {REPORT_SUFFIX}")
    if target.is_dir():
        raise OutputError(f"{label} is a folder; give a file name ending in {REPORT_SUFFIX}")
    if target.suffix != REPORT_SUFFIX:
        raise OutputError(f"{label}: reports are Markdown files ending in {REPORT_SUFFIX}")
    check_writable_folder(target.parent, label)
    text = render_report(path, target.parent)
    try:
        with atomic_path(target) as tmp:
            tmp.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise OutputError(f"cannot write {label}: {exc.strerror or exc}") from None
    return target


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == b.resolve() or (a.exists() and b.exists() and a.samefile(b))
    except OSError:
        return False


# --- reading ----------------------------------------------------------------------------

def _read(path: Path) -> tuple[dict[str, Any], list[dict[str, Any]], list[_Item]]:
    """Root attributes, cases (name, attributes, samples, time range) and every dataset
    outside ``/cases``, read through :func:`flex.data.results.reading` (which checks the file)."""
    with reading(path) as h5:
        root = {key: attribute_value(value) for key, value in h5.attrs.items()}
        cases = []
        for name in case_names(h5):
            group = h5[f"cases/{name}"]
            time_s = group["time"][()] if "time" in group else None
            cases.append({"name": name,
                          "attrs": {k: attribute_value(v) for k, v in group.attrs.items()},
                          "time": time_s})
        items: list[_Item] = []
        for top in h5:
            if top == "cases":
                continue
            obj = h5[top]
            if hasattr(obj, "shape"):
                items.append(_item("", top, obj))
            else:
                obj.visititems(lambda name, node, top=top: items.append(
                    _item(top, name, node)) if hasattr(node, "shape") else None)
        return root, cases, items


def _item(top: str, path: str, dataset) -> _Item:
    raw = dataset[()]
    if dataset.dtype.kind in "OSU":  # text: an object array of str
        data = np.empty(np.shape(raw), dtype=object)
        for index in np.ndindex(data.shape):
            data[index] = format_value(np.asarray(raw, dtype=object)[index])
    else:
        data = np.asarray(raw)
    return _Item(top, path, str(attribute_value(dataset.attrs.get("units", "")) or ""),
                 str(attribute_value(dataset.attrs.get("description", "")) or ""), data,
                 {key: attribute_value(value) for key, value in dataset.attrs.items()
                  if key not in ("units", "description")})


# --- Markdown helpers -------------------------------------------------------------------

def _link(target: Path, folder: Path) -> str:
    """``target`` relative to ``folder`` as a URL path (``../figures/a.png``)."""
    relative = os.path.relpath(os.path.abspath(target), os.path.abspath(folder))
    return quote(Path(relative).as_posix())


# --- sections ---------------------------------------------------------------------------

def _title_section(path: Path, folder: Path, root: dict[str, Any],
                   items: list[_Item]) -> list[str]:
    study = str(root.get("study") or "(no study attribute)")
    lines = [f"# {study}", "",
             f"Generated by `flex report` from [{code(path.name)}]({_link(path, folder)}); "
             f"every number below is read from that file.", "", "## Study report", ""]
    body = study_report_lines(root, items)
    if body:
        return lines + body
    return lines + ["This file has no study report (root attribute `summary_report`): it "
                    "was written before flex stored one, or by a tool that does not.", ""]


def _provenance_section(root: dict[str, Any]) -> list[str]:
    dirty = {"yes": " (with uncommitted changes)", "no": " (clean)"}.get(
        str(root.get("git_dirty")), f" (dirty: {root['git_dirty']})" if "git_dirty" in root
        else "")
    engines = ", ".join(f"{name} {format_value(root[f'{name}_version'])}" for name in ENGINES
                        if f"{name}_version" in root)
    rows: list[list[Any]] = [
        ["flex_version", root.get("flex_version", "")],
        ["flex_format", root.get("flex_format", "")],
        ["git_commit", f"{format_value(root.get('git_commit', 'unknown'))}{dirty}"],
        ["engines", engines],
        ["python", root.get("python_version", "")],
        ["platform", root.get("platform", "")],
        ["created_utc", root.get("created_utc", "")],
        ["command", code(str(root["command"])) if root.get("command") else ""],
        ["wall_time_s", root.get("wall_time_s", "not recorded")],
        ["failed_cases", root.get("failed_cases", "not recorded")],
    ]
    lines = ["## Provenance", "", *table(["item", "value"], rows)]
    others = [[code(key), value] for key, value in root.items()
              if key not in PROVENANCE_KEYS and key not in SHOWN_ELSEWHERE]
    if others:
        lines += ["Other root attributes:", "", *table(["attribute", "value"], others)]
    return lines


def _cases_section(cases: list[dict[str, Any]]) -> list[str]:
    lines = ["## Cases", ""]
    if not cases:
        return lines + ["This file has no cases.", ""]
    counters = _counter_keys(cases)
    header = ["case", "status", "samples", "t [s]",
              *(COUNTER_TITLES.get(key, key.replace("_", " ")) for key in counters), "notes"]
    rows, notes = [], {}
    for case in cases:
        attrs, time_s = case["attrs"], case["time"]
        has_time = time_s is not None and np.ndim(time_s) == 1 and len(time_s)
        status = str(attrs.get("status", ""))
        rows.append([code(case["name"]), status if status == "ok" else f"**{status}**",
                     len(time_s) if has_time else "-",
                     f"{format_value(time_s[0])} .. {format_value(time_s[-1])}" if has_time
                     else "-",
                     *(attrs.get(f"counter_{key}", "-") for key in counters),
                     "<br>".join(noted(" ".join(note.split()), notes, CASE_NOTE)
                                 for note in _case_notes(attrs))])
    lines += table(header, rows, long_cell=None, width=None) + note_lines(notes)
    return lines + _budget_section(cases) + _case_attributes(cases)


def _budget_section(cases: list[dict[str, Any]]) -> list[str]:
    """Each case's error budget: a row per headline quantity (value, total estimated error,
    relative, terms), then how the terms were made and what they leave out."""
    from flex.fidelity.stored_budget import (
        PREFIX,
        TERMS,
        budget_rows,
        coverage_text,
        stored_coverage,
        term_text,
    )

    rows, notes = [], {}
    for case in cases:
        for row in budget_rows(case["attrs"]):
            rows.append([code(case["name"]), row.what, row.value_text,
                         row.problem or f"{'bound ' if row.bound else ''}{row.total:.2g} "
                                        f"{row.units}",
                         f"{100 * row.relative:.2g} %" if math.isfinite(row.relative) else "-",
                         row.certificate_text or "-",
                         *(term_text(row.terms[t]) if t in row.terms else "-" for t in TERMS)])
        for key in ("method", "leaves_out", "validity", "unknown"):
            if case["attrs"].get(PREFIX + key):
                notes.setdefault(key, {}).setdefault(case["attrs"][PREFIX + key], []).append(
                    case["name"])
        coverage = stored_coverage(case["attrs"])
        if coverage:
            notes.setdefault("tolerance", {}).setdefault(coverage_text(
                coverage, float(case["attrs"].get("tolerance_relative", 0))), []).append(
                case["name"])
    if not rows:
        return []
    lines = [*wrap_markdown("Estimated error of each headline quantity (total = the "
                            "root-sum-square of the terms, in the quantity's unit: what the "
                            "error is; certificate = the bound refinement decides on, the "
                            "estimate times its stated safety factor; a raw peak's "
                            "error is a bound, not an estimate, marked so):"), ""]
    lines += table(["case", "quantity", "value", "estimated error", "relative",
                     "certificate", *TERMS], rows, long_cell=[None, None] + [BUDGET_CELL] * (
                         4 + len(TERMS)), width=None)
    for key, texts in notes.items():
        for text, names in texts.items():
            who = "every case" if len(names) == len(cases) else ", ".join(map(code, names))
            lines.append(f"- {key.replace('_', ' ')} ({who}): {text}")
    return lines + [""]


def _counter_keys(cases: list[dict[str, Any]]) -> list[str]:
    found = dict.fromkeys(key[len("counter_"):] for case in cases for key in case["attrs"]
                          if key.startswith("counter_"))
    return [key for key in COUNTER_TITLES if key in found] + [
        key for key in found if key not in COUNTER_TITLES]


def _fidelity_links(attrs: dict[str, Any]) -> list[str]:
    return [key[len("fidelity_"):-len("_model")] for key in attrs
            if key.startswith("fidelity_") and key.endswith("_model")]


def _case_notes(attrs: dict[str, Any]) -> list[str]:
    """Failure message, validity warning and the ``"auto"`` choices, in short form."""
    notes = []
    if attrs.get("message"):
        notes.append(f"message: {attrs['message']}")
    if attrs.get("validity_warning"):
        notes.append(f"**validity warning**: {attrs['validity_warning']}")
    notes += stress_lines(attrs)
    for link in _fidelity_links(attrs):
        prefix = f"fidelity_{link}_"
        modes = attrs.get(prefix + "modes")
        shown = f", {format_value(modes)} modes" if isinstance(modes, int) and modes >= 0 else ""
        reason = f" ({attrs[prefix + 'reason']})" if attrs.get(prefix + "reason") else ""
        notes.append(f"fidelity {link}: {format_value(attrs[prefix + 'model'])}{shown}{reason}")
    if attrs.get("solver_defaults_entry"):
        reason = attrs.get("solver_defaults_reason")
        notes.append(f"solver defaults: {attrs['solver_defaults_entry']}"
                     + (f" ({reason})" if reason else "")
                     + (f": {attrs['solver_defaults_keys']}"
                        if attrs.get("solver_defaults_keys") else ""))
    return notes


def _shown_in_notes(key: str, attrs: dict[str, Any]) -> bool:
    if key in CASE_KNOWN or key.startswith(("counter_", "solver_defaults_", "estimated_error_",
                                            "headline_")):
        return True
    if key.startswith(("coupler_peak_von_mises", "crank_peak_von_mises")) or key.endswith(
            ("_reduction_basis_sha256", "_reduction_basis_fingerprint")):
        return True  # the peaks are in the notes; the basis identity is for flex export
    return any(key.startswith(f"fidelity_{link}_") for link in _fidelity_links(attrs))


def _case_attributes(cases: list[dict[str, Any]]) -> list[str]:
    """The case attributes not in the cases table: one column each (up to 8), else one
    list per case."""
    extra = {case["name"]: {key: value for key, value in case["attrs"].items()
                            if not _shown_in_notes(key, case["attrs"])} for case in cases}
    keys = list(dict.fromkeys(key for attrs in extra.values() for key in attrs))
    if not keys:
        return []
    lines = ["Other case attributes:", ""]
    if len(keys) <= 8:
        rows = [[code(name), *(attrs.get(key, "-") for key in keys)]
                for name, attrs in extra.items() if attrs]
        return lines + table(["case", *keys], rows)
    for name, attrs in extra.items():
        if attrs:
            shown = "; ".join(f"{key} = {cell(value)}" for key, value in attrs.items())
            lines += wrap_markdown(f"- {code(name)}: {shown}")
    return lines + [""]


def _data_section(items: list[_Item]) -> list[str]:
    """Every dataset outside ``/cases``, one subsection per parent group."""
    lines = ["## Summary", ""]
    if not any(item.top == "summary" for item in items):
        lines += ["This file has no `/summary` tables.", ""]
    if any(is_findings_column(item) for item in items):
        lines += ["The findings tables (`/summary/findings/...`) are shown in the study report "
                  "above.", ""]
        items = [item for item in items if not is_findings_column(item)]
    groups: dict[str, list[_Item]] = {}
    for item in items:
        groups.setdefault(item.group, []).append(item)
    for group in sorted(groups):  # a group before the groups inside it
        lines += [f"### {code(group)}", ""]
        lines += _group_lines(groups[group])
    return lines


def _group_lines(items: list[_Item]) -> list[str]:
    """One group: scalars, tables of same-length 1-D arrays, lists, 2-D tables, then the
    large arrays summarised."""
    scalars = [item for item in items if item.data.ndim == 0]
    large = [item for item in items if item.data.ndim > 0 and item.data.size > LARGE]
    vectors = [item for item in items if item.data.ndim == 1 and item not in large]
    matrices = [item for item in items if item.data.ndim >= 2 and item not in large]
    lines: list[str] = []
    if scalars:
        lines += table(["name", "value", "unit", "description"],
                       [[code(i.name), i.data[()], i.units, i.description] for i in scalars],
                       long_cell=DESCRIPTION)
    lengths = Counter(len(item.data) for item in vectors)
    for length in dict.fromkeys(len(item.data) for item in vectors):
        members = [item for item in vectors if len(item.data) == length]
        if lengths[length] >= 2 and length > 0:
            lines += _columns_table(members)
        else:
            lines += [line for item in members for line in wrap_markdown(_vector_line(item))]
            lines.append("")
    for item in matrices:
        lines += _matrix_table(item)
    if large:
        lines += [f"Large arrays (more than {LARGE} elements), summarised:", ""]
        lines += table(["name", "shape", "min", "max", "unit", "description"],
                        [_large_row(item) for item in large])
    return lines


def _columns_table(items: list[_Item]) -> list[str]:
    """1-D arrays of one length as the columns of one table (short text first, as row
    labels, the one with the most distinct values leading: it names the rows where a wide
    table is split; long text last), then what each column is (folded)."""
    def order(item: _Item) -> tuple[int, int]:
        if not item.is_text:
            return 1, 0
        if max(len(str(value)) for value in item.data) > 40:
            return 2, 0
        return 0, -len(set(item.data))

    items = sorted(items, key=order)
    header = [with_unit(item.name, "" if item.is_text else item.units) for item in items]
    rows = [[item.data[row] for item in items] for row in range(len(items[0].data))]
    lines = table(header, rows, [item.data.dtype.kind in "iuf" for item in items])
    legend = [f"{code(item.name)}: {cell(item.description)}" for item in items
              if item.description and item.description != item.name]
    return lines + columns_legend(legend)


def _vector_line(item: _Item) -> str:
    values = ", ".join(cell(value) for value in item.data) if len(item.data) else "(empty)"
    about = f" ({item.description})" if item.description else ""
    return f"- {code(item.name)} [{item.units or '-'}]{about}: {values}"


def _matrix_table(item: _Item) -> list[str]:
    """A small array of 2 or more dimensions: one row per index of its first axis."""
    data = item.data.reshape(item.data.shape[0], -1) if item.data.shape[0] else item.data
    about = f": {item.description}" if item.description else ""
    lines = [f"{code(item.name)} [{item.units or '-'}], shape {item.data.shape}{about}", ""]
    if data.size == 0:
        return lines + ["(empty)", ""]
    header = ["row", *(f"[{column}]" for column in range(data.shape[1]))]
    return lines + table(header, [[row, *data[row]] for row in range(data.shape[0])])


def _large_row(item: _Item) -> list[Any]:
    shape = str(item.data.shape)
    if item.is_text:
        return [code(item.name), shape, "(text)", "(text)", item.units, item.description]
    values = item.data.astype(float) if item.data.dtype.kind == "b" else item.data
    finite = values[np.isfinite(values)]
    bad = values.size - finite.size
    if bad:
        shape += f", {bad} non-finite"
    low, high = (finite.min(), finite.max()) if finite.size else ("-", "-")
    if item.data.dtype.kind == "b" and finite.size:
        low, high = bool(low), bool(high)
    return [code(item.name), shape, low, high, item.units, item.description]


def _figures_section(path: Path, folder: Path, figures: list[Path] | None = None) -> list[str]:
    """Every ``figures/<stem>-*.png`` beside the result file (not those of another result
    file beside it whose name starts with ``<stem>-``), or the ``figures`` given."""
    lines = ["## Figures", ""]
    figures = _figures_of(path) if figures is None else sorted(figures)
    if not figures:
        return lines + [f"No figures `{figures_folder(Path(path.name)).as_posix()}/"
                        f"{path.stem}-*.png` beside the file.", ""]
    for figure in figures:
        lines += [f"![{figure.stem[len(path.stem) + 1:]}]({_link(figure, folder)})", ""]
    return lines


def _figures_of(path: Path) -> list[Path]:
    import glob

    folder = figures_folder(path)
    try:
        found = sorted(Path(name) for name in glob.glob(
            os.path.join(glob.escape(str(folder)), f"{glob.escape(path.stem)}-*.png")))
        longer = [other.stem for other in path.parent.iterdir()
                  if other.suffix in RESULT_SUFFIXES and other.stem.startswith(f"{path.stem}-")]
    except OSError:
        return []
    return [figure for figure in found if figure.is_file()
            and not any(figure.name.startswith(f"{stem}-") for stem in longer)]


def _scene_section(scene_toml: str) -> list[str]:
    if not scene_toml.strip():
        return []
    return ["## Scene", "", "<details><summary>The study's scene (root attribute "
            "<code>scene_toml</code>)</summary>", "", *fenced(scene_toml, "toml"),
            "</details>", ""]
