"""One calibration: every fitted or measured table an ``"auto"`` value resolves from, as one value.

A :class:`Calibration` holds four files of one folder, each the output of a study:

- ``criteria_fit.toml``: the coupler's rigid-or-flexible law (``make kfit``);
- ``crank_criteria_fit.toml``: the crank's own law (``make crank``);
- ``ffrf_rule.toml``: the FFRF settings rule, an FFRF link's step, modes and mesh per
  tolerance (``make calibrate``, :mod:`flex.config.ffrf_rule`);
- ``solver_defaults.toml``: the solver settings by model (``make tradeoff``,
  :mod:`flex.config.settings`).

The bundled calibration is the folder of this module (``flex/config/``);
:func:`load_calibration` loads it (``"bundled"``) or another folder holding the same four files.
It is passed as an argument to whatever resolves an ``"auto"`` (None there: the bundled one),
and :attr:`Calibration.digest` is part of a sweep case's identity
(:func:`flex.sweep.case_hash`): a changed law, rule or table never resumes stale cases.

``make calibration-install`` (:func:`install_calibration`, ``python -m flex.config.calibration
install``) installs fitted laws and the rule into the bundled folder in one step.
"""

from __future__ import annotations

import argparse
import hashlib
import shutil
import sys
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from types import MappingProxyType
from typing import Any

from flex.base.errors import FlexError

#: the parts of a calibration and their file names (in every calibration folder)
FILES = {"coupler_criterion": "criteria_fit.toml",
         "crank_criterion": "crank_criteria_fit.toml",
         "ffrf_rule": "ffrf_rule.toml",
         "solver_defaults": "solver_defaults.toml"}
#: the fitted files a study writes beside its result (``results/<name>``) and the part each
#: installs (:func:`install_calibration`)
INSTALLS = {"kfit-criterion.toml": "coupler_criterion",
            "crank-criterion.toml": "crank_criterion",
            "calibrate-rule.toml": "ffrf_rule"}
#: the study that writes each installable file (its run must be up to date and not failed)
STUDY_OF = {"kfit-criterion.toml": "kfit", "crank-criterion.toml": "crank",
            "calibrate-rule.toml": "calibrate"}
BUNDLED = "bundled"
BUNDLED_FOLDER = Path(__file__).parent


@dataclass(frozen=True)
class Calibration:
    """The four calibration files of one folder (their text; a criterion file not yet
    installed is None) and the two tables parsed, read-only (mappings that refuse changes,
    tuples for lists). Pickles as its texts (a sweep's worker processes get the same value).

    ``source``: ``"bundled"`` or the folder's path; ``folder``: where the files are.
    """

    source: str
    folder: Path
    coupler_criterion_toml: str | None
    crank_criterion_toml: str | None
    ffrf_rule_toml: str
    solver_defaults_toml: str
    ffrf_rule: Mapping[str, Any] = field(repr=False, compare=False)
    solver_defaults: Mapping[str, Mapping[str, Any]] = field(repr=False, compare=False)

    @property
    def digest(self) -> str:
        """SHA-256 (24 hex digits) of the four texts: what a sweep case's identity holds."""
        hasher = hashlib.sha256()
        for part in FILES:
            text = getattr(self, f"{part}_toml")
            hasher.update(f"{part}\0{'missing' if text is None else text}\0".encode())
        return hasher.hexdigest()[:24]

    def path(self, part: str) -> Path:
        """The file of ``part`` (a key of :data:`FILES`)."""
        return self.folder / FILES[part]

    def __reduce__(self):
        return _from_texts, (self.source, self.folder, self.coupler_criterion_toml,
                             self.crank_criterion_toml, self.ffrf_rule_toml,
                             self.solver_defaults_toml)


def _frozen(value: Any) -> Any:
    """A parsed TOML value that refuses changes: tables as read-only mappings, arrays as
    tuples."""
    if isinstance(value, dict):
        return MappingProxyType({key: _frozen(item) for key, item in value.items()})
    if isinstance(value, list):
        return tuple(_frozen(item) for item in value)
    return value


def _from_texts(source: str, folder: Path, coupler: str | None, crank: str | None,
                rule: str, defaults: str) -> Calibration:
    """The calibration of these four texts (``folder`` names them in messages), each value
    checked (:func:`flex.config.calibration_check.check_part`)."""
    from flex.config.calibration_check import check_part

    for part, text in (("coupler_criterion", coupler), ("crank_criterion", crank)):
        if text is not None:
            check_part(folder / FILES[part], part, _parse(folder, part, text))
    parsed = {part: _parse(folder, part, text) for part, text in (("ffrf_rule", rule),
                                                                  ("solver_defaults", defaults))}
    for part, data in parsed.items():
        check_part(folder / FILES[part], part, data)
    return Calibration(source, folder, coupler, crank, rule, defaults,
                       ffrf_rule=_frozen(parsed["ffrf_rule"]),
                       solver_defaults=_frozen(parsed["solver_defaults"]))


