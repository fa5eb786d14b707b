"""Progress of long work, in lines that read well in a log (no carriage returns, no bars).

- :func:`duration_text`: ``42 s``, ``3.5 min``, ``2.1 h``.
- :func:`heartbeat`: a context manager printing ``flex: <what>: still running after 30 s``
  lines to stderr at a fixed interval while a long call that reports nothing itself runs
  (a mesh, an eigen-solve), from a daemon thread that ends with the block.
- :func:`silence_watch`: a stream wrapper for the command line: a line whenever nothing
  was printed for :data:`PROGRESS_INTERVAL_S` (many short steps, each below its own
  announce threshold, are not silent for minutes).
- :class:`Progress`: a throttled reporter for work that knows how far it is: the first
  line after ``first_s`` seconds, then at most one every ``interval_s``.

Nothing here keeps state between calls (no module-level state); the stream is an argument
(stderr by default).
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TextIO

#: the longest silence on stderr the command line allows itself [s] (README: "progress every
#: 10 s"; :func:`silence_watch`)
PROGRESS_INTERVAL_S = 10.0
#: seconds between two progress lines of one job: a little below
#: :data:`PROGRESS_INTERVAL_S`, so that a job's own lines come first and the silence watch
#: speaks only when nothing else does
REPORT_INTERVAL_S = 9.0


def duration_text(seconds: float) -> str:
    """``seconds`` for a person: ``0.5 s``, ``9.4 s``, ``42 s``, ``105 s``, ``3.5 min``,
    ``2.1 h``, ``3 days``."""
    if seconds < 10:
        return f"{seconds:.2g} s"
    if seconds < 120:  # "1e+02 s" is no way to say a hundred seconds
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.2g} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.2g} h"
    return f"{seconds / 86400:.2g} days"


@contextmanager
def heartbeat(what: str, interval_s: float = REPORT_INTERVAL_S, stream: TextIO | None = None
              ) -> Iterator[None]:
    """Print ``flex: <what>: still running after <t>`` every ``interval_s`` seconds while the
    block runs (nothing for a block shorter than that)."""
    out = stream or sys.stderr
    done = threading.Event()
    start = time.perf_counter()

    def beat() -> None:
        while not done.wait(interval_s):
            print(f"flex: {what}: still running after "
                  f"{duration_text(time.perf_counter() - start)}", file=out, flush=True)

    thread = threading.Thread(target=beat, name="flex-heartbeat", daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join(timeout=1.0)


class _Watched:
    """A text stream that notes when it was last written to, and its last line."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream
        self.lock = threading.Lock()
        self.last_s = time.perf_counter()
        self.last_line = ""

    def write(self, text: str) -> int:
        with self.lock:
            self.last_s = time.perf_counter()
            lines = [line for line in text.splitlines() if line.strip()]
            if lines:
                self.last_line = lines[-1].strip()
            return self.stream.write(text)

    def write_aside(self, text: str) -> None:
        """Write ``text`` and flush, noting the time but keeping the last line (the watch's
        own lines: each names the work's last line, never the watch's previous one)."""
        with self.lock:
            self.last_s = time.perf_counter()
            self.stream.write(text)
            self.stream.flush()

    def __getattr__(self, name: str):
        return getattr(self.stream, name)


@contextmanager
def silence_watch(stream: TextIO, interval_s: float = PROGRESS_INTERVAL_S
                  ) -> Iterator[TextIO]:
    """Yield a stream that writes to ``stream``; while the block runs, whenever nothing was
    written to it for ``interval_s`` seconds, a line ``flex: still working after <t> (last
    line <t> ago: <line>)`` is (so a log shows a line at least every ``interval_s``, whatever
    the work and however it is split into steps shorter than their own announce
    thresholds)."""
    watched = _Watched(stream)
    done = threading.Event()
    start = time.perf_counter()

    def watch() -> None:
        while True:
            remaining = interval_s - (time.perf_counter() - watched.last_s)
            if remaining > 0:
                if done.wait(remaining):
                    return
                continue
            now = time.perf_counter()
            last = (f" (last line {duration_text(now - watched.last_s)} ago: "
                    f"{watched.last_line})" if watched.last_line else "")
            try:  # not a last line of its own: the next one names the work's again
                watched.write_aside(f"flex: still working after {duration_text(now - start)}"
                                    f"{last}\n")
            except (OSError, ValueError):  # a closed stream: nothing more to say
                return

    thread = threading.Thread(target=watch, name="flex-silence-watch", daemon=True)
    thread.start()
    try:
        yield watched
    finally:
        done.set()
        thread.join(timeout=1.0)


class Progress:
    """Throttled progress lines ``flex: <what>: <text>`` for work that knows how far it is:
    :meth:`update` prints only once ``first_s`` seconds have passed since the start and
    then at most every ``interval_s`` seconds."""

    def __init__(self, what: str, first_s: float = 2.0,
                 interval_s: float = REPORT_INTERVAL_S, stream: TextIO | None = None) -> None:
        self.what, self.first_s, self.interval_s = what, first_s, interval_s
        self.stream = stream
        self.start = time.perf_counter()
        self.last: float | None = None

    def update(self, text: str) -> bool:
        """Print ``text`` if it is time to; return whether it was printed."""
        now = time.perf_counter()
        if now - self.start < self.first_s:
            return False
        if self.last is not None and now - self.last < self.interval_s:
            return False
        self.last = now
        print(f"flex: {self.what}: {text}", file=self.stream or sys.stderr, flush=True)
        return True
