"""A toy bench suite for tests/test_bench_suites.py: the three functions a suite module provides,
measuring nothing. Registered as ``toy`` by the tests, it must run with no other edit."""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Iterator
from pathlib import Path

#: Parts measured, in order; the one named by ``INTERRUPT_AT`` (set by a test) sends SIGTERM to
#: this process before it is yielded.
PARTS = ("first", "second")
INTERRUPT_AT: str | None = None
#: The parts the last chart was drawn from.
DRAWN: list[str] = []


def settings(quick: bool, repeats: int | None) -> dict:
    """The command's two settings as the toy reads them."""
    return {"quick": quick, "repeats": repeats or 3}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part per name of :data:`PARTS`: two times and their ratio."""
    for name in PARTS:
        if name == INTERRUPT_AT:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5.0)  # the signal's KeyboardInterrupt lands here
        yield name, {"a_s": 2.0, "b_s": 0.5, "a_over_b": 4.0}


def chart(report: dict, path: Path) -> None:
    """A stand-in chart (a small blank PNG), drawn from the parts in :data:`DRAWN`."""
    from freefloat.app.bench.suites.drawing import save, subplots

    DRAWN[:] = [key for key in PARTS if key in report]
    fig, _ = subplots(1, 1, (3.0, 2.0))
    save(fig, path)
