"""The GJM inertia matrices and Jacobians, built by hand from the body kinematics.

Conventions (dissertation sec 3.1-3.3): the base twist is ``x0dot = [v0; w0]``, velocity of the
base CoM r0 and angular velocity, inertial frame; joint rates ``qdot`` in Pinocchio's joint
order; every vector in the inertial frame. For body i (the base is body 0, with no joint
columns) with mass m_i, CoM r_i, inertia I_i about its CoM and ``r_0i = r_i - r0``:

.. math::
    J_{T_i}[:, j] = k_j \\times (r_i - p_j),\\quad J_{R_i}[:, j] = k_j
    \\quad (\\text{joint } j \\text{ revolute and moving body } i; \\text{ prismatic: } k_j, 0)

    H_m = \\sum_i J_{R_i}^T I_i J_{R_i} + m_i J_{T_i}^T J_{T_i}                     \\quad (19)

    H_{0m} = [\\sum_i m_i J_{T_i};\\; \\sum_i I_i J_{R_i} + m_i r_{0i}^\\times J_{T_i}]  \\quad (22)

    H_0 = [[M I_3, -M r_{0C}^\\times], [M r_{0C}^\\times, \\sum_i I_i - m_i r_{0i}^\\times r_{0i}^\\times]]  \\quad (23)

The sums run over every body, the base included, so a base whose merged body CoM is not r0
(fixed-jointed parts on the base) is handled; with the base CoM at r0 they are the printed ones.
"""

from __future__ import annotations

import numpy as np

from .kinematics import BodyKinematics, TreeStructure

# [x]x flattened: entries 5, 7 hold -x, +x; 2, 6 hold +y, -y; 1, 3 hold -z, +z
_SKEW_INDEX = np.array([5, 7, 2, 6, 1, 3])
_SKEW_SOURCE = np.array([0, 0, 1, 1, 2, 2])
_SKEW_SIGN = np.array([-1.0, 1.0, 1.0, -1.0, -1.0, 1.0])


def skew_batch(x: np.ndarray) -> np.ndarray:
    """Cross-product matrices of vectors (..., 3): (..., 3, 3), ``[x]x y = x cross y``."""
    out = np.zeros(x.shape[:-1] + (9,))
    out[..., _SKEW_INDEX] = x[..., _SKEW_SOURCE] * _SKEW_SIGN
    return out.reshape(x.shape + (3,))


def point_jacobians(tree: TreeStructure, kin: BodyKinematics, points: np.ndarray, moved: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Linear and angular Jacobians of points (m, 3), inertial frame: ``J_T, J_R`` (m, 3, n),
    eqs 20-21, for a fixed base.

    ``moved`` (m, n) bool: ``moved[i, j]`` says whether joint j moves point i. Column j of ``J_T`` is
    ``k_j x (x_i - p_j) = [k_j]x x_i - k_j x p_j`` (revolute, one GEMM for all pairs) or ``k_j``.
    """
    n = len(tree.parent)
    K = skew_batch(kin.joint_axis)
    swept = (K.reshape(3 * n, 3) @ points.T).reshape(n, 3, -1) - (K @ kin.joint_position[:, :, None])
    rev = tree.revolute[:, None, None]
    mask = moved.T[:, None, :]
    JT = np.where(rev, swept, kin.joint_axis[:, :, None]) * mask
    JR = np.where(rev, kin.joint_axis[:, :, None], 0.0) * mask
    return JT.transpose(2, 1, 0), JR.transpose(2, 1, 0)


def body_jacobians(tree: TreeStructure, kin: BodyKinematics) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians of every body CoM: ``J_T, J_R`` (n + 1, 3, n), base first (zero)."""
    return point_jacobians(tree, kin, kin.com, tree.ancestor)


def inertia_matrices(tree: TreeStructure, kin: BodyKinematics, JT: np.ndarray, JR: np.ndarray):
    """``(H0, H0m, Hm)``: (6, 6), (6, n), (n, n), eqs 19, 22, 23, for the base twist [v0; w0] of
    the base CoM (inertial frame), from the body CoM Jacobians ``JT, JR`` (n + 1, 3, n), base first."""
    m, inertia = tree.mass, kin.inertia
    n = JT.shape[2]
    r0i = kin.com - kin.r0
    IJR = inertia @ JR
    weighted = np.sqrt(m)[:, None, None] * JT
    Hm = JR.reshape(-1, n).T @ IJR.reshape(-1, n) + weighted.reshape(-1, n).T @ weighted.reshape(-1, n)
    J_TS = (m @ JT.reshape(len(m), -1)).reshape(3, n)
    H_Sq = IJR.sum(axis=0) + (m @ (skew_batch(r0i) @ JT).reshape(len(m), -1)).reshape(3, n)
    total = m.sum()
    r0C = m @ r0i / total
    # -[r]x[r]x = |r|^2 I - r r^T
    H_S = inertia.sum(axis=0) + (m @ (r0i * r0i).sum(axis=1)) * np.eye(3) - (m[:, None] * r0i).T @ r0i
    H0 = np.zeros((6, 6))
    H0[:3, :3] = total * np.eye(3)
    H0[3:, :3] = total * skew_batch(r0C)
    H0[:3, 3:] = -H0[3:, :3]
    H0[3:, 3:] = H_S
    return H0, np.vstack((J_TS, H_Sq)), 0.5 * (Hm + Hm.T)


def end_effector_points(kin: BodyKinematics, ee_body: np.ndarray, ee_offset: np.ndarray) -> np.ndarray:
    """End-effector frame origins (k, 3), inertial frame, from their body indices (k,) and their
    offsets in the body (parent-joint) frames (k, 3), m."""
    return kin.origin[ee_body] + (kin.rotation[ee_body] @ ee_offset[:, :, None])[:, :, 0]


def end_effector_jacobians(r0: np.ndarray, r_E: np.ndarray, JT: np.ndarray, JR: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``Jm`` (6k, n) from the point Jacobians of the end-effectors (k, 3, n), eq 76, and
    ``J0E`` (6k, 6), eq 78: one 6-row block [v_E; w_E] per end-effector, inertial frame.

    ``r0`` (3,) is the base CoM and ``r_E`` (k, 3) the end-effector frame origins, inertial frame."""
    Jm = np.concatenate((JT, JR), axis=1).reshape(-1, JT.shape[2])
    J0E = np.tile(np.eye(6), (len(r_E), 1, 1))
    J0E[:, :3, 3:] = -skew_batch(r_E - r0)
    return Jm, J0E.reshape(-1, 6)
