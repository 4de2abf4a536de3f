"""Atlas kind ``workspace``: the free-floating workspace of one end-effector (Papadopoulos and
Dubowsky), beside the fixed-base workspace of the same arm.

Reasoning (zero momentum). The system CoM does not move (Vafa and Dubowsky's virtual ground), and
the end-effector's position relative to it is ``R0(attitude) f(q)``: its distance from the CoM,
``|f(q)|``, depends on the joints only, while the base attitude, which the joints' motions change
without the base being driven (non-holonomically), turns the direction. So the reachable workspace
is the shell (a planar robot: the annulus) about the CoM between the least and the greatest
``|f(q)|`` over the joint grid. Dynamic singularities, where J* loses rank, depend on q only too;
every point at a distance ``|f(q_s)|`` from the CoM of a singular ``q_s`` can be met at a dynamic
singularity on some path (which one depends on the attitude the path arrives with): those shells
form the path-dependent workspace (PDW). The rest of the reachable shell, the path-independent
workspace (PIW), is reached along any path without meeting one. On a grid, a point counts as
singular when sigma_min / sigma_max of the J* block is below ``--tolerance``; the singular radii
are filled in between neighbouring singular grid points (see :func:`shells`) and resolved in
:data:`BINS` radial bins.

The fixed-base workspace of the same arm is the set of its end-effector positions relative to the
base CoM with the base held, and its kinematic singularities those of Jm.

With a momentum M, the CoM drifts at P / m and the angular momentum turns the system: the shells
above still hold in the frame that moves with the CoM (|f(q)| and the rank of J* do not depend on
M), and the map adds, per joint configuration, the joint rate needed to hold the end-effector
against the drift (``hold_rate``, see :mod:`.arm_maps`), infinite in effect at a singularity.

Grid (default): every joint of the arm, from its lower to its upper limit (revolute joints without
limits over [-pi, pi]), the other joints held; ``--grid N`` points per axis (default: about
:data:`POINTS` in all, an odd count per axis so that zero is on it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .arm_figures import cloud_page, joint_panel
from .arm_maps import OPTIONS, ArmMap, described, evaluate
from .arm_maps import prepare as prepare_arm
from .grid import Axis, Grid
from .kinds import Options

__all__ = ["OPTIONS", "evaluate", "figures", "grid", "prepare", "shells", "summarise"]

#: Grid points of the default grid, about.
POINTS = 50_000
#: Radial bins of the shells.
BINS = 400


def prepare(target: str, options: Options) -> ArmMap:
    """The map's context: the default axes are all the arm's joints."""
    return prepare_arm(target, options, all_arm_joints=True)


def grid(context: ArmMap, options: Options) -> Grid:
    """Every axis over its joint's range, ``options.grid`` points each (default: odd, about
    :data:`POINTS` in all)."""
    n = options.grid or int(POINTS ** (1 / len(context.axes))) // 2 * 2 + 1
    return Grid(tuple(Axis(name, low, high, n) for name, (low, high) in zip(context.axes, context.limits)))


def shells(radius: np.ndarray, singular: np.ndarray, shape: tuple[int, ...], bins: int = BINS) -> dict:
    """The reachable radii [low, high] and their split into path-dependent radii and
    path-independent ones, as merged intervals of ``bins`` radial bins, m.

    ``radius`` and ``singular`` hold the grid's points in flat order over a grid of ``shape``. The
    path-dependent radii are those of the singular points and, where two neighbouring grid points
    (one step along one axis) are both singular, every radius between theirs: the singular set
    is a manifold the grid samples, and its radii fill the range between neighbouring samples on
    it (a singular point without a singular neighbour adds its own radius only)."""
    low, high = float(radius.min()), float(radius.max())
    edges = np.linspace(low, high, bins + 1)
    r, s = radius.reshape(shape), singular.reshape(shape)
    lows, highs = [radius[singular]], [radius[singular]]
    for axis in range(len(shape)):
        a = (slice(None),) * axis + (slice(0, -1),)
        b = (slice(None),) * axis + (slice(1, None),)
        both = s[a] & s[b]
        lows.append(np.minimum(r[a], r[b])[both])
        highs.append(np.maximum(r[a], r[b])[both])
    first = np.clip(np.searchsorted(edges, np.concatenate(lows), side="right") - 1, 0, bins - 1)
    last = np.clip(np.searchsorted(edges, np.concatenate(highs), side="right") - 1, 0, bins - 1)
    count = np.zeros(bins + 1, int)
    np.add.at(count, first, 1)
    np.add.at(count, last + 1, -1)
    dependent = np.cumsum(count)[:bins] > 0
    return {"reachable": [low, high], "path_dependent": _intervals(edges, dependent),
            "path_independent": _intervals(edges, ~dependent)}


def _intervals(edges: np.ndarray, mask: np.ndarray) -> list[list[float]]:
    """Runs of True bins as [start, end] radii."""
    padded = np.concatenate(([False], mask, [False])).astype(int)
    starts, ends = np.nonzero(np.diff(padded) == 1)[0], np.nonzero(np.diff(padded) == -1)[0]
    return [[float(edges[a]), float(edges[b])] for a, b in zip(starts, ends)]


def share(intervals: list[list[float]], reach: list[float], power: int) -> float:
    """Share of the shell ``reach`` that ``intervals`` cover, by area (power 2) or volume (3)."""
    whole = reach[1] ** power - reach[0] ** power
    return float(sum(b**power - a**power for a, b in intervals) / whole) if whole > 0 else 0.0


def summarise(context: ArmMap, grid: Grid, result: dict[str, np.ndarray]) -> dict:
    """Reachable, path-dependent and path-independent shells (free-floating, about the system CoM),
    the fixed-base reach (about the base CoM), and the singular shares of the grid."""
    power = 2 if context.base == "planar" else 3
    free = shells(result["radius_free"], result["singular_free"], grid.shape)
    fixed = shells(result["radius_fixed"], result["singular_fixed"], grid.shape)
    out = {
        **described(context),
        "reach_free_min_m": free["reachable"][0], "reach_free_max_m": free["reachable"][1],
        "reach_fixed_min_m": fixed["reachable"][0], "reach_fixed_max_m": fixed["reachable"][1],
        "pdw_share": share(free["path_dependent"], free["reachable"], power),
        "piw_share": share(free["path_independent"], free["reachable"], power),
        "singular_share_free": float(result["singular_free"].mean()),
        "singular_share_fixed": float(result["singular_fixed"].mean()),
        "shells_free": free, "shells_fixed": fixed,
    }
    if "hold_rate" in result:
        finite = result["hold_rate"][~result["singular_free"]]
        out["hold_rate_median_rad_s"] = float(np.median(finite)) if finite.size else None
        out["hold_rate_max_rad_s"] = float(finite.max()) if finite.size else None
    return out


def _page(context: ArmMap, result: dict[str, np.ndarray], path: Path) -> Path:
    """The spatial map's points on a meshcat page: the free-floating positions about the system CoM
    of the reference posture (grey; dynamic singularities red) and the fixed-base ones (blue;
    kinematic singularities orange), the greatest reach of each as a sphere's great circles (red
    about the system CoM, blue about the base CoM), the robot at the reference posture."""
    from .arm_maps import reference_point

    com, r0 = reference_point(context)
    grey, red, blue, orange = (np.array(c) for c in ((0.6, 0.6, 0.6), (0.85, 0.15, 0.15), (0.2, 0.45, 0.8),
                                                     (1.0, 0.6, 0.1)))
    free = np.where(result["singular_free"][:, None], red, grey)
    fixed = np.where(result["singular_fixed"][:, None], orange, blue)
    spheres = [("reach_free", 0xD62728, com, float(result["radius_free"].max())),
               ("reach_fixed", 0x1F77B4, r0, float(result["radius_fixed"].max()))]
    return cloud_page(context, [("free_floating", com + result["ee_from_com"], free),
                                ("fixed_base", r0 + result["ee_from_base"], fixed)], spheres, path)


def figures(context: ArmMap, grid: Grid, result: dict[str, np.ndarray], out: Path) -> list[Path]:
    """``workspace_task_space.png`` (free-floating shells about the CoM beside the fixed-base
    points about the base CoM), ``workspace_radii.png`` (the radii of every point and of the
    singular ones), for two or more axes ``workspace_joint_space.png`` (and with a momentum
    ``workspace_hold_rate.png``), and on a free base the
    3-D points on a meshcat page, ``workspace_points.html``."""
    from ..viz.plotting import figure, finish, save

    free = shells(result["radius_free"], result["singular_free"], grid.shape)
    fig, (left, right) = figure(1, 2, (12, 5.6), f"{context.target}: workspace of {context.end_effector}")
    step = max(1, len(result["radius_free"]) // 20_000)
    for ax, key, flags, about in ((left, "ee_from_com", "singular_free", "system CoM"),
                                  (right, "ee_from_base", "singular_fixed", "base CoM")):
        xy = result[key][::step, :2]
        ax.plot(xy[:, 0], xy[:, 1], ".", ms=1.5, color="0.6", label="grid points (this attitude)")
        bad = result[key][result[flags], :2]
        ax.plot(bad[:, 0], bad[:, 1], ".", ms=2.5, color="#d62728",
                label="singular (J*)" if ax is left else "singular (Jm)")
        ax.set_aspect("equal")
        finish(ax, "x (m)", "y (m)", f"{'free-floating' if ax is left else 'fixed base'}, about the {about}")
    angle = np.linspace(0, 2 * np.pi, 361)
    for kind, color in (("path_independent", "#2ca02c"), ("path_dependent", "#d62728")):
        for a, b in free[kind]:
            ring = np.concatenate((b * np.exp(1j * angle), a * np.exp(-1j * angle)))
            # solid: matplotlib before 3.11 refuses to draw the cycle's dashes at zero width
            left.fill(ring.real, ring.imag, color=color, alpha=0.25, lw=0, linestyle="-")
    left.plot([], [], "s", color="#2ca02c", alpha=0.4, label="PIW")
    left.plot([], [], "s", color="#d62728", alpha=0.4, label="PDW")
    left.legend(loc="upper right", fontsize=7)
    paths = [*save(fig, out, "workspace_task_space")]
    fig, (ax,) = figure(1, 1, (8, 4.5), f"{context.target}: distance of {context.end_effector} from the CoM")
    bins = np.linspace(free["reachable"][0], free["reachable"][1], 101)
    ax.hist(result["radius_free"], bins=bins, color="0.6", label="every grid point")
    ax.hist(result["radius_free"][result["singular_free"]], bins=bins, color="#d62728", label="singular J*")
    ax.set_yscale("log")
    finish(ax, "distance from the system CoM (m)", "grid points")
    paths += save(fig, out, "workspace_radii")
    if len(grid.axes) >= 2:
        fig, axes = figure(1, 2, (12, 5), f"{context.target}: {context.end_effector} over two joints")
        joint_panel(axes[0], context, grid, result["radius_free"], "distance from the system CoM (m)",
                    {"singular J*": result["singular_free"], "singular Jm": result["singular_fixed"]})
        joint_panel(axes[1], context, grid, result["radius_fixed"], "distance from the base CoM (m)", {})
        paths += save(fig, out, "workspace_joint_space")
        if "hold_rate" in result:
            fig, (ax,) = figure(1, 1, (7, 5), f"{context.target}: joint rate holding {context.end_effector} "
                                              "against the momentum's drift")
            held = np.where(result["singular_free"], np.nan, result["hold_rate"])  # no rate holds it there
            joint_panel(ax, context, grid, held, "hold rate (rad/s)",
                        {"singular J*": result["singular_free"]}, log=True)
            paths += save(fig, out, "workspace_hold_rate")
    if context.base == "free":
        paths.append(_page(context, result, out / "workspace_points.html"))
    return [p for p in paths if p.suffix == ".png"] + [p for p in paths if p.suffix != ".png"]
