"""Analytic time derivatives of the GJM Jacobians along a motion (q, v).

Differentiates the formulas of :mod:`.matrices` and :mod:`.model` in time, with the base moving
(twist ``x0dot = [v0; w0]`` of the base CoM r0, inertial frame) and the joints at ``qdot``. The
rigid motion gives every ingredient: body b turns at ``w_b = w0 + sum_j k_j qdot_j`` (revolute
joints j moving b), so joint j's axis turns as ``kdot_j = w_b x k_j`` (b = the body joint j moves)
and a point x of body b moves at ``xdot = v0 + w0 x (x - r0) + J_T(x) qdot``. Then, for an
end-effector origin r_E:

.. math::
    \\dot J_m[:, j] = [\\dot k_j \\times (r_E - p_j) + k_j \\times (\\dot r_E - \\dot p_j);\\; \\dot k_j]
    \\quad (\\text{revolute}; \\text{ prismatic: } [\\dot k_j; 0])                     \\quad (76)

    \\dot J_{0E} = [[0, -[\\dot r_E - v_0]^\\times], [0, 0]]                            \\quad (78)

    \\frac{d}{dt}(H_0^{-1} H_{0m}) = H_0^{-1} (\\dot H_{0m} - \\dot H_0 H_0^{-1} H_{0m}),\\quad
    \\dot J_0 = -\\frac{d}{dt}(H_0^{-1} H_{0m})                                        \\quad (71)

    \\dot J^* = \\dot J_m + \\dot J_{0E} J_0 + J_{0E} \\dot J_0                           \\quad (82, 89)

and the E-GJM's momentum term of eq 88, ``b = J0E H0^-1 M``, changes as
``bdot = J0Edot H0^-1 M - J0E H0^-1 H0dot H0^-1 M + J0E H0^-1 Mdot`` with, free of external
wrenches on a free base, ``Mdot = [0; -v0 x P]`` (P is conserved; L is taken about the moving point
r0); a planar base held in its plane, or external wrenches, need their ``Mdot`` passed in.
``H0dot``, ``H0mdot`` come from :func:`~freefloat.dynamics.gjm.derivatives`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...robot.robot import Robot
from .derivatives import GJMDerivatives, state_and_derivatives
from .matrices import body_jacobians, point_jacobians, skew_batch
from .model import GJMState, checked_state, model_of


class GJMRates(NamedTuple):
    """Time derivatives of the GJM Jacobians along the motion (q, v). ``n`` joints, ``k``
    end-effectors; rows ``[v_E; w_E]`` per end-effector (frame origin, inertial frame) in
    ``robot.end_effectors`` order, columns in Pinocchio's joint order, as in :class:`GJMState`.

    Attributes:
        Jm_dot: ``d Jm / dt`` (6k, n).
        J0E_dot: ``d J0E / dt`` (6k, 6).
        H0inv_H0m_dot: ``d (H0^-1 H0m) / dt`` (6, n), for the base twist [v0; w0] of the base CoM.
        J0_dot: ``d J0 / dt = -d (H0^-1 H0m) / dt`` (6, n).
        Jstar_dot: ``d J* / dt`` (6k, n): the GJM's, for several end-effectors the E-GJM's.
        drift: the E-GJM's momentum term ``b = J0E H0^-1 M`` of eq 88 (6k,).
        drift_dot: ``d b / dt`` (6k,) for the given momentum rate, by default a free base with no
            external wrench (``Mdot = [0; -v0 x P]``).
    """

    Jm_dot: np.ndarray
    J0E_dot: np.ndarray
    H0inv_H0m_dot: np.ndarray
    J0_dot: np.ndarray
    Jstar_dot: np.ndarray
    drift: np.ndarray
    drift_dot: np.ndarray


def rates_of(gjm, state: GJMState, deriv: GJMDerivatives, momentum_rate: np.ndarray | None = None) -> GJMRates:
    """The rates at a state and its inertia-matrix derivatives, already computed; ``momentum_rate``
    is ``Mdot`` (6,) for ``drift_dot`` (None: free base, no external wrench)."""
    tree, kin = gjm.tree, state.kinematics
    v0, w0, qdot = state.x0dot[:3], state.x0dot[3:], state.qdot
    moves_joint = tree.ancestor[1:]                   # joint j's point and axis ride on body j + 1
    _, JR = body_jacobians(tree, kin)
    w_body = w0 + JR[1:] @ qdot                       # (n, 3): angular velocity of body j + 1
    k, p = kin.joint_axis, kin.joint_position
    k_dot = np.cross(w_body, k)
    JTp, _ = point_jacobians(tree, kin, p, moves_joint)
    p_dot = v0 + np.cross(w0, p - kin.r0) + JTp @ qdot
    r_E = state.ee_position
    r_E_dot = v0 + np.cross(w0, r_E - kin.r0) + state.Jm.reshape(-1, 6, len(qdot))[:, :3] @ qdot

    # column j of end-effector e: revolute [k x (r_E - p); k], prismatic [k; 0], where j moves e
    lever, lever_dot = r_E[:, None] - p[None], r_E_dot[:, None] - p_dot[None]      # (k, n, 3)
    linear = np.where(tree.revolute[None, :, None],
                      np.cross(k_dot[None], lever) + np.cross(k[None], lever_dot), k_dot[None])
    angular = np.where(tree.revolute[None, :, None], k_dot[None], 0.0)
    mask = gjm.moved[len(tree.mass):][:, :, None]                                      # (k, n, 1)
    Jm_dot = np.concatenate(((linear * mask).transpose(0, 2, 1), (angular * mask).transpose(0, 2, 1)), axis=1)
    Jm_dot = Jm_dot.reshape(-1, len(qdot))

    J0E_dot = np.zeros((len(r_E), 6, 6))
    J0E_dot[:, :3, 3:] = -skew_batch(r_E_dot - v0)
    J0E_dot = J0E_dot.reshape(-1, 6)

    H0 = state.H0
    H0inv_H0m_dot = np.linalg.solve(H0, deriv.H0mdot + deriv.H0dot @ state.J0)
    J0_dot = -H0inv_H0m_dot
    Jstar_dot = Jm_dot + J0E_dot @ state.J0 + state.J0E @ J0_dot

    M = state.momentum_base
    base_rate = np.linalg.solve(H0, M)
    M_dot = np.concatenate((np.zeros(3), -np.cross(v0, M[:3]))) if momentum_rate is None else momentum_rate
    drift_dot = J0E_dot @ base_rate + state.J0E @ np.linalg.solve(H0, M_dot - deriv.H0dot @ base_rate)
    return GJMRates(Jm_dot=Jm_dot, J0E_dot=J0E_dot, H0inv_H0m_dot=H0inv_H0m_dot, J0_dot=J0_dot,
                    Jstar_dot=Jstar_dot, drift=state.J0E @ base_rate, drift_dot=drift_dot)


def state_and_rates(robot: Robot, q: np.ndarray, v: np.ndarray, backend: str = "compiled",
                    momentum_rate: np.ndarray | None = None) -> tuple[GJMState, GJMRates]:
    """The GJM state at (q, v) and its Jacobians' time derivatives, sharing one evaluation."""
    gjm = model_of(robot)
    state, deriv = state_and_derivatives(gjm, q, v, backend)
    return state, rates_of(gjm, state, deriv, momentum_rate)


def jacobian_rates(robot: Robot, q: np.ndarray, v: np.ndarray, backend: str = "compiled",
                   momentum_rate: np.ndarray | None = None) -> GJMRates:
    """Time derivatives of Jm, J0E, H0^-1 H0m, J0 and J* (the E-GJM) at Pinocchio state (q, v).

    The derivatives follow the motion that v gives (base twist and joint rates); the matrices
    depend on q only, so they are the derivatives along any path through q with velocity v.
    ``backend`` picks the implementation of the state and of H0dot, H0mdot (:data:`BACKENDS`);
    the rates themselves are numpy. ``momentum_rate``: ``Mdot`` (6,) for ``drift_dot``, [P; L about
    r0] rates in the inertial frame (None: free base, no external wrench).

    Raises:
        InvalidArgument: for q or v of the wrong size, not finite, or a non-unit quaternion.
    """
    _, q, v = checked_state(robot, q, v)
    return state_and_rates(robot, q, v, backend, momentum_rate)[1]
