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

Eq 139 integrates the rates open loop (:data:`OPEN_LOOP`, the printed form): any drift of the
end-effectors from their path stays. Given a pose reference and a gain ``kx`` > 0
(:data:`POSITION_FEEDBACK`, the closed-loop inverse kinematics that sec 4.4's "position-level IK"
points to), the rates are corrected by the measured pose error before the inversion:

.. math::
    \dot q_d = J^{*+}_{\{k\}} (\dot x_d + K_x e_x - b),\quad
    e_x = \begin{bmatrix} p_d - p \\ \log_3(R_d R^T) \end{bmatrix}_{\{k\}}

per end-effector (inertial axes, the rows of its twist ``[v; w]``), ``p, R`` from Pinocchio's
forward kinematics at the measured configuration. With a perfect inner loop the task error then
obeys ``de_x/dt = -K_x e_x``.

Then the joint-space computed-torque law (eqs 136-137) on the chosen model.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin

from ...dynamics import gjm
from ...errors import UnknownName
from ...robot.joints import JointCoordinates
from ...robot.robot import Robot
from .computed_torque import ControllerDynamics
from .inverse_egjm import InverseEGJM

#: ``reference(t) -> xdot_d``: end-effector rates of the task rows (len(rows),), inertial frame.
RateReference = Callable[[float], np.ndarray]

#: ``pose_reference(t) -> [M_d]``: the end-effectors' desired placements (pin.SE3, one per
#: end-effector in ``robot.end_effector_frame_ids`` order), inertial frame.
PoseReference = Callable[[float], Sequence[pin.SE3]]

#: The two forms of the joint reference: eq 139 as printed, and with task-space position feedback.
OPEN_LOOP, POSITION_FEEDBACK = "open_loop", "position_feedback"

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
        pose_reference: the end-effectors' desired placements for position feedback; None:
            eq 139 open loop (:data:`OPEN_LOOP`).
        kx: position feedback gain K_x, 1/s (> 0 with ``pose_reference``).

    Raises:
        UnknownName: for a ``qddot`` method not in :data:`QDDOT_METHODS`.
        ValueError: for ``kx`` <= 0 with a pose reference, or ``kx`` without one.
    """

    def __init__(self, robot: Robot, inverse: InverseEGJM, reference: RateReference, q_d0: np.ndarray,
                 control_period: float, kp: float = 10.0, kd: float = 100.0, model: str = "exact",
                 qddot: str = "analytic", acceleration: RateReference | None = None,
                 pose_reference: PoseReference | None = None, kx: float = 0.0):
        if qddot not in QDDOT_METHODS:
            raise UnknownName("qddot method", qddot, QDDOT_METHODS)
        if (pose_reference is None) != (kx == 0.0) or kx < 0.0:
            raise ValueError(f"position feedback needs both a pose reference and a gain kx > 0 (1/s), got "
                             f"kx={kx} and {'a' if pose_reference is not None else 'no'} pose reference")
        self.pose_reference, self.kx = pose_reference, kx
        self.form = OPEN_LOOP if pose_reference is None else POSITION_FEEDBACK
        self._data = robot.model.createData()
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

    def pose_error(self, t: float, q: np.ndarray) -> np.ndarray:
        """``e_x`` of the task rows (len(rows),): desired minus measured pose of each end-effector,
        ``[p_d - p; log3(R_d R^T)]`` in inertial axes (m, rad), Pinocchio's forward kinematics at ``q``."""
        model, data = self.robot.model, self._data
        pin.framesForwardKinematics(model, data, q)
        errors = []
        for fid, desired in zip(self.robot.end_effector_frame_ids, self.pose_reference(t)):
            M = data.oMf[fid]
            errors += [desired.translation - M.translation, pin.log3(desired.rotation @ M.rotation.T)]
        return np.concatenate(errors)[self.inverse.rows]

    def reference_joint(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance eq 139 by one period and return ``(q_d, qdot_d, qddot_d)`` (each (n,))."""
        xdot_ref = self.rate_reference(t)
        xdot = xdot_ref if self.pose_reference is None else xdot_ref + self.kx * self.pose_error(t, q)
        rows = self.inverse.rows
        if self.qddot_method == "analytic":
            state, rates = gjm.state_and_rates(self.robot, q, v)
        else:
            state = gjm.compute(self.robot, q, v)
        self.condition_numbers.append(self.inverse.condition(state))
        qdot_d = self.inverse.joint_rates(state, xdot)
        if self.qddot_method == "analytic":
            rate = pinv_rate(state.Jstar[rows], rates.Jstar_dot[rows], self.inverse.damping)
            xddot = self.reference_acceleration(t, xdot_ref)
            if self.pose_reference is not None:  # d/dt of K_x e_x: K_x (xdot_d - the measured task rates)
                xddot = xddot + self.kx * (xdot_ref - state.end_effector_velocity()[rows])
            qddot_d = rate(xdot - rates.drift[rows], xddot - rates.drift_dot[rows])
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
