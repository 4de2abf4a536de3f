"""One BLAS thread around the loops that multiply small matrices.

OpenBLAS's worker threads cost more than they save on matrices of a few dozen rows: with the
default two threads, ``gjm.compute`` at 72 joints ran 6-13 times slower than with one, and the
spinning threads slowed ``pin.aba`` in the same process twofold (docs/gjm.md). It wraps whole
loops (a simulation run), never single evaluations. Parallel work uses processes instead
(``freefloat.app`` runs, dask).

Finding the BLAS libraries (threadpoolctl scans every loaded library) cost 0.75 to 7 ms, each
time; the controller that found them is kept and scanned again only when modules were imported
since (a new BLAS comes with an import): entering the limit then costs about 20 us.
"""

from __future__ import annotations

import functools
import sys
from collections.abc import Callable
from typing import TypeVar

from threadpoolctl import ThreadpoolController

F = TypeVar("F", bound=Callable)

_found: list = [None, -1]  # [the controller, len(sys.modules) when it scanned]


def _controller() -> ThreadpoolController:
    """threadpoolctl's view of the loaded thread pools, scanned again after new imports."""
    if _found[1] != len(sys.modules):
        _found[:] = [ThreadpoolController(), len(sys.modules)]
    return _found[0]


def single_blas_thread(fn: F) -> F:
    """Decorator: run ``fn`` with BLAS limited to one thread, restoring the previous limit after."""

    @functools.wraps(fn)
    def limited(*args, **kwargs):
        with _controller().limit(limits=1, user_api="blas"):
            return fn(*args, **kwargs)

    return limited  # type: ignore[return-value]
