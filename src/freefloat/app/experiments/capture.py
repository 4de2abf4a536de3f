"""Capture experiments (dissertation sec 3.8, done exactly): the robot holds its posture until a
tumbling target's grasp point reaches the end-effector, grasps it by an exact impulse, then the
merged robot detumbles it."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin

from ...dynamics.metrics import spin_summary, summarize
from ...dynamics.simulation import RunResult
from ...errors import SceneError
from ...space.capture import Target, capture_and_detumble
from ..scenes import Scene
from .base import Checkpoint, Experiment, Outcome, Progress
from .detumbling import detumble_task, mission_joints, rows_spec
from .robot_run import APPROACH_MARGIN, RobotSetup, control_steps, prepare_robot, robot_outcome

#: How the page draws the target: orange, apart from the robot's greys and blues.
TARGET_MATERIAL = mg.MeshPhongMaterial(color=0xE07000)


@dataclass(kw_only=True)
class CaptureSetup(RobotSetup):
    """A capture scene resolved before the loop: the robot's setup and the target, which meets
    the end-effector at ``target.contact_time``."""

    target: Target


def prepare(scene: Scene) -> CaptureSetup:
    """The robot, its start, the detumble task checked on it, and the target placed so that its
    grasp point meets the end-effector at ``target.contact_time``.

    Raises:
        SceneError: naming ``target.end_effector``, a ``[task]`` key or a bad ``[target]``.
    """
    setup = prepare_robot(scene)
    robot, tg, s = setup.robot, scene.target, scene.angle_scale
    detumble_task(robot, scene)
    if tg.end_effector not in robot.end_effectors:
        raise SceneError(f"scene '{scene.name}': target.end_effector '{tg.end_effector}' is not an end-effector; "
                         f"end-effectors: {', '.join(robot.end_effectors)}")
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, setup.q0)
    point = data.oMf[robot.model.getFrameId(tg.end_effector)].translation
    try:
        target = Target.meeting(point, tg.contact_time, tg.mass, tg.inertia, tg.grasp, tg.velocity,
                                np.multiply(tg.angular_velocity, s), np.multiply(tg.rpy_at_contact, s), tg.size)
    except Exception as exc:
        raise SceneError(f"scene '{scene.name}': [target] {exc}") from exc
    return CaptureSetup(**vars(setup), target=target)


def run(setup: CaptureSetup, progress: Progress | None = None, checkpoint: Checkpoint | None = None) -> Outcome:
    """Approach, grasp and detumbling; the summary of the post-capture run with the grasp's
    momentum balance (merged robot after against robot + target before); the animation of both
    phases with the target and the grasp instant. (The capture runs as one call: no progress
    report nor checkpoints.)"""
    scene, robot = setup.scene, setup.robot
    tg, sim, ctrl = scene.target, scene.simulation, scene.controller
    start = time.perf_counter()
    res = capture_and_detumble(robot, setup.target, tg.end_effector, rows_spec(scene), mission_joints(scene),
                               scene.task.method, sim.control_period, tg.contact_time + APPROACH_MARGIN, sim.duration,
                               tg.tolerance, integrator=sim.integrator, q0=setup.q0, v0=setup.v0,
                               kp=ctrl.kp, kd=ctrl.kd, model=ctrl.model)
    wall = time.perf_counter() - start
    merged = dataclasses.replace(res.merged, visual_model=robot.visual_model)
    tel = res.post
    result = RunResult(tel, res.summary["status"], "", len(tel.t) - 1, wall, 0)
    summary = summarize(tel, merged)  # after the grasp: no external wrench, so drifts
    summary.update(spin_summary(merged, tel))
    summary.update(res.summary, sim_wall_time_s=wall, steps=len(res.pre.t) + len(tel.t) - 2)
    both_t = np.concatenate((res.pre.t, res.impact_time + tel.t[1:]))
    both_q = np.concatenate((res.pre.q, tel.q[1:]))
    poses = np.concatenate((res.target_poses[: len(res.pre.t)], res.target_poses[len(res.pre.t) + 1:]))
    return robot_outcome(setup, merged, tel, result, summary, animation=(both_t, both_q),
                         extra_bodies=[("target", mg.Mesh(mg.Box(list(tg.size)), TARGET_MATERIAL), poses)],
                         extra_telemetry={"pre_capture": res.pre}, events=[(res.impact_time, "grasp")], wrenches=(),
                         spin=True, settle_threshold=res.summary["settle_threshold"])


EXPERIMENT = Experiment("capture", "a robot grasps a tumbling target and detumbles it",
                        prepare, control_steps, run)
