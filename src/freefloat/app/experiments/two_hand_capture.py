"""Two-hand capture experiments: both hands of a robot grasp one tumbling target at once (one
impulse closing both welds), then detumble it through the loop it closes
(:mod:`freefloat.space.dual_capture`)."""

from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...dynamics.metrics import momentum_drift, settling_time, spin_summary, summarize
from ...dynamics.result import Result
from ...errors import FreefloatError, SceneError, did_you_mean
from ...robot.conventions import momentum_about_origin
from ...robot.loading import FreefloatWarning
from ...space.capture import SUMMARY_UNITS as CAPTURE_UNITS
from ...space.capture import target_angular_speed
from ...space.dual_capture import capture_with_two_hands, loop_conditioning, loop_history, second_grasp_at_contact
from ...space.planning import GraspMotion
from ...space.planning.plan import SUMMARY_UNITS as PLAN_UNITS
from ..scenes import Scene
from .base import Checkpoint, Experiment, Outcome, Progress
from .capture import (
    TARGET_COLOR,
    CaptureSetup,
    approach_summary,
    grasp_time,
    plan_tracking,
    planned,
    refuse_environment,
)
from .capture import TASK_HEADLINE as CAPTURE_HEADLINE
from .capture import UNITS as APPROACH_UNITS
from .capture import prepare as prepare_one_hand
from .detumbling import mission_joints, rows_spec
from .robot_run import APPROACH_MARGIN, control_steps, headline_of, robot_outcome
from .robot_run import UNITS as ROBOT_UNITS

#: How the page draws the target (see-through, so that the loop inside shows), the grasp points (a
#: green and a blue ball) and the loop's closing link through the target (a red bar between them).
TARGET_OPACITY = 0.35
GRASP_COLORS = (0x20A040, 0x2060D0)
LOOP_COLOR = 0xC02020
#: Smallest over largest singular value of the hands' relative motion below which the grasp posture
#: is called singular: at the satellite's zero posture (1.5e-27) the run's momentum drifted by
#: 7.9e-6 N s in 1 s, against 1.9e-13 at the bent posture the scene uses (conditioning 0.12).
SINGULAR_LOOP = 1e-6
#: Share of the target's spin just after the grasp below which the detumbling counts as settled.
SETTLED_SHARE = 1e-4
#: The two-hand capture's headline keys: the one-hand capture's and the squeeze of the loop.
TASK_HEADLINE = CAPTURE_HEADLINE + ("squeeze_max",)
#: The unit of each key of the two-hand task's summary (:func:`_loop_summary`; "" for a pure number).
UNITS = {
    "impact_time": "s", "momentum_before_impact": "N s, N m s", "momentum_after_impact": "N s, N m s",
    "momentum_balance_error": "N s or N m s", "momentum_drift_after_impact": "N s or N m s",
    "target_angular_velocity_at_impact": "rad/s", "target_angular_velocity_final": "rad/s", "settling_time": "s",
    "settle_threshold": "rad/s", "squeeze_max": "N", "squeeze_set": "N", "internal_force_max": "N",
    "closure_drift_max": "m", "closure_rotation_drift_max": "rad", "base_attitude_change_max": "rad",
    "peak_joint_torque": "N m", "torque_limited_share": "", "rows_residual_max": "m/s or rad/s",
}


@dataclass(kw_only=True)
class TwoHandSetup(CaptureSetup):
    """A two-hand capture scene resolved before the loop: the one-hand capture's setup (the target's
    first grasp point meets the first hand at ``target.contact_time``; no planned approach), the
    two hands and the second grasp point (target frame, m)."""

    hands: tuple[str, str]
    second_grasp: np.ndarray


def takes(scene: object) -> bool:
    """A robot scene whose ``[target]`` both hands grasp (``target.second_end_effector``)."""
    return isinstance(scene, Scene) and scene.target is not None and bool(scene.target.second_end_effector)


