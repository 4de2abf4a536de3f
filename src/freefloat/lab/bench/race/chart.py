"""The work-precision chart of one bench scene: wall time against the final-state error and
against the scene's second error, log-log, one curve per method."""

from __future__ import annotations

import itertools
from pathlib import Path

from .scene import BenchScene, Method
from .summary import curves
from .sweep import Point

#: Line style per (package, loop) in the charts.
STYLES = {("freefloat", "compiled"): "-o", ("freefloat", "python"): ":o", ("pinocchio", "python"): "-.^",
          ("mujoco", "python"): "--s", ("mujoco", "native"): "-.s"}


def _style(method: Method) -> str:
    """Line style of a method's curve: by package and loop; diamonds for a named plant model."""
    style = STYLES[(method.package, method.loop)]
    return style[:-1] + "d" if method.model else style


def draw_curves(ax, points: list[Point], key: str) -> None:
    """On the matplotlib axes ``ax``, log-log: each method's median wall time (ms) against its
    error ``key``, one curve per method, joined from the coarsest step or tolerance to the finest,
    the error axis reversed (finer to the right)."""
    import matplotlib.pyplot as plt

    for color, (label, curve) in zip(itertools.cycle(plt.get_cmap("tab20").colors), curves(points).items()):
        curve = sorted(curve, key=lambda p: -p.method.setting)
        ax.loglog([p.errors[key] for p in curve], [p.wall_time * 1e3 for p in curve], _style(curve[0].method),
                  color=color, label=label, ms=4)
    ax.invert_xaxis()
    ax.grid(True, which="both", alpha=0.3)


def chart(scene: BenchScene, points: list[Point], path: Path) -> None:
    """Log-log work-precision chart (:func:`draw_curves`): wall time against final-state error
    (left) and against the scene's secondary error (right: momentum, or constraint drift)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 6.5), sharey=True)
    for ax, (key, what) in zip(axes, (("state_error", "final-state error"), scene.secondary)):
        draw_curves(ax, points, key)
        ax.set_xlabel(what)
    axes[0].set_ylabel("wall time per run, ms (median)")
    rows = -(-len(curves(points)) // 3)
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=3, fontsize=7, frameon=False)
    names = {"freefloat": "freefloat", "pinocchio": "a bare Pinocchio loop", "mujoco": "MuJoCo"}
    present = [names[p] for p in names if any(q.method.package == p for q in points)]
    together = f" ({', '.join(present[:-1])} and {present[-1]} in one process)" if len(present) > 1 else ""
    fig.suptitle(f"{scene.name}: work against precision{together}; errors against a tight reference")
    fig.tight_layout(rect=(0.0, 0.03 * rows + 0.02, 1.0, 1.0))
    fig.savefig(path, dpi=120)
    plt.close(fig)
