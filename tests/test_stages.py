"""The RKMK stage loop: stage states in the chart at their own times, and a known first acceleration reused."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from freefloat.dynamics.integrators.stages import chart_velocity, rkmk_stages

from .conftest import torque_free

ROWS = (np.array([]), np.array([0.5]), np.array([0.0, 0.5]), np.array([0.0, 0.0, 1.0]))  # classical RK4
NODES = (0.0, 0.5, 0.5, 1.0)


def test_stages_sit_at_q_exp_theta_with_dexpinv_velocities():
    """Stage i is evaluated at q * exp(theta_i) at t0 + c_i h, and K[i] is dexp^-1_{-theta_i} of its velocity."""
    robot, f, q0, v0 = torque_free("free", seed=5, speed=1.0)
    seen = []

    def recording(t, q, v):
        seen.append((t, q.copy(), v.copy()))
        return f(q, v)

    t0, h, dexpinv = 0.3, 0.01, chart_velocity(robot.model)
    K, Acc = rkmk_stages(recording, robot.model, dexpinv, q0, v0, t0, h, ROWS, NODES)
    assert [t for t, _, _ in seen] == [t0 + c * h for c in NODES]  # each stage at its own time
    for i, row in enumerate(ROWS[1:], start=1):
        theta, vel = h * (row @ K[:i]), v0 + h * (row @ Acc[:i])
        np.testing.assert_allclose(seen[i][1], pin.integrate(robot.model, q0, theta), atol=1e-15)
        np.testing.assert_allclose(seen[i][2], vel, atol=1e-15)
        np.testing.assert_allclose(K[i], dexpinv(theta, vel), atol=1e-15)
    assert np.linalg.norm(K[3] - seen[3][2]) > 1e-8  # the free-flyer's correction is not the identity


def test_a_known_first_acceleration_costs_no_call():
    """Given f(q, v) as a0, a 4-stage tableau calls f three times and keeps a0 as the first stage."""
    robot, f, q0, v0 = torque_free("planar", seed=5, speed=1.0)
    calls = []

    def counting(t, q, v):
        calls.append(1)
        return f(q, v)

    a0 = f(q0, v0)
    _, Acc = rkmk_stages(counting, robot.model, chart_velocity(robot.model), q0, v0, 0.0, 0.01, ROWS, NODES, a0)
    assert len(calls) == 3
    np.testing.assert_array_equal(Acc[0], a0)
