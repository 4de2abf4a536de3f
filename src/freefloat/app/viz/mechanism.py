"""Figures and the meshcat page of a closed-chain mechanism run (a mechanism scene).

The page draws the mechanism's URDF spanning tree (loaded as a robot whose free-flyer base stays
at the origin) with the chains' joints of each sample; the loop closes because the simulated
joints satisfy the closure. Each closure's two points are followed (sphere and path): where they
part, the loop has come apart.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.figure import Figure

from ...dynamics.telemetry import MechanismTelemetry
from ...parallel.closed_chain import ClosedChain
from ...robot.loading import load_robot
from .figures import _figure, _finish, _path
from .markers import PALETTE, Marker
from .meshcat_html import write_trajectory_html


def write_mechanism_figures(telemetry: MechanismTelemetry, out_dir: str | Path) -> list[Path]:
    """Write ``platform_tracking.png``, ``efforts.png`` and ``loop_closure_drift.png``; returns
    the paths."""
    out_dir = Path(out_dir)
    figures = {"platform_tracking.png": tracking_figure(telemetry), "efforts.png": efforts_figure(telemetry),
               "loop_closure_drift.png": drift_figure(telemetry)}
    for name, figure in figures.items():
        figure.savefig(out_dir / name, dpi=120)
    return [out_dir / name for name in figures]


def tracking_figure(telemetry: MechanismTelemetry) -> Figure:
    """Platform path against the reference in the plane of q#_0, q#_1 (when p >= 2), and the
    tracking error ``|q#_d - q#|`` per coordinate vs t (log scale; m or rad)."""
    tel = telemetry
    p = tel.platform.shape[1]
    figure, axes = _figure(1, 2 if p >= 2 else 1, (12.0, 4.5))
    if p >= 2:
        axes[0].plot(tel.platform_reference[:, 0], tel.platform_reference[:, 1], "--", color="grey", label="reference")
        _path(axes[0], tel.platform[:, :2], "platform")
        _finish(axes[0], "q#_0", "q#_1", equal=True)
    for i in range(p):
        axes[-1].semilogy(tel.t, np.abs(tel.platform_reference[:, i] - tel.platform[:, i]), label=f"q#_{i}")
    _finish(axes[-1], "t (s)", "|q#_d - q#|")
    return figure


def efforts_figure(telemetry: MechanismTelemetry) -> Figure:
    """Actuator efforts (N m or N) vs t, drawn as steps (held over each step)."""
    figure, (ax,) = _figure(1, 1, (8.0, 4.0))
    for i in range(telemetry.efforts.shape[1]):
        ax.plot(telemetry.t, telemetry.efforts[:, i], drawstyle="steps-post", label=f"actuator {i}")
    _finish(ax, "t (s)", "effort (N m or N)")
    return figure


def drift_figure(telemetry: MechanismTelemetry) -> Figure:
    """Loop-closure residual max |qbar| (m) vs t, log scale; with angular constraints also their
    orientation residual (rad)."""
    figure, (ax,) = _figure(1, 1, (8.0, 4.0))
    ax.semilogy(telemetry.t, np.maximum(telemetry.drift, 1e-300), label="max |qbar| (m)")
    if np.any(telemetry.orientation_drift > 0):
        ax.semilogy(telemetry.t, np.maximum(telemetry.orientation_drift, 1e-300), label="orientation (rad)")
    _finish(ax, "t (s)", "loop-closure residual")
    return figure


def write_mechanism_html(chain: ClosedChain, t: np.ndarray, q: np.ndarray, path: str | Path, fps: float) -> Path:
    """Self-contained meshcat page of a mechanism run.

    Args:
        chain: the mechanism loaded from its closure file; its URDF is drawn, and it maps
            Orsino's coordinates to the spanning tree's joints.
        t: sample times, s (N,).
        q: Orsino's coordinates ``[q#; q°]`` (N, n_q).
        path: output ``.html`` file.
        fps: animation frames per second of simulated time.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(chain.urdf, base="free")
    tree, model = chain.model, robot.model
    tree_q = np.array([chain.pinocchio_q(qk) for qk in q]).reshape(len(t), tree.nq)
    configurations = np.tile(robot.neutral(), (len(t), 1))
    for j in range(1, tree.njoints):  # same URDF, so the same joint names; the robot adds its base
        start, size = model.idx_qs[model.getJointId(tree.names[j])], tree.nqs[j]
        configurations[:, start:start + size] = tree_q[:, tree.idx_qs[j]:tree.idx_qs[j] + size]
    return write_trajectory_html(robot, t, configurations, path, fps=fps, markers=closure_markers(chain, tree_q))


def closure_markers(chain: ClosedChain, tree_q: np.ndarray) -> list[Marker]:
    """Both points of every closure (the constraint frames' origins, inertial frame, m (N, 3)) at
    the spanning tree's configurations ``tree_q`` (N, nq)."""
    model, data = chain.model, chain.model.createData()
    sides = [(i, side, getattr(c, f"joint{side}_id"), getattr(c, f"joint{side}_placement"))
             for i, c in enumerate(chain.constraints) for side in (1, 2)]
    points = np.empty((len(sides), len(tree_q), 3))
    for k, qk in enumerate(tree_q):
        pin.forwardKinematics(model, data, qk)
        for s, (_, _, joint, placement) in enumerate(sides):
            points[s, k] = data.oMi[joint].act(placement.translation)
    return [Marker(f"closure{i}_{model.names[joint]}", PALETTE[s % len(PALETTE)], points[s])
            for s, (i, _, joint, _) in enumerate(sides)]
