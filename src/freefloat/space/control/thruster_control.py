r"""Base pose held by thrusters, and the reaction wheels' momentum dumped through them.

Each control period, with the base joint's pose ``(R, p)`` (inertial frame) and its local velocity
``[v; w]`` (base frame; Pinocchio's free-flyer ``v[:6]``), the pose latched at the first period
``(R_d, p_d)`` is held by a PD law on the locked robot (computed torque on its composite rigid
body, the arms' motion relative to the base neglected):

.. math::
    a_d = K_p \begin{bmatrix} R^T (p_d - p) \\ \log(R^T R_d) \end{bmatrix}
          - K_d \begin{bmatrix} v \\ \omega \end{bmatrix}, \qquad
    w = M_{00}(q)\, a_d,

``M_00`` the base block of the joint-space inertia matrix (the whole robot's spatial inertia at the
base joint's origin, base frame). The thrusters' allocation turns ``w`` into thrusts
(:meth:`~freefloat.space.thrusters.ThrusterSet.allocate`), held over the period as pulses.

Momentum dumping adds wheel torques that brake every wheel toward zero stored momentum,
``tau_i = clip(-k I_i Omega_i, +-tau_max)``, and feeds their reaction on the base forward into the
thrusters' torque, ``n += sum_i tau_i a_i`` (``a_i`` the spin axes, base frame): the base stays
held while the angular momentum the wheels stored leaves the system through the thrusters'
angular impulse. The arm joints get no torque.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...robot.robot import Robot
from ...robot.wheels import Wheels
from ..thrusters import ThrusterSet

__all__ = ["ThrusterHold"]


class ThrusterHold:
    """Thrusters holding the base's pose, and (with ``wheels``) dumping their momentum.

    Implements :class:`~freefloat.dynamics.simulation.Controller` (module docstring for the law).

    Args:
        robot: the robot (a free-flyer base); with wheels, ``wheels.robot``.
        thrusters: the thrusters on its base, which this law commands each period.
        control_period: the zero-order-hold period, s.
        kp: pose stiffness, 1/s^2. kd: pose damping, 1/s.
        wheels: the reaction wheels to dump (None: hold only).
        dump_rate: ``k``, the rate at which the wheels' stored momentum is braked, 1/s.

    Attributes:
        drives_wheels: whether this law sets the wheel torques itself (so no ``[attitude]`` law is
            composed with it).
        target: the held base joint pose (inertial), latched at the first period (None before).
    """

    def __init__(self, robot: Robot, thrusters: ThrusterSet, control_period: float, kp: float, kd: float,
                 wheels: Wheels | None = None, dump_rate: float = 0.0):
        self.model, self.data = robot.model, robot.model.createData()
        self.n_base, self.n_joints = robot.n_base, robot.n_joints
        self.thrusters, self.period, self.kp, self.kd = thrusters, control_period, kp, kd
        self.wheels, self.dump_rate = wheels, dump_rate
        self.drives_wheels = wheels is not None
        self.target: pin.SE3 | None = None

    def reference(self, t: float) -> None:
        """No joint reference (the law holds the base)."""
        return None

    def base_placement(self, q: np.ndarray) -> pin.SE3:
        """The base joint's pose in the inertial frame."""
        return self.model.jointPlacements[1] * pin.XYZQUATToSE3(q[:7])

    def base_wrench(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The PD wrench ``M_00 a_d`` at the base joint's origin, base frame (6,)."""
        placement = self.base_placement(q)
        if self.target is None:
            self.target = placement
        error = np.concatenate((placement.rotation.T @ (self.target.translation - placement.translation),
                                pin.log3(placement.rotation.T @ self.target.rotation)))
        M = np.triu(pin.crba(self.model, self.data, q)[:6, :6])  # Pinocchio fills the upper triangle
        return (M + np.triu(M, 1).T) @ (self.kp * error - self.kd * v[:6])

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (n_joints,): the wheels' dumping torques (zero elsewhere); commands the
        thrusters for the period starting at ``t``."""
        wrench = self.base_wrench(q, v)
        tau = np.zeros(self.n_joints)
        if self.wheels is not None:
            w = self.wheels
            tau_w = np.clip(-self.dump_rate * w.momenta(v), -w.max_torques, w.max_torques)
            wrench[3:] += w.axes() @ tau_w
            tau[w.columns] = tau_w
        self.thrusters.command(t, self.thrusters.allocate(wrench), self.period)
        return tau
