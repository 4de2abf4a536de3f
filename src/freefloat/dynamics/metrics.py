"""Run metrics: the dissertation's nested RMS (eq 140), conservation drifts (or, with external
wrenches, balances: :mod:`.balance`) and how the spin of the base and end-effectors settles."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ..robot.robot import Robot
from .balance import balance, free_com_motion
from .sensors.momentum import CONSERVED
from .telemetry import Telemetry
from .wrenches import ExternalWrench, WrenchField

#: A rate has settled when it stays within this fraction of its largest excursion from its final
#: value (the 2 % settling time of control engineering).
SETTLE_BAND = 0.02

#: The unit of each summary key this module computes (:func:`conservation`, :func:`summarize`,
#: :func:`spin_summary`; "" for a pure number), as the command line prints it. Joint errors are in
#: rad (m for a prismatic joint), torques in N m (N for a prismatic joint); a momentum's linear
#: part is in N s (kg m/s), its angular part in N m s (kg m^2/s).
UNITS = {
    "com_drift_max": "m", "linear_momentum_drift_max": "N s", "angular_momentum_drift_max": "N m s",
    "momentum_drift_max": "N s or N m s", "energy_drift_max": "J",
    "com_balance_max": "m", "linear_momentum_balance_max": "N s", "angular_momentum_balance_max": "N m s",
    "momentum_balance_max": "N s or N m s", "momentum_balance_relative": "", "energy_balance_max": "J",
    "external_impulse": "N s, N m s", "external_work": "J", "momentum_scale": "N s or N m s",
    "base_displacement": "m", "base_rotation_max": "rad", "end_effectors_start": "m", "end_effectors_end": "m",
    "peak_joint_torque": "N m", "tracking_rms_overall": "rad", "tracking_rms_per_arm": "rad",
    "tracking_error_max": "rad",
    "base_angular_velocity_max": "rad/s", "base_angular_velocity_final": "rad/s",
    "base_angular_velocity_settling_time": "s", "end_effector_angular_velocity_max": "rad/s",
    "end_effector_angular_velocity_final": "rad/s", "end_effector_angular_velocity_settling_time": "s",
    "settle_band": "",
}


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


def momentum_change(momentum: np.ndarray, base: str = "free") -> np.ndarray:
    """The change from sample 0 of the components of the momentum that a ``base`` of that kind
    conserves (:data:`~.sensors.momentum.CONSERVED`: all six on a free base; Px, Py, Lz on a planar
    one, whose joint's reactions change the others), the rest zero (N, 6)."""
    change = np.zeros_like(momentum)
    rows = CONSERVED[base]
    change[:, rows] = momentum[:, rows] - momentum[0, rows]
    return change


def momentum_drift(momentum: np.ndarray, base: str = "free") -> float:
    """Largest change from sample 0 of the linear or the angular momentum, as a vector norm, over
    the components a ``base`` of that kind conserves (:func:`momentum_change`).

    Args:
        momentum: ``[P; L about the inertial origin]`` per sample (N, 6), kg m/s and kg m^2/s.
    """
    change = momentum_change(momentum, base)
    return float(max(np.linalg.norm(change[:, :3], axis=1).max(), np.linalg.norm(change[:, 3:], axis=1).max()))


def settling_time(t: np.ndarray, signal: np.ndarray, threshold: float) -> float | None:
    """First sample time (s) after which ``signal`` (N,) stays below ``threshold``; None if its
    last sample is not below it."""
    above = np.flatnonzero(signal >= threshold)
    if not len(above):
        return float(t[0])
    return None if above[-1] == len(signal) - 1 else float(t[above[-1] + 1])


def band_settling_time(t: np.ndarray, signal: np.ndarray, band: float = SETTLE_BAND) -> float:
    """First sample time (s) after which ``signal`` (N,) stays within ``band`` times its largest
    excursion from its final value, ``|x - x_end| < band max |x - x_end|`` (``t[0]`` for a
    constant signal)."""
    deviation = np.abs(signal - signal[-1])
    top = deviation.max()
    return float(t[0]) if top == 0.0 else settling_time(t, deviation, band * top)  # type: ignore[return-value]


def angular_speeds(robot: Robot, telemetry: Telemetry) -> tuple[np.ndarray, np.ndarray]:
    """Angular speeds, rad/s: the base's ``|w0|`` (N,) and each end-effector frame's ``|w|``
    (N, k), inertial frame."""
    model, data = robot.model, robot.model.createData()
    ends = np.empty((len(telemetry.t), len(robot.end_effectors)))
    for row, (q, v) in enumerate(zip(telemetry.q, telemetry.v)):
        pin.forwardKinematics(model, data, q, v)
        for e, frame in enumerate(robot.end_effector_frame_ids):
            ends[row, e] = np.linalg.norm(pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED).angular)
    return np.linalg.norm(telemetry.base_twist[:, 3:], axis=1), ends


