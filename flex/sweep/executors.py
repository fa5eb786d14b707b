"""Where a sweep's cases run: one executor seam (:func:`make_executor`: processes, Dask,
serial) and the guard that turns any exception of a case into a failed case (module doc of
:mod:`flex.sweep`)."""

from __future__ import annotations

import os
import re
import traceback
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from pathlib import Path
from typing import Any

from flex.base.errors import FlexError
from flex.base.lifetime import die_with_parent
from flex.data.results import CaseResult
from flex.data.scene import Scene, to_toml


def simulate_scene_case(name: str, scene: Scene, *, cache_dir: Path | None = None
                        ) -> CaseResult:
    """The default case: :func:`flex.fidelity.simulation.simulate_case` of the scene (never raises
    for a diverged run: that is a ``failed`` case). ``cache_dir``: the reduction cache folder
    (None: reductions built in memory, no disk cache); bind it with ``functools.partial``."""
    from flex.fidelity.simulation import simulate_case

    return simulate_case(scene, name, cache_dir=cache_dir)


def guarded_case(function: Callable[..., Any], name: str, scene: Scene) -> Any:
    """Run ``function(name, scene)``; any exception becomes a failed :class:`CaseResult`."""
    try:
        result = function(name, scene)
    except BaseException as exc:  # noqa: BLE001 - a case must never stop the sweep
        if isinstance(exc, KeyboardInterrupt | SystemExit):
            raise
        where = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
        origin = f" (at {Path(where.filename).name}:{where.lineno})" if where else ""
        return CaseResult(name, to_toml(scene), status="failed",
                          message=f"{type(exc).__name__}: {exc}{origin}")
    if not isinstance(result, CaseResult):
        return CaseResult(name, to_toml(scene), status="failed",
                          message=f"case function returned {type(result).__name__}, "
                                  f"not CaseResult")
    result.name = name
    return result


def guarded_preparation(function: Callable[[Scene], Any], scene: Scene) -> tuple[bool, Any]:
    """Run ``function(scene)`` (a shared preparation): ``(True, its result)``, or ``(False,
    the exception as one line)``, recorded on the cases that needed it."""
    try:
        return True, function(scene)
    except Exception as exc:  # noqa: BLE001 - recorded on the cases that needed it
        return False, f"{type(exc).__name__}: {exc}"


# ------------------------------------------------------------------------------------------
# executors
# ------------------------------------------------------------------------------------------
class _DoneFuture:
    """A finished future for the serial executor (``result()`` re-raises like a future)."""

    def __init__(self, function: Callable[..., Any], args: tuple) -> None:
        self._value: Any = None
        self._error: BaseException | None = None
        try:
            self._value = function(*args)
        except Exception as exc:  # noqa: BLE001 - delivered by result()
            self._error = exc

    def result(self) -> Any:
        if self._error is not None:
            raise self._error
        return self._value

    def running(self) -> bool:
        return False


class Executor:
    """The executor seam: submit a function, wait for the first finished futures, close."""

    description = "executor"
    workers = 1
    #: submissions reach the workers pickled (a local process pool; Dask uses cloudpickle)
    pickles = False

    def submit(self, function: Callable[..., Any], *args: Any) -> Any:
        raise NotImplementedError

    def wait_first(self, futures: Iterable[Any], timeout: float | None = None) -> set:
        """Futures of ``futures`` that are finished (at least one unless timed out)."""
        raise NotImplementedError

    def restart(self) -> None:
        """Replace a broken pool (local processes only)."""

    def isolated(self) -> Executor:
        """A fresh single-worker executor for re-running a suspect case alone."""
        return self

    def close(self) -> None:
        """Release workers (and the cluster, if this executor started one)."""

    def abort(self) -> None:
        """Stop at once (an interrupt): running work is abandoned, not waited for."""
        self.close()


