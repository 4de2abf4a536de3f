"""What follows a grasp when the target is unknown (issue 39): an identification manoeuvre, then
detumbling on the model the controller believes.

The plant is always the true merged robot (:func:`~freefloat.space.capture.attach`); the
controllers compute on the robot they are given: the robot alone during the manoeuvre (it does
not know the target yet), then for the detumbling the true merged robot, one carrying the
identified target (:func:`~freefloat.space.target_identification.with_target`) or a wrong
nominal guess. Each is one run of the engine (:func:`freefloat.dynamics.simulation.run`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dynamics.identification.excitation import FourierTrajectory
from ..dynamics.integrators import make_integrator
from ..dynamics.metrics import momentum_drift, settling_time
from ..dynamics.models import ExactModel
from ..dynamics.simulation import RunResult, run
from ..robot.robot import Robot
from .capture import target_angular_speed
from .control.detumbling_control import DetumblingController
from .control.excitation import ExcitationTracking
from .detumbling import joint_indices, task_rows


def manoeuvre(merged: Robot, believed: Robot, q: np.ndarray, v: np.ndarray, trajectory: FourierTrajectory,
              joints: list[str], duration: float, control_period: float = 1e-3, kp: float = 400.0, kd: float = 40.0,
              integrator: str = "rkmk4") -> RunResult:
    """``duration`` s of the true merged robot from (q, v) while ``joints`` (names) track
    ``trajectory`` about their posture by computed torque on ``believed``
    (:class:`~freefloat.space.control.excitation.ExcitationTracking`); no external wrench, so the
    record conserves the system's momentum (what the identification reads)."""
    law = ExcitationTracking(believed, trajectory, joint_indices(believed, joints), kp, kd)
    return run(merged, q, v, duration, control_period, make_integrator(integrator, merged.model), ExactModel(merged), law)


@dataclass(frozen=True)
class Detumbling:
    """One detumbling run on a believed model.

    Attributes:
        result: the run (telemetry of the true merged robot).
        target_speed: |w| of the captured target per sample (N,), rad/s.
        settling_time: when |w| stays below the threshold, s (None: never).
        final_speed: |w| at the end, rad/s.
        peak_torque: largest |tau| of any joint, N m.
        momentum_drift: largest change of the system's momentum over the run (a check: internal
            torques only).
    """

    result: RunResult
    target_speed: np.ndarray
    settling_time: float | None
    final_speed: float
    peak_torque: float
    momentum_drift: float


def detumble(merged: Robot, believed: Robot, q: np.ndarray, v: np.ndarray, rows: list[tuple[str, str]],
             duration: float, settle_below: float, control_period: float = 1e-3, method: str = "min_norm",
             kp: float = 10.0, kd: float = 100.0, joints: list[str] | None = None,
             integrator: str = "rkmk4") -> Detumbling:
    """Detumble the true ``merged`` robot from (q, v) by stopping the end-effector ``rows``
    (``[(end_effector, component)]``) with the mission ``joints`` (all by default), the law
    (:class:`~freefloat.space.control.detumbling_control.DetumblingController`, dissertation eq
    134) computing on ``believed``; settled when the target's angular speed stays below
    ``settle_below`` rad/s."""
    law = DetumblingController(believed, task_rows(believed, rows), joint_indices(believed, joints), start=0.0,
                               control_period=control_period, method=method, kp=kp, kd=kd)
    result = run(merged, q, v, duration, control_period, make_integrator(integrator, merged.model), ExactModel(merged),
                 law)
    tel = result.telemetry
    speed = target_angular_speed(merged, tel.q, tel.v)
    return Detumbling(result, speed, settling_time(tel.t, speed, settle_below), float(speed[-1]),
                      float(np.abs(tel.tau).max()), momentum_drift(tel.momentum))
