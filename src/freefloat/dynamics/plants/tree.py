"""A robot tree as a plant of the generic loop (:func:`freefloat.dynamics.simulation.run_plant`):
any dynamics model of :data:`freefloat.dynamics.models.MODELS`, efforts on chosen joints. What a
plant wrapped around a tree needs (a motor-driven joint, :class:`.motor_driven.MotorDrivenPlant`);
:func:`~freefloat.dynamics.simulation.run` remains the robot's own loop (momentum, end-effector
telemetry)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...errors import InvalidArgument
from ...robot.robot import Robot
from ..models.base import DynamicsModel


class TreePlant:
    """A robot's tree under efforts on some of its joints.

    Args:
        robot: the robot (its model is the configuration space).
        model: its dynamics model (e.g. ``ExactModel(robot)``, or with friction,
            :class:`~freefloat.dynamics.models.friction.WithFriction`).
        actuated: velocity index of each actuated joint (k,); default every joint (the base's
            rows excluded), in Pinocchio's order.

    Raises:
        InvalidArgument: for an actuated index out of the joints' range or repeated.
    """

    name = "tree"
    max_drift = np.inf

    def __init__(self, robot: Robot, model: DynamicsModel, actuated: Sequence[int] | None = None):
        nv, n_base = robot.model.nv, robot.n_base
        self.actuated = np.arange(n_base, nv) if actuated is None else np.asarray(actuated, dtype=int)
        if len(set(self.actuated.tolist())) != len(self.actuated) or not all(n_base <= i < nv for i in self.actuated):
            raise InvalidArgument(f"tree plant: 'actuated' must be distinct joint velocity indices in [{n_base}, {nv}), "
                                  f"got {self.actuated.tolist()}")
        self.robot, self.model, self.space = robot, model, robot.model
        self.n_efforts = len(self.actuated)
        self.tau = np.zeros(nv)

    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Generalised acceleration (nv,) under efforts ``u`` (k,) on the actuated joints."""
        self.tau[self.actuated] = u
        return self.model.acceleration(q, v, self.tau)

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """A tree has no closure: ``(0, 0)``."""
        return 0.0, 0.0
