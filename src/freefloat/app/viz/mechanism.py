"""Figures of a closed-chain mechanism run (a mechanism scene): platform tracking, actuator
efforts, loop-closure drift, sliding variables and, on a moving base, its attitude and momentum.
Its page is :mod:`.mechanism_page`'s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ...dynamics.telemetry import MechanismTelemetry
from ...parallel.free_base import BaseTelemetry
from .plotting import curve, figure, finish, finish_path, log_curve, path, save_all

#: Names of the platform coordinates q#: the platform point's inertial x, y (, z), m.
COORDINATES = ("x", "y", "z")


def write_mechanism_figures(telemetry: MechanismTelemetry, out_dir: str | Path,
                            actuated: list[tuple[str, str]] | None = None) -> list[Path]:
    """Write ``platform_tracking``, ``efforts``, ``loop_closure_drift`` and ``sliding_variables``,
    those chosen (:func:`.plotting.choose`); ``actuated`` names the actuators and their units
    (:meth:`~freefloat.parallel.closed_chain.ClosedChain.actuators`), into ``out_dir`` (created if
    missing). Returns the paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    figures = {"platform_tracking": lambda: tracking_figure(telemetry),
               "efforts": lambda: efforts_figure(telemetry, actuated),
               "loop_closure_drift": lambda: drift_figure(telemetry),
               "sliding_variables": lambda: sliding_figure(telemetry)}
    return save_all(figures, out_dir)


def tracking_figure(telemetry: MechanismTelemetry) -> Figure:
    """Platform path against the reference (in 3-D for three coordinates, else in the xy-plane),
    and the tracking error ``|q#_d - q#|`` per coordinate vs t (m, log axis clipped to the data).
    The registry's mechanisms take as q# the platform point's inertial coordinates x, y (, z)."""
    tel = telemetry
    p = tel.platform.shape[1]
    flat = p < 3
    fig, axes = figure(1, 2, (13.0, 5.0), "Platform tracking", projections=[None if flat else "3d", None])
    padded = [np.pad(a, ((0, 0), (0, 3 - p))) for a in (tel.platform_reference, tel.platform)]
    axes[0].plot(*(padded[0][:, :2].T if flat else padded[0].T), color="grey", linestyle="--", linewidth=1.2,
                 label="reference")
    path(axes[0], padded[1], "platform", flat)
    finish_path(axes[0], flat, "platform path (o start, s end)")
    for i in range(p):
        log_curve(axes[1], tel.t, np.abs(tel.platform_reference[:, i] - tel.platform[:, i]), COORDINATES[i])
    finish(axes[1], "t (s)", "|q#_d - q#| (m)", "tracking error per coordinate")
    return fig


def efforts_figure(telemetry: MechanismTelemetry, actuated: list[tuple[str, str]] | None = None) -> Figure:
    """Actuator efforts vs t, drawn as steps (held over each step), one panel per unit (N m for
    revolute actuators, N for prismatic ones), each actuator named after its joint
    (``actuated``: :meth:`~freefloat.parallel.closed_chain.ClosedChain.actuators`; ``actuator i``
    without it)."""
    k = telemetry.efforts.shape[1]
    names = [name for name, _ in actuated] if actuated is not None else [f"actuator {i}" for i in range(k)]
    units = [unit for _, unit in actuated] if actuated is not None else ["N m or N"] * k
    kinds = list(dict.fromkeys(units))
    fig, axes = figure(len(kinds), 1, (9.0, 3.2 * len(kinds) + 0.8), "Actuator efforts, held over each step", right=0.8)
    for ax, unit in zip(axes, kinds):
        for i in (i for i in range(k) if units[i] == unit):
            curve(ax, telemetry.t, telemetry.efforts[:, i], names[i], drawstyle="steps-post")
        finish(ax, "t (s)", f"effort ({unit})", legend="outside")
    return fig


