"""Timing side by side: the functions compared take turns within each repeat, so that load from
other processes on a shared machine falls on all of them alike. The clock is the wall clock
(``time.perf_counter``) unless a suite passes another, e.g. ``time.process_time`` (this process's
CPU time, which other processes on a loaded machine do not inflate)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable


def side_by_side(fns: dict[str, tuple[Callable[[], object], int]], repeats: int,
                 clock: Callable[[], float] = time.perf_counter) -> dict[str, float]:
    """Best-of-``repeats`` mean time per call, s, of each ``name: (fn, calls)``, the functions
    taking turns within each repeat, timed by ``clock``."""
    best = dict.fromkeys(fns, math.inf)
    for _ in range(repeats):
        for name, (fn, calls) in fns.items():
            start = clock()
            for _ in range(calls):
                fn()
            best[name] = min(best[name], (clock() - start) / calls)
    return best


def per_call(fn: Callable[[], object], calls: int, repeats: int,
             clock: Callable[[], float] = time.perf_counter) -> float:
    """Best-of-``repeats`` mean time of ``fn()`` over ``calls`` calls, s, timed by ``clock``."""
    return side_by_side({"": (fn, calls)}, repeats, clock)[""]
