"""Dissertation-style figures of a run, drawn on matplotlib's Agg canvas (no display).

Each ``*_figure`` function returns a :class:`matplotlib.figure.Figure` that is not registered
with pyplot (nothing stays open; it is freed with its last reference), so tests can read the
plotted data; :func:`write_figures` saves them as PNG. All positions and momenta are in the
inertial frame, as recorded in :class:`~freefloat.dynamics.telemetry.Telemetry`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from scipy.spatial.transform import Rotation

from ...dynamics.metrics import free_com_motion
from ...dynamics.telemetry import Telemetry
from ...robot.robot import Robot


def write_figures(robot: Robot, telemetry: Telemetry, out_dir: str | Path) -> list[Path]:
    """Write the figures of a run as PNG files.

    Args:
        robot: the robot the run was simulated with.
        telemetry: the recorded run.
        out_dir: folder to write into (created if missing).

    Returns:
        The written files: ``joint_errors.png`` (only when the run has joint references),
        ``torques.png``, ``base_trajectory.png``, ``end_effector_paths.png``, ``com_drift.png``.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    figures = {
        "joint_errors.png": joint_error_figure(robot, telemetry),
        "torques.png": torque_figure(robot, telemetry),
        "base_trajectory.png": base_trajectory_figure(telemetry),
        "end_effector_paths.png": end_effector_paths_figure(robot, telemetry),
        "com_drift.png": com_drift_figure(robot, telemetry),
    }
    written = []
    for name, figure in figures.items():
        if figure is not None:
            figure.savefig(out_dir / name, dpi=120)
            written.append(out_dir / name)
    return written


def joint_error_figure(robot: Robot, telemetry: Telemetry) -> Figure | None:
    """Joint tracking error ``joint_reference - joint_positions`` vs t, one panel per arm.

    Revolute joints in deg, prismatic joints in m. Returns None when the run has no reference
    (all NaN).
    """
    error = telemetry.joint_reference - telemetry.joint_positions
    if np.all(np.isnan(error)):
        return None
    return _per_arm_figure(
        robot, telemetry.t, error * _joint_scale(robot), "error", "deg", "m", steps=False
    )


def torque_figure(robot: Robot, telemetry: Telemetry) -> Figure:
    """Joint torques (N m; forces in N for prismatic joints) vs t, one panel per arm, drawn as
    steps since ``tau[k]`` is held over [t_k, t_k+1)."""
    return _per_arm_figure(robot, telemetry.t, telemetry.tau, "torque", "N m", "N", steps=True)


def base_trajectory_figure(telemetry: Telemetry) -> Figure:
    """Base CoM position x, y, z (m) and attitude roll, pitch, yaw (deg; R = Rz(yaw) Ry(pitch)
    Rx(roll), unwrapped) vs t, and the base CoM path in the inertial xy-plane."""
    figure, (position_ax, attitude_ax, path_ax) = _figure(1, 3, (15.0, 4.0))
    t, r0 = telemetry.t, telemetry.base_position
    for i, axis in enumerate("xyz"):
        position_ax.plot(t, r0[:, i], label=axis)
    _finish(position_ax, "t (s)", "base CoM position (m)")
    attitude = np.degrees(base_attitude(telemetry.base_quaternion))
    for i, angle in enumerate(("roll", "pitch", "yaw")):
        attitude_ax.plot(t, attitude[:, i], label=angle)
    _finish(attitude_ax, "t (s)", "base attitude (deg)")
    _path(path_ax, r0[:, :2], "base CoM")
    _finish(path_ax, "x (m)", "y (m)", equal=True)
    return figure


