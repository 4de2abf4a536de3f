"""Joint locking (freefloat.robot.locking) against the full model with the locked accelerations
constrained to zero."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from freefloat import load_robot
from freefloat.errors import RobotModelError
from freefloat.paths import URDF_DIR
from freefloat.robot.locking import lock_joints

from .conftest import random_robots, random_state, robot_from_case

RANDOM = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def four_arm():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)


def locked_case(tmp_path_factory, case, pick_seed):
    """A random robot, a random non-empty subset of its joints locked at a random state whose
    locked rates are zero, and random joint torques (zero on the base and the locked joints)."""
    robot, rng = robot_from_case(tmp_path_factory, case, visuals=False)
    pick = np.random.default_rng(pick_seed)
    names = list(robot.joint_names)
    locked = list(pick.choice(names, size=pick.integers(1, len(names) + 1), replace=False))
    q, v = random_state(robot, rng)
    lock = lock_joints(robot, locked, q)
    v[lock.locked_v] = 0.0
    tau = np.zeros(robot.model.nv)
    tau[robot.n_base:] = rng.uniform(-2.0, 2.0, robot.n_joints)
    tau[lock.locked_v] = 0.0
    return robot, lock, q, v, tau


def kkt_acceleration(robot, lock, q, v, tau):
    """The full model's accelerations with ``a[locked] = 0``: the KKT system
    ``[[M, G^T], [G, 0]] [a; -s] = [tau - b; 0]`` built from CRBA, G selecting the locked rows."""
    model, data = robot.model, robot.model.createData()
    M = pin.crba(model, data, q)
    b = pin.nonLinearEffects(model, data, q, v)
    G = np.eye(model.nv)[lock.locked_v]
    kkt = np.block([[M, G.T], [G, np.zeros((len(G), len(G)))]])
    return np.linalg.solve(kkt, np.concatenate((tau - b, np.zeros(len(G)))))[: model.nv]


@RANDOM
@given(case=random_robots(), pick_seed=st.integers(0, 2**32 - 1))
def test_locked_dynamics_equal_the_full_dynamics_with_locked_accelerations_zero(tmp_path_factory, case, pick_seed):
    """The reduced model's ABA equals the full model's KKT solution with the locked joints' accelerations zero."""
    robot, lock, q, v, tau = locked_case(tmp_path_factory, case, pick_seed)
    expected = kkt_acceleration(robot, lock, q, v, tau)
    q_r, v_r = lock.reduce(q, v)
    small = lock.robot.model
    a_r = pin.aba(small, small.createData(), q_r, v_r, tau[lock.free_v])
    assert np.abs(a_r - expected[lock.free_v]).max() <= 1e-8 * max(1.0, np.abs(expected).max())
    assert np.abs(expected[lock.locked_v]).max() <= 1e-9 * max(1.0, np.abs(expected).max())


@RANDOM
@given(case=random_robots(), pick_seed=st.integers(0, 2**32 - 1))
def test_holding_torque_keeps_the_locked_joints_still_in_the_full_model(tmp_path_factory, case, pick_seed):
    """The full model's ABA with the holding torques (from the reduced ABA) added on the locked joints gives them
    zero acceleration and the free coordinates the reduced robot's accelerations."""
    robot, lock, q, v, tau = locked_case(tmp_path_factory, case, pick_seed)
    q_r, v_r = lock.reduce(q, v)
    a_free = pin.aba(lock.robot.model, lock.robot.model.createData(), q_r, v_r, tau[lock.free_v])
    held = tau.copy()
    held[lock.locked_v] += lock.holding_torque(q, v, a_free, tau)
    a = pin.aba(robot.model, robot.model.createData(), q, v, held)
    assert np.abs(a[lock.locked_v]).max() <= 1e-8 * max(1.0, np.abs(a).max())
    assert np.abs(a[lock.free_v] - a_free).max() <= 1e-8 * max(1.0, np.abs(a).max())


@RANDOM
@given(case=random_robots(), pick_seed=st.integers(0, 2**32 - 1))
def test_frames_of_the_locked_robot_are_where_the_full_robots_are(tmp_path_factory, case, pick_seed):
    """Every end-effector and the base CoM frame have the same placement in both models at the same state."""
    robot, lock, q, v, _ = locked_case(tmp_path_factory, case, pick_seed)
    full, small = robot.model, lock.robot.model
    q_r, _ = lock.reduce(q, v)
    d_full, d_small = full.createData(), small.createData()
    pin.framesForwardKinematics(full, d_full, q)
    pin.framesForwardKinematics(small, d_small, q_r)
    for name in (*robot.end_effectors, "base_com"):
        expected = d_full.oMf[full.getFrameId(name)].homogeneous
        assert np.abs(d_small.oMf[small.getFrameId(name)].homogeneous - expected).max() < 1e-12


def test_expand_puts_the_locked_positions_back_with_zero_rates(four_arm):
    """Expanding a reduced state gives the locked joints their lock positions and zero rates, the rest unchanged."""
    rng = np.random.default_rng(3)
    q, v = random_state(four_arm, rng)
    lock = lock_joints(four_arm, ["arm2_joint3", "arm4_joint1"], q)
    q_r, v_r = lock.reduce(q, v)
    q_back, v_back = lock.expand(q_r, v_r)
    expected_v = v.copy()
    expected_v[lock.locked_v] = 0.0
    assert np.array_equal(q_back, q) and np.array_equal(v_back, expected_v)


def test_unknown_joint_is_refused_naming_it(four_arm):
    """Locking a name that is not an actuated joint raises an error naming it and the valid joints."""
    with pytest.raises(RobotModelError, match="'arm9_joint1': not an actuated joint; did you mean 'arm4_joint1', .*\\(joints: arm1_joint1"):
        lock_joints(four_arm, ["arm9_joint1"], four_arm.neutral())


def test_the_floating_base_cannot_be_locked(four_arm):
    """The root joint is not an actuated joint and cannot be locked."""
    with pytest.raises(RobotModelError, match="cannot lock 'base'"):
        lock_joints(four_arm, ["base"], four_arm.neutral())


def test_a_joint_named_twice_is_refused(four_arm):
    """Naming one joint twice is an error naming it."""
    with pytest.raises(RobotModelError, match="'arm1_joint2' is named twice"):
        lock_joints(four_arm, ["arm1_joint2", "arm1_joint2"], four_arm.neutral())
