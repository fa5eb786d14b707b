"""What is in a result file (``python -m flex inspect FILE.h5 [PATH]``).

:func:`describe` reads a file into a plain dictionary (the ``--json`` output): provenance
(flex and engine versions, git commit, creation time, command), the resolved scene, every
case with its status, counters, time range, scene changes and datasets (shape, dtype, units,
description), and the ``/summary`` datasets (scalars with their values). With a PATH (the
forms of :func:`flex.data.results.select_datasets`) only the datasets it names are listed, the
scene shown is that case's full scene, and a single dataset gets its statistics (minimum and
maximum with the time they occur, first and last value). :func:`format_description` renders
the dictionary as the text the command prints.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from flex.data.results import (
    ResultPathError,
    attribute_value,
    case_names,
    parse_spec,
    reading,
    select_datasets,
    split_case_path,
)

PROVENANCE_KEYS = ("flex_format", "study", "flex_version", "git_commit", "git_dirty",
                   "exudyn_version", "ngsolve_version", "h5py_version", "numpy_version",
                   "scipy_version", "python_version", "platform", "created_utc", "command")
ENGINES = ("exudyn", "ngsolve", "h5py", "numpy", "scipy")


def describe(path: str | Path, spec: str | None = None) -> dict[str, Any]:
    """Everything :mod:`flex.tools.inspect` shows about ``path`` (restricted to ``spec``).

    Returns a JSON-serialisable dict with keys ``file``, ``provenance``, ``attributes``
    (other root attributes), ``scene_toml``, ``cases``, ``summary``, ``other`` and, with
    ``spec``, ``selection`` and (one dataset) ``dataset``. Raises
    :class:`~flex.base.errors.ResultFileError` for a bad file or a path it does not have.
    """
    name, column = parse_spec(spec) if spec else ("", None)
    with reading(path) as h5:
        selected = set(select_datasets(h5, name, path)) if spec else None
        if column is not None:  # a [i] suffix: one column of a two-column dataset
            _check_column(h5, selected or set(), column, name, path)
        root = {key: attribute_value(value) for key, value in h5.attrs.items()}
        provenance = {key: root.pop(key) for key in PROVENANCE_KEYS if key in root}
        scene_toml = str(root.pop("scene_toml", ""))
        out: dict[str, Any] = {"file": str(path), "provenance": provenance,
                               "attributes": root, "scene_toml": scene_toml,
                               "cases": {}, "summary": [], "other": []}
        base_scene = _parse_toml(scene_toml)
        out["case_count"] = len(case_names(h5))
        for case in case_names(h5):
            group = h5[f"cases/{case}"]
            if not hasattr(group, "keys"):
                continue
            entries = _entries(group, f"cases/{case}/", selected)
            if selected is not None and not entries:
                continue
            attrs = {key: attribute_value(value) for key, value in group.attrs.items()}
            time_s = group["time"][()] if "time" in group and hasattr(group["time"],
                                                                       "shape") else None
            info: dict[str, Any] = {
                "status": attrs.pop("status", "ok"), "message": attrs.pop("message", ""),
                "samples": int(len(time_s)) if time_s is not None and time_s.ndim == 1 else None,
                "time_range_s": ([float(time_s[0]), float(time_s[-1])]
                                 if time_s is not None and time_s.ndim == 1 and len(time_s)
                                 else None),
                "counters": {key[len("counter_"):]: attrs.pop(key) for key in list(attrs)
                             if key.startswith("counter_")},
                "scene_toml": str(attrs.pop("scene_toml", "")),
                "solver_settings_toml": str(attrs.pop("solver_settings_toml", "")),
                "attributes": attrs, "datasets": entries}
            info["scene_changes"] = _changes(base_scene, _parse_toml(info["scene_toml"]),
                                             str(attrs.get("solver_defaults_keys", "")))
            out["cases"][case] = info
        for name in h5:
            if name == "cases":
                continue
            obj = h5[name]
            entries = (_entries(obj, f"{name}/", selected) if hasattr(obj, "keys")
                       else _entries(h5, "", selected, only=[name]))
            out["summary" if name == "summary" else "other"] += entries
        if spec:
            out["selection"] = spec
            if len(selected or ()) == 1:
                (only,) = selected
                out["dataset"] = _statistics(h5, only, column)
        return out


def _check_column(h5, selected: set[str], column: int, name: str, label) -> None:
    """A ``[column]`` suffix must name a column of every dataset selected (two-column
    curves: 0 = x, 1 = y)."""
    for full in sorted(selected):
        shape = h5[full].shape
        if len(shape) != 2 or column >= shape[1]:
            raise ResultPathError(f"{full}[{column}] in '{label}': no such column (shape "
                                  f"{tuple(shape)}; a [i] suffix picks column i of a "
                                  f"two-column dataset; {name!r} without it shows them all)")


def _entries(group, prefix: str, selected: set[str] | None,
             only: list[str] | None = None) -> list[dict[str, Any]]:
    """One entry per dataset below ``group`` (paths relative to the case for cases)."""
    names: list[str] = []
    if only is not None:
        names = [n for n in only if hasattr(group[n], "shape")]
    else:
        group.visititems(lambda n, obj: names.append(n) if hasattr(obj, "shape") else None)
    out = []
    for name in names:
        full = prefix + name
        if selected is not None and full not in selected:
            continue
        dataset = group[name]
        entry = {"path": full if not full.startswith("cases/") else split_case_path(full)[1],
                 "full_path": full, "shape": list(dataset.shape), "dtype": _dtype(dataset),
                 **_units_description(dataset)}
        if dataset.shape == () or (dataset.size <= 3 and dataset.ndim == 1
                                   and not full.startswith("cases/")):
            entry["value"] = attribute_value(dataset[()])
        out.append(entry)
    return out


def _units_description(dataset) -> dict[str, str]:
    return {key: str(attribute_value(dataset.attrs.get(key, "")))
            for key in ("units", "description")}


def _dtype(dataset) -> str:
    kind = dataset.dtype.kind
    return "text" if kind in "OSU" else str(dataset.dtype)


def _parse_toml(text: str) -> dict[str, Any] | None:
    try:
        return tomllib.loads(text) if text else None
    except tomllib.TOMLDecodeError:
        return None


def _changes(base: dict[str, Any] | None, scene: dict[str, Any] | None,
             filled_by_flex: str = "") -> dict[str, Any]:
    """``{"section.key": value}`` where ``scene`` differs from ``base``; ``"auto"`` keys that
    flex filled (``filled_by_flex``: the case's ``solver_defaults_keys``: simulation keys by
    name, link keys as ``coupler.modes``) are not changes."""
    if base is None or scene is None:
        return {}
    filled = {item.split(" = ")[0] for item in filled_by_flex.split(", ") if item}
    out = {}
    for section, table in scene.items():
        if not isinstance(table, dict):
            continue
        for key, value in table.items():
            if (section == "simulation" and key in filled) or f"{section}.{key}" in filled:
                continue  # a solver key, or a link's modes / mesh size, that flex filled
            if not isinstance(base.get(section), dict) or base[section].get(key) != value:
                out[f"{section}.{key}"] = value
    return out


def _statistics(h5, path: str, column: int | None = None) -> dict[str, Any]:
    """Minimum, maximum (with their time), first and last value of a numeric dataset (of
    one of its columns)."""
    dataset = h5[path]
    info: dict[str, Any] = {"path": path if column is None else f"{path}[{column}]",
                            "shape": list(dataset.shape),
                            "dtype": _dtype(dataset), **_units_description(dataset)}
    values = dataset[()]
    if column is not None:
        values = values[:, column]
    if not isinstance(values, np.ndarray) or values.dtype.kind not in "biuf" or values.size == 0:
        info["value"] = attribute_value(values) if np.size(values) <= 20 else None
        return info
    case, _ = split_case_path(path)
    time_s = None
    if case is not None and f"cases/{case}/time" in h5:
        candidate = h5[f"cases/{case}/time"][()]
        if (values.ndim in (1, 2) and np.ndim(candidate) == 1
                and len(candidate) == values.shape[0]):
            time_s = candidate
    columns = values.reshape(len(values), -1).T if values.ndim in (1, 2) else [values.ravel()]
    stats = []
    for column in columns:
        finite = np.where(np.isfinite(column), column, np.nan)
        if np.isnan(finite).all():
            stats.append({"min": None, "max": None, "non_finite": int(column.size)})
            continue
        low, high = int(np.nanargmin(finite)), int(np.nanargmax(finite))
        entry = {"min": float(column[low]), "max": float(column[high]),
                 "first": float(column[0]), "last": float(column[-1]),
                 "non_finite": int(np.isnan(finite).sum())}
        if time_s is not None:
            entry["time_of_min_s"] = float(time_s[low])
            entry["time_of_max_s"] = float(time_s[high])
        stats.append(entry)
    info["columns"] = stats
    return info


def format_description(info: dict[str, Any]) -> str:
    """The text ``python -m flex inspect`` prints for a :func:`describe` dictionary."""
    prov = info["provenance"]
    lines = [info["file"]]

    def row(label: str, text: str) -> None:
        if text:
            lines.append(f"  {label:9s}{text}")

    cases = info["cases"]
    statuses = ", ".join(f"{name} {case['status']}" for name, case in cases.items())
    total = info.get("case_count", len(cases))
    shown = (f" (the {len(cases)} of the file's {total} cases that {info['selection']} "
             f"matches)" if info.get("selection") and total != len(cases) else "")
    row("study", f"{prov.get('study', '?')} ({prov.get('flex_format', '?')})"
        + (f"; cases: {statuses}{shown}" if statuses else ""))
    dirty = {"yes": " (with uncommitted changes)", "no": " (clean)"}.get(
        str(prov.get("git_dirty")), "")
    row("flex", f"{prov.get('flex_version', '?')}, git {prov.get('git_commit', '?')}{dirty}")
    row("engines", ", ".join(f"{name} {prov[f'{name}_version']}" for name in ENGINES
                             if f"{name}_version" in prov))
    row("python", f"{prov.get('python_version', '?')} on {prov.get('platform', '?')}")
    row("created", f"{prov.get('created_utc', '?')} (UTC)")
    row("command", str(prov.get("command", "")))
    row("also", ", ".join(f"{key} = {_short(value)}" for key, value in
                          info["attributes"].items()))
    for name, case in cases.items():
        lines.append("")
        lines.append(f"cases/{name}  {_case_line(case)}")
        if case["message"]:
            lines.append(f"  message: {case['message']}")
        if case["attributes"].get("validity_warning"):
            lines.append(f"  WARNING: {case['attributes']['validity_warning']}")
        lines += _estimate_lines(case["attributes"])
        lines += [f"  {line}" for line in stress_lines(case["attributes"])]
        if case["scene_changes"]:
            changes = ", ".join(f"{k} = {_short(v)}" for k, v in case["scene_changes"].items())
            lines.append(f"  scene: the file's scene with {changes}")
        lines += _solver_lines(case)
        lines += _table(case["datasets"])
    for title, entries in (("summary", info["summary"]), ("other", info["other"])):
        if entries:
            lines += ["", title]
            lines += _table(entries, strip=f"{title}/" if title == "summary" else "")
    if "dataset" in info:
        lines += ["", *_statistics_lines(info["dataset"])]
    scene_toml, heading = info["scene_toml"], "scene (resolved; root attribute scene_toml)"
    if '= "auto"' in scene_toml:
        heading = 'scene (root attribute scene_toml; each case holds its "auto" keys resolved)'
    if len(cases) == 1:  # one case (in the file, or matching PATH): the settings it ran with
        (name, case), = cases.items()
        if case["scene_toml"]:
            scene_toml, heading = case["scene_toml"], (
                f"scene of case {name} (resolved: the settings it ran with"
                f"{', after refinement' if case['attributes'].get('refine_status') else ''})")
    if scene_toml:
        lines += ["", heading]
        lines += [f"  {line}" if line else "" for line in scene_toml.rstrip().splitlines()]
    return "\n".join(lines)


def _solver_lines(case: dict[str, Any]) -> list[str]:
    """What the case's ``"auto"`` solver keys resolved to; after ``fidelity.refine`` that was
    the first guess, and the settings the stored run used (its scene) follow."""
    attrs = case["attributes"]
    keys = str(attrs.get("solver_defaults_keys", ""))
    if not keys:
        return []
    refined = bool(attrs.get("refine_status"))
    lines = [f"  solver: \"auto\" -> {'first guess ' if refined else ''}{keys} "
             f"({attrs.get('solver_defaults_entry', '?')}: "
             f"{attrs.get('solver_defaults_reason', '')})"]
    scene = _parse_toml(case["scene_toml"])
    if refined and scene:
        final = []
        for item in keys.split(", "):
            name = item.split(" = ")[0]
            section, key = name.split(".") if "." in name else ("simulation", name)
            if isinstance(scene.get(section), dict) and key in scene[section]:
                final.append(f"{name} = {scene[section][key]!r}")
        lines.append(f"  refined (fidelity.refine: {attrs['refine_status']}): the stored run "
                     f"used {', '.join(final)}")
    return lines


def _estimate_lines(attrs: dict[str, Any]) -> list[str]:
    """The case's error budget (:mod:`flex.fidelity.error_budget`): each headline quantity
    with its value, total estimated error (absolute and relative) and terms; how the terms
    were made, what the budget leaves out, the step estimate's validity."""
    from flex.fidelity.stored_budget import PREFIX, budget_rows, coverage_text, stored_coverage

    rows = budget_rows(attrs)
    if not rows and f"{PREFIX}validity" not in attrs:
        return []
    lines = ["  estimated error (total = the root-sum-square of the terms: the estimate, what "
             "the error is; the certificate: a bound, the estimate times its stated factor, "
             "what refinement decides on; a raw peak's is a bound, not an "
             "estimate, and says so):"]
    lines += [f"    {row.text()}" for row in rows] or ["    none"]
    for key in ("method", "leaves_out", "validity", "unknown"):
        if attrs.get(PREFIX + key):
            lines.append(f"    {key.replace('_', ' ')}: {attrs[PREFIX + key]}")
    coverage = stored_coverage(attrs)
    if coverage:
        lines.append(f"    {coverage_text(coverage, float(attrs.get('tolerance_relative', 0)))}")
    lines += _prediction_lines(attrs)
    lines += [f"    crest gap of the {key.removeprefix('crest_gap_').split('_')[0]}'s peak "
              f"deflection: {_quantity(value, 'm')} (the second-largest crest lies this far "
              f"below it)" for key, value in attrs.items() if key.startswith("crest_gap_")]
    if attrs.get("refine_status"):
        lines.append(f"  refinement (fidelity.refine): {attrs['refine_status']}, "
                     f"{_quantity(attrs.get('refine_wall_time_s', 0.0), 's')}")
        lines += [f"    {line}" for line in str(attrs.get("refine_attempts", "")).splitlines()]
    return lines


