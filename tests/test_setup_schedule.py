"""The build's schedule (setup_schedule.py): compile jobs within a memory budget, and the progress
it reports."""

import importlib.util
import io
import re
import sys
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("setup_schedule", ROOT / "setup_schedule.py")
setup_schedule = importlib.util.module_from_spec(spec)
spec.loader.exec_module(setup_schedule)


class Recorder:
    """Runs jobs (name, memory) and records the memory in use whenever one starts, and the order."""

    def __init__(self, memory: dict[str, float], hold: float = 0.02) -> None:
        self.memory, self.hold = memory, hold
        self.lock = threading.Lock()
        self.in_use, self.peaks, self.started = 0.0, [], []

    def work(self, job: str) -> None:
        with self.lock:
            self.in_use += self.memory[job]
            self.peaks.append(self.in_use)
            self.started.append(job)
        time.sleep(self.hold)
        with self.lock:
            self.in_use -= self.memory[job]

    def run(self, jobs: list[str], workers: int, budget: float) -> None:
        setup_schedule.run_within(jobs, self.work, self.memory.__getitem__, workers, budget)


def test_jobs_running_together_stay_within_the_budget():
    memory = {"big": 1.9, "chains": 0.9, "core": 0.8, "bindings": 0.9, "solver": 0.7, "small": 0.3}
    recorder = Recorder(memory)
    recorder.run(list(memory), workers=2, budget=2.0)
    assert sorted(recorder.started) == sorted(memory)
    assert max(recorder.peaks) <= 2.0


def test_a_job_larger_than_the_budget_runs_alone():
    memory = {"huge": 3.0, "a": 0.5, "b": 0.5}
    recorder = Recorder(memory)
    recorder.run(["a", "huge", "b"], workers=2, budget=2.0)
    assert max(recorder.peaks) == 3.0
    assert sorted(recorder.started) == ["a", "b", "huge"]


def test_jobs_that_fit_run_at_once():
    barrier = threading.Barrier(2, timeout=5)  # passes only when both jobs wait on it at the same time
    arrivals = []

    def work(job: str) -> None:
        try:
            arrivals.append(barrier.wait())  # 0 and 1: the order the two jobs arrived in
        except threading.BrokenBarrierError:
            arrivals.append("alone")

    setup_schedule.run_within(["a", "b"], work, lambda job: 1.0, workers=2, budget=2.0)
    assert sorted(arrivals, key=str) == [0, 1]


def test_jobs_start_in_order_when_one_fits_at_a_time():
    memory = {name: 1.5 for name in "abcd"}
    recorder = Recorder(memory, hold=0.0)
    recorder.run(list("abcd"), workers=2, budget=2.0)
    assert recorder.started == list("abcd")


def test_an_error_is_raised_and_no_job_starts_after_it():
    started = []

    def work(job: str) -> None:
        started.append(job)
        if job == "bad":
            raise RuntimeError("compile error in bad")

    with pytest.raises(RuntimeError, match="compile error in bad"):
        setup_schedule.run_within(["bad", "next", "last"], work, lambda job: 1.5, workers=2, budget=2.0)
    assert started == ["bad"]


def test_the_budget_is_a_share_per_compiler_within_the_memory_available():
    budget = setup_schedule.memory_budget
    assert budget(2, 64e9, 1e9, 0.8, None) == 2e9  # 2 cores, plenty of memory: 1 GB each
    assert budget(8, 64e9, 1e9, 0.8, None) == 8e9  # more cores, more compilers at once
    assert budget(2, 2e9, 1e9, 0.8, None) == 1.6e9  # little memory: its share
    assert budget(2, 64e9, 1e9, 0.8, 5e9) == 5e9  # FREEFLOAT_BUILD_MEMORY
    assert budget(2, 3e9, 1e9, 0.8, 5e9) == 3e9  # never more than is available


