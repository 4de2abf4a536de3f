"""Pinocchio's local base twist vs the dissertation's inertial base-CoM twist, both ways."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings

from freefloat import load_robot
from freefloat.errors import FreefloatError
from freefloat.robot.conventions import (
    base_acceleration,
    base_state,
    cross_rows,
    inertial_to_local_twist,
    local_base_acceleration,
    local_to_inertial_twist,
    momentum_about_origin,
    state_from_base,
    twist_map,
)
from freefloat.robot.loading import BASE_COM_FRAME

from .conftest import REPO, random_robots, random_state, robot_from_case


@settings(max_examples=30, deadline=None)
@given(random_robots())
def test_base_state_matches_pinocchio_frame_of_the_base_com(tmp_path_factory, case):
    """r0, R0 and [v0; w0] equal Pinocchio's placement and LOCAL_WORLD_ALIGNED velocity of the base CoM frame."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q, v)
    fid = robot.model.getFrameId(BASE_COM_FRAME)
    frame = pin.updateFramePlacement(robot.model, data, fid)
    r0, R0, x0dot = base_state(robot, q, v)
    np.testing.assert_allclose(r0, frame.translation, atol=1e-12)
    np.testing.assert_allclose(R0, frame.rotation, atol=1e-12)
    np.testing.assert_allclose(x0dot, pin.getFrameVelocity(robot.model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(random_robots())
def test_state_from_base_inverts_base_state(tmp_path_factory, case):
    """(q, v) -> (r0, R0, x0dot) -> (q, v) is the identity (quaternion sign aside)."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    r0, R0, x0dot = base_state(robot, q, v)
    q2, v2 = state_from_base(robot, r0, R0, x0dot, q[7:], v[6:])
    np.testing.assert_allclose(pin.difference(robot.model, q, q2), 0.0, atol=1e-12)
    np.testing.assert_allclose(v2, v, atol=1e-12)


def test_twist_map_agrees_with_the_functions():
    """x0dot = T v_b with T = [[R, -R [c]x], [0, R]], and the inverse function undoes it."""
    rng = np.random.default_rng(3)
    R, c, v = pin.exp3(rng.normal(size=3)), rng.normal(size=3), rng.normal(size=6)
    np.testing.assert_allclose(twist_map(R, c) @ v, local_to_inertial_twist(R, c, v), atol=1e-14)
    np.testing.assert_allclose(inertial_to_local_twist(R, c, local_to_inertial_twist(R, c, v)), v, atol=1e-14)


def test_planar_base_round_trip():
    """A planar base state converts both ways through the 6-D conventions."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", base="planar")
    q, v = random_state(robot, np.random.default_rng(0))
    r0, R0, x0dot = base_state(robot, q, v)
    assert x0dot[2] == 0.0 and np.all(x0dot[3:5] == 0.0)
    q2, v2 = state_from_base(robot, r0, R0, x0dot, q[4:], v[3:])
    np.testing.assert_allclose(q2, q, atol=1e-12)
    np.testing.assert_allclose(v2, v, atol=1e-12)


def test_planar_base_rejects_out_of_plane_state():
    """A planar base refuses a tilted pose or an out-of-plane twist with a clear message."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", base="planar")
    tilted = pin.rpy.rpyToMatrix(0.1, 0.0, 0.0)
    with pytest.raises(FreefloatError, match="planar base"):
        state_from_base(robot, np.zeros(3), tilted, np.zeros(6), np.zeros(16), np.zeros(16))


@settings(max_examples=30, deadline=None)
@given(random_robots())
def test_base_acceleration_is_the_classical_acceleration_of_the_base_com(tmp_path_factory, case):
    """x0ddot equals Pinocchio's classical LOCAL_WORLD_ALIGNED acceleration of the base CoM frame."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    a = rng.normal(size=robot.model.nv)
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q, v, a)
    fid = robot.model.getFrameId(BASE_COM_FRAME)
    pin.updateFramePlacement(robot.model, data, fid)
    expected = pin.getFrameClassicalAcceleration(robot.model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector
    np.testing.assert_allclose(base_acceleration(robot, q, v, a), expected, atol=1e-11)


@settings(max_examples=30, deadline=None)
@given(random_robots())
def test_local_base_acceleration_inverts_base_acceleration(tmp_path_factory, case):
    """Pinocchio base acceleration -> x0ddot -> Pinocchio base acceleration is the identity."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    a = rng.normal(size=robot.model.nv)
    np.testing.assert_allclose(local_base_acceleration(robot, q, v, base_acceleration(robot, q, v, a)), a[:6], atol=1e-12)


def test_cross_rows_matches_numpy_cross_under_broadcasting():
    rng = np.random.default_rng(7)
    a, b = rng.normal(size=(4, 1, 3)), rng.normal(size=(1, 5, 3))
    np.testing.assert_allclose(cross_rows(a, b), np.cross(a, b), atol=1e-15)


@settings(max_examples=15, deadline=None)
@given(random_robots())
def test_momentum_about_origin_is_the_sum_of_body_momenta(tmp_path_factory, case):
    """[P; L about the origin] equals the sum over bodies of their spatial momenta mapped to the
    inertial frame (oMi . (I_i v_i)), without the centroidal algorithm."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    model, data = robot.model, robot.model.createData()
    pin.forwardKinematics(model, data, q, v)
    total = sum((data.oMi[i].act(model.inertias[i] * data.v[i]).vector for i in range(1, model.njoints)),
                np.zeros(6))
    np.testing.assert_allclose(momentum_about_origin(model, model.createData(), q, v), total,
                               atol=1e-10 * max(1.0, np.abs(total).max()))
