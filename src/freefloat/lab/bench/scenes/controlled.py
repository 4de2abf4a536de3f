"""The controlled bench scene: the default scene file (``four_arm_joint_space.toml``: its start,
displacements, gains, controller model and control period, read from the file, not retyped) on
the balanced four-arm robot with a free (or planar) base, its quintic stretched over the bench's
duration: every joint of arms 1 and 4 by +5 deg, of arms 2 and 3 by -5 deg, arms 2 and 4 starting
with joint 1 at 90 deg, under joint-space computed torque (eqs 136-137, Kp = 10, Kd = 100, exact
H* and c*) held over 1 ms periods, from rest.

MuJoCo runs it two ways: stepped by freefloat's own Python-side controller (the state mapped to
Pinocchio's convention each period), and with the same law written on MuJoCo's own mass matrix
and bias forces (``mj_forward`` once per period, then the substeps), its fastest way for a
feedback law computed in Python (``mujoco.rollout`` takes open-loop controls only).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pinocchio as pin

from ....app.experiments import experiment_for
from ....app.scenes import find_scene
from ....dynamics.simulation import control_periods
from ....dynamics.wrenches import ExternalWrench
from ....robot.robot import Robot
from ....space.control import ComputedTorque
from ..in_mujoco.mjcf import balanced_model

#: The scene file the controlled bench scene runs.
SCENE = "four_arm_joint_space"


@dataclass(frozen=True)
class ControlledScene:
    """A controlled run of one robot: this module's computed-torque scene, or the post-capture
    detumbling of :mod:`.detumbling`.

    Attributes:
        name: scene name.
        robot: the robot (free base).
        q0, v0: initial Pinocchio state (nq,), (nv,).
        duration: simulated time, s.
        period: zero-order-hold control period, s.
        make_controller: a controller in its initial state (a fresh one per run: a controller may
            keep state from period to period).
        wrenches: external wrenches on links (held over each period, inertial frame).
    """

    name: str
    robot: Robot
    q0: np.ndarray
    v0: np.ndarray
    duration: float
    period: float
    make_controller: Callable[[], Any]
    wrenches: tuple[ExternalWrench, ...] = ()

    @property
    def model(self) -> pin.Model:
        """The Pinocchio free-flyer model both sides simulate."""
        return self.robot.model


def controlled_scene(duration: float = 1.0, base: str = "free") -> ControlledScene:
    """The controlled scene over ``duration`` s on a ``"free"`` or ``"planar"`` base (the motion is
    planar: :func:`.detumbling.planar_to_free` maps a planar-base state to the free base's), from
    the scene file :data:`SCENE` through its experiment's ``prepare``.

    Raises:
        InvalidArgument: unless the duration is a positive whole number of control periods.
    """
    scene = find_scene(SCENE)
    control_periods(duration, scene.simulation.control_period)
    scene = replace(scene, robot=replace(scene.robot, base=base), task=replace(scene.task, duration=duration),
                    simulation=replace(scene.simulation, duration=duration, model="exact"),
                    output=replace(scene.output, html=False))
    setup = experiment_for(scene).prepare(scene)
    robot = replace(setup.robot, model=balanced_model(setup.robot.model))
    law = scene.controller
    controller = ComputedTorque(robot, setup.controller.trajectory, law.kp, law.kd, law.model)
    return ControlledScene("controlled", robot, setup.q0, setup.v0, duration, scene.simulation.control_period,
                           lambda: controller)


def substeps(scene: ControlledScene, h: float) -> int:
    """Equal integration steps of about ``h`` per control period."""
    return max(1, round(scene.period / h))


def periods(scene: ControlledScene) -> int:
    """Control periods in the scene."""
    return round(scene.duration / scene.period)


def mujoco_law(scene: ControlledScene, model, data) -> np.ndarray:
    """Joint torques (n,) of the scene's law from MuJoCo's own mass matrix and ``qfrc_bias`` at its
    current state (after ``mj_forward``): ``tau = H* (qdd_d + Kp e + Kd edot) + c*`` with the base
    rows eliminated, which gives the same law in any base velocity coordinates."""
    import mujoco

    nv = model.nv
    M = np.empty((nv, nv))
    mujoco.mj_fullM(model, data, M)
    b = data.qfrc_bias
    t = data.time
    law = scene.make_controller()
    q_d, qdot_d, qddot_d = law.trajectory(t)
    coupling = np.linalg.solve(M[:6, :6], np.column_stack((M[:6, 6:], b[:6])))
    H = M[6:, 6:] - M[6:, :6] @ coupling[:, :-1]
    c = b[6:] - M[6:, :6] @ coupling[:, -1]
    return H @ (qddot_d + law.kp * (q_d - data.qpos[7:]) + law.kd * (qdot_d - data.qvel[6:])) + c
