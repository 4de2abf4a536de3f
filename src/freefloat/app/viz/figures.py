"""Figures of a robot run, fit to print: titled, units on every axis, arms named, curves that
lie on each other still distinguishable, paths in 3-D (or in the xy-plane when the motion stays
in it, said so) with the robot drawn at start and end, log axes clipped to the data.

Each ``*_figure`` function returns a :class:`matplotlib.figure.Figure` on the Agg canvas (see
:mod:`.plotting`), so tests can read the plotted data; :func:`write_figures` saves those the run
chose (:mod:`freefloat.app.figure_set`), less those whose data is identically zero
(:func:`.figure_data.empty_figures` says which and why, for the summary). Positions and momenta
are in the inertial frame, as recorded in :class:`~freefloat.dynamics.telemetry.Telemetry`; joint
errors in rad (m for prismatic joints), as in the summary.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from ...dynamics.balance import Balance, balance
from ...dynamics.metrics import SETTLE_BAND, angular_speeds, band_settling_time, free_com_motion
from ...dynamics.telemetry import Telemetry
from ...dynamics.wrenches import ExternalWrench
from ...robot.joints import prismatic_columns
from ...robot.robot import Arm, Robot
from .figure_data import base_attitude, empty_figures, why_no_joint_errors
from .plotting import (
    STYLES,
    curve,
    decade_label,
    figure,
    finish,
    finish_path,
    in_plane,
    log_curve,
    path,
    save_all,
    thin,
)

#: Title of a planned capture's approach tracking figure.
APPROACH_TITLE = "Approach before the grasp: joint tracking error, plan - actual"
#: Colours of the robot drawn at the start and at the end of a run.
START_COLOR, END_COLOR = "#b0b0b0", "#303030"


def write_figures(robot: Robot, telemetry: Telemetry, out_dir: str | Path,
                  wrenches: tuple[ExternalWrench, ...] = (), control_period: float | None = None,
                  spin: bool = False, settle_threshold: float | None = None,
                  residuals: Balance | None = None) -> list[Path]:
    """Write the figures of a run that its writer chose (:func:`.plotting.choose`; default: every
    one, as PNG), each drawn only when chosen.

    Args:
        robot: the robot the run was simulated with.
        telemetry: the recorded run.
        out_dir: folder to write into (created if missing).
        wrenches: the run's external wrenches; with some, ``conservation_balance`` (momentum and
            energy against what they applied) replaces ``com_drift``.
        control_period: s; needed with ``wrenches``.
        spin: also draw ``angular_rates`` (base and end-effector spin decaying: detumbling and
            capture runs), with the ``settle_threshold`` (rad/s) if given, and
            ``angular_momentum`` (L(t) itself, dissertation fig 41).
        residuals: the run's balance when it has fields of the environment (computed where
            they are, by the run: :func:`~freefloat.dynamics.balance.balance`); given, it is
            drawn as ``conservation_balance`` in place of ``com_drift``.

    Returns:
        The written files: ``joint_errors`` (only when the run has joint references),
        ``torques``, ``base_trajectory``, ``end_effector_paths``, ``end_effector_displacement``,
        ``com_drift`` or ``conservation_balance``, ``angular_rates`` and ``angular_momentum``,
        each in the chosen formats, less those not chosen and those
        :func:`.figure_data.empty_figures` names.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    left_out = empty_figures(robot, telemetry, spin)
    panels = ArmPanels(robot, telemetry.t)  # joint_errors and torques: one figure, redrawn
    figures = {
        "joint_errors": lambda: joint_error_figure(robot, telemetry, panels),
        "torques": lambda: torque_figure(robot, telemetry, panels),
        "base_trajectory": lambda: base_trajectory_figure(telemetry),
        "end_effector_paths": lambda: end_effector_paths_figure(robot, telemetry),
        "end_effector_displacement": lambda: end_effector_displacement_figure(robot, telemetry),
    }
    if residuals is not None:
        figures["conservation_balance"] = lambda: balance_figure(telemetry, residuals)
    elif wrenches:
        if control_period is None:
            raise ValueError("write_figures: a run with external wrenches needs its control_period")
        figures["conservation_balance"] = lambda: balance_figure(
            telemetry, balance(robot, telemetry, wrenches, control_period))
    else:
        figures["com_drift"] = lambda: com_drift_figure(robot, telemetry)
    if spin:
        figures["angular_rates"] = lambda: angular_rates_figure(robot, telemetry, settle_threshold)
        figures["angular_momentum"] = lambda: angular_momentum_figure(telemetry)
    return save_all({name: None if name in left_out else draw for name, draw in figures.items()}, out_dir)


