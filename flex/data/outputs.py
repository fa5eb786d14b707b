"""Where a run's outputs go, checked before anything runs; figures written all or nothing.

- A result file ends in ``.h5``/``.hdf5``, is not an input of the run (the scene file, a
  file the run reads), and its folder can be written: :func:`check_output` refuses
  otherwise, before any case is simulated.
- Figures go to ``figures/`` beside the result file, named after it:
  ``results/dynamics.h5`` -> ``results/figures/dynamics-*.png``, ``runs/a.h5`` ->
  ``runs/figures/a-*.png``, so two result files never share a figure.
- :func:`staged_figures` lets a study draw into a private folder and moves the figures into
  place only when every one was drawn: an error or an interrupt leaves the previous figures
  as they were.
- A run that did not end as its study declares never replaces an existing result file: it
  is written beside it as :func:`failed_path` (``<name>.failed.h5``).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from flex.base.errors import OutputError

RESULT_SUFFIXES = (".h5", ".hdf5")


def check_output(path: str | Path, inputs: Iterable[str | Path] = ()) -> Path:
    """The result file ``path`` as a :class:`Path`, or :class:`OutputError` naming why it
    cannot be one: empty, wrong suffix, a folder, one of ``inputs``, or in a folder that
    cannot be created or written."""
    text = str(path)
    if not text.strip():
        raise OutputError("--out '': give a result file name ending in .h5 or .hdf5")
    out = Path(text)
    if out.suffix not in RESULT_SUFFIXES:
        raise OutputError(f"--out '{out}': result files end in .h5 or .hdf5")
    if out.is_dir():
        raise OutputError(f"--out '{out}' is a folder; give a result file name ending in .h5")
    for source in inputs:
        if source and _same_file(out, Path(source)):
            raise OutputError(f"--out '{out}' is an input of this run ({source}); "
                              f"choose another result file")
    check_writable_folder(out.parent, f"--out '{out}'")
    return out


def check_writable_folder(folder: Path, label: str) -> None:
    """Refuse (:class:`OutputError`) a folder that cannot be created or written: its
    nearest existing ancestor must be a writable folder."""
    existing = folder if str(folder) else Path(".")
    while not existing.exists():
        if existing.is_symlink():
            raise OutputError(f"{label}: '{existing}' is a broken link")
        existing = existing.parent
    if not existing.is_dir():
        raise OutputError(f"{label}: '{existing}' is a file, not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise OutputError(f"{label}: folder '{existing}' is not writable")


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == b.resolve() or (a.exists() and b.exists() and a.samefile(b))
    except OSError:
        return False


def failed_path(path: Path) -> Path:
    """Where a run that did not end as declared is written when ``path`` holds a good one:
    ``x.h5`` -> ``x.failed.h5``."""
    return path.with_name(f"{path.stem}.failed{path.suffix}")


def figures_folder(result_path: Path) -> Path:
    """The folder of a result file's figures: ``figures/`` beside it."""
    return result_path.parent / "figures"


@contextmanager
def staged_figures(result_path: Path, study: str) -> Iterator[tuple[Path, list[Path]]]:
    """Yield ``(private folder, placed)``: the study draws its ``<study>-*.png`` into the
    private folder; on success each is renamed ``<result stem>-*`` into
    :func:`figures_folder` and listed in ``placed``. On any error or interrupt nothing is
    placed and the private folder is removed."""
    target = figures_folder(result_path)
    try:
        target.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{result_path.stem}.", suffix=".figures",
                                        dir=target))
    except OSError as exc:
        raise OutputError(f"cannot write figures to '{target}': "
                          f"{exc.strerror or exc}") from None
    placed: list[Path] = []
    try:
        yield staging, placed
        for drawn in sorted(staging.iterdir()):
            name = drawn.name
            if name.startswith(f"{study}-"):
                name = f"{result_path.stem}-{name[len(study) + 1:]}"
            os.replace(drawn, target / name)
            placed.append(target / name)
    except OSError as exc:
        raise OutputError(f"cannot write figures to '{target}': "
                          f"{exc.strerror or exc}") from None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
