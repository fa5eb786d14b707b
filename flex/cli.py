"""Command line: ``python -m flex run|scene|inspect|plot|compare ...``.

Every user error (bad scene key, impossible geometry, diverged run, bad result file) is
printed as one line ``flex: error: ...`` and exits with status 2; no traceback.
"""

from __future__ import annotations

import argparse
import os
import sys

from .errors import FlexError


def _parser() -> argparse.ArgumentParser:
    from .study import STUDIES

    parser = argparse.ArgumentParser(prog="python -m flex", description=__doc__.split("\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)

    def scene_options(sub: argparse.ArgumentParser) -> None:
        sub.add_argument("study", choices=STUDIES, metavar="STUDY",
                         help=f"one of: {', '.join(STUDIES)}")
        sub.add_argument("--scene", metavar="FILE.toml",
                         help="scene file or bundled parameter set (default cavezza2012)")
        sub.add_argument("--set", dest="overrides", action="append", default=[],
                         metavar="SECTION.KEY=VALUE", help="override one scene value (TOML)")

    run = commands.add_parser("run", help="run a study and write results/<study>.h5")
    scene_options(run)
    run.add_argument("--out", metavar="FILE.h5", help="result file (default results/STUDY.h5)")
    run.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    run.add_argument("--quiet", action="store_true", help="print nothing on success")
    run.add_argument("--scheduler", metavar="ADDRESS",
                     help="sweeps (kfit): 'local' (local Dask cluster), tcp://host:8786 (a Dask "
                          "scheduler) or 'serial'; default: a process pool on all cores")
    run.add_argument("--workers", type=int, metavar="N",
                     help="sweeps: number of local worker processes (default: all cores)")
    scene = commands.add_parser("scene", help="print the fully resolved scene as TOML")
    scene_options(scene)
    _result_tools(commands)
    return parser


PATH_HELP = ("path inside the file: cases/<case>/crank/angle, <case>/crank/angle, or "
             "crank/angle when the file has one case; a group means every dataset below "
             "it; * and ? are wildcards; a [i] suffix picks one column")


def _result_tools(commands) -> None:
    """The ``inspect``, ``plot`` and ``compare`` subcommands (reading result files)."""
    from .compare import DEFAULT_ATOL, DEFAULT_RTOL, INTERPOLATIONS

    inspect = commands.add_parser(
        "inspect", help="list a result file: cases, datasets, units, provenance, scene",
        description="List the cases and datasets of a result file (shape, units, "
                    "description), its provenance and its resolved scene.")
    inspect.add_argument("file", metavar="FILE.h5")
    inspect.add_argument("path", nargs="?", metavar="PATH", help=PATH_HELP)
    inspect.add_argument("--json", action="store_true", help="print JSON (for scripts)")

    plot = commands.add_parser(
        "plot", help="plot stored curves against time (or against each other)",
        description="Plot curves of a result file against time, with units on the axes; "
                    "--vs overlays the same paths from another file (another run or a "
                    "reference curve file).")
    plot.add_argument("file", metavar="FILE.h5")
    plot.add_argument("paths", nargs="+", metavar="PATH", help=PATH_HELP)
    plot.add_argument("--vs", action="append", default=[], metavar="OTHER.h5",
                      help="overlay the same paths from this file (repeatable)")
    plot.add_argument("--x", dest="x_spec", metavar="PATH",
                      help="plot against this dataset of the same case instead of time")
    plot.add_argument("--out", metavar="FIG.png",
                      help="figure file, .png/.pdf/.svg (default: figures/ beside FILE)")
    plot.add_argument("--title", help="figure title (default: the file names)")

    compare = commands.add_parser(
        "compare", help="compare curves of two result files on a common time base",
        description="Compare curves of A (under test) with B (reference) after "
                    "interpolating onto a common time base (the overlap of both time "
                    "ranges, on the finer grid). A curve (each column of a two-column "
                    "curve) passes when max|a - b| <= atol + rtol * max|b|. Exit status: 0 "
                    "all within tolerance, 1 some not, 2 a bad file or a PATH missing from "
                    "either file. Without PATH every curve of the cases both files have "
                    "is compared (/summary only when named; wall-clock timings never).")
    compare.add_argument("file_a", metavar="A.h5")
    compare.add_argument("file_b", metavar="B.h5")
    compare.add_argument("paths", nargs="*", metavar="PATH", help=PATH_HELP)
    compare.add_argument("--rtol", type=float, default=DEFAULT_RTOL,
                         help=f"relative tolerance, times max|b| (default {DEFAULT_RTOL:g})")
    compare.add_argument("--atol", type=float, default=DEFAULT_ATOL,
                         help=f"absolute tolerance in the curve's units (default "
                              f"{DEFAULT_ATOL:g})")
    compare.add_argument("--interp", choices=INTERPOLATIONS, default="cubic",
                         help="interpolation onto the common time base (default cubic)")
    compare.add_argument("--limit", type=int, default=20, metavar="N",
                         help="show the N largest deviations (failures always; 0: all)")
    compare.add_argument("--json", action="store_true", help="print JSON (for scripts)")


def _result_tool(args: argparse.Namespace) -> int:
    """Run ``inspect``, ``plot`` or ``compare``; returns the exit status."""
    import json

    if args.command == "inspect":
        from .inspect import describe, format_description

        info = describe(args.file, args.path)
        _print(json.dumps(info, indent=2) if args.json else format_description(info))
        return 0
    if args.command == "plot":
        from .plotcurves import plot_curves

        figure = plot_curves(args.file, args.paths, args.vs, args.x_spec, args.out,
                             args.title)
        _print(f"wrote {figure}")
        return 0
    from .compare import compare_files

    report = compare_files(args.file_a, args.file_b, args.paths, args.rtol, args.atol,
                           args.interp)
    _print(json.dumps(report.as_dict(), indent=2) if args.json
           else report.format(args.limit))
    return 0 if report.passed else 1


def _print(text: str) -> None:
    """Print to stdout; a closed pipe (``| head``) ends quietly."""
    import os

    try:
        print(text, flush=True)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def _auto_note(scene) -> str:
    """A TOML comment saying what the scene's "auto" solver keys resolve to (or when)."""
    from .settings import has_auto, resolve_solver_settings

    if not has_auto(scene):
        return ""
    if "auto" in (scene["crank"]["model"], scene["coupler"]["model"]):
        return ('# [simulation] "auto" keys: chosen at run time, once the model = "auto" links '
                "are decided (flex/settings.py)\n")
    _, choice = resolve_solver_settings(scene)
    keys = ", ".join(f"{key} = {value!r}" for key, value in choice.keys.items())
    return f'# [simulation] "auto" keys -> {keys} ({choice.entry}: {choice.reason})\n'


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit status."""
    parser = _parser()
    args, extra = parser.parse_known_args(argv)
    if extra:  # PATHs after options (compare A B --rtol 1e-6 PATH): argparse leaves them over
        if args.command in ("plot", "compare") and not any(e.startswith("-") for e in extra):
            args.paths += extra
        else:
            parser.error(f"unrecognized arguments: {' '.join(extra)}")
    try:
        if args.command == "run":
            from .study import run_study

            if args.scheduler:
                os.environ["FLEX_SCHEDULER"] = args.scheduler
            if args.workers is not None:
                if args.workers < 1:
                    raise FlexError(f"--workers {args.workers}: must be at least 1")
                os.environ["FLEX_WORKERS"] = str(args.workers)
            output = run_study(args.study, args.scene, args.overrides, args.out,
                               figures=not args.no_figures, quiet=args.quiet)
            return 0 if output.as_expected else 1
        if args.command == "scene":
            from .scene import to_toml
            from .study import load_study, study_scene

            scene = study_scene(load_study(args.study), args.scene, args.overrides)
            print(_auto_note(scene) + to_toml(scene), end="")
            return 0
        if args.command in ("inspect", "plot", "compare"):
            return _result_tool(args)
    except FlexError as exc:
        print(f"flex: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("flex: interrupted; no result file was changed", file=sys.stderr)
        return 130
    return 2
