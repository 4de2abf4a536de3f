"""The detumbling solver: residuals, eq 120, optimality of the null-space choice, bad requests."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat import gjm, load_robot
from freefloat.lab.reproduce.states import state_with_momentum
from freefloat.space.detumbling import joint_indices, solve, task_rows

from .conftest import REPO, random_state


@pytest.fixture(scope="module")
def tumbling():
    """The two-arm robot (free base) with angular and linear momentum, its GJM state."""
    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    q, v = state_with_momentum(robot, np.random.default_rng(0), P=np.array([2.0, -1.0, 0.5]), L=np.array([0.3, -0.2, 4.0]))
    return robot, gjm.compute(robot, q, v)


def test_min_norm_solution_zeroes_the_rows_with_the_least_joint_rate(tumbling):
    """J*{k} qdot + J0E{k} H0^-1 M = 0, and no other exact solution is shorter."""
    robot, s = tumbling
    rows, joints = task_rows(robot, [("arm1_ee", "wz"), ("arm2_ee", "wz")]), joint_indices(robot, None)
    sol = solve(s, rows, joints)
    assert np.abs(sol.residual).max() < 1e-12
    null = np.linalg.svd(s.Jstar[rows])[2][len(rows):].T
    for z in np.random.default_rng(1).normal(size=(5, null.shape[1])):
        assert np.linalg.norm(sol.qdot) < np.linalg.norm(sol.qdot + null @ z)


def test_single_mission_joint_is_eq_120(tumbling):
    """One row, one joint: qdot_j = -(J0E{k} H0^-1 M) / J*{k, j}, every other joint still."""
    robot, s = tumbling
    rows, joints = task_rows(robot, [("arm1_ee", "wz")]), joint_indices(robot, ["arm1_joint4"])
    sol = solve(s, rows, joints, method="single")
    b = s.J0E[rows[0]] @ np.linalg.solve(s.H0, s.momentum_base)
    assert sol.qdot[joints[0]] == pytest.approx(-b / s.Jstar[rows[0], joints[0]], rel=1e-12)
    assert np.count_nonzero(sol.qdot) == 1 and abs(sol.residual[0]) < 1e-12


def test_null_space_choice_lowers_the_base_angular_velocity(tumbling):
    """The null-space solution keeps the residual at zero and turns the base less than min-norm."""
    robot, s = tumbling
    rows, joints = task_rows(robot, [("arm1_ee", "wz")]), joint_indices(robot, None)
    plain, better = solve(s, rows, joints), solve(s, rows, joints, method="null_space")
    assert np.abs(better.residual).max() < 1e-12
    assert np.linalg.norm(better.base_twist[3:]) < np.linalg.norm(plain.base_twist[3:])


@pytest.mark.parametrize("seed", range(4))
def test_null_space_choice_ignores_round_off_objective_components(seed):
    """On a planar arm with a free base the joints cannot move the base's wx, wy: the null-space
    step drops those round-off directions (C N's tiny singular values) instead of dividing by them,
    so the rates stay of the min-norm's size, the rows stay stopped and the base turns less."""
    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    s = gjm.compute(robot, *random_state(robot, np.random.default_rng(seed)))
    rows, joints = task_rows(robot, [("arm1_ee", "wz")]), joint_indices(robot, None)
    plain, better = solve(s, rows, joints), solve(s, rows, joints, method="null_space")
    assert np.abs(better.qdot).max() < 100.0 * max(1.0, np.abs(plain.qdot).max())
    assert np.abs(better.residual).max() < 1e-12
    assert np.linalg.norm(better.base_twist[3:]) <= np.linalg.norm(plain.base_twist[3:]) + 1e-12


def test_base_twist_is_what_the_momentum_gives(tumbling):
    """The reported base twist is J0 qdot + H0^-1 M, the momentum constraint (eq 84)."""
    robot, s = tumbling
    sol = solve(s, task_rows(robot, [("arm2_ee", "angular")]), joint_indices(robot, None))
    np.testing.assert_allclose(s.H0 @ sol.base_twist + s.H0m @ sol.qdot, s.momentum_base, atol=1e-10)


@pytest.mark.parametrize(("call", "message"), [
    (lambda r, s: task_rows(r, [("arm9_ee", "wz")]), "no end-effector 'arm9_ee'"),
    (lambda r, s: task_rows(r, [("arm1_ee", "spin")]), "unknown component 'spin'"),
    (lambda r, s: joint_indices(r, ["arm1_joint9"]), "no joint 'arm1_joint9'"),
    (lambda r, s: solve(s, task_rows(r, [("arm1_ee", "all"), ("arm2_ee", "all")]), joint_indices(r, ["arm1_joint1", "arm1_joint2"])),
     "12 task rows but 2 mission joints: use method='least_squares'"),
])
def test_bad_requests_are_named(tumbling, call, message):
    """Unknown end-effectors, components and joints, over-determined tasks and useless mission joints fail clearly."""
    robot, s = tumbling
    with pytest.raises(ValueError, match=message):
        call(robot, s)


def test_a_mission_joint_that_cannot_move_the_row_is_refused(tumbling):
    """With the plane horizontal, no z-axis joint moves an end-effector along z: eq 120 is refused."""
    robot, _ = tumbling
    q, v = robot.neutral(), np.random.default_rng(2).normal(size=robot.model.nv)
    flat = gjm.compute(robot, q, v)
    with pytest.raises(ValueError, match="does not move row"):
        solve(flat, task_rows(robot, [("arm1_ee", "vz")]), joint_indices(robot, ["arm1_joint4"]), method="single")
