"""A pre-capture plan: the joint path, what it does to the base and the grasp, and its checks."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from ...dynamics.models.exact import joint_space_dynamics
from ...errors import InfeasiblePlan
from ...robot.conventions import base_state
from .floating_kinematics import FloatingKinematics, rollout
from .request import ApproachRequest, Limits

#: The unit of each key of :meth:`Plan.summary` ("" for a text); joint rates in rad/s (m/s for a
#: prismatic joint), torques in N m (N).
SUMMARY_UNITS = {
    "approach_method": "", "approach_plan_attitude_change": "rad", "approach_plan_attitude_max": "rad",
    "approach_plan_position_error": "m", "approach_plan_velocity_error": "m/s", "approach_plan_angle_error": "rad",
    "approach_plan_angular_velocity_error": "rad/s", "approach_plan_peak_joint_rate": "rad/s",
    "approach_plan_peak_torque": "N m", "approach_joint_rate_limits": "rad/s", "approach_torque_limits": "N m",
}


class JointPath:
    """The joint reference ``(q_d, qdot_d, qddot_d)(t)`` of a plan, actuated joint coordinates
    (n,) each, from a piecewise polynomial on [0, T] (scipy ``PPoly`` or ``BPoly``); before 0 it
    holds the start, after T it goes on at the rate of T (so a contact a little late is met)."""

    def __init__(self, poly: Any):
        self.poly, self.rate, self.acceleration = poly, poly.derivative(), poly.derivative(2)
        self.duration = float(poly.x[-1])
        self._start, self._end, self._end_rate = poly(0.0), poly(self.duration), self.rate(self.duration)

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Reference ``(q_d, qdot_d, qddot_d)`` at ``t`` s, (n,) each."""
        if t < 0.0:
            return self._start.copy(), np.zeros_like(self._start), np.zeros_like(self._start)
        if t > self.duration:
            return self._end + self._end_rate * (t - self.duration), self._end_rate.copy(), np.zeros_like(self._end)
        return self.poly(t), self.rate(t), self.acceleration(t)


@dataclass
class Plan:
    """A joint path checked against the free-floating kinematics it causes.

    Attributes:
        method: the planner's name.
        path: the joint reference.
        times: the evaluation grid (N,), s.
        q, v: the configurations and velocities along the path with the robot's momentum
            conserved (Runge-Kutta 4 of the base motion), (N, nq), (N, nv).
        torque: ``H* qddot_d + c*`` on the grid, the exact joint-space dynamics (N, n), N m.
        joint_rate: ``qdot_d`` on the grid (N, n), rad/s.
        position_error: largest |end-effector - grasp point| at T over the task components, m.
        velocity_error: largest |their velocity difference| at T over the task components, m/s.
        attitude: base attitude change from the start on the grid, the angle of
            ``R0(t) R0(0)^T`` (N,), rad.
        limits: the limits the plan was checked against.
        angle_error: largest orientation mismatch with the handle at T (``"pose"``; else 0), rad.
        angular_velocity_error: largest angular velocity mismatch at T (``"pose"``; else 0), rad/s.
    """

    method: str
    path: JointPath
    times: np.ndarray
    q: np.ndarray
    v: np.ndarray
    torque: np.ndarray
    joint_rate: np.ndarray
    position_error: float
    velocity_error: float
    attitude: np.ndarray
    limits: Limits
    angle_error: float = 0.0
    angular_velocity_error: float = 0.0

    @property
    def attitude_change(self) -> float:
        """Base attitude change at the grasp instant, rad."""
        return float(self.attitude[-1])

    def summary(self) -> dict[str, Any]:
        """The plan's figures of merit (JSON-ready), keys ``approach_plan_*``."""
        return {
            "approach_method": self.method,
            "approach_plan_attitude_change": self.attitude_change,
            "approach_plan_attitude_max": float(self.attitude.max()),
            "approach_plan_position_error": self.position_error,
            "approach_plan_velocity_error": self.velocity_error,
            "approach_plan_angle_error": self.angle_error,
            "approach_plan_angular_velocity_error": self.angular_velocity_error,
            "approach_plan_peak_joint_rate": float(np.abs(self.joint_rate).max()),
            "approach_plan_peak_torque": float(np.abs(self.torque).max()),
            "approach_joint_rate_limits": self.limits.joint_rate.tolist(),
            "approach_torque_limits": self.limits.torque.tolist(),
        }


