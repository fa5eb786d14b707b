"""User-facing errors: one message naming the problem and the accepted range."""


class FlexError(Exception):
    """A problem the user can fix (bad input, impossible geometry, diverged run, bad file).

    The command line prints ``str(error)`` alone, without a traceback, and exits with 2.
    """


class SceneError(FlexError):
    """A scene (TOML parameter set or ``--set`` override) is invalid."""


class SimulationError(FlexError):
    """A simulation diverged or its solver failed; the message names step and time."""


class ResultFileError(FlexError):
    """A result file is missing, truncated, not HDF5, or not written by flex."""