def prepare(scene: Scene) -> TwoHandSetup:
    """The one-hand capture's setup (:func:`.capture.prepare`), the second hand checked, and the
    second grasp point checked against where that hand is at contact.

    Raises:
        SceneError: naming ``target.second_end_effector``, ``target.second_grasp`` (with the point
            that would meet the hand), an ``[[environment]]`` or what the one-hand setup refuses.
    """
    refuse_environment(scene, "a two-hand capture")
    one = prepare_one_hand(scene)
    tg, robot = scene.target, one.robot
    where = f"{scene.source}: " if scene.source else f"scene '{scene.name}': "
    hands = (tg.end_effector, tg.second_end_effector)
    if hands[1] not in robot.end_effectors or hands[1] == hands[0]:
        raise SceneError(f"{where}'target.second_end_effector' '{hands[1]}' must be an end-effector other than "
                         f"'{hands[0]}'{did_you_mean(hands[1], [e for e in robot.end_effectors if e != hands[0]], 'others')}")
    rotation = pin.rpy.rpyToMatrix(*np.multiply(tg.rpy_at_contact, scene.angle_scale))
    meets = second_grasp_at_contact(robot, hands, one.q0, np.asarray(tg.grasp), rotation)
    if tg.second_grasp is None:
        second = meets
    else:
        second = np.asarray(tg.second_grasp, float)
        if second.shape != (3,):
            raise SceneError(f"{where}'target.second_grasp' must be three numbers (m), got {list(tg.second_grasp)}")
        miss = float(np.linalg.norm(second - meets))
        if miss > tg.tolerance:
            raise SceneError(f"{where}'target.second_grasp' {second.tolist()} is {miss:.4g} m from '{hands[1]}' when "
                             f"'target.grasp' meets '{hands[0]}' (tolerance {tg.tolerance} m): both contacts must "
                             f"close together; with this posture, second_grasp = {np.round(meets, 6).tolist()}")
    conditioning = loop_conditioning(robot, hands, one.q0)
    if conditioning < SINGULAR_LOOP:
        warnings.warn(f"{where}the hands' relative motion is singular at the grasp posture (conditioning "
                      f"{conditioning:.1e}): the loop's constraint loses a rank and the run loses accuracy; grasp "
                      "with the arms bent ([initial.joint_positions])", FreefloatWarning, stacklevel=2)
    plans = {}
    if scene.approach is not None:  # both hands onto both grasp points, the second at the same instant
        first = GraspMotion.of(one.target)
        grasps = (first, dataclasses.replace(first, grasp=second))
        plans = planned(scene, one, hands, grasps)
    return TwoHandSetup(**{**vars(one), **plans}, hands=hands, second_grasp=second)


def run(setup: TwoHandSetup, progress: Progress | None = None, checkpoint: Checkpoint | None = None) -> Outcome:
    """Approach, the two-hand grasp and detumbling through the loop; the summary (grasp momentum
    balance, the loop's squeeze and drift, target spin settling, base attitude), the loop figure,
    and the page with the target, both grasp points and the loop between them."""
    scene, robot = setup.scene, setup.robot
    tg, sim, ctrl = scene.target, scene.simulation, scene.controller
    start = time.perf_counter()
    try:
        res = capture_with_two_hands(
            robot, setup.target, setup.hands, setup.second_grasp, _rows(setup), _joints(setup), sim.control_period,
            tg.contact_time + APPROACH_MARGIN, sim.duration, tg.tolerance, sim.integrator, setup.q0, setup.v0, ctrl.kp, ctrl.kd,
            sim.baumgarte, ctrl.squeeze, ctrl.torque_limit or 0.0, progress, checkpoint, sim.backend,
            approach_controller=plan_tracking(setup), grasp_time=grasp_time(setup))
    except FreefloatError as exc:
        raise SceneError(f"scene '{scene.name}': {exc}") from exc
    history = loop_history(res, setup.target, sim.baumgarte)
    wall = time.perf_counter() - start
    merged = dataclasses.replace(res.merged, visual_model=robot.visual_model)
    tel, result = res.post, res.post_result
    summary = summarize(tel, merged)
    summary.update(spin_summary(merged, tel))
    summary.update(_loop_summary(res, history, setup))
    summary.update(status=result.status, message=result.message, sim_wall_time_s=wall,
                   steps=len(res.pre.t) + len(tel.t) - 2, loop=result.backend)
    if setup.plan is not None:
        summary.update(approach_summary(setup), **approach_outcome(res, setup))
    both_t = np.concatenate((res.pre.t, res.impact_time + tel.t[1:]))
    both_q = np.concatenate((res.pre.q, tel.q[1:]))
    outcome = robot_outcome(
        setup, merged, tel, Result(tel, result.status, result.message, len(tel.t) - 1, wall, 0), summary,
        animation=(both_t, both_q), extra_bodies=lambda: _page_bodies(tg.size, res.target_poses, res.grasp_poses),
        extra_telemetry={"pre_capture": res.pre}, events=[(res.impact_time, "both hands grasp")], wrenches=(),
        spin=True, settle_threshold=summary["settle_threshold"], approach=None if setup.plan is None else res.pre,
        task_headline=TASK_HEADLINE)
    from ..viz.figure_job import ClosedLoop

    outcome.figures = dataclasses.replace(outcome.figures, loop=ClosedLoop(
        history.t, history.squeeze, history.internal, history.drift_position, history.drift_rotation))
    return outcome


def approach_outcome(res, setup: TwoHandSetup) -> dict:
    """The simulated approach: the base attitude change from the start to the grasp (rad) and the
    largest grasp mismatch of the two hands just before it (m, m/s), from the pre-capture telemetry
    and the target's grasp poses (the grasp points' velocities from their last two poses, to
    within their acceleration times the control period)."""
    from ...space.capture import attitude_change

    pre, robot = res.pre, setup.robot
    model, data = robot.model, robot.model.createData()
    pin.forwardKinematics(model, data, pre.q[-1], pre.v[-1])
    row, dt = len(pre.t) - 1, pre.t[-1] - pre.t[-2]
    gaps, speeds = [], []
    for hand, grasp in zip(setup.hands, res.grasp_poses):
        frame = model.getFrameId(hand)
        gaps.append(np.linalg.norm(pin.updateFramePlacement(model, data, frame).translation - grasp[row, :3, 3]))
        hand_velocity = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED).linear
        speeds.append(np.linalg.norm(hand_velocity - (grasp[row, :3, 3] - grasp[row - 1, :3, 3]) / dt))
    return {"approach_base_attitude_change": attitude_change(pre.base_quaternion),
            "grasp_position_mismatch": float(max(gaps)), "grasp_velocity_mismatch": float(max(speeds))}


