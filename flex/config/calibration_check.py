"""The values of a calibration, checked: each key of each file within its accepted range.

A calibration folder (:mod:`flex.config.calibration`) is read by every ``"auto"`` of a run:
a value no fit could have written (a negative step coefficient, a rigid step of a second,
a Newton mode flex does not have) would run and give numbers that look right. Each file is
checked when it is loaded (:func:`check_part`): every table and key it must hold, each value
of the kind and range below, no key flex would ignore. A failure is one
:class:`~flex.base.errors.FlexError` naming the file, the key (``table.key``, ``levels[2].key``)
and the accepted range.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from flex.base.errors import FlexError


@dataclass(frozen=True)
class Spec:
    """One calibration key: its kind (``float``, ``int``, ``bool``, ``str``, ``"matrix"``, a
    tuple of accepted strings), an inclusive ``low`` / ``high`` (``open_low``: strictly
    above ``low``) and whether it may be absent."""

    kind: Any = float
    low: float = -math.inf
    high: float = math.inf
    open_low: bool = False
    optional: bool = False

    def accepted(self) -> str:
        """The accepted range, for messages."""
        if isinstance(self.kind, tuple):
            return "one of " + ", ".join(f'"{c}"' for c in self.kind)
        if self.kind in (str, bool):
            return {str: "a string", bool: "true or false"}[self.kind]
        what = {float: "a finite number", int: "an integer", "matrix": "a square array of "
                "finite numbers"}[self.kind]
        bounds = ([f"{'>' if self.open_low else '>='} {self.low:g}"]
                  if math.isfinite(self.low) else []) + (
            [f"<= {self.high:g}"] if math.isfinite(self.high) else [])
        return what + (f" {' and '.join(bounds)}" if bounds else "")

    def holds(self, value: Any) -> bool:
        """Whether ``value`` is of this kind and in range."""
        if isinstance(self.kind, tuple):
            return isinstance(value, str) and value in self.kind
        if self.kind in (str, bool):
            return isinstance(value, self.kind)
        if self.kind == "matrix":
            rows = value if isinstance(value, list | tuple) else None
            return bool(rows) and all(isinstance(row, list | tuple) and len(row) == len(rows)
                                      and all(_real(v) and math.isfinite(v) for v in row)
                                      for row in rows)
        if not _real(value) or (self.kind is int and not isinstance(value, int)):
            return False
        return (math.isfinite(value) and (value > self.low if self.open_low
                                          else value >= self.low) and value <= self.high)


def _real(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


POSITIVE = Spec(float, 0.0, open_low=True)
FRACTION = Spec(float, 0.0, 1.0, open_low=True)
#: a solver defaults entry (``solver_defaults.toml``; the scene's own ranges of these keys)
SOLVER_ENTRY = {"step_s": Spec(float, 0.0, 1e-3, open_low=True, optional=True),
                "spectral_radius": Spec(float, 0.0, 1.0),
                "newton": Spec(("full", "modified", "jacobian_per_step")),
                "newton_relative_tolerance": Spec(float, 0.0, 1e-3, open_low=True),
                "accuracy": FRACTION}
#: the tables of ``solver_defaults.toml`` (every one an entry of :data:`SOLVER_ENTRY`)
SOLVER_TABLES = ("rigid", "flexible_fallback", "ffrf_rule")
#: ``ffrf_rule.toml``: its tables and the keys of each ``[[levels]]`` entry
RULE_TABLES = {"mesh": {"per_thickness": Spec(float, 0.0, 100.0, open_low=True),
                        "per_length": Spec(float, 1.0, 1000.0)},
               "family": {"slenderness_min": POSITIVE, "slenderness_max": POSITIVE,
                          "damped_ratio_min": Spec(float, 0.0, 1.0)}}
RULE_LEVEL = {"damping": Spec(("undamped", "damped")), "tolerance": Spec(float, 0.0, 0.5,
                                                                         open_low=True),
              "mode_cutoff_ratio": Spec(float, 1.0, 1000.0), "mode_cutoff_load": Spec(float, 0.0),
              "n_load_min": POSITIVE, "n_load_max": POSITIVE,
              "modes_max": Spec(int, 1, 100), "steps_per_top_period": Spec(float, 0.0, 1000.0),
              "steps_coefficient": Spec(float, 0.0, 1e6, open_low=True),
              "steps_exponent": Spec(float, -10.0, 10.0), "worst_error": Spec(float, 0.0, 1.0),
              "scenes": Spec(list, optional=True)}
#: a criterion file's ``[[laws]]`` entry (``criteria_fit.toml``, ``crank_criteria_fit.toml``)
LAW = {"damping_ratio": Spec(float, 0.0, 1.0), "measure": Spec(str),
       "log_coefficient": Spec(float), "exponent": Spec(float, 0.0, 100.0, open_low=True),
       "floor": Spec(float, 0.0), "with_floor": Spec(bool), "covariance": Spec("matrix"),
       "residual_std": Spec(float, 0.0), "dof": Spec(int, 1),
       "r_squared": Spec(float, -math.inf, 1.0, optional=True),
       "n_min": POSITIVE, "n_max": POSITIVE, "e_min": Spec(float, 0.0, optional=True),
       "e_max": Spec(float, 0.0, optional=True), "n_points": Spec(int, 1, optional=True)}


def check_part(path: Path, part: str, data: Mapping[str, Any]) -> None:
    """Check the parsed file ``path`` of calibration part ``part`` (a key of
    :data:`flex.config.calibration.FILES`); raise :class:`FlexError` on the first value out
    of range, missing key or key flex would ignore."""
    if part == "solver_defaults":
        _tables(path, data, {name: SOLVER_ENTRY for name in SOLVER_TABLES})
    elif part == "ffrf_rule":
        _tables(path, data, {**RULE_TABLES, "levels": None})
        levels = data["levels"]
        if not isinstance(levels, list) or not levels:
            _fail(path, "levels", "at least one [[levels]] table")
        for index, level in enumerate(levels):
            _keys(path, f"levels[{index}]", level, RULE_LEVEL)
            _ordered(path, f"levels[{index}]", level, "n_load_min", "n_load_max")
        _ordered(path, "family", data["family"], "slenderness_min", "slenderness_max")
    else:
        _tables(path, data, {"criterion": None, "laws": None})
        laws = data["laws"]
        if not isinstance(laws, list) or not laws:
            _fail(path, "laws", "at least one [[laws]] table")
        for index, law in enumerate(laws):
            known = {key: value for key, value in law.items() if not key.startswith("meta_")} \
                if isinstance(law, Mapping) else law
            _keys(path, f"laws[{index}]", known, LAW)
            _ordered(path, f"laws[{index}]", law, "n_min", "n_max")


def _tables(path: Path, data: Mapping[str, Any], tables: Mapping[str, Any]) -> None:
    for name in data:
        if name not in tables:
            _fail(path, name, f"a table of this file ({', '.join(tables)}); it would be ignored")
    for name, keys in tables.items():
        if name not in data:
            _fail(path, name, "present: the file must hold it")
        if keys is not None:
            _keys(path, name, data[name], keys)


def _keys(path: Path, where: str, table: Any, keys: Mapping[str, Spec]) -> None:
    if not isinstance(table, Mapping):
        _fail(path, where, "a table")
    for key, value in table.items():
        spec = keys.get(key)
        if spec is None:
            _fail(path, f"{where}.{key}", f"one of the keys {', '.join(keys)} (it would be "
                                          f"ignored)")
        if spec.kind is list:
            if not isinstance(value, list):
                _fail(path, f"{where}.{key}", "an array")
        elif not spec.holds(value):
            _fail(path, f"{where}.{key}", spec.accepted(), value)
    for key, spec in keys.items():
        if key not in table and not spec.optional:
            _fail(path, f"{where}.{key}", f"present ({spec.accepted()})")


def _ordered(path: Path, where: str, table: Mapping[str, Any], low: str, high: str) -> None:
    if table[low] > table[high]:
        _fail(path, f"{where}.{high}", f">= {where}.{low} = {table[low]:g}", table[high])


def _fail(path: Path, key: str, accepted: str, value: Any = None) -> None:
    shown = "" if value is None else f" = {value!r}"[:60]
    raise FlexError(f"calibration file '{path}': {key}{shown}: must be {accepted}")


__all__ = ["LAW", "RULE_LEVEL", "RULE_TABLES", "SOLVER_ENTRY", "Spec", "check_part"]