def arm_name(arm: Arm, index: int) -> str:
    """An arm's name: the common prefix of its joint names (``arm1_joint1``, ``arm1_joint2`` ->
    ``arm1``; ``left_shoulder_pan_joint``, ... -> ``left``), else ``arm <index + 1>``."""
    prefix = os.path.commonprefix(list(arm.joints)) if len(arm.joints) > 1 else ""
    prefix = prefix.rstrip("_- ")
    if prefix.lower().endswith("joint"):
        prefix = prefix[: -len("joint")].rstrip("_- ")
    return prefix or f"arm {index + 1}"


def joint_error_figure(robot: Robot, telemetry: Telemetry, panels: ArmPanels | None = None,
                       title: str = "Joint tracking error, reference - actual") -> Figure | None:
    """Joint tracking error ``joint_reference - joint_positions`` (rad; m for prismatic joints)
    vs t, one panel per arm, drawn on ``panels`` (default: new ones). Returns None when the run
    has no reference (all NaN)."""
    error = telemetry.joint_reference - telemetry.joint_positions
    if np.all(np.isnan(error)):
        return None
    return (panels or ArmPanels(robot, telemetry.t)).draw(error, title, "error (rad)", "m", steps=False)


def write_approach_figure(robot: Robot, approach: Telemetry, out_dir: str | Path) -> list[Path]:
    """``approach_joint_errors``: the joint tracking error of a planned capture's approach
    (``approach``: the pre-capture phase, its joint reference the plan), as :func:`joint_error_figure`
    draws it, when chosen (:func:`.plotting.choose`) and not identically zero or absent."""
    if why_no_joint_errors(approach) is not None:
        return []
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    draw = lambda: joint_error_figure(robot, approach, title=APPROACH_TITLE)  # noqa: E731  -- drawn when chosen
    return save_all({"approach_joint_errors": draw}, out_dir)


def torque_figure(robot: Robot, telemetry: Telemetry, panels: ArmPanels | None = None) -> Figure:
    """Joint torques (N m; N for prismatic joints) vs t, one panel per arm, drawn as steps since
    ``tau[k]`` is held over [t_k, t_k+1), on ``panels`` (default: new ones)."""
    return (panels or ArmPanels(robot, telemetry.t)).draw(
        telemetry.tau, "Joint torques, held over each control period", "torque (N m)", "N", steps=True)


def base_trajectory_figure(telemetry: Telemetry) -> Figure:
    """Base CoM position x, y, z (m) and attitude roll, pitch, yaw (deg; R = Rz(yaw) Ry(pitch)
    Rx(roll), unwrapped) vs t, and the base CoM path: in 3-D, or in the xy-plane when the motion
    stays in it (the panel says which)."""
    flat = in_plane(telemetry.base_position)
    fig, (position_ax, attitude_ax, path_ax) = figure(
        1, 3, (15.0, 4.5), "Base CoM trajectory and attitude (inertial frame)",
        projections=[None, None, None if flat else "3d"])
    t, r0 = telemetry.t, telemetry.base_position
    for i, axis in enumerate("xyz"):
        curve(position_ax, t, r0[:, i], axis)
    finish(position_ax, "t (s)", "base CoM position (m)", "position")
    attitude = np.degrees(base_attitude(telemetry.base_quaternion))
    for i, angle in enumerate(("roll", "pitch", "yaw")):
        curve(attitude_ax, t, attitude[:, i], angle)
    finish(attitude_ax, "t (s)", "attitude (deg)", "attitude, R = Rz(yaw) Ry(pitch) Rx(roll)")
    path(path_ax, r0, "base CoM", flat)
    finish_path(path_ax, flat, "base CoM path")
    return fig


