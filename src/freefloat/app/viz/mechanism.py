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
from .markers import PALETTE, Marker
from .meshcat_html import write_trajectory_html
from .plotting import curve, figure, finish, finish_path, log_curve, path, save_all

#: Names of the platform coordinates q#: the platform point's inertial x, y (, z), m.
COORDINATES = ("x", "y", "z")


def write_mechanism_figures(telemetry: MechanismTelemetry, out_dir: str | Path,
                            chain: ClosedChain | None = None) -> list[Path]:
    """Write ``platform_tracking``, ``efforts`` and ``loop_closure_drift`` as PNG and PDF;
    ``chain`` names the actuators and their units. Returns the paths."""
    out_dir = Path(out_dir)
    figures = {"platform_tracking": tracking_figure(telemetry), "efforts": efforts_figure(telemetry, chain),
               "loop_closure_drift": drift_figure(telemetry)}
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


def efforts_figure(telemetry: MechanismTelemetry, chain: ClosedChain | None = None) -> Figure:
    """Actuator efforts vs t, drawn as steps (held over each step), one panel per unit (N m for
    revolute actuators, N for prismatic ones), each actuator named after its joint (from
    ``chain``; ``actuator i`` without it)."""
    k = telemetry.efforts.shape[1]
    names = [chain.model.names[j] for j in chain.actuated] if chain is not None else [f"actuator {i}" for i in range(k)]
    units = [_unit(chain.model.joints[j].shortname()) for j in chain.actuated] if chain is not None else ["N m or N"] * k
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


def _unit(kind: str) -> str:
    """Effort unit of a Pinocchio joint type: N for prismatic joints, N m otherwise."""
    return "N" if "Prismatic" in kind or kind.startswith("JointModelP") else "N m"


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
