"""Joint-space computed-torque control of a free-floating robot (dissertation eqs 136-137)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ...robot.joints import JointCoordinates
from ...robot.robot import Robot
from .trajectory import QuinticTrajectory


class ControllerDynamics:
    """A named dynamics model's joint-space form ``tau = H qddot + c``, queried once per control
    period by a controller.

    Models with memory (``end_period``, e.g. ``nidc``'s integrated coupling, eq 67) are advanced
    over the previous period, from the state of the previous query, before each new query; so every
    controller that uses this class keeps them current.

    Args:
        robot: the robot.
        name: model name (see :data:`freefloat.models.MODELS`).
    """

    def __init__(self, robot: Robot, name: str):
        from ...dynamics.models import make_model

        self.model = make_model(name, robot)
        self._end_period = getattr(self.model, "end_period", None)
        self._last: tuple[float, np.ndarray, np.ndarray] | None = None

    def at(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(H, c)`` at the start ``t`` (s) of a control period: (n, n), (n,), Pinocchio joint order."""
        if self._end_period is not None:
            if self._last is not None:
                self._end_period(self._last[1], self._last[2], t - self._last[0])
            self._last = (t, q.copy(), v.copy())
        return self.model.joint_space_at(q, v)


@dataclass(frozen=True)
class QuinticComputedTorqueLaw:
    """:class:`ComputedTorque` on a :class:`QuinticTrajectory` as the compiled loop runs it (the
    exact ``H*``, ``c*``; ``_sim.Simulation.set_computed_torque``).

    Attributes:
        start: the quintic's start, joint positions (n,), rad or m.
        delta: goal minus start (n,).
        duration: the quintic's duration, s.
        kp: proportional gain, 1/s^2.
        kd: derivative gain, 1/s.
    """

    start: np.ndarray
    delta: np.ndarray
    duration: float
    kp: float
    kd: float

    kind: ClassVar[str] = "quintic_computed_torque"

    def install(self, simulation: Any, robot: Robot) -> None:
        """Hand this law to the compiled loop."""
        simulation.set_computed_torque(self.start, self.delta, self.duration, self.kp, self.kd)


class ComputedTorque:
    """Computed torque ``tau = H(q) tau' + c(q, v)``, ``tau' = qddot_d + Kp e + Kd edot``,
    ``e = q_d - q`` (eqs 136-137), with ``(H, c)`` from a dynamics model's joint-space form.

    Args:
        robot: the robot.
        trajectory: joint reference.
        kp: proportional gain (scalar: Kp = kp I), 1/s^2. The dissertation uses 10.
        kd: derivative gain (scalar: Kd = kd I), 1/s. The dissertation uses 100.
        model: name of the dynamics model the controller uses (see :data:`freefloat.models.MODELS`).
    """

    def __init__(self, robot: Robot, trajectory: QuinticTrajectory, kp: float, kd: float, model: str = "exact"):
        if kp < 0.0 or kd < 0.0:
            raise ValueError(f"gains must be >= 0, got kp={kp}, kd={kd}")
        self.robot, self.trajectory, self.kp, self.kd = robot, trajectory, kp, kd
        self.dynamics = ControllerDynamics(robot, model)
        self.joints = JointCoordinates(robot)

    def compiled_law(self) -> QuinticComputedTorqueLaw | None:
        """This law for the compiled loop (:mod:`freefloat.dynamics.compiled`), which has it with
        the exact ``H*`` and ``c*`` only: None for another controller model."""
        if self.dynamics.model.name != "exact":
            return None
        trajectory = self.trajectory
        return QuinticComputedTorqueLaw(trajectory.start, trajectory.delta, trajectory.duration, self.kp, self.kd)

    def reference(self, t: float) -> np.ndarray:
        """Reference joint positions q_d(t) (n,)."""
        return self.trajectory(t)[0]

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (n,) for state (q, v) at time t."""
        q_d, qdot_d, qddot_d = self.trajectory(t)
        nb = self.robot.n_base
        e = q_d - self.joints.get(q)
        edot = qdot_d - v[nb:]
        H, c = self.dynamics.at(t, q, v)
        return H @ (qddot_d + self.kp * e + self.kd * edot) + c
