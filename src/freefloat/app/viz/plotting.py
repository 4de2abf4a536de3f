"""What every run figure shares: an Agg figure with fixed margins, distinguishable curves,
labelled axes, log axes clipped to the data, and writing the figures a run chose (PNG, and PDF
when asked: :func:`choose`).

Figures are not registered with pyplot (nothing stays open). Layout is fixed fractions
(``subplots_adjust``) rather than constrained layout, which doubled the cost of a save.
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
from cycler import cycler
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator, NullLocator

from .rendering import Renderer, in_helper

#: Formats a figure is written in unless a run chose others (:func:`choose`): PNG to look at.
FORMATS = ("png",)
#: What a run chose to draw (:func:`choose`): figure names (None: every one) and formats.
_CHOSEN: contextvars.ContextVar[tuple[frozenset[str] | None, tuple[str, ...]]] = contextvars.ContextVar(
    "figures_chosen", default=(None, FORMATS))
#: A figure to write: drawn already, drawn when called (so that one not chosen costs nothing),
#: or None (not drawn).
Drawing = Figure | Callable[[], Figure | None] | None
#: Curve styles: colour and dash change together, so curves lying on each other stay
#: distinguishable (the first drawn widest, so a later one on top leaves it visible).
STYLES = (cycler(color=["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"])
          + cycler(linestyle=["-", "--", "-.", ":", "-", "--", "-.", ":"])
          + cycler(linewidth=[2.6, 1.8, 1.6, 2.0, 1.2, 1.2, 1.2, 1.2]))
#: Smallest positive value a log axis shows, relative to the largest one plotted.
LOG_RANGE = 1e-8
#: Most samples a curve is drawn with; longer series keep each bucket's extremes
#: (:func:`thin`): a figure is ~1000 px wide, and dense dashed curves dominated the cost.
MAX_POINTS = 1600
#: Most intervals between a linear y axis's labelled ticks.
Y_TICKS = 5


def figure(rows: int, cols: int, size: tuple[float, float], title: str, right: float = 0.97,
           projections: list[str | None] | None = None) -> tuple[Figure, list[Axes]]:
    """A titled figure on an Agg canvas with a flat list of its axes (row-major); ``right`` is
    the axes' right edge as a fraction of the width (less leaves room for outside legends);
    ``projections`` gives each axes' projection (``"3d"`` or None). Panels stacked in one column
    share their time axis, labelled once at the bottom (fewer tick labels to draw)."""
    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    kinds = projections or [None] * (rows * cols)
    axes: list[Axes] = []
    for i, kind in enumerate(kinds):
        shared = axes[0] if cols == 1 and axes and kind is None else None
        axes.append(fig.add_subplot(rows, cols, i + 1, projection=kind, sharex=shared))
    for ax in axes:
        ax.set_prop_cycle(STYLES)
        if ax.name == "rectilinear":  # the default's 7-9 labelled ticks on a short panel: each tick is 5 artists
            ax.yaxis.set_major_locator(MaxNLocator(nbins=Y_TICKS, steps=[1, 2, 2.5, 5, 10]))
        if cols == 1 and ax is not axes[-1]:
            ax.tick_params(labelbottom=False)
    fig.suptitle(title)
    fig.subplots_adjust(left=0.07 if cols > 1 else 0.1, right=right, bottom=0.5 / size[1] + 0.04,
                        top=1.0 - 0.75 / size[1], hspace=0.35 if cols == 1 else 0.55, wspace=0.3)
    return fig, axes


def finish(ax: Axes, xlabel: str, ylabel: str, title: str | None = None, legend: str | None = "inside") -> None:
    """Axis labels (with units), optional title, grid and legend (``"inside"`` upper right,
    ``"outside"`` right of the axes, or None)."""
    if ax.xaxis.get_tick_params().get("labelbottom", True):  # hidden on the upper stacked panels
        ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title is not None:
        ax.set_title(title, fontsize="medium", y=1.0)  # a fixed place: no layout pass over the tick labels
    ax.grid(True, alpha=0.3)
    if legend == "outside":
        ax.legend(fontsize="small", loc="center left", bbox_to_anchor=(1.0, 0.5))
    elif legend == "inside":
        ax.legend(fontsize="small", loc="upper right")


def thin(values: np.ndarray, limit: int = MAX_POINTS) -> np.ndarray:
    """Indices (M,) of the samples of ``values`` (N,) to draw: all of them when N <= limit, else
    the first, the last, and in each of ``limit // 2`` consecutive buckets the smallest and the
    largest value (NaNs ignored), so spikes survive."""
    n = len(values)
    if n <= limit:
        return np.arange(n)
    size = -(-n // (limit // 2))
    padded = np.concatenate([values, np.full(size * (limit // 2) - n, np.nan)]).reshape(-1, size)
    offsets = np.arange(len(padded)) * size
    low = np.where(np.isnan(padded), np.inf, padded).argmin(axis=1) + offsets
    high = np.where(np.isnan(padded), -np.inf, padded).argmax(axis=1) + offsets
    return np.unique(np.concatenate([[0, n - 1], np.minimum(low, n - 1), np.minimum(high, n - 1)]))


def curve(ax: Axes, t: np.ndarray, values: np.ndarray, label: str, **style) -> None:
    """Plot a time series ``values`` (N,) against ``t`` (N,), thinned by :func:`thin`."""
    shown = thin(np.asarray(values, dtype=float))
    ax.plot(t[shown], values[shown], label=label, **style)


def log_curve(ax: Axes, t: np.ndarray, values: np.ndarray, label: str) -> None:
    """Plot ``values`` (N,) on a log axis, leaving out those below ``LOG_RANGE`` times the largest
    (a 0, or a denormal at t = 0, would stretch the axis to 1e-300), and clip the axis to the
    data of all its curves."""
    values = np.asarray(values, dtype=float)
    top = np.nanmax(values, initial=0.0)
    shown = thin(values)
    ax.semilogy(t[shown], np.where(values > LOG_RANGE * top, values, np.nan)[shown], label=label)
    shown = np.concatenate([np.asarray(line.get_ydata(), float) for line in ax.get_lines()])
    shown = shown[np.isfinite(shown) & (shown > 0)]
    if len(shown):
        ax.set_ylim(shown.min() / 2, shown.max() * 2)
    ax.yaxis.set_major_locator(LogLocator(numticks=8))  # at most 8 labelled decades,
    ax.yaxis.set_minor_locator(NullLocator())  # no minor ticks: each tick is an artist to draw
    ax.yaxis.set_major_formatter(FuncFormatter(decade_label))


_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def decade_label(value: float, _position: int | None = None) -> str:
    """A log axis's tick label: ``10`` with the exponent in Unicode superscripts at a power of ten
    (``1e-8`` -> 10⁻⁸), else ``%.3g``. Matplotlib's default writes these in mathtext, whose first
    use built its parser: 0.25 s, a tenth of the default job."""
    if not np.isfinite(value) or value <= 0.0:
        return ""
    exponent = int(np.round(np.log10(value)))
    if abs(value / 10.0**exponent - 1.0) > 1e-9:
        return f"{value:.3g}"
    return f"10{str(exponent).translate(_SUPERSCRIPT)}"


@contextlib.contextmanager
def choose(names: frozenset[str] | None, formats: tuple[str, ...]) -> Iterator[None]:
    """Within: :func:`save_all` draws only the figures named in ``names`` (None: every one) and
    writes each in ``formats`` (of :data:`freefloat.app.figure_set.FORMATS`)."""
    token = _CHOSEN.set((names, tuple(formats)))
    try:
        yield
    finally:
        _CHOSEN.reset(token)


def save_all(figures: dict[str, Drawing], out_dir: Path) -> list[Path]:
    """Draw and write the chosen figures (:func:`choose`) of ``figures`` with :func:`save`, in
    order (None: skipped); returns the paths, in order.

    Rendering is most of the cost (text layout, rasterising), so a helper process
    (:mod:`.rendering`: a new interpreter, not a fork) renders every other figure, from the
    second, while this one draws every figure and renders the rest (a lone figure, or in the
    helper itself: here). A
    figure goes to the helper pickled as it is when sent, so the next one may redraw the same
    Figure (see :class:`~freefloat.app.viz.figures.ArmPanels`); a figure the helper fails on is
    rendered here from that copy."""
    names, formats = _CHOSEN.get()
    helper: Renderer | None = None
    stems: list[str] = []
    for stem, drawing in figures.items():
        if drawing is None or (names is not None and stem not in names):
            continue
        fig = drawing() if callable(drawing) else drawing
        if fig is None:
            continue
        sent = False
        if len(stems) % 2 == 1 and not in_helper():  # every other figure, from the second, to the helper
            helper = helper or Renderer(save)
            sent = helper.send(fig, out_dir.absolute(), stem, formats)  # the helper's working folder may be another
        if not sent:
            save(fig, out_dir, stem, formats)
        stems.append(stem)
    if helper is not None:
        helper.collect()
    return [out_dir / f"{stem}.{fmt}" for stem in stems for fmt in formats]


def save(fig: Figure, out_dir: Path, stem: str, formats: tuple[str, ...] = FORMATS) -> list[Path]:
    """Write ``<stem>.<format>`` for each of ``formats`` (PNG at 120 dpi, zlib level 1: encoding
    was the largest single cost); returns the paths."""
    files = [out_dir / f"{stem}.{fmt}" for fmt in formats]
    for file in files:
        fig.savefig(file, dpi=120, **({"pil_kwargs": {"compress_level": 1}} if file.suffix == ".png" else {}))
    return files


def in_plane(points: np.ndarray) -> bool:
    """Whether points (N, 3) stay in one plane z = const (to 1e-9 of their span)."""
    span = float(np.ptp(points, axis=0).max(initial=0.0))
    return float(np.ptp(points[:, 2])) <= 1e-9 * max(span, 1.0)


def path(ax: Axes, xyz: np.ndarray, label: str, flat: bool) -> None:
    """A path (N, 3) with its start (o) and end (s) marked in the path's colour; its xy
    projection when ``flat``."""
    coords = xyz[:, :2].T if flat else xyz.T
    shown = np.unique(np.r_[np.arange(0, len(xyz), max(1, len(xyz) // MAX_POINTS)), len(xyz) - 1])
    (line,) = ax.plot(*coords[:, shown], label=label)
    for index, marker in ((0, "o"), (-1, "s")):  # every cycled property given: the cycle stays put
        ax.plot(*coords[:, [index]], marker=marker, color=line.get_color(), linestyle="none", linewidth=0, label="_")


def finish_path(ax: Axes, flat: bool, title: str, legend: str = "inside") -> None:
    """Axis labels of a path panel, equal scales, and a title saying which view it is."""
    if flat:
        ax.set_aspect("equal", adjustable="datalim")
        finish(ax, "x (m)", "y (m)", f"{title}; xy-plane (the motion stays in it)", legend=legend)
    else:
        ax.set_zlabel("z (m)")
        limits = np.array([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()])
        centre, half = limits.mean(axis=1), (limits[:, 1] - limits[:, 0]).max() / 2
        ax.set_xlim3d(centre[0] - half, centre[0] + half)
        ax.set_ylim3d(centre[1] - half, centre[1] + half)
        ax.set_zlim3d(centre[2] - half, centre[2] + half)
        ax.set_box_aspect((1.0, 1.0, 1.0))  # equal scales on the three axes
        finish(ax, "x (m)", "y (m)", f"{title}; 3-D", legend=legend)
