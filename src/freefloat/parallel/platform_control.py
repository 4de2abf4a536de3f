"""The platform reference of a mechanism scene's control
(:class:`freefloat.parallel.sliding_mode.PlatformControl`): a circle in chosen platform
coordinates, which the compiled loop also evaluates (``cpp/sim/chain_loop.hpp``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CircleReference:
    """``q#_d(t) = center + radius (cos(rate t) e_a + sin(rate t) e_b)``, ``(a, b) = axes``;
    the other platform coordinates held at ``center`` (p,). Units of q# (m or rad), rad/s."""

    center: np.ndarray
    radius: float
    rate: float
    axes: tuple[int, int] = (0, 1)

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q#_d, qdot#_d, qddot#_d)`` at ``t`` s, each (p,)."""
        c, s = np.cos(self.rate * t), np.sin(self.rate * t)
        r, w = self.radius, self.rate
        q, qd, qdd = np.array(self.center, float), np.zeros(len(self.center)), np.zeros(len(self.center))
        q[list(self.axes)] += r * c, r * s
        qd[list(self.axes)] = -r * w * s, r * w * c
        qdd[list(self.axes)] = -r * w * w * c, -r * w * w * s
        return q, qd, qdd