class SerialExecutor(Executor):
    """Runs every submission at once, in this process."""

    description = "serial (in-process)"

    def submit(self, function: Callable[..., Any], *args: Any) -> _DoneFuture:
        return _DoneFuture(function, args)

    def wait_first(self, futures: Iterable[Any], timeout: float | None = None) -> set:
        return set(futures)


#: seconds an aborted worker gets to end on SIGTERM before it is killed (SIGKILL)
ABORT_GRACE_S = 2.0


class ProcessExecutor(Executor):
    """``concurrent.futures.ProcessPoolExecutor`` with ``workers`` spawned processes."""

    pickles = True

    def __init__(self, workers: int | None = None) -> None:
        import multiprocessing

        self.workers = int(workers or os.cpu_count() or 1)
        # spawn, not fork: Exudyn and NGsolve hold threads that a fork would copy half-way
        self._context = multiprocessing.get_context("spawn")
        self._pool = self._new_pool()
        self.description = f"local processes ({self.workers} workers)"

    def _new_pool(self) -> ProcessPoolExecutor:
        """A pool whose workers end with this process (:func:`die_with_parent`), however it
        ends: a run killed with SIGKILL left its workers computing for minutes."""
        return ProcessPoolExecutor(self.workers, mp_context=self._context,
                                   initializer=die_with_parent, initargs=(os.getpid(),))

    def submit(self, function: Callable[..., Any], *args: Any) -> Future:
        return self._pool.submit(function, *args)

    def wait_first(self, futures: Iterable[Any], timeout: float | None = None) -> set:
        return wait(list(futures), timeout=timeout, return_when=FIRST_COMPLETED)[0]

    def restart(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool = self._new_pool()

    def isolated(self) -> Executor:
        return ProcessExecutor(1)

    def close(self) -> None:
        self._pool.shutdown(wait=True, cancel_futures=True)

    def abort(self) -> None:
        """Cancel what waits and end the workers: SIGTERM, then SIGKILL for those still
        there after :data:`ABORT_GRACE_S` (a worker in a minutes-long eigen-solve, or in an
        Exudyn solve that turns SIGTERM into an exception and asks for the next case, does
        not end on SIGTERM: an interrupted ``flex run calibrate --workers 2`` went on for
        minutes, joining its workers). A new pool serves any later submission."""
        import multiprocessing
        import time

        self._pool.shutdown(wait=False, cancel_futures=True)
        # every child process of this (interrupted) process, the pool's workers among them
        children = multiprocessing.active_children()
        for child in children:
            child.terminate()
        deadline = time.monotonic() + ABORT_GRACE_S
        for child in children:
            child.join(timeout=max(0.0, deadline - time.monotonic()))
        for child in children:
            if child.is_alive():
                child.kill()
                child.join(timeout=ABORT_GRACE_S)
        self._pool = self._new_pool()


#: seconds a Dask scheduler without workers is given for one to join before it is refused
WORKER_WAIT_S = 30.0


class DaskExecutor(Executor):
    """A ``dask.distributed.Client``: to ``address``, or to a new loopback ``LocalCluster``.

    The local cluster has ``workers`` single-threaded worker processes (default: all cores)
    bound to 127.0.0.1 without a dashboard; :meth:`close` stops it. A remote scheduler is
    used as it is (its workers need ``flex`` installed and, to share reductions, the
    ``cache_dir`` the case functions get must be a folder they all reach).
    """

    def __init__(self, address: str | None = None, workers: int | None = None) -> None:
        try:
            from distributed import Client, LocalCluster
        except ImportError:  # pragma: no cover - a declared dependency
            raise FlexError("scheduler: dask.distributed is not installed "
                            "(pip install 'dask[distributed]')") from None
        self._cluster = None
        if address is None:
            self.workers = int(workers or os.cpu_count() or 1)
            self._cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                         processes=True, host="127.0.0.1",
                                         dashboard_address=None, silence_logs=40)
            self.client = Client(self._cluster)
            self.description = f"Dask local cluster ({self.workers} workers)"
        else:
            try:
                self.client = Client(address, timeout="20s")
            except OSError as exc:
                raise FlexError(f"scheduler {address}: cannot connect ({exc})") from None
            self.workers = self._wait_for_workers(address)
            self.description = f"Dask scheduler {address} ({self.workers} workers)"

    def _wait_for_workers(self, address: str) -> int:
        """The scheduler's workers, once it has one: said when it has none yet, refused
        after :data:`WORKER_WAIT_S` (a sweep on a scheduler without workers waited in
        silence, for ever)."""
        import sys

        found = len(self.client.scheduler_info().get("workers", {}))
        if found:
            return found
        print(f"flex: scheduler {address} has no worker yet: waiting up to "
              f"{WORKER_WAIT_S:g} s for one", file=sys.stderr, flush=True)
        try:
            self.client.wait_for_workers(1, timeout=WORKER_WAIT_S)
        except (TimeoutError, OSError) as exc:
            self.client.close()
            raise FlexError(f"scheduler {address}: no worker joined within "
                            f"{WORKER_WAIT_S:g} s (start some: dask worker {address}; or "
                            f"run without --scheduler) ({type(exc).__name__})") from None
        return max(1, len(self.client.scheduler_info().get("workers", {})))

    def submit(self, function: Callable[..., Any], *args: Any) -> Any:
        return self.client.submit(function, *args, pure=False)

    def wait_first(self, futures: Iterable[Any], timeout: float | None = None) -> set:
        from distributed import wait as dask_wait
        from distributed.client import TimeoutError as DaskTimeout

        futures = list(futures)
        try:
            return set(dask_wait(futures, timeout=timeout, return_when="FIRST_COMPLETED").done)
        except (DaskTimeout, TimeoutError):
            return {f for f in futures if f.done()}

    def close(self) -> None:
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()


