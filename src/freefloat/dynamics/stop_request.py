"""A process-wide request to stop the runs in progress, for runs on threads other than the main one.

Ctrl-C and SIGTERM reach only the main thread; a run on another thread (``freefloat batch
--threads``) is told through this flag instead. The simulation loops look at it between chunks
(compiled loop) or control periods (Python loop) and stop there as they do on Ctrl-C (status
``"interrupted"``); a run that starts while it is set stops before its first period. Whoever sets
it (:func:`stopping`) waits for the runs and clears it.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator

_REQUEST = threading.Event()


def check() -> None:
    """Raise ``KeyboardInterrupt`` (what a loop does on Ctrl-C) when a stop is requested."""
    if _REQUEST.is_set():
        raise KeyboardInterrupt


@contextlib.contextmanager
def stopping() -> Iterator[None]:
    """Within the block, every run of this process stops at its next check (the block waits for
    them); on leaving, runs go on again."""
    _REQUEST.set()
    try:
        yield
    finally:
        _REQUEST.clear()
