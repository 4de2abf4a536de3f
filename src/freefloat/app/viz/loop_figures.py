"""Figures of a closed loop over a run: the internal (squeeze) force the loop carries and how far
the closure drifts open."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .plotting import curve, figure, finish, log_curve


def loop_figure(t: np.ndarray, squeeze: np.ndarray | None, internal: np.ndarray | None, drift_position: np.ndarray,
                drift_rotation: np.ndarray) -> Figure:
    """Squeeze along grasp 2 -> grasp 1 and the internal force's norm (N; a panel only when given),
    and the closures' largest position (m) and rotation (rad) residuals on a log scale, vs t
    (all (N,))."""
    forces = squeeze is not None
    fig, axes = figure(2 if forces else 1, 1, (9.0, 6.5 if forces else 3.8),
                       "Closed loop through the target" if forces else "Loop closures")
    if forces:
        curve(axes[0], t, squeeze, "squeeze (along grasp 2 -> grasp 1)")
        curve(axes[0], t, internal, "|internal force|")
        finish(axes[0], "t (s)", "force (N)", "internal wrench of the loop")
        low, high = min(0.0, np.nanmin(squeeze, initial=0.0)), max(0.0, np.nanmax(internal, initial=0.0))
        axes[0].set_ylim(1.2 * low - 1.0, 1.2 * high + 1.0)  # from zero: a held squeeze reads as a flat line at its value
        axes[0].ticklabel_format(axis="y", useOffset=False)
    drift_ax = axes[-1]
    log_curve(drift_ax, t, drift_position, "position residual (m)")
    log_curve(drift_ax, t, drift_rotation, "rotation residual (rad)")
    finish(drift_ax, "t (s)", "closure residual", "closure drift")
    return fig
