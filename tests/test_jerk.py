"""Jerk by the composition of motion (thesis proposal eqs 4-5, 19-21) on random trees, against
Pinocchio's kinematic derivatives and finite differences of its classical accelerations."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from freefloat.errors import BadShape, InvalidArgument, UnknownName
from freefloat.robot.jerk import com_motions, frame_motion, joint_motions, poisson_jerk

from .conftest import REPO, random_robots, robot_from_case


def state(model: pin.Model, rng: np.random.Generator):
    """A random configuration (the root inside the unit box) and generalized velocity,
    acceleration and jerk (nv,) each."""
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    return (q, *rng.normal(size=(3, model.nv)))


def derivative_jerks(model: pin.Model, q, v, a, j, points: list[tuple[int, np.ndarray]]) -> np.ndarray:
    """Jerks (P, 3) of points (joint id, position in the joint frame), N's axes, by the chain rule
    on Pinocchio's derivatives of the classical point acceleration (LOCAL_WORLD_ALIGNED):
    ``d a / dq v + d a / dv a + d a / da j``."""
    data = model.createData()
    pin.computeForwardKinematicsDerivatives(model, data, q, v, a)
    out = []
    for joint, point in points:
        _, adq, adv, ada = pin.getPointClassicAccelerationDerivatives(
            model, data, joint, pin.SE3(np.eye(3), point), pin.LOCAL_WORLD_ALIGNED)
        out.append(adq @ v + adv @ a + ada @ j)
    return np.array(out)


def scale(x: np.ndarray) -> float:
    return max(1.0, float(np.abs(x).max()))


@settings(max_examples=25, deadline=None)
@given(random_robots(max_links=8), st.sampled_from(["free", "planar"]))
def test_joint_origins_and_coms_match_pinocchios_derivatives(tmp_path_factory, case, base):
    """The jerk of every joint origin and link CoM of a random tree (free or planar root) equals
    the chain rule on Pinocchio's classical-acceleration derivatives to 1e-12 relative."""
    robot, rng = robot_from_case(tmp_path_factory, case, base=base)
    model = robot.model
    q, v, a, j = state(model, rng)
    origins = [m.jerk for m in joint_motions(model, q, v, a, j)[1:]]
    coms = [m.jerk for m in com_motions(model, q, v, a, j)]
    points = [(i, np.zeros(3)) for i in range(1, model.njoints)] + [(i, model.inertias[i].lever) for i in range(1, model.njoints)]
    expected = derivative_jerks(model, q, v, a, j, points)
    assert np.abs(np.array(origins + coms) - expected).max() <= 1e-12 * scale(expected)


@settings(max_examples=25, deadline=None)
@given(random_robots(max_links=8))
def test_angular_jerks_match_pinocchios_derivatives(tmp_path_factory, case):
    """Every body's angular jerk equals the chain rule on Pinocchio's joint-acceleration
    derivatives (the angular rows, LOCAL_WORLD_ALIGNED: N's axes) to 1e-12 relative."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    model = robot.model
    q, v, a, j = state(model, rng)
    data = model.createData()
    pin.computeForwardKinematicsDerivatives(model, data, q, v, a)
    bodies = joint_motions(model, q, v, a, j)
    for i in range(1, model.njoints):
        _, adq, adv, ada = pin.getJointAccelerationDerivatives(model, data, i, pin.LOCAL_WORLD_ALIGNED)
        expected = (adq @ v + adv @ a + ada @ j)[3:]
        assert np.abs(bodies[i].angular_jerk - expected).max() <= 1e-12 * scale(expected)


def trajectory(model: pin.Model, q0, v0, a0, j0):
    """The motion with generalized velocity ``v(t) = v0 + a0 t + j0 t^2 / 2`` from ``q0`` at t = 0:
    ``t -> (q, v, a)``, q by integrating ``xi' = dIntegrate(q0, xi)^-1 v(t)`` (DOP853, rtol
    1e-13) and ``q = integrate(q0, xi)``: exact on the Lie group of a free or planar root."""
    def q_at(t: float) -> np.ndarray:
        if t == 0.0:
            return q0
        rate = lambda s, xi: np.linalg.solve(pin.dIntegrate(model, q0, xi, pin.ARG1), v0 + a0 * s + 0.5 * j0 * s * s)
        xi = solve_ivp(rate, (0.0, t), np.zeros(model.nv), method="DOP853", rtol=1e-13, atol=1e-16).y[:, -1]
        return pin.integrate(model, q0, xi)
    return lambda t: (q_at(t), v0 + a0 * t + 0.5 * j0 * t * t, a0 + j0 * t)


def classical_accelerations(model: pin.Model, data: pin.Data, q, v, a, frames: list[int]) -> np.ndarray:
    """Classical linear accelerations of the frames' origins and the bodies' angular
    accelerations, N's axes, (F, 6), by Pinocchio."""
    pin.forwardKinematics(model, data, q, v, a)
    pin.updateFramePlacements(model, data)
    rows = []
    for f in frames:
        linear = pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED).linear
        rows.append(np.concatenate((linear, pin.getFrameAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED).angular)))
    return np.array(rows)


