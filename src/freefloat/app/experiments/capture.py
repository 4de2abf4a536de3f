"""Capture experiments (dissertation sec 3.8, done exactly): the robot holds its posture until a
tumbling target's grasp point reaches the end-effector, grasps it by an exact impulse, then the
merged robot detumbles it. With ``[approach]`` the pre-capture phase is planned instead
(:mod:`freefloat.space.planning`): the hand is brought onto the grasp point at the contact time
with its velocity, tracked by computed torque, so one scene runs the three phases."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ...dynamics.metrics import spin_summary, summarize
from ...dynamics.result import Result
from ...errors import FreefloatError, InfeasiblePlan, SceneError, did_you_mean
from ...space.capture import SUMMARY_UNITS as CAPTURE_UNITS
from ...space.capture import Environment, Target, capture_and_detumble
from ...space.orbit.field import OrbitField
from ...space.planning import ApproachRequest, GraspMotion, Limits, Plan, plan_approach, planned_path
from ...space.planning.plan import SUMMARY_UNITS as PLAN_UNITS
from ...space.planning.tracking import PlanTracking
from ..controllers import JointGains
from ..environments import ENVIRONMENTS
from ..scenes import Scene
from ..viz.figure_job import LvlhRows
from .base import Checkpoint, Experiment, Outcome, Progress
from .detumbling import detumble_task, mission_joints, rows_spec
from .robot_run import (
    APPROACH_MARGIN,
    SPIN_HEADLINE,
    RobotSetup,
    control_steps,
    headline_of,
    prepare_robot,
    robot_outcome,
)
from .robot_run import UNITS as ROBOT_UNITS
from .wheel_run import CaptureWheels, capture_wheel_telemetry

#: How the page draws the target: orange (0xRRGGBB), apart from the robot's greys and blues.
TARGET_COLOR = 0xE07000


@dataclass(kw_only=True)
class CaptureSetup(RobotSetup):
    """A capture scene resolved before the loop: the robot's setup and the target, which meets
    the end-effector at ``target.contact_time``; with ``[approach]`` the checked plan that brings
    the end-effector there, and the minimum-norm plan of the same approach when compared."""

    target: Target
    plan: Plan | None = None
    min_norm: Plan | None = None


def takes(scene: object) -> bool:
    """A robot scene whose ``[target]`` one hand grasps (no ``second_end_effector``)."""
    return isinstance(scene, Scene) and scene.target is not None and not scene.target.second_end_effector


def prepare(scene: Scene) -> CaptureSetup:
    """The robot, its start, the detumble task checked on it, and the target placed so that its
    grasp point meets the end-effector at ``target.contact_time`` (``approach.reach`` from where
    the hand starts, with an ``[approach]``: then planned here).

    Raises:
        SceneError: naming ``target.end_effector``, a ``[task]`` key, a bad ``[target]``, an
            approach that cannot be planned, or a ``[controller]`` without the computed-torque
            gains the capture's laws read.
    """
    if not isinstance(scene.controller.settings, JointGains):
        raise SceneError(f"scene '{scene.name}': a capture's laws are computed torque with the [controller] gains "
                         f"(kind 'computed_torque' or 'detumbling'), not controller '{scene.controller.kind}'")
    setup = prepare_robot(scene)
    robot, tg = setup.robot, scene.target
    detumble_task(robot, scene)
    if tg.end_effector not in robot.end_effectors:
        raise SceneError(f"scene '{scene.name}': target.end_effector '{tg.end_effector}' is not an end-effector"
                         f"{did_you_mean(tg.end_effector, robot.end_effectors, 'end-effectors')}")
    target = scene_target(scene, setup, (0.0, 0.0, 0.0) if scene.approach is None else scene.approach.reach)
    capture_fields(setup)
    if scene.approach is None or tg.second_end_effector:  # a two-hand plan is made once both grasps are known
        return CaptureSetup(**vars(setup), target=target)
    return CaptureSetup(**vars(setup), target=target,
                        **planned(scene, setup, (tg.end_effector,), (GraspMotion.of(target),)))


def refuse_environment(scene: Scene, what: str) -> None:
    """Refuse a scene with an ``[[environment]]`` for a capture that flies in none (``what``
    names it: "a two-hand capture"), instead of running it as if the entry were not there.

    Raises:
        SceneError: naming the first entry's kind.
    """
    if scene.environment:
        raise SceneError(f"{scene.source or f'scene {scene.name!r}'}: [[environment]] kind "
                         f"'{scene.environment[0].kind}' is not applied by {what} (only the one-hand capture flies "
                         "in an 'orbit'): remove it")


def capture_fields(setup) -> Environment | None:
    """The fields a capture flies in: those of the scene's orbits (``[[environment]] kind =
    "orbit"``) on any robot or body, ``fields(model, start)`` for a run starting at ``start`` s
    (:data:`~freefloat.space.capture.Environment`), or None out of orbit.

    Raises:
        SceneError: naming an ``[[environment]]`` entry of another kind, which a capture does not
            apply (it would act on the scene's robot only, not on the target or the merged robot).
    """
    scene = setup.scene
    others = [e.kind for e in scene.environment if e.kind != "orbit"]
    if others:
        raise SceneError(f"{scene.source or f'scene {scene.name!r}'}: [[environment]] kind '{others[0]}' is not "
                         "applied by a capture (it flies in an 'orbit' only): remove it")
    orbits = [f.orbit for f in setup.environment if isinstance(f, OrbitField)]
    if not orbits:
        return None
    return lambda model, start: tuple(OrbitField(model, orbit.later(start)) for orbit in orbits)


def scene_target(scene: Scene, setup, reach) -> Target:
    """The scene's target, flying so that its grasp point meets ``target.end_effector`` at
    ``target.contact_time`` at the hand's start position plus ``reach`` (inertial, m (3,)).

    Raises:
        SceneError: naming ``[target]`` when the target cannot be placed.
    """
    robot, tg, s = setup.robot, scene.target, scene.angle_scale
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, setup.q0)
    point = data.oMf[robot.model.getFrameId(tg.end_effector)].translation + np.asarray(reach, float)
    try:
        return Target.meeting(point, tg.contact_time, tg.mass, tg.inertia, tg.grasp, tg.velocity,
                              np.multiply(tg.angular_velocity, s), np.multiply(tg.rpy_at_contact, s), tg.size)
    except Exception as exc:
        raise SceneError(f"scene '{scene.name}': [target] {exc}") from exc


def approach_key(scene: Scene) -> str:
    """Where a message about ``[approach]`` points: the scene's file (or its name) and the table."""
    return f"{scene.source or f'scene {scene.name!r}'}: [approach]"


def approach_request(scene: Scene, setup, hands: tuple[str, ...], grasps: tuple[GraspMotion, ...]) -> ApproachRequest:
    """The request of the scene's ``[approach]`` for ``hands`` onto ``grasps`` (flights in scene
    time): from ``approach.start`` (the initial posture, at rest when later than 0) to
    ``target.contact_time``, its limits (angle unit converted), mission joints and grid, a
    tolerance of a tenth of ``target.tolerance``.

    Raises:
        SceneError: naming ``[approach]`` for a bad limit, an unknown ``approach.mission_joints``,
            a start not before the contact, a late start from a moving robot, a ``turn`` without
            ``match = "pose"``, or ``controller.kind = "none"`` (the plan is tracked by computed torque).
    """
    ap, robot = scene.approach, setup.robot
    joints = None if ap.mission_joints is None else mission_joint_indices(robot, ap.mission_joints)
    rate = None if ap.max_joint_rate is None else ap.max_joint_rate * scene.angle_scale
    where = approach_key(scene)
    if ap.start >= scene.target.contact_time:
        raise SceneError(f"{where} 'start' {ap.start} s must come before 'target.contact_time' "
                         f"{scene.target.contact_time} s")
    if ap.start > 0.0 and np.abs(setup.v0).max() > 0.0:
        raise SceneError(f"{where} 'start' {ap.start} s plans from the initial posture held at rest: the [initial] "
                         "velocities must be zero (or start at 0)")
    if ap.match == "position" and any(ap.turn):
        raise SceneError(f"{where} 'turn' {list(ap.turn)} turns the hand's handle, which only 'match' = \"pose\" "
                         "plans; with \"position\" remove it (or set match = \"pose\")")
    if scene.controller.kind == "none":
        raise SceneError(f"{where} is tracked by computed torque on the plan, but 'controller.kind' is \"none\"; "
                         "set it to \"computed_torque\" (its gains and model track the plan), or remove [approach]")
    if ap.match == "pose":
        grasps = handles(scene, setup, hands, grasps)
    try:
        return ApproachRequest(robot, setup.q0, setup.v0, hands, tuple(g.shifted(ap.start) for g in grasps),
                               scene.target.contact_time - ap.start, Limits.of(robot, rate, ap.max_torque), joints,
                               ap.steps, tolerance=0.1 * scene.target.tolerance, match=ap.match)
    except FreefloatError as exc:
        raise SceneError(f"{approach_key(scene)} {str(exc).removeprefix('approach: ')}") from exc


def handles(scene: Scene, setup, hands: tuple[str, ...], grasps: tuple[GraspMotion, ...]) -> tuple[GraspMotion, ...]:
    """The grasp flights with their handles (``match = "pose"``): each hand's start orientation
    turned by ``approach.turn`` (inertial rotation vector, angle unit) is the handle's orientation
    at ``target.contact_time``, fixed on the target from there."""
    robot, contact = setup.robot, scene.target.contact_time
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, setup.q0)
    turn = pin.exp3(np.multiply(scene.approach.turn, scene.angle_scale))
    out = []
    for hand, grasp in zip(hands, grasps):
        target_then = pin.exp3(grasp.angular_velocity * contact) @ grasp.rotation
        handle = target_then.T @ turn @ data.oMf[robot.model.getFrameId(hand)].rotation
        out.append(dataclasses.replace(grasp, handle=handle))
    return tuple(out)


