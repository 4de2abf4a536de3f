"""Atlas kind ``singularities``: where the generalized Jacobian J* of one end-effector loses rank
(dynamic singularities, Papadopoulos and Dubowsky) against where its fixed-base Jacobian Jm does
(kinematic singularities), with the condition number and the manipulability sqrt(det(J J^T)) (the
product of the singular values) of both, side by side, over two joints of the arm (default: its
first two, the other joints held at the reference posture; ``--grid N`` points per axis, default
:data:`POINTS_PER_AXIS`). See :mod:`.arm_maps` for the rows, columns and frames.

For the four-arm robot of the dissertation the map is drawn at Table 4's stretched posture and the
setting of its figs 38-40 is placed on it: the first second of the joint-space task's reference
path (quintic, every joint 5 deg in 5 s) from offsets of 0, 0.1 and 1 deg off the stretched arms,
projected on the map's axes, with the condition number along each path of the mapped block and of
the E-GJM rows the dissertation inverts (vx, vy, wz of the four end-effectors, all 16 joints).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...documents import DIRECTION, FIGS_38_40_OFFSET_DEG, TASK_DEG, TASK_S, start_angles
from .arm_figures import joint_panel
from .arm_maps import OPTIONS, ArmMap, described, evaluate, robot_of
from .arm_maps import prepare as prepare_arm
from .grid import Axis, Grid
from .kinds import Options

__all__ = ["OPTIONS", "evaluate", "figures", "figs_38_40", "grid", "prepare", "summarise"]

#: Points per axis of the default grid.
POINTS_PER_AXIS = 101
#: Start offsets of the dissertation's figs 38-40, deg, and the span of their paths, s.
OFFSETS_DEG, PATH_S = tuple(sorted(FIGS_38_40_OFFSET_DEG.values())), 1.0
#: Half-width of the figs 38-40 figure's close-up about the reference posture, deg.
ZOOM_DEG = 2.0


def prepare(target: str, options: Options) -> ArmMap:
    """The map's context: the default axes are the arm's first two joints."""
    return prepare_arm(target, options, all_arm_joints=False)


def grid(context: ArmMap, options: Options) -> Grid:
    """Every axis over its joint's range, ``options.grid`` (default :data:`POINTS_PER_AXIS`) points each."""
    n = options.grid or POINTS_PER_AXIS
    return Grid(tuple(Axis(name, low, high, n) for name, (low, high) in zip(context.axes, context.limits)))


def _spread(values: np.ndarray) -> dict[str, float]:
    finite = values[np.isfinite(values)]
    return {"min": float(finite.min()), "median": float(np.median(finite)), "max": float(finite.max()),
            "infinite": int((~np.isfinite(values)).sum())} if finite.size else {"infinite": int(values.size)}


def summarise(context: ArmMap, grid: Grid, result: dict[str, np.ndarray]) -> dict:
    """Shares of singular points (dynamic only, kinematic only, both), the spreads of the condition
    numbers and manipulabilities, and (four-arm robot) the figs 38-40 paths."""
    free, fixed = result["singular_free"], result["singular_fixed"]
    out = {**described(context),
           "singular_share_free": float(free.mean()), "singular_share_fixed": float(fixed.mean()),
           "dynamic_only_share": float((free & ~fixed).mean()), "kinematic_only_share": float((fixed & ~free).mean()),
           "condition_free": _spread(result["cond_free"]), "condition_fixed": _spread(result["cond_fixed"]),
           "manipulability_free": _spread(result["manipulability_free"]),
           "manipulability_fixed": _spread(result["manipulability_fixed"])}
    paths = figs_38_40(context)
    if paths:
        out["figs_38_40"] = {f"{offset:g}_deg": {"start_on_axes_deg": np.degrees(p["on_axes"][0]).tolist(),
                                                  "condition_block_start": float(p["cond_block"][0]),
                                                  "condition_egjm_start": float(p["cond_egjm"][0]),
                                                  "condition_block_end": float(p["cond_block"][-1]),
                                                  "condition_egjm_end": float(p["cond_egjm"][-1])}
                             for offset, p in paths.items()}
    return out


def figs_38_40(context: ArmMap, samples: int = 21) -> dict[float, dict[str, np.ndarray]]:
    """For the four-arm robot (else empty): per offset of :data:`OFFSETS_DEG`, the reference path's
    first :data:`PATH_S` s at ``samples`` times: ``on_axes`` (samples, len(axes)) rad, and the
    condition numbers of the mapped J* block (``cond_block``) and of the E-GJM rows vx, vy, wz of
    the four end-effectors over all joints (``cond_egjm``), as the dissertation computes them."""
    if Path(context.target).stem != "four_arm_planar" or context.base != "planar":
        return {}
    from ...dynamics import gjm
    from ...robot.joints import JointCoordinates
    from ...space.control import QuinticTrajectory

    robot = robot_of(context.target, context.base)
    coords, q, v = JointCoordinates(robot), robot.neutral(), np.zeros(robot.model.nv)
    egjm_rows = (6 * np.arange(4)[:, None] + np.array([0, 1, 5])).ravel()
    block_rows = 6 * context.index + np.array(context.rows)
    out = {}
    for offset in OFFSETS_DEG:
        start = start_angles(offset)
        path = QuinticTrajectory(start, start + np.radians(TASK_DEG) * np.array(DIRECTION), TASK_S)
        angles = np.array([path(t)[0] for t in np.linspace(0.0, PATH_S, samples)])
        conds = []
        for a in angles:
            coords.set(q, a)
            Jstar = gjm.model_of(robot).compute(q, v).Jstar
            conds.append([_condition(Jstar[block_rows][:, list(context.columns)]), _condition(Jstar[egjm_rows])])
        conds = np.array(conds)
        out[offset] = {"on_axes": angles[:, list(context.axis_index)], "cond_block": conds[:, 0],
                       "cond_egjm": conds[:, 1]}
    return out


