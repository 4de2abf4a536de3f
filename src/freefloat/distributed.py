"""Work spread over processes: a pool of this machine's processes (:func:`process_pool`), or
Dask: a client of a local cluster or of a scheduler, and the results of submitted tasks as they
finish.

Dask is an optional dependency (``pip install -e ".[dask]"``), imported when a client is made.
Shared by the 5R sweeps (:mod:`freefloat.parallel.sweeps`) and the batches of runs
(:mod:`freefloat.app.batch`); it imports nothing of freefloat but its errors.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import signal
import socket
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any

from tqdm import tqdm

from .errors import InvalidArgument, spelled
from .extras import require

tqdm.monitor_interval = 0  # no monitor thread: a signal at exit made its atexit hook print a traceback

#: Seconds between a pool worker's looks at whether the process that made it is still there.
PARENT_WATCH_S = 0.5


def process_pool(workers: int, initializer: Callable[[], None] | None = None) -> ProcessPoolExecutor:
    """A pool of ``workers`` new interpreters (spawned, never forked: this process has threads, BLAS's
    and progress bars', and a fork of a threaded process can deadlock; Python 3.12 warns at every
    fork there). As with any spawned pool, a script that makes one needs the
    ``if __name__ == "__main__":`` guard.

    The pool is made to be stopped from this process (see :class:`_Pool`): its workers ignore
    Ctrl-C (a terminal sends it to the whole process group; this process decides), each ends
    itself within :data:`PARENT_WATCH_S` s once this process is gone (killed outright, its
    workers otherwise waited on their queue for ever, holding its output pipes open), a stop
    signal arriving while a worker is launched waits until the launch is done, and a block left
    by an exception cancels the calls not yet started."""
    return _Pool(workers, mp_context=multiprocessing.get_context("spawn"), initializer=_start_worker,
                 initargs=(os.getpid(), initializer))


class _Pool(ProcessPoolExecutor):
    """A process pool for :func:`process_pool`."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        """As ``ProcessPoolExecutor.submit``, with Ctrl-C, SIGTERM and SIGHUP held while it may launch
        a worker: one arriving then cut the hand-over of the worker's start-up data, and the worker
        printed a traceback ('EOFError: Ran out of input'). A signal held takes effect on return; the
        worker starts with them blocked and unblocks them once it has started (:func:`_start_worker`)."""
        arrived: list[int] = []
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, _STOPS)  # inherited by the worker launched
        previous = {s: signal.signal(s, lambda signum, frame: arrived.append(signum)) for s in _STOPS} \
            if threading.current_thread() is threading.main_thread() else {}
        try:
            return super().submit(fn, *args, **kwargs)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
            for signum, handler in previous.items():
                signal.signal(signum, handler)
            if arrived:
                signal.raise_signal(arrived[0])

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> bool:
        """Wait for the workers; calls not started yet are cancelled when an exception (Ctrl-C,
        SIGTERM) leaves the block, instead of all being run first."""
        self.shutdown(wait=True, cancel_futures=exc_type is not None)
        return False


def terminate(pool: ProcessPoolExecutor) -> None:
    """Stop ``pool`` now: calls not started cancelled, running ones killed (Python 3.14's
    ``terminate_workers``; before it, the executor's own process table, read before ``shutdown``
    empties it)."""
    stop = getattr(pool, "terminate_workers", None)
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    if stop is not None:
        stop()
        return
    for process in processes:
        process.terminate()


#: The signals that stop a freefloat command (held while a worker is launched).
_STOPS = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}


def _start_worker(parent: int, initializer: Callable[[], None] | None) -> None:
    """In a new worker: ignore Ctrl-C, release the signals held at its launch, watch ``parent``
    (see :func:`process_pool`), then run ``initializer``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOPS)
    threading.Thread(target=_end_with, args=(parent,), name="freefloat-parent-watch", daemon=True).start()
    if initializer is not None:
        initializer()


def _end_with(parent: int) -> None:
    """End this process as soon as its parent is no longer ``parent`` (it died; the orphan was
    handed to another)."""
    while os.getppid() == parent:
        time.sleep(PARENT_WATCH_S)
    os._exit(1)


def client(address: str | None = None, workers: int = 2, processes: bool = True, connect_timeout: float = 5.0,
           threads: int = 1):
    """A Dask client: connected to ``address`` (e.g. ``tcp://host:8786``) or to a new local cluster
    of ``workers`` workers on this machine (loopback only, ``threads`` threads each: several tasks
    of a worker run at once where they release the GIL, as the compiled loop does).

    Raises:
        InvalidArgument: naming the address when it is malformed or nothing answers there within
            ``connect_timeout`` s.
        MissingExtra: without Dask.
    """
    require("dask", "a Dask client")
    from dask.distributed import Client, LocalCluster

    if address:
        _reachable(address, connect_timeout)
        return Client(address, timeout=connect_timeout)
    network = {"host": "127.0.0.1"} if processes else {}  # in-process clusters have no sockets
    # our own workers: their failures reach us through the futures; their log would print
    # tracebacks of lost heartbeats when the user stops the command
    return Client(LocalCluster(n_workers=workers, threads_per_worker=threads, processes=processes,
                               dashboard_address=None, silence_logs=logging.CRITICAL, **network))


def _reachable(address: str, timeout: float) -> None:
    """Check that a scheduler listens at ``address`` before Dask tries (its own failure takes
    its whole timeout and leaves a half-made client behind).

    Raises:
        InvalidArgument: naming the address and what is wrong with it.
    """
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address, strict=True)
        host, port = parse_host_port(location)
    except (ValueError, TypeError) as exc:
        raise InvalidArgument(f"{_scheduler()} '{address}' is not a Dask address such as tcp://host:8786 "
                              f"({exc})") from exc
    if scheme not in ("tcp", "tls"):
        raise InvalidArgument(f"{_scheduler()} '{address}': scheme '{scheme}' is not supported here; use "
                              "tcp://host:port")
    try:
        socket.create_connection((host, port), timeout=timeout).close()
    except OSError as exc:
        raise InvalidArgument(f"{_scheduler()} '{address}': no Dask scheduler answers ({exc.strerror or exc})") from exc


def _scheduler() -> str:
    """The scheduler's argument as the caller spells it (:func:`~freefloat.errors.spelled`)."""
    return spelled("scheduler", "--scheduler")


def settle_futures(futures: dict, label: str, quiet: bool, timeout: float,
           on_result: Callable[[int, object], None] | None = None) -> dict[int, object]:
    """Results of ``futures`` ({index: future}) as they complete, each a value or the exception
    it raised; stops waiting when none completes within ``timeout`` s (the rest are missing).
    ``on_result(index, result)`` is called as each completes; the futures still pending when it
    returns (or is interrupted) are cancelled."""
    from dask.distributed import TimeoutError as DaskTimeout
    from dask.distributed import as_completed

    index_of = {future.key: i for i, future in futures.items()}
    results: dict[int, object] = {}
    try:
        with tqdm(total=len(futures), desc=label, disable=quiet) as bar:
            completed = as_completed(list(futures.values()), timeout=timeout)
            try:
                for future in completed:
                    i = index_of[future.key]
                    try:
                        results[i] = future.result()
                    except Exception as exc:  # the task's own failure, recorded, not fatal
                        results[i] = exc
                    if on_result is not None:
                        on_result(i, results[i])
                    bar.update(1)
            except (DaskTimeout, TimeoutError):
                pass
    finally:
        for future in futures.values():
            future.cancel()
    return results