def planned(scene: Scene, setup, hands: tuple[str, ...], grasps: tuple[GraspMotion, ...]) -> dict[str, Plan | None]:
    """The scene's approach plan of ``hands`` onto ``grasps`` (``plan``) and, with
    ``approach.compare``, the minimum-norm plan of the same request (``min_norm``; unchecked,
    since it is only compared).

    Raises:
        SceneError: naming ``[approach]`` with what fails (out of reach, a limit, the deadline),
            or a bad request (:func:`approach_request`).
    """
    request = approach_request(scene, setup, hands, grasps)
    try:
        plan = plan_approach(request, scene.approach.method)
    except FreefloatError as exc:
        raise SceneError(f"{approach_key(scene)} {str(exc).removeprefix('approach: ')}") from exc
    compared = None
    if scene.approach.compare:
        try:
            compared = planned_path(request, "min_norm")
        except InfeasiblePlan:  # only compared: a diverging minimum-norm plan leaves no ratio
            compared = None
    return {"plan": plan, "min_norm": compared}


def mission_joint_indices(robot, names: tuple[str, ...]) -> np.ndarray:
    """Indices of ``names`` among the robot's joints (n_mission,).

    Raises:
        SceneError: naming ``approach.mission_joints`` and the joints.
    """
    unknown = [name for name in names if name not in robot.joint_names]
    if unknown:
        raise SceneError(f"'approach.mission_joints': no joint '{unknown[0]}'"
                         f"{did_you_mean(unknown[0], robot.joint_names, 'joints')}")
    return np.array([robot.joint_names.index(name) for name in names], dtype=int)


