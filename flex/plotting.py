"""Figure helpers: readable PNGs with titles, axis labels and units (matplotlib, Agg)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


@contextmanager
def figure(path: Path, title: str, xlabel: str, ylabel: str,
           size: tuple[float, float] = (7.0, 4.5)) -> Iterator:
    """Yield axes; on exit add grid/legend, save ``path`` at 120 dpi and close."""
    fig, ax = plt.subplots(figsize=size, layout="constrained")
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    yield ax
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    fig.savefig(path, dpi=120)
    plt.close(fig)
