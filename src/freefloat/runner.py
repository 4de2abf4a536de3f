"""Run a scene end to end: load, set up, simulate, write the output folder."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pinocchio as pin

from .control import ComputedTorque, Controller, QuinticTrajectory
from .conventions import state_from_base
from .errors import SceneError
from .integrators import Integrator, make_integrator
from .joints import JointCoordinates
from .loading import load_robot
from .metrics import summarize
from .models import DynamicsModel, make_model
from .paths import URDF_DIR
from .robot import Robot
from .scenes import Scene
from .simulation import RunResult, run


@dataclass
class Prepared:
    """Everything a scene resolves to before the loop starts."""

    robot: Robot
    q0: np.ndarray
    v0: np.ndarray
    model: DynamicsModel
    integrator: Integrator
    controller: Controller | None


def resolve_urdf(scene: Scene) -> Path:
    """The scene's URDF: absolute, relative to the scene file, or a built-in robot in ``urdf/``.

    Raises:
        SceneError: naming ``robot.urdf`` and the places searched.
    """
    name = Path(scene.robot.urdf)
    candidates = [name] if name.is_absolute() else [
        *([scene.source.parent / name] if scene.source else []), Path.cwd() / name, URDF_DIR / name
    ]
    for path in candidates:
        if path.is_file():
            return path
    raise SceneError(f"scene '{scene.name}': robot.urdf '{name}' not found in {[str(c.parent) for c in candidates]}")


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
    sim = scene.simulation
    controller = None
    if scene.controller.kind == "computed_torque":
        if scene.task.kind != "joint_quintic":
            raise SceneError(f"scene '{scene.name}': controller 'computed_torque' needs task.kind = 'joint_quintic'")
        goal = joint_q0 + joint_table(robot, scene.task.displacement, s, "task.displacement")
        trajectory = QuinticTrajectory(joint_q0, goal, scene.task.duration)
        controller = ComputedTorque(robot, trajectory, scene.controller.kp, scene.controller.kd, scene.controller.model)
    return Prepared(
        robot=robot, q0=q0, v0=v0,
        model=make_model(sim.model, robot),
        integrator=make_integrator(sim.integrator, robot.model, sim.substeps, sim.rtol, sim.atol),
        controller=controller,
    )


def simulate_scene(
    scene: Scene, progress: Callable[[int], None] | None = None
) -> tuple[Prepared, RunResult, dict[str, object]]:
    """Run a scene; return its setup, the raw result and the summary metrics."""
    prepared = prepare(scene)
    sim = scene.simulation
    result = run(
        prepared.robot, prepared.q0, prepared.v0, sim.duration, sim.control_period,
        prepared.integrator, prepared.model, prepared.controller,
        record_every=sim.record_every, progress=progress,
    )
    summary = summarize(result.telemetry, prepared.robot) if len(result.telemetry.t) else {}
    summary.update(status=result.status, message=result.message, steps=result.steps,
                   sim_wall_time_s=result.wall_time_s, model_evaluations=result.evaluations)
    return prepared, result, summary
