"""Reaction wheels in a robot scene: ``[[wheels]]`` mounted on the loaded robot, ``[attitude]``
composed with the arm's controller, and what a run reports about the wheels (summary keys, the
``telemetry_wheels.npz`` arrays, the ``reaction_wheels`` figure). The wheels run in joint-space
and detumbling scenes, with loop closures (the law reads the closed dynamics), with locked joints
(mounted on the reduced robot the loop simulates) and through a one-hand capture (the law around
each phase's, continued on the merged robot after the grasp; the target's momentum counted with
the rest of the system)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from ...dynamics.balance import applied
from ...dynamics.models.base import DynamicsModel
from ...dynamics.sensors.momentum import CONSERVED
from ...dynamics.simulation import Controller
from ...dynamics.telemetry import Arrays, Telemetry
from ...dynamics.wrenches import ExternalWrench, WrenchField
from ...errors import RobotModelError, SceneError
from ...robot.conventions import base_link_placement, momentum_about_origin
from ...robot.robot import Robot
from ...robot.wheels import Wheels, WheelSpec, mount_wheels
from ...space.capture import CaptureResult, Target, TargetBody
from ...space.control.wheel_attitude import WheelAttitudeControl
from ..scenes import Scene
from ..scenes.schema import AttitudeSection

#: The scene kinds whose runs compose the attitude law with their own.
KINDS = ("joint_space", "detumbling", "capture")
#: Summary keys about the wheels the command line prints.
HEADLINE = ("wheel_saturated", "wheel_momentum_max", "wheel_momentum_balance_max")
#: The unit of each key of :func:`wheel_summary` ("" for a pure number, a count or a record).
UNITS = {
    "wheel_momentum_final": "N m s", "wheel_momentum_max": "N m s", "wheel_momentum_limit": "N m s",
    "wheel_torque_max": "N m", "wheel_stored_momentum_change": "N m s", "arm_reaction_momentum": "N m s",
    "wheel_momentum_balance_max": "N m s", "tracking_error_max": "rad", "wheel_saturated": "",
    "wheel_saturation_events": "", "wheel_saturated_periods": "",
}


@dataclass
class WheelTelemetry(Arrays):
    """The wheels over a run, one row per telemetry sample (``telemetry_wheels.npz``).

    Attributes:
        t: time, s (N,).
        speed: wheel rates relative to the base ``Omega``, rad/s (N, nw).
        momentum: stored momentum of each wheel about its axis ``I Omega``, N m s (N, nw).
        torque: wheel torques held over [t_k, t_k+1), N m (N, nw).
        stored: the wheels' stored angular momentum ``sum_i I_i Omega_i R a_i``, inertial frame,
            N m s (N, 3).
        rest: angular momentum of everything else (the robot with its wheels not spinning
            relative to the base, from Pinocchio; in a capture, with the target: flying before the
            grasp, carried after) about the inertial origin, N m s (N, 3).
        balance: ``stored + rest`` minus its start value minus the external angular impulse
            about the origin (round-off when the wheels' momentum is the arm's reaction), N m s
            (N, 3); on a planar base its z component only (the joint's reaction torques change x, y).
    """

    t: np.ndarray
    speed: np.ndarray
    momentum: np.ndarray
    torque: np.ndarray
    stored: np.ndarray
    rest: np.ndarray
    balance: np.ndarray


def scene_wheels(scene: Scene, robot: Robot) -> Wheels | None:
    """The scene's ``[[wheels]]`` on ``robot`` (None without any).

    Raises:
        SceneError: naming the file and ``wheels[i]`` key for a wheel that cannot be mounted, and
            the keys wheels cannot be used with (a scene of a kind not in :data:`KINDS`: a
            two-hand capture, a capture with ``[identification]``), a plant model other than the exact one, a roll or pitch attitude
            on a planar base, a wheel among ``robot.locked_joints``, a detumbling task whose
            mission joints include a wheel or default to all joints).
    """
    if not scene.wheels:
        return None
    where = f"{scene.source}: " if scene.source else f"scene '{scene.name}': "
    specs = [WheelSpec(name=w.joint or w.name, max_momentum=w.max_momentum, max_torque=w.max_torque,
                       axis=None if w.joint else w.axis, position=w.position, mass=w.mass, inertia=w.inertia,
                       transverse_inertia=w.transverse_inertia, key=f"wheels[{i}]")
             for i, w in enumerate(scene.wheels)]
    try:
        wheels = mount_wheels(robot, specs)
    except RobotModelError as exc:
        raise SceneError(f"{where}{exc}") from exc
    if scene.kind not in KINDS:
        raise SceneError(f"{where}[[wheels]] run in {', '.join(KINDS)} scenes; this {scene.kind} scene's phases do "
                         "not run the attitude law")
    if scene.simulation.model not in ("exact", "auto"):
        raise SceneError(f"{where}'simulation.model' = {scene.simulation.model!r}: a scene with [[wheels]] simulates "
                         "the exact plant (the GJM models do not carry the rotors' momentum); set it to \"exact\" "
                         "or \"auto\"")
    if robot.base == "planar" and scene.attitude is not None and scene.attitude.rpy is not None \
            and len(scene.attitude.rpy) == 3 and any(scene.attitude.rpy[:2]):
        raise SceneError(f"{where}'attitude.rpy' = {list(scene.attitude.rpy)} rolls or pitches a planar base, which "
                         "turns about z only; give [0, 0, yaw]")
    names = {w.name for w in wheels.wheels}
    locked = sorted(names & set(scene.robot.locked_joints or ()))
    if locked:
        raise SceneError(f"{where}'robot.locked_joints' names the reaction wheel {', '.join(locked)}, which [attitude] "
                         "drives; lock arm joints only")
    if scene.task.kind == "detumble" and (scene.task.mission_joints is None or names & set(scene.task.mission_joints)):
        raise SceneError(f"{where}'task.mission_joints' must list the arm joints that detumble: the wheels "
                         f"({', '.join(sorted(names))}) are driven by [attitude]")
    return wheels


def target_rotation(scene: Scene, robot: Robot, q0: np.ndarray) -> np.ndarray:
    """The base-link rotation ``[attitude]`` holds (3, 3), inertial frame: the initial one, or the
    base CoM frame at ``attitude.rpy`` (angle_unit) turned back to the base-link frame."""
    rpy = None if scene.attitude is None else scene.attitude.rpy
    if rpy is None:
        return base_link_placement(robot, q0).rotation
    if len(rpy) != 3:
        raise SceneError(f"scene '{scene.name}': 'attitude.rpy' must be three angles, got {list(rpy)}")
    return pin.rpy.rpyToMatrix(*(np.multiply(rpy, scene.angle_scale))) @ robot.base_com_rotation.T


def wheel_attitude_control(scene: Scene, wheels: Wheels, arm: Controller | None, q0: np.ndarray,
                           closed: DynamicsModel | None = None) -> Controller | None:
    """The controller of a scene with wheels on the robot the loop simulates: the attitude law
    composed with the arm's controller (``[attitude] kind = "hold"``, the default), or free wheels
    under the arm's controller (``"none"``: no wheel torque); a controller that drives the wheels
    itself (``drives_wheels``, as momentum dumping does) runs alone. With ``closed`` (the plant's
    closed-loop dynamics, a copy of the law's own) the law reads the loop's response."""
    if getattr(arm, "drives_wheels", False):
        return arm
    attitude = scene.attitude or AttitudeSection()
    if attitude.kind == "none":
        return WheelAttitudeControl(wheels, arm, None, closed=closed)
    return WheelAttitudeControl(wheels, arm, target_rotation(scene, wheels.robot, q0), attitude.kp, attitude.kd,
                                closed=closed)


class CaptureWheels:
    """The wheels through a one-hand capture's phases (its ``compose``,
    :data:`freefloat.space.capture.Compose`): the scene's attitude law around the hold or approach,
    then the same law, its saturation record continued, around the detumbling of the merged robot.

    Attributes:
        law: the last phase's law (None before the first), whose record spans both phases.
    """

    def __init__(self, scene: Scene, wheels: Wheels, q0: np.ndarray):
        self.scene, self.wheels, self.q0 = scene, wheels, q0
        self.law: WheelAttitudeControl | None = None

    def __call__(self, robot: Robot, law: Controller, t0: float) -> Controller:
        """The phase's controller on ``robot`` from ``t0`` s (:data:`freefloat.space.capture.Compose`)."""
        if self.law is None:
            self.law = wheel_attitude_control(self.scene, self.wheels.on(robot), law, self.q0)
        else:
            self.law = self.law.continued(self.wheels.on(robot), law, t0)
        return self.law


