"""User-facing errors and the command line's exit statuses.

Every problem a user can fix is a :class:`FlexError`: the command line prints
``flex: error: <message>`` (one line naming the problem and the accepted range), no
traceback, and exits with :data:`EXIT_BAD_INPUT`.

Exit statuses of ``flex`` (documented in ``flex --help`` and the README):

====  ==========================================================================
0     success (every case ended as the study declares; compare: within tolerance)
1     a result that is not what was asked: failed cases, or compare differences
2     bad input: a scene, a ``--set`` value, an argument, a result file, an output
      that cannot be written; nothing was run, or nothing was changed
3     internal error: a bug in flex (the message says so; ``FLEX_DEBUG=1`` shows
      the traceback)
130   interrupted by SIGINT (Ctrl-C); 143: terminated by SIGTERM
====  ==========================================================================
"""

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_INTERNAL = 3
EXIT_SIGINT = 130
EXIT_SIGTERM = 143

EXIT_STATUSES = {
    EXIT_OK: "success",
    EXIT_FAILED: "failed cases, or compare differences beyond the tolerance",
    EXIT_BAD_INPUT: "bad input (scene, --set value, argument, result file, unwritable output)",
    EXIT_INTERNAL: "internal error (a bug in flex; FLEX_DEBUG=1 shows the traceback)",
    EXIT_SIGINT: "interrupted (SIGINT, Ctrl-C)",
    EXIT_SIGTERM: "terminated (SIGTERM)",
}


class FlexError(Exception):
    """A problem the user can fix (bad input, impossible geometry, diverged run, bad file).

    The command line prints ``str(error)`` alone, without a traceback, and exits with 2.
    """


class SceneError(FlexError):
    """A scene (TOML parameter set or ``--set`` override) is invalid."""


class SimulationError(FlexError):
    """A simulation diverged or its solver failed; the message names step and time."""


class ResultFileError(FlexError):
    """A result file is missing, truncated, not HDF5, malformed, or not written by flex."""


class OutputError(FlexError):
    """An output (result file, figure, folder) cannot be written, or would overwrite an
    input."""


class ArgumentError(FlexError, TypeError):
    """An argument of a public function (:mod:`flex.api`) that is not of an accepted type or
    value, e.g. ``simulate(None)``; a :class:`TypeError` too, as Python code expects."""


class CacheError(OutputError):
    """A cache folder (the reduction cache) that cannot be used; the message names the cache
    and how to move it."""


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that every clean-up that handles an interrupt runs."""
