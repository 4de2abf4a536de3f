"""The build's schedule (used by setup.py, which cannot import the package): compile jobs run on a
few threads, each started only while the memory of the jobs running beside it stays within a
budget."""

from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from typing import TypeVar

Job = TypeVar("Job")


def run_within(jobs: Iterable[Job], work: Callable[[Job], object], memory: Callable[[Job], float], workers: int,
               budget: float) -> None:
    """``work(job)`` for every job on up to ``workers`` threads. The first job in order whose
    ``memory(job)`` (bytes) fits in ``budget`` beside the running ones starts next; a job that
    never fits runs alone. Raises the first error once the running jobs have ended; no job starts
    after an error."""
    pending, running = list(jobs), {}
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        while pending or running:
            used = sum(running.values())
            fits = [job for job in pending if not running or used + memory(job) <= budget]
            if fits and len(running) < workers:
                pending.remove(fits[0])
                running[pool.submit(work, fits[0])] = memory(fits[0])
                continue
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in done:
                del running[future]
                future.result()  # the pool ends the running jobs before the error leaves it


def memory_budget(workers: int, available: float, per_job: float, share: float, requested: float | None) -> float:
    """Bytes the compilers running at once may take together: ``requested`` if given, else
    ``per_job`` per compiler process within ``share`` of the memory ``available``; never more
    than ``available``."""
    return min(requested or min(per_job * workers, share * available), available)