def _read(folder: Path, part: str, required: bool) -> str | None:
    path = folder / FILES[part]
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        if required:
            raise FlexError(f"calibration folder '{folder}' has no {FILES[part]} (a "
                            f"calibration folder holds {', '.join(FILES.values())})") from None
        return None
    except (OSError, UnicodeDecodeError) as exc:  # not UTF-8: it came back as a Python error
        raise FlexError(f"calibration file '{path}' cannot be read: "
                        f"{getattr(exc, 'strerror', None) or exc}") from None


def _parse(folder: Path, part: str, text: str) -> dict[str, Any]:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise FlexError(f"calibration file '{folder / FILES[part]}' is not valid TOML: "
                        f"{exc}") from None


def load_calibration(name: str | Path = BUNDLED) -> Calibration:
    """The calibration ``name``: ``"bundled"`` (flex/config/, what every ``"auto"`` reads
    by default) or a folder holding the four files of :data:`FILES` (a criterion file may be
    missing: a link whose model is ``"auto"`` then refuses to run). Raises
    :class:`FlexError` naming the folder or file for a missing folder, rule or solver table,
    or a file that is not TOML."""
    if str(name) == BUNDLED:
        return _bundled()
    return _load(Path(name), str(name))


@cache
def _bundled() -> Calibration:
    """The bundled calibration, read once (its files change only by an install, after which
    every study reruns)."""
    return _load(BUNDLED_FOLDER, BUNDLED)


def _load(folder: Path, source: str) -> Calibration:
    if not folder.is_dir():
        raise FlexError(f"calibration '{source}': no such folder (a calibration is "
                        f"'{BUNDLED}' or a folder holding {', '.join(FILES.values())})")
    texts = {part: _read(folder, part, required=part in ("ffrf_rule", "solver_defaults"))
             for part in FILES}
    return _from_texts(source, folder, texts["coupler_criterion"], texts["crank_criterion"],
                       texts["ffrf_rule"], texts["solver_defaults"])


def calibration_of(calibration: Calibration | None) -> Calibration:
    """``calibration``, or the bundled one for None (the default of every function that
    takes one)."""
    return _bundled() if calibration is None else calibration


def install_calibration(files: Sequence[str | Path], folder: str | Path = BUNDLED_FOLDER
                        ) -> list[str]:
    """Install fitted files (``results/kfit-criterion.toml``, ``crank-criterion.toml``,
    ``calibrate-rule.toml``: :data:`INSTALLS`) as their parts of the calibration in
    ``folder`` (default: the bundled one), all checked before any is copied: each must be
    TOML with every value in range (:mod:`flex.config.calibration_check`), beside its
    study's result file (``results/<study>.h5``) and not from a run that
    failed afterwards (a newer ``<study>.failed.h5``). Returns one line per file (copied, or already
    installed). Raises :class:`FlexError` naming the first file that fails a check."""
    folder = Path(folder)
    plan = []
    for given in map(Path, files):
        part = INSTALLS.get(given.name)
        if part is None:
            raise FlexError(f"'{given}': not a fitted calibration file (expected one of "
                            f"{', '.join(INSTALLS)})")
        text = _read_file(given)
        _check_toml(given, text)
        _check_fresh(given)
        from flex.config.calibration_check import check_part

        check_part(given, part, tomllib.loads(text))
        plan.append((given, folder / FILES[part], text))
    lines = []
    for given, target, text in plan:
        if target.is_file() and target.read_text(encoding="utf-8") == text:
            lines.append(f"{target} is already {given}")
            continue
        shutil.copyfile(given, target)
        lines.append(f"cp {given} {target}")
    return lines


def _read_file(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        study = STUDY_OF[path.name]
        raise FlexError(f"'{path}' does not exist: run 'make {study}' first") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise FlexError(f"'{path}' cannot be read: "
                        f"{getattr(exc, 'strerror', None) or exc}") from None


def _check_toml(path: Path, text: str) -> None:
    try:
        tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise FlexError(f"'{path}' is not valid TOML ({exc}): not installed") from None


def _check_fresh(path: Path) -> None:
    """A fitted file is installed only from an up-to-date run that did not fail afterwards."""
    study = STUDY_OF[path.name]
    result, failed = path.parent / f"{study}.h5", path.parent / f"{study}.failed.h5"
    if not result.is_file():
        raise FlexError(f"'{path}' has no result file '{result}' beside it: run 'make {study}'")
    if failed.is_file() and failed.stat().st_mtime > result.stat().st_mtime:
        raise FlexError(f"the last {study} run failed ({failed}): its fit '{path}' is not "
                        f"installed")


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m flex.config.calibration install FILE... [--into FOLDER]``."""
    parser = argparse.ArgumentParser(
        prog="python -m flex.config.calibration",
        description="install fitted laws and the FFRF rule as the calibration (make "
                    "calibration-install)")
    commands = parser.add_subparsers(dest="command", required=True)
    install = commands.add_parser("install", help="copy fitted files into a calibration folder")
    install.add_argument("files", nargs="+", help=f"fitted files: {', '.join(INSTALLS)}")
    install.add_argument("--into", default=str(BUNDLED_FOLDER),
                         help="the calibration folder (default: the bundled one)")
    args = parser.parse_args(argv)
    try:
        for line in install_calibration(args.files, args.into):
            print(line)
    except FlexError as exc:
        print(f"flex: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
