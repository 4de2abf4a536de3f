"""Control of a closed-chain mechanism in its platform coordinates q# (thesis proposal secs 5.5-5.6),
for any :class:`~freefloat.parallel.mechanism.ParallelMechanism` with as many actuators as
platform coordinates.

On the nominal model's ``H qddot# + v_M + g_M = B tau`` (eq 137, ``B = C^T U``, from
:func:`~freefloat.parallel.platform.platform_dynamics` at the measured state), with
``e = q#_d - q#`` and ``s = -(edot + lambda e)``:

.. math::
    \\text{computed torque (eq 190):}\\quad B\\tau = v_M + g_M + H(\\ddot q_d + 2\\lambda\\dot e + \\lambda^2 e)

    \\text{sliding mode (eq 153):}\\quad B\\tau = v_M + g_M + H(\\sigma - k(\\sigma, \\dot q^\\#) f(s)),
    \\quad \\sigma = \\ddot q_d + \\lambda \\dot e,

``f = tanh(100 s)`` or ``sign(s)``, ``k`` eq 167's gain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..parallel.mechanism import ParallelMechanism
from ..parallel.platform import platform_dynamics
from ..parallel.sliding_mode import Reference, SlidingModeGains


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


@dataclass(frozen=True)
class PlatformControl:
    """Computed torque (``gains`` None) or sliding mode on a nominal model.

    Attributes:
        model: the mechanism the controller believes (its p platform coordinates lead q).
        reference: ``t -> (q#_d, qdot#_d, qddot#_d)``, each (p,).
        lam: lambda, 1/s.
        gains: eq 167's gains; None means computed torque (eq 190).
        saturation: ``"tanh"`` (``tanh(100 s)``) or ``"sign"``.
    """

    model: ParallelMechanism
    reference: Reference
    lam: float
    gains: SlidingModeGains | None = None
    saturation: str = "tanh"

    def efforts(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Actuator efforts (k,), N m or N, for the measured coordinates q and rates qd (n_q,)."""
        p, lam = self.model.p, self.lam
        q_d, qd_d, qdd_d = self.reference(t)
        e, edot = q_d - q[:p], qd_d - qd[:p]
        H, v, g, B = platform_dynamics(self.model, q, qd[:p])
        if self.gains is None:
            acceleration = qdd_d + 2.0 * lam * edot + lam**2 * e
        else:
            s = -(edot + lam * e)
            sigma = qdd_d + lam * edot
            switch = np.sign(s) if self.saturation == "sign" else np.tanh(100.0 * s)
            acceleration = sigma - self.gains.k(sigma, qd[:p]) * switch
        return np.linalg.solve(B, v + g + H @ acceleration)