def end_effector_paths_figure(robot: Robot, telemetry: Telemetry) -> Figure:
    """The robot drawn at the start (light) and at the end (dark) of the run, the end-effector
    paths and the base CoM path: in 3-D, or in the xy-plane when the motion stays in it."""
    points = np.concatenate([telemetry.ee_position.reshape(-1, 3), telemetry.base_position])
    flat = in_plane(points)
    fig, (ax,) = figure(1, 1, (7.5, 6.5), "Robot at start and end, end-effector and base CoM paths",
                        right=0.72, projections=[None if flat else "3d"])
    for q, color, label in ((telemetry.q[0], START_COLOR, "robot at start"), (telemetry.q[-1], END_COLOR, "robot at end")):
        for k, segment in enumerate(skeleton(robot, q)):
            coords = segment[:, :2].T if flat else segment.T
            ax.plot(*coords, color=color, linestyle="-", linewidth=2.0, label=label if k == 0 else "_")
    ax.set_prop_cycle(STYLES)
    for k, (arm, name) in enumerate(zip(robot.arms, robot.end_effectors)):
        path(ax, telemetry.ee_position[:, k], f"{arm_name(arm, k)} ({name})", flat)
    path(ax, telemetry.base_position, "base CoM", flat)
    finish_path(ax, flat, "o start, s end", legend="outside")
    return fig


def end_effector_displacement_figure(robot: Robot, telemetry: Telemetry) -> Figure:
    """Each end-effector's displacement from its start, x, y, z (m, inertial frame) vs t, one
    panel per arm: the motion at its own scale, which the whole robot's span hides."""
    n = max(1, len(robot.end_effectors))
    fig, axes = figure(n, 1, (9.0, 2.6 * n + 0.8), "End-effector displacement from the start (inertial frame)",
                       right=0.85)
    for k, (ax, arm) in enumerate(zip(axes, robot.arms)):
        moved = telemetry.ee_position[:, k] - telemetry.ee_position[0, k]
        for i, axis in enumerate("xyz"):
            curve(ax, telemetry.t, moved[:, i], axis)
        finish(ax, "t (s)", "displacement (m)", f"{arm_name(arm, k)} ({arm.end_effector})", legend="outside")
    return fig


def com_drift_figure(robot: Robot, telemetry: Telemetry) -> Figure:
    """Drift of the system CoM from its free motion (m; the curve whose maximum is the summary's
    ``com_drift_max``, see :func:`freefloat.dynamics.metrics.free_com_motion`) and of the momenta
    ``|P(t) - P(0)|`` (kg m/s) and ``|L(t) - L(0)|`` (kg m^2/s, about the inertial origin) vs t,
    on log axes clipped to the data."""
    fig, (com_ax, momentum_ax) = figure(2, 1, (8.0, 6.5), "Conservation: CoM and momentum drift", right=0.97)
    t, momentum = telemetry.t, telemetry.momentum
    log_curve(com_ax, t, np.linalg.norm(telemetry.com - free_com_motion(telemetry, robot), axis=1),
              "|com - free motion|")
    finish(com_ax, "t (s)", "|com - free motion| (m)", "system CoM against com(0) + t P(0)/m + g t^2/2",
           legend=None)  # one curve, named by its axis: a legend is a quarter of a panel's render
    log_curve(momentum_ax, t, np.linalg.norm(momentum[:, :3] - momentum[0, :3], axis=1), "|P - P(0)| (kg m/s)")
    log_curve(momentum_ax, t, np.linalg.norm(momentum[:, 3:] - momentum[0, 3:], axis=1), "|L - L(0)| (kg m^2/s)")
    finish(momentum_ax, "t (s)", "momentum drift", "linear and angular momentum (about the origin)")
    return fig


def balance_figure(telemetry: Telemetry, residuals: Balance) -> Figure:
    """A run with external wrenches against the conservation laws: the momentum change and the
    impulse applied (linear kg m/s, angular kg m^2/s about the origin), the energy change less
    the joint torques' work and the wrenches' work (J), both on linear axes; below, on log axes
    clipped to the data, what is left of each balance (the summary's ``*_balance_max`` are
    their maxima), with the CoM's (m)."""
    fig, (momentum_ax, energy_ax, residual_ax, energy_residual_ax) = figure(
        2, 2, (13.0, 7.5), "Conservation with external wrenches: change = what the wrenches applied")
    tel, done = telemetry, residuals.applied
    t, change = tel.t, tel.momentum - tel.momentum[0]
    for part, name, unit in ((slice(0, 3), "P", "kg m/s"), (slice(3, 6), "L", "kg m^2/s")):
        curve(momentum_ax, t, np.linalg.norm(change[:, part], axis=1), f"|{name} - {name}(0)| ({unit})")
        curve(momentum_ax, t, np.linalg.norm(done.impulse[:, part], axis=1), f"|impulse| on {name} ({unit})")
    finish(momentum_ax, "t (s)", "momentum change, impulse", "momentum change and impulse applied (about the origin)")
    curve(energy_ax, t, tel.energy - tel.energy[0] - tel.work, "E - E(0) - W joints")
    curve(energy_ax, t, done.work, "W wrenches")
    finish(energy_ax, "t (s)", "energy (J)", "energy change and work of the wrenches")
    log_curve(residual_ax, t, np.linalg.norm(residuals.momentum[:, :3], axis=1), "|P - P(0) - impulse| (kg m/s)")
    log_curve(residual_ax, t, np.linalg.norm(residuals.momentum[:, 3:], axis=1), "|L - L(0) - impulse| (kg m^2/s)")
    log_curve(residual_ax, t, np.linalg.norm(residuals.com, axis=1), "|com - its forced motion| (m)")
    finish(residual_ax, "t (s)", "balance residual", "momentum and CoM balance")
    log_curve(energy_residual_ax, t, np.abs(residuals.energy), "|E - E(0) - W joints - W wrenches|")
    finish(energy_residual_ax, "t (s)", "energy balance residual (J)", "energy balance")
    return fig


