"""Quintic references and exact computed torque."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings

from freefloat import load_robot
from freefloat.dynamics.models import make_model
from freefloat.lab.reproduce.states import state_with_momentum
from freefloat.space.control import ComputedTorque, QuinticTrajectory, joint_space_dynamics
from freefloat.space.control.detumbling_control import DetumblingController
from freefloat.space.control.inverse_egjm import InverseEGJM
from freefloat.space.control.task_space import TaskSpaceComputedTorque
from freefloat.space.detumbling import task_rows

from .conftest import REPO, random_robots, random_state, robot_from_case


def test_quintic_hits_its_ends_at_rest():
    """q(0) = start, q(T) = goal, zero velocity and acceleration at both ends."""
    traj = QuinticTrajectory(np.array([0.0, 1.0]), np.array([0.5, -1.0]), 5.0)
    for t, pos in ((0.0, [0.0, 1.0]), (5.0, [0.5, -1.0]), (7.0, [0.5, -1.0])):
        q, qd, qdd = traj(t)
        np.testing.assert_allclose(q, pos, atol=1e-15)
        np.testing.assert_allclose(np.concatenate((qd, qdd)), 0.0, atol=1e-15)


def test_quintic_derivatives_match_finite_differences():
    """Velocity and acceleration are the central differences of position and velocity."""
    traj = QuinticTrajectory(np.zeros(3), np.array([1.0, -2.0, 0.3]), 2.0)
    h = 1e-6
    for t in (0.3, 1.0, 1.7):
        np.testing.assert_allclose(traj(t)[1], (traj(t + h)[0] - traj(t - h)[0]) / (2 * h), atol=1e-8)
        np.testing.assert_allclose(traj(t)[2], (traj(t + h)[1] - traj(t - h)[1]) / (2 * h), atol=1e-7)


@settings(max_examples=25, deadline=None)
@given(random_robots())
def test_computed_torque_imposes_the_servo_acceleration(tmp_path_factory, case):
    """Under the controller's torques, ABA's joint accelerations equal qdd_d + Kp e + Kd edot."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    traj = QuinticTrajectory(rng.normal(size=robot.n_joints), rng.normal(size=robot.n_joints), 3.0)
    ctrl = ComputedTorque(robot, traj, kp=10.0, kd=100.0)
    tau = np.concatenate((np.zeros(robot.n_base), ctrl.torque(1.2, q, v)))
    a = pin.aba(robot.model, robot.model.createData(), q, v, tau)
    q_d, qd_d, qdd_d = traj(1.2)
    expected = qdd_d + 10.0 * (q_d - q[7:]) + 100.0 * (qd_d - v[6:])
    np.testing.assert_allclose(a[6:], expected, rtol=1e-8, atol=1e-8 * np.abs(expected).max())


@settings(max_examples=25, deadline=None)
@given(random_robots())
def test_generalized_inertia_is_symmetric_positive_definite(tmp_path_factory, case):
    """H* (the Schur complement of the base block) is symmetric positive definite."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    H, _ = joint_space_dynamics(robot, robot.model.createData(), q, v)
    np.testing.assert_allclose(H, H.T, atol=1e-10 * np.abs(H).max())
    assert np.linalg.eigvalsh(H).min() > 0.0


def nidc_controllers(robot, q):
    """The three computed-torque controllers, each on the ``nidc`` model (name -> controller)."""
    n, rows = robot.n_joints, task_rows(robot, [("arm1_ee", "wz")])
    theta = q[7:]
    return {
        "joint_space": ComputedTorque(robot, QuinticTrajectory(theta, theta + 0.1, 5.0), 10.0, 100.0, "nidc"),
        "task_space": TaskSpaceComputedTorque(robot, InverseEGJM(rows), lambda t: np.zeros(1), theta, 0.01,
                                              model="nidc"),
        "detumbling": DetumblingController(robot, rows, np.arange(n), 0.0, 0.01, model="nidc"),
    }


@pytest.mark.parametrize("name", ["joint_space", "task_space", "detumbling"])
def test_controllers_advance_the_nidc_integral_once_per_period(name):
    """Two periods of a controller on ``nidc`` leave D = dt dxdot0/dq at the first state (eq 67),
    as a model advanced by hand does."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    q, v = state_with_momentum(robot, np.random.default_rng(11))
    controller = nidc_controllers(robot, q)[name]
    controller.torque(0.0, q, v)
    controller.torque(0.01, q, v)
    by_hand = make_model("nidc", robot)
    by_hand.end_period(q, v, 0.01)
    assert np.abs(by_hand.D).max() > 1e-6
    np.testing.assert_allclose(controller.dynamics.model.D, by_hand.D, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("start, goal, duration, message", [
    ([0.0], [np.nan], 1.0, "'goal' must be finite"), ([0.0], [1.0], 0.0, "'duration' must be > 0"),
    ([0.0], [1.0], None, "'duration' must be a real number"), ([0.0], [1.0, 2.0], 1.0, "'goal' must have shape"),
    ([0.0], [1.0], 1e-300, "accelerations overflow"),
])
def test_a_quintic_refuses_what_it_cannot_follow(start, goal, duration, message):
    """A NaN goal, a duration that is not > 0 or so short that its accelerations overflow, and
    mismatched ends are refused naming them (NaN goals were accepted, None raised a TypeError)."""
    from freefloat import InvalidArgument

    with pytest.raises(InvalidArgument, match=message):
        QuinticTrajectory(np.array(start), np.array(goal), duration)
