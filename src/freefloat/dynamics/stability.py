"""The largest stable step of a simulation, found by bisection on the step.

``stable(h) -> bool`` says whether a run with step ``h`` (s) is stable; whatever it means by that
(the run completes, a drift stays below a bound) is the caller's definition. The search assumes
one boundary in ``[low, high]``: steps below it stable, steps above it not. It bisects
geometrically (the midpoint of ``lo`` and ``hi`` is ``sqrt(lo hi)``) until ``hi / lo - 1 <=
rtol``, and checks ``low`` or ``high`` only when no step tried was stable, or none unstable.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from ..errors import InvalidArgument

__all__ = ["StabilityLimit", "largest_stable_step"]


@dataclass(frozen=True)
class StabilityLimit:
    """Where the search ended.

    Attributes:
        stable: largest step found stable, s; None when even ``low`` is unstable.
        unstable: smallest step found unstable, s; None when even ``high`` is stable.
        evaluations: calls of ``stable``.
    """

    stable: float | None
    unstable: float | None
    evaluations: int

    @property
    def bracketed(self) -> bool:
        """True when both a stable and an unstable step were found."""
        return self.stable is not None and self.unstable is not None


def largest_stable_step(stable: Callable[[float], bool], low: float, high: float, rtol: float = 0.02) -> StabilityLimit:
    """Bisect ``[low, high]`` (s) for the boundary between stable and unstable steps.

    Returns:
        The bracket ``stable < boundary <= unstable`` with ``unstable / stable - 1 <= rtol``, or an
        open bracket when every step tried (down to ``low``, up to ``high``) went one way.

    Raises:
        InvalidArgument: unless ``0 < low < high`` are finite and ``0 < rtol``.
    """
    if not (math.isfinite(low) and math.isfinite(high) and 0.0 < low < high):
        raise InvalidArgument(f"stability search: need finite 0 < low < high, got low = {low}, high = {high}")
    if not rtol > 0.0:
        raise InvalidArgument(f"stability search: rtol must be > 0, got {rtol}")
    lo, hi, calls = low, high, 0
    found_stable: float | None = None
    found_unstable: float | None = None
    while hi / lo - 1.0 > rtol:
        h = math.sqrt(lo * hi)
        calls += 1
        if stable(h):
            lo = found_stable = h
        else:
            hi = found_unstable = h
    if found_stable is None:
        calls += 1
        found_stable = low if stable(low) else None
        if found_stable is None:
            found_unstable = low
    if found_unstable is None:
        calls += 1
        found_unstable = None if stable(high) else high
        if found_unstable is None:
            found_stable = high
    return StabilityLimit(found_stable, found_unstable, calls)
