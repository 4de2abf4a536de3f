"""Atlas kind ``mechanism``: a closed-chain mechanism's workspace, its type I and type II
singularity loci and its working / assembly modes (issue 21 item 5; the thesis proposal's fig. 8
for the 5R), from :mod:`freefloat.parallel.maps`.

``freefloat atlas mechanism five_bar`` (or ``rsu_ppap``) maps, over a grid of platform points
(task space), every working mode: where it exists, the determinants and conditioning of the
inverse (type I) and direct (type II) blocks of the constraint Jacobian. ``--axes`` picks the
grid: two or three platform coordinates (the others held at the built-in scenes' start), or the
actuated joints' names (``c1_joint1 c2_joint1``; ``rsu1_crank rsu2_crank`` with the rail held):
the actuated-joint space, where the assembly modes are mapped instead. The summary names the
mode the built-in scenes run in, counts each mode's points and the loci's (grid edges bisected
onto them, :mod:`freefloat.parallel.maps.loci`), and for the 5R compares the map with the
closed-form workspace. Figures: one panel per mode (the scenes' marked), the mode's region, its
type I and type II points, the scenes' path; for the 5R the exact boundary; a 3-D grid gives
slices, a 3-D scatter of the scenes' mode and its point cloud on a meshcat page.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InvalidArgument, UnknownName, spelled
from .grid import Axis, Grid
from .kinds import Options
from .mechanism_targets import (
    MECHANISMS,
    MechanismMapContext,
    actuated_names,
    labels,
    scene_mode,
    scene_of,
    setup_of,
)

OPTIONS = frozenset({"grid", "axes"})
#: sigma_min / sigma_max of its block above which a bisected locus point is counted as unconfirmed
#: (a mode that ended where Newton failed from every start rather than at a singularity).
UNCONFIRMED = 1e-3


def prepare(target: str, options: Options) -> MechanismMapContext:
    """Check the mechanism name and ``--axes`` (two or three platform coordinates, or two or three
    actuated joints).

    Raises:
        UnknownName: for a mechanism this kind does not map.
        InvalidArgument: for axes that are not 2-3 distinct coordinates of one space.
    """
    if target not in MECHANISMS:
        raise UnknownName("mechanism for the mechanism maps", target, MECHANISMS)
    space = MECHANISMS[target]
    names = tuple(options.axes or space.axes)
    joints = actuated_names(target)
    for kind, pool in (("task", space.coordinates), ("joint", joints)):
        if set(names) <= set(pool) and len(set(names)) == len(names) and 2 <= len(names) <= 3:
            return MechanismMapContext(target, kind, tuple(pool.index(n) for n in names), names)
    raise InvalidArgument(f"atlas mechanism {target}: {spelled('axes=', '--axes')} must be two or three distinct platform coordinates "
                          f"({', '.join(space.coordinates)}) or actuated joints ({', '.join(joints)}), got {', '.join(names)}")


def grid(context: MechanismMapContext, options: Options) -> Grid:
    """The axes over their ranges, ``--grid`` points each (default 61 for the 5R, 31 for the
    2RSU+PPaP)."""
    space = MECHANISMS[context.mechanism]
    n = options.grid or space.points
    if context.space == "task":
        ranges, units = space.ranges, ["m"] * len(space.ranges)
    else:
        from ...parallel.maps.solve import revolute

        mech = setup_of(context.mechanism).nominal
        ranges, units = space.joint_ranges, ["rad" if r else "m" for r in revolute(mech)[mech.actuated]]
    return Grid(tuple(Axis(name, *ranges[i], n, units[i]) for name, i in zip(context.names, context.axes)))


def full_coordinates(context: MechanismMapContext, points: np.ndarray) -> np.ndarray:
    """Grid points (m, d) completed with the held coordinates: platform points (m, p) or actuated
    joints (m, k), held at the scenes' start."""
    mech = setup_of(context.mechanism).nominal
    start, q0, _ = scene_of(context.mechanism)
    held = start if context.space == "task" else q0[mech.actuated]
    full = np.tile(held, (len(points), 1))
    full[:, list(context.axes)] = points
    return full


def held_values(context: MechanismMapContext) -> dict[str, float]:
    """The coordinates not mapped and the value they are held at (the scenes' start)."""
    names = MECHANISMS[context.mechanism].coordinates if context.space == "task" else actuated_names(context.mechanism)
    values = full_coordinates(context, np.zeros((1, len(context.axes))))[0]
    return {name: float(values[i]) for i, name in enumerate(names) if i not in context.axes}


def evaluate(context: MechanismMapContext, points: np.ndarray) -> dict[str, np.ndarray]:
    """Per point (m rows): ``found`` (m, M) whether each mode exists; ``inverse``, ``direct``
    (m, M) the blocks' determinants; ``inverse_ratio``, ``direct_ratio`` (m, M) their
    sigma_min / sigma_max; ``legs`` (m, M, n_legs); ``q`` (m, M, n_q) the solutions."""
    from ...parallel.maps.grids import joint_map, task_map

    mech = setup_of(context.mechanism).nominal
    space = MECHANISMS[context.mechanism]
    full = full_coordinates(context, points)
    if context.space == "task":
        solved = task_map(mech, full, count=space.starts[0])
    else:
        solved = joint_map(mech, full, np.array(space.ranges), count=space.starts[1])
    s = solved.singular
    return {"found": solved.modes.found, "inverse": s.inverse, "direct": s.direct, "inverse_ratio": s.inverse_ratio,
            "direct_ratio": s.direct_ratio, "legs": s.legs, "q": solved.modes.q}