def wheel_telemetry(wheels: Wheels, telemetry: Telemetry, wrenches: tuple[ExternalWrench, ...],
                    control_period: float, environment: tuple[WrenchField, ...] = ()) -> WheelTelemetry:
    """The wheels' rows of a run (:class:`WheelTelemetry`), balanced against the impulse of the
    ``wrenches`` and of the ``environment``'s fields."""
    robot, tel = wheels.robot, telemetry
    stored, rest = split_momentum(wheels, tel)
    impulse = (applied(robot, tel, wrenches, control_period, environment).impulse[:, 3:] if wrenches or environment
               else np.zeros_like(stored))
    return _rows(wheels, tel.t, tel.v, tel.tau, stored, rest, impulse)


def capture_wheel_telemetry(wheels: Wheels, target: Target, capture: CaptureResult) -> WheelTelemetry:
    """The wheels' rows through a capture of ``target``: the approach (``capture.pre`` on
    ``wheels.robot``, its last row the grasp's instant before the impulse), then the merged
    robot's run (``capture.post``, times from the grasp, its first row just after the impulse);
    ``rest`` counts the target, flying freely (its constant momentum about the origin) before the
    grasp and carried after, so the balance holds across the grasp's impulse (no external
    impulse)."""
    body = TargetBody(target)
    flying = body.momentum(*body.initial_state())[3:]
    stored_pre, rest_pre = split_momentum(wheels, capture.pre)
    stored_post, rest_post = split_momentum(wheels.on(capture.merged), capture.post)
    stored = np.concatenate((stored_pre, stored_post))
    rest = np.concatenate((rest_pre + flying, rest_post))
    pre, post = capture.pre, capture.post
    return _rows(wheels, np.concatenate((pre.t, capture.impact_time + post.t)), np.concatenate((pre.v, post.v)),
                 np.concatenate((pre.tau, post.tau)), stored, rest, np.zeros_like(stored))


