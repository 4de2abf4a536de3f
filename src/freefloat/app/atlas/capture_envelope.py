"""Atlas kind ``capture_envelope``: where a planned capture scene's target can be grasped within the
limits (issue 21 items 3 and 7).

``freefloat atlas capture_envelope SCENE`` takes a one-hand capture scene with an ``[approach]``
(``capture_planned_planar``, ``capture_planned_satellite`` or a file) and moves the meeting point:
over a plane of ``reach`` offsets (where the grasp point meets the hand at ``target.contact_time``,
from where the hand starts; ``--axes`` two of x, y, z, default x, y; the third held at the scene's
value), each point is planned with the scene's method, limits, mission joints and deadline
(:mod:`freefloat.space.planning`) and checked. The map holds, per point, the outcome (0 graspable,
else the refusal: 1 out of reach, 2 a joint-rate limit, 3 a torque limit, 4 the optimiser found no
path), the plan's base attitude change at the grasp (rad), its grasp position mismatch (m) and its
peak joint rate and torque as fractions of their limits. The plane spans the arm's reach (the sum of
its link lengths) about the hand's start, ``--grid`` points per axis (default 11).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InfeasiblePlan, InvalidArgument, SceneError, spelled
from .grid import Axis, Grid
from .kinds import Options
from .outcome_maps import cell_extent, outcome_panel, write_map

OPTIONS = frozenset({"grid", "axes"})
#: The unit of each summary key that has one (the terminal prints it).
SUMMARY_UNITS = {"contact_time": "s", "held_reach": "m", "farthest_graspable": "m", "attitude_change_max": "rad",
                 "attitude_change_median": "rad"}
#: The outcome codes of the map, by index: graspable, then :data:`InfeasiblePlan.REASONS`.
OUTCOMES = ("graspable", *InfeasiblePlan.REASONS)
COORDINATES = ("x", "y", "z")
#: Points per axis of the default grid.
POINTS = 11
#: Fewest points per chunk (the engine's contract): a point is a whole plan, about 0.3 s, so
#: chunks stay a few seconds long and an interrupt loses no more.
MIN_CHUNK = 4


@dataclass(frozen=True)
class EnvelopeContext:
    """The scene (as named on the command line), the two mapped reach coordinates (indices), the
    held reach (m (3,)) and the half-span of the plane (m)."""

    scene: str
    axes: tuple[int, int]
    reach: tuple[float, float, float]
    span: float


@functools.lru_cache(maxsize=4)
def _setup(scene_name: str):
    """The scene and its setup without its own approach plan (the robot, its start), once per
    process.

    Raises:
        SceneError: for a scene that is not a planned one-hand capture.
    """
    from ..runner import prepare as prepare_scene
    from ..scenes import find_scene

    scene = find_scene(scene_name)
    if getattr(scene, "approach", None) is None or scene.target.second_end_effector:
        raise SceneError(f"atlas capture_envelope: scene '{scene.name}' is not a one-hand capture with an [approach] "
                         "(e.g. capture_planned_planar, capture_planned_satellite)")
    return scene, prepare_scene(dataclasses.replace(scene, approach=None))


def prepare(target: str, options: Options) -> EnvelopeContext:
    """Check the scene (a one-hand capture with an ``[approach]``) and ``--axes``.

    Raises:
        SceneError: for a scene that is not a planned one-hand capture.
        InvalidArgument: for axes that are not two distinct coordinates of x, y, z.
    """
    from ...space.planning.request import arm_reach

    scene, setup = _setup(target)
    names = options.axes or ("x", "y")
    if len(names) != 2 or len(set(names)) != 2 or not set(names) <= set(COORDINATES):
        raise InvalidArgument(f"atlas capture_envelope {target}: {spelled('axes=', '--axes')} must be two distinct coordinates of x, y, z, "
                              f"got {', '.join(names)}")
    return EnvelopeContext(target, tuple(COORDINATES.index(n) for n in names), tuple(scene.approach.reach),
                           arm_reach(setup.robot, setup.q0, scene.target.end_effector)[1])


def grid(context: EnvelopeContext, options: Options) -> Grid:
    """The plane of the two reach coordinates over +- the arm's reach, ``--grid`` points each
    (default :data:`POINTS`, odd so that the hand's start is on it)."""
    n = options.grid or POINTS
    return Grid(tuple(Axis(COORDINATES[i], -context.span, context.span, n, "m") for i in context.axes))


def evaluate(context: EnvelopeContext, points: np.ndarray) -> dict[str, np.ndarray]:
    """Per point (m, 2): ``outcome`` (m,) int (index into :data:`OUTCOMES`), ``attitude_change``,
    ``position_error`` (m), ``rate_fraction``, ``torque_fraction`` (m,) (NaN where no plan came out:
    the optimiser's refusal)."""
    from ...space.planning import GraspMotion, check, planned_path
    from ..experiments.capture import approach_request, scene_target

    scene, setup = _setup(context.scene)
    hand, method = scene.target.end_effector, scene.approach.method
    out = {"outcome": np.zeros(len(points), int), **{key: np.full(len(points), np.nan) for key in
           ("attitude_change", "position_error", "rate_fraction", "torque_fraction")}}
    for k, point in enumerate(points):
        reach = np.array(context.reach)
        reach[list(context.axes)] = point
        target = scene_target(scene, setup, reach)
        request = approach_request(scene, setup, (hand,), (GraspMotion.of(target),))
        try:
            plan = planned_path(request, method)
            out["attitude_change"][k], out["position_error"][k] = plan.attitude_change, plan.position_error
            out["rate_fraction"][k] = float((np.abs(plan.joint_rate) / request.limits.joint_rate).max())
            out["torque_fraction"][k] = float((np.abs(plan.torque) / request.limits.torque).max())
            check(plan, request)
        except InfeasiblePlan as exc:
            out["outcome"][k] = OUTCOMES.index(exc.reason)
    return out


def summarise(context: EnvelopeContext, grid: Grid, result: dict[str, np.ndarray]) -> dict:
    """The scene and method, the count of each outcome, the farthest graspable meeting point from
    the hand's start (m) and the base attitude change over the graspable points (rad)."""
    scene, _ = _setup(context.scene)
    ok = result["outcome"] == 0
    offsets = np.tile(np.array(context.reach), (grid.size, 1))
    offsets[:, list(context.axes)] = grid.points()
    attitude = result["attitude_change"][ok]
    return {"scene": scene.name, "method": scene.approach.method, "contact_time": scene.target.contact_time,
            "held_reach": list(context.reach), "points": grid.size,
            **{name: int((result["outcome"] == i).sum()) for i, name in enumerate(OUTCOMES)},
            "farthest_graspable": float(np.linalg.norm(offsets[ok], axis=1).max()) if ok.any() else None,
            "attitude_change_max": float(attitude.max()) if ok.any() else None,
            "attitude_change_median": float(np.median(attitude)) if ok.any() else None}


def figures(context: EnvelopeContext, grid: Grid, result: dict[str, np.ndarray], out: Path) -> list[Path]:
    """``capture_envelope.png``: the outcome over the plane (graspable, or why not) and the plan's
    base attitude change (log, graspable points), the scene's own meeting point marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a, b = grid.axes
    held = np.array(context.reach)[list(context.axes)]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    outcome_panel(fig, axes[0], grid, result["outcome"], OUTCOMES, ["#2a9d8f", "#e76f51", "#f4a261", "#e9c46a", "#8d99ae"],
                  "outcome of the planned approach")
    graspable = np.where(result["outcome"] == 0, result["attitude_change"], np.nan)
    values = np.ma.masked_invalid(np.log10(np.maximum(graspable, 1e-16)).reshape(grid.shape).T)
    image = axes[1].imshow(values, origin="lower", extent=cell_extent(grid), aspect="equal", cmap="viridis")
    fig.colorbar(image, ax=axes[1], shrink=0.8)
    axes[1].set_title("log10 base attitude change at the grasp (rad)", fontsize=9)
    for ax in axes:
        ax.plot(*held, "k+", markersize=10, label="the scene's meeting point")
        ax.set_xlabel(f"reach {a.name} (m)")
        ax.set_ylabel(f"reach {b.name} (m)")
        ax.legend(fontsize=7, loc="upper right")
    return write_map(fig, f"capture envelope: {context.scene}", out / "capture_envelope.png")
