"""Markdown pieces of a report (:mod:`flex.tools.report`): values, cells, tables, fenced
blocks, inline code, and prose wrapped to short lines.

A report is read in an editor and in a browser: no line of prose is longer than
:data:`WIDTH` characters (:func:`wrap_markdown` breaks paragraphs and list items, which
Markdown joins again), and a table cell holds a number, a name or a few words.
"""

from __future__ import annotations

import re
import textwrap
from typing import Any

import numpy as np

#: prose lines are wrapped to this many characters [characters]
WIDTH = 100
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


def table(header: list[str], rows: list[list[Any]], right: list[bool] | None = None
          ) -> list[str]:
    """A Markdown table (then an empty line) of ``rows`` under ``header``; the columns
    ``right`` marks (numbers) aligned right."""
    right = right or [False] * len(header)
    lines = ["| " + " | ".join(cell(h) for h in header) + " |",
             "|" + "|".join("---:" if flag else "---" for flag in right) + "|"]
    lines += ["| " + " | ".join(cell(value) for value in row) + " |" for row in rows]
    return lines + [""]


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
