"""Where the runs of a batch run: one after another in this process, on threads of this process,
in a pool of worker processes, or on Dask workers (a local cluster, whose workers may each run
several threads, or a scheduler's). Runs that can share one compiled call
(:mod:`.compiled_runs`: a ``joint_space`` scene varying its initial state) run in groups of one
call each, here on C++ threads (one per ``--threads``), in a pool or on Dask as tasks of several
runs (:func:`run_group`); the others run one by one (:func:`~.one_run.run_one`), on Python threads
with ``--threads``: the compiled loop, most of a run's time, releases the GIL, while the rest of
a run (its setup and summary) is Python and takes turns.

:func:`executor` gives ``execute(plans, on_row)``, which calls ``on_row(row)`` as each run
finishes, in the order they finish, and returns nothing; a ``KeyboardInterrupt`` (Ctrl-C, or
SIGTERM turned into one by the caller) stops the work at once (pool workers are terminated,
Dask's pending tasks cancelled, threads' runs stopped at their next chunk by
:mod:`freefloat.dynamics.stop_request`) and propagates, after every row already finished was given.
"""

from __future__ import annotations

import contextlib
import numbers
import os
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass
from typing import Any

from ...distributed import client, process_pool, settle_futures, terminate
from ...dynamics import stop_request
from ...dynamics.many_runs import MAX_THREADS
from ...dynamics.threads import ONE_BLAS_THREAD
from ...errors import InvalidArgument, spelled
from . import compiled_runs
from .one_run import run_one
from .variations import RunPlan

OnRow = Callable[[dict[str, Any]], None]
Execute = Callable[[list[RunPlan], OnRow], None]

#: With Dask, the batch ends when no run finishes within this many seconds (every worker lost);
#: the runs left are recorded as failed.
DASK_TIMEOUT = 600.0


def local_limit() -> int:
    """Most worker processes a local pool or cluster may start: the cores, and at least 4."""
    return max(4, os.cpu_count() or 1)


@dataclass(frozen=True)
class Workers:
    """Where the runs go: ``count`` processes (1 and not ``dask``: this process, one after
    another, or on ``threads`` threads), through Dask when ``dask`` (a local cluster of ``count``
    workers of ``threads`` threads each, or ``scheduler``'s). ``force`` (``--force-workers``)
    lets ``count`` exceed :func:`local_limit`: the processes then take turns on the cores.

    Raises:
        InvalidArgument: naming ``count`` (``--workers``) below 1 or above :func:`local_limit`
            (without ``scheduler`` or ``force``), or ``threads`` outside [1,
            :data:`~freefloat.dynamics.many_runs.MAX_THREADS`], ``scheduler`` without ``dask``,
            ``threads`` with a process pool (``count`` > 1 without ``dask``) or with ``scheduler``
            (its workers have their own threads), as the caller spells them
            (:func:`~freefloat.errors.spelled`).
    """

    count: int = 1
    dask: bool = False
    scheduler: str | None = None
    threads: int = 1
    force: bool = False

    def __post_init__(self) -> None:
        count, threads = spelled("count", "--workers"), spelled("threads", "--threads")
        scheduler, dask = spelled("scheduler", "--scheduler"), spelled("dask=True", "--dask")
        if isinstance(self.count, bool) or not isinstance(self.count, numbers.Integral) or self.count < 1:
            raise InvalidArgument(f"{count} must be an integer >= 1, got {self.count!r}")
        if self.scheduler is None and self.count > local_limit() and not self.force:
            raise InvalidArgument(f"{count} {self.count} is more processes than this machine can run at once: it has "
                                  f"{os.cpu_count() or 1} cores and takes up to {local_limit()} (each process an "
                                  f"interpreter of its own; more only take turns); give {spelled('scheduler', '--scheduler')} "
                                  f"for a cluster's workers, or {spelled('force=True', '--force-workers')} to start "
                                  f"{self.count} all the same")
        if not 1 <= self.threads <= MAX_THREADS:
            raise InvalidArgument(f"{threads} must be from 1 to {MAX_THREADS}, got {self.threads}")
        if self.scheduler is not None and not self.dask:
            raise InvalidArgument(f"{scheduler} is a Dask scheduler's address; it needs {dask}")
        if self.threads > 1 and self.scheduler is not None:
            raise InvalidArgument(f"{threads} sets the threads of a local Dask cluster's workers; with {scheduler} "
                                  "the scheduler's workers run with their own")
        if self.threads > 1 and self.count > 1 and not self.dask:
            raise InvalidArgument(f"{threads} {self.threads} with {count} {self.count}: choose threads of this "
                                  f"process or a pool of processes (or {dask} for workers of several threads each)")

    @property
    def label(self) -> str:
        """``serial``, ``threads of K``, ``pool of K`` or ``dask ...``, for reports."""
        if self.dask:
            if self.scheduler:
                return f"dask scheduler {self.scheduler}"
            each = f" of {self.threads} threads each" if self.threads > 1 else ""
            return f"dask local cluster of {self.count}{each}"
        if self.threads > 1:
            return f"threads of {self.threads}"
        return "serial" if self.count == 1 else f"pool of {self.count}"


