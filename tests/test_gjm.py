"""Hand-built GJM quantities against Pinocchio (CRBA, centroidal momentum, frame Jacobians)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings

from freefloat import gjm, load_robot
from freefloat.dynamics.reference import reference
from freefloat.dynamics.verify import central_differences, relative_error
from freefloat.robot.joints import JointCoordinates

from .conftest import REPO, random_robots, robot_from_case

QUANTITIES = ("H0", "H0m", "Hm", "Hstar", "J0", "Jm", "J0E", "Jstar", "momentum_base", "momentum_origin")


def gjm_state(robot, rng, backend="compiled"):
    """A random state with the base away from the origin, and the hand-built and reference values."""
    q = robot.neutral()
    q[:3] = rng.uniform(-2, 2, 3)
    quat = rng.normal(size=4)
    q[3:7] = quat / np.linalg.norm(quat)
    JointCoordinates(robot).set(q, rng.uniform(-np.pi, np.pi, robot.n_joints))
    v = rng.normal(size=robot.model.nv)
    return q, v, gjm.compute(robot, q, v, backend), reference(robot, q, v)


@pytest.mark.slow
@pytest.mark.parametrize("backend", gjm.BACKENDS)
@settings(max_examples=40, deadline=None)
@given(random_robots())
def test_matrices_jacobians_and_momenta_match_pinocchio(tmp_path_factory, backend, case):
    """On random trees (prismatic, fixed, branching, offset base CoM) every quantity of either
    backend agrees with Pinocchio to 1e-9."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    _, _, state, ref = gjm_state(robot, rng, backend)
    for name in QUANTITIES:
        assert relative_error(getattr(state, name), getattr(ref, name)) < 1e-9, name


@pytest.mark.parametrize("backend", gjm.BACKENDS)
@settings(max_examples=25, deadline=None)
@given(random_robots(max_links=6))
def test_joint_derivatives_match_central_differences(tmp_path_factory, backend, case):
    """dH0/dq_k, dH0m/dq_k, dHm/dq_k at fixed base pose equal central differences of CRBA's."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v, _, _ = gjm_state(robot, rng)
    der = gjm.derivatives(robot, q, v, backend)
    coords = JointCoordinates(robot)
    for k in range(robot.n_joints):
        fd = central_differences(robot, q, v, k, coords)
        for name, base in (("dH0", "H0"), ("dH0m", "H0m"), ("dHm", "Hm")):
            assert np.abs(getattr(der, name)[k] - fd[base]).max() < 1e-6 * max(1.0, np.abs(fd[base]).max()), (name, k)


@pytest.mark.parametrize("backend", gjm.BACKENDS)
@settings(max_examples=25, deadline=None)
@given(random_robots(max_links=6))
def test_time_derivatives_match_differences_along_the_motion(tmp_path_factory, backend, case):
    """H0dot, H0mdot, Hmdot (base turning, joints moving) equal central differences along (q, v)."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v, _, _ = gjm_state(robot, rng)
    der = gjm.derivatives(robot, q, v, backend)
    fd = central_differences(robot, q, v, None, JointCoordinates(robot))
    for name, base in (("H0dot", "H0"), ("H0mdot", "H0m"), ("Hmdot", "Hm")):
        assert np.abs(getattr(der, name) - fd[base]).max() < 1e-6 * max(1.0, np.abs(fd[base]).max()), name


@settings(max_examples=40, deadline=None)
@given(random_robots())
def test_inertia_matrices_are_symmetric_positive_definite(tmp_path_factory, case):
    """H0, Hm and H* are symmetric positive definite."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    _, _, state, _ = gjm_state(robot, rng)
    for matrix in (state.H0, state.Hm, state.Hstar):
        np.testing.assert_allclose(matrix, matrix.T, atol=1e-12 * np.abs(matrix).max())
        assert np.linalg.eigvalsh(matrix).min() > 0.0


@settings(max_examples=40, deadline=None)
@given(random_robots())
def test_nonzero_momentum_map_gives_the_end_effector_velocity(tmp_path_factory, case):
    """x_Edot = J* qdot + J0E H0^-1 M (eq 88) equals Pinocchio's frame velocity at any momentum."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    _, _, state, ref = gjm_state(robot, rng)
    assert relative_error(state.end_effector_velocity(), ref.ee_velocity) < 1e-9


