"""The report's figures (``freefloat reproduce all``), drawn from what the studies saved: the
planar robots' runs as :func:`~..series_report.series_arrays` dictionaries, the 5R's series from
``five_bar``'s report. Each function returns one Agg :class:`~matplotlib.figure.Figure` (not
registered with pyplot), with the project's margins and curve styles (:mod:`....app.viz.plotting`).

Conventions of the inputs: ``t`` (N,) s; joints (N, n) rad, four joints per arm, arm-major;
end-effector poses (N, k, 3) as x, y in m and the z-rotation in deg, inertial frame.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from ....app.viz.plotting import curve, figure, finish, log_curve

JOINTS_PER_ARM = 4
WIDE, TALL = (10.0, 4.2), (10.0, 6.4)


def _arms(n_joints: int) -> range:
    return range(n_joints // JOINTS_PER_ARM)


def per_arm(runs: dict[str, dict], key: str, title: str, ylabel: str, scale: float = 1.0,
            reference: str | None = None) -> Figure:
    """One panel per arm: the arm's four columns of ``run[key]`` (N, n) times ``scale`` for each
    run of ``runs`` (label -> series), and optionally the column ``reference`` of the first run."""
    first = next(iter(runs.values()))
    arms = _arms(first[key].shape[1])
    fig, axes = figure(2, (len(arms) + 1) // 2, TALL, title)
    for arm, ax in zip(arms, axes):
        for label, run in runs.items():
            for j in range(JOINTS_PER_ARM):
                col = arm * JOINTS_PER_ARM + j
                curve(ax, run["t"], run[key][:, col] * scale, f"{label} joint {j + 1}" if len(runs) > 1 else f"joint {j + 1}")
        if reference is not None:
            for j in range(JOINTS_PER_ARM):
                ax.plot(first["t"], first[reference][:, arm * JOINTS_PER_ARM + j] * scale, "k:", linewidth=0.8)
        finish(ax, "t (s)", ylabel, f"arm {arm + 1}", legend="inside" if arm == 0 else None)
    return fig


def joint_errors(runs: dict[str, dict], title: str) -> Figure:
    """Joint tracking errors q_d - q (deg) per arm, one curve per joint and run."""
    errors = {label: {"t": r["t"], "e": r["joint_reference"] - r["joints"]} for label, r in runs.items()}
    return per_arm(errors, "e", title, "q_d - q (deg)", np.degrees(1.0))


def ee_paths(runs: dict[str, dict], title: str) -> Figure:
    """End-effector paths in the plane (x, y in m), one panel per arm, start marked."""
    first = next(iter(runs.values()))
    k = first["ee"].shape[1]
    fig, axes = figure(1, k, (10.0, 3.6), title)
    for arm, ax in enumerate(axes):
        for label, run in runs.items():
            ax.plot(run["ee"][:, arm, 0], run["ee"][:, arm, 1], label=label)
        ax.plot(*first["ee"][0, arm, :2], "ko", markersize=3, label="start")
        finish(ax, "x (m)", "y (m)", f"arm {arm + 1}", legend="inside" if arm == 0 else None)
    return fig


def ee_components(runs: dict[str, dict], title: str, components: Sequence[int], labels: Sequence[str],
                  relative: bool = False) -> Figure:
    """End-effector pose components over time (x, y in m or the z-rotation in deg), one panel per
    component and arm pair; ``relative``: minus the start value."""
    first = next(iter(runs.values()))
    fig, axes = figure(len(components), 1, (10.0, 2.4 * len(components) + 1.0), title)
    for ax, c, ylabel in zip(axes, components, labels):
        for label, run in runs.items():
            for arm in range(first["ee"].shape[1]):
                values = run["ee"][:, arm, c] - (run["ee"][0, arm, c] if relative else 0.0)
                curve(ax, run["t"], values, f"{label} arm {arm + 1}" if len(runs) > 1 else f"arm {arm + 1}")
        finish(ax, "t (s)", ylabel, legend="outside")
    fig.subplots_adjust(right=0.78)
    return fig


def tracking_errors(tsc: dict, jsc: dict, title: str, components: Sequence[int], labels: Sequence[str]) -> Figure:
    """TSC end-effector pose minus the JSC path (its reference) per component and arm."""
    difference = {"t": tsc["t"], "ee": tsc["ee"] - jsc["ee"]}
    return ee_components({"TSC - JSC": difference}, title, components, labels)


def ee_plane_errors(tsc: dict, jsc: dict, title: str) -> Figure:
    """The TSC end-effector position error in the plane (x error against y error, m) per arm."""
    e = tsc["ee"] - jsc["ee"]
    fig, axes = figure(1, e.shape[1], (10.0, 3.6), title)
    for arm, ax in enumerate(axes):
        ax.plot(e[:, arm, 0], e[:, arm, 1])
        finish(ax, "x error (m)", "y error (m)", f"arm {arm + 1}", legend=None)
        ax.ticklabel_format(style="sci", scilimits=(-2, 2))
    return fig


def kjc(kjc_arrays: dict, title: str, components: Sequence[int], labels: Sequence[str]) -> Figure:
    """E-GJM end-effector rates minus central differences of the simulated pose over time, per
    component and arm (the dissertation's kinematic consistency, KJC)."""
    residual = kjc_arrays["rates"] - kjc_arrays["differences"]
    fig, axes = figure(len(components), 1, (10.0, 2.4 * len(components) + 1.0), title)
    for ax, c, ylabel in zip(axes, components, labels):
        for arm in range(residual.shape[1]):
            curve(ax, kjc_arrays["t"], residual[:, arm, c], f"arm {arm + 1}")
        finish(ax, "t (s)", ylabel, legend="outside")
    fig.subplots_adjust(right=0.85)
    return fig


def base_motion(runs: dict[str, dict], title: str) -> Figure:
    """Base CoM x, y (m) and yaw (deg) over time."""
    fig, axes = figure(3, 1, TALL, title)
    for ax, c, ylabel in zip(axes, range(3), ("x (m)", "y (m)", "yaw (deg)")):
        for label, run in runs.items():
            curve(ax, run["t"], run["base"][:, c], label)
        finish(ax, "t (s)", ylabel, legend="inside" if c == 0 else None)
    return fig


def com_drift(runs: dict[str, dict], title: str) -> Figure:
    """|CoM(t) - CoM(0)| (m, log axis), the system CoM in the inertial frame."""
    fig, (ax,) = figure(1, 1, WIDE, title)
    for label, run in runs.items():
        log_curve(ax, run["t"], np.linalg.norm(run["com"] - run["com"][0], axis=1), label)
    finish(ax, "t (s)", "|CoM(t) - CoM(0)| (m)")
    return fig


def configuration(segments: np.ndarray, title: str) -> Figure:
    """The robot's links as segments (S, 2, 3) in the plane, m."""
    fig, (ax,) = figure(1, 1, (6.0, 6.0), title)
    for a, b in segments:
        ax.plot([a[0], b[0]], [a[1], b[1]], "o-", color="#1f77b4", markersize=3)
    ax.set_aspect("equal")
    finish(ax, "x (m)", "y (m)", legend=None)
    return fig


def angles_and_rates(run: dict, title: str, joint_space: bool) -> Figure:
    """Angles (deg, change from the start) and angular rates (rad/s) over time: the end-effectors'
    z-rotation and rate (``joint_space`` False, the dissertation's "TS") or every joint's ("JS")."""
    if joint_space:
        angles, rates = np.degrees(run["joints"] - run["joints"][0]), run["joint_rates"]
        names = [f"arm {i // JOINTS_PER_ARM + 1} joint {i % JOINTS_PER_ARM + 1}" for i in range(angles.shape[1])]
    else:
        angles, rates = run["ee"][..., 2] - run["ee"][0, :, 2], run["ee_wz"]
        names = [f"arm {i + 1} end-effector" for i in range(angles.shape[1])]
    fig, axes = figure(2, 1, TALL, title)
    for i, name in enumerate(names):
        curve(axes[0], run["t"], angles[:, i], name)
        curve(axes[1], run["t"], rates[:, i], name)
    finish(axes[0], "t (s)", "angle - start (deg)", legend="outside")
    finish(axes[1], "t (s)", "rate (rad/s)", legend=None)
    fig.subplots_adjust(right=0.78)
    return fig


def angular_momentum(run: dict, title: str) -> Figure:
    """The angular momentum about the system CoM, z (kg m^2/s), and |L(t) - L(end)| on a log axis."""
    fig, axes = figure(2, 1, TALL, title)
    curve(axes[0], run["t"], run["L_com"][:, 2], "L_z about the CoM")
    log_curve(axes[1], run["t"], np.linalg.norm(run["L_com"] - run["L_com"][-1], axis=1), "|L(t) - L(end)|")
    finish(axes[0], "t (s)", "L_z (kg m^2/s)")
    finish(axes[1], "t (s)", "|L - L(end)| (kg m^2/s)")
    return fig


def condition_numbers(study: dict, title: str, offset: str) -> Figure:
    """cond(J*) of the E-GJM rows along the first second from one start offset (deg)."""
    c = study[offset]
    fig, (ax,) = figure(1, 1, WIDE, title)
    log_curve(ax, np.asarray(c["t"]), np.asarray(c["condition"]), f"start offset {offset} deg")
    finish(ax, "t (s)", "condition number of J*")
    return fig


def five_bar_series(cases: dict[str, dict], key: str, column: int, title: str, ylabel: str,
                    scale: float = 1.0, symlog: float | None = None) -> Figure:
    """One column of a 5R series (``e_mm``, ``s`` or ``torque_Nm``) for each case, over time."""
    fig, (ax,) = figure(1, 1, WIDE, title)
    for label, case in cases.items():
        curve(ax, np.asarray(case["t"]), np.asarray(case[key])[:, column] * scale, label)
    if symlog is not None:
        ax.set_yscale("symlog", linthresh=symlog)
    finish(ax, "t (s)", ylabel)
    return fig


def five_bar_linkage(points: list[np.ndarray], title: str, labels: Sequence[str]) -> Figure:
    """Chains as polylines (each (3, 2): base joint, elbow, tip; m) in the plane."""
    fig, (ax,) = figure(1, 1, (6.0, 5.0), title)
    for chain, label in zip(points, labels):
        ax.plot(chain[:, 0], chain[:, 1], "o-", label=label)
    ax.set_aspect("equal")
    finish(ax, "x (m)", "y (m)")
    return fig


def workspace(workspace_map: dict, threshold: float, path: np.ndarray, title: str,
              singularities: dict | None = None) -> Figure:
    """The 5R's conditioning grid: out of reach, near-singular (condition >= ``threshold``),
    non-singular, and the reference ``path`` (M, 2) in m; over it, from ``singularities``
    (:func:`~..five_bar_report.singularity_map`), the exact boundary and the type I and type II
    loci of the path's working mode."""
    from matplotlib.colors import ListedColormap

    x, y = np.asarray(workspace_map["x"]), np.asarray(workspace_map["y"])
    c = np.array([[np.nan if v is None else v for v in row] for row in workspace_map["condition"]])
    region = np.where(np.isnan(c), 0, np.where(c >= threshold, 1, 2))
    fig, (ax,) = figure(1, 1, (9.0, 4.6), title)
    ax.pcolormesh(x, y, region, shading="nearest", vmin=0, vmax=2,
                  cmap=ListedColormap(["#08306b", "#fdd835", "#9ecae1"]))
    ax.plot(path[:, 0], path[:, 1], color="#d62728", linewidth=2, label="reference circle (eq 189)")
    if singularities is not None:
        for k, arc in enumerate(singularities["boundary"]):
            points = np.asarray(arc["points"])
            ax.plot(points[:, 0], points[:, 1], "k-", linewidth=1, label="exact boundary" if k == 0 else None)
        for kind, style in (("I", "k."), ("II", "m.")):
            points = np.asarray(singularities["loci"].get(kind, [])).reshape(-1, 2)
            ax.plot(points[:, 0], points[:, 1], style, markersize=3,
                    label=f"type {kind} locus, mode {singularities['mode']}")
    ax.plot([], [], "s", color="#08306b", label="out of reach")
    ax.plot([], [], "s", color="#fdd835", label=f"near-singular (condition >= {threshold:g})")
    ax.plot([], [], "s", color="#9ecae1", label="non-singular")
    ax.set_aspect("equal")
    finish(ax, "x (m)", "y (m)", legend="outside")
    fig.subplots_adjust(right=0.62)
    return fig


def saturation(title: str) -> Figure:
    """tanh(100 s) against sign(s)."""
    s = np.linspace(-0.1, 0.1, 801)
    fig, (ax,) = figure(1, 1, WIDE, title)
    ax.plot(s, np.tanh(100 * s), label="tanh(100 s)")
    ax.plot(s, np.sign(s), label="sign(s)")
    finish(ax, "s", "f(s)")
    return fig