@contextlib.contextmanager
def executor(workers: Workers) -> Iterator[Execute]:
    """``execute(plans, on_row)`` on ``workers``; a Dask client is connected (or its local
    cluster started) on entering, and closed on leaving.

    Raises:
        InvalidArgument: on entering, naming ``scheduler`` when nothing answers there.
    """
    if workers.dask:
        with client(workers.scheduler, workers.count, threads=workers.threads) as dask_client:
            yield lambda plans, on_row: run_dask(dask_client, plans, on_row, workers.count)
    elif workers.threads > 1:
        yield lambda plans, on_row: run_threads(plans, workers.threads, on_row)
    elif workers.count > 1:
        yield lambda plans, on_row: run_pool(plans, workers.count, on_row)
    else:
        yield run_serial


def run_serial(plans: list[RunPlan], on_row: OnRow) -> None:
    """Each run in this process, in order (runs that can share one compiled call: in groups of
    one call, :mod:`.compiled_runs`). A run the loop reports ``interrupted`` stops the batch (its
    row is not kept: the run did not finish)."""
    if compiled_runs.can_run(plans):
        with ONE_BLAS_THREAD:
            return compiled_runs.run_in_groups(plans, 1, on_row)
    for plan in plans:
        row = run_one(plan)
        if row["status"] == "interrupted":
            raise KeyboardInterrupt
        on_row(row)


def run_threads(plans: list[RunPlan], threads: int, on_row: OnRow) -> None:
    """The runs on ``threads`` threads of this process. On ``KeyboardInterrupt`` (only the main
    thread gets one) or any error of ``on_row``, the runs not started are cancelled, the running
    ones asked to stop (:func:`~freefloat.dynamics.stop_request.stopping`: each stops within one
    chunk of its loop) and waited for, a second Ctrl-C included; on an interrupt, those that
    finished are given, the interrupted ones are not rows (as in :func:`run_serial`)."""
    with ONE_BLAS_THREAD:  # set and restored by this thread: see freefloat.dynamics.threads
        if compiled_runs.can_run(plans):  # on C++ threads, in groups of one call (.compiled_runs)
            return compiled_runs.run_in_groups(plans, threads, on_row)
        _run_threads(plans, threads, on_row)


def _run_threads(plans: list[RunPlan], threads: int, on_row: OnRow) -> None:
    """:func:`run_threads` inside the BLAS limit."""
    pool = ThreadPoolExecutor(threads, thread_name_prefix="freefloat-run")
    pending: dict[Future, RunPlan] = {pool.submit(run_one, plan): plan for plan in plans}
    try:
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                _give(pending.pop(future), future, on_row)
    except BaseException as exc:
        with stop_request.stopping():
            for future in pending:
                future.cancel()
            while not all(future.done() for future in pending):
                with contextlib.suppress(KeyboardInterrupt):  # a second Ctrl-C: they are stopping
                    wait(pending)
        if isinstance(exc, KeyboardInterrupt):
            for future, plan in pending.items():
                if not future.cancelled():
                    _give(plan, future, on_row)
        raise
    finally:
        pool.shutdown(wait=True)


