"""Run metrics: the dissertation's nested RMS (eq 140) and conservation drifts."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..robot.robot import Robot
from .telemetry import Telemetry


def rms(x: np.ndarray, axis: int = 0) -> np.ndarray:
    """Root mean square along ``axis`` (eq 140: ``(sum_k e_k^2 / n_T)^(1/2)``)."""
    return np.sqrt(np.mean(np.square(x), axis=axis))


def nested_rms(errors: np.ndarray, robot: Robot) -> tuple[float, dict[str, float]]:
    """Eq 140 applied in layers: per joint over time, per arm over its joints, then over arms.

    Args:
        errors: joint tracking errors ``q_d - q`` over time (n_T, n_joints).
        robot: gives the arms (a joint shared by two arms counts in both).

    Returns:
        ``(overall, per_arm)``; ``per_arm`` is keyed by end-effector name.
    """
    per_joint = rms(errors, axis=0)
    per_arm = {arm.end_effector: float(rms(per_joint[arm.v_indices - robot.n_base])) for arm in robot.arms}
    return float(rms(np.array(list(per_arm.values())))), per_arm


def rotation_angle(quaternions: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Rotation angle between unit quaternions [x, y, z, w] (N, 4) and one reference (4,), rad.

    Uses ``2 atan2(|q_perp|, |q . ref|)``, accurate for small angles (``arccos`` is not).
    """
    dot = quaternions @ reference
    perp = np.linalg.norm(quaternions - np.outer(dot, reference), axis=1)
    return 2.0 * np.arctan2(perp, np.abs(dot))


def free_com_motion(telemetry: Telemetry, robot: Robot) -> np.ndarray:
    """System-CoM path that momentum conservation demands without external wrenches (N, 3):
    ``com(0) + t P(0) / m + g t^2 / 2`` (inertial frame, m)."""
    tel = telemetry
    t = tel.t - tel.t[0]
    mass = pin.computeTotalMass(robot.model)
    return tel.com[0] + np.outer(t, tel.momentum[0, :3] / mass) + 0.5 * np.outer(t**2, robot.model.gravity.linear)


def momentum_drift(momentum: np.ndarray) -> float:
    """Largest change from sample 0 of the linear or the angular momentum, as a vector norm.

    Args:
        momentum: ``[P; L about the inertial origin]`` per sample (N, 6), kg m/s and kg m^2/s.
    """
    change = momentum - momentum[0]
    return float(max(np.linalg.norm(change[:, :3], axis=1).max(), np.linalg.norm(change[:, 3:], axis=1).max()))


def settling_time(t: np.ndarray, signal: np.ndarray, threshold: float) -> float | None:
    """First sample time (s) after which ``signal`` (N,) stays below ``threshold``; None if its
    last sample is not below it."""
    above = np.flatnonzero(signal >= threshold)
    if not len(above):
        return float(t[0])
    return None if above[-1] == len(signal) - 1 else float(t[above[-1] + 1])


def summarize(telemetry: Telemetry, robot: Robot) -> dict[str, object]:
    """Figures of merit of a run (SI units; see the README's output table)."""
    tel = telemetry
    out: dict[str, object] = {
        "com_drift_max": float(np.linalg.norm(tel.com - free_com_motion(tel, robot), axis=1).max()),
        "linear_momentum_drift_max": float(np.linalg.norm(tel.momentum[:, :3] - tel.momentum[0, :3], axis=1).max()),
        "angular_momentum_drift_max": float(np.linalg.norm(tel.momentum[:, 3:] - tel.momentum[0, 3:], axis=1).max()),
        "energy_drift_max": float(np.abs(tel.energy - tel.energy[0] - tel.work).max()),
        "base_displacement": (tel.base_position[-1] - tel.base_position[0]).tolist(),
        "base_rotation_max": float(rotation_angle(tel.base_quaternion, tel.base_quaternion[0]).max()),
        "end_effectors_start": {n: tel.ee_position[0, i].tolist() for i, n in enumerate(robot.end_effectors)},
        "end_effectors_end": {n: tel.ee_position[-1, i].tolist() for i, n in enumerate(robot.end_effectors)},
        "peak_joint_torque": float(np.abs(tel.tau).max()) if tel.tau.size else 0.0,
    }
    out["momentum_drift_max"] = momentum_drift(tel.momentum)
    errors = tel.joint_reference - tel.joint_positions
    if np.isfinite(errors).all() and errors.size:
        overall, per_arm = nested_rms(errors, robot)
        out["tracking_rms_overall"] = overall
        out["tracking_rms_per_arm"] = per_arm
        out["tracking_error_max"] = float(np.abs(errors).max())
    return out


def kinematic_consistency(telemetry: Telemetry, robot: Robot) -> tuple[float, np.ndarray]:
    """KJC (dissertation Table 3): the E-GJM end-effector rates ``J* qdot + J0E H0^-1 M``
    against the end-effector motion actually simulated (central differences of the recorded
    positions), linear rows; nested RMS over time per end-effector, then overall.

    Returns:
        ``(overall, per_end_effector)``: m/s, (k,).
    """
    from . import gjm

    tel = telemetry
    rows = len(tel.t)
    dt = np.diff(tel.t)
    fd = (tel.ee_position[2:] - tel.ee_position[:-2]) / (dt[1:] + dt[:-1])[:, None, None]
    errors = np.empty((rows - 2, len(robot.end_effectors), 3))
    for k in range(1, rows - 1):
        rates = gjm.compute(robot, tel.q[k], tel.v[k]).end_effector_velocity().reshape(-1, 6)[:, :3]
        errors[k - 1] = rates - fd[k - 1]
    per_ee = rms(rms(errors, axis=0), axis=1)
    return float(rms(per_ee)), per_ee
