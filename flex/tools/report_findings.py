"""The study's own part of a report (:mod:`flex.tools.report`, its "Study report" section):
its findings as Markdown, its tables from the file's data, its long printed text folded.

A study declares its findings (:class:`flex.study.Summary`): short Markdown in the root
attribute ``summary_findings`` and tables of data, the column datasets of
:func:`flex.data.tables.findings_table` (under ``/summary/findings/<table>/``, marked by
their attributes). The section then shows the findings (prose wrapped to short lines), each
table where a line ``[[table:<table>]]`` puts it (the others after the findings, in their
order), every cell as :func:`flex.tools.markdown.format_value` writes it, and the printed
report (root attribute ``summary_report``) folded. A file without findings shows its printed
report as before: as written when it holds Markdown tables, else as a fenced block.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Any

from flex.data.tables import COLUMN_ATTR, LABEL_ATTR, ORDER_ATTR, TITLE_ATTR
from flex.tools.markdown import fenced, table, with_unit, wrap_markdown

_PLACE = re.compile(r"^\s*\[\[table:([^\]]+)\]\]\s*$")


def is_findings_column(item: Any) -> bool:
    """Whether a dataset (:class:`flex.tools.report._Item`) is a column of a findings table."""
    return COLUMN_ATTR in item.attrs and item.data.ndim == 1


def study_report_lines(root: Mapping[str, Any], items: Sequence[Any]) -> list[str]:
    """The body of the "Study report" section (see the module doc); empty when the file
    has neither findings nor a printed report."""
    findings = str(root.get("summary_findings") or "")
    report = root.get("summary_report")
    report = report if isinstance(report, str) and report.strip() else ""
    tables = _tables(items)
    if not findings.strip() and not tables:
        if not report:
            return []
        if "\n|---" in report:  # the study wrote Markdown (its tables): shown as written
            return [*wrap_markdown(report.strip()), ""]
        return ["The study's printed report (root attribute `summary_report`):", "",
                *fenced(report)]
    lines: list[str] = []
    for line in wrap_markdown(findings.strip()):
        placed = _PLACE.match(line)
        if placed and placed.group(1) in tables:
            lines += _table_lines(tables.pop(placed.group(1)))
        else:
            lines.append(line)
    lines.append("")
    for name in sorted(tables, key=lambda name: (tables[name][0].attrs.get(ORDER_ATTR, 0),
                                                  name)):
        lines += _table_lines(tables[name])
    if report:
        lines += ["<details><summary>The study's full printed report (root attribute "
                  "<code>summary_report</code>)</summary>", "", *fenced(report), "</details>",
                  ""]
    return lines


def _tables(items: Sequence[Any]) -> dict[str, list[Any]]:
    """The findings tables by name (the columns' group below ``/summary/findings``), each
    its columns in their order."""
    out: dict[str, list[Any]] = {}
    for item in items:
        if is_findings_column(item):
            out.setdefault(item.group.rsplit("/", 1)[-1], []).append(item)
    return {name: sorted(columns, key=lambda item: int(item.attrs[COLUMN_ATTR]))
            for name, columns in out.items()}


def _table_lines(columns: list[Any]) -> list[str]:
    """A findings table: its title in bold, the table (units in the headers of numeric
    columns, numbers aligned right), what each column is (folded)."""
    first = columns[0]
    title = str(first.attrs.get(TITLE_ATTR) or first.group)
    numeric = [item.data.dtype.kind in "iuf" for item in columns]
    header = [with_unit(str(item.attrs.get(LABEL_ATTR) or item.name),
                        item.units if number and (item.data.dtype.kind == "f"
                                                  or item.units not in ("", "1")) else "")
              for item, number in zip(columns, numeric, strict=True)]
    lines = [f"**{title}**", ""]
    length = min(len(item.data) for item in columns)
    if length == 0:
        return lines + ["(no rows)", ""]
    lines += table(header, [[item.data[row] for item in columns] for row in range(length)],
                   numeric)
    return lines + columns_legend([f"{label}: {item.description}" for label, item
                                   in zip(header, columns, strict=True)
                                   if item.description and item.description != label])


def columns_legend(entries: Sequence[str]) -> list[str]:
    """What each column of a table is (``entries``: ``"name: description"``), folded: a
    list under "Columns" that opens on a click; nothing without entries."""
    if not entries:
        return []
    return ["<details><summary>Columns</summary>", "",
            *wrap_markdown("\n".join(f"- {entry}" for entry in entries)), "", "</details>", ""]
