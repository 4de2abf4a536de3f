"""What Ctrl-C (SIGINT), SIGTERM and SIGHUP do while freefloat works: standard library only, so
the command line can take them over before it imports anything heavy.

- While starting (imports, loading the robot) they are deferred (:func:`signals_deferred`): a
  library that catches ``BaseException`` around its imports (trimesh) cannot swallow them, and
  the command stops cleanly once started.
- While a run goes, the first one stops it (``KeyboardInterrupt`` where it arrives, which the
  loop turns into an interrupted run that keeps its samples) and every later one is only
  counted (:func:`stop_once`), so a second Ctrl-C cannot cut the writing of what the first kept.
"""

from __future__ import annotations

import contextlib
import importlib
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from types import ModuleType

#: Signals that stop a run as Ctrl-C (SIGINT) does.
STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))
#: Ctrl-C and the stop signals.
ALL_SIGNALS = (signal.SIGINT, *STOP_SIGNALS)


_BEFORE_MAIN = threading.Event()


def defer_until_main() -> None:
    """For the program's first lines: Ctrl-C, SIGTERM and SIGHUP only set a flag until
    :func:`arrived_before_main` is called."""
    for signum in ALL_SIGNALS:
        signal.signal(signum, _before_main)


def _before_main(signum: int, frame: object) -> None:
    _BEFORE_MAIN.set()


def arrived_before_main() -> bool:
    """Give the signals back their usual handlers if :func:`defer_until_main` took them; whether
    one arrived meanwhile."""
    if threading.current_thread() is threading.main_thread():
        for signum in ALL_SIGNALS:
            if signal.getsignal(signum) is _before_main:
                signal.signal(signum, signal.default_int_handler if signum == signal.SIGINT else signal.SIG_DFL)
    return _BEFORE_MAIN.is_set()


class Interrupts:
    """The interrupts received inside :func:`stop_once`: the first raises ``KeyboardInterrupt``,
    the later ones are counted (and, once :meth:`defer` is called, all are)."""

    def __init__(self) -> None:
        self.count = 0
        self.raising = True

    def defer(self) -> int:
        """From now on only count interrupts; returns the count so far."""
        self.raising = False
        return self.count

    def __call__(self, signum: int, frame: object) -> None:
        self.count += 1
        if self.raising and self.count == 1:
            raise KeyboardInterrupt(signal.Signals(signum).name)
        if self.count == 2:
            sys.stderr.write("\nfreefloat: stopping; writing what was computed (the drawings are skipped)\n")


@contextlib.contextmanager
def stop_once() -> Iterator[Interrupts]:
    """Inside the block, the first of Ctrl-C, SIGTERM, SIGHUP raises ``KeyboardInterrupt``; the
    later ones only count (see :class:`Interrupts`)."""
    received = Interrupts()
    with handling(received, ALL_SIGNALS):
        yield received


@contextlib.contextmanager
def signals_raise_keyboard_interrupt() -> Iterator[None]:
    """SIGTERM and SIGHUP raise ``KeyboardInterrupt`` inside the block, as Ctrl-C does."""

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt(signal.Signals(signum).name)

    with handling(interrupt, STOP_SIGNALS):
        yield


@contextlib.contextmanager
def signals_deferred() -> Iterator[threading.Event]:
    """Ctrl-C, SIGTERM and SIGHUP set the yielded event inside the block instead of stopping
    the process there."""
    received = threading.Event()
    with handling(lambda signum, frame: received.set(), ALL_SIGNALS):
        yield received


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """Ctrl-C, SIGTERM and SIGHUP wait until the block ends (a file or a figure being written is
    finished: matplotlib left half-way through a drawing fails on the next one), then raise
    ``KeyboardInterrupt`` carrying the first one's name."""
    arrived: list[int] = []
    with handling(lambda signum, frame: arrived.append(signum), ALL_SIGNALS):
        yield
    if arrived:
        raise KeyboardInterrupt(signal.Signals(arrived[0]).name)


def imported_whole(name: str) -> ModuleType:
    """``import name`` with Ctrl-C, SIGTERM and SIGHUP held until it is done (see
    :func:`signals_held`): a compiled extension whose initialisation a ``KeyboardInterrupt`` cuts
    fails with ``ImportError: initialization failed`` instead (mujoco does) and stays unusable."""
    with signals_held():
        return importlib.import_module(name)


def cut_by_interrupt(exc: BaseException) -> KeyboardInterrupt | None:
    """The ``KeyboardInterrupt`` among ``exc``'s causes, if any: an import an interrupt cut short
    raises ``ImportError`` from it."""
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, KeyboardInterrupt):
            return cause
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return None


@contextlib.contextmanager
def handling(handler: Callable[[int, object], None], signums: tuple[int, ...]) -> Iterator[None]:
    """``handler`` for ``signums`` inside the block (main thread only; elsewhere a no-op)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {signum: signal.signal(signum, handler) for signum in signums}
    try:
        yield
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old)
