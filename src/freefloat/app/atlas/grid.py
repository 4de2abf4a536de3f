"""The grid of an atlas: a tensor product of named axes, its points by flat index (C order over
the axes), its chunks, and the check that a grid's results fit in this machine's memory."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from ...errors import InvalidArgument, spelled

#: Share of the available memory a grid's results may take (the rest for the chunks in flight,
#: the figures and the rest of the machine).
MEMORY_SHARE = 0.5


@dataclass(frozen=True)
class Axis:
    """One axis of a grid: ``n`` evenly spaced values from ``low`` to ``high`` (both included).

    Attributes:
        name: what the axis is (a joint's name, ``"x"``, ...).
        low, high: the ends, in ``unit``.
        n: number of values (>= 1; 1 gives ``low`` alone).
        unit: SI unit of the values (``"rad"``, ``"m"``).
    """

    name: str
    low: float
    high: float
    n: int
    unit: str = "rad"

    def __post_init__(self) -> None:
        if not (isinstance(self.n, (int, np.integer)) and self.n >= 1):
            raise InvalidArgument(f"grid axis '{self.name}': the number of points must be an integer >= 1, "
                                  f"got {self.n!r}")
        if not (np.isfinite(self.low) and np.isfinite(self.high)) or self.high < self.low:
            raise InvalidArgument(f"grid axis '{self.name}': needs finite low <= high, got [{self.low}, {self.high}]")

    def values(self) -> np.ndarray:
        """The axis's values (n,)."""
        return np.linspace(self.low, self.high, self.n) if self.n > 1 else np.array([float(self.low)])


@dataclass(frozen=True)
class Grid:
    """The tensor product of ``axes``; point ``k`` is the ``k``-th in C order (last axis fastest).

    Attributes:
        axes: the axes, in the column order of :meth:`points`.
    """

    axes: tuple[Axis, ...]

    @property
    def shape(self) -> tuple[int, ...]:
        """Points per axis."""
        return tuple(axis.n for axis in self.axes)

    @property
    def size(self) -> int:
        """Number of points (an exact integer: a product past 2^63 does not wrap around)."""
        return math.prod(int(n) for n in self.shape)

    def points(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Points ``start`` to ``stop`` (exclusive; default the last) as rows (m, len(axes))."""
        stop = self.size if stop is None else stop
        index = np.unravel_index(np.arange(start, stop), self.shape)
        return np.column_stack([axis.values()[i] for axis, i in zip(self.axes, index)]) if self.axes \
            else np.zeros((stop - start, 0))

    def chunks(self, size: int) -> list[tuple[int, int]]:
        """``(start, stop)`` of consecutive chunks of at most ``size`` points covering the grid."""
        return [(start, min(start + size, self.size)) for start in range(0, self.size, max(1, size))]

    def describe(self) -> list[dict]:
        """The axes as JSON-able dicts (for the journal and the summary)."""
        return [{"name": a.name, "low": a.low, "high": a.high, "n": a.n, "unit": a.unit} for a in self.axes]


def available_memory() -> int:
    """Bytes of memory available to new allocations (``MemAvailable`` of /proc/meminfo; the
    physical memory where that is not readable)."""
    try:
        with open("/proc/meminfo") as file:
            for line in file:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def check_memory(grid: Grid, bytes_per_point: int, available: int | None = None) -> None:
    """Refuse a grid whose results would take more than :data:`MEMORY_SHARE` of the available memory.

    Raises:
        InvalidArgument: giving the points, the bytes they need and the bytes available.
    """
    available = available_memory() if available is None else available
    need = grid.size * bytes_per_point
    if need > MEMORY_SHARE * available:
        raise InvalidArgument(
            f"grid too large for memory: {' x '.join(map(str, grid.shape))} = {grid.size:,} points at "
            f"{bytes_per_point} bytes each need {need / 2**30:.3g} GiB; {available / 2**30:.3g} GiB are available "
            f"and a map may take {MEMORY_SHARE:.0%}; use a smaller {spelled('grid=', '--grid')}")
