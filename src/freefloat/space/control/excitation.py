"""An identification manoeuvre: chosen joints track a Fourier-series trajectory (Swevers et al.
1997, :class:`~freefloat.dynamics.identification.excitation.FourierTrajectory`) about the
posture they start from, the others hold theirs, by computed torque on the model the controller
has (a robot that does not know what it carries yet: the tracking is then approximate, and the
identification reads the motion that happened, not the reference).
"""

from __future__ import annotations

import numpy as np

from ...dynamics.identification.excitation import FourierTrajectory
from ...errors import BadShape
from ...robot.joints import JointCoordinates
from ...robot.robot import Robot
from .computed_torque import ControllerDynamics


class ExcitationTracking:
    """``tau = H (qddot_d + kp e + kd edot) + c`` on the robot's joints (eqs 136-137), the
    reference ``q_d = hold + [0; f(t - start)]`` on ``joints`` (f a Fourier series that starts
    at 0 displacement: its offset is subtracted) and ``hold`` elsewhere, ``hold`` the joints'
    posture at the first call.

    Args:
        robot: the robot the controller believes (its ``H``, ``c``).
        trajectory: the series of the moved joints, offset ignored (n_moved coordinates).
        joints: indices of the moved joints among the robot's joints (n_moved,).
        kp, kd: gains, 1/s^2 and 1/s.
        start: time the manoeuvre starts, s.
        model: dynamics model of the law (see :data:`freefloat.models.MODELS`).

    Raises:
        BadShape: when the series does not have one coordinate per moved joint.
    """

    def __init__(self, robot: Robot, trajectory: FourierTrajectory, joints: np.ndarray, kp: float, kd: float,
                 start: float = 0.0, model: str = "exact"):
        self.robot, self.joints, self.kp, self.kd, self.start = robot, np.asarray(joints, int), kp, kd, start
        if trajectory.a.shape[0] != len(self.joints):
            raise BadShape(f"excitation: the trajectory has {trajectory.a.shape[0]} coordinates for "
                           f"{len(self.joints)} moved joints")
        self.trajectory = trajectory
        self.dynamics = ControllerDynamics(robot, model)
        self.coords = JointCoordinates(robot)
        self.hold: np.ndarray | None = None
        self._origin = trajectory(0.0)[0]

    def _desired(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q_d, qdot_d, qddot_d)`` (n,) each."""
        q, qd, qdd = (np.zeros(self.robot.n_joints) for _ in range(3))
        f, fd, fdd = self.trajectory(t - self.start)
        q[self.joints], qd[self.joints], qdd[self.joints] = f - self._origin, fd, fdd
        return self.hold + q, qd, qdd

    def reference(self, t: float) -> np.ndarray | None:
        """The joint reference q_d (n,), None before the first call."""
        return None if self.hold is None else self._desired(t)[0]

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (n,) at time t for the measured state."""
        if self.hold is None:
            self.hold = self.coords.get(q)
        q_d, qd_d, qdd_d = self._desired(t)
        H, c = self.dynamics.at(t, q, v)
        nb = self.robot.n_base
        return H @ (qdd_d + self.kp * (q_d - self.coords.get(q)) + self.kd * (qd_d - v[nb:])) + c
