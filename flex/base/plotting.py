"""Figure helpers: readable PNGs with titles, axis labels and units (matplotlib, Agg).

House style (what every study figure follows; :func:`review` checks the mechanical part):

- every figure says what is shown in its title; every numeric axis has a label with its
  unit in brackets (``[m]``, ``[-]`` for a ratio);
- tick labels never collide (:func:`review`); long numbers are avoided by choosing the unit
  (mm, ms, um) rather than by packing ticks;
- a trajectory is drawn with equal aspect (a circle stays a circle);
- curves that differ by orders of magnitude get one panel each (:func:`panels`) or a log
  scale of their magnitude; a conserved quantity is shown as its relative drift
  (:func:`relative_drift`) on its own axis, never on a scale that hides it;
- in a legend one style means one thing: colour for one dimension (the case), line style
  or marker for another (the measure), explained by proxy entries (:func:`legend_below`)
  rather than by a caption in the title; abbreviations are spelt out.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np

# figures are made as Figure objects on the Agg canvas, without pyplot (its import and
# backend set-up cost ~0.3 s of a command line that draws one figure)
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import LogLocator, MaxNLocator, NullFormatter

DPI = 120
MICRO = "\u00b5"  # micro sign for units: um -> µm


def new_figure(size: tuple[float, float]) -> Figure:
    """A figure of ``size`` [inch] with constrained layout, on the Agg canvas (no pyplot)."""
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


@contextmanager
def figure(path: Path, title: str, xlabel: str, ylabel: str,
           size: tuple[float, float] = (7.0, 4.5)) -> Iterator:
    """Yield axes; on exit add grid/legend, save ``path`` at 120 dpi and close. The title
    is the figure's (centred on the figure and wrapped to its width, whatever the width of
    the tick labels beside the axes)."""
    fig = new_figure(size)
    ax = fig.subplots()
    fig.suptitle(wrap(title, size[0]))
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    yield ax
    if ax.get_legend_handles_labels()[0] and ax.get_legend() is None and not fig.legends:
        ax.legend(fontsize="small")
    save(fig, path)


@contextmanager
def panels(path: Path, title: str, rows: int = 1, cols: int = 1,
           size: tuple[float, float] | None = None, sharex: bool | str = False,
           sharey: bool | str = False, **kwargs) -> Iterator:
    """Yield ``(fig, axes)`` of a ``rows`` x ``cols`` grid (``axes`` a flat list) under one
    title; on exit add a grid and a legend to every axes that has labelled curves and no
    legend yet, save ``path`` and close. Axis labels are the caller's."""
    size = size or (7.0, 1.0 + 2.4 * rows)
    fig = new_figure(size)
    axes = fig.subplots(rows, cols, sharex=sharex, sharey=sharey, squeeze=False, **kwargs)
    fig.suptitle(wrap(title, size[0]))
    flat = list(axes.ravel())
    for ax in flat:
        ax.grid(True, alpha=0.3)
    yield fig, flat
    for ax in flat if not fig.legends else []:  # a figure legend replaces the axes' own
        if ax.get_legend_handles_labels()[0] and ax.get_legend() is None:
            ax.legend(fontsize="small")
    save(fig, path)


