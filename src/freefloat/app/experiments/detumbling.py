"""Detumbling experiments (dissertation sec 5.3): from ``task.start`` the detumbling controller
stops the chosen end-effector velocity rows with the mission joints (eqs 115-120, 134); the
summary says how fast and how far they settle."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...dynamics import gjm
from ...dynamics.metrics import settling_time, spin_summary
from ...dynamics.telemetry import Telemetry
from ...errors import SceneError
from ...robot.robot import Robot
from ...space.detumbling import joint_indices, task_rows
from ..controllers import ControlContext, DetumbleTask, build_controller
from ..scenes import Scene
from .base import Checkpoint, Experiment, Outcome, Progress
from .robot_run import (
    SPIN_HEADLINE,
    RobotSetup,
    control_steps,
    headline_of,
    prepare_robot,
    robot_outcome,
    run_loop,
    summary_of,
)
from .robot_run import UNITS as ROBOT_UNITS


def takes(scene: object) -> bool:
    """A robot scene without a ``[target]`` whose task is ``"detumble"``."""
    return isinstance(scene, Scene) and scene.target is None and scene.task.kind == "detumble"


def prepare(scene: Scene) -> RobotSetup:
    """The robot, its start and the scene's controller on the detumble task (``controller.kind =
    "detumbling"``, or its old spelling ``"computed_torque"``: the detumbling controller).

    Raises:
        SceneError: naming ``task.rows``, ``task.mission_joints`` or the bad start.
    """
    setup = prepare_robot(scene)
    rows, joints = detumble_task(setup.robot, scene)
    task = DetumbleTask(rows, joints, scene.task.start, scene.task.method)
    setup.controller = build_controller(ControlContext(scene, setup.robot, task, scene.simulation.control_period,
                                                       scene.angle_scale, setup.environment, setup.plant_wheels))
    return setup


def run(setup: RobotSetup, progress: Progress | None = None, checkpoint: Checkpoint | None = None) -> Outcome:
    """The loop, the summary with the detumbled rows' speed and settling time, the drawings."""
    result = run_loop(setup, progress, checkpoint)
    task: dict[str, Any] = {}
    if len(result.telemetry.t):
        task = detumble_summary(setup.robot, result.telemetry, detumble_task(setup.robot, setup.scene)[0])
    return robot_outcome(setup, setup.robot, result.telemetry, result, summary_of(setup, result, **task), spin=True,
                         settle_threshold=task.get("settle_threshold"), task_headline=SPIN_HEADLINE)


def rows_spec(scene: Scene) -> list[tuple[str, str]]:
    """``[task] rows`` as (end-effector, component) pairs.

    Raises:
        SceneError: naming ``task.rows`` when missing or not ``"end_effector:component"``.
    """
    if not scene.task.rows:
        raise SceneError(f"scene '{scene.name}': task.kind 'detumble' needs 'task.rows', e.g. [\"arm1_ee:wz\"]")
    spec = []
    for item in scene.task.rows:
        ee, sep, component = item.partition(":")
        if not sep:
            raise SceneError(f"scene '{scene.name}': 'task.rows' item '{item}' must be 'end_effector:component'")
        spec.append((ee, component))
    return spec


def mission_joints(scene: Scene) -> list[str] | None:
    """``[task] mission_joints`` as a list (None: every joint)."""
    return None if scene.task.mission_joints is None else list(scene.task.mission_joints)


def detumble_task(robot: Robot, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Row and mission-joint indices of a detumble task.

    Raises:
        SceneError: naming the ``[task]`` key that names an unknown row or joint.
    """
    try:
        return task_rows(robot, rows_spec(scene)), joint_indices(robot, mission_joints(scene))
    except ValueError as exc:
        raise SceneError(f"scene '{scene.name}': [task] {exc}") from exc


#: The unit of each key :func:`detumble_summary` adds to :func:`~freefloat.dynamics.metrics.spin_summary`'s.
UNITS = {"detumbled_rows_speed_final": "m/s or rad/s", "detumbled_rows_speed_max": "m/s or rad/s",
         "settling_time": "s", "settle_threshold": "m/s or rad/s"}


def detumble_summary(robot: Robot, telemetry: Telemetry, rows: np.ndarray, threshold: float = 1e-6) -> dict:
    """Speed of the detumbled rows over the run (m/s or rad/s): final, max, and the settling
    time (s) after which it stays below ``threshold``; how the base's and each end-effector's
    spin settles (:func:`~freefloat.dynamics.metrics.spin_summary`)."""
    speed = np.array([np.abs(gjm.compute(robot, q, v).end_effector_velocity()[rows]).max()
                      for q, v in zip(telemetry.q, telemetry.v)])
    settled = settling_time(telemetry.t, speed, threshold)
    return {"detumbled_rows_speed_final": float(speed[-1]), "detumbled_rows_speed_max": float(speed.max()),
            "settling_time": settled, "settle_threshold": threshold, **spin_summary(robot, telemetry)}


EXPERIMENT = Experiment("detumbling", "a robot stops end-effector velocity rows after an impulse",
                        "robot scenes without a [target] whose task.kind is \"detumble\"", takes, prepare,
                        control_steps, run, headline_of(SPIN_HEADLINE), {**ROBOT_UNITS, **UNITS})
