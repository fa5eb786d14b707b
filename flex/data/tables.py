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
