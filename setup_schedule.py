"""The build's schedule (used by setup.py, which cannot import the package): compile jobs run on a
few threads, each started only while the memory of the jobs running beside it stays within a
budget; and the compile's progress, a line per unit started and finished, written where the user
sees it as it goes."""

import os
import sys
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from typing import TextIO, TypeVar

Job = TypeVar("Job")

GB = 1e9
CLEAR_LINE, UP = "\r\x1b[2K", "\x1b[1A"  # ANSI: to the line's start and clear it; one line up


def run_within(jobs: Iterable[Job], work: Callable[[Job], object], memory: Callable[[Job], float], workers: int,
               budget: float, started: Callable[[Job, float], None] | None = None) -> None:
    """``work(job)`` for every job on up to ``workers`` threads. The first job in order whose
    ``memory(job)`` (bytes) fits in ``budget`` beside the running ones starts next; a job that
    never fits runs alone. ``started(job, in_use)``, if given, is called as each job starts, with
    the memory of the jobs then running, its own included (bytes). Raises the first error once the
    running jobs have ended; no job starts after an error."""
    pending, running = list(jobs), {}
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        while pending or running:
            used = sum(running.values())
            fits = [job for job in pending if not running or used + memory(job) <= budget]
            if fits and len(running) < workers:
                job = fits[0]
                pending.remove(job)
                if started is not None:
                    started(job, used + memory(job))
                running[pool.submit(work, job)] = memory(job)
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


def terminal(device: str = "/dev/tty") -> TextIO:
    """Where the build's progress goes: the user's terminal (``device``, line-buffered) when the
    build has one, since pip and uv keep a build backend's stdout and stderr to themselves unless
    asked to be verbose; else stderr, which they show with ``-v`` and on a failure."""
    try:
        return open(device, "w", buffering=1)
    except OSError:
        return sys.stderr


class Progress:
    """The compile's progress as it goes, one line per event written to ``out`` at once: each unit
    started (with the peak memory it was scheduled with and the memory in use with it, against the
    budget), each unit finished (``[3/10] cpp/sim/loop.cpp 14.2 s``, its wall time), and the
    total. Safe to call from the compile threads."""

    def __init__(self, out: TextIO, budget: float, workers: int) -> None:
        self.out, self.budget, self.workers = out, budget, workers
        self.lock = threading.Lock()
        self.total = self.finished = self.lines = 0
        self.begin = time.perf_counter()

    def say(self, line: str) -> None:
        with self.lock:
            self.out.write(self.on_terminal(line) if self.out.isatty() else line + "\n")
            self.out.flush()
            self.lines += 1

    def on_terminal(self, line: str) -> str:
        """``line`` as written to a terminal the installer also draws on. pip's spinner writes a
        character at the cursor, on the line below the last one written here: that line is cleared
        first (the first line starts on a line of its own). uv (which sets ``UV`` for a build)
        redraws its two lines of progress from the line above the cursor: its two lines are
        cleared first, and an empty line is left below for the next redraw."""
        if self.lines == 0:
            before = "\r\n"
        else:
            before = CLEAR_LINE + (UP + CLEAR_LINE if os.environ.get("UV") else "")
        return before + line + "\r\n" + ("\r\n" if os.environ.get("UV") else "")

    def plan(self, units: int, up_to_date: int) -> None:
        """``units`` to compile, ``up_to_date`` more already compiled (reused); the clock starts."""
        self.total, self.begin = units, time.perf_counter()
        if units == 0:
            self.say(f"freefloat: {up_to_date} C++ units up to date, nothing to compile")
            return
        kept = f" ({up_to_date} more up to date)" if up_to_date else ""
        self.say(f"freefloat: compiling {units} C++ units{kept}, up to {self.workers} at a time within "
                 f"{self.budget / GB:.2f} GB of memory")

    def started(self, unit: str, peak: float, in_use: float) -> None:
        """``unit`` starts; ``peak`` its measured compile peak, ``in_use`` with the running units (bytes)."""
        self.say(f"        {unit} started (peak {peak / GB:.2f} GB; {in_use / GB:.2f} of {self.budget / GB:.2f} GB "
                 "in use)")

    def ended(self, unit: str, seconds: float, failed: bool = False) -> None:
        """``unit`` compiled (or ``failed``) in ``seconds`` of wall time."""
        with self.lock:
            self.finished += not failed
            count = "failed" if failed else f"[{self.finished}/{self.total}]"
        self.say(f"{count:<8}{unit} {seconds:.1f} s")

    def linked(self, modules: int, seconds: float) -> None:
        """``modules`` linked in ``seconds``: the end of the build, with its wall time since :meth:`plan`."""
        self.say(f"freefloat: {self.finished} C++ units compiled, {modules} modules linked in {seconds:.1f} s; "
                 f"{time.perf_counter() - self.begin:.1f} s in all")