def wrap(title: str, width_in: float) -> str:
    """``title`` broken into lines that fit a figure ``width_in`` inches wide (default font
    size: about 10.5 characters per inch)."""
    import textwrap

    width = max(20, int(width_in * 10.5))
    if len(title) <= width or "\n" in title:
        return title
    lines = -(-len(title) // width)  # balanced lines rather than a last word alone
    return "\n".join(textwrap.wrap(title, min(width, -(-len(title) // lines) + 8),
                                   break_on_hyphens=False))


def save(fig, path: Path) -> Path:
    """Save ``fig`` at :data:`DPI` and close it."""
    fig.savefig(path, dpi=DPI)
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:  # a figure a caller made with pyplot: released from its registry
        pyplot.close(fig)
    return Path(path)


def relative_drift(values: np.ndarray) -> np.ndarray:
    """``(E - E0) / E0`` of a conserved quantity sampled in time (0 where E0 is 0)."""
    values = np.asarray(values, dtype=float)
    start = values[0] if values.size else 0.0
    if start == 0.0:
        return np.zeros_like(values)
    return (values - start) / abs(start)


def scaled(values, unit: str) -> tuple[np.ndarray, str]:
    """``values`` in ``unit`` (SI, e.g. "m", "m/s", "J") rescaled with the SI prefix (k, -,
    m, \u00b5, n) that keeps their largest magnitude in [1, 1000): (values, new unit). Below
    1 n``unit`` (round-off) they stay in ``unit``, the axis showing the power of ten."""
    values = np.asarray(values, dtype=float)
    finite = np.abs(values[np.isfinite(values)])
    peak = finite.max() if finite.size else 0.0
    prefixes = (("k", 1e-3), ("", 1.0), ("m", 1e3), (MICRO, 1e6), ("n", 1e9))
    prefix, factor = next(((p, f) for p, f in prefixes if peak * f >= 1.0), ("", 1.0))
    return values * factor, prefix + unit


def sparse_ticks(ax, axis: str = "both", bins: int = 5) -> None:
    """At most ``bins`` + 1 major ticks on a linear ``axis`` ("x", "y" or "both")."""
    for name in ("x", "y") if axis == "both" else (axis,):
        getattr(ax, f"{name}axis").set_major_locator(MaxNLocator(bins, steps=[1, 2, 2.5, 5, 10]))


def decade_ticks(ax, axis: str = "both") -> None:
    """Label only the decades of a log ``axis`` (minor ticks drawn, not labelled): minor labels
    such as 2x10^0 3x10^0 4x10^0 collide on a short range."""
    for name in ("x", "y") if axis == "both" else (axis,):
        target = getattr(ax, f"{name}axis")
        target.set_major_locator(LogLocator(base=10))
        target.set_minor_locator(LogLocator(base=10, subs=np.arange(2, 10)))
        target.set_minor_formatter(NullFormatter())


def log_ticks(ax, axis: str = "x") -> None:
    """Label 1, 2 and 5 x 10^k on a log ``axis`` that spans about two decades or less (a
    single labelled decade says little), as plain numbers; minor ticks unlabelled."""
    from matplotlib.ticker import FuncFormatter

    target = getattr(ax, f"{axis}axis")
    target.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    target.set_minor_locator(LogLocator(base=10, subs=np.arange(2, 10)))
    target.set_minor_formatter(NullFormatter())
    target.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))


def legend_below(fig, entries: Sequence[tuple[str, dict]] = (), ncol: int | None = None,
                 collect: bool = True):
    """One legend under the axes of ``fig``: the labelled curves of all its axes (each label
    once; none with ``collect=False``) followed by proxy entries ``(label, line style
    kwargs)`` explaining what a line style or marker means (drawn black)."""
    handles, labels = [], []
    for ax in fig.axes if collect else []:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            if label not in labels and not label.startswith("_"):
                handles.append(handle)
                labels.append(label)
    for label, style in entries:
        handles.append(Line2D([], [], **({"color": "k", "linestyle": "none"} | style)))
        labels.append(label)
    return fig.legend(handles, labels, loc="outside lower center", fontsize="small",
                      ncol=ncol or min(len(labels), 2))


# ------------------------------------------------------------------------------------------
# review: the mechanical part of the house style, for tests
# ------------------------------------------------------------------------------------------
def review(fig) -> list[str]:
    """What a reviewer would flag mechanically in ``fig`` (drawn first): no title, an axis
    without a label or without a unit, tick labels that overlap. Empty: nothing found."""
    fig.canvas.draw()
    fig.canvas.draw()  # constrained layout settles on the second pass
    renderer = fig.canvas.get_renderer()
    problems = []
    axes = [ax for ax in fig.axes if ax.get_visible() and ax.axison
            and not hasattr(ax, "_colorbar")]
    if not fig.get_suptitle() and not any(ax.get_title() for ax in axes):
        problems.append("no title")
    page = fig.bbox
    for text in _texts(fig):
        box = text.get_window_extent(renderer)
        if (box.x0 < page.x0 - 2 or box.x1 > page.x1 + 2 or box.y0 < page.y0 - 2
                or box.y1 > page.y1 + 2):
            problems.append(f"text cut at the figure's edge: '{text.get_text()[:60]}' "
                            f"({box.x0:.0f}..{box.x1:.0f} x {box.y0:.0f}..{box.y1:.0f} px)")
    for index, ax in enumerate(axes):
        name = ax.get_title() or (fig.get_suptitle()[:50] if len(axes) == 1 else f"axes {index}")
        for axis, shared in ((ax.xaxis, ax.get_shared_x_axes()),
                             (ax.yaxis, ax.get_shared_y_axes())):
            problems += [f"{name}: {axis.axis_name} tick labels overlap: {text}"
                         for text in _overlaps(axis, renderer)]
            if not axis.get_visible() or not _labels(axis, renderer):
                continue
            label = axis.get_label_text()
            if not label:
                siblings = [a for a in shared.get_siblings(ax) if a is not ax]
                texts = [getattr(a, f"get_{axis.axis_name}label")() for a in siblings]
                fig_label = fig._supxlabel if axis.axis_name == "x" else fig._supylabel
                label = next((t for t in texts if t), "") or (fig_label.get_text()
                                                              if fig_label else "")
            if not label:
                problems.append(f"{name}: {axis.axis_name} axis has no label")
            elif "[" not in label and not _categorical(axis):
                problems.append(f"{name}: {axis.axis_name} label '{label}' has no [unit]")
        for child in getattr(ax, "child_axes", []):
            for axis in (child.xaxis, child.yaxis):
                problems += [f"{name} (secondary): {axis.axis_name} tick labels overlap: "
                             f"{text}" for text in _overlaps(axis, renderer)]
    return problems


def _texts(fig) -> list:
    """The visible, non-empty texts of ``fig``: titles, axis labels, annotations, legends
    (tick labels are checked by :func:`_overlaps`)."""
    from matplotlib.axis import Tick
    from matplotlib.text import Text

    ticks = {id(label) for tick in fig.findobj(Tick) for label in (tick.label1, tick.label2)}
    return [artist for artist in fig.findobj(Text) if artist.get_visible()
            and artist.get_text().strip() and id(artist) not in ticks]


def _categorical(axis) -> bool:
    """Whether ``axis`` shows names (bar-chart categories, or tick labels set as fixed
    texts) rather than numbers."""
    import re

    from matplotlib.ticker import FixedFormatter, FixedLocator, FuncFormatter

    if isinstance(axis.get_major_locator(), FixedLocator) and isinstance(
            axis.get_major_formatter(), FixedFormatter | FuncFormatter):
        return True  # set_ticks(positions, labels): names at fixed places
    for tick in axis.get_major_ticks():
        text = re.sub(r"\\mathdefault|\\times|[${}^]", "", tick.label1.get_text())
        if re.search(r"[A-Za-z_]{2,}", text):
            return True
    return False


def _labels(axis, renderer) -> list:
    """The tick labels ``axis`` draws: (text, window extent)."""
    low, high = sorted(axis.get_view_interval())
    slack = 1e-9 * max(abs(high - low), 1e-300)
    out = []
    for ticks, locations in ((axis.get_major_ticks(), axis.get_majorticklocs()),
                             (axis.get_minor_ticks(), axis.get_minorticklocs())):
        for tick, location in zip(ticks, locations, strict=False):
            if not low - slack <= location <= high + slack:
                continue
            for label in (tick.label1, tick.label2):
                if label.get_visible() and label.get_text().strip():
                    out.append((label.get_text(), label.get_window_extent(renderer)))
    return out


def _overlaps(axis, renderer) -> list[str]:
    labels = _labels(axis, renderer)
    found = []
    for i, (text_a, box_a) in enumerate(labels):
        for text_b, box_b in labels[i + 1:]:
            width = min(box_a.x1, box_b.x1) - max(box_a.x0, box_b.x0)
            height = min(box_a.y1, box_b.y1) - max(box_a.y0, box_b.y0)
            if width > 0.5 and height > 0.5:
                found.append(f"'{text_a}' and '{text_b}'")
    return found