def plan_tracking(setup: CaptureSetup) -> PlanTracking | None:
    """Computed torque (``[controller]`` gains and model) on the setup's plan from
    ``approach.start``; None without a plan (the capture holds its posture)."""
    if setup.plan is None:
        return None
    ctrl = setup.scene.controller
    return PlanTracking(setup.robot, setup.plan.path, ctrl.kp, ctrl.kd, ctrl.model, setup.scene.approach.start)


def grasp_time(setup: CaptureSetup) -> float:
    """When the hands may close: the planned contact time, or at once without a plan (s)."""
    return 0.0 if setup.plan is None else setup.scene.target.contact_time


#: The capture's headline keys: the spin's settling, and a planned approach's base rotation, its
#: ratio to the minimum-norm plan's and the grasp mismatch.
TASK_HEADLINE = SPIN_HEADLINE + ("approach_base_attitude_change", "approach_attitude_ratio", "grasp_position_mismatch")
#: The unit of each key :func:`approach_summary` adds to the plan's own
#: (:data:`freefloat.space.planning.plan.SUMMARY_UNITS`).
UNITS = {"approach_min_norm_attitude_change": "rad", "approach_attitude_ratio": "",
         "target_lvlh_relative_grasp": "m", "target_lvlh_relative_final": "m"}


def approach_summary(setup: CaptureSetup) -> dict:
    """The plan's figures of merit, the limits used and, when compared, the minimum-norm plan's
    base attitude change and the ratio of the two (min-norm / this plan)."""
    plan = setup.plan
    out = plan.summary()
    if setup.min_norm is not None:
        out["approach_min_norm_attitude_change"] = setup.min_norm.attitude_change
        out["approach_attitude_ratio"] = setup.min_norm.attitude_change / max(plan.attitude_change, 1e-300)
    return out