@settings(max_examples=10, deadline=None)
@given(random_robots(max_links=6))
def test_end_effector_jerks_are_finite_differences_of_pinocchios_accelerations(tmp_path_factory, case):
    """Along a smooth motion with a given generalized jerk (free-floating root), the end-effectors'
    jerks and angular jerks equal 4th-order central differences (h = 1 ms) of Pinocchio's
    classical accelerations to 1e-8 relative."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    model = robot.model
    q, v, a, j = state(model, rng)
    frames = list(robot.end_effector_frame_ids)
    motion, data, h = trajectory(model, q, v, a, j), model.createData(), 1e-3
    samples = [classical_accelerations(model, data, *motion(k * h), frames) for k in (-2, -1, 1, 2)]
    expected = (samples[0] - 8.0 * samples[1] + 8.0 * samples[2] - samples[3]) / (12.0 * h)
    ours = np.array([np.concatenate((m.jerk, m.angular_jerk)) for m in (frame_motion(model, q, v, a, j, f) for f in frames)])
    assert np.abs(ours - expected).max() <= 1e-8 * scale(expected)


def test_serial_chains_of_the_5r_match_finite_differences():
    """On the 5R's spanning tree (two fixed-base RR chains, urdf/five_bar.urdf), the link CoMs'
    jerks equal central differences of their classical accelerations (polynomial joint motion)."""
    model = pin.buildModelFromUrdf(str(REPO / "urdf" / "five_bar.urdf"))
    rng = np.random.default_rng(1)
    q, v, a, j = (rng.normal(size=model.nv) for _ in range(4))
    lever = [pin.Frame(f"com{i}", i, model.getFrameId(model.names[i]), pin.SE3(np.eye(3), model.inertias[i].lever),
                       pin.FrameType.OP_FRAME) for i in range(1, model.njoints)]
    frames = [model.addFrame(f) for f in lever]
    data, h = model.createData(), 1e-3
    at = lambda t: (q + v * t + a * t**2 / 2 + j * t**3 / 6, v + a * t + j * t**2 / 2, a + j * t)
    samples = [classical_accelerations(model, data, *at(k * h), frames) for k in (-2, -1, 1, 2)]
    expected = (samples[0] - 8.0 * samples[1] + 8.0 * samples[2] - samples[3]) / (12.0 * h)
    ours = np.array([np.concatenate((m.jerk, m.angular_jerk)) for m in com_motions(model, q, v, a, j)])
    assert np.abs(ours - expected).max() <= 1e-9 * scale(expected)


@settings(max_examples=15, deadline=None)
@given(random_robots(max_links=6))
def test_jerk_is_the_jacobian_times_the_joint_jerk_plus_a_bias(tmp_path_factory, case):
    """``j(q, v, a, qddd) = J qddd + j(q, v, a, 0)`` with J Pinocchio's linear frame Jacobian of the
    end-effector (LOCAL_WORLD_ALIGNED): the jerk's analogue of eq 49."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    model = robot.model
    q, v, a, j = state(model, rng)
    frame = robot.end_effector_frame_ids[0]
    data = model.createData()
    J = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
    bias = frame_motion(model, q, v, a, np.zeros(model.nv), frame)
    full = frame_motion(model, q, v, a, j, frame)
    expected = np.concatenate((J[:3] @ j + bias.jerk, J[3:] @ j + bias.angular_jerk))
    assert np.abs(np.concatenate((full.jerk, full.angular_jerk)) - expected).max() <= 1e-12 * scale(expected)


def test_printed_eq4_misses_the_jerk_by_alpha_cross_the_difference():
    """Eq 4 as printed (``alpha x (alpha x r)``) differs from eq 5 (``alpha x (omega x r)``) by
    exactly ``alpha x ((alpha - omega) x r)``; with it the 5R's CoM jerks miss Pinocchio's
    derivatives, with eq 5 they do not."""
    rng = np.random.default_rng(2)
    jerk_o, w, alpha, alpha_dot, r = rng.normal(size=(5, 3))
    difference = poisson_jerk(jerk_o, w, alpha, alpha_dot, r, "printed_eq4") - poisson_jerk(jerk_o, w, alpha, alpha_dot, r)
    np.testing.assert_allclose(difference, np.cross(alpha, np.cross(alpha - w, r)), atol=1e-14)
    model = pin.buildModelFromUrdf(str(REPO / "urdf" / "five_bar.urdf"))
    q, v, a, j = (rng.normal(size=model.nv) for _ in range(4))
    expected = derivative_jerks(model, q, v, a, j, [(i, model.inertias[i].lever) for i in range(1, model.njoints)])
    printed = np.array([m.jerk for m in com_motions(model, q, v, a, j, form="printed_eq4")])
    right = np.array([m.jerk for m in com_motions(model, q, v, a, j)])
    assert np.abs(right - expected).max() <= 1e-12 * scale(expected) < 0.01 * np.abs(printed - expected).max()


def test_a_joint_without_a_constant_motion_subspace_is_named():
    """A spherical joint in ZYX angles (its motion subspace turns with q) is refused by name."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelSphericalZYX(), pin.SE3.Identity(), "wrist")
    with pytest.raises(InvalidArgument, match="joint 'wrist' is a JointModelSphericalZYX"):
        joint_motions(model, pin.neutral(model), *np.zeros((3, model.nv)))


def test_bad_shapes_and_frames_are_named():
    """A state vector of the wrong size names the argument and both shapes; an unknown frame
    lists the valid ones."""
    model = pin.buildModelFromUrdf(str(REPO / "urdf" / "five_bar.urdf"))
    q = pin.neutral(model)
    with pytest.raises(BadShape, match=r"'j' must have shape \(4,\), got \(3,\)"):
        joint_motions(model, q, np.zeros(4), np.zeros(4), np.zeros(3))
    with pytest.raises(UnknownName, match="unknown frame 'c3_ee'.*c1_ee"):
        frame_motion(model, q, *np.zeros((3, 4)), "c3_ee")