#: a Dask scheduler address: protocol://host:port (host a name, IPv4 or [IPv6]); inproc://
#: addresses need no port
ADDRESS = re.compile(r"^(?:(?:tcp|tls|ucx|ws|wss)://(?:\[[0-9A-Fa-f:.]+\]|[^\s:/\[\]]+)"
                     r":(?P<port>\d{1,5})|inproc://\S+)$")
SCHEDULER_CHOICES = ("expected processes (default), serial, local (Dask on this machine) or "
                     "a Dask address like tcp://host:8786")


def check_scheduler(scheduler: str | None) -> None:
    """Refuse (:class:`FlexError`, one line) a ``scheduler`` that is none of the module
    doc's: a Dask address needs ``protocol://host:port`` with a port in 1..65535."""
    if scheduler in (None, "processes", "serial", "local"):
        return
    match = ADDRESS.match(str(scheduler))
    if match is None and re.match(r"^(tcp|tls|ucx|ws|wss)://", str(scheduler)):
        raise FlexError(f"scheduler {scheduler!r}: a Dask address needs a port, "
                        f"protocol://host:port like tcp://host:8786")
    if match is None:
        raise FlexError(f"scheduler {scheduler!r}: {SCHEDULER_CHOICES}")
    if match["port"] is not None and not 1 <= int(match["port"]) <= 65535:
        raise FlexError(f"scheduler {scheduler!r}: port {match['port']} is outside 1..65535")


def make_executor(scheduler: str | None = None, workers: int | None = None) -> Executor:
    """The executor for ``scheduler`` (see the module doc); unknown values are refused
    (:func:`check_scheduler`; ``""`` is the default, as None)."""
    scheduler = scheduler or None
    check_scheduler(scheduler)
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise FlexError(f"workers = {workers!r}: must be an integer >= 1")
    if scheduler in (None, "", "processes"):
        return ProcessExecutor(workers)
    if scheduler == "serial":
        return SerialExecutor()
    if scheduler == "local":
        return DaskExecutor(None, workers)
    return DaskExecutor(scheduler, workers)

