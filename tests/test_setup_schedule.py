"""The build's schedule (setup_schedule.py): compile jobs within a memory budget."""

import importlib.util
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
