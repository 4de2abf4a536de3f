"""Figures of the atlas kind ``mechanism`` (:mod:`.mechanism_maps`): a panel per mode over a 2-D
grid, slices, a 3-D scatter of the scenes' mode and (task space) a meshcat page of its point
cloud with the mechanism over a 3-D one."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .grid import Grid
from .mechanism_targets import labels, scene_mode, scene_of, setup_of

#: Colours of the loci: type I (legs stretched or folded), type II (platform free with the actuators locked).
TYPE_COLOURS = {"I": "black", "II": "crimson"}


def draw(context, grid: Grid, result: dict[str, np.ndarray], loci: dict, out: Path) -> list[Path]:
    """The figures of a map (see :func:`.mechanism_maps.figures`)."""
    import matplotlib

    matplotlib.use("Agg")
    if len(grid.axes) == 2:
        return [_modes(context, grid, result, loci, out / "modes.png")]
    if context.space != "task":
        return [_slices(context, grid, result, loci, out / "slices.png"), _cloud(context, grid, result, out / "workspace_3d.png")]
    return [_slices(context, grid, result, loci, out / "slices.png"), _cloud(context, grid, result, out / "workspace_3d.png"),
            _page(context, grid, result, out / "workspace.html")]


def _modes(context, grid: Grid, result: dict[str, np.ndarray], loci: dict, path: Path) -> Path:
    import matplotlib.pyplot as plt


    names, scene = labels(context), scene_mode(context)
    cols = 2 if len(names) <= 4 else 4
    rows = int(np.ceil(len(names) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 4.4 * rows), squeeze=False)
    a, b = grid.axes
    x, y = a.values(), b.values()
    for j, (ax, name) in enumerate(zip(axes.ravel(), names)):
        found = result["found"][:, j].reshape(grid.shape).T
        ax.pcolormesh(x, y, found, cmap="Blues", vmin=-0.6, vmax=1.6, shading="nearest")
        for kind, locus in loci.items():
            on = locus.mode == name
            xy = _plane(context, locus)[on]
            ax.plot(xy[:, 0], xy[:, 1], ".", ms=2.5, color=TYPE_COLOURS[kind], label=f"type {kind}")
        _overlay(context, ax)
        ax.set_title(f"mode {name}" + ("  (the scenes')" if name == scene else ""), fontsize=10)
        ax.set_xlabel(f"{a.name} ({a.unit})")
        ax.set_ylabel(f"{b.name} ({b.unit})")
        ax.set_aspect("equal" if a.unit == b.unit else "auto")
    for ax in axes.ravel()[len(names):]:
        ax.axis("off")
    axes.ravel()[0].legend(loc="lower left", fontsize=8, markerscale=4)
    space = "working modes over platform points" if context.space == "task" else "assembly modes over actuated joints"
    fig.suptitle(f"{context.mechanism}: {space} (shaded: the mode exists; start of the scenes "
                 f"{np.round(scene_of(context.mechanism)[0], 3).tolist()})", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _plane(context, locus) -> np.ndarray:
    """A locus' points in the grid's coordinates (K, d)."""
    return locus.coordinates[:, list(context.axes)]


def _overlay(context, ax) -> None:
    """The scenes' start (platform point, or actuated joints in joint space) and path; the 5R's
    exact workspace boundary (task space)."""

    start, q0, trajectory = scene_of(context.mechanism)
    i, j = context.axes
    if context.space != "task":
        actuated = q0[setup_of(context.mechanism).nominal.actuated]
        ax.plot(actuated[i], actuated[j], "o", color="orange", ms=5)
        return
    ax.plot(start[i], start[j], "o", color="orange", ms=5)
    if trajectory.get("kind") == "circle":
        axes = trajectory.get("axes", [0, 1])
        if [i, j] == list(axes):
            t = np.linspace(0, 2 * np.pi, 200)
            c, r = trajectory["center"], trajectory["radius"]
            ax.plot(c[i] + r * np.cos(t), c[j] + r * np.sin(t), color="orange", lw=1.2, label="scenes' path")
    if context.mechanism == "five_bar":
        from ...parallel.five_bar import FiveBarParameters
        from ...parallel.maps.five_bar_exact import boundary

        for arc in boundary(FiveBarParameters()):
            ax.plot(arc.points[:, 0], arc.points[:, 1], "--", color="grey", lw=0.8)


def _slices(context, grid: Grid, result: dict[str, np.ndarray], loci: dict, path: Path) -> Path:
    import matplotlib.pyplot as plt

    a, b, c = grid.axes
    anywhere = result["found"].any(axis=1).reshape(grid.shape)
    occupied = np.flatnonzero(anywhere.any(axis=(0, 1)))
    levels = occupied[np.unique(np.linspace(0, len(occupied) - 1, 3).round().astype(int))] if len(occupied) else [c.n // 2]
    fig, axes = plt.subplots(1, len(levels), figsize=(4.8 * len(levels), 4.4), squeeze=False)
    spacing = (c.high - c.low) / max(c.n - 1, 1)
    for ax, k in zip(axes[0], levels):
        ax.pcolormesh(a.values(), b.values(), anywhere[:, :, k].T, cmap="Blues", vmin=-0.6, vmax=1.6, shading="nearest")
        for kind, locus in loci.items():
            xyz = _plane(context, locus)
            near = np.abs(xyz[:, 2] - c.values()[k]) <= 0.5 * spacing
            ax.plot(xyz[near, 0], xyz[near, 1], ".", ms=2.5, color=TYPE_COLOURS[kind], label=f"type {kind}")
        ax.set_title(f"{c.name} = {c.values()[k]:.3g} {c.unit}", fontsize=10)
        ax.set_xlabel(f"{a.name} ({a.unit})")
        ax.set_ylabel(f"{b.name} ({b.unit})")
    axes[0, 0].legend(loc="lower left", fontsize=8, markerscale=4)
    fig.suptitle(f"{context.mechanism}: where some mode exists (shaded) and the loci within half a step", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _scene_points(context, grid: Grid, result: dict[str, np.ndarray]):
    """The scenes' mode's name, and where it exists: the grid points (m, d), log10 of the direct
    block's sigma_min / sigma_max there (m,) and the solutions (m, n_q)."""
    name = scene_mode(context)
    j = labels(context).index(name)
    found = result["found"][:, j]
    return name, grid.points()[found], np.log10(np.maximum(result["direct_ratio"][found, j], 1e-12)), result["q"][found, j]


