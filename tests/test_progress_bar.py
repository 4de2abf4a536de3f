"""The command line's progress bar of a loop: timed as the loop's wall time is, from its first
report to its last."""

from __future__ import annotations

import io
import re
import time

import pytest

from freefloat.app.progress_bar import LoopBar


def _bar(**options) -> tuple[LoopBar, io.StringIO]:
    shown = io.StringIO()
    bar = LoopBar(100, "loop", "step", **options)
    bar.tqdm = lambda *a, **k: __import__("tqdm").tqdm(*a, **k, file=shown)
    return bar, shown


def test_the_bar_times_the_loop_only():
    """Set-up before the first report and work after the last are not in the bar's time: its
    last line's rate is the count over the loop's time."""
    bar, shown = _bar()
    bar.DELAY = 0.0
    time.sleep(0.3)  # set-up: the bar does not exist yet
    start = time.perf_counter()
    for done in range(0, 101, 20):
        bar(done)
        time.sleep(0.05)
    loop = time.perf_counter() - start - 0.05  # the loop ended at its last report
    time.sleep(0.3)  # the summary and files after the loop
    bar.close()
    rate = float(re.findall(r"100/100 \[[\d:]+<[\d:]+, +([\d.]+)step/s\]", shown.getvalue())[-1])
    assert 100 / rate == pytest.approx(loop, rel=0.2)


def test_the_bar_closes_at_its_total_and_says_so():
    """The last report of the count closes the bar (it stayed open through the writing and reached
    100 % twice) and calls ``ended``; later reports and closes draw nothing."""
    ended = []
    bar, shown = _bar(ended=lambda: ended.append(True))
    bar.DELAY = 0.0
    for done in (0, 50, 100):
        bar(done)
    assert bar.closed and ended == [True]
    drawn = shown.getvalue()
    bar(100)
    bar.close()
    assert shown.getvalue() == drawn and drawn.count("100/100") >= 1


def test_the_first_report_starts_the_command_s_run():
    """``started`` is called once, at the first report (the command is past its checks)."""
    started = []
    bar, _ = _bar(started=lambda: started.append(True), quiet=True)
    assert started == []
    bar(0)
    bar(10)
    assert started == [True]
