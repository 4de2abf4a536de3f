"""Orsino's serial-chain model (thesis proposal sec 5.3) against Pinocchio's CRBA and RNEA."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from freefloat.parallel.serial import SerialChain, dh_matrix


def random_chain(seed: int, n: int) -> SerialChain:
    rng = np.random.default_rng(seed)
    inertia = []
    for _ in range(n):
        A = rng.normal(size=(3, 3))
        inertia.append(A @ A.T + 0.05 * np.eye(3))
    base = np.eye(4)
    base[:3, :3] = pin.exp3(rng.normal(size=3))
    base[:3, 3] = rng.normal(size=3)
    return SerialChain.from_dh(a=rng.uniform(-0.5, 0.5, n), alpha=rng.uniform(-np.pi, np.pi, n), d=rng.uniform(-0.3, 0.3, n),
                               theta=rng.uniform(-np.pi, np.pi, n), prismatic=rng.random(n) < 0.3, mass=rng.uniform(0.2, 3.0, n),
                               com=rng.uniform(-0.2, 0.2, (n, 3)), inertia=np.array(inertia), base=base,
                               gravity=np.array([0.0, -9.8, 0.0]))


def pinocchio_chain(chain: SerialChain) -> pin.Model:
    """The same chain as a fixed-base Pinocchio model: joint i about z of B_{i-1}."""
    model = pin.Model()
    model.gravity = pin.Motion(chain.gravity, np.zeros(3))
    parent, previous_link = 0, pin.SE3(chain.base)
    for i in range(chain.dof):
        joint_model = pin.JointModelPZ() if chain.prismatic[i] else pin.JointModelRZ()
        jid = model.addJoint(parent, joint_model, previous_link * pin.SE3(chain.placement[i]), f"j{i + 1}")
        # B_i = joint frame * (joint motion) * L_i: the inertia, given in B_i, goes to the joint frame through L_i
        L = pin.SE3(chain.link[i])
        model.appendBodyToJoint(jid, L.act(pin.Inertia(chain.mass[i], chain.com[i], chain.inertia[i])), pin.SE3.Identity())
        parent, previous_link = jid, L
    return model


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 6))
def test_mass_matrix_and_forces_match_pinocchio(seed, n):
    """M, v + g of eqs 61-64 equal CRBA and RNEA(q, qd, 0) on random chains with prismatic joints."""
    chain = random_chain(seed, n)
    model = pinocchio_chain(chain)
    data = model.createData()
    rng = np.random.default_rng(seed + 1)
    q, qd = rng.uniform(-1, 1, n), rng.normal(size=n)
    M, v, g = chain.dynamics(q, qd)
    M_ref = pin.crba(model, data, q)
    M_ref = np.triu(M_ref) + np.triu(M_ref, 1).T
    np.testing.assert_allclose(M, M_ref, atol=1e-10 * max(1.0, np.abs(M_ref).max()))
    np.testing.assert_allclose(v + g, pin.rnea(model, data, q, qd, np.zeros(n)), atol=1e-9 * max(1.0, np.abs(v + g).max()))
    np.testing.assert_allclose(g, pin.computeGeneralizedGravity(model, data, q), atol=1e-10 * max(1.0, np.abs(g).max()))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 6))
def test_tip_acceleration_bias_is_the_second_derivative(seed, n):
    """The end-effector Jacobian and bias (eqs 30, 52) give d^2 x/dt^2 (central differences along a path)."""
    chain = random_chain(seed, n)
    rng = np.random.default_rng(seed + 2)
    q0, qd, qdd = rng.uniform(-1, 1, n), rng.normal(size=n), rng.normal(size=n)
    h = 1e-4
    path = lambda t: q0 + qd * t + 0.5 * qdd * t**2  # noqa: E731
    fd = (chain.tip(path(h)) - 2 * chain.tip(path(0.0)) + chain.tip(path(-h))) / h**2
    kin = chain.kinematics(q0, qd)
    np.testing.assert_allclose(kin["tip_Jv"] @ qdd + kin["tip_c"], fd, atol=1e-5 * max(1.0, np.abs(fd).max()))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 6))
def test_last_link_angular_jacobian_and_bias_match_pinocchio(seed, n):
    """``tip_Jw qdd + tip_dw`` is the last link's angular acceleration in N (Pinocchio's
    LOCAL_WORLD_ALIGNED joint acceleration at (q, qd, qdd))."""
    chain = random_chain(seed, n)
    model = pinocchio_chain(chain)
    data = model.createData()
    rng = np.random.default_rng(seed + 3)
    q, qd, qdd = rng.uniform(-1, 1, n), rng.normal(size=n), rng.normal(size=n)
    pin.forwardKinematics(model, data, q, qd, qdd)
    reference = data.oMi[n].rotation @ data.a[n].angular
    kin = chain.kinematics(q, qd)
    np.testing.assert_allclose(kin["tip_Jw"] @ qdd + kin["tip_dw"], reference, atol=1e-10 * max(1.0, np.abs(reference).max()))


def test_dh_matrix_is_a_rigid_transform():
    """The standard DH matrix (eq 22 with the sin(theta) sin(alpha) entry) is a proper rotation."""
    T = dh_matrix(0.7, 0.1, 0.3, -1.1)
    np.testing.assert_allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-15)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0)