#: The last map's loci, keyed by its context and result (summarise and figures both need them).
_LOCI: dict = {}


def loci_of(context: MechanismMapContext, grid: Grid, result: dict[str, np.ndarray]):
    """The type I and type II loci (bisected grid edges) of the map, ``{kind: Locus}``."""
    key = (context, grid, id(result["found"]))
    if key not in _LOCI:
        _LOCI.clear()
        _LOCI[key] = _bisected(context, grid, result)
    return _LOCI[key]


def _bisected(context: MechanismMapContext, grid: Grid, result: dict[str, np.ndarray]):
    from ...parallel.maps.grids import ModeMap
    from ...parallel.maps.jacobians import Singularity
    from ...parallel.maps.loci import loci
    from ...parallel.maps.modes import Modes

    solved = ModeMap(full_coordinates(context, grid.points()), Modes(labels(context), result["q"], result["found"]),
                     Singularity(*(result[k] for k in ("inverse", "direct", "legs", "inverse_ratio", "direct_ratio"))))
    found = loci(setup_of(context.mechanism).nominal, solved, grid.shape, context.space)
    return {locus.kind: locus for locus in found}


def path_clearance(context: MechanismMapContext, locus) -> float | None:
    """Least distance, m, from the scenes' circular path to the type II points of the scenes'
    working mode (task space, the path in the mapped plane); None otherwise."""
    trajectory = scene_of(context.mechanism)[2]
    on = locus.mode == scene_mode(context)
    if context.space != "task" or trajectory.get("kind") != "circle" or not on.any():
        return None
    plane = list(trajectory.get("axes", [0, 1]))
    if plane != list(context.axes[:2]) or len(context.axes) != 2:
        return None
    offset = locus.coordinates[on][:, plane] - np.asarray(trajectory["center"], float)[plane]
    return float(np.abs(np.linalg.norm(offset, axis=1) - trajectory["radius"]).min())


def summarise(context: MechanismMapContext, grid: Grid, result: dict[str, np.ndarray]) -> dict:
    """The modes (and the scenes'), points per mode, points where any mode exists, the loci's
    points per kind and how singular they are (largest sigma_min / sigma_max of their block, and
    how many exceed :data:`UNCONFIRMED`), the
    area or volume mapped, the scenes' path's clearance from the type II locus of their mode
    (:func:`path_clearance`); for the 5R's task space the closed-form area and the grid points
    that disagree with the closed-form workspace."""
    from ...parallel.maps import five_bar_exact
    from ...parallel.maps.jacobians import closure, partition

    mech = setup_of(context.mechanism).nominal
    part = partition(mech)
    found = result["found"]
    cell = float(np.prod([(a.high - a.low) / max(a.n - 1, 1) for a in grid.axes]))
    loci = loci_of(context, grid, result)
    out = {"mechanism": context.mechanism, "space": context.space, "axes": list(context.names),
           "held": held_values(context), "modes": list(labels(context)),
           "scene_mode": scene_mode(context), "points": grid.size, "any_mode": int(found.any(axis=1).sum()),
           "per_mode": dict(zip(labels(context), found.sum(axis=0).tolist())),
           "measure_any_mode": found.any(axis=1).sum() * cell}
    for kind, locus in loci.items():
        columns = part.joints if kind == "I" else part.unactuated
        ratio = np.linalg.svd(closure(mech, locus.q)[1][..., columns], compute_uv=False) if len(locus.q) else np.ones((0, 1))
        out[f"type_{kind}_points"] = len(locus.q)
        out[f"type_{kind}_ratio_max"] = float((ratio[:, -1] / ratio[:, 0]).max()) if len(locus.q) else None
        out[f"type_{kind}_unconfirmed"] = int((ratio[:, -1] / ratio[:, 0] > UNCONFIRMED).sum())
    clearance = path_clearance(context, loci["II"])
    if clearance is not None:
        out["scene_path_type_II_clearance"] = clearance
    if context.mechanism == "five_bar" and context.space == "task":
        from ...parallel.five_bar import FiveBarParameters

        p = FiveBarParameters()
        out["exact_area"] = five_bar_exact.area(p)
        out["disagree_with_annuli"] = int((found.any(axis=1) != five_bar_exact.contains(p, grid.points())).sum())
        r = np.linalg.norm(loci["I"].coordinates[:, None] - five_bar_exact.bases(p), axis=-1)
        out["type_I_distance_to_circles_max"] = float(np.abs(r[..., None] - np.array(five_bar_exact.radii(p))).reshape(len(r), -1)
                                                      .min(axis=1).max()) if len(r) else None
    return out


def figures(context: MechanismMapContext, grid: Grid, result: dict[str, np.ndarray], out: Path) -> list[Path]:
    """``modes.png``: one panel per mode over a 2-D grid (the mode's region, type I points black,
    type II red, the scenes' start and path, the 5R's exact boundary dashed), the scenes' mode
    named; a 3-D grid: ``slices.png`` (the workspace on three slices of the last axis, with its
    loci near them), ``workspace_3d.png`` (the scenes' mode's points, coloured by the direct
    block's conditioning) and, in task space, ``workspace.html`` (the same points about the
    mechanism at the scenes' start in a self-contained meshcat page)."""
    from . import mechanism_figures

    return mechanism_figures.draw(context, grid, result, loci_of(context, grid, result), out)
