"""Work spread over processes: a pool's workers do not outlive the process that made them,
ignore Ctrl-C, and survive one that arrives as they are launched."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

#: A process that makes a pool of one worker, prints the worker's id, then waits to be killed.
_PARENT = """
import os, sys, time
from freefloat.distributed import process_pool
if __name__ == "__main__":
    pool = process_pool(1)
    print(pool.submit(os.getpid).result(), flush=True)
    time.sleep(600)
"""


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie waiting to be reaped does not)."""
    try:
        return "State:\tZ" not in Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False


def test_a_pool_worker_ends_when_its_parent_is_killed(tmp_path):
    """SIGKILL to the process that made a pool ends its workers within seconds (they waited on
    their queue for ever, holding the parent's output pipes open)."""
    script = tmp_path / "parent.py"
    script.write_text(_PARENT)
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    worker = int(parent.stdout.readline())
    assert worker != parent.pid and _alive(worker)
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait(timeout=30)
    deadline = time.monotonic() + 20
    while _alive(worker) and time.monotonic() < deadline:
        time.sleep(0.1)
    survived = _alive(worker)
    if survived:
        os.kill(worker, signal.SIGKILL)
    assert not survived, f"worker {worker} outlived its killed parent"


def test_ctrl_c_while_a_worker_is_launched_waits_for_the_launch():
    """Ctrl-C arriving as the pool launches a worker stops the caller once the launch is done,
    and the worker starts and works (the launch was cut and the worker printed 'EOFError: Ran
    out of input')."""
    from freefloat.distributed import process_pool

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    pool = process_pool(1)
    launch = pool._spawn_process

    def interrupted_launch():
        os.kill(os.getpid(), signal.SIGINT)  # held until the launch is done
        launch()

    pool._spawn_process = interrupted_launch
    try:
        try:
            pool.submit(os.getpid)
            raise AssertionError("Ctrl-C was lost")
        except KeyboardInterrupt:
            pass
        assert len(pool._processes) == 1
        assert pool.submit(os.getpid).result(timeout=60) in pool._processes
    finally:
        signal.signal(signal.SIGINT, previous)
        pool.shutdown()


@pytest.mark.slow
def test_a_worker_ignores_ctrl_c_and_an_interrupted_block_cancels_what_waits():
    """A worker ignores Ctrl-C (a terminal sends it to the whole group; the caller decides), and
    leaving the pool's block by an exception cancels the calls not started instead of running
    them all first."""
    from freefloat.distributed import process_pool

    started = time.monotonic()
    try:
        with process_pool(1) as pool:
            worker = pool.submit(os.getpid).result(timeout=60)
            os.kill(worker, signal.SIGINT)
            assert pool.submit(os.getpid).result(timeout=60) == worker
            waiting = [pool.submit(time.sleep, 1.0) for _ in range(20)]
            raise RuntimeError("stop")
    except RuntimeError:
        pass
    assert time.monotonic() - started < 10.0 and sum(f.cancelled() for f in waiting) >= 15  # a few already queued


def test_terminate_kills_a_running_call_and_cancels_the_rest():
    """terminate(pool) ends a worker in the middle of a long call within seconds, and the calls
    waiting end too, cancelled or failed (shutdown alone would wait for every call to finish)."""
    from freefloat.distributed import process_pool, terminate

    pool = process_pool(1)
    worker = pool.submit(os.getpid).result(timeout=60)
    running = pool.submit(time.sleep, 600)
    waiting = [pool.submit(time.sleep, 600) for _ in range(3)]
    while not running.running():
        time.sleep(0.01)
    terminate(pool)
    deadline = time.monotonic() + 20
    while _alive(worker) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _alive(worker)
    assert running.exception(timeout=20) is not None
    assert all(f.cancelled() or f.exception(timeout=20) is not None for f in waiting)
