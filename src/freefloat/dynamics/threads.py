"""One BLAS thread around the loops that multiply small matrices, and process-wide settings that
several threads of one process enter and leave at their own times (:class:`Shared`).

OpenBLAS's worker threads cost more than they save on matrices of a few dozen rows: with the
default two threads, ``gjm.compute`` at 72 joints ran 6-13 times slower than with one, and the
spinning threads slowed ``pin.aba`` in the same process twofold (docs/gjm.md). It wraps whole
loops (a simulation run), never single evaluations. Parallel runs use processes (``freefloat.app``
runs, dask) or threads of this process (``freefloat batch --threads``: the compiled loop releases
the GIL), all of them under the one limit.

The limit is process-wide (threadpoolctl sets it in the BLAS library), so it is :class:`Shared`:
the first thread to enter sets it and the last to leave restores what the first found; a thread
leaving early never lifts it under another one still running. OpenBLAS (0.3.31 here) ignores, in
some orders, a raise of its thread count made from a thread other than the main one (a batch on
2 threads left BLAS at one thread when its last run's thread restored two), so an executor of
threads enters the limit in its own thread first and leaves it last
(:func:`freefloat.app.batch.executors.run_threads`).

Finding the BLAS libraries (threadpoolctl scans every loaded library) cost 0.75 to 7 ms, each
time; the controller that found them is kept and scanned again only when modules were imported
since (a new BLAS comes with an import): entering the limit then costs about 20 us.
"""

from __future__ import annotations

import functools
import sys
import threading
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any, TypeVar

from threadpoolctl import ThreadpoolController

F = TypeVar("F", bound=Callable)

_found: list = [None, -1]  # [the controller, len(sys.modules) when it scanned]


class Shared:
    """A process-wide setting entered by several threads, each in its own time: a context
    manager whose first entrant (of all threads, nested or not) enters ``make()`` and whose last
    leaver exits it, the count and the setting changed under one lock. Re-entrant."""

    def __init__(self, make: Callable[[], AbstractContextManager[Any]]):
        self._make = make
        self._lock = threading.Lock()
        self._holders = 0
        self._held: AbstractContextManager[Any] | None = None

    @property
    def holders(self) -> int:
        """How many entries (over all threads) have not left yet."""
        return self._holders

    def __enter__(self) -> None:
        with self._lock:
            if self._holders == 0:
                held = self._make()
                held.__enter__()
                self._held = held
            self._holders += 1

    def __exit__(self, *exc: object) -> None:
        with self._lock:
            self._holders -= 1
            if self._holders == 0:
                held, self._held = self._held, None
                assert held is not None
                held.__exit__(None, None, None)


def _controller() -> ThreadpoolController:
    """threadpoolctl's view of the loaded thread pools, scanned again after new imports."""
    if _found[1] != len(sys.modules):
        _found[:] = [ThreadpoolController(), len(sys.modules)]
    return _found[0]


#: BLAS limited to one thread while any thread of this process is inside.
ONE_BLAS_THREAD = Shared(lambda: _controller().limit(limits=1, user_api="blas"))


def single_blas_thread(fn: F) -> F:
    """Decorator: run ``fn`` inside :data:`ONE_BLAS_THREAD` (the previous limit restored when the
    last thread inside leaves)."""

    @functools.wraps(fn)
    def limited(*args, **kwargs):
        with ONE_BLAS_THREAD:
            return fn(*args, **kwargs)

    return limited  # type: ignore[return-value]

