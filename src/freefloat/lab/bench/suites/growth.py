"""What the size sweeps (``gjm``, ``models``) share: their clock, and the growth with robot size,
the exponent ``p`` of ``time ~ nv^p``, the least-squares slope of log time against log nv over
the generated robots (spatial arms around one base, nv = 6 + 4 arms)."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import numpy as np

#: What times every row: this process's CPU time, which other processes on the shared machine do
#: not inflate (the wall clock of a loaded machine moved these figures by 2-5x between runs).
CLOCK = time.process_time


def exponent(sizes: Sequence[float], times: Sequence[float]) -> float:
    """Slope of ``log(times)`` against ``log(sizes)`` (least squares), at least two sizes."""
    return float(np.polyfit(np.log(sizes), np.log(times), 1)[0])


def exponents(rows: Sequence[dict], keys: Sequence[str], time: Callable[[dict, str], float]) -> dict[str, float]:
    """``{key: exponent}`` over ``rows`` (each with ``n_joints``; nv = n_joints + 6), ``time(row,
    key)`` the time of ``key`` in a row."""
    sizes = [row["n_joints"] + 6 for row in rows]
    return {key: exponent(sizes, [time(row, key) for row in rows]) for key in keys}
