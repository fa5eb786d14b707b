"""Plot stored curves (``python -m flex plot FILE.h5 PATH [PATH ...]``).

Contract: each PATH (the forms of :func:`flex.data.results.select_datasets`, plus an optional
``[column]`` suffix) is drawn against its case's ``time`` -- or, with ``x_spec``, against
another dataset of the same case (``--x crank/angle``: speed over angle; ``--x
crank/midpoint_position[0]`` with ``crank/midpoint_position[1]``: the trajectory). Axis
labels carry the datasets' units; curves of a second unit go on a right-hand axis, a third
unit is refused. Every file in ``others`` (``--vs``: another run, or a reference curve file
such as ``tests/reference_curves/*.h5``) overlays the same PATHs, dashed, in the same colour.
Datasets without a time axis are drawn against their index. ``--x`` naming a dataset of
another case (sampled on another time base) is refused, naming both cases. The figure is
written atomically (PNG, PDF or SVG by the extension; a temporary file renamed when complete,
so a failure leaves a previous figure intact) and its path returned; a figure path that is
one of the files being read, a folder, or inside a file or an unwritable folder is refused
(:class:`~flex.base.errors.OutputError`) before anything is read.
"""

from __future__ import annotations

import os
import re
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flex.base.errors import FlexError, OutputError
from flex.data.results import (
    ResultPathError,
    atomic_path,
    os_reason,
    parse_spec,
    reading,
    select_datasets,
    split_case_path,
)

FORMATS = (".png", ".pdf", ".svg")
LINESTYLES = ("-", "--", ":", "-.")


@dataclass
class Curve:
    """One line of a plot: x and y values with their labels and units."""

    file: str
    label: str
    key: str  # the same curve in every file has the same key (same colour)
    x: np.ndarray
    y: np.ndarray
    x_label: str
    x_units: str
    y_units: str


def load_curves(path: str | Path, specs: Sequence[str], x_spec: str | None = None
                ) -> list[Curve]:
    """The curves ``specs`` name in result file ``path`` (see the module contract)."""
    curves: list[Curve] = []
    with reading(path) as h5:
        for spec in specs:
            name, column = parse_spec(spec)
            for full in select_datasets(h5, name, path):
                case, rel = split_case_path(full)
                if case is not None and rel == "time" and len(specs) > 1:
                    continue
                y, y_units, columns = _values(h5, full, column, path)
                x, x_label, x_units = _abscissa(h5, full, case, x_spec, len(y), path)
                for index, values in columns(y):
                    suffix = "" if index is None else f"[{index}]"
                    label = (f"{case}/{rel}" if case is not None else full) + suffix
                    curves.append(Curve(str(path), label, full + suffix, x, values,
                                        x_label, x_units, y_units))
    return curves


def _values(h5, full: str, column: int | None, label):
    dataset = h5[full]
    values = dataset[()]
    if not isinstance(values, np.ndarray) or values.dtype.kind not in "biuf":
        raise FlexError(f"{full} in '{label}' is text or a scalar; nothing to plot "
                        f"(python -m flex inspect shows its value)")
    units = str(_attr(dataset, "units"))
    if column is not None:
        if values.ndim != 2 or column >= values.shape[1]:
            raise ResultPathError(f"{full}[{column}] in '{label}': no such column (shape "
                                  f"{values.shape})")
        values = values[:, column]
    if values.ndim > 2:
        raise FlexError(f"{full} in '{label}' has shape {values.shape}; plot one column "
                        f"of a 1-D or 2-D dataset")

    def columns(array: np.ndarray):
        if array.ndim == 1:
            return [(column, array.astype(float))]
        return [(index, array[:, index].astype(float)) for index in range(array.shape[1])]

    return values, units, columns


def _abscissa(h5, full: str, case: str | None, x_spec: str | None, count: int, label):
    """x values, label and units for a dataset of ``count`` rows."""
    if x_spec:
        name, column = parse_spec(x_spec)
        target = _x_dataset(h5, name, case, full, x_spec, label)
        values = h5[target][()]
        if not isinstance(values, np.ndarray) or values.dtype.kind not in "biuf":
            raise FlexError(f"--x {x_spec}: {target} in '{label}' is text or a scalar; it "
                            f"must be a numeric column of {count} values like {full}")
        if column is not None:
            if np.ndim(values) != 2 or column >= np.shape(values)[1]:
                raise ResultPathError(f"--x {x_spec}: {target} in '{label}' has no column "
                                      f"{column} (shape {np.shape(values)})")
            values = values[:, column]
        if np.ndim(values) != 1 or len(values) != count:
            raise FlexError(f"--x {x_spec}: {target} in '{label}' has shape "
                            f"{np.shape(values)}; it must be one column of {count} values "
                            f"like {full} (add [0] or [1] for a two-column dataset)")
        rel = split_case_path(target)[1] + ("" if column is None else f"[{column}]")
        return values.astype(float), rel, str(_attr(h5[target], "units"))
    time_path = f"cases/{case}/time" if case is not None else None
    if time_path and time_path in h5 and len(h5[time_path]) == count:
        return h5[time_path][()].astype(float), "time", "s"
    return np.arange(count, dtype=float), "index", ""


