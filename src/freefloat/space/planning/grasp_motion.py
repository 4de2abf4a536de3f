"""The free flight of a target's grasp point, known ahead of the grasp (what a pre-capture planner
aims at)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument
from ..capture import Target


@dataclass(frozen=True)
class GraspMotion:
    """Torque-free motion of a target spinning about a principal axis (so ``w`` is constant):
    CoM ``c(t) = c_0 + v t``, orientation ``R(t) = exp(w t) R_0``, grasp point
    ``p(t) = c(t) + R(t) g``.

    Attributes:
        com: CoM at t = 0, inertial frame, m (3,).
        velocity: CoM velocity, inertial frame, m/s (3,).
        angular_velocity: w, inertial frame, rad/s (3,).
        rotation: target frame orientation at t = 0, inertial frame (3, 3).
        grasp: grasp point in the target frame, from its CoM, m (3,).
        handle: orientation of the grasp frame (the handle a hand aligns with) in the target
            frame (3, 3).
    """

    com: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    rotation: np.ndarray
    grasp: np.ndarray
    handle: np.ndarray = field(default_factory=lambda: np.eye(3))

    @classmethod
    def of(cls, target: Target) -> GraspMotion:
        """The grasp-point flight of ``target`` from its state at t = 0.

        Raises:
            InvalidArgument: when the spin is not along a principal axis (the target precesses
                and ``w`` is not constant).
        """
        R = pin.rpy.rpyToMatrix(*target.rpy)
        w = np.asarray(target.angular_velocity, float)
        w_body = R.T @ w
        torque_free = np.cross(w_body, np.diag(target.inertia) @ w_body)
        if np.linalg.norm(torque_free) > 1e-9 * max(1.0, w_body @ w_body) * max(target.inertia):
            raise InvalidArgument("GraspMotion: the target's spin must lie along a principal axis (it precesses "
                                  "otherwise and its grasp point cannot be predicted in closed form)")
        return cls(np.asarray(target.position, float), np.asarray(target.velocity, float), w, R,
                   np.asarray(target.grasp, float))

    def shifted(self, start: float) -> GraspMotion:
        """The same flight with its time origin at ``start`` s (``shifted(s).at(t) == at(s + t)``)."""
        rotation = pin.exp3(self.angular_velocity * start) @ self.rotation
        return GraspMotion(self.com + self.velocity * start, self.velocity, self.angular_velocity, rotation, self.grasp,
                           self.handle)

    def orientation(self, t: float) -> np.ndarray:
        """The grasp frame's orientation at ``t`` s, inertial frame: ``R(t) handle`` (3, 3); it
        turns at ``w``."""
        return pin.exp3(self.angular_velocity * t) @ self.rotation @ self.handle

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Grasp point position, velocity and acceleration at ``t`` s, inertial frame, (3,) each:
        ``p``, ``v + w x r`` and ``w x (w x r)`` with ``r = R(t) g``."""
        w = self.angular_velocity
        r = pin.exp3(w * t) @ self.rotation @ self.grasp
        w_r = np.cross(w, r)
        return self.com + self.velocity * t + r, self.velocity + w_r, np.cross(w, w_r)
