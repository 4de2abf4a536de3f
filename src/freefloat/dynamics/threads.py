"""One BLAS thread around the loops that multiply small matrices.

OpenBLAS's worker threads cost more than they save on matrices of a few dozen rows: with the
default two threads, ``gjm.compute`` at 72 joints ran 6-13 times slower than with one, and the
spinning threads slowed ``pin.aba`` in the same process twofold (docs/gjm.md). Entering the limit
costs about 0.4 ms, so it wraps whole loops (a simulation run), never single evaluations.
Parallel work uses processes instead (``freefloat.app`` runs, dask).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import TypeVar

from threadpoolctl import threadpool_limits

F = TypeVar("F", bound=Callable)


def single_blas_thread(fn: F) -> F:
    """Decorator: run ``fn`` with BLAS limited to one thread, restoring the previous limit after."""

    @functools.wraps(fn)
    def limited(*args, **kwargs):
        with threadpool_limits(limits=1, user_api="blas"):
            return fn(*args, **kwargs)

    return limited  # type: ignore[return-value]
