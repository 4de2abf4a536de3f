"""A capture by contact over time: the contact force and the penetration, the latch marked
(``contact`` figure), beside the robot run's own figures."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np


@dataclass(frozen=True)
class ContactFigures:
    """The figure job of a capture by contact: the robot run's ``figures(folder)`` (a
    :class:`~.figure_job.RobotFigures`), then the ``contact`` figure of ``rows`` (a
    :class:`~freefloat.app.experiments.contact_capture.ContactRows`)."""

    figures: Callable[[Path], list[Path]] | None
    rows: Any

    def __call__(self, folder: Path) -> list[Path]:
        """Draw and write the chosen figures into ``folder``; returns the paths."""
        from .plotting import save_all

        paths = self.figures(folder) if self.figures is not None else []
        if len(self.rows.t) >= 2:
            paths += save_all({"contact": lambda: contact_figure(*self.rows)}, folder)
        return paths


def contact_figure(t: np.ndarray, depth: np.ndarray, force: np.ndarray, latch_time: float | None):
    """Contact force (N) and penetration (mm) vs t (s) ((N,) each), a dashed line at the latch."""
    from .plotting import curve, figure, finish

    fig, axes = figure(2, 1, (9.0, 6.0), "Contact between the hand and the target")
    curve(axes[0], t, force, "|f| at the contact point")
    curve(axes[1], t, 1e3 * depth, "penetration depth")
    for ax in axes:
        if latch_time is not None:
            ax.axvline(latch_time, color="k", linestyle="--", linewidth=0.8, label=f"latch at {latch_time:.3f} s")
    finish(axes[0], "t (s)", "contact force (N)", "contact force (Hunt-Crossley and friction)", legend=None)
    finish(axes[1], "t (s)", "penetration (mm)", "penetration depth", legend=None)
    for ax in axes:  # a latch holds the curves at their top right, a rebound's peak is mid-run
        ax.legend(fontsize="small", loc="best")
    return fig