def _prediction_lines(attrs: dict[str, Any]) -> list[str]:
    """A rigid link's predicted bending (``predicted_*``, a prediction from its loads, not
    a run), each with its stated error."""
    from flex.fidelity.predictor import PREDICTED_PREFIX

    lines = []
    for key, value in attrs.items():
        name = key.removeprefix(PREDICTED_PREFIX)
        if not key.startswith(PREDICTED_PREFIX) or name.endswith("_error") or name == "method":
            continue
        unit = "Pa" if name.endswith("_Pa") else "m"
        error = attrs.get(f"{key}_error")
        what = name.removesuffix(f"_{unit}").replace("_", " ")
        lines.append(f"    predicted {what} (rigid link, a prediction): {_quantity(value, unit)}"
                     + (f" +- {_quantity(error, unit)}" if error is not None else ""))
    if attrs.get(f"{PREDICTED_PREFIX}method"):  # also when it says why there is none
        lines.append(f"    prediction: {attrs[f'{PREDICTED_PREFIX}method']}")
    return lines


def _position(value: Any) -> bool:
    """Whether a stored position is three real numbers (x, y, z)."""
    try:
        return np.size(value) == 3 and bool(np.all(np.isfinite(np.asarray(value,
                                                                          dtype=float))))
    except (TypeError, ValueError):
        return False


