"""dopri5's dense output on the group and its first-same-as-last stage."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.integrators import DormandPrince45

from .conftest import torque_free


@pytest.fixture(scope="module", params=["free", "planar"])
def tumbling(request):
    """A torque-free SC_3DoF tumbling on the given base: robot, f, q0, v0."""
    return torque_free(request.param, seed=0, speed=2.0)


def state_error(model: pin.Model, q: np.ndarray, v: np.ndarray, q_ref: np.ndarray, v_ref: np.ndarray) -> float:
    return float(np.linalg.norm(np.concatenate((pin.difference(model, q_ref, q), v - v_ref))))


def test_dense_output_is_accurate_between_steps(tumbling):
    """At rtol 1e-8, 401 samples from the dense output stay within 1e-6 of a tight reference."""
    robot, f, q0, v0 = tumbling
    times = np.linspace(0.0, 1.0, 401)
    solver = DormandPrince45(robot.model, rtol=1e-8, atol=1e-10)
    Q, V = solver.solve(f, q0, v0, times)
    assert solver.accepted < 200  # most samples fall inside steps
    Q_ref, V_ref = DormandPrince45(robot.model, rtol=1e-13, atol=1e-14).solve(f, q0, v0, times)
    assert max(state_error(robot.model, *x) for x in zip(Q, V, Q_ref, V_ref)) < 1e-6


def test_dense_output_costs_no_extra_evaluations(tumbling):
    """Sampling 401 times costs the same evaluations as one advance over the run."""
    robot, f, q0, v0 = tumbling
    sampled, plain = DormandPrince45(robot.model, rtol=1e-8), DormandPrince45(robot.model, rtol=1e-8)
    sampled.solve(f, q0, v0, np.linspace(0.0, 1.0, 401))
    plain.advance(f, q0, v0, 1.0)
    assert sampled.evaluations() == plain.evaluations()


def test_dense_output_has_local_order_five_inside_a_step(tumbling):
    """Within one step the midpoint error of the continuous extension falls ~32x when h halves."""
    robot, f, q0, v0 = tumbling
    errors = []
    for h in (0.04, 0.02):
        loose = DormandPrince45(robot.model, rtol=1e3, atol=1e3)  # one accepted step of length h
        Q, V = loose.solve(f, q0, v0, np.array([0.5 * h, h]))
        assert loose.accepted == 1
        q_ref, v_ref = DormandPrince45(robot.model, rtol=1e-13, atol=1e-14).advance(f, q0, v0, 0.5 * h)
        errors.append(state_error(robot.model, Q[0], V[0], q_ref, v_ref))
    assert 20.0 < errors[0] / errors[1] < 45.0


def test_last_stage_is_reused_as_the_next_first(tumbling):
    """An accepted step after the first costs six evaluations, not seven."""
    robot, f, q0, v0 = tumbling
    solver = DormandPrince45(robot.model, rtol=1e-8)
    solver.advance(f, q0, v0, 1.0)
    assert solver.evaluations() == 7 + 6 * (solver.accepted + solver.rejected - 1)


def test_solve_rejects_decreasing_times(tumbling):
    """Output times that go backwards are refused with a message naming them."""
    robot, f, q0, v0 = tumbling
    with pytest.raises(ValueError, match="increasing"):
        DormandPrince45(robot.model).solve(f, q0, v0, np.array([0.0, 0.2, 0.1]))
