"""The exact reference: Pinocchio's articulated-body algorithm (ABA)."""

from __future__ import annotations

from typing import Sequence

import numpy as np
import pinocchio as pin

from ..robot import Robot


class ExactModel:
    """Exact forward dynamics by Pinocchio ABA (Featherstone), O(n).

    Args:
        robot: the robot; a private ``pin.Data`` is allocated.
    """

    name = "exact"

    def __init__(self, robot: Robot):
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()

    def joint_space_at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(H*, c*)`` with ``tau = H* qddot + c*``: the exact joint-space dynamics (n, n), (n,)."""
        from ..control.computed_torque import joint_space_dynamics

        return joint_space_dynamics(self.robot, self.data, q, v)

    def acceleration(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        fext: Sequence[pin.Force] | None = None,
    ) -> np.ndarray:
        if fext is None:
            return pin.aba(self.model, self.data, q, v, tau)
        return pin.aba(self.model, self.data, q, v, tau, fext)
