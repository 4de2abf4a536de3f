"""Timing side by side: the functions compared take turns within each repeat, so that load from
other processes on a shared machine falls on all of them alike."""

from __future__ import annotations

import math
import time
from typing import Callable


def side_by_side(fns: dict[str, tuple[Callable[[], object], int]], repeats: int) -> dict[str, float]:
    """Best-of-``repeats`` mean time per call, s, of each ``name: (fn, calls)``, the functions
    taking turns within each repeat."""
    best = dict.fromkeys(fns, math.inf)
    for _ in range(repeats):
        for name, (fn, calls) in fns.items():
            start = time.perf_counter()
            for _ in range(calls):
                fn()
            best[name] = min(best[name], (time.perf_counter() - start) / calls)
    return best


def per_call(fn: Callable[[], object], calls: int, repeats: int) -> float:
    """Best-of-``repeats`` mean time of ``fn()`` over ``calls`` calls, s."""
    return side_by_side({"": (fn, calls)}, repeats)[""]
