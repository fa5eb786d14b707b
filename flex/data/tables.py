"""Tables as datasets: a table's columns declared once, each stored as one dataset.

A study's summary often holds a table: rows of values (one mapping per row) and, per column,
its unit and description. :func:`table_datasets` turns the rows and that declaration into one
:class:`~flex.data.results.Dataset` per column, so the units and descriptions live beside
the column names, not in a hand-written ``Dataset(...)`` per column.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from flex.data.results import Dataset

#: a column's declaration: (units, description) or (units, description, numpy dtype)
Column = tuple[str, str] | tuple[str, str, Any]


def table_datasets(rows: Iterable[Mapping[str, Any]], columns: Mapping[str, Column],
                   group: str = "") -> dict[str, Dataset]:
    """One dataset per declared column, ``<group>/<column>`` (``<column>`` without a group),
    in the order of ``columns``: the column's value of every row, in row order, with the
    declared units and description.

    The array's dtype is the declared one, else ``object`` for a column of text (the first
    row's value is a ``str``: Python strings, stored as HDF5 strings) and numpy's own
    otherwise (an empty table gives empty float columns). A column missing from a row
    raises KeyError: every row holds every declared column."""
    rows = list(rows)
    prefix = f"{group}/" if group else ""
    out = {}
    for name, (units, description, *dtype) in columns.items():
        values = [row[name] for row in rows]
        kind = dtype[0] if dtype else (object if values and isinstance(values[0], str)
                                       else None)
        out[prefix + name] = Dataset(np.array(values, dtype=kind), units, description)
    return out


#: the group under ``/summary`` holding the tables a report shows with the study's findings
FINDINGS = "findings"
#: attributes of a findings table's column datasets: the table's title, the column's
#: position in it, the table's position among the findings tables, the column's header
TITLE_ATTR, COLUMN_ATTR, ORDER_ATTR, LABEL_ATTR = ("table_title", "table_column",
                                                   "table_order", "table_label")


def findings_table(name: str, title: str, rows: Iterable[Mapping[str, Any]],
                   columns: Mapping[str, Column], order: int = 0,
                   labels: Mapping[str, str] | None = None) -> dict[str, Dataset]:
    """A table the report shows with the study's findings (``flex report``: its study report
    section): the columns of :func:`table_datasets` under ``findings/<name>/``, each marked
    (dataset attributes) with the table's ``title``, its own position, the table's ``order``
    among the findings tables (smallest first) and its header (``labels[column]``, default
    the column's name with spaces; the report adds ``[units]``).

    The report shows every row: keep the cells short (a number, a name, a few words) and
    the long explanations in the column descriptions or the study's printed report."""
    out = table_datasets(rows, columns, f"{FINDINGS}/{name}")
    for position, (key, dataset) in enumerate(out.items()):
        column = key.rsplit("/", 1)[-1]
        dataset.attrs.update({TITLE_ATTR: title, COLUMN_ATTR: position, ORDER_ATTR: order,
                              LABEL_ATTR: (labels or {}).get(column, column.replace("_", " "))})
    return out
