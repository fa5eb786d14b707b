"""Markdown pieces of a report (:mod:`flex.tools.report`): values, cells, tables, fenced
blocks, inline code, and prose wrapped to short lines.

A report is read in an editor and in a browser: no line of prose is longer than
:data:`WIDTH` characters (:func:`wrap_markdown` breaks paragraphs and list items, which
Markdown joins again), and a table cell holds a number, a name or a few words.
"""

from __future__ import annotations

import re
import textwrap
from collections.abc import Sequence
from typing import Any

import numpy as np

#: prose lines are wrapped to this many characters [characters]
WIDTH = 100
#: a table cell longer than this is shown as a note below its table [characters]
LONG_CELL = 80
#: a table wider than this is split into tables of fewer columns [characters]
LINE = 200
_LIST_ITEM = re.compile(r"^(\s*(?:[-*+]|\d+[.)])\s+)")


def format_value(value: Any) -> str:
    """A value as the report shows it: floats with 4 significant digits (``:.4g``, so never
    more digits than the value has: ``0.08``, ``1500``, ``7.93e+10``), integers exactly,
    booleans as ``true``/``false``, text as it is (bytes decoded as UTF-8)."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return f"{value:.4g}"
    if value is None:
        return ""
    return str(value)


def cell(value: Any) -> str:
    """A table cell: formatted, on one line, with ``|`` escaped."""
    text = value if isinstance(value, str) else format_value(value)
    return " ".join(text.split()).replace("|", "\\|")


def table(header: list[str], rows: list[list[Any]], right: list[bool] | None = None,
          long_cell: int | Sequence[int | None] | None = LONG_CELL,
          width: int | None = LINE) -> list[str]:
    """A Markdown table (then an empty line) of ``rows`` under ``header``; the columns
    ``right`` marks (numbers) aligned right.

    A cell longer than ``long_cell`` characters shows ``note <n>`` and its text follows the
    table as note ``n`` (one note per distinct text, wrapped to short lines); a table wider
    than ``width`` characters is split into tables of fewer columns, each repeating the
    row's names (its leading text columns, up to two). None: no limit; ``long_cell`` may
    give one limit per column."""
    right = list(right or [False] * len(header))
    head = [cell(h) for h in header]
    body = [[cell(value) for value in row] for row in rows]
    notes: dict[str, int] = {}
    limits = (list(long_cell) if isinstance(long_cell, Sequence)
              else [long_cell] * len(header))
    body = [[noted(text, notes, limit) for text, limit in zip(row, limits, strict=True)]
            for row in body]
    lines: list[str] = []
    for columns in _column_groups(head, body, width, right):
        lines += ["| " + " | ".join(head[i] for i in columns) + " |",
                  "|" + "|".join("---:" if right[i] else "---" for i in columns) + "|"]
        lines += ["| " + " | ".join(row[i] for i in columns) + " |" for row in body] + [""]
    return lines + note_lines(notes)


def noted(text: str, notes: dict[str, int], limit: int | None = LONG_CELL) -> str:
    """``text``, or ``note <n>`` when it is longer than ``limit`` characters (None: never):
    its number in ``notes`` (text -> number), added there if new."""
    if limit is None or len(text) <= limit:
        return text
    return f"note {notes.setdefault(text, len(notes) + 1)}"


def note_lines(notes: dict[str, int]) -> list[str]:
    """The notes of :func:`noted` as a list (each wrapped to short lines), then an empty
    line; nothing without notes."""
    lines = [line for text, number in notes.items()
             for line in wrap_markdown(f"- note {number}: {text}")]
    return lines + [""] if lines else []


def _column_groups(head: list[str], body: list[list[str]], width: int | None,
                   right: list[bool]) -> list[list[int]]:
    """The columns of each table a table is split into (see :func:`table`): all of them
    when its lines fit in ``width``, else the row's names (its leading text columns, up to
    two: those not aligned ``right``) with as many more as fit, in order."""
    sizes = [max([len(head[i]), *(len(row[i]) for row in body)]) + 3
             for i in range(len(head))]
    if width is None or sum(sizes) + 1 <= width or len(head) < 3:
        return [list(range(len(head)))]
    key = [0]
    while (len(key) < 2 and key[-1] + 1 < len(head) - 1 and not right[key[-1] + 1]
           and sum(sizes[i] for i in key) + sizes[key[-1] + 1] <= width // 2):
        key.append(key[-1] + 1)
    groups: list[list[int]] = [list(key)]
    for index in range(len(key), len(head)):
        if len(groups[-1]) > len(key) and sum(sizes[i] for i in groups[-1]) + sizes[index] + 1 \
                > width:
            groups.append(list(key))
        groups[-1].append(index)
    return groups


def fenced(text: str, language: str = "text") -> list[str]:
    """``text`` in a fenced block whose fence is longer than any backtick run inside."""
    longest = max((len(run) for run in re.findall(r"`+", text)), default=0)
    fence = "`" * max(3, longest + 1)
    return [f"{fence}{language}", text.rstrip("\n"), fence, ""]


def code(text: str) -> str:
    """Inline code that survives backticks in ``text``."""
    longest = max((len(run) for run in re.findall(r"`+", text)), default=0)
    fence = "`" * (longest + 1)
    pad = " " if text.startswith("`") or text.endswith("`") else ""
    return f"{fence}{pad}{text}{pad}{fence}"


def with_unit(name: str, units: str) -> str:
    """A column header: ``name [units]`` (``name`` alone without units)."""
    return f"{name} [{units}]" if units else name


def wrap_markdown(text: str, width: int = WIDTH) -> list[str]:
    """The lines of the Markdown ``text`` with every paragraph and list-item line longer than
    ``width`` characters broken at spaces (a list item's continuation indented under its
    text: it renders the same); tables, headings, fenced blocks and HTML left as they are."""
    out: list[str] = []
    in_fence = False
    for line in text.splitlines():
        if line.lstrip().startswith(("```", "~~~")):
            in_fence = not in_fence
        if in_fence or len(line) <= width or line.lstrip().startswith(("|", "#", "<", "```")):
            out.append(line)
            continue
        marker = _LIST_ITEM.match(line)
        first = marker.group(1) if marker else line[:len(line) - len(line.lstrip())]
        out += textwrap.wrap(line[len(first):], width, initial_indent=first,
                             subsequent_indent=" " * len(first), break_long_words=False,
                             break_on_hyphens=False)
    return out