@settings(max_examples=40, deadline=None)
@given(random_robots())
def test_momentum_about_origin_is_momentum_about_base_plus_r0_cross_p(tmp_path_factory, case):
    """L_origin = L_base + r0 x P, and eq 184 with the corrected H0^C reproduces it."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    _, _, state, _ = gjm_state(robot, rng)
    P = state.momentum_base[:3]
    np.testing.assert_allclose(state.momentum_origin[3:], state.momentum_base[3:] + np.cross(state.kinematics.r0, P), atol=1e-10)
    assert relative_error(gjm.momentum_about_origin(state), state.momentum_origin) < 1e-12


def test_printed_eq_182_is_wrong_away_from_the_origin():
    """Eq 182 as printed misses the angular momentum about the origin once r0 and r0C are nonzero."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    rng = np.random.default_rng(0)
    _, _, state, ref = gjm_state(robot, rng)
    printed = gjm.momentum_about_origin(state, "printed_eq182")
    assert relative_error(printed, ref.momentum_origin) > 1e-2
    np.testing.assert_allclose(printed[:3], ref.momentum_origin[:3], rtol=1e-12)  # P is unaffected


def test_printed_eq_182_agrees_when_the_base_is_at_the_origin():
    """With r0 = 0 both H0^C variants vanish in the lower-right block and agree."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    q, v = robot.neutral(), np.random.default_rng(1).normal(size=robot.model.nv)
    JointCoordinates(robot).set(q, np.random.default_rng(2).uniform(-1, 1, robot.n_joints))
    state = gjm.compute(robot, q, v)
    np.testing.assert_allclose(gjm.momentum_about_origin(state, "printed_eq182"), gjm.momentum_about_origin(state), atol=1e-12)


def test_egjm_blocks_tile_the_generalized_jacobian():
    """The E-GJM blocks of the four-arm robot are J*'s 6x4 tiles, coupling blocks = -J0E^i H0^-1 H0m_j."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    _, _, state, _ = gjm_state(robot, np.random.default_rng(3))
    blocks = gjm.egjm_blocks(state, robot)
    np.testing.assert_array_equal(np.block([[blocks[(i, j)] for j in range(4)] for i in range(4)]), state.Jstar)
    coupling = -state.J0E[6:12] @ np.linalg.solve(state.H0, state.H0m[:, 8:12])  # eq 91, arm 2 <- arm 3
    np.testing.assert_allclose(blocks[(1, 2)], coupling, atol=1e-12)


def test_planar_base_gives_the_same_matrices_as_the_free_base():
    """A planar-base robot's GJM (embedded in 3-D) equals the free-base one at the same planar state."""
    planar = load_robot(REPO / "urdf" / "four_arm_planar.urdf", base="planar", visuals=False)
    free = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    rng = np.random.default_rng(4)
    joints, yaw = rng.uniform(-1, 1, 16), 0.7
    qp = np.concatenate(([0.3, -0.2, np.cos(yaw), np.sin(yaw)], joints))
    vp = rng.normal(size=19)
    qf = np.concatenate(([0.3, -0.2, 0.0, 0.0, 0.0, np.sin(yaw / 2), np.cos(yaw / 2)], joints))
    vf = np.concatenate((vp[:2], [0, 0, 0], vp[2:]))
    a, b = gjm.compute(planar, qp, vp), gjm.compute(free, qf, vf)
    for name in QUANTITIES:
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), atol=1e-12, err_msg=name)


def test_reference_refuses_a_planar_base():
    """The Pinocchio reference of the 6x6 H0 needs a free-flyer base, and says so."""
    from freefloat import FreefloatError

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", base="planar", visuals=False)
    with pytest.raises(FreefloatError, match="free-flyer"):
        reference(robot, robot.neutral(), np.zeros(robot.model.nv))


def test_tree_branching_mid_arm(tmp_path):
    """A Y-shaped arm (two end-effectors sharing joints 1-2) matches Pinocchio; SPART's issue #5 case."""
    from .conftest import load_text

    link = '<link name="{0}"><inertial><origin xyz="0.2 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    joint = '<joint name="{0}" type="revolute"><parent link="{1}"/><child link="{2}"/><origin xyz="{3}" rpy="0 0 {4}"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
    parts = ['<robot name="y">', link.format("base").replace('mass value="1"', 'mass value="20"')]
    for name, parent, xyz, yaw in (("a", "base", "0.5 0 0", 0), ("b", "a", "0.4 0 0", 0.3),
                                   ("c", "b", "0.4 0 0", 0.5), ("d", "b", "0.4 0 0", -0.5)):
        parts += [link.format(name), joint.format("j" + name, parent, name, xyz, yaw)]
    robot = load_text(tmp_path, "".join(parts) + "</robot>")
    assert robot.end_effectors == ("c", "d") and robot.arms[0].joints[:2] == robot.arms[1].joints[:2]
    _, _, state, ref = gjm_state(robot, np.random.default_rng(5))
    assert relative_error(state.Jstar, ref.Jstar) < 1e-12
    assert relative_error(state.end_effector_velocity(), ref.ee_velocity) < 1e-12
    blocks = gjm.egjm_blocks(state, robot)
    np.testing.assert_array_equal(blocks[(0, 1)][:, :2], blocks[(0, 0)][:, :2])  # shared joints