def split_momentum(wheels: Wheels, telemetry: Telemetry) -> tuple[np.ndarray, np.ndarray]:
    """The wheels' stored angular momentum and the rest of the robot's (the robot with its wheels
    not spinning, from Pinocchio), about the inertial origin at each row, N m s (N, 3) each."""
    robot, tel = wheels.robot, telemetry
    model = robot.model
    data = model.createData()
    axes = wheels.axes()
    stored = np.array([base_link_placement(robot, q).rotation @ axes @ h for q, h in zip(tel.q, wheels.momenta(tel.v))])
    rest = np.array([momentum_about_origin(model, data, q, wheels.without_rates(v))[3:] for q, v in zip(tel.q, tel.v)])
    return stored, rest


def _rows(wheels: Wheels, t: np.ndarray, v: np.ndarray, tau: np.ndarray, stored: np.ndarray, rest: np.ndarray,
          impulse: np.ndarray) -> WheelTelemetry:
    """The :class:`WheelTelemetry` of rows at times ``t`` (N,), Pinocchio rates ``v`` (N, nv),
    joint torques ``tau`` (N, n_joints), with the external angular ``impulse`` (N, 3) so far."""
    total = stored + rest
    balance = np.zeros_like(total)
    conserved = CONSERVED[wheels.robot.base]
    kept = conserved[conserved >= 3] - 3  # L components the base's joint does not react
    balance[:, kept] = (total - total[0] - impulse)[:, kept]
    return WheelTelemetry(t=t, speed=wheels.speeds(v), momentum=wheels.momenta(v), torque=tau[:, wheels.columns],
                          stored=stored, rest=rest, balance=balance)


def wheel_summary(wheels: Wheels, control: Controller | None, rows: WheelTelemetry,
                  telemetry: Telemetry) -> dict[str, Any]:
    """Summary keys of the wheels: stored momentum (final, largest, per wheel, N m s), the
    largest torque, the momentum balance (N m s), the arm's reaction and the wheels' momentum
    change at the end (inertial, N m s), and the saturations: ``wheel_saturated`` (any limit
    reached), each event, and the control periods each wheel spent at a limit. With a joint
    reference, ``tracking_error_max`` over the arm joints only (a wheel has no reference: its row
    holds the wheel's own angle, a period behind at the last sample)."""
    names = [w.name for w in wheels.wheels]
    out: dict[str, Any] = {
        "wheel_momentum_final": dict(zip(names, rows.momentum[-1].tolist())),
        "wheel_momentum_max": dict(zip(names, np.abs(rows.momentum).max(axis=0).tolist())),
        "wheel_momentum_limit": dict(zip(names, wheels.max_momenta.tolist())),
        "wheel_torque_max": dict(zip(names, np.abs(rows.torque).max(axis=0).tolist())),
        "wheel_stored_momentum_change": (rows.stored[-1] - rows.stored[0]).tolist(),
        "arm_reaction_momentum": (rows.rest[-1] - rows.rest[0]).tolist(),
        "wheel_momentum_balance_max": float(np.linalg.norm(rows.balance, axis=1).max()),
    }
    errors = (telemetry.joint_reference - telemetry.joint_positions)[:, wheels.arm_columns]
    if errors.size and np.isfinite(errors).all():
        out["tracking_error_max"] = float(np.abs(errors).max())
    if isinstance(control, WheelAttitudeControl):
        out.update(
            wheel_saturated=bool(control.events),
            wheel_saturation_events=[{"t": e.t, "wheel": e.wheel, "limit": e.limit, "asked": e.asked}
                                     for e in control.events],
            wheel_saturated_periods=dict(zip(names, control.saturated_periods.tolist())),
        )
    return out


__all__ = ["HEADLINE", "KINDS", "UNITS", "CaptureWheels", "WheelTelemetry", "capture_wheel_telemetry", "scene_wheels",
           "split_momentum", "target_rotation", "wheel_attitude_control", "wheel_summary", "wheel_telemetry"]