def test_each_job_is_announced_as_it_starts_with_the_memory_then_in_use():
    """started(job, in_use) comes as each job starts, in_use counting the running jobs and its own."""
    memory = {"a": 1.2, "b": 0.7, "c": 0.5}
    announced = []
    recorder = Recorder(memory)
    setup_schedule.run_within(list(memory), recorder.work, memory.__getitem__, 2, 2.0,
                              lambda job, in_use: announced.append((job, in_use)))
    assert [job for job, _ in announced] == recorder.started
    assert announced[:2] == [("a", 1.2), ("b", pytest.approx(1.9))]
    assert all(memory[job] <= in_use <= 2.0 for job, in_use in announced)


def test_progress_counts_the_units_finished_with_their_times_then_the_total():
    """Progress writes a line per unit started (peak, memory in use, budget) and finished
    ([k/n], seconds), a failure as such, and the linking with the build's total."""
    out = io.StringIO()
    progress = setup_schedule.Progress(out, 2e9, 2)
    progress.plan(2, 1)
    progress.started("cpp/sim/loop.cpp", 1.24e9, 1.93e9)
    progress.ended("cpp/sim/loop.cpp", 14.23)
    progress.ended("cpp/gjm/gjm.cpp", 3.0, failed=True)
    progress.linked(2, 1.5)
    lines = out.getvalue().splitlines()
    assert lines[:4] == ["freefloat: compiling 2 C++ units (1 more up to date), up to 2 at a time within 2.00 GB of memory",
                         "        cpp/sim/loop.cpp started (peak 1.24 GB; 1.93 of 2.00 GB in use)",
                         "[1/2]   cpp/sim/loop.cpp 14.2 s",
                         "failed  cpp/gjm/gjm.cpp 3.0 s"]
    assert re.fullmatch(r"freefloat: 1 C\+\+ units compiled, 2 modules linked in 1\.5 s; \d+\.\d s in all", lines[4])


def test_nothing_to_compile_is_said_so():
    """With every object up to date the plan says so in one line."""
    out = io.StringIO()
    setup_schedule.Progress(out, 2e9, 2).plan(0, 14)
    assert out.getvalue() == "freefloat: 14 C++ units up to date, nothing to compile\n"


def test_progress_goes_to_the_terminal_when_there_is_one_else_to_stderr(tmp_path):
    """terminal() opens the device it is given (the user's /dev/tty), line-buffered, and falls back
    to stderr when there is none (a CI log: pip and uv show it with -v)."""
    device = tmp_path / "tty"
    with setup_schedule.terminal(str(device)) as out:
        out.write("[1/2] cpp/a.cpp 1.0 s\n")
        assert device.read_text() == "[1/2] cpp/a.cpp 1.0 s\n"  # written at the line's end, not at close
    assert setup_schedule.terminal(str(tmp_path / "no" / "tty")) is sys.stderr


class Terminal(io.StringIO):
    """A terminal's stream: what is written, and isatty() true."""

    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("under_uv", [False, True], ids=["pip", "uv"])
def test_on_a_terminal_each_line_clears_what_the_installer_drew_there(monkeypatch, under_uv):
    """On a terminal the first line starts on a line of its own (after pip's or uv's last line), each
    next one clears the spinner pip left at the cursor, or under uv its two redrawn lines above
    the empty line left for them."""
    if under_uv:
        monkeypatch.setenv("UV", "/usr/bin/uv")
    else:
        monkeypatch.delenv("UV", raising=False)
    out = Terminal()
    progress = setup_schedule.Progress(out, 2e9, 2)
    progress.plan(1, 0)
    progress.ended("cpp/a.cpp", 1.0)
    clear, up, after = "\r\x1b[2K", "\x1b[1A", "\r\n\r\n" if under_uv else "\r\n"
    plan = "freefloat: compiling 1 C++ units, up to 2 at a time within 2.00 GB of memory"
    assert out.getvalue() == ("\r\n" + plan + after + (clear + up + clear if under_uv else clear)
                              + "[1/1]   cpp/a.cpp 1.0 s" + after)
