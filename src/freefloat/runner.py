"""Run a scene end to end: load, set up, simulate, write the output folder."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import pinocchio as pin

from .control import ComputedTorque, Controller, QuinticTrajectory
from .control.detumbling_control import DetumblingController
from .conventions import state_from_base
from .errors import SceneError
from .integrators import Integrator, make_integrator
from .joints import JointCoordinates
from .loading import load_robot
from .metrics import settling_time, summarize
from .models import DynamicsModel, make_model
from .paths import URDF_DIR
from .robot import Robot
from .scenes import MechanismScene, Scene
from .simulation import RunResult, run
from .wrenches import ExternalWrench


@dataclass
class Prepared:
    """Everything a scene resolves to before the loop starts (and, for a capture, what the
    output needs beyond the main telemetry: the target's poses, the whole animation, the
    pre-capture telemetry)."""

    robot: Robot
    q0: np.ndarray
    v0: np.ndarray
    model: DynamicsModel
    integrator: Integrator
    controller: Controller | None
    wrenches: tuple[ExternalWrench, ...] = ()
    extra_bodies: list = field(default_factory=list)
    animation: tuple[np.ndarray, np.ndarray] | None = None
    extra_telemetry: dict = field(default_factory=dict)


def resolve_file(scene: Scene | MechanismScene, value: str, key: str) -> Path:
    """A file a scene names under ``key``: absolute, relative to the scene file, to the working
    directory, or a built-in file in ``urdf/``.

    Raises:
        SceneError: naming the key and the places searched.
    """
    name = Path(value)
    candidates = [name] if name.is_absolute() else [
        *([scene.source.parent / name] if scene.source else []), Path.cwd() / name, URDF_DIR / name
    ]
    for path in candidates:
        if path.is_file():
            return path
    raise SceneError(f"scene '{scene.name}': {key} '{name}' not found in {[str(c.parent) for c in candidates]}")


def resolve_urdf(scene: Scene) -> Path:
    """The scene's URDF (``robot.urdf``), found as :func:`resolve_file` says."""
    return resolve_file(scene, scene.robot.urdf, "robot.urdf")


def joint_table(robot: Robot, table: dict[str, float], angle_scale: float, key: str) -> np.ndarray:
    """Per-joint values (n_joints,) from a table keyed by joint or end-effector (= its whole arm).

    Revolute values are scaled by ``angle_scale`` (the scene's angle unit), prismatic ones are m.

    Raises:
        SceneError: naming ``key`` and the unknown name, with the valid names.
    """
    out = np.zeros(robot.n_joints)
    model, nb = robot.model, robot.n_base
    arms = {arm.end_effector: arm for arm in robot.arms}
    for name, value in table.items():
        if name in arms:
            indices = arms[name].v_indices - nb
        elif model.existJointName(name) and model.getJointId(name) > 1:
            j = model.getJointId(name)
            indices = np.arange(model.idx_vs[j], model.idx_vs[j] + model.nvs[j]) - nb
        else:
            raise SceneError(
                f"'{key}': '{name}' is neither a joint nor an end-effector; joints: "
                f"{', '.join(robot.joint_names)}; end-effectors: {', '.join(robot.end_effectors)}"
            )
        out[indices] = value
    return out * _angle_scales(robot, angle_scale)


def _angle_scales(robot: Robot, angle_scale: float) -> np.ndarray:
    """``angle_scale`` for revolute coordinates, 1 for prismatic ones (n_joints,)."""
    scales = np.full(robot.n_joints, angle_scale)
    for j in range(2, robot.model.njoints):
        if "Prismatic" in robot.model.joints[j].shortname():
            start = robot.model.idx_vs[j] - robot.n_base
            scales[start:start + robot.model.nvs[j]] = 1.0
    return scales


def prepare(scene: Scene) -> Prepared:
    """Load the robot and build the initial state, models, integrator and controller."""
    robot = load_robot(
        resolve_urdf(scene), base=scene.robot.base, end_effectors=scene.robot.end_effectors,
        gravity=scene.robot.gravity, visuals=scene.output.html,
    )
    s, ini = scene.angle_scale, scene.initial
    joint_q0 = joint_table(robot, ini.joint_positions, s, "initial.joint_positions")
    joint_v0 = joint_table(robot, ini.joint_velocities, s, "initial.joint_velocities")
    q_joints = pin.neutral(robot.model)
    JointCoordinates(robot).set(q_joints, joint_q0)
    x0dot = np.concatenate((ini.base_linear_velocity, np.multiply(ini.base_angular_velocity, s)))
    rotation0 = pin.rpy.rpyToMatrix(*(np.multiply(ini.base_rpy, s)))
    try:
        q0, v0 = state_from_base(
            robot, np.array(ini.base_position), rotation0, x0dot,
            q_joints[robot.model.nqs[1]:], joint_v0,
        )
    except Exception as exc:
        raise SceneError(f"scene '{scene.name}': [initial] {exc}") from exc
    sim, ctrl = scene.simulation, scene.controller
    controller = None
    if ctrl.kind == "computed_torque" and scene.task.kind == "joint_quintic":
        goal = joint_q0 + joint_table(robot, scene.task.displacement, s, "task.displacement")
        trajectory = QuinticTrajectory(joint_q0, goal, scene.task.duration)
        controller = ComputedTorque(robot, trajectory, ctrl.kp, ctrl.kd, ctrl.model)
    elif ctrl.kind == "computed_torque" and scene.task.kind == "detumble":
        rows, joints = detumble_task(robot, scene)
        controller = DetumblingController(robot, rows, joints, scene.task.start, sim.control_period,
                                          scene.task.method, ctrl.kp, ctrl.kd, ctrl.model)
    elif ctrl.kind == "computed_torque":
        raise SceneError(f"scene '{scene.name}': controller 'computed_torque' needs task.kind 'joint_quintic' or 'detumble'")
    wrenches = tuple(ExternalWrench(w.link, w.force, w.torque, w.start, w.end, w.rise) for w in scene.wrenches)
    return Prepared(
        robot=robot, q0=q0, v0=v0,
        model=make_model(sim.model, robot),
        integrator=make_integrator(sim.integrator, robot.model, sim.substeps, sim.rtol, sim.atol),
        controller=controller,
        wrenches=wrenches,
    )


