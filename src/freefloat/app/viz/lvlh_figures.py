"""The relative orbit (the ``relative_orbit`` figure): points of a run in orbit (the base CoM, a
capture's target) in the LVLH (Hill) frame of the reference orbit, where Clohessy-Wiltshire
relative motion is read (:mod:`freefloat.space.orbit`)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .plotting import curve, figure, finish, thin

#: The LVLH axes: x radial (out), y along-track, z orbit normal.
AXES = ("x radial", "y along-track", "z normal")


def lvlh_figure(t: np.ndarray, names: list[str], positions: np.ndarray) -> Figure:
    """Each point's LVLH position x (radial), y (along-track), z (normal) vs t, m, one panel an
    axis, and its path in the orbit plane, radial x against along-track y (the usual
    Clohessy-Wiltshire view), o at the start (``positions`` (N, m, 3), m; NaN rows not drawn)."""
    fig, axes = figure(2, 2, (13.0, 7.5), "Relative orbit in the LVLH frame (x radial, y along-track, z normal)")
    for i, (ax, axis) in enumerate(zip(axes[:3], AXES)):
        for k, name in enumerate(names):
            curve(ax, t, positions[:, k, i], name)
        finish(ax, "t (s)", f"{axis.split()[0]} (m)", axis, legend="inside" if i == 0 else None)
    plane = axes[3]
    for k, name in enumerate(names):
        shown = thin(positions[:, k, 1])
        line, = plane.plot(positions[shown, k, 1], positions[shown, k, 0], label=name)
        first = np.flatnonzero(np.isfinite(positions[:, k, 0]))
        if len(first):
            plane.plot(positions[first[0], k, 1], positions[first[0], k, 0], marker="o", color=line.get_color(),
                       linestyle="none", linewidth=line.get_linewidth(), label="_")  # all cycled keys: the cycle stays
    finish(plane, "y along-track (m)", "x radial (m)", "path in the orbit plane, o start")
    return fig
