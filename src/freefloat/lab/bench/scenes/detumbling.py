"""The post-capture detumbling bench scene: the built-in scene ``detumble_impulse_both_arms``
(dissertation sec 5.3, scenario 4: 500 N m capture impulses on both arms' last links from 5 to
15 ms, then both end-effectors' rotation stopped with all joints, min-norm solution, computed
torque on the exact model held over 1 ms) on a **free** base, its inertias balanced (MuJoCo
refuses the URDF's, see :func:`..in_mujoco.mjcf.balanced_model`), so MuJoCo's free joint and the MJCF
of :mod:`..in_mujoco.mjcf` take it as they are; the same scene on its planar base is the smaller model of the
sweep (:func:`.free_floating.planar_to_free` maps its states for the errors).

MuJoCo is stepped by freefloat's detumbling controller (state mapped each period) with the
impulses as ``xfrc_applied`` (:mod:`..in_mujoco.wrenches`); the law has no form on MuJoCo's own
matrices here (it needs the generalized Jacobian of the end-effector rows).
"""

from __future__ import annotations

import dataclasses

from ....app.experiments.detumbling import prepare
from ....app.scenes import find_scene
from ....space.control.detumbling_control import DetumblingController
from ..in_mujoco.mjcf import balanced_model
from .controlled import ControlledScene

#: The built-in scene the bench runs.
SOURCE = "detumble_impulse_both_arms"


def detumbling_scene(duration: float = 1.0, base: str = "free") -> ControlledScene:
    """The detumbling scene over ``duration`` s on a ``"free"`` or ``"planar"`` base.

    Raises:
        SceneError: unless the duration is a positive whole number of control periods.
    """
    scene = find_scene(SOURCE)
    scene = dataclasses.replace(scene, robot=dataclasses.replace(scene.robot, base=base),
                                simulation=dataclasses.replace(scene.simulation, duration=duration, model="exact"))
    setup = prepare(scene)
    robot = dataclasses.replace(setup.robot, model=balanced_model(setup.robot.model))
    c = setup.controller

    def make_controller() -> DetumblingController:
        return DetumblingController(robot, c.rows, c.joints, c.start, c.T, c.method, c.kp, c.kd)

    return ControlledScene("detumbling", robot, setup.q0, setup.v0, duration, scene.simulation.control_period,
                           make_controller, setup.wrenches)

