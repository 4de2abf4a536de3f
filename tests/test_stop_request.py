"""A stop request stops runs on other threads between chunks or periods
(freefloat.dynamics.stop_request)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from freefloat import load_robot
from freefloat.dynamics import stop_request
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import make_model
from freefloat.dynamics.simulation import run

from .conftest import REPO


@pytest.mark.parametrize("backend", ["compiled", "python"])
def test_a_run_on_another_thread_stops_as_interrupted_when_asked(backend):
    """A 100 s torque-free run on a thread: once it reported progress, a stop request ends it
    within a chunk with status "interrupted" and the rows it computed; the next run goes on."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    v0 = np.zeros(robot.model.nv)
    v0[3:6] = [0.1, -0.2, 0.3]
    started, results = threading.Event(), []

    def tumble(duration: float) -> None:
        results.append(run(robot, robot.neutral(), v0, duration, 1e-3, make_integrator("rkmk4", robot.model),
                           make_model("exact", robot), record_every=100, progress=lambda k: k and started.set(),
                           backend=backend))

    worker = threading.Thread(target=tumble, args=(100.0,))
    worker.start()
    assert started.wait(60)
    with stop_request.stopping():
        worker.join(60)
    assert not worker.is_alive()
    stopped = results[0]
    assert stopped.status == "interrupted" and 0 < stopped.steps < 100_000
    tumble(0.01)
    assert results[1].status == "completed"


def test_a_run_started_while_a_stop_is_requested_stops_before_its_first_period():
    """A run entered while the request holds computes nothing: status "interrupted", 0 periods."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    with stop_request.stopping():
        result = run(robot, robot.neutral(), np.zeros(robot.model.nv), 0.01, 1e-3,
                     make_integrator("rkmk4", robot.model), make_model("exact", robot))
    assert result.status == "interrupted" and result.steps == 0
