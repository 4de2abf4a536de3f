"""Joint-space reference trajectories."""

from __future__ import annotations

import numpy as np

from ...arguments import real_array, real_number
from ...errors import InvalidArgument


class QuinticTrajectory:
    """Quintic polynomial from ``start`` to ``goal`` in ``duration`` s, zero velocity and
    acceleration at both ends (dissertation sec 4.2.2); holds ``goal`` afterwards.

    .. math:: q(t) = q_0 + (q_1 - q_0)(10 s^3 - 15 s^4 + 6 s^5), \\quad s = t / T.

    Args:
        start: joint positions at t = 0, rad or m (n,).
        goal: joint positions at t = duration (n,).
        duration: T, s (> 0).

    Raises:
        InvalidArgument: for a start or goal that is not finite real numbers of one shape, a
            duration that is not > 0, or one so short that the accelerations overflow.
    """

    def __init__(self, start: np.ndarray, goal: np.ndarray, duration: float):
        self.duration = real_number("duration", duration, above=0.0)
        self.start = real_array("start", start)
        self.delta = real_array("goal", goal, self.start.shape) - self.start
        with np.errstate(all="ignore"):
            overflow = not np.isfinite(self.delta / self.duration**2).all()
        if overflow:
            raise InvalidArgument(f"a trajectory of {duration} s cannot move from start to goal: its accelerations "
                                  "overflow; lengthen it")

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Reference ``(q_d, qdot_d, qddot_d)`` at time t (each (n,))."""
        T = self.duration
        s = min(max(t / T, 0.0), 1.0)
        p = s**3 * (10.0 - 15.0 * s + 6.0 * s**2)
        dp = 30.0 * s**2 * (1.0 - s) ** 2 / T
        ddp = 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / T**2
        return self.start + p * self.delta, dp * self.delta, ddp * self.delta
