"""A PD joint controller of your own, registered into freefloat.CONTROLLERS from outside the package.

A scene names this file (``plugins = ["pd_controller.py"]``) and the kind (``[controller] kind =
"pd"``, with the keys ``kp`` and ``kd``); freefloat validates those keys as it does a built-in's
and runs the law in its Python loop (the law has no compiled twin), with the same telemetry::

    freefloat simulate examples/pd_controller.toml
    freefloat batch examples/pd_controller.toml --runs 4

From Python, ``freefloat.use("examples/pd_controller.py")`` registers it too, then
``freefloat.simulate("examples/pd_controller.toml")``.

The law drives every joint to the goal of the scene's joint quintic (``[task] kind =
"joint_quintic"``, start + displacement), with no model:

.. math:: \\tau = K_p (q_{goal} - q) - K_d \\dot q.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from freefloat import CONTROLLERS, ControlContext, ControllerSpec, Rules
from freefloat.robot.joints import JointCoordinates


@dataclass(frozen=True)
class PDSettings:
    """``[controller]`` keys of kind ``"pd"``: ``kp`` (N m/rad, or N/m on a prismatic joint) and
    ``kd`` (N m s/rad, or N s/m), the same on every joint."""

    kp: float = 50.0
    kd: float = 10.0


class JointPD:
    """``tau = kp (goal - q) - kd qdot`` on the joints (n_joints,); ``reference(t)`` is the goal."""

    def __init__(self, robot, goal: np.ndarray, kp: float, kd: float):
        self.robot, self.goal, self.kp, self.kd = robot, np.asarray(goal, float), kp, kd
        self.joints = JointCoordinates(robot)

    def reference(self, t: float) -> np.ndarray:
        """The set point (n_joints,)."""
        return self.goal

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (n_joints,) at the state (q, v)."""
        return self.kp * (self.goal - self.joints.get(q)) - self.kd * v[self.robot.n_base:]


def build(context: ControlContext, settings: PDSettings) -> JointPD:
    """The PD law toward the end of the scene's joint quintic."""
    trajectory = context.reference
    return JointPD(context.plant, trajectory.start + trajectory.delta, settings.kp, settings.kd)


CONTROLLERS.register(ControllerSpec(
    "pd", "joint PD to the goal of the joint quintic (no model)", PDSettings, build, tasks=("joint_quintic",),
    rules=Rules({}, set(), {("controller", "kp"), ("controller", "kd")})))
