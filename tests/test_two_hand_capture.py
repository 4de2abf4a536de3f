"""The two-hand capture experiment (freefloat.app.experiments.two_hand_capture)."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.app import runner
from freefloat.errors import SceneError

from .conftest import quiet_scene

SCENE = "capture_two_hands_satellite"


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """The built-in scene with 0.3 s of detumbling."""
    return runner.simulate(quiet_scene(tmp_path_factory.mktemp("s"), SCENE, simulation={"duration": 0.3}))


def test_the_grasp_keeps_the_momentum_of_robot_and_box(short_run):
    """The merged robot just after the grasp has robot + box momentum before it, to 1e-12 relative."""
    s = short_run.summary
    assert s["momentum_balance_error"] < 1e-12 * np.abs(s["momentum_before_impact"]).max()


def test_the_loop_stays_closed_and_carries_the_chosen_squeeze(short_run):
    """The closure drifts under 1e-7 m, the internal wrench is the scene's 20 N squeeze (1e-6), and
    no torque exceeds the 150 N m limit."""
    s = short_run.summary
    assert s["closure_drift_max"] < 1e-7 and s["squeeze_max"] == pytest.approx(20.0, abs=1e-6)
    assert s["internal_force_max"] == pytest.approx(20.0, abs=1e-6)
    assert s["peak_joint_torque"] <= 150.0 * (1 + 1e-12)


def test_the_box_stops_turning(short_run):
    """The rate gain kd = 20/s makes the box's spin decay as exp(-kd t): after 0.3 s it is under
    5e-3 of its spin just after the grasp (exp(-6) = 2.5e-3)."""
    s = short_run.summary
    assert s["target_angular_velocity_final"] < 5e-3 * s["target_angular_velocity_at_impact"]


def test_a_second_grasp_off_the_second_hand_is_refused_with_the_right_one(tmp_path):
    """A second grasp point 10 cm off where the second hand is at contact: the error names the key,
    the miss, and the point that would close both contacts together."""
    scene = quiet_scene(tmp_path, SCENE, target={"second_grasp": [-0.25, -0.2, 0.0]})
    with pytest.raises(SceneError, match=r"'target.second_grasp' \[-0.25, -0.2, 0.0\] is 0.1 m from 'right_tool0'.*"
                                         r"second_grasp = \[-0.25, -0.3, 0.0\]"):
        runner.prepare(scene)


@pytest.mark.parametrize("hand", ["left_tool0", "no_hand"])
def test_a_second_hand_that_is_not_another_end_effector_is_refused(tmp_path, hand):
    """The second hand must be an end-effector other than the first; the error lists the others,
    the nearest first."""
    scene = quiet_scene(tmp_path, SCENE, target={"second_end_effector": hand})
    with pytest.raises(SceneError, match=r"'target.second_end_effector' .* other than 'left_tool0'; (did you mean "
                                         r"'right_tool0'\? \(others: right_tool0\)|others: right_tool0)$"):
        runner.prepare(scene)


BENT = {"shoulder_lift_joint": -90.0, "elbow_joint": 90.0, "wrist_1_joint": -90.0, "wrist_2_joint": 90.0}


def _relative_motion_rank(robot, q) -> int:
    """Rank of the joints' map to the right tool's twist relative to the left tool's, from
    Pinocchio's frame Jacobians (numpy's SVD rank): 6 when a weld between the hands is regular."""
    import pinocchio as pin

    model, data = robot.model, robot.model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    left, right = (pin.getFrameJacobian(model, data, model.getFrameId(f), pin.LOCAL_WORLD_ALIGNED)[:, 6:]
                   for f in ("left_tool0", "right_tool0"))
    return int(np.linalg.matrix_rank(right - left))


@pytest.mark.parametrize("stretched", [True, False])
def test_the_grasp_posture_is_warned_exactly_when_the_loop_is_singular(tmp_path, stretched):
    """The warning follows the loop's rank as Pinocchio's Jacobians give it: at the zero posture
    (arms stretched) the hands' relative motion has rank 5 and preparing the scene warns, naming
    the fix; at the scene's bent posture it has rank 6 and nothing is warned."""
    import warnings

    from freefloat.robot.loading import FreefloatWarning

    angles = {f"{side}_{joint}": 0.0 if stretched else value for side in ("left", "right")
              for joint, value in BENT.items()}
    scene = quiet_scene(tmp_path, SCENE, initial={"joint_positions": angles}, target={"second_grasp": None})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        setup = runner.prepare(scene)
    singular = [w for w in caught if issubclass(w.category, FreefloatWarning) and "singular at the grasp" in str(w.message)]
    rank = _relative_motion_rank(setup.robot, setup.q0)
    assert rank == (5 if stretched else 6)
    assert bool(singular) == (rank < 6)
    if singular:
        assert "[initial.joint_positions]" in str(singular[0].message)


def test_an_environment_is_refused_naming_its_kind(tmp_path):
    """A two-hand capture flies in no environment: an [[environment]] is refused, not ignored."""
    from freefloat.app.scenes import builtin_scenes, load_scene

    path = tmp_path / "in_orbit.toml"
    path.write_text(builtin_scenes()["capture_two_hands_planar"].read_text()
                    + '\n[[environment]]\nkind = "orbit"\naltitude = 400e3\n')
    with pytest.raises(SceneError, match="kind 'orbit' is not applied by a two-hand capture"):
        runner.prepare(load_scene(path))
