"""Resolved-rate approach planning: follow a task-space quintic from the end-effector to the grasp
point with a rate law of :mod:`.reaction_null_space`, closed on the position error.

The task path ``x_d(t)`` is the quintic with the end-effector's position and velocity (zero
acceleration) at t = 0 and the grasp point's position, velocity and acceleration at T; the law is
asked for ``xdot_d + K (x_d - x_E)`` along the free-floating motion it causes (the base moving at
the conserved momentum, :func:`.floating_kinematics.rollout`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from scipy.interpolate import CubicHermiteSpline

from ...errors import InfeasiblePlan
from ...robot.joints import JointCoordinates
from .floating_kinematics import FloatingKinematics, rollout
from .plan import JointPath
from .reaction_null_space import RateLaw, TaskRows
from .request import ApproachRequest


def quintic(T: float, start: tuple[np.ndarray, ...], end: tuple[np.ndarray, ...]) -> np.ndarray:
    """Coefficients (6, m) of the quintic ``x(t) = sum_i c_i t^i`` with position, velocity and
    acceleration ``start`` at 0 and ``end`` at T ((m,) each)."""
    rows = []
    for t in (0.0, T):
        powers = np.array([t**i for i in range(6)])
        rows += [powers, np.array([i * t ** max(i - 1, 0) for i in range(6)]),
                 np.array([i * (i - 1) * t ** max(i - 2, 0) for i in range(6)])]
    return np.linalg.solve(np.array(rows), np.array([*start, *end]))


def task_path(request: ApproachRequest) -> np.ndarray:
    """The quintic's coefficients (6, m) over the task components of every hand, hand after hand
    (see the module docstring)."""
    model, data = request.robot.model, request.robot.model.createData()
    pin.forwardKinematics(model, data, request.q0, request.v0)
    c = request.task_components()
    start, end = [], []
    for frame, grasp in zip(request.frames, request.grasps):
        velocity = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED).linear
        start.append((pin.updateFramePlacement(model, data, frame).translation[c], velocity[c], np.zeros(len(c))))
        end.append(tuple(value[c] for value in grasp.at(request.duration)))
    return quintic(request.duration, tuple(np.concatenate(parts) for parts in zip(*start)),
                   tuple(np.concatenate(parts) for parts in zip(*end)))


def orientation_paths(request: ApproachRequest) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per hand, ``(R_E0, coefficients (6, 3))`` of its orientation path for ``match = "pose"``:
    ``R_d(t) = exp(phi(t)) R_E0`` with the quintic rotation vector ``phi`` (inertial) from 0 at the
    hand's angular velocity to ``log(R_g(T) R_E0^T)`` at the grasp frame's, ``w = J_l(phi)
    phi_dot`` (SO(3)'s left Jacobian, ``J_r(phi)^T``), zero ``phi_ddot`` at both ends."""
    model, data = request.robot.model, request.robot.model.createData()
    pin.forwardKinematics(model, data, request.q0, request.v0)
    out = []
    for frame, grasp in zip(request.frames, request.grasps):
        start = pin.updateFramePlacement(model, data, frame).rotation
        w_start = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED).angular
        end = pin.log3(grasp.orientation(request.duration) @ start.T)
        end_rate = np.linalg.solve(pin.Jexp3(end).T, grasp.angular_velocity)
        ends = (np.zeros(3), w_start, np.zeros(3)), (end, end_rate, np.zeros(3))
        out.append((start, quintic(request.duration, *ends)))
    return out


def resolved_rate_path(request: ApproachRequest, law: RateLaw) -> JointPath:
    """The joint path of ``law`` following :func:`task_path` (and, with ``match = "pose"``,
    :func:`orientation_paths`) on the request's grid, closed on the position and orientation
    errors: the rolled-out joint positions and rates joined by a cubic Hermite spline (C1; the
    accelerations are its second derivative).

    Raises:
        InfeasiblePlan: when the roll-out diverges (reason ``"reach"``).
    """
    robot = request.robot
    kin = FloatingKinematics.at_state(robot, request.q0, request.v0)
    angular = request.angular_components()
    task = TaskRows.position(robot, request.end_effectors, request.joints, angular)
    coefficients, turns = task_path(request), orientation_paths(request) if angular.size else []
    hands, c = [robot.end_effectors.index(name) for name in request.end_effectors], request.task_components()
    data = robot.model.createData()

    def rates(t: float, q: np.ndarray) -> np.ndarray:
        state = kin.matrices(q)
        powers = np.array([t**k for k in range(6)])
        speeds = np.array([k * t ** max(k - 1, 0) for k in range(6)])
        x_d, xdot_d = powers @ coefficients, speeds @ coefficients
        linear = (xdot_d + request.gain * (x_d - state.ee_position[hands][:, c].ravel())).reshape(len(hands), -1)
        if not turns:
            return law(state, kin.momentum_base(state), linear.ravel(), task)
        pin.framesForwardKinematics(robot.model, data, q)
        parts = []
        for k, (frame, (start, phi)) in enumerate(zip(request.frames, turns)):
            rotation_vector, rate = powers @ phi, speeds @ phi
            w_d = pin.Jexp3(rotation_vector).T @ rate
            error = pin.log3(pin.exp3(rotation_vector) @ start @ data.oMf[frame].rotation.T)
            parts.append(np.concatenate((linear[k], (w_d + request.gain * error)[angular])))
        return law(state, kin.momentum_base(state), np.concatenate(parts), task)

    times = request.times
    q, v = rollout(kin, request.q0, rates, times)
    if not (np.isfinite(q).all() and np.isfinite(v).all()):
        raise InfeasiblePlan("approach: the grasp point is out of reach: the plan diverged (non-finite joint rates) "
                             f"before t = {request.duration:.4g} s, the path meeting a singularity", "reach")
    coords = JointCoordinates(robot)
    positions = np.array([coords.get(qk) for qk in q])
    positions[:, coords.circle_pos] = np.unwrap(positions[:, coords.circle_pos], axis=0)
    return JointPath(CubicHermiteSpline(times, positions, v[:, robot.n_base:]))