def _give(plan: RunPlan, future: Future, on_row: OnRow) -> None:
    """``on_row`` of a finished ``future``'s row (a failed row if it raised), unless its run was
    interrupted."""
    exc = future.exception()
    row = future.result() if exc is None else failed_row(plan, f"{type(exc).__name__}: {exc}")
    if row["status"] != "interrupted":
        on_row(row)


def run_pool(plans: list[RunPlan], workers: int, on_row: OnRow) -> None:
    """The runs on a pool of ``workers`` processes (:func:`freefloat.distributed.process_pool`), in
    tasks of several runs (:func:`run_group`). Workers ignore Ctrl-C; this process stops them. A
    worker that dies (killed, crashed) fails the runs it leaves, each recorded with the reason."""
    groups = task_groups(plans, workers)
    pool = process_pool(workers)
    try:
        pending: dict[Future, list[RunPlan]] = {pool.submit(run_group, group): group for group in groups}
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                group = pending.pop(future)
                exc = future.exception()
                for row in future.result() if exc is None else [failed_row(p, f"worker process lost: {exc}")
                                                                 for p in group]:
                    on_row(row)
    except BaseException:
        terminate(pool)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def run_dask(dask_client, plans: list[RunPlan], on_row: OnRow, workers: int = 1) -> None:
    """The runs as tasks of several runs each (:func:`run_group`) on ``dask_client``'s workers (a
    local cluster's or a scheduler's; ``workers``: how many, for the tasks' size)."""
    groups = task_groups(plans, workers)
    futures = {i: dask_client.submit(run_group, group, pure=False) for i, group in enumerate(groups)}

    def finished(i: int, result: object) -> None:
        for row in result if isinstance(result, list) else [failed_row(p, f"{type(result).__name__}: {result}")
                                                             for p in groups[i]]:
            on_row(row)

    settled = settle_futures(futures, "batch", True, DASK_TIMEOUT, finished)
    for i, group in enumerate(groups):
        if i not in settled:
            for plan in group:
                on_row(failed_row(plan, f"no Dask worker finished a run within {DASK_TIMEOUT:g} s"))


#: Tasks per worker a pool or Dask batch aims at (more tasks balance the load; fewer share more
#: runs in one compiled call).
TASKS_PER_WORKER = 4


def task_groups(plans: list[RunPlan], workers: int) -> list[list[RunPlan]]:
    """``plans`` in consecutive tasks of at most :data:`~.compiled_runs.GROUP_PER_THREAD` runs,
    at least :data:`TASKS_PER_WORKER` tasks per worker when there are runs enough."""
    size = max(1, min(compiled_runs.GROUP_PER_THREAD, len(plans) // (TASKS_PER_WORKER * workers)))
    return [plans[i:i + size] for i in range(0, len(plans), size)]


def run_group(plans: list[RunPlan]) -> list[dict[str, Any]]:
    """The rows of ``plans`` run in a worker: in one compiled call when they can share one
    (:mod:`.compiled_runs`), one by one otherwise."""
    rows: list[dict[str, Any]] = []
    if compiled_runs.can_run(plans):
        with ONE_BLAS_THREAD:
            compiled_runs.run_in_groups(plans, 1, rows.append)
        return rows
    return [run_one(plan) for plan in plans]


def failed_row(plan: RunPlan, message: str) -> dict[str, Any]:
    """The row of a run that never returned one."""
    return {"run": plan.index, "seed": plan.seed, "status": "failed", "message": message, **plan.varied}