def _x_dataset(h5, name: str, case: str | None, full: str, x_spec: str, label) -> str:
    """The dataset ``--x`` names for the curve ``full`` (of ``case``): looked up first inside
    that case; a dataset of another case (or outside the cases) is refused, since it was
    sampled on another time base."""
    if case is not None and not any(char in name for char in "*?"):
        candidate = f"cases/{case}/{name}"
        if candidate in h5 and hasattr(h5[candidate], "shape"):
            return candidate
    found = select_datasets(h5, name, label)
    same = [path for path in found if split_case_path(path)[0] == case]
    if len(same) == 1:
        return same[0]
    if len(same) > 1:
        raise FlexError(f"--x {x_spec}: names {len(same)} datasets in '{label}' ("
                        f"{', '.join(same[:3])}{', ...' if len(same) > 3 else ''}); "
                        f"name one dataset")
    def owner(name: str | None) -> str:
        return f"belongs to case {name}" if name is not None else "is outside the cases"

    other = split_case_path(found[0])[0]
    raise FlexError(f"--x {x_spec}: {found[0]} in '{label}' {owner(other)}, but {full} "
                    f"{owner(case)}; --x must name a dataset of the same case (each case "
                    f"has its own time samples)")


def _attr(dataset, key: str) -> str:
    value = dataset.attrs.get(key, "")
    return value.decode() if isinstance(value, bytes) else str(value)


def default_output(path: str | Path, specs: Sequence[str]) -> Path:
    """``<folder of FILE>/figures/plot-<file stem>-<paths>.png`` (never a study's own figure)."""
    path = Path(path)
    slug = re.sub(r"[^A-Za-z0-9_.]+", "-", "-".join(specs)).strip("-.")[:80] or "curves"
    return path.parent / "figures" / f"plot-{path.stem}-{slug}.png"


def plot_curves(path: str | Path, specs: Sequence[str], others: Sequence[str | Path] = (),
                x_spec: str | None = None, out: str | Path | None = None,
                title: str | None = None) -> Path:
    """Draw ``specs`` of result file ``path`` (and of each file in ``others``) and save.

    Returns the figure's path (default :func:`default_output`). Raises
    :class:`~flex.base.errors.FlexError` for a bad file, a missing path, mismatched x units or
    more than two y units.
    """
    if not specs:
        raise FlexError("plot needs at least one PATH, e.g. crank/angle")
    if out is not None and not str(out).strip():  # '' wrote the default figure instead
        raise OutputError(f"--out {str(out)!r}: an empty file name; give a figure file, "
                          f".png, .pdf or .svg (or leave --out out for the default)")
    target = Path(out) if out else default_output(path, specs)
    files = [path, *others]
    _check_output(target, files, "--out" if out else "the default figure")
    curves_by_file = [load_curves(f, specs, x_spec) for f in files]
    curves = [c for group in curves_by_file for c in group]
    if not curves:
        raise FlexError(f"nothing to plot: {' '.join(specs)} in '{path}' names only time "
                        f"bases or empty datasets")
    x_units = list(dict.fromkeys((c.x_label if c.x_label in ("time", "index") else "x",
                                  c.x_units) for c in curves))
    if len(x_units) > 1:
        raise FlexError("the curves have different x axes ("
                        + ", ".join(f"{name} [{units}]" for name, units in x_units)
                        + "); plot them separately")
    y_units = list(dict.fromkeys(c.y_units for c in curves))
    if len(y_units) > 2:
        raise FlexError(f"the curves have {len(y_units)} units ({', '.join(y_units)}); "
                        f"one plot shows at most two (left and right axis)")
    import warnings

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        return _draw(plt, path, specs, files, curves_by_file, curves, y_units, title, target)


