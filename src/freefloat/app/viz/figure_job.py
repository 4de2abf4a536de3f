"""A robot run's figures as one picklable job, and which of them its data leaves out.

Light (numpy and SciPy's rotations only when asked; no matplotlib): a run hands its
:class:`RobotFigures` to the figure helper (:mod:`.rendering`), which draws and writes them while
the run writes its data and page, so that the run itself never imports the plotting stack; and it
names the figures whose data is identically zero in its summary (:func:`empty_figures`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ...dynamics.metrics import angular_speeds, free_com_motion

if TYPE_CHECKING:
    from ...dynamics.telemetry import Telemetry
    from ...dynamics.wrenches import ExternalWrench
    from ...robot.robot import Robot


class ClosedLoop(NamedTuple):
    """What the ``closed_loop`` figure draws, each (N,) at the times ``t`` (s): the squeeze and
    the internal force's norm (N; None for closures that carry no grasp) and the closures' largest
    position (m) and rotation (rad) residuals."""

    t: np.ndarray
    squeeze: np.ndarray | None
    internal: np.ndarray | None
    drift_position: np.ndarray
    drift_rotation: np.ndarray


class WheelRows(NamedTuple):
    """What the ``reaction_wheels`` figure draws: times (N,), s; the wheels' names; stored momenta
    (N, nw), N m s, and their limits (nw,); torques (N, nw), N m, and their limits (nw,)."""

    t: np.ndarray
    names: list[str]
    momenta: np.ndarray
    max_momenta: np.ndarray
    torques: np.ndarray
    max_torques: np.ndarray


@dataclass(frozen=True)
class RobotFigures:
    """Every figure of a robot run, drawn by calling the job with the folder to write into (those
    chosen, :func:`.plotting.choose`): :func:`~.figures.write_figures` of ``robot`` and
    ``telemetry`` (with the run's ``wrenches``, ``control_period``, ``spin`` and
    ``settle_threshold``), the ``closed_loop`` figure of ``loop``, a planned capture's approach
    tracking (``approach`` on ``approach_robot``) and the ``reaction_wheels`` figure of ``wheels``,
    each when given."""

    robot: Robot
    telemetry: Telemetry
    wrenches: tuple[ExternalWrench, ...] = ()
    control_period: float | None = None
    spin: bool = False
    settle_threshold: float | None = None
    loop: ClosedLoop | None = None
    approach: Telemetry | None = None
    approach_robot: Robot | None = None
    wheels: WheelRows | None = None

    def __call__(self, folder: Path) -> list[Path]:
        """Draw and write the chosen figures into ``folder``; returns the paths."""
        from .figures import write_approach_figure, write_figures
        from .loop_figures import loop_figure
        from .plotting import save_all
        from .wheel_figures import wheel_figure

        paths = write_figures(self.robot, self.telemetry, folder, self.wrenches, self.control_period, self.spin,
                              self.settle_threshold)
        if self.loop is not None and len(self.loop.t) >= 2:
            paths += save_all({"closed_loop": lambda: loop_figure(*self.loop)}, folder)
        if self.approach is not None:
            paths += write_approach_figure(self.approach_robot or self.robot, self.approach, folder)
        if self.wheels is not None and len(self.wheels.t) >= 2:
            paths += save_all({"reaction_wheels": lambda: wheel_figure(*self.wheels)}, folder)
        return paths


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
