"""The command line's progress bar of a loop, timed as the summary times it.

The bar starts when the loop reports its start (``progress(0)``: the moment its wall time starts)
and stops at its last report, so that the time and rate it ends on are the loop's, the ones the
summary prints (``completed: 5000 steps in 0.48 s``), not those of the set-up before the loop or
of the summary and files after it (each of those has its own timed line).
"""

from __future__ import annotations

import time
from collections.abc import Callable


class LoopBar:
    """A tqdm bar over a loop's reports, made at the first one and closed at the last.

    Args:
        total: the count the loop reports up to (None: given by the reports).
        desc, unit: the bar's label and unit.
        quiet: show nothing.
        started: called at the first report (the command is past its checks).
        ended: called when the count reaches ``total`` (the loop has ended).
    """

    #: Seconds before a bar shows (a short loop shows none).
    DELAY = 0.5

    def __init__(self, total: int | None, desc: str, unit: str, quiet: bool = False,
                 started: Callable[[], None] = lambda: None, ended: Callable[[], None] = lambda: None) -> None:
        self.total, self.desc, self.unit, self.quiet = total, desc, unit, quiet
        self.started, self.ended = started, ended
        from tqdm import tqdm  # imported here, not in the loop's time

        self.tqdm = tqdm
        self.bar = None
        self.last = 0.0
        self.closed = False

    def __call__(self, done: int, total: int | None = None) -> None:
        """A report: ``done`` of ``total`` (default: the bar's)."""
        if self.closed:
            return
        self.last = time.time()  # tqdm's clock
        if self.bar is None:
            self.started()
            self.bar = self.tqdm(total=total or self.total, initial=done, desc=self.desc, unit=self.unit,
                                 disable=self.quiet, delay=self.DELAY)
            if not self.bar.disable:
                self.bar.start_t = self.bar.last_print_t = self.last  # the loop's start, not the bar's making
        self.bar.update(done - self.bar.n)
        if self.bar.total and done >= self.bar.total:
            self.close()
            self.ended()

    def close(self) -> None:
        """End the bar at its last report (its time stops there, whenever this is called)."""
        if self.bar is not None and not self.closed:
            if not self.bar.disable:  # the bar's clock moved on by the time since the last report (not the loop's)
                shift = time.time() - self.last
                self.bar.start_t += shift
                self.bar.last_print_t += shift
            self.bar.close()
        self.closed = True