def evaluate(request: ApproachRequest, path: JointPath, method: str) -> Plan:
    """The plan of ``path``: its base motion (the momentum of the request's start conserved), the
    grasp mismatch at T and the torques on the request's grid."""
    robot, times = request.robot, request.times
    kin = FloatingKinematics.at_state(robot, request.q0, request.v0)
    q, v = rollout(kin, request.q0, lambda t, _q: path(t)[1], times)
    data = robot.model.createData()
    errors = np.linalg.norm(request.grasp_errors(q[-1], v[-1]), axis=2).max(axis=0)  # (4,): the worst hand
    R_start = base_state(robot, q[0], v[0])[1]
    attitude = np.array([np.linalg.norm(pin.log3(base_state(robot, qk, vk)[1] @ R_start.T)) for qk, vk in zip(q, v)])
    rates, torque = np.empty((len(times), robot.n_joints)), np.empty((len(times), robot.n_joints))
    for k, t in enumerate(times):
        _, rates[k], acceleration = path(t)
        H, bias = joint_space_dynamics(robot, data, q[k], v[k])
        torque[k] = H @ acceleration + bias
    return Plan(method, path, times, q, v, torque, rates, float(errors[0]), float(errors[1]), attitude, request.limits,
                float(errors[2]), float(errors[3]))


def check(plan: Plan, request: ApproachRequest) -> Plan:
    """The plan if it meets the grasp within the request's tolerances and keeps the limits.

    Raises:
        InfeasiblePlan: naming what fails: a plan that diverged, the grasp point out of reach
            (position or velocity mismatch at T, with the arm's reach), or the first joint and time
            where a joint-rate or torque limit is exceeded (with the hint that the deadline may be
            too short).
    """
    T = request.duration
    if not (np.isfinite(plan.q).all() and np.isfinite(plan.v).all() and np.isfinite(plan.torque).all()):
        raise InfeasiblePlan(f"approach ({plan.method}): the grasp point is out of reach: the plan diverged (non-finite "
                             f"joint rates or torques) before t = {T:.4g} s, the path meeting a singularity", "reach")
    errors = np.linalg.norm(request.grasp_errors(plan.q[-1], plan.v[-1]), axis=2)  # (k, 4)
    missed = np.flatnonzero((errors > request.tolerances).any(axis=1))
    if missed.size:
        k = int(missed[0])
        distance, reach = request.arm_reach(k)
        units = ("m", "m/s", "rad", "rad/s")[: 4 if request.match == "pose" else 2]
        ends = " and ".join(f"{e:.3g} {u} (tolerance {t:.3g})" for e, u, t in zip(errors[k], units, request.tolerances))
        raise InfeasiblePlan(
            f"approach ({plan.method}): the grasp {'frame' if request.match == 'pose' else 'point'} is out of reach of "
            f"'{request.end_effectors[k]}' at t = {T:.4g} s: the plan ends {ends} from it; the grasp point is "
            f"{distance:.3g} m from the arm's first joint, whose reach is {reach:.3g} m (or the path meets a "
            "singularity)", "reach")
    names = request.robot.joint_names
    for what, values, limit, unit in (("joint_rate", plan.joint_rate, request.limits.joint_rate, "rad/s"),
                                      ("torque", plan.torque, request.limits.torque, "N m")):
        excess = np.abs(values) / limit
        k, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
        if excess[k, j] > 1.0:
            raise InfeasiblePlan(
                f"approach ({plan.method}): {what.replace('_', ' ')} limit violated: joint '{names[j]}' needs "
                f"{abs(values[k, j]):.4g} {unit} at t = {plan.times[k]:.4g} s (limit {limit[j]:.4g} {unit}); the "
                f"deadline of {T:.4g} s is too short for this approach, or the limit too tight", what)
    return plan
