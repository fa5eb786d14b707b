"""Command line: ``python -m flex run|scene|studies ...``.

Every user error (bad scene key, impossible geometry, diverged run, bad result file) is
printed as one line ``flex: error: ...`` and exits with status 2; no traceback.
"""

from __future__ import annotations

import argparse
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
    scene = commands.add_parser("scene", help="print the fully resolved scene as TOML")
    scene_options(scene)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit status."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "run":
            from .study import run_study

            output = run_study(args.study, args.scene, args.overrides, args.out,
                               figures=not args.no_figures, quiet=args.quiet)
            return 1 if any(c.status != "ok" for c in output.results.values()) else 0
        if args.command == "scene":
            from .scene import to_toml
            from .study import load_study, study_scene

            print(to_toml(study_scene(load_study(args.study), args.scene, args.overrides)),
                  end="")
            return 0
    except FlexError as exc:
        print(f"flex: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("flex: interrupted; no result file was changed", file=sys.stderr)
        return 130
    return 2