def stress_lines(attrs: dict[str, Any]) -> list[str]:
    """The peak von Mises stress of each FFRF link (case attributes of
    :func:`flex.bodies.stress.peak_attrs`), where and when, with its estimated error:
    one line per link."""
    from flex.fidelity.stored_budget import PREFIX

    lines = []
    for link in ("coupler", "crank"):
        parts = []
        for suffix, where in (("", "away from the joint faces"), ("_at_joints", "at them")):
            name = f"{link}_peak_von_mises{suffix}"
            if f"{name}_Pa" not in attrs:
                continue
            raw_error = attrs.get(f"{PREFIX}{name}_Pa")
            error = _number(raw_error)
            if _number(attrs[f"{name}_Pa"]) is None or _number(attrs.get(
                    f"{name}_time_s")) is None or not _position(attrs.get(
                        f"{name}_position_m")):
                parts.append(f"{_short(attrs[f'{name}_Pa'])} Pa {where} at t = "
                             f"{_short(attrs.get(f'{name}_time_s'))} s (attributes that are "
                             f"not one number, shown as stored)")
                continue
            x, y, z = (1e3 * float(v) for v in np.ravel(attrs[f"{name}_position_m"]))
            if raw_error is not None and error is None:
                parts.append(f"estimated error {_short(raw_error)} (not a number, as stored)")
            parts.append(f"{attrs[f'{name}_Pa'] / 1e6:.4g} MPa {where} at t = "
                         f"{attrs[f'{name}_time_s'] * 1e3:.4g} ms, (x, y, z) = ({x:.3g}, "
                         f"{y:.3g}, {z:.3g}) mm on the plate"
                         + (f" (estimated error {error / 1e6:.2g} MPa: the budget above)"
                            if error is not None else ""))
        if parts:
            lines.append(f"peak von Mises stress, {link}: " + "; ".join(parts))
    return lines