def detumble_rows_spec(scene: Scene) -> list[tuple[str, str]]:
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


def detumble_task(robot: Robot, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Row and mission-joint indices of a detumble task, errors naming the scene key."""
    from .detumbling import joint_indices, task_rows

    try:
        rows = task_rows(robot, detumble_rows_spec(scene))
        joints = joint_indices(robot, None if scene.task.mission_joints is None else list(scene.task.mission_joints))
    except ValueError as exc:
        raise SceneError(f"scene '{scene.name}': [task] {exc}") from exc
    return rows, joints


def simulate_scene(
    scene: Scene, progress: Callable[[int], None] | None = None
) -> tuple[Prepared, RunResult, dict[str, object]]:
    """Run a scene; return its setup, the raw result and the summary metrics."""
    prepared = prepare(scene)
    if scene.target is not None:
        return simulate_capture(scene, prepared)
    sim = scene.simulation
    result = run(
        prepared.robot, prepared.q0, prepared.v0, sim.duration, sim.control_period,
        prepared.integrator, prepared.model, prepared.controller, wrenches=prepared.wrenches,
        record_every=sim.record_every, progress=progress,
    )
    summary = summarize(result.telemetry, prepared.robot) if len(result.telemetry.t) else {}
    if scene.task.kind == "detumble" and len(result.telemetry.t):
        summary.update(detumble_summary(prepared.robot, result.telemetry, detumble_task(prepared.robot, scene)[0]))
    summary.update(status=result.status, message=result.message, steps=result.steps,
                   sim_wall_time_s=result.wall_time_s, model_evaluations=result.evaluations)
    return prepared, result, summary


def detumble_summary(robot: Robot, telemetry, rows: np.ndarray, threshold: float = 1e-6) -> dict:
    """Speed of the detumbled rows over the run: final, settling time below ``threshold``."""
    from . import gjm

    speed = np.array([np.abs(gjm.compute(robot, q, v).end_effector_velocity()[rows]).max()
                      for q, v in zip(telemetry.q, telemetry.v)])
    settled = settling_time(telemetry.t, speed, threshold)
    return {"detumbled_rows_speed_final": float(speed[-1]), "detumbled_rows_speed_max": float(speed.max()),
            "settling_time": settled, "settle_threshold": threshold,
            "base_angular_velocity_final": float(np.linalg.norm(telemetry.base_twist[-1, 3:]))}


def simulate_capture(scene: Scene, prepared: Prepared) -> tuple[Prepared, RunResult, dict[str, object]]:
    """A capture scene: approach, exact grasp, detumbling of the merged robot."""
    import time as _time

    import pinocchio as pin

    from .capture import Target, capture_and_detumble

    tg, sim, ctrl, s = scene.target, scene.simulation, scene.controller, scene.angle_scale
    robot = prepared.robot
    if tg.end_effector not in robot.end_effectors:
        raise SceneError(f"scene '{scene.name}': target.end_effector '{tg.end_effector}' is not an end-effector; "
                         f"end-effectors: {', '.join(robot.end_effectors)}")
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, prepared.q0)
    point = data.oMf[robot.model.getFrameId(tg.end_effector)].translation
    try:
        target = Target.meeting(point, tg.contact_time, tg.mass, tg.inertia, tg.grasp, tg.velocity,
                                np.multiply(tg.angular_velocity, s), np.multiply(tg.rpy_at_contact, s), tg.size)
    except Exception as exc:
        raise SceneError(f"scene '{scene.name}': [target] {exc}") from exc
    start = _time.perf_counter()
    res = capture_and_detumble(robot, target, tg.end_effector, detumble_rows_spec(scene),
                               None if scene.task.mission_joints is None else list(scene.task.mission_joints),
                               scene.task.method, sim.control_period, tg.contact_time + 0.5, sim.duration,
                               tg.tolerance, integrator=sim.integrator, q0=prepared.q0, v0=prepared.v0,
                               kp=ctrl.kp, kd=ctrl.kd, model=ctrl.model)
    wall = _time.perf_counter() - start
    merged = dataclasses.replace(res.merged, visual_model=robot.visual_model)
    tel = res.post
    result = RunResult(tel, res.summary["status"], "", len(tel.t) - 1, wall, 0)
    summary = summarize(tel, merged)
    summary.update(res.summary, sim_wall_time_s=wall, steps=len(res.pre.t) + len(tel.t) - 2)
    import meshcat.geometry as mg

    both_t = np.concatenate((res.pre.t, res.impact_time + tel.t[1:]))
    both_q = np.concatenate((res.pre.q, tel.q[1:]))
    poses = np.concatenate((res.target_poses[: len(res.pre.t)], res.target_poses[len(res.pre.t) + 1:]))
    prepared = dataclasses.replace(prepared, robot=merged, extra_bodies=[("target", mg.Box(list(tg.size)), poses)],
                                   animation=(both_t, both_q), extra_telemetry={"pre_capture": res.pre})
    return prepared, result, summary
