"""Command line: ``flex run|scene|inspect|plot|compare|report ...`` (also ``python -m flex``).

Every user error (bad scene key, impossible geometry, bad result file, an output that
cannot be written) is printed as one line ``flex: error: ...`` and exits with status 2; no
traceback. The exit statuses are those of :mod:`flex.base.errors`.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from flex import __version__
from flex.base.errors import (
    EXIT_BAD_INPUT,
    EXIT_FAILED,
    EXIT_INTERNAL,
    EXIT_OK,
    EXIT_SIGINT,
    EXIT_SIGTERM,
    EXIT_STATUSES,
    FlexError,
    Terminated,
)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``flex: error: ...``, status 2), like every other
    refusal of flex."""

    def error(self, message: str):  # noqa: D102 - argparse's contract
        command = self.prog.removeprefix("flex").strip()
        print(f"flex: error: {command + ': ' if command else ''}{message} "
              f"(see '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(EXIT_BAD_INPUT)


#: seconds without a line on stderr after which the command line says it is still working
#: (README: "progress at least every 10 s")
PROGRESS_INTERVAL_S = 10.0

EPILOG = "exit status:\n" + "\n".join(f"  {code:<4} {text}" for code, text in
                                      EXIT_STATUSES.items())


def _parser() -> argparse.ArgumentParser:
    from flex.study import STUDIES

    parser = _Parser(prog="flex", epilog=EPILOG,
                     formatter_class=argparse.RawDescriptionHelpFormatter,
                     description="flex: rigid and flexible (FFRF) slider-crank deployment "
                                 "studies on Exudyn and NGsolve, results in HDF5.")
    parser.add_argument("--version", action="version", version=f"flex {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    def scene_options(sub: argparse.ArgumentParser) -> None:
        sub.add_argument("study", choices=STUDIES, metavar="STUDY",
                         help=f"one of: {', '.join(STUDIES)}")
        sub.add_argument("--scene", metavar="FILE.toml",
                         help="scene file or bundled parameter set (default cavezza2012)")
        sub.add_argument("--set", dest="overrides", action="append", default=[],
                         metavar="SECTION.KEY=VALUE", help="override one scene value (TOML)")

    run = commands.add_parser(
        "run", help="run a study and write results/<study>.h5",
        description="Run a study: simulate its cases, write one HDF5 result file (default "
                    "results/STUDY.h5) and its figures (figures/<file stem>-*.png beside "
                    "it). A run with a failed case never replaces an existing result file: "
                    "it is written beside it as <name>.failed.h5.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    scene_options(run)
    run.add_argument("--out", metavar="FILE.h5", help="result file (default results/STUDY.h5)")
    run.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    run.add_argument("--quiet", action="store_true", help="print nothing on success")
    run.add_argument("--scheduler", metavar="ADDRESS",
                     help="sweeps (kfit): 'local' (local Dask cluster), tcp://host:8786 (a Dask "
                          "scheduler) or 'serial'; default: a process pool on all cores")
    run.add_argument("--workers", type=int, metavar="N",
                     help="sweeps: number of local worker processes (default: all cores)")
    run.add_argument("--folder", metavar="DIR",
                     help="sweeps: folder of the per-case files, where a rerun resumes "
                          "(default: results/<study>-cases)")
    run.add_argument("--retry-failed", action="store_true",
                     help="sweeps: rerun the cases that failed last time (default: keep them)")
    scene = commands.add_parser("scene", help="print the fully resolved scene as TOML")
    scene_options(scene)
    run.add_argument("--animate", action="store_true",
                     help="also animate each case with a flexible link (flex animate): "
                          "figures/<file stem>-<case>.mp4 (or .gif) beside the result file")
    _result_tools(commands)
    _view_tools(commands)
    _design_command(commands)
    return parser


def _view_tools(commands) -> None:
    """The ``export`` and ``animate`` subcommands (a case's bodies and fields)."""
    export = commands.add_parser(
        "export", help="write a case's meshes and nodal fields as XDMF + HDF5 (ParaView)",
        description="Write each body of a case as one mesh (flexible links: the plate mesh "
                    "of their reduction or nonlinear FE body; rigid links and the slider: "
                    "boxes) with, at each stored time (or every N-th), the nodal displacement "
                    "in the mechanism's and the link's frame and the recovered von Mises and "
                    "axial stress, as OUT/<file stem>-<case>.xdmf + .h5 (ParaView, meshio). "
                    "Refused (exit 2) when the reduction rebuilt today is not the mode basis "
                    "the case was computed with.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    export.add_argument("file", metavar="FILE.h5")
    export.add_argument("case", nargs="?", metavar="CASE",
                        help="case name (may be omitted when the file has one case)")
    export.add_argument("--out", required=True, metavar="DIR", help="output folder")
    export.add_argument("--every", type=int, default=1, metavar="N",
                        help="export every N-th stored time (and the last; default 1)")
    export.add_argument("--force", action="store_true",
                        help="replace existing output files that flex did not write "
                             "(default: refused)")
    animate = commands.add_parser(
        "animate", help="animate a case: the mechanism with its flexible links deformed",
        description="Draw the mechanism in its plane at the stored times, each flexible link "
                    "deformed (magnified, the factor printed on each frame) and coloured by "
                    "von Mises stress, with the time and the crank angle; mp4 (H.264) when "
                    "an ffmpeg encoder is available (the imageio-ffmpeg package), else gif.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    animate.add_argument("file", metavar="FILE.h5")
    animate.add_argument("case", nargs="?", metavar="CASE",
                         help="case name (may be omitted when the file has one case)")
    animate.add_argument("--out", required=True, metavar="FILE",
                         help="animation file, .mp4 or .gif; .png: one frame (--time)")
    animate.add_argument("--time", type=float, metavar="S", dest="at_time_s",
                         help="for a .png: the frame nearest this time (default: the time "
                              "of the peak von Mises stress)")
    animate.add_argument("--frames", type=int, default=200, metavar="N",
                         help="at most N frames, evenly spaced in the stored samples "
                              "(default 200)")
    animate.add_argument("--fps", type=int, default=25, help="frames per second (default 25)")
    animate.add_argument("--magnification", type=float, metavar="X",
                         help="deformation scale (default: the peak deflection drawn as "
                              "1/20 of the link length, rounded to 1, 2 or 5 x 10^k)")
    animate.add_argument("--force", action="store_true",
                         help="replace an existing --out that flex did not write "
                              "(default: refused)")


def _design_command(commands) -> None:
    """The ``design`` subcommand (docs/design.md)."""
    design = commands.add_parser(
        "design", help="vary one input of a scene to meet a target within the stress limit",
        description="Answer a design question about a scene (coupler.model = auto): the "
                    "smallest coupler thickness, preload or rate, or the initial angle nearest "
                    "the scene's, that meets the target while peak coupler stress x safety "
                    "factor <= allowable. Prints the answer with every case behind it and "
                    "writes them to an HDF5 file. An unreachable target: one line, exit 2.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    design.add_argument("--vary", required=True, choices=("thickness", "angle", "preload", "rate"))
    target = design.add_mutually_exclusive_group(required=True)
    target.add_argument("--peak-speed", type=float, metavar="RAD_PER_S", help="at least")
    target.add_argument("--deployment-time", type=float, metavar="S", help="at most")
    target.add_argument("--final-angle", type=float, metavar="DEG", help="at least")
    design.add_argument("--allowable-stress", type=float, default=250e6, metavar="PA",
                        help="allowable coupler stress (default 250e6, ASTM A36 yield)")
    design.add_argument("--safety-factor", type=float, default=1.5, help="default 1.5")
    design.add_argument("--range", nargs=2, type=float, metavar=("MIN", "MAX"),
                        help="values searched, in the input's unit (m, deg, m, N/m)")
    design.add_argument("--scene", metavar="FILE.toml", help="scene file (default cavezza2012)")
    design.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="SECTION.KEY=VALUE", help="override one scene value (TOML)")
    design.add_argument("--out", default="results/design-question.h5", metavar="FILE.h5",
                        help="evidence file (default results/design-question.h5)")


def _design(args: argparse.Namespace) -> int:
    from flex.bodies.reduction import reduction_cache_dir
    from flex.config.settings import tolerance_beyond_reach
    from flex.data.outputs import check_output
    from flex.data.scene import load_scene
    from flex.experiments.design import question as dq
    from flex.experiments.design.cases import BASE_OVERRIDES

    target = next(name for name in dq.TARGETS if getattr(args, name) is not None)
    question = dq.Question(args.vary, target, getattr(args, target), args.allowable_stress,
                           args.safety_factor, tuple(args.range) if args.range else None)
    question.check()
    path = check_output(args.out, [args.scene] if args.scene else [])
    scene = load_scene(args.scene, BASE_OVERRIDES + list(args.overrides))
    dq.check_scene(scene, question)
    beyond = tolerance_beyond_reach(scene)
    if beyond:  # each case's own warning is not printed (flex.experiments.design.cases.design_case)
        print(f"flex: warning: design: {beyond}", file=sys.stderr, flush=True)
    result = dq.answer(scene, question, reduction_cache_dir(os.environ))
    _print(dq.answer_text(result))
    _print(f"wrote {dq.write_answer(result, scene, path)}")
    return EXIT_OK


PATH_HELP = ("path inside the file: cases/<case>/crank/angle, <case>/crank/angle, or "
             "crank/angle when the file has one case; a group means every dataset below "
             "it; * and ? are wildcards; a [i] suffix picks one column")


def _result_tools(commands) -> None:
    """The ``inspect``, ``plot`` and ``compare`` subcommands (reading result files)."""
    from flex.tools.compare import DEFAULT_ATOL, DEFAULT_RTOL, INTERPOLATIONS

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
                    "curve) passes when max|a - b| <= atol + rtol * max|b| and the common "
                    "time base covers B's whole time span with at least two samples (a "
                    "shorter, shifted or one-sample run fails, saying which span was "
                    "compared; --partial accepts the overlap). Exit status: 0 "
                    "all within tolerance, 1 some not, 2 a bad file or a PATH missing from "
                    "either file. Without PATH every curve of the cases both files have "
                    "is compared (/summary only when named; wall-clock timings never).")
    compare.add_argument("file_a", metavar="A.h5")
    compare.add_argument("file_b", metavar="B.h5")
    compare.add_argument("paths", nargs="*", metavar="PATH", help=PATH_HELP)
    compare.add_argument("--rtol", type=float, default=None,
                         help=f"relative tolerance, times max|b| (default: a curve whose cases "
                              f"state their history errors is allowed their root-sum-square, "
                              f"any other {DEFAULT_RTOL:g})")
    compare.add_argument("--atol", type=float, default=DEFAULT_ATOL,
                         help=f"absolute tolerance in the curve's units (default "
                              f"{DEFAULT_ATOL:g})")
    compare.add_argument("--interp", choices=INTERPOLATIONS, default="cubic",
                         help="interpolation onto the common time base (default cubic)")
    compare.add_argument("--limit", type=int, default=20, metavar="N",
                         help="show the N largest deviations (failures always; 0: all)")
    compare.add_argument("--partial", action="store_true",
                         help="compare on the overlap when A does not cover B's time span "
                              "(the report says which span; default: such a curve fails)")
    compare.add_argument("--json", action="store_true", help="print JSON (for scripts)")

    report = commands.add_parser(
        "report", help="write a Markdown report generated from a result file",
        description="Write a Markdown report of a result file: the study's report, "
                    "provenance, cases, every /summary table with units, and links to its "
                    "figures; every number is read from the file. Default output: "
                    "reports/<file stem>.md beside FILE. Exit status: 0 written, 2 a bad "
                    "file or output (nothing written).")
    report.add_argument("file", metavar="FILE.h5")
    report.add_argument("--out", metavar="REPORT.md",
                        help="report file, ending in .md (default: reports/ beside FILE)")


def _result_tool(args: argparse.Namespace) -> int:
    """Run ``inspect``, ``plot`` or ``compare``; returns the exit status."""
    import json

    if args.command == "report":
        from flex.tools.report import write_report

        _print(f"wrote {write_report(args.file, args.out)}")
        return EXIT_OK
    if args.command in ("export", "animate"):
        return _view_tool(args)
    if args.command == "inspect":
        from flex.tools.inspect import describe, format_description

        info = describe(args.file, args.path)
        _print(json.dumps(info, indent=2) if args.json else format_description(info))
        return 0
    if args.command == "plot":
        from flex.tools.plotcurves import plot_curves

        figure = plot_curves(args.file, args.paths, args.vs, args.x_spec, args.out,
                             args.title)
        _print(f"wrote {figure}")
        return 0
    from flex.tools.compare import compare_files

    report = compare_files(args.file_a, args.file_b, args.paths, args.rtol, args.atol,
                           args.interp, args.partial)
    _print(json.dumps(report.as_dict(), indent=2) if args.json
           else report.format(args.limit))
    return EXIT_OK if report.passed else EXIT_FAILED


def _view_tool(args: argparse.Namespace) -> int:
    """Run ``export`` or ``animate``; the reduction cache folder is read here, once."""
    from flex.bodies.reduction import reduction_cache_dir

    cache_dir = reduction_cache_dir(os.environ)
    if args.command == "export":
        from flex.tools.export import export_case

        done = export_case(args.file, args.case, args.out, args.every, cache_dir=cache_dir,
                           force=args.force)
        _print(f"wrote {done.xdmf} and {done.hdf5.name} ({done.times} times, {done.nodes} "
               f"nodes, {done.bytes_written / 1e6:.1f} MB)")
        return EXIT_OK
    from flex.tools.animate import animate_case

    done = animate_case(args.file, args.case, args.out, frames=args.frames, fps=args.fps,
                        magnification=args.magnification, cache_dir=cache_dir,
                        at_time_s=args.at_time_s, force=args.force)
    _print(f"wrote {done.path} ({done.frames} frame{'s' if done.frames != 1 else ''}, "
           f"{done.width}x{done.height} px, "
           f"deformation x {done.magnification:g})")
    return EXIT_OK


def _print(text: str, end: str = "\n") -> None:
    """Print to stdout; a closed pipe (``| head``) ends quietly."""
    try:
        print(text, end=end, flush=True)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def _auto_note(scene) -> str:
    """A TOML comment saying what the scene's "auto" solver keys resolve to (or when)."""
    from flex.config.settings import has_auto, resolve_solver_settings

    if not has_auto(scene):
        return ""
    if "auto" in (scene["crank"]["model"], scene["coupler"]["model"]):
        return ('# [simulation] "auto" keys: chosen at run time, once the model = "auto" links '
                "are decided (flex/config/settings.py)\n")
    _, choice = resolve_solver_settings(scene)
    keys = ", ".join(f"{key} = {value!r}" for key, value in choice.keys.items())
    return f'# [simulation] "auto" keys -> {keys} ({choice.entry}: {choice.reason})\n'


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit status (:mod:`flex.base.errors`). No exception
    leaves it: a bug prints one ``flex: internal error`` line and returns 3 (``FLEX_DEBUG=1``
    shows the traceback)."""
    from flex.base.interrupts import interrupts_not_swallowed
    from flex.base.progress import silence_watch

    received: list[int] = []
    restore = _catch_signals(received)
    stderr = sys.stderr
    try:
        with interrupts_not_swallowed(), silence_watch(stderr, PROGRESS_INTERVAL_S) as watched:
            sys.stderr = watched  # a line on stderr at least every PROGRESS_INTERVAL_S
            return _dispatch(argv)
    except FlexError as exc:
        print(f"flex: error: {_one_line(str(exc))}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:
        return _interrupted(exc, received)
    except OSError as exc:  # an output or input the operating system refused
        if received:  # an interrupt inside a C extension can surface as any error
            return _interrupted(exc, received)
        where = (f"cannot access '{exc.filename}'" if exc.filename else
                 "a file could not be read or written (the system named none)")
        print(f"flex: error: {where}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as exc:  # noqa: BLE001 - the last line of defence: no traceback
        if received:  # e.g. Ctrl-C during an import comes back as "ImportError"
            return _interrupted(exc, received)
        if os.environ.get("FLEX_DEBUG") == "1":
            raise
        print(f"flex: internal error: {type(exc).__name__}: {_one_line(str(exc))} (a bug in "
              f"flex: please report it with the command line; FLEX_DEBUG=1 shows where)",
              file=sys.stderr)
        return EXIT_INTERNAL
    finally:
        sys.stderr = stderr
        restore()


def console() -> None:
    """The ``flex`` console command."""
    sys.exit(main())


def _one_line(text: str, limit: int = 1000) -> str:
    text = " ".join(text.split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _catch_signals(received: list[int]):
    """SIGINT raises KeyboardInterrupt and SIGTERM :class:`~flex.base.errors.Terminated` (a
    KeyboardInterrupt, so a terminated run cleans up like Ctrl-C); each is noted in
    ``received``. Returns the function restoring the previous handlers."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return lambda: None

    def on_signal(signum, frame):
        received.append(signum)
        raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    return lambda: [signal.signal(sig, handler) for sig, handler in previous.items()]


def _interrupted(exc: BaseException, received: list[int]) -> int:
    """Say what an interrupt left behind; 130 (SIGINT) or 143 (SIGTERM)."""
    import signal

    kind = getattr(exc, "kind", type(exc))
    terminated = (isinstance(kind, type) and issubclass(kind, Terminated)) or (
        signal.SIGTERM in received)
    what = "terminated" if terminated else "interrupted"
    written = getattr(exc, "written", [])
    if written:
        files = ", ".join(str(path) for path in written)
        print(f"flex: {what}; already written: {files}; nothing else was changed (files not "
              f"yet written were left as they were)", file=sys.stderr)
    else:
        print(f"flex: {what}; no result file was changed", file=sys.stderr)
    return EXIT_SIGTERM if terminated else EXIT_SIGINT


def _dispatch(argv: list[str] | None) -> int:
    parser = _parser()
    args, extra = parser.parse_known_args(argv)
    if args.command is None:
        parser.error(f"unrecognized arguments: {' '.join(extra)}" if extra else
                     "a COMMAND is required: run, scene, design, inspect, plot, compare, report, "
                     "export or animate")
    if extra:  # PATHs after options (compare A B --rtol 1e-6 PATH): argparse leaves them over
        if args.command in ("plot", "compare") and not any(e.startswith("-") for e in extra):
            args.paths += extra
        else:
            parser.error(f"unrecognized arguments: {' '.join(extra)}")
    if args.command == "run":
        return _run(args)
    if args.command == "design":
        return _design(args)
    if args.command == "scene":
        from flex.config.usage import explicit_keys
        from flex.data.scene import to_toml
        from flex.study import check_cases, check_structure, load_study, study_scene

        module = load_study(args.study)
        given = explicit_keys(args.scene, args.overrides)
        check_structure(module, given)
        scene = study_scene(module, args.scene, args.overrides)
        check_cases(module, module.cases(scene), given)
        _print(_auto_note(scene) + to_toml(scene), end="")
        return EXIT_OK
    return _result_tool(args)


def _check_animate(study: str, source: str | None, overrides: list[str]) -> None:
    """``--animate`` for a study none of whose cases flex animate can show is refused before
    anything runs (an exact-beam coupler's run wrote its result, figure and report, then
    exited 2); a case decided at run time (``auto``) may be shown."""
    from flex.study import load_study, study_scene
    from flex.tools.motion import motion_problem

    module = load_study(study)
    problems = {motion_problem(scene)
                for scene in module.cases(study_scene(module, source, overrides)).values()}
    if "" not in problems:
        raise FlexError(f"--animate: no case of study '{study}' can be animated: "
                        f"{sorted(problems)[0]}; run without --animate")


def _run(args: argparse.Namespace) -> int:
    from flex.study import from_environment, load_study, run_study

    if args.workers is not None and args.workers < 1:
        raise FlexError(f"--workers {args.workers}: must be at least 1")
    sweep_options = [name for name, value in (("--scheduler", args.scheduler),
                                              ("--workers", args.workers),
                                              ("--folder", args.folder),
                                              ("--retry-failed", args.retry_failed or None))
                     if value is not None]
    if sweep_options and not getattr(load_study(args.study), "SWEEP", False):
        raise FlexError(f"{' and '.join(sweep_options)}: study '{args.study}' runs its cases "
                        f"in this process; these options apply to sweep studies (kfit)")
    if args.scheduler is not None:
        from flex.sweep.executors import check_scheduler

        try:
            check_scheduler(args.scheduler)
        except FlexError as exc:
            raise FlexError(f"--{exc}") from None
    if args.animate:
        _check_animate(args.study, args.scene, args.overrides)
    sweep = None
    if getattr(load_study(args.study), "SWEEP", False):
        import dataclasses

        from flex.sweep import settings_from_environment

        # the environment is read here, once, at the edge; the library gets arguments
        sweep = settings_from_environment(os.environ)
        sweep = dataclasses.replace(
            sweep, scheduler=args.scheduler or sweep.scheduler,
            workers=args.workers or sweep.workers,
            folder=Path(args.folder) if args.folder else sweep.folder,
            retry_failed=args.retry_failed or sweep.retry_failed)
    # the reduction cache folder and the study's declared variables: read here, once
    output = run_study(args.study, args.scene, args.overrides, args.out,
                       figures=not args.no_figures, quiet=args.quiet, sweep=sweep,
                       **from_environment(args.study, os.environ))
    if args.animate and output.as_expected and output.path is not None:
        from flex.study import Interrupted
        from flex.tools.animate import animate_results

        cache_dir = from_environment(args.study, os.environ)["cache_dir"]
        written = [output.path, *output.figures, *([output.report] if output.report else [])]
        try:
            for done in animate_results(output.path, cache_dir=cache_dir):
                written.append(done.path)
                if not args.quiet:
                    _print(f"wrote {done.path} ({done.frames} frames)")
        except KeyboardInterrupt as exc:  # the run's files are in place: say so
            raise Interrupted(written, getattr(exc, "kind", type(exc))) from None
    return EXIT_OK if output.as_expected else EXIT_FAILED
