"""Tracking the detumbling solution (dissertation sec 3.8, eq 134) with computed torque.

Before ``start`` the joints hold their initial posture (computed torque, Kp, Kd). From ``start``
on, each control period solves :func:`freefloat.space.detumbling.solve` at the measured state for the
joint rates ``qdot_d`` that stop the task rows, and drives the joints onto them:

.. math:: \\tau = H (\\ddot q_d + K_d (\\dot q_d - \\dot q)) + c,

with ``qddot_d`` the backward difference of ``qdot_d`` over the period and ``(H, c)`` the chosen
model's joint-space form. With the exact model the compiled loop runs the same law in C++
(:meth:`DetumblingController.compiled_law`); this class stays the readable reference.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ...dynamics import gjm
from ...robot.joints import JointCoordinates
from ...robot.robot import Robot
from ..detumbling import check_task, solve
from .computed_torque import ControllerDynamics


@dataclass
class DetumblingLaw:
    """The detumbling controller (``DetumblingController``, dissertation sec 3.8, eq 134) as the
    compiled loop runs it, with the exact ``H*``, ``c*`` and the detumbling solve of
    ``freefloat.space.detumbling.solve`` on Pinocchio's Jacobians.

    Attributes:
        rows: stacked end-effector rows to stop (r,), into the 6k rows ``[v_E; w_E]``.
        joints: mission joint indices (s,).
        method: ``single``, ``min_norm``, ``null_space`` or ``least_squares``.
        secondary: ``null_space``'s objective, ``base_angular_velocity`` or ``base_twist``.
        rcond: the solver's pseudo-inverse cut (singular values not above ``rcond`` times the largest).
        start: time the detumbling starts, s (before it: hold the posture).
        kp, kd: gains, 1/s^2 and 1/s.
        period: the backward-difference period of ``qddot_d``, s.
        hold: the held joint positions (n,), or None for those at the first period.
        previous: the previous detumbling period's ``qdot_d`` (n,), or None.
        report: called after each compiled chunk with ``(hold, previous, residuals)``, the
            residuals the max ``|residual|`` of each detumbling period of the chunk (the
            controller keeps its state current through it).
    """

    rows: np.ndarray
    joints: np.ndarray
    method: str
    secondary: str
    rcond: float
    start: float
    kp: float
    kd: float
    period: float
    hold: np.ndarray | None
    previous: np.ndarray | None
    report: Callable[[np.ndarray | None, np.ndarray | None, np.ndarray], None]

    kind: ClassVar[str] = "detumbling"

    def install(self, simulation: Any, robot: Robot) -> None:
        """Hand this law to the compiled loop (``_sim.Simulation.set_detumbling``)."""
        simulation.set_detumbling([int(r) for r in self.rows], [int(j) for j in self.joints], self.method,
                                  self.secondary, self.rcond, self.start, self.kp, self.kd, self.period, self.hold,
                                  self.previous)

    def collect(self, simulation: Any) -> None:
        """Hand the state the compiled loop kept over a chunk to :attr:`report`."""
        self.report(*simulation.take_detumbling_state())


class DetumblingController:
    """Hold, then detumble.

    Args:
        robot: the robot (with the captured target merged in, for a real capture).
        rows: stacked end-effector rows to stop (``freefloat.space.detumbling.task_rows``).
        joints: mission joint indices (``freefloat.space.detumbling.joint_indices``).
        start: time the detumbling starts, s (before it: hold the posture).
        control_period: T, s.
        method: solver method (``min_norm``, ``single``, ``null_space``, ``least_squares``).
        kp, kd: gains, 1/s^2 and 1/s.
        model: dynamics model of the computed-torque law.
    """

    def __init__(self, robot: Robot, rows: np.ndarray, joints: np.ndarray, start: float, control_period: float,
                 method: str = "min_norm", kp: float = 10.0, kd: float = 100.0, model: str = "exact"):
        self.robot, self.rows, self.joints, self.start, self.T = robot, rows, joints, start, control_period
        self.method, self.kp, self.kd = method, kp, kd
        self.dynamics = ControllerDynamics(robot, model)
        self.coords = JointCoordinates(robot)
        self.hold: np.ndarray | None = None
        self._qdot_prev: np.ndarray | None = None
        self.residuals: list[float] = []

    def compiled_law(self) -> DetumblingLaw | None:
        """This law for the compiled loop (:mod:`freefloat.dynamics.compiled`), with the state it
        has so far; None (the Python law) for a controller model other than ``exact``, or a task
        :func:`~freefloat.space.detumbling.solve` refuses (its error then comes from Python)."""
        if self.dynamics.model.name != "exact":
            return None
        try:
            check_task(self.rows, self.joints, self.method)
        except ValueError:
            return None
        return DetumblingLaw(self.rows, self.joints, self.method, "base_angular_velocity", 1e-10, self.start, self.kp,
                             self.kd, self.T, self.hold, self._qdot_prev, self._absorb)

    def _absorb(self, hold: np.ndarray | None, qdot_prev: np.ndarray | None, residuals: np.ndarray) -> None:
        """Take over the compiled law's state after a chunk (see :class:`DetumblingLaw`)."""
        self.hold, self._qdot_prev = hold, qdot_prev
        self.residuals.extend(residuals.tolist())

    def reference(self, t: float) -> np.ndarray | None:
        """The held posture before the start (n,), None afterwards."""
        return self.hold if t < self.start else None

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (n,) at time t for the measured state."""
        nb = self.robot.n_base
        if self.hold is None:
            self.hold = self.coords.get(q)
        H, c = self.dynamics.at(t, q, v)
        if t < self.start:
            return H @ (self.kp * (self.hold - self.coords.get(q)) - self.kd * v[nb:]) + c
        sol = solve(gjm.compute(self.robot, q, v), self.rows, self.joints, self.method)
        self.residuals.append(float(np.abs(sol.residual).max()))
        qddot_d = np.zeros_like(sol.qdot) if self._qdot_prev is None else (sol.qdot - self._qdot_prev) / self.T
        self._qdot_prev = sol.qdot
        return H @ (qddot_d + self.kd * (sol.qdot - v[nb:])) + c
