"""Wrench-to-joint-torque mappings against the exact answer from ABA."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat import load_robot
from freefloat.lab.reproduce.states import state_with_momentum
from freefloat.space.force_propagation import equivalent_torques, stacked_wrench

from .conftest import REPO


@pytest.fixture(scope="module")
def robot():
    return load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)


def wrenches(rng):
    return {"arm1_ee": rng.normal(size=6), "arm3_ee": rng.normal(size=6)}


def relative(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


def test_generalized_jacobian_transpose_is_exact_at_any_state(robot):
    """J*^T F equals the exact equivalent torque, moving or not."""
    rng = np.random.default_rng(0)
    for _ in range(5):
        q, v = state_with_momentum(robot, rng, L=rng.normal(size=3))
        t = equivalent_torques(robot, q, v, wrenches(rng))
        assert relative(t["generalized"], t["exact"]) < 1e-9


def test_fixed_base_jacobian_transpose_is_wrong_for_a_free_base(robot):
    """Jm^T F misses the base's reaction: off by O(1) on the four-arm robot."""
    rng = np.random.default_rng(1)
    q, v = state_with_momentum(robot, rng)
    t = equivalent_torques(robot, q, v, wrenches(rng))
    assert relative(t["fixed_base"], t["exact"]) > 1e-2


def test_newton_euler_is_exact_at_rest_and_drifts_with_base_rotation(robot):
    """The locked-joint propagation matches at rest; its w x I w term errs once the base turns."""
    rng = np.random.default_rng(2)
    q, _ = state_with_momentum(robot, rng)
    F = wrenches(rng)
    rest = equivalent_torques(robot, q, np.zeros(robot.model.nv), F)
    assert relative(rest["newton_euler"], rest["exact"]) < 1e-9
    v = np.zeros(robot.model.nv)
    v[3:6] = [0.5, -1.0, 2.0]
    turning = equivalent_torques(robot, q, v, F)
    assert relative(turning["newton_euler"], turning["exact"]) > 1e-3


def test_unknown_end_effector_is_named(robot):
    """A wrench on an end-effector that does not exist fails naming it."""
    with pytest.raises(ValueError, match="no end-effector 'arm9_ee'"):
        stacked_wrench(robot, {"arm9_ee": np.ones(6)})