def _condition(J: np.ndarray) -> float:
    """sigma_max / sigma_min of ``J`` (inf when sigma_min is 0)."""
    sv = np.linalg.svd(J, compute_uv=False)
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf


def figures(context: ArmMap, grid: Grid, result: dict[str, np.ndarray], out: Path) -> list[Path]:
    """``singularities_condition.png`` and ``singularities_manipulability.png`` (free-floating
    beside fixed-base, singular loci dotted), and for the four-arm robot the figs 38-40 paths on
    the condition map."""
    from ..viz.plotting import figure, save

    loci = {"singular J*": result["singular_free"], "singular Jm": result["singular_fixed"]}
    paths: list[Path] = []
    if len(grid.axes) < 2:
        return paths
    marks = figs_38_40(context)
    for key, label, log in (("cond", "condition number", True), ("manipulability", "manipulability", False)):
        fig, axes = figure(1, 2, (12, 5), f"{context.target}: {label} of {context.end_effector}'s Jacobian")
        for ax, side, name in ((axes[0], "free", "free-floating J*"), (axes[1], "fixed", "fixed-base Jm")):
            joint_panel(ax, context, grid, result[f"{key}_{side}"], label, loci, log=log)
            ax.set_title(name)
            for (offset, p), style in zip(marks.items(), ("o", "s", "^")):
                ax.plot(*np.degrees(p["on_axes"][:, :2]).T, style + "-", ms=4, mfc="none", color="#ff7f0e",
                        label=f"figs 38-40 path, {offset:g} deg")
            if marks:
                ax.legend(loc="upper right", fontsize=7, markerscale=1.5)
        paths += save(fig, out, f"singularities_{key}")
    if marks:
        paths += _figs_38_40_figure(context, marks, out)
    return [p for p in paths if p.suffix == ".png"] + [p for p in paths if p.suffix != ".png"]


def _figs_38_40_figure(context: ArmMap, marks: dict[float, dict[str, np.ndarray]], out: Path) -> list[Path]:
    """``singularities_figs38_40.png``: left, cond(J*) of the mapped block on a fine grid of
    :data:`ZOOM_DEG` about the stretched posture with the three paths on it (the map's cells are
    far larger than the paths); right, the condition numbers along the paths over their first
    :data:`PATH_S` s (the dissertation's figs 38-40, its E-GJM rows, beside the mapped block's)."""
    from ..viz.plotting import figure, finish, save

    fig, (left, right) = figure(1, 2, (12, 5), f"{context.target}: figs 38-40 placed on the map")
    values = [context.posture[j] + np.radians(np.linspace(-ZOOM_DEG, ZOOM_DEG, 81)) for j in context.axis_index[:2]]
    local = np.column_stack([v.ravel() for v in np.meshgrid(*values, indexing="ij")]
                            + [np.full(81 * 81, context.posture[j]) for j in context.axis_index[2:]])
    cond = np.log10(evaluate(context, local)["cond_free"].reshape(81, 81))
    image = left.imshow(cond.T, origin="lower", aspect="auto", cmap="viridis",
                        extent=(*np.degrees(values[0][[0, -1]]), *np.degrees(values[1][[0, -1]])),
                        vmin=np.percentile(cond, 1), vmax=np.percentile(cond, 99))
    fig.colorbar(image, ax=left, label="log10 condition number of J*")
    t = np.linspace(0.0, PATH_S, len(next(iter(marks.values()))["cond_egjm"]))
    for (offset, p), style in zip(marks.items(), ("o", "s", "^")):
        left.plot(*np.degrees(p["on_axes"][:, :2]).T, style + "-", ms=4, mfc="none", color="#ff7f0e",
                  label=f"{offset:g} deg")
        right.semilogy(t, p["cond_egjm"], style + "-", ms=3, label=f"E-GJM (12 x 16), {offset:g} deg")
        right.semilogy(t, p["cond_block"], style + ":", ms=3, label=f"mapped J* block, {offset:g} deg")
    left.set_xlabel(f"{context.axes[0]} (deg)")
    left.set_ylabel(f"{context.axes[1]} (deg)")
    left.legend(loc="upper right", fontsize=7, title="start offset", title_fontsize=7)
    finish(right, "time along the path (s)", "condition number", legend="inside")
    return save(fig, out, "singularities_figs38_40")
