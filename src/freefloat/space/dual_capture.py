"""Capture of one tumbling target by two hands at once, and detumbling through the loop it closes.

Before contact the target flies freely and the robot holds its posture
(:func:`~freefloat.space.capture.approach`); contact is declared when *both* grasp points are
within the tolerance of their hands. At that instant the two welds close together: the robot and
the target become one Pinocchio tree (the target a second free-flyer root) and the impulse of
:func:`~freefloat.dynamics.closures.closing_impulse` stops both hands' relative motion with the
target in one solve (12 rows, not two welds one after the other); the impulse is internal, so
robot + target momentum is kept exactly. Each weld holds the relative pose the hand had at
contact. Afterwards the target's inertia rides on the first hand's body (as in a one-hand
capture) and the second weld is a loop closure of the merged robot, simulated by the
constrained dynamics and detumbled by :class:`~freefloat.space.control.loop_detumbling.LoopDetumblingController`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from ..dynamics.closures import KINDS, ClosedModel, Closure, closing_impulse, closure_drift, solve
from ..robot.conventions import momentum_about_origin
from ..robot.robot import Robot
from .capture import TARGET_FRAME, Target, TargetBody, approach, attach, frame_poses

#: The merged robot's frame on the target where the second hand holds it.
SECOND_GRASP_FRAME = "captured_target_grasp_2"


@dataclass(frozen=True)
class TwoHandImpact:
    """The simultaneous grasp.

    Attributes:
        v_robot: robot velocity after the impact (nv,).
        v_target: target local twist after the impact (6,).
        impulse: the two welds' impulses (12,): per hand [linear; angular] on the target's grasp
            frame, in the hand frame's axes (N s, N m s).
        momentum_before, momentum_after: robot + target [P; L about the origin] (6,).
    """

    v_robot: np.ndarray
    v_target: np.ndarray
    impulse: np.ndarray
    momentum_before: np.ndarray
    momentum_after: np.ndarray


def robot_and_target(robot: Robot, body: TargetBody) -> pin.Model:
    """One Pinocchio tree: the robot's, with the target's free-flyer appended as a second root
    (configuration ``[q_robot; q_target]``, velocity ``[v_robot; v_target]``)."""
    model = pin.appendModel(robot.model, body.model, 0, pin.SE3.Identity())
    model.gravity = robot.model.gravity
    return model


def grasp_welds(model: pin.Model, data: pin.Data, hands: tuple[str, ...]) -> list[Closure]:
    """One weld per hand of ``model`` (a :func:`robot_and_target` tree at the state ``data``
    holds): the hand frame (frame 1) to a frame on the target at the hand's current pose."""
    target = model.getJointId("target")
    welds = []
    for hand in hands:
        frame = model.frames[model.getFrameId(hand)]
        oM_hand = data.oMi[frame.parentJoint] * frame.placement
        welds.append(Closure(f"{hand}-target", KINDS["weld"], frame.parentJoint, frame.placement, target,
                             data.oMi[target].actInv(oM_hand), (hand, "target")))
    return welds


def two_hand_impact(robot: Robot, hands: tuple[str, ...], q: np.ndarray, v: np.ndarray, body: TargetBody,
                    q_t: np.ndarray, v_t: np.ndarray) -> TwoHandImpact:
    """Both hands' welds closed at once (module docstring)."""
    model = robot_and_target(robot, body)
    data = model.createData()
    q_all, v_all = np.concatenate((q, q_t)), np.concatenate((v, v_t))
    pin.forwardKinematics(model, data, q_all)
    hit = closing_impulse(model, data, q_all, v_all, grasp_welds(model, data, hands))
    nv = robot.model.nv
    return TwoHandImpact(hit.v_after[:nv], hit.v_after[nv:], hit.impulse,
                         momentum_about_origin(model, data, q_all, v_all),
                         momentum_about_origin(model, data, q_all, hit.v_after))


