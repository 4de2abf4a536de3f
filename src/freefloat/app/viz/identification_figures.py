"""The captured target identified: each of its ten inertial parameters as estimated, with its
95 % interval, beside the true value (``identification`` figure), beside the robot run's own
figures."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: The summary's rows of each parameter, in the order of :class:`IdentifiedParameters`' tuples.
ROWS = ("estimate", "half_width", "true")
#: The inertia's six components as drawn: (row, column) of the 3 x 3 matrix and the label.
INERTIA_COMPONENTS = (((0, 0), "xx"), ((1, 1), "yy"), ((2, 2), "zz"), ((0, 1), "xy"), ((0, 2), "xz"), ((1, 2), "yz"))


@dataclass(frozen=True)
class IdentifiedParameters:
    """The target's parameters from a capture_identification summary: mass (kg), CoM in the
    end-effector frame (m, (3,)) and inertia about the CoM (kg m^2, (3, 3)); each as
    ``estimate``, 95 % ``half_width`` and ``true`` rows, in that order of the tuples."""

    mass: tuple[float, float, float]
    com: tuple[np.ndarray, np.ndarray, np.ndarray]
    inertia: tuple[np.ndarray, np.ndarray, np.ndarray]

    @classmethod
    def of(cls, summary: dict) -> IdentifiedParameters:
        """From the summary keys of :func:`~freefloat.app.experiments.capture_identification.identification_summary`."""
        return cls(tuple(float(summary[f"target_mass_{k}"]) for k in ROWS),
                   tuple(np.asarray(summary[f"target_com_{k}"], dtype=float) for k in ROWS),
                   tuple(np.asarray(summary[f"target_inertia_{k}"], dtype=float) for k in ROWS))


@dataclass(frozen=True)
class IdentificationFigures:
    """The figure job of a capture with identification: the robot run's ``figures(folder)`` (a
    :class:`~.figure_job.RobotFigures`), then the ``identification`` figure of ``parameters``."""

    figures: Callable[[Path], list[Path]] | None
    parameters: IdentifiedParameters

    def __call__(self, folder: Path) -> list[Path]:
        """Draw and write the chosen figures into ``folder``; returns the paths."""
        from .plotting import save_all

        paths = self.figures(folder) if self.figures is not None else []
        return paths + save_all({"identification": lambda: identification_figure(self.parameters)}, folder)


def identification_figure(parameters: IdentifiedParameters):
    """Three panels: mass (kg), CoM (mm, end-effector frame) and inertia about the CoM (kg m^2):
    each estimate's error (estimate minus true) with its 95 % interval as an error bar, so that
    the true value, zero, lies inside the bar where the interval holds it; the true values in the
    tick labels."""
    from .plotting import figure

    inertia = [np.array([m[i, j] for (i, j), _ in INERTIA_COMPONENTS]) for m in parameters.inertia]
    panels = (("mass", ["m"], [np.array([v]) for v in parameters.mass], 1.0, "kg", 3),
              ("centre of mass", ["x", "y", "z"], list(parameters.com), 1e3, "mm", 1),
              ("inertia about the CoM", [label for _, label in INERTIA_COMPONENTS], inertia, 1.0, "kg m^2", 3))
    fig, axes = figure(1, 3, (11.0, 4.2), "The captured target identified: estimate minus true, 95 % intervals")
    for ax, (title, labels, (estimate, half, true), scale, unit, decimals) in zip(axes, panels):
        x = np.arange(len(labels))
        ax.axhline(0.0, color="tab:red", linewidth=1.0, label="true")
        ax.errorbar(x, scale * (estimate - true), yerr=scale * half, fmt="o", capsize=4,
                    label="estimate, 95 % interval")
        ax.set_xticks(x, [f"{label}\n({round(scale * t, decimals) + 0.0:g})" for label, t in zip(labels, true)])
        ax.set_xlim(-0.6, len(labels) - 0.4)
        ax.set_ylabel(f"estimate - true ({unit})")
        ax.set_title(f"{title} (true value, {unit})", fontsize="medium")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize="small", loc="upper right")
    return fig