def _draw(plt, path, specs, files, curves_by_file, curves, y_units, title, target) -> Path:
    """Draw the curves and write the figure atomically (see :func:`plot_curves`)."""
    fig, left = plt.subplots(figsize=(7.5, 4.5), layout="constrained")
    axes = {y_units[0]: left}
    if len(y_units) == 2:
        axes[y_units[1]] = left.twinx()
    keys = list(dict.fromkeys(c.key for c in curves))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    several = len(files) > 1
    names = [Path(f).name for f in files]
    file_labels = {str(f): (name if names.count(name) == 1 else str(f))
                   for f, name in zip(files, names, strict=True)}
    for file_index, group in enumerate(curves_by_file):
        style = LINESTYLES[file_index % len(LINESTYLES)]
        for curve in group:
            label = f"{file_labels[curve.file]}: {curve.label}" if several else curve.label
            colour = colours[keys.index(curve.key) % len(colours)]
            axes[curve.y_units].plot(curve.x, curve.y, style, color=colour, label=_plain(label),
                                     linewidth=1.4 if file_index == 0 else 1.2)
    first = curves[0]
    left.set_xlabel(_plain(f"{first.x_label} [{first.x_units}]" if first.x_units
                           else first.x_label))
    for units, ax in axes.items():
        names = list(dict.fromkeys(c.label.split("/", 1)[-1] if "/" in c.label else c.label
                                   for c in curves if c.y_units == units))
        name = ", ".join(names) if len(names) <= 2 else "value"
        ax.set_ylabel(_plain(f"{name} [{units}]" if units else name))
    left.grid(True, alpha=0.3)
    handles, labels = [], []
    for ax in axes.values():
        h, lab = ax.get_legend_handles_labels()
        handles += h
        labels += lab
    if len(labels) > 1:  # under the axes: a legend inside would hide curves
        columns = 1 if len(labels) > 4 else 2
        fig.set_figheight(4.5 + 0.22 * -(-len(labels) // columns))
        fig.legend(handles, labels, fontsize="small", loc="outside lower center",
                   ncol=columns)
    if title is None:  # say what is shown: the paths, against what, from which file(s)
        title = (f"{', '.join(specs)} against {first.x_label}: "
                 + " vs ".join(dict.fromkeys(file_labels[str(f)] for f in files)))
    left.set_title(_plain(textwrap.fill(title, 80)), fontsize="medium")
    try:
        fig.canvas.draw()  # drawing errors (values out of range) before any file is made
        target.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(target) as tmp:
            fig.savefig(tmp, dpi=120, format=target.suffix.lower()[1:])
    except OSError as exc:
        raise OutputError(f"cannot write figure '{target}': {os_reason(exc)}; the previous "
                          f"figure (if any) is unchanged") from None
    except (ValueError, OverflowError, ArithmeticError) as exc:
        reason = " ".join(str(exc).split())[:120]
        raise FlexError(f"cannot draw {', '.join(specs)} of '{path}': {reason} (values too "
                        f"large to draw? python -m flex inspect shows their range)") from None
    finally:
        plt.close(fig)
    return target


def _plain(text: str) -> str:
    """``text`` shown as written: a ``$`` does not start matplotlib's math mode (a lone or
    malformed ``$...$`` in a file name, path or title would fail at drawing time)."""
    return str(text).replace("$", r"\$")


def _check_output(target: Path, inputs: Sequence[str | Path], what: str) -> None:
    """Refuse, before anything is read or drawn, a figure path that would overwrite an input
    file or that cannot be written (a folder, a parent that is a file, no permission)."""
    for source in inputs:
        if _same_file(target, Path(source)):
            raise OutputError(f"{what} '{target}' is the result file '{source}' being read; "
                              f"it would be overwritten (choose another figure name)")
    if target.suffix.lower() not in FORMATS:
        raise OutputError(f"{what} '{target}': figures end in {', '.join(FORMATS)}")
    if target.is_dir():
        raise OutputError(f"{what} '{target}' is a directory; name a figure file inside it "
                          f"(e.g. '{target / 'figure.png'}')")
    if target.is_symlink() and not target.exists():
        raise OutputError(f"{what} '{target}' is a symbolic link to nothing")
    folder = target.parent
    while not folder.exists() and not folder.is_symlink() and folder != folder.parent:
        folder = folder.parent
    if folder.is_symlink() and not folder.exists():
        raise OutputError(f"{what} '{target}': '{folder}' is a symbolic link to nothing")
    if not folder.is_dir():
        raise OutputError(f"{what} '{target}': '{folder}' is a file, not a folder; the "
                          f"figure cannot be written there")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{what} '{target}': folder '{folder}' is not writable")


def _same_file(a: Path, b: Path) -> bool:
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
        return a.resolve() == b.resolve()
    except (OSError, RuntimeError, ValueError):
        return False