def attach_with_loop(robot: Robot, hands: tuple[str, ...], q: np.ndarray, body: TargetBody,
                     q_t: np.ndarray) -> tuple[Robot, Closure]:
    """The robot with the target's inertia on the first hand's body (:func:`attach`), a frame
    :data:`SECOND_GRASP_FRAME` on it where the second hand is at ``q``, and the weld that closes
    the loop there (frame 1: the second hand)."""
    merged = attach(robot, hands[0], q, body, q_t)
    model = merged.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    first = model.frames[model.getFrameId(hands[0])].parentJoint
    oM_second = data.oMf[model.getFrameId(hands[1])]
    model.addFrame(pin.Frame(SECOND_GRASP_FRAME, first, data.oMi[first].actInv(oM_second), pin.FrameType.OP_FRAME))
    return merged, Closure.between(model, hands[1], SECOND_GRASP_FRAME, KINDS["weld"], f"{hands[1]}-target")


@dataclass
class TwoHandCapture:
    """A two-hand capture and detumbling run.

    Attributes:
        pre: telemetry before contact; post: after the impact (the merged robot; time from the impact).
        merged: the robot with the target on the first hand; closure: the loop's weld.
        impact_time: s; hit: the impact.
        post_result: the post-capture run's result (status, message, wall time).
        controller: the loop law (its log).
        target_poses: target CoM poses, inertial (rows of pre then post, 4, 4).
        grasp_poses: the two grasp frames' poses over the same rows (2, N, 4, 4).
    """

    pre: Any
    post: Any
    merged: Robot
    closure: Closure
    impact_time: float
    hit: TwoHandImpact
    post_result: Any
    controller: Any
    target_poses: np.ndarray
    grasp_poses: np.ndarray


def second_grasp_at_contact(robot: Robot, hands: tuple[str, ...], q: np.ndarray, grasp: np.ndarray,
                            rotation_at_contact: np.ndarray) -> np.ndarray:
    """The second grasp point (target body frame, from the CoM, m) that meets the second hand
    when the first grasp point ``grasp`` meets the first hand (``Target.meeting``) with the
    target's orientation ``rotation_at_contact`` (3, 3) and the robot holding its posture ``q``."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    hand1, hand2 = (data.oMf[robot.model.getFrameId(h)].translation for h in hands)
    com = hand1 - rotation_at_contact @ np.asarray(grasp, float)
    return rotation_at_contact.T @ (hand2 - com)


def loop_conditioning(robot: Robot, hands: tuple[str, ...], q: np.ndarray) -> float:
    """How far from singular the loop two hands close is at ``q``: the smallest over the largest
    singular value of the joints' map to the hands' relative twist (world axes; 0: the hands
    cannot move relative to each other in some direction, and a weld between them is singular)."""
    model, data = robot.model, robot.model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    first, second = (pin.getFrameJacobian(model, data, model.getFrameId(h), pin.LOCAL_WORLD_ALIGNED)[:, robot.n_base:]
                     for h in hands[:2])
    singular = np.linalg.svd(second - first, compute_uv=False)
    return float(singular[-1] / singular[0]) if singular[0] > 0 else 0.0


def capture_with_two_hands(robot: Robot, target: Target, hands: tuple[str, ...], second_grasp: np.ndarray,
                           rows: np.ndarray, joints: np.ndarray, control_period: float, approach_time: float,
                           detumble_time: float, tolerance: float = 1e-3, integrator: str = "rkmk4",
                           q0: np.ndarray | None = None, v0: np.ndarray | None = None, kp: float = 10.0,
                           kd: float = 100.0, baumgarte: float = 0.0, squeeze: float = 0.0,
                           torque_limit: float = 0.0, progress: Any = None, checkpoint: Any = None,
                           backend: str = "auto", approach_controller: Any = None,
                           grasp_time: float = 0.0) -> TwoHandCapture:
    """Hold (or follow ``approach_controller``, a planned approach of both hands, not grasping
    before ``grasp_time`` s) until both grasp points reach both hands, close both welds by one impulse, then
    detumble the merged robot through the loop (module docstring). ``backend``: the post-grasp
    run's loop (``dynamics.simulation.run``; ``"auto"``: the compiled loop, closures and law in C++).

    Raises:
        FreefloatError: when the grasp points do not both come within ``tolerance`` of the hands in
            ``approach_time`` (the message names the hands and gives the closest approach).
    """
    from ..dynamics.integrators import make_integrator
    from ..dynamics.simulation import run
    from .control.loop_detumbling import LoopDetumblingController

    body = TargetBody(target, (np.asarray(second_grasp, float),))
    pre, flight = approach(robot, body, hands, control_period, approach_time, tolerance, integrator, q0, v0, kp, kd,
                           "exact", approach_controller, grasp_time)
    t_hit = float(pre.telemetry.t[-1])
    q, v = pre.telemetry.q[-1], pre.telemetry.v[-1]
    hit = two_hand_impact(robot, hands, q, v, body, flight.q, flight.v)
    merged, closure = attach_with_loop(robot, hands, q, body, flight.q)
    controller = LoopDetumblingController(merged, closure, TARGET_FRAME, target.mass, np.asarray(target.inertia),
                                          rows, joints, control_period, kd, baumgarte, squeeze, torque_limit)
    post = run(merged, q, hit.v_robot, detumble_time, control_period, make_integrator(integrator, merged.model),
               ClosedModel(merged, [closure], baumgarte), controller, progress=progress,
               checkpoint=checkpoint, backend=backend)
    poses = np.concatenate((flight.poses[: len(pre.telemetry.t)], frame_poses(merged, TARGET_FRAME, post.telemetry.q)[1:]))
    grasps = np.stack([np.concatenate((_carried(flight.poses[: len(pre.telemetry.t)], target, point),
                                       frame_poses(merged, name, post.telemetry.q)[1:]))
                       for point, name in ((target.grasp, hands[0]), (second_grasp, SECOND_GRASP_FRAME))])
    return TwoHandCapture(pre.telemetry, post.telemetry, merged, closure, t_hit, hit, post, controller, poses, grasps)


def _carried(poses: np.ndarray, target: Target, point: np.ndarray) -> np.ndarray:
    """Poses of a point fixed on the target (body frame) along the target's poses (N, 4, 4)."""
    out = poses.copy()
    out[:, :3, 3] = poses[:, :3, 3] + poses[:, :3, :3] @ np.asarray(point, float)
    return out