def run(setup: CaptureSetup, progress: Progress | None = None, checkpoint: Checkpoint | None = None) -> Outcome:
    """Approach, grasp and detumbling; the summary of the post-capture run with the grasp's
    momentum balance (merged robot after against robot + target before); the animation of both
    phases with the target and the grasp instant. (The capture runs as one call: no progress
    report nor checkpoints.)"""
    scene, robot = setup.scene, setup.robot
    tg, sim, ctrl = scene.target, scene.simulation, scene.controller
    fields = capture_fields(setup)
    start = time.perf_counter()
    wheels = None if setup.wheels is None else CaptureWheels(scene, setup.wheels, setup.q0)
    res = capture_and_detumble(robot, setup.target, tg.end_effector, rows_spec(scene), mission_joints(scene),
                               scene.task.method, sim.control_period, tg.contact_time + APPROACH_MARGIN, sim.duration,
                               tg.tolerance, integrator=sim.integrator, q0=setup.q0, v0=setup.v0,
                               kp=ctrl.kp, kd=ctrl.kd, model=ctrl.model,
                               approach_controller=plan_tracking(setup), grasp_time=grasp_time(setup), compose=wheels,
                               environment=fields)
    wall = time.perf_counter() - start
    merged = dataclasses.replace(res.merged, visual_model=robot.visual_model)
    tel = res.post
    result = Result(tel, res.summary["status"], "", len(tel.t) - 1, wall, 0)
    after = () if fields is None else fields(merged, res.impact_time)
    summary = summarize(tel, merged, (), sim.control_period, after)  # after the grasp: balances in fields, else drifts
    for field, entry in zip(after, [e for e in scene.environment if e.kind == "orbit"]):
        summary.update(ENVIRONMENTS[entry.kind].summarise(field, merged, tel))
    summary.update(spin_summary(merged, tel))
    summary.update(res.summary, sim_wall_time_s=wall, steps=len(res.pre.t) + len(tel.t) - 2)
    if after:  # in fields the momentum is not conserved: momentum_balance_max balances it against their impulse
        del summary["momentum_drift_after_impact"]
    if setup.plan is not None:
        summary.update(approach_summary(setup))
    both_t = np.concatenate((res.pre.t, res.impact_time + tel.t[1:]))
    both_q = np.concatenate((res.pre.q, tel.q[1:]))
    poses = np.concatenate((res.target_poses[: len(res.pre.t)], res.target_poses[len(res.pre.t) + 1:]))
    if wheels is not None:
        setup.wheel_control = wheels.law
    lvlh = None
    if fields is not None:
        orbit = next(f.orbit for f in setup.environment if isinstance(f, OrbitField))
        lvlh = relative_orbit(orbit, both_t, len(res.pre.t) - 1,
                              np.concatenate((res.pre.base_position, tel.base_position[1:])), poses[:, :3, 3])
        summary.update(target_lvlh_relative_grasp=lvlh.relative[0].tolist(),
                       target_lvlh_relative_final=lvlh.relative[1].tolist())
        lvlh = lvlh.rows
    return robot_outcome(setup, merged, tel, result, summary, animation=(both_t, both_q),
                         extra_bodies=lambda: [("target", target_box(tg.size), poses)],
                         extra_telemetry={"pre_capture": res.pre}, events=[(res.impact_time, "grasp")], wrenches=(),
                         spin=True, settle_threshold=res.summary["settle_threshold"],
                         approach=None if setup.plan is None else res.pre, task_headline=TASK_HEADLINE,
                         wheel_rows=None if wheels is None else capture_wheel_telemetry(setup.wheels, setup.target, res),
                         lvlh=lvlh, environment=after)


class RelativeOrbit(NamedTuple):
    """A capture in orbit in the LVLH frame: the ``relative_orbit`` figure's rows, and the
    target's CoM less the chaser base's CoM in LVLH axes at the grasp and at the end (2, 3), m."""

    rows: LvlhRows
    relative: np.ndarray


def relative_orbit(orbit, t: np.ndarray, grasp_row: int, base: np.ndarray, target: np.ndarray) -> RelativeOrbit:
    """The base and target CoMs (simulation frame, (N, 3) each, m) at the capture's times ``t``
    (N,), s, of ``orbit`` (:class:`~freefloat.space.orbit.CircularOrbit`) in its LVLH frame, and
    the target relative to the base there at row ``grasp_row`` and at the last."""
    positions = np.stack([orbit.to_lvlh(t, points)[0] for points in (base, target)], axis=1)
    return RelativeOrbit(LvlhRows(t, ["base CoM", "target CoM"], positions),
                         positions[[grasp_row, -1], 1] - positions[[grasp_row, -1], 0])



def target_box(size: tuple[float, float, float]) -> object:
    """The page's target: an orange box of ``size`` (m, along its x, y, z), a meshcat object
    (meshcat imported here: a run that draws no page never imports it)."""
    import meshcat.geometry as mg

    return mg.Mesh(mg.Box(list(size)), mg.MeshPhongMaterial(color=TARGET_COLOR))


EXPERIMENT = Experiment("capture", "a robot grasps a tumbling target and detumbles it",
                        "robot scenes with a [target] grasped by one hand", takes,
                        prepare, control_steps, run, headline_of(TASK_HEADLINE),
                        {**ROBOT_UNITS, **CAPTURE_UNITS, **PLAN_UNITS, **UNITS})
