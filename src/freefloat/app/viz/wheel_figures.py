"""The reaction wheels over a run: each wheel's stored momentum against its limit, and its torque
against the motor's limit."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .plotting import curve, figure, finish


def wheel_figure(t: np.ndarray, names: list[str], momenta: np.ndarray, max_momenta: np.ndarray, torques: np.ndarray,
                 max_torques: np.ndarray) -> Figure:
    """Stored momentum ``I Omega`` (N m s) and torque (N m) of each wheel vs t, both with their limits
    as dashed lines (``momenta``, ``torques`` (N, nw); limits (nw,))."""
    fig, axes = figure(2, 1, (9.0, 6.5), "Reaction wheels")
    for i, name in enumerate(names):
        curve(axes[0], t, momenta[:, i], name)
        curve(axes[1], t, torques[:, i], name)
        for ax, limit in ((axes[0], max_momenta[i]), (axes[1], max_torques[i])):
            color = ax.lines[-1].get_color()
            ax.axhline(limit, color=color, linestyle="--", linewidth=0.8)
            ax.axhline(-limit, color=color, linestyle="--", linewidth=0.8)
    finish(axes[0], "t (s)", "stored momentum I Omega (N m s)", "wheel momentum and its limit (dashed)")
    finish(axes[1], "t (s)", "torque (N m)", "wheel torque and its limit (dashed)")
    return fig
