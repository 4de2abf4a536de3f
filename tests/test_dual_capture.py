"""Two hands grasp one target at once (freefloat.space.dual_capture)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.closures import closing_impulse, kinematics, stacked
from freefloat.robot.conventions import momentum_about_origin
from freefloat.space.capture import robot_momentum
from freefloat.space.dual_capture import attach_with_loop, grasp_welds, robot_and_target, two_hand_impact

from .conftest import box_in_both_hands

HANDS = ("left_tool0", "right_tool0")


@pytest.fixture(scope="module")
def contact():
    """The dual-arm satellite at a random posture with both hands on a spinning, drifting box, and
    random robot velocities: (robot, body, q, v, q_t, v_t)."""
    robot, body, q, q_t, rng = box_in_both_hands(11)
    return robot, body, q, rng.normal(size=robot.model.nv) * 0.3, q_t, np.array([0.05, -0.05, 0.02, 0.0, 0.0, 0.2])


def test_second_grasp_meets_the_second_hand(contact):
    """The second grasp point computed for the posture lies on the second hand when the first lies on the first."""
    robot, body, q, _, q_t, _ = contact
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    for k, hand in enumerate(HANDS):
        assert np.linalg.norm(body.grasp_point(q_t, k) - data.oMf[robot.model.getFrameId(hand)].translation) < 1e-12


def test_both_welds_close_together_and_momentum_is_kept(contact):
    """After the impact neither hand moves relative to the box (12 rows) and robot + box momentum is
    unchanged to 1e-12 (relative)."""
    robot, body, q, v, q_t, v_t = contact
    hit = two_hand_impact(robot, HANDS, q, v, body, q_t, v_t)
    model = robot_and_target(robot, body)
    data = model.createData()
    q_all, v_all = np.concatenate((q, q_t)), np.concatenate((hit.v_robot, hit.v_target))
    pin.forwardKinematics(model, data, q_all)
    welds = grasp_welds(model, data, HANDS)
    kinematics(model, data, q_all, v_all)
    J = stacked(welds, model, data, drift=False)[1]
    scale = np.abs(hit.momentum_before).max()
    assert np.abs(J @ v_all).max() < 1e-12 * max(1.0, np.abs(v).max())
    assert np.abs(hit.momentum_after - hit.momentum_before).max() < 1e-12 * scale


def test_one_weld_after_the_other_is_not_the_simultaneous_grasp(contact):
    """Closing the welds one after the other reopens the first (its relative velocity is no longer
    zero after the second impulse); the simultaneous impulse leaves both closed."""
    robot, body, q, v, q_t, v_t = contact
    model = robot_and_target(robot, body)
    data = model.createData()
    q_all, v_all = np.concatenate((q, q_t)), np.concatenate((v, v_t))
    pin.forwardKinematics(model, data, q_all)
    first, second = grasp_welds(model, data, HANDS)
    after_second = closing_impulse(model, data, q_all, closing_impulse(model, data, q_all, v_all, [first]).v_after,
                                   [second]).v_after
    kinematics(model, data, q_all, after_second)
    assert np.abs(stacked([first], model, data, drift=False)[1] @ after_second).max() > 1e-3


def test_the_merged_robot_carries_the_momentum_of_robot_and_box(contact):
    """The merged robot (box on the first hand, second weld a loop closure) at v+ has the momentum of
    robot + box before the impact (to 1e-12), and its loop closure holds at v+."""
    robot, body, q, v, q_t, v_t = contact
    hit = two_hand_impact(robot, HANDS, q, v, body, q_t, v_t)
    merged, closure = attach_with_loop(robot, HANDS, q, body, q_t)
    data = merged.model.createData()
    kinematics(merged.model, data, q, hit.v_robot)
    e, J, _ = stacked([closure], merged.model, data, drift=False)
    before = robot_momentum(robot, q, v) + momentum_about_origin(body.model, body.data, q_t, v_t)
    assert np.abs(robot_momentum(merged, q, hit.v_robot) - before).max() < 1e-12 * np.abs(before).max()
    assert np.abs(e).max() < 1e-12 and np.abs(J @ hit.v_robot).max() < 1e-11
