"""After a grasp: the identification manoeuvre (computed torque on a Fourier trajectory) and
detumbling on a believed model, each one run of the engine on the true merged robot."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics.identification.excitation import random_trajectory
from freefloat.errors import BadShape
from freefloat.robot.joints import JointCoordinates
from freefloat.space.after_capture import detumble, manoeuvre
from freefloat.space.capture import Target, grasp
from freefloat.space.control.excitation import ExcitationTracking

HAND = "arm1_ee"


@pytest.fixture(scope="module")
def held():
    """The two-arm planar robot (free base) holding a 20 kg box spinning at 0.5 rad/s."""
    robot = load_robot("two_arm_planar", base="free", visuals=False)
    q0 = robot.neutral()
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q0)
    hand = data.oMf[robot.model.getFrameId(HAND)].translation
    target = Target.meeting(hand, 0.2, 20.0, (1.0, 1.5, 2.0), (-0.3, 0.0, 0.0), (-0.05, 0.0, 0.0), (0.0, 0.0, 0.5))
    return robot, grasp(robot, target, HAND, approach_time=0.3, q0=q0)


def test_manoeuvre_on_the_true_model_tracks_and_keeps_the_momentum(held):
    """With the merged robot as the believed model, arm 1's joints follow the series (within
    1e-3 rad once the start from rest has decayed, after 0.5 s), arm 2's hold, and the merged robot's
    momentum stays constant (no external wrench: 1e-9 relative)."""
    robot, g = held
    trajectory = random_trajectory(np.zeros(4), 3, 2.0, 0.2, 0.5, np.random.default_rng(0))
    arm1 = [name for name in robot.joint_names if name.startswith("arm1")]
    run = manoeuvre(g.merged, g.merged, g.q, g.v, trajectory, arm1, 1.0, kp=400.0, kd=40.0)
    tel = run.telemetry
    joints = np.array([JointCoordinates(robot).get(q) for q in tel.q])
    reference = joints[0, :4] + trajectory(tel.t)[0] - trajectory(0.0)[0]
    assert np.abs(joints[500:, :4] - reference[500:]).max() < 1e-3
    assert np.abs(joints[500:, 4:] - joints[0, 4:]).max() < 1e-3
    momentum = tel.momentum
    assert np.abs(momentum - momentum[0]).max() < 1e-9 * np.abs(momentum[0]).max()


def test_detumbling_on_the_true_model_stops_the_target(held):
    """Eq 134 on the true merged robot brings the target's spin from 0.5 rad/s below 1e-6 rad/s,
    with the momentum kept."""
    _, g = held
    result = detumble(g.merged, g.merged, g.q, g.v, [(HAND, "angular")], 1.0, 1e-6)
    assert result.target_speed[0] > 0.1 and result.settling_time is not None and result.final_speed < 1e-6
    assert result.momentum_drift < 1e-9 * max(1.0, np.abs(result.result.telemetry.momentum[0]).max())


def test_a_series_for_other_joints_is_refused(held):
    """A series of 3 coordinates for 4 moved joints."""
    robot, _ = held
    with pytest.raises(BadShape, match="3 coordinates for 4"):
        ExcitationTracking(robot, random_trajectory(np.zeros(3), 2, 1.0, 0.1, 0.1, np.random.default_rng(1)),
                           np.arange(4), 100.0, 20.0)
