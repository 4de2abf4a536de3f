"""Where the runs of a batch run: one after another in this process, in a pool of worker
processes, or on Dask workers (a local cluster or a scheduler's). The dynamics hold the GIL, so
the parallel ones use processes.

:func:`executor` gives ``execute(plans, on_row)``, which calls ``on_row(row)`` as each run
finishes, in the order they finish, and returns nothing; a ``KeyboardInterrupt`` (Ctrl-C, or
SIGTERM turned into one by the caller) stops the work at once (pool workers are terminated,
Dask's pending tasks cancelled) and propagates, after every row already finished was given.
"""

from __future__ import annotations

import contextlib
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from typing import Any, Callable, Iterator

from ...distributed import client, process_pool, settle_futures
from ...errors import FreefloatError
from .one_run import run_one
from .variations import RunPlan

OnRow = Callable[[dict[str, Any]], None]
Execute = Callable[[list[RunPlan], OnRow], None]

#: With Dask, the batch ends when no run finishes within this many seconds (every worker lost);
#: the runs left are recorded as failed.
DASK_TIMEOUT = 600.0


@dataclass(frozen=True)
class Workers:
    """Where the runs go: ``count`` processes (1 and not ``dask``: this process, one after
    another), through Dask when ``dask`` (a local cluster of ``count``, or ``scheduler``'s).

    Raises:
        FreefloatError: naming ``--workers`` below 1, or ``--scheduler`` without ``--dask``.
    """

    count: int = 1
    dask: bool = False
    scheduler: str | None = None

    def __post_init__(self) -> None:
        if self.count < 1:
            raise FreefloatError(f"--workers must be >= 1, got {self.count}")
        if self.scheduler is not None and not self.dask:
            raise FreefloatError("--scheduler is a Dask scheduler's address; it needs --dask")

    @property
    def label(self) -> str:
        """``serial``, ``pool of K`` or ``dask ...``, for reports."""
        if self.dask:
            return f"dask scheduler {self.scheduler}" if self.scheduler else f"dask local cluster of {self.count}"
        return "serial" if self.count == 1 else f"pool of {self.count}"


@contextlib.contextmanager
def executor(workers: Workers) -> Iterator[Execute]:
    """``execute(plans, on_row)`` on ``workers``; a Dask client is connected (or its local
    cluster started) on entering, and closed on leaving.

    Raises:
        FreefloatError: on entering, naming ``--scheduler`` when nothing answers there.
    """
    if workers.dask:
        with client(workers.scheduler, workers.count) as dask_client:
            yield lambda plans, on_row: run_dask(dask_client, plans, on_row)
    elif workers.count > 1:
        yield lambda plans, on_row: run_pool(plans, workers.count, on_row)
    else:
        yield run_serial


def run_serial(plans: list[RunPlan], on_row: OnRow) -> None:
    """Each run in this process, in order. A run the loop reports ``interrupted`` stops the
    batch (its row is not kept: the run did not finish)."""
    for plan in plans:
        row = run_one(plan)
        if row["status"] == "interrupted":
            raise KeyboardInterrupt
        on_row(row)


def run_pool(plans: list[RunPlan], workers: int, on_row: OnRow) -> None:
    """The runs on a pool of ``workers`` processes (:func:`freefloat.distributed.process_pool`). Workers ignore
    Ctrl-C; this process stops them. A worker that dies (killed, crashed) fails the runs it
    leaves, each recorded with the reason."""
    pool = process_pool(workers)
    try:
        pending: dict[Future, RunPlan] = {pool.submit(run_one, plan): plan for plan in plans}
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                plan = pending.pop(future)
                exc = future.exception()
                on_row(future.result() if exc is None else failed_row(plan, f"worker process lost: {exc}"))
    except BaseException:
        _terminate(pool)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def run_dask(dask_client, plans: list[RunPlan], on_row: OnRow) -> None:
    """The runs as tasks of ``dask_client`` (a local cluster's or a scheduler's workers)."""
    futures = {i: dask_client.submit(run_one, plan, pure=False) for i, plan in enumerate(plans)}

    def finished(i: int, result: object) -> None:
        on_row(result if isinstance(result, dict) else failed_row(plans[i], f"{type(result).__name__}: {result}"))

    settled = settle_futures(futures, "batch", True, DASK_TIMEOUT, finished)
    for i, plan in enumerate(plans):
        if i not in settled:
            on_row(failed_row(plan, f"no Dask worker finished a run within {DASK_TIMEOUT:g} s"))


def failed_row(plan: RunPlan, message: str) -> dict[str, Any]:
    """The row of a run that never returned one."""
    return {"run": plan.index, "seed": plan.seed, "status": "failed", "message": message, **plan.varied}


def _terminate(pool: ProcessPoolExecutor) -> None:
    """Stop ``pool`` now: pending runs cancelled, running ones killed (Python 3.14's
    ``terminate_workers``; before it, the executor's own process table)."""
    pool.shutdown(wait=False, cancel_futures=True)
    terminate = getattr(pool, "terminate_workers", None)
    if terminate is not None:
        terminate()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.terminate()
