"""Task-space computed torque through the inverse E-GJM (dissertation sec 4.4, eqs 138-139).

End-effector rate references become joint references at every control period:
``qdot_d = J*{k}^+ (xdot_d - b)`` with ``b = J0E{k} H0^-1 M`` at the measured state (eq 138,
guarded by :class:`~freefloat.space.control.inverse_egjm.InverseEGJM`),
``q_d(k) = q_d(k-1) + qdot_d T`` (eq 139), and ``qddot_d`` by one of :data:`QDDOT_METHODS`:

- ``"analytic"`` (default): the time derivative of eq 138 along the measured motion, with the
  E-GJM's derivative from :func:`freefloat.dynamics.gjm.jacobian_rates`:

  .. math::
      \\ddot q_d = \\dot{(J^+)} (\\dot x_d - b) + J^+ (\\ddot x_d - \\dot b),\\quad
      \\dot{(J^+)} = -J^+ \\dot J J^+ + J^+ J^{+T} \\dot J^T (I - J J^+) + (I - J^+ J) \\dot J^T J^{+T} J^+

  (the derivative of the pseudo-inverse at constant rank; with damping lambda the derivative of
  ``J^T (J J^T + lambda^2 I)^-1 (xdot_d - b)`` instead);
- ``"backward_difference"``: ``(qdot_d(k) - qdot_d(k-1)) / T``, the dissertation's own method.

Then the joint-space computed-torque law (eqs 136-137) on the chosen model.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...dynamics import gjm
from ...errors import UnknownName
from ...robot.joints import JointCoordinates
from ...robot.robot import Robot
from .computed_torque import ControllerDynamics
from .inverse_egjm import InverseEGJM

#: ``reference(t) -> xdot_d``: end-effector rates of the task rows (len(rows),), inertial frame.
RateReference = Callable[[float], np.ndarray]

#: How the law obtains the joint acceleration reference ``qddot_d``.
QDDOT_METHODS = ("analytic", "backward_difference")


def pinv_rate(J: np.ndarray, J_dot: np.ndarray, damping: float = 0.0) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """``(e, e_dot) -> d/dt [J^+ e]`` (n,) for ``J`` (m, n) changing at ``J_dot`` (m, n).

    Undamped: the pseudo-inverse's derivative at constant rank (Golub and Pereyra). Damped
    (``lambda = damping > 0``): the derivative of ``J^T W^-1 e`` with ``W = J J^T + lambda^2 I``.
    """
    if damping > 0.0:
        W = J @ J.T + damping**2 * np.eye(len(J))

        def damped(e: np.ndarray, e_dot: np.ndarray) -> np.ndarray:
            y = np.linalg.solve(W, e)
            return J_dot.T @ y + J.T @ np.linalg.solve(W, e_dot - (J_dot @ (J.T @ y) + J @ (J_dot.T @ y)))
        return damped
    P = np.linalg.pinv(J)

    def plain(e: np.ndarray, e_dot: np.ndarray) -> np.ndarray:
        x = P @ e
        left = e - J @ x                              # (I - J J^+) e
        return (-P @ (J_dot @ x) + P @ (P.T @ (J_dot.T @ left)) + J_dot.T @ (P.T @ x)
                - P @ (J @ (J_dot.T @ (P.T @ x))) + P @ e_dot)
    return plain


class TaskSpaceComputedTorque:
    """Task-space tracking by joint-space computed torque on references from the inverse E-GJM.

    Args:
        robot: the robot.
        inverse: the guarded inversion (task rows, damping, thresholds).
        reference: end-effector rate reference of the task rows.
        q_d0: initial joint reference (n,), normally the initial joint positions.
        control_period: T of eq 139, s.
        kp, kd: gains (the dissertation keeps Kp = 10, Kd = 100).
        model: dynamics model of the computed-torque law.
        qddot: one of :data:`QDDOT_METHODS`.
        acceleration: ``t -> xddot_d`` (len(rows),), the reference's time derivative, for
            ``"analytic"``; None: the reference's backward difference over the period.

    Raises:
        UnknownName: for a ``qddot`` method not in :data:`QDDOT_METHODS`.
    """

    def __init__(self, robot: Robot, inverse: InverseEGJM, reference: RateReference, q_d0: np.ndarray,
                 control_period: float, kp: float = 10.0, kd: float = 100.0, model: str = "exact",
                 qddot: str = "analytic", acceleration: RateReference | None = None):
        if qddot not in QDDOT_METHODS:
            raise UnknownName("qddot method", qddot, QDDOT_METHODS)
        self.robot, self.inverse, self.rate_reference = robot, inverse, reference
        self.T, self.kp, self.kd = control_period, kp, kd
        self.qddot_method, self.acceleration = qddot, acceleration
        self.dynamics = ControllerDynamics(robot, model)
        self.joints = JointCoordinates(robot)
        self.q_d = np.array(q_d0, dtype=float)
        self._qdot_prev: np.ndarray | None = None
        self.condition_numbers: list[float] = []

    def reference_acceleration(self, t: float, xdot: np.ndarray) -> np.ndarray:
        """``xddot_d`` (len(rows),): the given derivative, or the reference's backward difference."""
        if self.acceleration is not None:
            return np.asarray(self.acceleration(t), dtype=float)
        return (xdot - self.rate_reference(t - self.T)) / self.T if t > 0.0 else np.zeros_like(xdot)

    def reference_joint(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance eq 139 by one period and return ``(q_d, qdot_d, qddot_d)`` (each (n,))."""
        xdot = self.rate_reference(t)
        rows = self.inverse.rows
        if self.qddot_method == "analytic":
            state, rates = gjm.state_and_rates(self.robot, q, v)
        else:
            state = gjm.compute(self.robot, q, v)
        self.condition_numbers.append(self.inverse.condition(state))
        qdot_d = self.inverse.joint_rates(state, xdot)
        if self.qddot_method == "analytic":
            rate = pinv_rate(state.Jstar[rows], rates.Jstar_dot[rows], self.inverse.damping)
            qddot_d = rate(xdot - rates.drift[rows], self.reference_acceleration(t, xdot) - rates.drift_dot[rows])
        else:
            qddot_d = np.zeros_like(qdot_d) if self._qdot_prev is None else (qdot_d - self._qdot_prev) / self.T
        if self._qdot_prev is not None:
            self.q_d = self.q_d + qdot_d * self.T
        self._qdot_prev = qdot_d
        return self.q_d.copy(), qdot_d, qddot_d

    def reference(self, t: float) -> np.ndarray:
        """The joint reference q_d of the current period (n,), for telemetry."""
        return self.q_d.copy()

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (n,) for the measured state (q, v) at time t."""
        q_d, qdot_d, qddot_d = self.reference_joint(t, q, v)
        nb = self.robot.n_base
        H, c = self.dynamics.at(t, q, v)
        return H @ (qddot_d + self.kp * (q_d - self.joints.get(q)) + self.kd * (qdot_d - v[nb:])) + c