def angular_rates_figure(robot: Robot, telemetry: Telemetry, threshold: float | None = None) -> Figure:
    """Spin decaying. Above, the base angular velocity ``w0`` (x, y, z, rad/s, inertial frame) on
    linear axes, with the time after which ``|w0|`` stays within the settling band
    (:func:`~freefloat.dynamics.metrics.band_settling_time`). Below, each end-effector's angular
    speed ``|w|`` and the base's (rad/s) on a log axis down to the smallest positive value, with
    the settle ``threshold`` when given."""
    fig, (base_ax, log_ax) = figure(2, 1, (9.0, 7.0), "Angular rates: base and end-effectors", right=0.75)
    t = telemetry.t
    base, ends = angular_speeds(robot, telemetry)
    for i, axis in enumerate("xyz"):
        curve(base_ax, t, telemetry.base_twist[:, 3 + i], f"w0 {axis}")
    settled = band_settling_time(t, base)
    base_ax.axvline(settled, color="grey", linestyle=":", linewidth=1.0, label=f"settled, {settled:.3g} s")
    finish(base_ax, "t (s)", "w0 (rad/s)", f"base angular velocity: final |w0| {base[-1]:.3g} rad/s, within "
           f"{SETTLE_BAND:.0%} of its peak change from {settled:.3g} s", legend="outside")
    rates = [(f"{arm_name(arm, k)} ({arm.end_effector})", ends[:, k]) for k, arm in enumerate(robot.arms)]
    for label, rate in rates + [("base", base)]:
        shown = thin(rate)
        log_ax.semilogy(t[shown], np.where(rate > 0.0, rate, np.nan)[shown], label=label)
    if threshold is not None:
        log_ax.axhline(threshold, color="grey", linestyle=":", linewidth=1.0, label=f"threshold {threshold:.3g} rad/s")
    positive = np.concatenate([ends.ravel(), base, [threshold] if threshold is not None else []])
    positive = positive[np.isfinite(positive) & (positive > 0.0)]
    if len(positive):
        log_ax.set_ylim(positive.min() / 2, positive.max() * 2)
    log_ax.yaxis.set_major_formatter(FuncFormatter(decade_label))
    finish(log_ax, "t (s)", "|w| (rad/s)", "angular speeds, log axis: how far they settle", legend="outside")
    return fig


def angular_momentum_about_com(telemetry: Telemetry) -> np.ndarray:
    """The system's angular momentum about its CoM, inertial axes, kg m^2/s (N, 3), from the
    recorded ``[P; L_O]`` about the inertial origin: ``L_G = L_O - com x P`` (Pinocchio's
    centroidal momentum's angular part)."""
    momentum = telemetry.momentum
    return momentum[:, 3:] - np.cross(telemetry.com, momentum[:, :3])


def angular_momentum_figure(telemetry: Telemetry) -> Figure:
    """The angular momentum L(t) itself (dissertation fig 41 plots only log |L - L0|): above,
    about the system CoM (x, y, z, kg m^2/s, inertial axes; :func:`angular_momentum_about_com`),
    below, about the inertial origin as recorded. Constant after a capture (no external
    wrench); a capture impulse shows as its step."""
    fig, (com_ax, origin_ax) = figure(2, 1, (9.0, 7.0), "Angular momentum L(t), inertial axes", right=0.82)
    t, about_com = telemetry.t, angular_momentum_about_com(telemetry)
    for i, axis in enumerate("xyz"):
        curve(com_ax, t, about_com[:, i], f"L_{axis}")
        curve(origin_ax, t, telemetry.momentum[:, 3 + i], f"L_{axis}")
    finish(com_ax, "t (s)", "L about CoM (kg m^2/s)", "about the system CoM", legend="outside")
    finish(origin_ax, "t (s)", "L about O (kg m^2/s)", "about the inertial origin", legend="outside")
    return fig