def _number(value: Any) -> float | None:
    """``value`` as a float when it is one number (a stored attribute a hand may have made
    a string or an array), else None."""
    if isinstance(value, bool | str | bytes) or np.size(value) != 1:
        return None
    try:
        return float(np.ravel(value)[0])
    except (TypeError, ValueError):
        return None


def _quantity(value: Any, units: str) -> str:
    """A stored number with its units, or the stored value as it is when it is not one."""
    number = _number(value)
    return f"{number:.3g} {units}" if number is not None else f"{_short(value)} (not a number)"


def _case_line(case: dict[str, Any]) -> str:
    parts = [case["status"]]
    if case["samples"] is not None and case["time_range_s"]:
        start, end = case["time_range_s"]
        parts.append(f"{case['samples']} samples, t = {start:g} .. {end:g} s")
    counters = case["counters"]
    named = [("steps", "steps"), ("newton_iterations", "Newton iterations"),
             ("jacobian_updates", "Jacobian updates")]
    text = ", ".join(f"{_short(counters[key])} {label}" for key, label in named
                     if key in counters)
    if "wall_time_s" in counters:
        wall = counters["wall_time_s"]
        wall = f"{wall:.3g}" if isinstance(wall, int | float) else _short(wall)
        text += f", {wall} s wall time"
    if text:
        parts.append(text.lstrip(", "))
    return "; ".join(parts)