def drift_figure(telemetry: MechanismTelemetry) -> Figure:
    """Loop-closure residual max |qbar| (m) vs t; with angular constraints also their
    orientation residual (rad); log axis clipped to the data (an exact closure at t = 0 is left
    out rather than drawn at 1e-300)."""
    fig, (ax,) = figure(1, 1, (8.0, 4.5), "Loop-closure drift")
    log_curve(ax, telemetry.t, telemetry.drift, "max |qbar| (m)")
    if np.any(telemetry.orientation_drift > 0):
        log_curve(ax, telemetry.t, telemetry.orientation_drift, "orientation (rad)")
    finish(ax, "t (s)", "loop-closure residual (m; rad)")
    return fig


def sliding_figure(telemetry: MechanismTelemetry) -> Figure:
    """The law's sliding variables ``s = -(edot + lambda e)`` (m/s) per platform coordinate vs t
    (the thesis's figs 14-15 and 20-21): linear, and |s| on a log axis clipped to the data, where
    the reaching phase and the boundary layer the law keeps s in are read."""
    tel = telemetry
    fig, (linear, log) = figure(2, 1, (9.0, 7.0), "Sliding variables s = -(edot + lambda e), e = q#_d - q#")
    for i in range(tel.sliding.shape[1]):
        curve(linear, tel.t, tel.sliding[:, i], f"s_{COORDINATES[i]}")
        log_curve(log, tel.t, np.abs(tel.sliding[:, i]), f"|s_{COORDINATES[i]}|")
    finish(linear, "t (s)", "s (m/s)")
    finish(log, "t (s)", "|s| (m/s)")
    return fig


def write_base_figures(base: BaseTelemetry, momentum_drift: np.ndarray, out_dir: str | Path) -> list[Path]:
    """A mechanism on a moving base: write ``base_attitude`` (:func:`base_attitude_figure`) and
    ``momentum`` (:func:`momentum_figure`), those chosen (:func:`.plotting.choose`); returns the paths."""
    return save_all({"base_attitude": lambda: base_attitude_figure(base),
                     "momentum": lambda: momentum_figure(base, momentum_drift)}, Path(out_dir))


def base_attitude_figure(base: BaseTelemetry) -> Figure:
    """The base's reaction: the rotation vector of its attitude against its start (rad, x, y, z
    and the angle turned) and its displacement (m, x, y, z) vs t."""
    fig, (turn, move) = figure(2, 1, (9.0, 7.0), "Base reaction: attitude and position")
    for i, axis in enumerate(COORDINATES):
        curve(turn, base.t, base.base_rotation[:, i], f"rotation vector {axis}")
    curve(turn, base.t, np.linalg.norm(base.base_rotation, axis=1), "angle turned", color="black", linestyle="--")
    finish(turn, "t (s)", "log3(R(0)^T R(t)) (rad)")
    for i, axis in enumerate(COORDINATES):
        curve(move, base.t, base.base_position[:, i] - base.base_position[0, i], axis)
    finish(move, "t (s)", "base displacement (m)")
    return fig


def momentum_figure(base: BaseTelemetry, drift: np.ndarray) -> Figure:
    """The system's momentum about its CoM, each component vs t (linear N s, angular N m s), and
    the largest change of the conserved components (``drift`` (N,), gravity's impulse taken out:
    what the loop and the integrator leave), log axis."""
    fig, (linear, angular, change) = figure(3, 1, (9.0, 9.0), "System momentum (about its CoM, inertial axes)")
    for i, axis in enumerate(COORDINATES):
        curve(linear, base.t, base.momentum[:, i], f"P_{axis}")
        curve(angular, base.t, base.momentum[:, 3 + i], f"L_{axis}")
    finish(linear, "t (s)", "linear (N s)")
    finish(angular, "t (s)", "angular (N m s)")
    log_curve(change, base.t, drift, "max |h(t) - h(0) - impulse of gravity|")
    finish(change, "t (s)", "momentum drift (N s; N m s)")
    return fig
