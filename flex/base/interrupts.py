"""Interrupts that are never swallowed.

Python runs a signal handler between two bytecodes of the main thread, wherever that is.
When that is inside a weakref callback, a finalizer or ``__del__`` (pybind11 and h5py run
such callbacks all the time), the ``KeyboardInterrupt`` the handler raises cannot propagate:
Python prints "Exception ignored in ..." and goes on, and a Ctrl-C is lost while a run goes on
for minutes. :func:`interrupts_not_swallowed` delivers such an interrupt again: it is raised
anew at the next function call or return once the hook has returned (should that again be
inside a callback, the same happens again).

Nothing here keeps state between calls; the hook is installed for the block only.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def interrupts_not_swallowed() -> Iterator[None]:
    """While the block runs, a ``KeyboardInterrupt`` (SIGINT) or
    :class:`~flex.base.errors.Terminated` (SIGTERM) that Python could only report as an
    unraisable exception is delivered again (the same signal, raised anew) instead of being
    printed and forgotten; other unraisable exceptions go to the previous hook."""
    previous = sys.unraisablehook

    def hook(unraisable) -> None:
        kind = unraisable.exc_type
        if isinstance(kind, type) and issubclass(kind, KeyboardInterrupt) and \
                not sys.is_finalizing():
            _raise_outside(sys._getframe(), kind)
            return
        previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    finally:
        sys.unraisablehook = previous


def _raise_outside(hook_frame, kind: type) -> None:
    """Raise ``kind`` at the next call or return of this thread outside ``hook_frame`` (a
    profile function, removed as it fires): the callback that swallowed it has ended by then,
    so it propagates through the ordinary code that triggered the callback."""
    previous = sys.getprofile()

    def again(frame, event, arg) -> None:
        inner = frame
        while inner is not None:
            if inner is hook_frame:  # still in the hook (or below it)
                return
            inner = inner.f_back
        sys.setprofile(previous)
        raise kind()

    sys.setprofile(again)


__all__ = ["interrupts_not_swallowed"]
