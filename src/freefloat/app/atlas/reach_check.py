"""Mapped workspace points reached by a simulated motion: the robot driven from its reference
posture to a grid configuration by computed torque on the exact plant (Pinocchio's ABA, RKMK4, the
one simulation loop, zero momentum), and where its end-effector arrives, measured with Pinocchio
(independent of the hand-built GJM the map is computed with)."""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ...dynamics.integrators import make_integrator
from ...dynamics.models import ExactModel
from ...dynamics.simulation import run
from ...robot.joints import JointCoordinates
from ...space.control import ComputedTorque, QuinticTrajectory
from .arm_maps import ArmMap, robot_of

#: The motion: a quintic of MOVE_S s, then SETTLE_S s held, control period DT s; gains.
MOVE_S, SETTLE_S, DT, KP, KD = 1.0, 0.5, 1e-3, 400.0, 40.0


class Arrival(NamedTuple):
    """Where a simulated motion to a grid point ended.

    Attributes:
        ee_from_com: end-effector origin minus system CoM, in the base-link frame, m (3,): what the
            map's ``ee_from_com`` gives at the reference base attitude.
        com_drift: how far the system CoM moved, m.
    """

    ee_from_com: np.ndarray
    com_drift: float


def drive_to(context: ArmMap, point: np.ndarray) -> Arrival:
    """Simulate the motion from the reference posture to grid point ``point`` (len(axes),)."""
    robot = robot_of(context.target, context.base)
    model, data = robot.model, robot.model.createData()
    start = np.array(context.posture)
    goal = start.copy()
    goal[list(context.axis_index)] = point
    q0 = robot.neutral()
    JointCoordinates(robot).set(q0, start)
    com0 = pin.centerOfMass(model, data, q0).copy()
    controller = ComputedTorque(robot, QuinticTrajectory(start, goal, MOVE_S), KP, KD)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        telemetry = run(robot, q0, np.zeros(model.nv), MOVE_S + SETTLE_S, DT, make_integrator("rkmk4", model),
                        ExactModel(robot), controller, record_every=round((MOVE_S + SETTLE_S) / DT)).telemetry
    q = telemetry.q[-1]
    com = pin.centerOfMass(model, data, q)
    pin.updateFramePlacements(model, data)
    ee = data.oMf[robot.end_effector_frame_ids[context.index]].translation
    return Arrival(data.oMi[1].rotation.T @ (ee - com), float(np.linalg.norm(com - com0)))
