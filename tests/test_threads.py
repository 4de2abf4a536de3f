"""BLAS limited to one thread around the hot loops (freefloat.dynamics.threads)."""

from __future__ import annotations

import numpy as np
from threadpoolctl import threadpool_info

from freefloat import load_robot
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import make_model
from freefloat.dynamics.simulation import run
from freefloat.dynamics.threads import single_blas_thread

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