def _cloud(context, grid: Grid, result: dict[str, np.ndarray], path: Path) -> Path:
    """The points where the scenes' mode exists as a 3-D scatter, coloured by the direct block's
    sigma_min / sigma_max (log scale: dark where the platform nears a type II singularity)."""
    import matplotlib.pyplot as plt

    name, points, ratio, _ = _scene_points(context, grid, result)
    fig = plt.figure(figsize=(6.5, 5.5))
    ax = fig.add_subplot(projection="3d")
    shown = ax.scatter(*points.T, c=ratio, s=3, cmap="viridis")
    fig.colorbar(shown, ax=ax, shrink=0.6, label="log10 sigma_min/sigma_max of the direct block")
    ax.set_xlabel(f"{grid.axes[0].name} ({grid.axes[0].unit})")
    ax.set_ylabel(f"{grid.axes[1].name} ({grid.axes[1].unit})")
    ax.set_zlabel(f"{grid.axes[2].name} ({grid.axes[2].unit})")
    ax.set_title(f"{context.mechanism}: mode {name} (the scenes')", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _page(context, grid: Grid, result: dict[str, np.ndarray], path: Path) -> Path:
    """A self-contained meshcat page: the mechanism at the scenes' start and the points where the
    scenes' mode exists (task space: the platform points, inertial frame, m), coloured from red
    (direct block's sigma ratio least on the map: nearest type II) to green (largest)."""
    import meshcat.geometry as mg

    from ..viz.mechanism_page import write_mechanism_html

    _, _, ratio, q = _scene_points(context, grid, result)
    points = q[:, :3]
    shade = (ratio - ratio.min()) / max(np.ptp(ratio), 1e-12)
    colours = np.column_stack((1.0 - shade, shade, np.full_like(shade, 0.2)))
    cloud = mg.Points(mg.PointsGeometry(points.T.astype(np.float32), colours.T.astype(np.float32)),
                      mg.PointsMaterial(size=0.008))
    setup = setup_of(context.mechanism)
    return write_mechanism_html(setup.display, np.zeros(1), scene_of(context.mechanism)[1][None], path, 30.0,
                                extra=[("workspace", cloud, np.eye(4)[None])])