def _table(entries: list[dict[str, Any]], strip: str = "") -> list[str]:
    if not entries:
        return []
    names = [e["path"][len(strip):] if strip and e["path"].startswith(strip) else e["path"]
             for e in entries]
    width = max(len(n) for n in names)
    lines = []
    for name, entry in zip(names, entries, strict=True):
        if "value" in entry:
            shape = f"= {_short(entry['value'])}"
        else:
            shape = "(" + ", ".join(str(n) for n in entry["shape"]) + (
                ",)" if len(entry["shape"]) == 1 else ")")
            if entry["dtype"] == "text":
                shape += " text"
        lines.append(f"  {name:{width}s}  {shape:14s}  {entry['units']:9s}  "
                     f"{entry['description']}")
    return lines


def _statistics_lines(stats: dict[str, Any]) -> list[str]:
    lines = [stats["path"],
             f"  shape {tuple(stats['shape'])} {stats['dtype']}, units {stats['units']}: "
             f"{stats['description']}"]
    columns = stats.get("columns")
    if columns is None:
        if stats.get("value") is not None:
            lines.append(f"  value {_short(stats['value'], 200)}")
        return lines
    for index, column in enumerate(columns):
        prefix = f"  [{index}] " if len(columns) > 1 else "  "
        if column["min"] is None:
            lines.append(f"{prefix}no finite values ({column['non_finite']} non-finite)")
            continue
        at_min = (f" at t = {column['time_of_min_s']:.6g} s" if "time_of_min_s" in column
                  else "")
        at_max = (f" at t = {column['time_of_max_s']:.6g} s" if "time_of_max_s" in column
                  else "")
        bad = f"; {column['non_finite']} non-finite" if column["non_finite"] else ""
        lines.append(f"{prefix}min {column['min']:.6g}{at_min}, max {column['max']:.6g}"
                     f"{at_max}; first {column['first']:.6g}, last {column['last']:.6g}{bad}")
    return lines


def _short(value: Any, limit: int = 60) -> str:
    if isinstance(value, float):
        text = f"{value:.4g}"
    elif isinstance(value, list) and all(isinstance(v, float) for v in value):
        text = "[" + ", ".join(f"{v:.4g}" for v in value) + "]"
    else:
        text = str(value)
    text = text.replace("\n", " ")
    return text if len(text) <= limit else text[:limit - 3] + "..."
