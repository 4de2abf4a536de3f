"""Atlas kind ``feasibility``: where the worst-case sliding-mode gain design (eqs 154-170) has a
solution over a closed-chain mechanism's uncertainty set (issue 21 item 5).

``freefloat atlas feasibility five_bar`` (or ``rsu_ppap``) maps, over a plane of platform points,
the spectral radius of ``|Delta|_max(x)`` over the parameter box's vertices (eq 161 is solvable at
x iff it is below 1: :mod:`freefloat.parallel.gain_feasibility`) and the critical scale s*(x) of
the stated uncertainties (feasible while s* > 1). The 5R maps its plane (x, y); the 2RSU+PPaP a
plane through its home pose (``--axes``: two of x, y, z; default x, z), the third coordinate held
at home. The uncertainties are the documents' (5R: sec 5.6's six) or the data file's (2RSU+PPaP:
its seven masses, +-15 %).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InvalidArgument, UnknownName, spelled
from .grid import Axis, Grid
from .kinds import Options

OPTIONS = frozenset({"grid", "axes"})


@dataclass(frozen=True)
class MechanismPlane:
    """A mechanism's map: its gain model's builder (module, function), its platform coordinates
    with the range of each (m), the point the unmapped ones are held at, the default axes and
    points per axis."""

    build: Callable
    coordinates: tuple[str, ...]
    ranges: tuple[tuple[float, float], ...]
    held: tuple[float, ...]
    axes: tuple[str, str]
    points: int


def _five_bar():
    from ...parallel.five_bar import FiveBarParameters
    from ...parallel.sliding_mode import FiveBarModel

    return FiveBarModel(FiveBarParameters())


def _rsu_ppap():
    from ...parallel.rsu_ppap import load_data, load_rsu_ppap
    from ...parallel.rsu_ppap_masses import RsuPpapModel

    return RsuPpapModel(load_rsu_ppap().mechanism, load_data())


#: The mechanisms this kind maps, by name (the ``TARGET``).
MECHANISMS = {
    "five_bar": MechanismPlane(_five_bar, ("x", "y"), ((-0.32, 0.32), (0.0, 0.32)), (0.0, 0.0), ("x", "y"), 41),
    "rsu_ppap": MechanismPlane(_rsu_ppap, ("x", "y", "z"), ((-0.3, 0.15), (-0.25, 0.25), (0.15, 0.55)),
                               (0.0, 0.0, 0.40), ("x", "z"), 31),
}


@dataclass(frozen=True)
class FeasibilityContext:
    """The target's name and the two mapped platform coordinates (indices)."""

    mechanism: str
    axes: tuple[int, int]


@functools.cache
def model_of(mechanism: str):
    """The mechanism's gain model, built once per process."""
    return MECHANISMS[mechanism].build()


def prepare(target: str, options: Options) -> FeasibilityContext:
    """Check the mechanism name and ``--axes``.

    Raises:
        UnknownName: for a mechanism this kind does not map.
        InvalidArgument: for axes that are not two distinct platform coordinates.
    """
    if target not in MECHANISMS:
        raise UnknownName("mechanism for the feasibility map", target, MECHANISMS)
    plane = MECHANISMS[target]
    names = options.axes or plane.axes
    if len(names) != 2 or len(set(names)) != 2 or not set(names) <= set(plane.coordinates):
        raise InvalidArgument(f"atlas feasibility {target}: {spelled('axes=', '--axes')} must be two distinct platform coordinates of "
                              f"{', '.join(plane.coordinates)}, got {', '.join(names)}")
    return FeasibilityContext(target, tuple(plane.coordinates.index(n) for n in names))


def grid(context: FeasibilityContext, options: Options) -> Grid:
    """The plane of the two axes over their ranges, ``--grid`` points each (default 41 for the
    5R, 31 for the 2RSU+PPaP)."""
    plane = MECHANISMS[context.mechanism]
    n = options.grid or plane.points
    return Grid(tuple(Axis(plane.coordinates[i], *plane.ranges[i], n, "m") for i in context.axes))


