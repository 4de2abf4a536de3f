"""Computed torque on a planned joint path, for the one loop (dissertation eqs 136-137)."""

from __future__ import annotations

import numpy as np

from ...robot.robot import Robot
from ..control.computed_torque import ComputedTorque
from .plan import JointPath


class Delayed:
    """A joint path started ``start`` s late: ``(q_d, qdot_d, qddot_d)(t) = path(t - start)``
    (before it, the path's start held at rest)."""

    def __init__(self, path: JointPath, start: float):
        self.path, self.start = path, start

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.path(t - self.start)


class PlanTracking(ComputedTorque):
    """:class:`~freefloat.space.control.ComputedTorque` on a plan's
    :class:`~freefloat.space.planning.JointPath` (``trajectory(t) -> (q_d, qdot_d, qddot_d)``),
    started at ``start`` s (holding the path's start before). The compiled loop knows quintic
    references only, so this law runs in Python."""

    def __init__(self, robot: Robot, path: JointPath, kp: float, kd: float, model: str = "exact", start: float = 0.0):
        super().__init__(robot, Delayed(path, start), kp, kd, model)

    def compiled_law(self) -> None:
        """None: the Python law (see the class docstring)."""
        return None
