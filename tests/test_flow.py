"""First-order systems stepped by the engine's integrators: the order on SE(3), the stage times,
the integrators that have no first-order form."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import InvalidArgument
from freefloat.dynamics.flow import rollout, stage_times


@pytest.fixture(scope="module")
def body():
    """One free-flying body (SE(3)) and a velocity field on it that depends on time and attitude
    (so that the chart's dexp^-1 matters)."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "body")

    def velocity(t, q):
        R = pin.Quaternion(q[6], *q[3:6]).toRotationMatrix()
        w = np.array([np.sin(3 * t), np.cos(2 * t), 0.5]) + 0.8 * R.T @ np.array([0.0, 0.0, 1.0])
        return np.concatenate((R.T @ np.array([1.0, t, 0.0]), w))

    return model, velocity


@pytest.mark.parametrize("name, order", [("euler", 1), ("rk4_naive", 2), ("rkmk3", 3), ("rkmk4", 4), ("rkmk6", 6)])
def test_a_first_order_system_converges_at_the_integrators_order(body, name, order):
    """Halving the step divides the end error by 2^order on SE(3) (against RKMK8 at a 10x finer
    grid): the RKMK tableaus keep their order, the uncorrected RK4 is second order."""
    model, velocity = body
    q0 = pin.neutral(model)
    reference = rollout(velocity, model, q0, np.linspace(0.0, 2.0, 801), "rkmk8")[0][-1]
    errors = [np.linalg.norm(pin.difference(model, reference, rollout(velocity, model, q0, np.linspace(0.0, 2.0, n + 1),
                                                                      name)[0][-1])) for n in (20, 40)]
    assert errors[0] / errors[1] == pytest.approx(2.0**order, rel=0.12)


def test_the_velocity_is_asked_only_at_the_stage_times(body):
    """Every time the roll-out asks the velocity for is in stage_times (a caller may tabulate a
    plan's rates there), four calls an RKMK4 step (the first stage is the last step's end), and
    the returned velocities are the field's at the grid."""
    model, velocity = body
    times = np.linspace(0.0, 1.3, 14)
    asked = []
    qs, vs = rollout(lambda t, q: asked.append(t) or velocity(t, q), model, pin.neutral(model), times)
    assert set(asked) <= set(stage_times(times).tolist()) and len(asked) == 4 * (len(times) - 1) + 1
    np.testing.assert_array_equal(vs[5], velocity(times[5], qs[5]))


def test_an_adaptive_integrator_is_refused_naming_those_that_work(body):
    """dopri5 has no first-order form: the error names it and the fixed-step ones."""
    model, velocity = body
    with pytest.raises(InvalidArgument, match="'dopri5' steps no first-order system .*rkmk4"):
        rollout(velocity, model, pin.neutral(model), np.linspace(0.0, 1.0, 3), "dopri5")