def evaluate(context: FeasibilityContext, points: np.ndarray) -> dict[str, np.ndarray]:
    """``assembled``, ``feasible`` (m,) booleans, ``radius`` and ``scale`` (m,) (NaN where the
    mechanism does not assemble), ``Delta`` (m, p, p) at the plane's points (m, 2)."""
    from ...parallel.gain_feasibility import feasibility

    full = np.tile(np.array(MECHANISMS[context.mechanism].held), (len(points), 1))
    full[:, list(context.axes)] = points
    out = feasibility(model_of(context.mechanism), full)
    return {"assembled": out.assembled, "feasible": out.feasible, "radius": out.radius, "scale": out.scale,
            "Delta": out.Delta}


def summarise(context: FeasibilityContext, grid: Grid, result: dict[str, np.ndarray]) -> dict:
    """Counts (assembled, feasible, singular poses), the spectral radius (finite ones) and critical
    scale over the assembled points, and the radius of a design pooled over every feasible point
    (that design is feasible iff it is below 1)."""
    from ...parallel.gain_feasibility import largest_scale, region_radius

    model = model_of(context.mechanism)
    on = result["assembled"]
    finite = on & np.isfinite(result["radius"])
    return {"mechanism": context.mechanism, "uncertain": dict(zip(model.names, model.uncertainty.tolist())),
            "held": dict(zip(MECHANISMS[context.mechanism].coordinates, MECHANISMS[context.mechanism].held)),
            "points": grid.size, "assembled": int(on.sum()), "feasible": int(result["feasible"].sum()),
            "singular": int((on & np.isinf(result["radius"])).sum()),
            "radius_max": float(result["radius"][finite].max()) if finite.any() else None,
            "radius_min": float(result["radius"][finite].min()) if finite.any() else None,
            "scale_min": float(np.nanmin(result["scale"][on])) if on.any() else None,
            "scale_median": float(np.nanmedian(result["scale"][on])) if on.any() else None,
            "scale_cap": largest_scale(model),
            "pooled_radius": region_radius(result["Delta"], result["feasible"])}


def figures(context: FeasibilityContext, grid: Grid, result: dict[str, np.ndarray], out: Path) -> list[Path]:
    """``feasibility.png``: the spectral radius (contour at 1) and the critical scale (contour at
    1, the stated uncertainty) over the plane, blank where the mechanism does not assemble,
    singular poses crossed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a, b = grid.axes
    extent = (a.low, a.high, b.low, b.high)
    singular = grid.points()[result["assembled"] & np.isinf(result["radius"])]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, key, label in ((axes[0], "radius", "spectral radius of |Delta|_max (eq 161: < 1)"),
                           (axes[1], "scale", "critical scale s* of the uncertainties (feasible: > 1)")):
        values = np.ma.masked_invalid(np.where(np.isinf(result[key]), np.nan, result[key]).reshape(grid.shape).T)
        image = ax.imshow(values, origin="lower", extent=extent, aspect="equal", cmap="viridis")
        if np.ma.count(values) and values.min() < 1.0 < values.max():
            ax.contour(a.values(), b.values(), values.filled(np.nan), levels=[1.0], colors="red")
        if len(singular):
            ax.plot(singular[:, 0], singular[:, 1], "rx", markersize=5, label="singular pose")
            ax.legend(fontsize=7, loc="upper right")
        fig.colorbar(image, ax=ax, shrink=0.8)
        ax.set_title(label, fontsize=9)
        ax.set_xlabel(f"{a.name} (m)")
        ax.set_ylabel(f"{b.name} (m)")
    fig.suptitle(f"gain feasibility of {context.mechanism}")
    fig.tight_layout()
    path = out / "feasibility.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return [path]
