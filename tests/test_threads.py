"""BLAS limited to one thread around the hot loops, and settings shared by threads
(freefloat.dynamics.threads)."""

from __future__ import annotations

import contextlib
import threading

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from freefloat import load_robot
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import make_model
from freefloat.dynamics.simulation import run
from freefloat.dynamics.threads import ONE_BLAS_THREAD, Shared, single_blas_thread

from .conftest import REPO


def blas_threads() -> list[int]:
    """Threads of every loaded BLAS library."""
    return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]


def test_decorated_function_runs_on_one_blas_thread_and_the_limit_is_restored():
    """Inside a decorated function every BLAS has one thread; after it, the previous counts return."""
    before = blas_threads()
    inside = single_blas_thread(blas_threads)()
    assert inside and set(inside) == {1}
    assert blas_threads() == before


def test_simulation_evaluates_the_model_on_one_blas_thread():
    """simulation.run calls the dynamics model with BLAS limited to one thread."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    exact, seen = make_model("exact", robot), []

    class Recording:
        name = "recording"

        def acceleration(self, q, v, tau, fext=None):
            seen.extend(blas_threads())
            return exact.acceleration(q, v, tau, fext)

        def joint_space_at(self, q, v):
            return exact.joint_space_at(q, v)

    run(robot, robot.neutral(), np.zeros(robot.model.nv), 0.002, 0.001, make_integrator("rkmk4", robot.model), Recording())
    assert seen and set(seen) == {1}


def in_turns(first_in, second_in, first_out, second_out) -> None:
    """Thread A does ``first_in``, thread B ``second_in``, A ``first_out``, B ``second_out``, in
    that order (each a callable run on its own thread)."""
    steps = [threading.Event() for _ in range(4)]

    def thread(mine: tuple[int, int], calls) -> None:
        for k, call in zip(mine, calls):
            if k:
                assert steps[k - 1].wait(10)
            call()
            steps[k].set()

    a = threading.Thread(target=thread, args=((0, 2), (first_in, first_out)))
    b = threading.Thread(target=thread, args=((1, 3), (second_in, second_out)))
    a.start(), b.start()
    a.join(20), b.join(20)
    assert all(step.is_set() for step in steps)


def test_a_shared_setting_is_entered_by_the_first_thread_in_and_left_by_the_last_out():
    """Thread A enters, B enters, A leaves, B leaves: the setting is entered once (at A's entry)
    and left once (at B's exit), with its holder count in between."""
    log: list[str] = []

    @contextlib.contextmanager
    def setting():
        log.append("enter")
        yield
        log.append("exit")

    shared = Shared(setting)
    in_turns(shared.__enter__, lambda: (shared.__enter__(), log.append(f"held {shared.holders}")),
             lambda: (shared.__exit__(None, None, None), log.append(f"held {shared.holders}")),
             lambda: shared.__exit__(None, None, None))
    assert log == ["enter", "held 2", "held 1", "exit"] and shared.holders == 0


def with_a_thread(main_steps, thread_steps) -> None:
    """Alternate steps: main ``main_steps[0]``, thread ``thread_steps[0]``, main ``main_steps[1]``,
    ... (each a callable; the thread's on a new thread)."""
    turns = [threading.Event() for _ in range(len(thread_steps))]
    done = [threading.Event() for _ in range(len(thread_steps))]

    def thread() -> None:
        for turn, finished, step in zip(turns, done, thread_steps):
            assert turn.wait(10)
            step()
            finished.set()

    worker = threading.Thread(target=thread)
    worker.start()
    for k, step in enumerate(main_steps):
        step()
        if k < len(thread_steps):
            turns[k].set()
            assert done[k].wait(10)
    worker.join(10)


def test_overlapping_threads_keep_one_blas_thread_until_the_last_leaves():
    """The limit is set by the first thread in and restored by the last out, whichever threads
    they are: a thread in, the main thread in, the thread out: the main thread still runs on one
    BLAS thread, and once it is out the old count is back; the main thread in, a thread in, the
    main thread out: the thread still runs on one (a threadpoolctl limit per thread restored the
    old count under the other)."""
    before = blas_threads()
    if max(before, default=1) < 2:
        pytest.skip("BLAS runs one thread already here: the limit cannot be told apart")
    enter, leave = ONE_BLAS_THREAD.__enter__, lambda: ONE_BLAS_THREAD.__exit__(None, None, None)
    seen: dict[str, list[int]] = {}
    with_a_thread([lambda: None, enter, lambda: seen.setdefault("main", blas_threads()), leave],
                  [enter, leave, lambda: None])
    assert set(seen["main"]) == {1} and blas_threads() == before
    try:
        with_a_thread([enter, leave], [enter, lambda: (seen.setdefault("thread", blas_threads()), leave())])
        assert set(seen["thread"]) == {1}
    finally:  # OpenBLAS may ignore the raise made from the thread (dynamics/threads.py); put it back
        threadpool_limits(limits=max(before), user_api="blas")
