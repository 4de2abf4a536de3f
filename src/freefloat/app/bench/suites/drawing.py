"""What the suites' charts share: a figure on the Agg backend, its saving, the axes of a size sweep."""

from __future__ import annotations

from pathlib import Path


def subplots(rows: int, columns: int, size: tuple[float, float], **options):
    """``(figure, axes)`` of ``rows`` x ``columns`` panels, ``size`` in inches, drawn off screen."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(rows, columns, figsize=size, **options)


def save(fig, path: Path) -> None:
    """Lay out, write (120 dpi) and close a figure of :func:`subplots`."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def mark_smoke(path: Path) -> None:
    """Write :data:`~..options.SMOKE` in a band above the chart at ``path`` (a PNG), so that a
    ``--quick`` chart is not read as a measurement."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..options import SMOKE

    image = plt.imread(path)
    height, width = image.shape[:2]
    band = 28  # pixels
    fig = plt.figure(figsize=(width / 120, (height + band) / 120), dpi=120, facecolor="firebrick")
    fig.figimage(image)
    fig.text(0.5, 1.0 - 0.5 * band / (height + band), SMOKE, ha="center", va="center", color="white", fontsize=9,
             weight="bold")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def growth_axes(ax, ylabel: str) -> None:
    """Finish an axis of a size sweep (:mod:`.robots`): joints on a log2 scale, ``ylabel``, title
    and legend."""
    ax.set_xscale("log", base=2)
    ax.set_xlabel("joints (spatial 4-link arms around one base)")
    ax.set_ylabel(ylabel)
    ax.set_title("growth with robot size")
    ax.legend(fontsize=8)
