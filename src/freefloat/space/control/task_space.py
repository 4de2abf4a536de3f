"""Task-space computed torque through the inverse E-GJM (dissertation sec 4.4, eqs 138-139).

End-effector rate references become joint references at every control period:
``qdot_d = J*{k}^+ (xdot_d - J0E{k} H0^-1 M)`` at the measured state (eq 138, guarded by
:class:`~freefloat.space.control.inverse_egjm.InverseEGJM`), ``q_d(k) = q_d(k-1) + qdot_d T`` (eq 139),
``qddot_d`` by the backward difference of ``qdot_d`` over the period; then the joint-space
computed-torque law (eqs 136-137) on the chosen model.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ...dynamics import gjm
from ...robot.joints import JointCoordinates
from ...robot.robot import Robot
from .computed_torque import ControllerDynamics
from .inverse_egjm import InverseEGJM

#: ``reference(t) -> xdot_d``: end-effector rates of the task rows (len(rows),), inertial frame.
RateReference = Callable[[float], np.ndarray]


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
    """

    def __init__(self, robot: Robot, inverse: InverseEGJM, reference: RateReference, q_d0: np.ndarray,
                 control_period: float, kp: float = 10.0, kd: float = 100.0, model: str = "exact"):
        self.robot, self.inverse, self.rate_reference = robot, inverse, reference
        self.T, self.kp, self.kd = control_period, kp, kd
        self.dynamics = ControllerDynamics(robot, model)
        self.joints = JointCoordinates(robot)
        self.q_d = np.array(q_d0, dtype=float)
        self._qdot_prev: np.ndarray | None = None
        self.condition_numbers: list[float] = []

    def reference_joint(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance eq 139 by one period and return ``(q_d, qdot_d, qddot_d)`` (each (n,))."""
        state = gjm.compute(self.robot, q, v)
        self.condition_numbers.append(self.inverse.condition(state))
        qdot_d = self.inverse.joint_rates(state, self.rate_reference(t))
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
