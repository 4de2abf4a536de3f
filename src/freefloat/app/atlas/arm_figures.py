"""Drawing shared by the space-robot kinds: a joint-space panel over the grid's first two axes
(the other axes at the grid value nearest the reference posture), and a meshcat page of 3-D
point clouds about the robot."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...robot.joints import JointCoordinates
from .arm_maps import ArmMap, robot_of
from .grid import Grid


def joint_slice(context: ArmMap, grid: Grid, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The first two axes' values (n0,), (n1,) and ``values`` (rows in flat grid order) on that
    plane (n0, n1), the other axes at the grid value nearest their reference posture."""
    cube = values.reshape(grid.shape)
    index = [slice(None), slice(None)] + [
        int(np.argmin(np.abs(axis.values() - context.posture[j])))
        for axis, j in zip(grid.axes[2:], context.axis_index[2:])]
    return grid.axes[0].values(), grid.axes[1].values(), cube[tuple(index)]


def joint_panel(ax, context: ArmMap, grid: Grid, values: np.ndarray, label: str, loci: dict[str, np.ndarray],
                log: bool = False) -> None:
    """``values`` as an image over the first two axes (deg; colours span the 1st to 99th
    percentile, so that the near-infinite values at a singularity do not flatten the rest), with
    each ``loci`` flag drawn as dots."""
    x, y, image = joint_slice(context, grid, values)
    shown = np.log10(np.clip(image, 1e-300, None)) if log else image
    shown = np.where(np.isfinite(shown), shown, np.nan)
    low, high = np.nanpercentile(shown, [1, 99]) if np.isfinite(shown).any() else (0.0, 1.0)
    half = [0.5 * (np.degrees(v[-1] - v[0]) / (len(v) - 1) if len(v) > 1 else 0.5) for v in (x, y)]
    extent = (np.degrees(x[0]) - half[0], np.degrees(x[-1]) + half[0], np.degrees(y[0]) - half[1],
              np.degrees(y[-1]) + half[1])  # cells centred on the grid's evenly spaced values
    image = ax.imshow(shown.T, origin="lower", extent=extent, aspect="auto", interpolation="nearest",
                      cmap="viridis", vmin=low, vmax=high)
    ax.figure.colorbar(image, ax=ax, label=f"log10 {label}" if log else label)
    for (name, flags), color, size in zip(loci.items(), ("#d62728", "#ffffff"), (4.0, 1.5)):
        _, _, mask = joint_slice(context, grid, flags)
        i, j = np.nonzero(mask)
        ax.plot(np.degrees(x[i]), np.degrees(y[j]), ".", ms=size, color=color, label=name)
    ax.set_xlabel(f"{grid.axes[0].name} (deg)")
    ax.set_ylabel(f"{grid.axes[1].name} (deg)")
    if loci:
        ax.legend(loc="upper right", fontsize=7, markerscale=3)


#: Most points of a cloud drawn on a page (an evenly strided sample beyond it).
MAX_CLOUD = 30_000


def cloud_page(context: ArmMap, clouds: list[tuple[str, np.ndarray, np.ndarray]],
               spheres: list[tuple[str, int, np.ndarray, float]], path: Path) -> Path:
    """A self-contained meshcat page (no server) of the robot at the reference posture and point
    clouds about it: each ``(name, points (m, 3) in the inertial frame, m; colours (m, 3) in [0, 1])``,
    thinned to :data:`MAX_CLOUD` points; each sphere ``(name, 0xRRGGBB, centre (3,), radius)`` drawn
    as its three great circles on the inertial planes (the camera frames them all)."""
    import meshcat.geometry as mg

    from ..viz.meshcat_html import write_trajectory_html

    robot = robot_of(context.target, context.base)
    q = robot.neutral()
    JointCoordinates(robot).set(q, np.array(context.posture))
    extra = []
    for name, points, colours in clouds:
        kept = np.arange(0, len(points), max(1, int(np.ceil(len(points) / MAX_CLOUD))))
        geometry = mg.PointsGeometry(points[kept].T.astype(np.float32), colours[kept].T.astype(np.float32))
        extra.append((name, mg.Points(geometry, mg.PointsMaterial(size=0.004)), np.eye(4)[None]))
    turn = np.linspace(0.0, 2 * np.pi, 121)
    ring = np.column_stack((np.cos(turn), np.sin(turn), np.zeros_like(turn)))
    lines = [(f"{name}_{plane}", colour, centre + radius * ring[:, order])
             for name, colour, centre, radius in spheres
             for plane, order in (("xy", [0, 1, 2]), ("xz", [0, 2, 1]), ("yz", [2, 0, 1]))]
    return write_trajectory_html(robot, np.zeros(1), q[None], path, extra=extra, lines=lines)