@dataclass
class LoopHistory:
    """The loop over a run, at the start of each control period (the telemetry rows but the last).

    Attributes:
        t: period starts, s (N,).
        squeeze: internal force along grasp 2 -> grasp 1, N (N,).
        internal: norm of the internal wrench's force part, N (N,).
        force: the closure force lambda (N, 6): [force; moment about the second grasp point] on the
            target, in the second hand's frame axes (N, N m).
        drift_position, drift_rotation: closure residuals, m and rad (N,).
    """

    t: np.ndarray
    squeeze: np.ndarray
    internal: np.ndarray
    force: np.ndarray
    drift_position: np.ndarray
    drift_rotation: np.ndarray


def loop_history(capture: TwoHandCapture, target: Target, baumgarte: float) -> LoopHistory:
    """The plant's closure force, internal wrench and drift at the start of every post-capture
    control period (the constrained dynamics re-solved there with the period's held torques)."""
    from .control.loop_detumbling import internal_wrench

    merged, closure, tel = capture.merged, capture.closure, capture.post
    model, data = merged.model, merged.model.createData()
    nb, n = merged.n_base, max(len(tel.t) - 1, 0)
    out = LoopHistory(tel.t[:n].copy(), np.zeros(n), np.zeros(n), np.zeros((n, 6)), np.zeros(n), np.zeros(n))
    tau = np.zeros(model.nv)
    for k in range(n):
        q, v = tel.q[k], tel.v[k]
        tau[nb:] = tel.tau[k]  # held over [t_k, t_k+1)
        sol = solve(model, data, q, v, tau, [closure], baumgarte)
        out.squeeze[k], wrench = internal_wrench(merged, closure, TARGET_FRAME, target.mass, np.asarray(target.inertia),
                                                 q, v, sol.acceleration, sol.force)
        out.internal[k] = float(np.linalg.norm(wrench[:3]))
        out.force[k] = sol.force
        out.drift_position[k], out.drift_rotation[k] = closure_drift(model, data, q, [closure])
    return out


__all__ = ["SECOND_GRASP_FRAME", "LoopHistory", "TwoHandCapture", "TwoHandImpact", "attach_with_loop",
           "capture_with_two_hands", "grasp_welds", "loop_conditioning", "loop_history", "robot_and_target",
           "second_grasp_at_contact", "two_hand_impact"]
