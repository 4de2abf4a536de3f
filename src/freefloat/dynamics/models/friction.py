"""Any dynamics model of a robot tree with joint friction (:mod:`freefloat.dynamics.friction`) as a
generalised force: ``M qddot + h = tau - f(v)``.

The actuators' effective inertias need no wrapper: they are Pinocchio's ``model.armature`` (the
rotor inertia times the gear ratio squared on the joint's diagonal of ``M``), which ABA, CRBA and
RNEA include (:func:`freefloat.dynamics.motors.add_armature`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument
from ..friction import JointFriction
from .base import DynamicsModel


class WithFriction:
    """``model`` with joint friction: its accelerations under ``tau - f(v)``.

    Args:
        model: a model of :data:`~freefloat.dynamics.models.MODELS` (``exact``: Pinocchio's ABA).
        friction: over the robot's velocity coordinates (nv,), zero on the floating base's
            (:meth:`JointFriction.of_model` of the robot's model reads the URDF's ``<dynamics>``).

    Its name is the model's with ``_friction``: the compiled loop, which has no friction, leaves
    it to the Python loop.

    Raises:
        InvalidArgument: for a friction of another size than nv, or one on the base's coordinates.
    """

    def __init__(self, model: DynamicsModel, friction: JointFriction):
        robot = model.robot
        nv, n_base = robot.model.nv, robot.n_base
        if friction.n != nv:
            raise InvalidArgument(f"{model.name} with friction: the friction is for {friction.n} coordinates, the robot "
                                  f"has nv = {nv}")
        if friction[:n_base]:
            raise InvalidArgument(f"{model.name} with friction: the floating base's {n_base} coordinates cannot have "
                                  "joint friction")
        self.inner, self.friction, self.n_base = model, friction, n_base
        self.name = f"{model.name}_friction"

    def __getattr__(self, name: str) -> Any:  # robot, model, end_period, ...: the wrapped model's
        if name == "inner":
            raise AttributeError(name)
        return getattr(self.inner, name)

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
                     fext: Sequence[pin.Force] | None = None) -> np.ndarray:
        """Generalised acceleration (nv,) under ``tau - f(v)`` (tau (nv,), zero on the base rows)."""
        return self.inner.acceleration(q, v, np.asarray(tau, dtype=float) - self.friction.force(v), fext)

    def joint_space_at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(H, c + f)`` with ``tau = H qddot + c + f(qdot)`` on the joints (n, n), (n,)."""
        H, c = self.inner.joint_space_at(q, v)
        return H, c + self.friction.force(np.asarray(v, dtype=float))[self.n_base:]
