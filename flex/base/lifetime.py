"""Child processes that end with the process that started them, however it ends.

A run killed with SIGKILL runs no clean-up: its pool workers (and what they hold, the output
pipe among it) computed on for minutes. :func:`die_with_parent` is a worker initializer that
asks the kernel for a signal when the parent ends (Linux ``prctl(PR_SET_PDEATHSIG)``), or
polls the parent elsewhere; :func:`dying_with_this_process` wraps a command line the same
way (the signal survives ``exec``). Nothing here keeps state between calls.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

#: Linux prctl option: the signal this process gets when its parent ends
_PR_SET_PDEATHSIG = 1

#: the wrapper of :func:`dying_with_this_process`: arm, check the parent, exec the command
_LAUNCHER = ("import os, sys; from flex.base.lifetime import die_with_parent; "
             "die_with_parent(int(sys.argv[1]), int(sys.argv[2])); "
             "os.execvp(sys.argv[3], sys.argv[3:])")


def die_with_parent(parent_pid: int, signum: int = int(signal.SIGKILL)) -> None:
    """End this process with ``signum`` when ``parent_pid`` (the process that started it)
    ends, however that ends (SIGKILL included). On Linux the kernel sends it
    (``prctl(PR_SET_PDEATHSIG)``; it fires when the *thread* that started this process
    ends: flex starts its workers from the thread that submits, the main thread);
    elsewhere a daemon thread polls the parent every second. A parent already gone ends
    this process at once. Meant for the first thing a child runs (a pool's initializer)."""
    armed = False
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(_PR_SET_PDEATHSIG, int(signum), 0, 0, 0) == 0
        except (OSError, AttributeError):  # no prctl: the watchdog below
            armed = False
    if os.getppid() != parent_pid:  # the parent ended before the request took effect
        os.kill(os.getpid(), signum)
        os._exit(1)
    if not armed:
        def watch() -> None:
            while os.getppid() == parent_pid:
                time.sleep(1.0)
            os.kill(os.getpid(), signum)
            os._exit(1)

        threading.Thread(target=watch, name="flex-parent-watch", daemon=True).start()


def dying_with_this_process(argv: list[str], signum: int = int(signal.SIGTERM)) -> list[str]:
    """``argv`` wrapped so that the command gets ``signum`` when this process ends (a
    ``make`` a study runs: SIGTERM, which make passes on to its recipes)."""
    return [sys.executable, "-c", _LAUNCHER, str(os.getpid()), str(int(signum)), *argv]


__all__ = ["die_with_parent", "dying_with_this_process"]
