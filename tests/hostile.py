"""Harness of the hostile-input suite: run the command line in process and check the contract.

Each hostile case asserts (README "When something goes wrong"):

- no traceback, on stdout or stderr;
- the documented exit status (:mod:`flex.base.errors`);
- for a refusal (status 2): exactly one ``flex: error: ...`` line on stderr that contains
  the words the case names (the key, file or argument at fault);
- no watched file changed (result files, scene files, figures: compared byte for byte;
  bystanders -- the other files of a folder, which the command was not given -- by name,
  size, inode and modification time).
"""

from __future__ import annotations

import contextlib
import hashlib
import io
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from flex.base.errors import EXIT_BAD_INPUT
from flex.cli import main


@dataclass
class Outcome:
    status: int
    stdout: str
    stderr: str

    def error_lines(self) -> list[str]:
        return [line for line in self.stderr.splitlines() if line.startswith("flex: error:")]


def fingerprint(paths: Iterable[Path]) -> dict[Path, str | None]:
    """SHA-256 of each file (None: absent); a folder contributes every file below it."""
    seen: dict[Path, str | None] = {}
    for path in paths:
        path = Path(path)
        files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
        for file in files:
            seen[file] = hashlib.sha256(file.read_bytes()).hexdigest() if file.exists() else None
    return seen


def stat_signature(folders: Iterable[Path]) -> dict[Path, tuple[int, int, int]]:
    """Size, inode and modification time [ns] of every file below ``folders``: a bystander
    that is written, replaced or removed shows here without reading it (hashing every
    bystander for every command was ~30 % of the hostile result-file cases)."""
    seen: dict[Path, tuple[int, int, int]] = {}
    for folder in folders:
        for file in Path(folder).rglob("*"):
            if file.is_file():
                info = file.stat()
                seen[file] = (info.st_size, info.st_ino, info.st_mtime_ns)
    return seen


def run_cli(argv: Sequence[str]) -> Outcome:
    """``flex ARGV`` in this process; SystemExit (argparse, --version) becomes the status."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main(list(argv))
        except SystemExit as exc:
            status = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    return Outcome(int(status), out.getvalue(), err.getvalue())


def check_refused(argv: Sequence[str], names: Sequence[str] = (), watch: Iterable[Path] = (),
                  status: int = EXIT_BAD_INPUT, bystanders: Iterable[Path] = ()) -> Outcome:
    """Run ``argv``; assert the contract for a refusal naming ``names`` (case-insensitive).
    ``watch``: files compared byte for byte; ``bystanders``: folders whose files are
    compared by :func:`stat_signature`."""
    watch, bystanders = list(watch), list(bystanders)
    before = fingerprint(watch)
    around = stat_signature(bystanders)
    outcome = run_cli(argv)
    assert_no_traceback(outcome)
    assert outcome.status == status, (argv, outcome)
    if status == EXIT_BAD_INPUT:
        lines = outcome.error_lines()
        assert len(lines) == 1, (argv, outcome.stderr)
        for name in names:
            assert name.lower() in lines[0].lower(), (name, lines[0])
    assert fingerprint(watch) == before, f"{argv} changed a watched file"
    after = stat_signature(bystanders)
    changed = [str(file) for file, signature in around.items() if after.get(file) != signature]
    assert not changed, f"{argv} changed files beside those given: {changed}"
    return outcome


def assert_no_traceback(outcome: Outcome) -> None:
    for text in (outcome.stdout, outcome.stderr):
        assert "Traceback" not in text, text
        assert "internal error" not in text, text


def earlier_run(folder: Path) -> Path:
    """An earlier run in ``folder``: its result file (returned), figure and report, for the
    checks that an error exit changes none of them."""
    import numpy as np

    from flex.data.results import CaseResult, Dataset, write_results

    path = write_results(folder / "run.h5", "simulate", [CaseResult("case", "", {
        "time": Dataset(np.linspace(0, 1, 11), "s"), "crank/angle": Dataset(np.zeros(11),
                                                                            "rad")})])
    (folder / "figures").mkdir()
    (folder / "figures" / "run-crank-angle.png").write_bytes(b"yesterday's figure")
    (folder / "reports").mkdir()
    (folder / "reports" / "run.md").write_text("yesterday's report\n")
    return path