def skeleton(robot: Robot, q: np.ndarray) -> list[np.ndarray]:
    """Segments (2, 3) joining each joint origin to its parent's, and each end-effector frame to
    its joint, at configuration ``q``; inertial frame, m."""
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, q)
    segments = [np.array([data.oMi[model.parents[j]].translation, data.oMi[j].translation])
                for j in range(2, model.njoints)]
    for frame_id in robot.end_effector_frame_ids:
        joint = model.frames[frame_id].parentJoint
        segments.append(np.array([data.oMi[joint].translation, data.oMf[frame_id].translation]))
    return segments


class ArmPanels:
    """One panel per arm plotting per-joint time series (``joint_errors``, ``torques``): the first
    :meth:`draw` makes the figure, each later one redraws the same figure, its lines given the new
    data, style and labels (a run's second per-arm figure costs its rendering only). A drawn
    figure is the same as a fresh one's in every plotted datum (tested). One figure legend names
    the joints of every panel when the arms name them alike (:func:`joint_suffixes`), else each
    panel has its own."""

    def __init__(self, robot: Robot, t: np.ndarray):
        self.robot, self.t = robot, t
        self.fig: Figure | None = None

    def draw(self, values: np.ndarray, title: str, ylabel: str, prismatic_unit: str, steps: bool) -> Figure:
        """The columns of ``values`` (N, n_joints) of each arm's joints vs t, one line per joint,
        as steps (held over each period) when ``steps``; the figure titled ``title``, the panels'
        y axes ``ylabel`` (with ``prismatic_unit`` for the prismatic joints' arms)."""
        robot, t = self.robot, self.t
        n = max(1, len(robot.arms))
        first = self.fig is None
        shared = joint_suffixes(robot)
        if first:
            self.fig, _ = figure(n, 1, (10.0, 2.6 * n + 0.8), title, right=0.78 if shared is None else 0.85)
        else:
            self.fig.suptitle(title)
        prismatic = prismatic_columns(robot)
        style = "steps-post" if steps else "default"
        for k, (ax, arm) in enumerate(zip(self.fig.axes, robot.arms)):
            columns = arm.v_indices - robot.n_base
            for i, (name, column) in enumerate(zip(arm.joints, columns)):
                if first:
                    curve(ax, t, values[:, column], name, drawstyle=style)
                else:
                    shown = thin(np.asarray(values[:, column], dtype=float))
                    ax.lines[i].set_data(t[shown], values[shown, column])
                    ax.lines[i].set_drawstyle(style)
            label = ylabel[:-1] + f"; {prismatic_unit} prismatic)" if prismatic[columns].any() else ylabel
            if first:
                finish(ax, "t (s)", label, f"{arm_name(arm, k)} (end-effector {arm.end_effector})",
                       legend="outside" if shared is None else None)
            else:
                ax.set_ylabel(label)
                ax.relim()
                ax.autoscale_view()
        if first and shared is not None:  # one legend for all panels: a legend costs a quarter of a render
            top = self.fig.axes[0]
            self.fig.legend(top.lines, shared, title="each arm's", fontsize="small", title_fontsize="small",
                            loc="upper left", bbox_to_anchor=(top.get_position().x1 + 0.01, top.get_position().y1))
        return self.fig


def joint_suffixes(robot: Robot) -> list[str] | None:
    """Each arm's joint names less the arm's name (:func:`arm_name`: ``arm1_joint2`` ->
    ``joint2``) when every arm's list is the same and names them apart, so that one legend
    serves every per-arm panel; else None (each panel has its own legend)."""
    lists = set()
    for k, arm in enumerate(robot.arms):
        name = arm_name(arm, k)
        if not all(joint.startswith(name) for joint in arm.joints):
            return None
        lists.add(tuple(joint[len(name):].lstrip("_- ") for joint in arm.joints))
    if len(lists) != 1:
        return None
    (suffixes,) = lists
    return list(suffixes) if all(suffixes) and len(set(suffixes)) == len(suffixes) else None
