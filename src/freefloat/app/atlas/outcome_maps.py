"""What the maps of outcomes over a plane share (``capture_envelope``, ``contact_envelope``): the
cells' extent, a panel of named outcomes and the figure written (matplotlib imported by the
caller's ``figures``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .grid import Grid


def cell_extent(grid: Grid) -> tuple[float, float, float, float]:
    """``imshow``'s extent of a two-axis ``grid`` whose points are the cells' centres."""
    a, b = grid.axes
    half = [(axis.high - axis.low) / max(axis.n - 1, 1) / 2 for axis in (a, b)]
    return (a.low - half[0], a.high + half[0], b.low - half[1], b.high + half[1])


def outcome_panel(fig: Any, ax: Any, grid: Grid, outcome: np.ndarray, names: tuple[str, ...], colours: list[str],
                  title: str, aspect: str = "equal") -> None:
    """The outcome codes (grid.size,) (indices into ``names``, one colour each) over the plane,
    with a colour bar naming them."""
    from matplotlib.colors import ListedColormap

    image = ax.imshow(outcome.reshape(grid.shape).T, origin="lower", extent=cell_extent(grid), aspect=aspect,
                      cmap=ListedColormap(colours), vmin=-0.5, vmax=len(names) - 0.5)
    bar = fig.colorbar(image, ax=ax, ticks=range(len(names)), shrink=0.8)
    bar.ax.set_yticklabels(names, fontsize=7)
    ax.set_title(title, fontsize=9)


def write_map(fig: Any, title: str, path: Path) -> list[Path]:
    """Title, lay out and write ``fig`` to ``path`` (PNG, 120 dpi), then close it."""
    import matplotlib.pyplot as plt

    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return [path]
