"""A run's figures as one picklable job, and the function the figure helper runs it with.

Light (no matplotlib): a run hands its :class:`RobotFigures` or :class:`MechanismFigures` to the
figure helper (:mod:`.rendering`) as :func:`draw_chosen`'s argument; the helper draws and writes
them while the run writes its data and page, so that the run itself never imports the plotting
stack.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ...robot.robot import Robot

if TYPE_CHECKING:
    from ...dynamics.balance import Balance
    from ...dynamics.telemetry import MechanismTelemetry, Telemetry
    from ...dynamics.wrenches import ExternalWrench
    from ...parallel.free_base import BaseTelemetry


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


class ThrusterRows(NamedTuple):
    """What the ``thrusters`` figure draws: times (N,), s; the thrusts held (N, k), N; the
    propellant burnt since the start (N,), kg; the specific impulse, s
    (:meth:`freefloat.space.thrusters.ThrusterSet.rows`)."""

    t: np.ndarray
    thrust: np.ndarray
    propellant: np.ndarray
    specific_impulse: float


class LvlhRows(NamedTuple):
    """What the ``relative_orbit`` figure draws: times (N,), s; the names of the points tracked
    (the base CoM, a capture's target CoM); their LVLH positions (N, m, 3), m (x radial, y
    along-track, z orbit normal: :mod:`freefloat.space.orbit.lvlh`), NaN where a point is not
    tracked (the target once grasped, when it moves with the hand)."""

    t: np.ndarray
    names: list[str]
    positions: np.ndarray


@dataclass(frozen=True)
class RobotFigures:
    """Every figure of a robot run, drawn by calling the job with the folder to write into (those
    chosen, :func:`.plotting.choose`): :func:`~.figures.write_figures` of ``robot`` and
    ``telemetry`` (with the run's ``wrenches``, ``control_period``, ``spin``,
    ``settle_threshold`` and, for a run with fields of the environment, its balance
    ``residuals``, computed by the run where the fields are), the ``closed_loop`` figure of ``loop``, a planned capture's approach
    tracking (``approach`` on ``approach_robot``), the ``reaction_wheels`` figure of ``wheels``, the
    ``thrusters`` figure of ``thrusters`` and the ``relative_orbit`` figure of ``lvlh``, each when
    given."""

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
    residuals: Balance | None = None
    thrusters: ThrusterRows | None = None
    lvlh: LvlhRows | None = None

    def __reduce__(self) -> tuple:
        """Pickled (for the figure helper) with its robots' visual geometry left out: no figure
        draws it, and a mesh robot's pickles to hundreds of MB (the UR5 satellite's 353 MB: its
        meshes' collision structures), past :data:`~freefloat.app.outputs.JOB_BYTES`."""
        values = [getattr(self, f.name) for f in fields(self)]
        return type(self), tuple(replace(v, visual_model=None) if isinstance(v, Robot) else v for v in values)

    def __call__(self, folder: Path) -> list[Path]:
        """Draw and write the chosen figures into ``folder``; returns the paths."""
        from .figures import write_approach_figure, write_figures
        from .loop_figures import loop_figure
        from .lvlh_figures import lvlh_figure
        from .plotting import save_all
        from .thruster_figures import thruster_figure
        from .wheel_figures import wheel_figure

        paths = write_figures(self.robot, self.telemetry, folder, self.wrenches, self.control_period, self.spin,
                              self.settle_threshold, self.residuals)
        if self.loop is not None and len(self.loop.t) >= 2:
            paths += save_all({"closed_loop": lambda: loop_figure(*self.loop)}, folder)
        if self.approach is not None:
            paths += write_approach_figure(self.approach_robot or self.robot, self.approach, folder)
        if self.wheels is not None and len(self.wheels.t) >= 2:
            paths += save_all({"reaction_wheels": lambda: wheel_figure(*self.wheels)}, folder)
        if self.thrusters is not None and len(self.thrusters.t) >= 2:
            paths += save_all({"thrusters": lambda: thruster_figure(*self.thrusters)}, folder)
        if self.lvlh is not None and len(self.lvlh.t) >= 2:
            paths += save_all({"relative_orbit": lambda: lvlh_figure(*self.lvlh)}, folder)
        return paths


@dataclass(frozen=True)
class MechanismFigures:
    """Every figure of a mechanism run, drawn by calling the job with the folder to write into
    (those chosen, :func:`.plotting.choose`): :func:`~.mechanism.write_mechanism_figures` of
    ``telemetry`` (``actuated``: the actuators' names and units,
    :meth:`~freefloat.parallel.closed_chain.ClosedChain.actuators`)
    and, on a moving base, :func:`~.mechanism.write_base_figures` of ``base`` and its
    ``momentum_drift`` (N,)."""

    telemetry: MechanismTelemetry
    actuated: list[tuple[str, str]]
    base: BaseTelemetry | None = None
    momentum_drift: np.ndarray | None = None

    def __call__(self, folder: Path) -> list[Path]:
        """Draw and write the chosen figures into ``folder``; returns the paths."""
        from .mechanism import write_base_figures, write_mechanism_figures

        written = write_mechanism_figures(self.telemetry, folder, self.actuated)
        if self.base is None:
            return written
        return written + write_base_figures(self.base, self.momentum_drift, folder)


def draw_chosen(figures: Callable[[Path], list[Path]], names: frozenset[str] | None, formats: tuple[str, ...],
                into: Path) -> list[Path]:
    """A run's figures: ``figures(into)`` with ``names`` chosen in ``formats``
    (:func:`.plotting.choose`); the paths written. The job a run sends to the figure helper."""
    from .plotting import choose

    with choose(names, formats):
        return figures(into)
