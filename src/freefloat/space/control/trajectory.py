"""Joint-space reference trajectories."""

from __future__ import annotations

import numpy as np


class QuinticTrajectory:
    """Quintic polynomial from ``start`` to ``goal`` in ``duration`` s, zero velocity and
    acceleration at both ends (dissertation sec 4.2.2); holds ``goal`` afterwards.

    .. math:: q(t) = q_0 + (q_1 - q_0)(10 s^3 - 15 s^4 + 6 s^5), \\quad s = t / T.

    Args:
        start: joint positions at t = 0, rad or m (n,).
        goal: joint positions at t = duration (n,).
        duration: T, s (> 0).
    """

    def __init__(self, start: np.ndarray, goal: np.ndarray, duration: float):
        if not duration > 0.0:
            raise ValueError(f"trajectory duration must be > 0, got {duration}")
        self.start = np.asarray(start, dtype=float)
        self.delta = np.asarray(goal, dtype=float) - self.start
        self.duration = float(duration)

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Reference ``(q_d, qdot_d, qddot_d)`` at time t (each (n,))."""
        T = self.duration
        s = min(max(t / T, 0.0), 1.0)
        p = s**3 * (10.0 - 15.0 * s + 6.0 * s**2)
        dp = 30.0 * s**2 * (1.0 - s) ** 2 / T
        ddp = 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / T**2
        return self.start + p * self.delta, dp * self.delta, ddp * self.delta
