"""Capture of a tumbling rigid target by an end-effector (dissertation sec 3.8, done exactly).

Before contact the target is a free rigid body (its own Pinocchio free-flyer model, a plant the
engine flies with the robot's integrator and control period) and the robot holds its posture. Contact is declared when the target's grasp
point comes within ``tolerance`` of the end-effector frame origin. The impact is perfectly
inelastic and grasping: a 6-D weld at the grasp point, solved as an exact impulse,

.. math::
    (J_r M_r^{-1} J_r^T + J_t M_t^{-1} J_t^T)\\,\\Lambda = -(J_r v_r^- - J_t v_t^-), \\quad
    v_r^+ = v_r^- + M_r^{-1} J_r^T \\Lambda, \\quad v_t^+ = v_t^- - M_t^{-1} J_t^T \\Lambda,

with ``J_r``, ``J_t`` the frame Jacobians (LOCAL_WORLD_ALIGNED) of the end-effector and of the
grasp point; the impulse is internal, so the total momentum is conserved exactly. Afterwards the
target's inertia is appended to the end-effector's body at its pose relative to it, and the
merged robot continues with the robot part of ``v+``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from ..dynamics.metrics import momentum_drift, settling_time
from ..errors import InvalidArgument, SimulationDiverged, TargetMissed
from ..robot.conventions import momentum_about_origin, skew
from ..robot.robot import Robot

TARGET_FRAME = "captured_target"
#: ``compose(robot, law, t0) -> controller``: what a capture's phase runs on ``robot`` in place of
#: its own ``law`` (the hold or approach from 0 s, the detumbling on the merged robot from the
#: impact time ``t0`` s), e.g. reaction wheels holding the base attitude around it.
Compose = Callable[[Robot, Any, float], Any]
#: The unit of each key of a capture's summary (:func:`capture_and_detumble`; "" for a pure number
#: or a text); momenta ``[P; L about the origin]`` in N s and N m s.
SUMMARY_UNITS = {
    "impact_time": "s", "approach_base_attitude_change": "rad", "grasp_position_mismatch": "m",
    "grasp_velocity_mismatch": "m/s", "grasp_angular_velocity_mismatch": "rad/s", "grasp_impulse": "N s",
    "momentum_before_impact": "N s, N m s", "momentum_after_impact": "N s, N m s", "momentum_balance_error": "N s or N m s",
    "momentum_drift_after_impact": "N s or N m s", "target_angular_velocity_at_impact": "rad/s",
    "target_angular_velocity_final": "rad/s", "settling_time": "s", "settle_threshold": "rad/s",
    "peak_joint_torque": "N m", "base_angular_velocity_final": "rad/s", "base_angular_velocity_max": "rad/s",
    "solver_residual_max": "m/s or rad/s", "status": "",
}


@dataclass(frozen=True)
class Target:
    """A rigid target body.

    Attributes:
        mass: kg.
        inertia: principal moments about its CoM, body frame, kg m^2 (3,).
        grasp: grasp point in the body frame (from the CoM), m (3,).
        position: CoM position, inertial frame, m (3,).
        rpy: orientation, R = Rz(yaw) Ry(pitch) Rx(roll), rad (3,).
        velocity: CoM velocity, inertial frame, m/s (3,).
        angular_velocity: inertial frame, rad/s (3,).
        size: box edges for display, m (3,).
    """

    mass: float
    inertia: tuple[float, float, float]
    grasp: tuple[float, float, float]
    position: tuple[float, float, float]
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    size: tuple[float, float, float] = (0.3, 0.3, 0.3)

    def __post_init__(self):
        if not self.mass > 0.0 or min(self.inertia) <= 0.0:
            raise InvalidArgument(f"target: mass {self.mass} and inertia {self.inertia} must be positive")

    @classmethod
    def meeting(cls, point, time: float, mass: float, inertia, grasp, velocity, angular_velocity,
                rpy_at_contact=(0.0, 0.0, 0.0), size=(0.3, 0.3, 0.3)) -> Target:
        """The target whose grasp point is at ``point`` (inertial) at ``time`` s, moving freely.

        Back-propagates torque-free motion, exact when the spin lies along a principal axis
        (then it is constant): CoM ``c(t) = c_c + v (t - time)``, ``R(t) = exp(w (t - time)) R_c``.

        Raises:
            InvalidArgument: when the spin is not along a principal axis at contact.
        """
        R_c = pin.rpy.rpyToMatrix(*rpy_at_contact)
        w = np.asarray(angular_velocity, float)
        w_body = R_c.T @ w
        if np.linalg.norm(w_body) > 0 and np.linalg.norm(np.cross(w_body, np.diag(inertia) @ w_body)) > 1e-9 * np.linalg.norm(w_body) ** 2 * max(inertia):
            raise InvalidArgument("Target.meeting: the spin must lie along a principal axis of the target (it precesses otherwise)")
        com_c = np.asarray(point, float) - R_c @ np.asarray(grasp, float)
        R0 = pin.exp3(-w * time) @ R_c
        return cls(mass=mass, inertia=tuple(inertia), grasp=tuple(grasp), position=tuple(com_c - np.asarray(velocity, float) * time),
                   rpy=tuple(pin.rpy.matrixToRpy(R0)), velocity=tuple(velocity), angular_velocity=tuple(w), size=tuple(size))


class TargetBody:
    """The target as a one-body free-flyer Pinocchio model, with a frame at each grasp point:
    ``grasp`` (``target.grasp``), then ``grasp_2``, ... for ``more_grasps`` (body frame, from the
    CoM, m). It is also a plant of the engine (:mod:`freefloat.dynamics.plants`): a free rigid
    body under no effort, which ``freefloat.run(body, q, v, ...)`` flies.

    Attributes:
        name: the plant kind, ``"free_body"``.
        space: its configuration space, :attr:`model` (SE(3)).
    """

    name = "free_body"
    n_efforts = 0
    max_drift = np.inf

    def __init__(self, target: Target, more_grasps: tuple[np.ndarray, ...] = ()):
        self.target = target
        model = pin.Model()
        joint = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "target")
        model.appendBodyToJoint(joint, pin.Inertia(target.mass, np.zeros(3), np.diag(target.inertia)), pin.SE3.Identity())
        names = ["grasp", *(f"grasp_{k + 2}" for k in range(len(more_grasps)))]
        for name, point in zip(names, (target.grasp, *more_grasps)):
            model.addFrame(pin.Frame(name, joint, pin.SE3(np.eye(3), np.asarray(point, float)), pin.FrameType.OP_FRAME))
        model.gravity = pin.Motion.Zero()
        self.model, self.data, self.space = model, model.createData(), model
        self.grasp_ids = tuple(model.getFrameId(name) for name in names)
        self.grasp_id = self.grasp_ids[0]
        self._flight, self._no_torque = model.createData(), np.zeros(6)  # the plant's own Data

    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The free body's acceleration (6,) at pose ``q`` (7,) and local twist ``v`` (6,)
        (Pinocchio's ABA: the gyroscopic term alone); ``u`` is empty."""
        return pin.aba(self.model, self._flight, q, v, self._no_torque)

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """A free body has no closure: ``(0, 0)``."""
        return 0.0, 0.0

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """``(q, v)`` of the target: pose and local twist from the inertial data."""
        t = self.target
        R = pin.rpy.rpyToMatrix(*t.rpy)
        q = pin.SE3ToXYZQUAT(pin.SE3(R, np.asarray(t.position, float)))
        v = np.concatenate((R.T @ np.asarray(t.velocity, float), R.T @ np.asarray(t.angular_velocity, float)))
        return q, v

    def grasp_point(self, q: np.ndarray, k: int = 0) -> np.ndarray:
        """Grasp point ``k``, inertial frame (3,)."""
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[self.grasp_ids[k]].translation.copy()

    def momentum(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """[P; L about the inertial origin] of the target (6,)."""
        return momentum_about_origin(self.model, self.data, q, v)


@dataclass(frozen=True)
class Impact:
    """The exact inelastic grasp.

    Attributes:
        v_robot: robot velocity after the impact (nv,).
        v_target: target local twist after the impact (6,).
        impulse: the weld impulse on the robot, [linear; angular] about the end-effector frame
            origin (the grasp point to within the contact tolerance), N s and N m s, inertial
            axes (6,).
        momentum_before, momentum_after: total [P; L about the origin] of robot and target, the
            two as separate bodies (6,); after the impact they balance for any internal impulse,
            so the check that can fail is :func:`grasp_balance_error` on the merged robot.
    """

    v_robot: np.ndarray
    v_target: np.ndarray
    impulse: np.ndarray
    momentum_before: np.ndarray
    momentum_after: np.ndarray


def robot_momentum(robot: Robot, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """[P; L about the inertial origin] of a robot (6,)."""
    return momentum_about_origin(robot.model, robot.model.createData(), q, v)


def impact(robot: Robot, end_effector: str, q: np.ndarray, v: np.ndarray, body: TargetBody,
           q_t: np.ndarray, v_t: np.ndarray) -> Impact:
    """Solve the grasp impulse (see the module docstring)."""
    model, data = robot.model, robot.model.createData()
    fid = model.getFrameId(end_effector)
    M_r = pin.crba(model, data, q)
    M_r = np.triu(M_r) + np.triu(M_r, 1).T
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J_r = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
    tm, td = body.model, body.data
    M_t = pin.crba(tm, td, q_t)
    M_t = np.triu(M_t) + np.triu(M_t, 1).T
    pin.computeJointJacobians(tm, td, q_t)
    pin.updateFramePlacements(tm, td)
    J_t = pin.getFrameJacobian(tm, td, body.grasp_id, pin.LOCAL_WORLD_ALIGNED)
    # Evaluate the target's twist at the end-effector point, so both halves of the impulse act at
    # one point (contact is declared within a tolerance): v_p = v_g + w x (p - g).
    lever = data.oMf[fid].translation - td.oMf[body.grasp_id].translation
    J_t = np.vstack((J_t[:3] - skew(lever) @ J_t[3:], J_t[3:]))
    Wr, Wt = np.linalg.solve(M_r, J_r.T), np.linalg.solve(M_t, J_t.T)
    impulse = np.linalg.solve(J_r @ Wr + J_t @ Wt, -(J_r @ v - J_t @ v_t))
    v_r_plus, v_t_plus = v + Wr @ impulse, v_t - Wt @ impulse
    before = robot_momentum(robot, q, v) + body.momentum(q_t, v_t)
    after = robot_momentum(robot, q, v_r_plus) + body.momentum(q_t, v_t_plus)
    return Impact(v_r_plus, v_t_plus, impulse, before, after)


def attach(robot: Robot, end_effector: str, q: np.ndarray, body: TargetBody, q_t: np.ndarray) -> Robot:
    """The robot with the target's inertia appended to the end-effector's body (rigid grasp),
    and a frame ``captured_target`` at the target's CoM."""
    model = pin.Model(robot.model)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    frame = model.frames[model.getFrameId(end_effector)]
    joint = frame.parentJoint
    oM_target = pin.XYZQUATToSE3(q_t)
    placement = data.oMi[joint].actInv(oM_target)
    t = body.target
    model.appendBodyToJoint(joint, pin.Inertia(t.mass, np.zeros(3), np.diag(t.inertia)), placement)
    model.addFrame(pin.Frame(TARGET_FRAME, joint, placement, pin.FrameType.OP_FRAME))
    return dataclasses.replace(robot, model=model, visual_model=None)


#: The fields of an environment (:class:`~freefloat.dynamics.wrenches.WrenchField`: in orbit,
#: say) on a robot or a body's Pinocchio model: ``environment(robot_or_model, start)``, for a run
#: whose time 0 is ``start`` s of the capture's (the detumbling's run starts at the grasp).
Environment = Callable[[Any, float], Sequence[Any]]


class Flight(NamedTuple):
    """The target's free flight in fields, one row per control period: poses (N, 7) and local
    twists (N, 6)."""

    q: np.ndarray
    v: np.ndarray


@dataclass
class FlyingTarget:
    """The target's free flight during an approach.

    Attributes:
        q, v: its state when the approach ended (7,), (6,): pose (xyz, quaternion) and local twist.
        poses: its CoM frame poses, inertial, one per control period from the start (N, 4, 4).
        closest: smallest largest gap between grasp points and end-effectors (m) and when (s).
    """

    q: np.ndarray
    v: np.ndarray
    poses: np.ndarray
    closest: tuple[float, float]


def approach(robot: Robot, body: TargetBody, end_effectors: tuple[str, ...], control_period: float,
             duration: float, tolerance: float, integrator: str, q0: np.ndarray | None, v0: np.ndarray | None,
             kp: float, kd: float, model: str, controller: Any = None,
             not_before: float = 0.0, compose: Compose | None = None,
             environment: Environment | None = None) -> tuple[Any, FlyingTarget]:
    """The robot holds its posture (computed torque on its joints), or follows ``controller`` (e.g.
    a planned approach, :mod:`freefloat.space.planning`), while the target flies freely, until
    every grasp point ``k`` of ``body`` is within ``tolerance`` of ``end_effectors[k]``'s frame
    origin: the run's result (status ``"stopped"`` there) and the target's flight. A planned
    grasp closes the hand at its instant: no contact is declared before ``not_before`` s. With
    ``compose``, the robot runs ``compose(robot, law, 0.0)`` (:data:`Compose`) instead of the law.

    Both fly in the engine: nothing touches the target before contact, so its free flight over
    ``duration`` is one run of its own (:class:`TargetBody` as a plant, the robot's integrator and
    control period), and the robot's run's stop event reads the target's pose at its period. With
    ``environment`` (in orbit, say) both fly in its fields, the target's flight then integrated
    with its fields' stage times by :func:`~freefloat.space.orbit.propagation.propagate` (a plant
    takes no fields).

    Raises:
        TargetMissed: when the grasp points do not all come within ``tolerance`` in ``duration`` s
            (the message names the end-effectors and gives the closest approach and when).
        SimulationDiverged: when the approach (or the target's flight) diverged.
        KeyboardInterrupt: when the approach was interrupted (Ctrl-C, SIGTERM).
    """
    from ..dynamics.integrators import make_integrator
    from ..dynamics.models import ExactModel
    from ..dynamics.simulation import run
    from .control.detumbling_control import DetumblingController
    from .detumbling import joint_indices, task_rows

    if environment is None:
        free = run(body, *body.initial_state(), duration, control_period, integrator)  # the target alone
        if free.status == "interrupted":  # Ctrl-C or SIGTERM during the approach stops the whole run
            raise KeyboardInterrupt(free.message)
        if free.status != "completed":
            raise SimulationDiverged(f"the target's free flight {free.status}: {free.message}")
        path = free.telemetry
    else:
        from .orbit.propagation import propagate

        times = control_period * np.arange(round(duration / control_period) + 1)
        path = Flight(*propagate(body.model, environment(body.model, 0.0), *body.initial_state(), times))
    frames = [robot.model.getFrameId(name) for name in end_effectors]
    data = robot.model.createData()
    closest = [np.inf, 0.0]  # smallest largest gap (m) and when (s)

    def reached(t: float, q: np.ndarray, v: np.ndarray) -> bool:
        pin.framesForwardKinematics(robot.model, data, q)
        pin.framesForwardKinematics(body.model, body.data, path.q[round(t / control_period)])
        gap = max(float(np.linalg.norm(body.data.oMf[g].translation - data.oMf[f].translation))
                  for g, f in zip(body.grasp_ids, frames))
        if gap < closest[0]:
            closest[:] = gap, t
        return gap < tolerance and t > not_before - 0.5 * control_period

    hold = controller or DetumblingController(robot, task_rows(robot, [(end_effectors[0], "angular")]),
                                              joint_indices(robot, None), start=np.inf,
                                              control_period=control_period, kp=kp, kd=kd, model=model)
    hold = hold if compose is None else compose(robot, hold, 0.0)
    q0 = robot.neutral() if q0 is None else q0
    v0 = np.zeros(robot.model.nv) if v0 is None else v0
    pre = run(robot, q0, v0, duration, control_period, make_integrator(integrator, robot.model), ExactModel(robot),
              hold, stop=reached, environment=() if environment is None else environment(robot, 0.0))
    if pre.status == "interrupted":  # Ctrl-C or SIGTERM during the approach stops the whole run
        raise KeyboardInterrupt(pre.message)
    if pre.status != "stopped":
        gap, when = closest
        names = "' and '".join(end_effectors)
        if pre.status != "completed":
            raise SimulationDiverged(f"the approach to '{names}' {pre.status}: {pre.message}")
        raise TargetMissed(f"target never reaches '{names}' within {tolerance} m in "
                           f"{duration} s (closest approach {gap:.4g} m at t = {when:.4g} s)")
    k = len(pre.telemetry.t) - 1  # the contact's period
    poses = np.array([pin.XYZQUATToSE3(q).homogeneous for q in path.q[: k + 1]])
    return pre, FlyingTarget(path.q[k].copy(), path.v[k].copy(), poses, (closest[0], closest[1]))


@dataclass(frozen=True)
class Grasp:
    """The approach and the grasp: the merged robot's start.

    Attributes:
        pre: the approach run (status ``"stopped"`` at contact).
        body: the target's own model.
        flight: the target's free flight up to contact.
        hit: the impact.
        merged: the robot with the target attached (:func:`attach`).
        q, v: the merged robot's state just after the impact (nq,), (nv,).
    """

    pre: Any
    body: TargetBody
    flight: FlyingTarget
    hit: Impact
    merged: Robot
    q: np.ndarray
    v: np.ndarray


def grasp(robot: Robot, target: Target, end_effector: str, control_period: float = 1e-3, approach_time: float = 1.0,
          tolerance: float = 1e-3, integrator: str = "rkmk4", q0: np.ndarray | None = None,
          v0: np.ndarray | None = None, kp: float = 10.0, kd: float = 100.0, model: str = "exact",
          approach_controller: Any = None, grasp_time: float = 0.0, compose: Compose | None = None,
          environment: Environment | None = None) -> Grasp:
    """Hold (or follow ``approach_controller``; either composed by ``compose``) until the target's
    grasp point reaches ``end_effector`` (:func:`approach`, in the fields of ``environment``), grasp
    it by the exact impulse (:func:`impact`) and merge it into the robot (:func:`attach`).

    Raises:
        TargetMissed, SimulationDiverged: as :func:`approach`.
    """
    body = TargetBody(target)
    pre, flight = approach(robot, body, (end_effector,), control_period, approach_time, tolerance, integrator, q0, v0,
                           kp, kd, model, approach_controller, grasp_time, compose, environment)
    q, v = pre.telemetry.q[-1], pre.telemetry.v[-1]
    hit = impact(robot, end_effector, q, v, body, flight.q, flight.v)
    return Grasp(pre, body, flight, hit, attach(robot, end_effector, q, body, flight.q), q, hit.v_robot)


@dataclass
class CaptureResult:
    """A capture and detumbling run.

    Attributes:
        pre: telemetry before contact (robot holding its posture).
        post: telemetry after the impact (the merged robot detumbling).
        merged: the robot with the target attached.
        impact_time: s.
        hit: the impact.
        target_angular_velocity: |w| of the captured target after the impact, rad/s (rows of post).
        summary: figures of merit (see :func:`capture_and_detumble`).
        target_poses: target CoM frame poses, inertial (rows of pre then post, 4, 4).
    """

    pre: object
    post: object
    merged: Robot
    impact_time: float
    hit: Impact
    target_angular_velocity: np.ndarray
    summary: dict
    target_poses: np.ndarray


def capture_and_detumble(robot: Robot, target: Target, end_effector: str, rows_spec, joints: list[str] | None,
                         method: str = "min_norm", control_period: float = 1e-3, approach_time: float = 1.0,
                         detumble_time: float = 1.0, tolerance: float = 1e-3, settle_below: float = 1e-6,
                         integrator: str = "rkmk4", q0: np.ndarray | None = None, v0: np.ndarray | None = None,
                         kp: float = 10.0, kd: float = 100.0, model: str = "exact",
                         approach_controller: Any = None, grasp_time: float = 0.0,
                         compose: Compose | None = None, environment: Environment | None = None) -> CaptureResult:
    """Hold (or follow ``approach_controller``) until the target's grasp point reaches
    ``end_effector``, grasp it (exact impulse), then detumble the merged robot by stopping the
    end-effector rows ``rows_spec``; not before ``grasp_time`` s (a planned grasp instant). With
    ``compose`` (:data:`Compose`) each phase runs its law composed (the detumbling on the merged
    robot, from the impact time); with ``environment``, every phase in its fields (the
    detumbling's, whose telemetry starts at 0, made with their clock started at the grasp). The
    summary has the approach's base attitude change (rad, start to contact) and the grasp
    mismatch at contact (:func:`grasp_mismatch`).

    Raises:
        TargetMissed: when the target does not come within ``tolerance`` of the end-effector
            in ``approach_time`` (the message gives the closest approach and when).
    """
    from ..dynamics.integrators import make_integrator
    from ..dynamics.models import ExactModel
    from ..dynamics.simulation import run
    from .control.detumbling_control import DetumblingController
    from .detumbling import joint_indices, task_rows

    held = grasp(robot, target, end_effector, control_period, approach_time, tolerance, integrator, q0, v0, kp, kd,
                 model, approach_controller, grasp_time, compose, environment)
    pre, state, hit, merged, q = held.pre, held.flight, held.hit, held.merged, held.q
    t_hit = pre.telemetry.t[-1]
    gap, relative_speed, relative_spin = grasp_mismatch(robot, end_effector, q, pre.telemetry.v[-1], held.body,
                                                        state.q, state.v)
    merged_after = robot_momentum(merged, q, hit.v_robot)
    controller = DetumblingController(merged, task_rows(merged, rows_spec), joint_indices(merged, joints), start=0.0,
                                      control_period=control_period, method=method, kp=kp, kd=kd, model=model)
    post = run(merged, q, hit.v_robot, detumble_time, control_period, make_integrator(integrator, merged.model),
               ExactModel(merged), controller if compose is None else compose(merged, controller, float(t_hit)),
               environment=() if environment is None else environment(merged, t_hit))
    tel = post.telemetry
    w = target_angular_speed(merged, tel.q, tel.v)
    settled = settling_time(tel.t, w, settle_below)
    summary = {  # units: SUMMARY_UNITS
        "impact_time": float(t_hit),
        "approach_base_attitude_change": attitude_change(pre.telemetry.base_quaternion),
        "grasp_position_mismatch": gap,
        "grasp_velocity_mismatch": relative_speed,
        "grasp_angular_velocity_mismatch": relative_spin,
        "grasp_impulse": float(np.linalg.norm(hit.impulse[:3])),
        "momentum_before_impact": hit.momentum_before.tolist(),
        "momentum_after_impact": merged_after.tolist(),
        "momentum_balance_error": grasp_balance_error(merged, q, hit.v_robot, hit.momentum_before),
        "momentum_drift_after_impact": momentum_drift(tel.momentum),
        "target_angular_velocity_at_impact": float(w[0]),
        "target_angular_velocity_final": float(w[-1]),
        "settling_time": settled,
        "settle_threshold": settle_below,
        "peak_joint_torque": float(max(np.abs(pre.telemetry.tau).max(), np.abs(tel.tau).max())),
        "base_angular_velocity_final": float(np.linalg.norm(tel.base_twist[-1, 3:])),
        "base_angular_velocity_max": float(np.linalg.norm(tel.base_twist[:, 3:], axis=1).max()),
        "solver_residual_max": float(max(controller.residuals)) if controller.residuals else 0.0,
        "status": post.status,
    }
    post_poses = attached_poses(merged, tel.q)
    poses = np.concatenate((state.poses[: len(pre.telemetry.t)], post_poses))
    return CaptureResult(pre.telemetry, tel, merged, float(t_hit), hit, w, summary, poses)


def grasp_mismatch(robot: Robot, end_effector: str, q: np.ndarray, v: np.ndarray, body: TargetBody,
                   q_t: np.ndarray, v_t: np.ndarray) -> tuple[float, float, float]:
    """``(|p_E - p_g|, |v_E - v_g|, |w_E - w_t|)``: the end-effector frame origin against the grasp
    point, position (m) and linear velocity (m/s, inertial), and the end-effector's angular
    velocity against the target's (rad/s), just before the grasp."""
    model, data = robot.model, robot.model.createData()
    fid = model.getFrameId(end_effector)
    pin.forwardKinematics(model, data, q, v)
    p_E = pin.updateFramePlacement(model, data, fid).translation
    v_E = pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
    pin.forwardKinematics(body.model, body.data, q_t, v_t)
    p_g = pin.updateFramePlacement(body.model, body.data, body.grasp_id).translation
    v_g = pin.getFrameVelocity(body.model, body.data, body.grasp_id, pin.LOCAL_WORLD_ALIGNED)
    return (float(np.linalg.norm(p_E - p_g)), float(np.linalg.norm(v_E.linear - v_g.linear)),
            float(np.linalg.norm(v_E.angular - v_g.angular)))


def attitude_change(quaternions: np.ndarray) -> float:
    """Angle of the rotation from the first to the last of the base quaternions (N, 4) (xyzw), rad."""
    first, last = (pin.Quaternion(np.asarray(quat, float)).matrix() for quat in (quaternions[0], quaternions[-1]))
    return float(np.linalg.norm(pin.log3(last @ first.T)))


def grasp_balance_error(merged: Robot, q: np.ndarray, v_after: np.ndarray, before: np.ndarray) -> float:
    """Max-norm of the merged robot's momentum just after the grasp minus robot + target just
    before, ``max |h_merged(q, v+) - (h_robot^- + h_target^-)|`` ([P; L about the origin]).

    The merged robot carries the target rigidly with the end-effector, so this balance holds only
    when ``v+`` really welds the two: an impulse of the wrong size breaks it (the sum of the robot
    and the target as two free bodies after the impact balances for any internal impulse).

    Args:
        merged: the robot with the target attached (:func:`attach`).
        q: configuration at the impact (nq,).
        v_after: the robot's velocity after the impact (nv,).
        before: total momentum before the impact (6,).
    """
    return float(np.abs(robot_momentum(merged, q, v_after) - before).max())


def attached_poses(merged: Robot, qs: np.ndarray) -> np.ndarray:
    """Poses of the captured target frame over the samples (N, 4, 4), inertial frame."""
    return frame_poses(merged, TARGET_FRAME, qs)


def frame_poses(robot: Robot, frame: str, qs: np.ndarray) -> np.ndarray:
    """Poses of ``frame`` over the samples (N, 4, 4), inertial frame."""
    model, data = robot.model, robot.model.createData()
    fid = model.getFrameId(frame)
    out = np.empty((len(qs), 4, 4))
    for k, q in enumerate(qs):
        pin.framesForwardKinematics(model, data, q)
        out[k] = data.oMf[fid].homogeneous
    return out


def target_angular_speed(merged: Robot, qs: np.ndarray, vs: np.ndarray) -> np.ndarray:
    """|w| of the captured target frame over the samples (N,), rad/s."""
    model, data = merged.model, merged.model.createData()
    fid = model.getFrameId(TARGET_FRAME)
    out = np.empty(len(qs))
    for k, (q, v) in enumerate(zip(qs, vs)):
        pin.forwardKinematics(model, data, q, v)
        out[k] = np.linalg.norm(pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED).angular)
    return out
