"""Joint-space experiments: every joint follows a quintic from its start to a displaced goal
under computed torque (dissertation eqs 136-137, any controller model), or the robot moves
torque-free (``task.kind = "none"``, ``controller.kind = "none"``)."""

from __future__ import annotations

from ...dynamics.result import Result
from ...space.control import QuinticTrajectory
from ..controllers import ControlContext, build_controller
from ..scenes import Scene
from .base import Checkpoint, Experiment, Outcome, Progress
from .robot_run import (
    UNITS,
    RobotSetup,
    control_steps,
    headline_of,
    joint_table,
    prepare_robot,
    robot_outcome,
    run_loop,
    summary_of,
)


def takes(scene: object) -> bool:
    """A robot scene without a ``[target]`` whose task is not ``"detumble"`` (a joint quintic or
    none: torque-free)."""
    return isinstance(scene, Scene) and scene.target is None and scene.task.kind != "detumble"


def prepare(scene: Scene) -> RobotSetup:
    """The robot, its start, and the scene's controller (:data:`freefloat.app.controllers.CONTROLLERS`)
    on the joint quintic reference (None without a ``joint_quintic`` task).

    Raises:
        SceneError: naming the key for a bad start or displacement, or a controller that needs
            another task.
    """
    setup = prepare_robot(scene)
    task, reference = scene.task, None
    if task.kind == "joint_quintic":
        robot, s = setup.robot, scene.angle_scale
        start = joint_table(robot, scene.initial.joint_positions, s, "initial.joint_positions")
        goal = start + joint_table(robot, task.displacement, s, "task.displacement")
        reference = QuinticTrajectory(setup.plant_joints(start), setup.plant_joints(goal), task.duration)
    setup.controller = build_controller(ControlContext(scene, setup.plant, reference, scene.simulation.control_period,
                                                       scene.angle_scale, setup.environment, setup.plant_wheels))
    return setup


def run(setup: RobotSetup, progress: Progress | None = None, checkpoint: Checkpoint | None = None) -> Outcome:
    """The loop, the summary (tracking, drifts, base motion) and the run's drawings."""
    return outcome_of(setup, run_loop(setup, progress, checkpoint))


def outcome_of(setup: RobotSetup, result: Result) -> Outcome:
    """The outcome of the loop's ``result`` (a run of ``setup``'s loop, here or in a batch of many
    runs in one call): the summary (tracking, drifts, base motion) and the run's drawings."""
    return robot_outcome(setup, setup.robot, result.telemetry, result, summary_of(setup, result))


EXPERIMENT = Experiment("joint_space", "joint-space task or torque-free motion of a robot",
                        "robot scenes without a [target] whose task.kind is not \"detumble\"", takes, prepare,
                        control_steps, run,
                        headline_of(()), UNITS)