def spin_summary(robot: Robot, telemetry: Telemetry) -> dict[str, object]:
    """How the spin of the base and of each end-effector (a captured target's, once grasped)
    settles: largest and final angular speed (rad/s) and the time (s) after which it stays within
    :data:`SETTLE_BAND` of its largest excursion from the final value
    (:func:`band_settling_time`); end-effector values keyed by name."""
    t = telemetry.t
    base, ends = angular_speeds(robot, telemetry)
    names = robot.end_effectors
    return {
        "base_angular_velocity_max": float(base.max()), "base_angular_velocity_final": float(base[-1]),
        "base_angular_velocity_settling_time": band_settling_time(t, base),
        "end_effector_angular_velocity_max": {n: float(ends[:, e].max()) for e, n in enumerate(names)},
        "end_effector_angular_velocity_final": {n: float(ends[-1, e]) for e, n in enumerate(names)},
        "end_effector_angular_velocity_settling_time": {n: band_settling_time(t, ends[:, e])
                                                        for e, n in enumerate(names)},
        "settle_band": SETTLE_BAND,
    }


def conservation(telemetry: Telemetry, robot: Robot, wrenches: tuple[ExternalWrench, ...] | list[ExternalWrench] = (),
                 control_period: float | None = None,
                 environment: Sequence[WrenchField] = ()) -> dict[str, float | list[float]]:
    """How well the run keeps the conservation laws (SI units).

    Without external wrenches, drifts: ``com_drift_max`` (m, from :func:`free_com_motion`),
    ``linear_momentum_drift_max``, ``angular_momentum_drift_max``, ``momentum_drift_max`` (their
    max, see :func:`momentum_drift`; kg m/s, kg m^2/s about the inertial origin; on a planar base
    of Px, Py, Lz only, which its joint's reactions do not change) and
    ``energy_drift_max`` (``max |E - E(0) - W_tau|``, J). With wrenches (profiles, or fields of the
    ``environment``) the momentum and energy
    change by what they apply, so none of that is a drift: balances instead
    (:func:`freefloat.dynamics.balance.balance`), ``com_balance_max``,
    ``linear_momentum_balance_max``, ``angular_momentum_balance_max``, ``momentum_balance_max``,
    ``energy_balance_max``, with ``momentum_balance_relative`` (``momentum_balance_max`` over the
    largest applied impulse), ``external_impulse`` (``[linear; angular about the origin]`` at the
    end, N s and N m s, gravity included) and ``external_work`` (J).

    Both carry ``momentum_scale``: the largest linear or angular momentum of the run (norm, as
    :func:`momentum_drift`), the scale against which the run's drifts and balances are bounded.

    Raises:
        ValueError: when wrenches are given without ``control_period``.
    """
    tel = telemetry
    scale = float(max(np.linalg.norm(tel.momentum[:, :3], axis=1).max(), np.linalg.norm(tel.momentum[:, 3:], axis=1).max()))
    if not wrenches and not environment:
        change = momentum_change(tel.momentum, robot.base)
        return {
            "com_drift_max": float(np.linalg.norm(tel.com - free_com_motion(tel, robot), axis=1).max()),
            "linear_momentum_drift_max": float(np.linalg.norm(change[:, :3], axis=1).max()),
            "angular_momentum_drift_max": float(np.linalg.norm(change[:, 3:], axis=1).max()),
            "momentum_drift_max": momentum_drift(tel.momentum, robot.base),
            "energy_drift_max": float(np.abs(tel.energy - tel.energy[0] - tel.work).max()),
            "momentum_scale": scale,
        }
    if control_period is None:
        raise ValueError("conservation: a run with external wrenches needs its control_period")
    res = balance(robot, tel, wrenches, control_period, environment)
    linear, angular = (float(np.linalg.norm(part, axis=1).max()) for part in (res.momentum[:, :3], res.momentum[:, 3:]))
    applied = res.applied.impulse
    largest = max(np.linalg.norm(applied[:, :3], axis=1).max(), np.linalg.norm(applied[:, 3:], axis=1).max())
    return {
        "com_balance_max": float(np.linalg.norm(res.com, axis=1).max()),
        "linear_momentum_balance_max": linear, "angular_momentum_balance_max": angular,
        "momentum_balance_max": max(linear, angular),
        "momentum_balance_relative": max(linear, angular) / float(largest) if largest > 0.0 else None,
        "energy_balance_max": float(np.abs(res.energy).max()),
        "external_impulse": applied[-1].tolist(), "external_work": float(res.applied.work[-1]),
        "momentum_scale": scale,
    }


def summarize(telemetry: Telemetry, robot: Robot, wrenches: tuple[ExternalWrench, ...] | list[ExternalWrench] = (),
              control_period: float | None = None, environment: Sequence[WrenchField] = ()) -> dict[str, object]:
    """Figures of merit of a run (SI units; see the README's output table): the conservation
    laws (:func:`conservation`: drifts, or balances against ``wrenches`` and the ``environment``'s
    fields applied over each ``control_period``), base motion, end-effector positions, peak
    torque, tracking errors."""
    tel = telemetry
    out: dict[str, object] = conservation(tel, robot, wrenches, control_period, environment)
    out.update({
        "base_displacement": (tel.base_position[-1] - tel.base_position[0]).tolist(),
        "base_rotation_max": float(rotation_angle(tel.base_quaternion, tel.base_quaternion[0]).max()),
        "end_effectors_start": {n: tel.ee_position[0, i].tolist() for i, n in enumerate(robot.end_effectors)},
        "end_effectors_end": {n: tel.ee_position[-1, i].tolist() for i, n in enumerate(robot.end_effectors)},
        "peak_joint_torque": float(np.abs(tel.tau).max()) if tel.tau.size else 0.0,
    })
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
