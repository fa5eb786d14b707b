"""Where a run's outputs go, checked before anything runs; figures written all or nothing.

- A result file ends in ``.h5``/``.hdf5``, is not an input of the run (the scene file, a
  file the run reads), replaces only a result file flex wrote, and its folder can be
  written: :func:`check_output` refuses
  otherwise, before any case is simulated.
- Figures go to ``figures/`` beside the result file, named after it:
  ``results/dynamics.h5`` -> ``results/figures/dynamics-*.png``, ``runs/a.h5`` ->
  ``runs/figures/a-*.png``, so two result files never share a figure.
- :class:`Staging`: a run writes its result file, its figures and its report under private
  names and moves them into place together only when all are written: an error (a full disk,
  a report path that is a folder) or an interrupt leaves the previous files as they were.
- A run that did not end as its study declares never replaces an existing result file: it
  is written beside it as :func:`failed_path` (``<name>.failed.h5``).
- Other outputs (``flex export``, ``flex animate``) replace only files flex wrote
  (:func:`check_replaceable`, its provenance marker); :func:`free_bytes` for a size check.
"""

from __future__ import annotations

import os
import secrets
import shutil
from collections.abc import Callable, Iterable
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
    check_replaceable(out, _is_flex_result, "--out", hint="move it away or choose another "
                      "--out (a result file flex wrote is replaced); nothing was run")
    check_writable_folder(out.parent, f"--out '{out}'")
    return out


def _is_flex_result(path: Path) -> bool:
    """Whether ``path`` is an HDF5 file flex wrote (its ``flex_format`` root attribute)."""
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            return "flex_format" in h5.attrs
    except (OSError, ValueError):
        return False


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


def check_replaceable(path: Path, written_by_flex: Callable[[Path], bool], label: str,
                      force: bool = False,
                      hint: str = "move it away, choose another output, or pass --force to "
                                  "replace it; nothing was changed") -> None:
    """Refuse (:class:`OutputError`, one line) to replace ``path`` when it is a folder, or
    an existing file that ``written_by_flex`` does not recognise as flex's own output (its
    provenance marker), unless ``force``: a file of the same name that someone else wrote is
    never replaced silently."""
    if path.is_dir():
        raise OutputError(f"{label} '{path}' is a folder; nothing was changed")
    if force or not (path.exists() or path.is_symlink()):
        return
    try:
        ours = path.is_file() and written_by_flex(path)
    except OSError:
        ours = False
    if not ours:
        raise OutputError(f"{label} '{path}' exists and was not written by flex (no flex "
                          f"provenance in it): {hint}")


def has_marker(path: Path, marker: bytes, window: int = 1 << 16) -> bool:
    """Whether ``marker`` occurs in the first or the last ``window`` bytes of ``path`` (a
    provenance string a writer put in a file's metadata)."""
    with path.open("rb") as file:
        head = file.read(window)
        size = file.seek(0, os.SEEK_END)
        file.seek(max(0, size - window))
        return marker in head or marker in file.read(window)


def free_bytes(folder: Path) -> int:
    """Free space [bytes] for an unprivileged writer in ``folder`` (or its nearest existing
    ancestor)."""
    existing = folder if str(folder) else Path(".")
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    return int(shutil.disk_usage(existing).free)


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


class Staging:
    """One run's outputs written under private names beside their targets, and moved into
    place together by :meth:`commit`: until then no existing file is changed, so an error or
    an interrupt while writing any of them (a full disk while drawing figures, a report that
    cannot be written) leaves the previous result, figures and report as they were.

    ``result``: the private name of the result file (``.<name>.<pid>.<random>.part`` beside
    ``target``, removed by a later write if this process is killed); :meth:`figures`: the
    private folder the study draws its ``<study>-*.png`` into (``figures/.<stem>.*.figures``
    beside the target); ``report``: the private name of the report. :meth:`discard` removes
    whatever was not committed (use ``with``).
    """

    def __init__(self, target: Path, report_target: Path, study: str) -> None:
        self.target, self.report_target, self.study = Path(target), Path(report_target), study
        self.result = self._part(self.target)
        self.report = self._part(self.report_target)
        self._figures: Path | None = None
        self.placed: list[Path] = []

    @staticmethod
    def _part(path: Path) -> Path:
        return path.parent / f".{path.name}.{os.getpid()}.{secrets.token_hex(8)}.part"

    def __enter__(self) -> Staging:
        return self

    def __exit__(self, *exc_info) -> None:
        self.discard()

    def figures(self) -> Path:
        """The private folder to draw figures into (created on first use)."""
        if self._figures is None:
            folder = figures_folder(self.target)
            try:
                folder.mkdir(parents=True, exist_ok=True)
                # named before it exists: an interrupt between creating the folder and
                # keeping its name (tempfile.mkdtemp's return) left it behind for discard()
                # to miss (make test-slow: 1 in 3 SIGINTs at the writing phase)
                self._figures = folder / (f".{self.target.stem}.{secrets.token_hex(8)}"
                                          ".figures")
                self._figures.mkdir()
            except OSError as exc:
                self._figures = None
                raise OutputError(f"cannot write figures to '{folder}': "
                                  f"{exc.strerror or exc}; nothing was changed") from None
        return self._figures

    def planned_figures(self) -> list[Path]:
        """Where the figures drawn so far will go: ``<study>-x.png`` -> ``<stem>-x.png``."""
        if self._figures is None:
            return []
        folder = figures_folder(self.target)
        names = []
        for drawn in sorted(self._figures.iterdir()):
            name = drawn.name
            if name.startswith(f"{self.study}-"):
                name = f"{self.target.stem}-{name[len(self.study) + 1:]}"
            names.append(folder / name)
        return names

    def commit(self) -> list[Path]:
        """Move the result file, the figures and the report into place, in that order; each
        move is a rename within its folder. Every target is checked first (a folder where a
        file goes is refused with nothing moved). Returns the files placed (also in
        ``placed`` as they go, for an interrupt's message)."""
        moves = [(self.result, self.target)]
        if self._figures is not None:
            moves += list(zip(sorted(self._figures.iterdir()), self.planned_figures(),
                              strict=True))
        if self.report.exists():
            moves.append((self.report, self.report_target))
        for _, target in moves:
            if target.is_dir():
                raise OutputError(f"'{target}' is a folder: it cannot be replaced by this run's "
                                  f"file; nothing was changed")
        try:
            for source, target in moves:
                os.replace(source, target)
                self.placed.append(target)
        except OSError as exc:
            done = ", ".join(str(path) for path in self.placed) or "nothing"
            raise OutputError(f"cannot move '{source}' to '{target}': {exc.strerror or exc}; "
                              f"already in place: {done}") from None
        return list(self.placed)

    def discard(self) -> None:
        """Remove what was not committed."""
        for part in (self.result, self.report):
            part.unlink(missing_ok=True)
        if self._figures is not None:
            shutil.rmtree(self._figures, ignore_errors=True)
