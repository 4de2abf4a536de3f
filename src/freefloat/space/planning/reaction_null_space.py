"""Resolved-rate laws for an end-effector task of a free-floating robot: the minimum-norm GJM
solution and Yoshida's reaction null space (RNS).

With total momentum ``M`` (about the base CoM, inertial frame) the end-effector velocity is
``x_Edot = J* qdot + J0E H0^-1 M`` (eq 88) and the base twist ``x0dot = J0 qdot + H0^-1 M``
(eq 71). For the task rows ``k`` and the mission joints ``S``:

- **min_norm**: :math:`\\dot q_S = J^*\\{k,S\\}^+ (\\dot x_d - J_{0E}\\{k\\} H_0^{-1} M)`;
  the base turns as the coupling makes it.
- **null_space** (reaction null space): the base-attitude rows ``a`` of ``x0dot`` come first,
  :math:`A = J_0\\{a,S\\}`, :math:`b = -(H_0^{-1} M)\\{a\\}`, and the task is solved inside the
  null space of ``A``:

  .. math:: \\dot q_S = A^+ b + (J P)^+ (r - J A^+ b), \\quad P = I - A^+ A,
     \\quad J = J^*\\{k,S\\}, \\quad r = \\dot x_d - J_{0E}\\{k\\} H_0^{-1} M,

  so the base angular velocity is zero (exactly ``A qdot_S = b``) whenever ``A`` has full row rank.
  At zero momentum these are the joint rates that leave no reaction on the base attitude
  (Yoshida's reaction null space); the task is met when ``J P`` still has full row rank.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...dynamics.gjm import GJMState
from ...robot.robot import Robot

#: Singular values below this fraction of the scale of their matrix's source (J* for the task,
#: J0 for the attitude rows) are dropped by the pseudo-inverses.
RCOND = 1e-10


@dataclass(frozen=True)
class TaskRows:
    """Which rows and joints a resolved-rate law uses.

    Attributes:
        rows: rows of the stacked ``[v_E; w_E]`` per end-effector (r,).
        attitude: rows of the base twist ``[v0; w0]`` that are its angular velocity: (3,) on a
            free base (wx, wy, wz), (1,) on a planar one (wz).
        joints: the mission joints, indices into the actuated joints (s,).
    """

    rows: np.ndarray
    attitude: np.ndarray
    joints: np.ndarray

    @classmethod
    def position(cls, robot: Robot, end_effectors: tuple[str, ...], joints: np.ndarray | None = None,
                 angular: tuple[int, ...] | np.ndarray = ()) -> TaskRows:
        """The end-effectors' linear rows (vx, vy, vz; vx, vy on a planar base) and then their
        ``angular`` components (indices into wx, wy, wz), hand after hand, and the base's attitude
        rows, with ``joints`` (default all)."""
        planar = robot.base == "planar"
        components = np.concatenate((np.arange(2 if planar else 3), 3 + np.asarray(angular, int)))
        rows = np.concatenate([6 * robot.end_effectors.index(name) + components for name in end_effectors])
        attitude = np.array([5]) if planar else np.arange(3, 6)
        return cls(rows, attitude, np.arange(robot.n_joints) if joints is None else np.asarray(joints, int))


#: A resolved-rate law: joint rates (n,) from the GJM state, the momentum about the base CoM
#: (6,), the task velocity of the rows (r,) and the rows.
RateLaw = Callable[[GJMState, np.ndarray, np.ndarray, TaskRows], np.ndarray]


def _task(state: GJMState, momentum_base: np.ndarray, task_velocity: np.ndarray,
          task: TaskRows) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(J, r, drift)``: ``J*{k,S}``, the task's right-hand side ``xdot_d - J0E{k} H0^-1 M`` and
    the base twist's drift ``H0^-1 M`` (6,)."""
    drift = np.linalg.solve(state.H0, momentum_base)
    return state.Jstar[np.ix_(task.rows, task.joints)], task_velocity - state.J0E[task.rows] @ drift, drift


def pinv(M: np.ndarray, scale: float) -> np.ndarray:
    """Pseudo-inverse of M (r, s) dropping singular values up to ``RCOND * scale``: a cut fixed by
    the source matrix, not by M itself (a projected ``J P`` or a coupling ``A`` made of round-off
    would otherwise be inverted as if it were real, giving rates of 1e15)."""
    U, sigma, Vt = np.linalg.svd(M, full_matrices=False)
    keep = sigma > RCOND * scale
    return (Vt[keep].T / sigma[keep]) @ U[:, keep].T


def _full(state: GJMState, task: TaskRows, q_S: np.ndarray) -> np.ndarray:
    """Joint rates (n,) zero outside the mission joints."""
    qdot = np.zeros(state.Jstar.shape[1])
    qdot[task.joints] = q_S
    return qdot


def min_norm_rates(state: GJMState, momentum_base: np.ndarray, task_velocity: np.ndarray,
                   task: TaskRows) -> np.ndarray:
    """The minimum-norm GJM solution ``J*{k,S}^+ (xdot_d - J0E{k} H0^-1 M)`` (n,)."""
    J, r, _ = _task(state, momentum_base, task_velocity, task)
    return _full(state, task, pinv(J, max(np.abs(state.Jstar).max(), 1.0)) @ r)


def reaction_null_space_rates(state: GJMState, momentum_base: np.ndarray, task_velocity: np.ndarray,
                              task: TaskRows) -> np.ndarray:
    """Zero base angular velocity first, then the task in the reaction null space (n,); see the
    module docstring."""
    J, r, drift = _task(state, momentum_base, task_velocity, task)
    A = state.J0[np.ix_(task.attitude, task.joints)]
    A_pinv = pinv(A, max(np.abs(state.J0).max(), 1.0))
    particular = A_pinv @ -drift[task.attitude]
    P = np.eye(len(task.joints)) - A_pinv @ A
    return _full(state, task, particular + pinv(J @ P, max(np.abs(state.Jstar).max(), 1.0)) @ (r - J @ particular))


#: The resolved-rate laws by scene name.
RATE_LAWS: dict[str, RateLaw] = {"min_norm": min_norm_rates, "null_space": reaction_null_space_rates}
