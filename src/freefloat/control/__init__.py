"""Trajectories and controllers."""

from typing import Protocol

import numpy as np

from .computed_torque import ComputedTorque, joint_space_dynamics
from .trajectory import QuinticTrajectory


class Controller(Protocol):
    """Gives joint torques (n_joints,) at the start of each control period (zero-order hold)."""

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray: ...

    def reference(self, t: float) -> np.ndarray | None:
        """Reference joint positions (n_joints,) or None."""
        ...


__all__ = ["Controller", "ComputedTorque", "QuinticTrajectory", "joint_space_dynamics"]
