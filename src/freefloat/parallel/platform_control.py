"""What a mechanism scene's platform control needs besides the law itself
(:class:`freefloat.parallel.sliding_mode.PlatformControl`: computed torque, eq 190, or sliding
mode, eq 153, for any mechanism with as many actuators as platform coordinates): a circle
reference in chosen platform coordinates and eq 167's gain from printed numbers (eq 187).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .sliding_mode import SlidingModeGains


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


def printed_gains(n: np.ndarray, T: np.ndarray, n_ij: dict[tuple[int, int], np.ndarray]) -> SlidingModeGains:
    """Eq 167's gain from printed numbers (e.g. eq 187): ``n`` (p,), ``T`` (p, p), ``n_ij``
    {(i, j): (p,)} for i >= j. The design's worst cases and eta are unknown for printed gains:
    they are NaN, and no design points."""
    p = len(n)
    return SlidingModeGains(n=np.asarray(n, float), T=np.asarray(T, float),
                            n_ij={k: np.asarray(v, float) for k, v in n_ij.items()}, eta=float("nan"),
                            Delta_max=np.full((p, p), np.nan), delta0_max=np.full(p, np.nan),
                            deltaij_max={}, points=np.empty((0, p)))