def base_attitude(quaternions: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (rad, unwrapped over time) with R = Rz(yaw) Ry(pitch) Rx(roll), from
    quaternions [qx, qy, qz, qw] (N, 4); returns (N, 3)."""
    yaw_pitch_roll = Rotation.from_quat(quaternions).as_euler("ZYX")
    return np.unwrap(yaw_pitch_roll[:, ::-1], axis=0)


def end_effector_paths_figure(robot: Robot, telemetry: Telemetry) -> Figure:
    """Paths of the end-effector frame origins in the inertial xy-plane, start (o) and end (s)
    marked."""
    figure, (ax,) = _figure(1, 1, (6.0, 6.0))
    for k, name in enumerate(robot.end_effectors):
        _path(ax, telemetry.ee_position[:, k, :2], name)
    _finish(ax, "x (m)", "y (m)", equal=True)
    return figure


def com_drift_figure(robot: Robot, telemetry: Telemetry) -> Figure:
    """Drift of the system CoM from its free motion (m; the curve whose maximum is the summary's
    ``com_drift_max``, see :func:`freefloat.dynamics.metrics.free_com_motion`) and of the momenta
    ``|P(t) - P(0)|`` (kg m/s) and ``|L(t) - L(0)|`` (kg m^2/s, about the inertial origin) vs t."""
    figure, (com_ax, momentum_ax) = _figure(2, 1, (8.0, 6.0))
    t, momentum = telemetry.t, telemetry.momentum
    drift = np.linalg.norm(telemetry.com - free_com_motion(telemetry, robot), axis=1)
    com_ax.plot(t, drift, label="|com - free motion|")
    _finish(com_ax, "t (s)", "CoM drift (m)")
    momentum_ax.plot(
        t, np.linalg.norm(momentum[:, :3] - momentum[0, :3], axis=1), label="|P - P(0)| (kg m/s)"
    )
    momentum_ax.plot(
        t, np.linalg.norm(momentum[:, 3:] - momentum[0, 3:], axis=1), label="|L - L(0)| (kg m^2/s)"
    )
    _finish(momentum_ax, "t (s)", "momentum drift")
    return figure


def _per_arm_figure(
    robot: Robot,
    t: np.ndarray,
    values: np.ndarray,
    what: str,
    unit: str,
    prismatic_unit: str,
    steps: bool,
) -> Figure:
    """One panel per arm plotting the columns of ``values`` (N, n_joints) of the arm's joints."""
    figure, axes = _figure(max(1, len(robot.arms)), 1, (10.0, 3.0 * max(1, len(robot.arms))))
    prismatic = _joint_scale(robot) == 1.0
    for ax, arm in zip(axes, robot.arms):
        columns = arm.v_indices - robot.n_base
        for name, column in zip(arm.joints, columns):
            ax.plot(
                t, values[:, column], label=name, drawstyle="steps-post" if steps else "default"
            )
        units = unit + (f"; {prismatic_unit} prismatic" if prismatic[columns].any() else "")
        _finish(ax, "t (s)", f"{what} ({units})", title=arm.end_effector, legend_outside=True)
    return figure


def _joint_scale(robot: Robot) -> np.ndarray:
    """Per joint column (n_joints,): 180/pi for revolute joints (rad to deg), 1 for prismatic."""
    model = robot.model
    scale = np.empty(robot.n_joints)
    for j in range(2, model.njoints):
        kind = model.joints[j].shortname()
        is_prismatic = "Prismatic" in kind or kind.startswith("JointModelP")
        start = model.idx_vs[j] - robot.n_base
        scale[start : start + model.nvs[j]] = 1.0 if is_prismatic else 180.0 / np.pi
    return scale


def _path(ax: Axes, xy: np.ndarray, label: str) -> None:
    """A planar path (N, 2) with its start (o) and end (s) marked in the path's colour."""
    (line,) = ax.plot(xy[:, 0], xy[:, 1], label=label)
    ax.plot(xy[:1, 0], xy[:1, 1], "o", color=line.get_color(), label=f"{label} start")
    ax.plot(xy[-1:, 0], xy[-1:, 1], "s", color=line.get_color(), label=f"{label} end")


def _figure(rows: int, cols: int, size: tuple[float, float]) -> tuple[Figure, list[Axes]]:
    """A figure on an Agg canvas with a flat list of its axes."""
    figure = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(figure)
    return figure, list(np.atleast_1d(figure.subplots(rows, cols)).ravel())


def _finish(
    ax: Axes,
    xlabel: str,
    ylabel: str,
    title: str | None = None,
    equal: bool = False,
    legend_outside: bool = False,
) -> None:
    """Labels, grid, legend (right of the axes if ``legend_outside``) and (for paths) equal
    axis scales."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title is not None:
        ax.set_title(title)
    if equal:
        ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    if legend_outside:
        ax.legend(fontsize="small", loc="center left", bbox_to_anchor=(1.0, 0.5))
    else:
        ax.legend(fontsize="small")