def _rows(setup: TwoHandSetup) -> np.ndarray:
    from ...space.detumbling import task_rows

    return task_rows(setup.robot, rows_spec(setup.scene))


def _joints(setup: TwoHandSetup) -> np.ndarray:
    from ...space.detumbling import joint_indices

    return joint_indices(setup.robot, mission_joints(setup.scene))


def _loop_summary(res, history, setup: TwoHandSetup) -> dict:
    """The task's figures of merit (SI units; angles rad)."""
    merged, tel = res.merged, res.post
    w = target_angular_speed(merged, tel.q, tel.v)
    after = momentum_about_origin(merged.model, merged.model.createData(), tel.q[0], tel.v[0])
    q_base = tel.base_quaternion
    attitude = [2.0 * np.arccos(min(1.0, abs(float(np.dot(q_base[0], qk))))) for qk in q_base]
    saturated = res.controller.log.saturated
    return {
        "impact_time": res.impact_time,
        "momentum_before_impact": res.hit.momentum_before.tolist(),
        "momentum_after_impact": after.tolist(),
        "momentum_balance_error": float(np.abs(after - res.hit.momentum_before).max()),
        "momentum_drift_after_impact": momentum_drift(tel.momentum),
        "target_angular_velocity_at_impact": float(w[0]),
        "target_angular_velocity_final": float(w[-1]),
        "settling_time": settling_time(tel.t, w, SETTLED_SHARE * w[0]),
        "settle_threshold": SETTLED_SHARE * float(w[0]),
        "squeeze_max": float(np.abs(history.squeeze).max(initial=0.0)),
        "squeeze_set": setup.scene.controller.squeeze,
        "internal_force_max": float(history.internal.max(initial=0.0)),
        "closure_drift_max": float(history.drift_position.max(initial=0.0)),
        "closure_rotation_drift_max": float(history.drift_rotation.max(initial=0.0)),
        "base_attitude_change_max": float(max(attitude)),
        "peak_joint_torque": float(np.abs(tel.tau).max()),
        "torque_limited_share": float(np.mean(saturated)) if saturated else 0.0,
        "rows_residual_max": float(max(res.controller.log.rows_residual, default=0.0)),
    }


def _page_bodies(size, target_poses: np.ndarray, grasp_poses: np.ndarray) -> list:
    """The target box, a ball at each grasp point and a bar between them (the loop's closing
    link through the target), posed over the page's frames (meshcat imported here, for the page only)."""
    import meshcat.geometry as mg

    target = mg.Mesh(mg.Box(list(size)), mg.MeshPhongMaterial(color=TARGET_COLOR, opacity=TARGET_OPACITY, transparent=True))
    bodies = [("target", target, target_poses)]
    for k, color in enumerate(GRASP_COLORS):
        bodies.append((f"grasp_{k + 1}", mg.Mesh(mg.Sphere(0.04), mg.MeshPhongMaterial(color=color)), grasp_poses[k]))
    span = grasp_poses[1, :, :3, 3] - grasp_poses[0, :, :3, 3]
    length = float(np.linalg.norm(span[0]))
    bar = np.repeat(np.eye(4)[None], len(span), axis=0)
    bar[:, :3, 3] = 0.5 * (grasp_poses[0, :, :3, 3] + grasp_poses[1, :, :3, 3])
    for k, d in enumerate(span):  # the cylinder's axis (y) along the span
        y = d / max(np.linalg.norm(d), 1e-12)
        x = np.cross(y, [0.0, 0.0, 1.0]) if abs(y[2]) < 0.9 else np.cross(y, [1.0, 0.0, 0.0])
        x /= np.linalg.norm(x)
        bar[k, :3, :3] = np.column_stack((x, y, np.cross(x, y)))
    bodies.append(("loop", mg.Mesh(mg.Cylinder(length, 0.015), mg.MeshPhongMaterial(color=LOOP_COLOR)), bar))
    return bodies


EXPERIMENT = Experiment("two_hand_capture", "both hands grasp one tumbling target at once and detumble it "
                        "through the closed loop", "robot scenes with a [target] grasped by both hands (target.second_end_effector)",
                        takes, prepare, control_steps, run, headline_of(TASK_HEADLINE),
                        {**ROBOT_UNITS, **CAPTURE_UNITS, **PLAN_UNITS, **APPROACH_UNITS, **UNITS})
