"""Partial derivatives of H0, H0m, Hm with respect to the joints, and their time derivatives.

The dissertation (sec 3.2.1, eqs 26-58) differentiates the frame matrices; here the same result
is obtained from the rigid motion each joint imposes on the bodies it moves. With the base pose
fixed, joint k (axis k_k through p_k) moves a point x of a body it carries by
``dx/dq_k = k_k x (x - p_k)`` (revolute) or ``k_k`` (prismatic), a direction u by ``k_k x u``
and an inertia tensor by ``[k_k]x I - I [k_k]x`` (revolute). Along a motion the base also turns
at w0, which rotates every inertial-frame quantity:

.. math::
    \\dot H_0 = \\sum_k \\partial_k H_0 \\dot q_k + \\Omega H_0 - H_0 \\Omega, \\quad
    \\dot H_{0m} = \\sum_k \\partial_k H_{0m} \\dot q_k + \\Omega H_{0m}, \\quad
    \\dot H_m = \\sum_k \\partial_k H_m \\dot q_k,

with ``Omega = diag([w0]x, [w0]x)``; the base translation does not enter (all levers are relative).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...errors import UnknownName
from ...robot.robot import Robot
from .kinematics import BodyKinematics, TreeStructure
from .matrices import body_jacobians, skew_batch
from .model import BACKENDS, GJM, GJMState, checked_state, state_of


class GJMDerivatives(NamedTuple):
    """Joint derivatives at fixed base pose and base twist, and time derivatives along (q, v).

    Attributes:
        dH0: ``dH0/dq_k`` stacked over k (n, 6, 6).
        dH0m: ``dH0m/dq_k`` (n, 6, n).
        dHm: ``dHm/dq_k`` (n, n, n).
        H0dot: time derivative of H0 along the motion (6, 6).
        H0mdot: time derivative of H0m (6, n).
        Hmdot: time derivative of Hm (n, n).
    """

    dH0: np.ndarray
    dH0m: np.ndarray
    dHm: np.ndarray
    H0dot: np.ndarray
    H0mdot: np.ndarray
    Hmdot: np.ndarray


def point_derivatives(tree: TreeStructure, kin: BodyKinematics, points: np.ndarray, moved: np.ndarray) -> np.ndarray:
    """``d point_i / d q_k`` (n, m, 3) for points (m, 3) moved by joint k where ``moved[i, k]``."""
    k, p = kin.joint_axis[:, None, :], kin.joint_position[:, None, :]
    swept = np.where(tree.revolute[:, None, None], np.cross(k, points[None] - p), k)
    return swept * moved.T[:, :, None]


def direction_derivatives(tree: TreeStructure, kin: BodyKinematics, directions: np.ndarray, moved: np.ndarray) -> np.ndarray:
    """``d u_i / d q_k`` (n, m, 3) for directions (m, 3); prismatic joints turn nothing."""
    turned = np.cross(kin.joint_axis[:, None, :], directions[None])
    return turned * (moved.T & tree.revolute[:, None])[:, :, None]


def joint_derivatives(tree: TreeStructure, kin: BodyKinematics):
    """``(dH0, dH0m, dHm)`` at fixed base pose, stacked over joints."""
    JT, JR = body_jacobians(tree, kin)
    A, m, inertia = tree.ancestor, tree.mass, kin.inertia
    joint_body = A[1:]  # joint j's point and axis ride on body j + 1
    dcom = point_derivatives(tree, kin, kin.com, A)                       # (n, nb, 3)
    dp = point_derivatives(tree, kin, kin.joint_position, joint_body)     # (n, n, 3)
    dk = direction_derivatives(tree, kin, kin.joint_axis, joint_body)     # (n, n, 3)
    K = skew_batch(kin.joint_axis) * tree.revolute[:, None, None]        # (n, 3, 3)
    dI = (K[:, None] @ inertia[None] - inertia[None] @ K[:, None]) * A.T[:, :, None, None]

    lever = kin.com[:, None, :] - kin.joint_position[None, :, :]          # (nb, n, 3)
    rev = tree.revolute[None, None, :, None]
    dlever = dcom[:, :, None, :] - dp[:, None, :, :]                      # (n, nb, n, 3)
    dJT = np.where(rev, np.cross(dk[:, None], lever[None]) + np.cross(kin.joint_axis[None, None], dlever), dk[:, None])
    dJT = (dJT * A[None, :, :, None]).transpose(0, 1, 3, 2)               # (n, nb, 3, n)
    dJR = (np.where(rev, dk[:, None], 0.0) * A[None, :, :, None]).transpose(0, 1, 3, 2)

    n, nb = len(tree.parent), len(m)
    flat = lambda x: x.reshape(n, 3 * nb, n)  # noqa: E731  (n, nb, 3, n) -> (n, 3 nb, n)
    IJR = inertia @ JR                                                    # (nb, 3, n)
    half = flat(dJR).transpose(0, 2, 1) @ IJR.reshape(3 * nb, n) \
        + flat(dJT).transpose(0, 2, 1) @ (m[:, None, None] * JT).reshape(3 * nb, n)
    dHm = half + half.transpose(0, 2, 1) + JR.reshape(3 * nb, n).T @ flat(dI @ JR[None])

    r0i = kin.com - kin.r0
    dJ_TS = (m @ dJT.transpose(1, 0, 2, 3).reshape(nb, -1)).reshape(n, 3, n)
    mR = m[:, None, None] * skew_batch(r0i)                               # (nb, 3, 3)
    dH_Sq = (dI @ JR[None] + inertia[None] @ dJR + m[None, :, None, None] * (skew_batch(dcom) @ JT[None])
             + mR[None] @ dJT).sum(axis=1)
    total = m.sum()
    dr0C = (m @ dcom.transpose(1, 0, 2).reshape(nb, -1)).reshape(n, 3) / total
    cross_terms = (m[None, :, None] * dcom).transpose(0, 2, 1) @ r0i      # sum_b m_b dcom_b r0i_b^T
    dH_S = (dI.sum(axis=1) + 2.0 * (cross_terms.trace(axis1=1, axis2=2))[:, None, None] * np.eye(3)
            - cross_terms - cross_terms.transpose(0, 2, 1))
    n = len(tree.parent)
    dH0 = np.zeros((n, 6, 6))
    dH0[:, :3, 3:] = -total * skew_batch(dr0C)
    dH0[:, 3:, :3] = total * skew_batch(dr0C)
    dH0[:, 3:, 3:] = dH_S
    return dH0, np.concatenate((dJ_TS, dH_Sq), axis=1), dHm


def time_derivatives(tree: TreeStructure, state: GJMState) -> GJMDerivatives:
    """Joint and time derivatives at a state already computed by :meth:`GJM.compute`."""
    dH0, dH0m, dHm = joint_derivatives(tree, state.kinematics)
    Omega = np.zeros((6, 6))
    Omega[:3, :3] = Omega[3:, 3:] = skew_batch(state.x0dot[3:])
    qdot = state.qdot
    return GJMDerivatives(
        dH0=dH0, dH0m=dH0m, dHm=dHm,
        H0dot=np.tensordot(qdot, dH0, 1) + Omega @ state.H0 - state.H0 @ Omega,
        H0mdot=np.tensordot(qdot, dH0m, 1) + Omega @ state.H0m,
        Hmdot=np.tensordot(qdot, dHm, 1),
    )


def state_and_derivatives(gjm: GJM, q: np.ndarray, v: np.ndarray, backend: str = "compiled") -> tuple[GJMState, GJMDerivatives]:
    """The GJM state and its derivatives at (q, v), from one call to the compiled core or from
    the numpy reference (``backend`` as in :meth:`GJM.compute`)."""
    if backend == "compiled":
        state, deriv = gjm.core.compute_with_derivatives(q, v)
        return state_of(state), GJMDerivatives(*deriv)
    if backend not in BACKENDS:
        raise UnknownName("GJM backend", backend, BACKENDS)
    state = gjm.compute(q, v, backend)
    return state, time_derivatives(gjm.tree, state)


def derivatives(robot: Robot, q: np.ndarray, v: np.ndarray, backend: str = "compiled") -> GJMDerivatives:
    """Joint and time derivatives of the GJM inertia matrices at Pinocchio state (q, v).

    Derivative k is with respect to joint k (Pinocchio order) at fixed base pose and twist; the
    time derivatives follow the motion given by v (base twist and joint rates). ``backend``:
    ``"compiled"`` (default) or ``"numpy"``, the reference.

    Raises:
        InvalidArgument: for q or v of the wrong size, not finite, or a non-unit quaternion.
    """
    gjm, q, v = checked_state(robot, q, v)
    if backend == "compiled":
        return GJMDerivatives(*gjm.core.derivatives(q, v))
    return state_and_derivatives(gjm, q, v, backend)[1]
