"""What a robot run's figures plot and need no matplotlib for: the base attitude as angles, and
which figures a run's data leaves with nothing to show (named in its summary's
``figures_not_drawn``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...dynamics.metrics import angular_speeds, free_com_motion

if TYPE_CHECKING:
    from ...dynamics.telemetry import Telemetry
    from ...robot.robot import Robot


def empty_figures(robot: Robot, telemetry: Telemetry, spin: bool = False) -> dict[str, str]:
    """The figures :func:`~.figures.write_figures` leaves out because what they plot is
    identically zero (or, for ``joint_errors``, absent), each with the reason, as the summary says
    it."""
    tel = telemetry
    out = {}
    missing = why_no_joint_errors(tel)
    if missing is not None:
        out["joint_errors"] = missing
    if not np.any(tel.tau):
        out["torques"] = "every joint torque is zero (a torque-free run)"
    if not (np.any(tel.base_position) or np.any(base_attitude(tel.base_quaternion))):
        out["base_trajectory"] = "the base stays at the origin, unrotated"
    if not np.any(tel.ee_position - tel.ee_position[:1]):
        out["end_effector_displacement"] = "no end-effector moves"
    if not (np.any(tel.com - free_com_motion(tel, robot)) or np.any(tel.momentum - tel.momentum[:1])):
        out["com_drift"] = "the CoM and momentum do not drift at all"
    if spin and not (np.any(tel.base_twist[:, 3:]) or np.any(angular_speeds(robot, tel)[1])):
        out["angular_rates"] = "nothing turns"
    if spin and not np.any(tel.momentum[:, 3:]):
        out["angular_momentum"] = "the angular momentum is zero throughout"
    return out


def why_no_joint_errors(telemetry: Telemetry) -> str | None:
    """Why a run's joint tracking error is not worth a figure (no reference, or an error of zero
    throughout), or None when it is."""
    errors = telemetry.joint_reference - telemetry.joint_positions
    if np.all(np.isnan(errors)):
        return "the run has no joint reference"
    if not np.any(np.nan_to_num(errors)):
        return "every joint tracking error is zero"
    return None


def base_attitude(quaternions: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (rad, unwrapped over time) with R = Rz(yaw) Ry(pitch) Rx(roll), from
    quaternions [qx, qy, qz, qw] (N, 4); returns (N, 3)."""
    from scipy.spatial.transform import Rotation  # here: scipy is 0.3 s for the figures that need no attitude

    yaw_pitch_roll = Rotation.from_quat(quaternions).as_euler("ZYX")
    return np.unwrap(yaw_pitch_roll[:, ::-1], axis=0)
