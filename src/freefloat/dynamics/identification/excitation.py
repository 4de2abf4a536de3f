"""Exciting trajectories: finite Fourier series (Swevers, Ganseman, Tükel, De Schutter and Van
Brussel, IEEE Trans. Robot. Autom. 13(5), 1997) and their optimisation for the condition number
of the regressor they give.

Coordinate ``i`` (of n) follows, with ``omega_f = 2 pi / period`` and H harmonics,

.. math:: q_i(t) = q_{i,0} + \\sum_{l=1}^{H} \\frac{a_{il}}{\\omega_f l} \\sin(\\omega_f l t)
          - \\frac{b_{il}}{\\omega_f l} \\cos(\\omega_f l t),

so ``qdot_i = sum_l a_il cos(omega_f l t) + b_il sin(omega_f l t)``: periodic (a whole period
averages measurement noise out and needs no start or end transient), its derivatives exact. The
displacement and rate are bounded by ``sum_l (|a_il| + |b_il|) / (omega_f l)`` and
``sum_l |a_il| + |b_il|``; :meth:`FourierTrajectory.bounded` scales each coordinate's
coefficients down until both bounds meet the limits.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import scipy.optimize

from ...errors import BadShape, InvalidArgument
from ..threads import single_blas_thread


@dataclass(frozen=True)
class FourierTrajectory:
    """A finite Fourier series per coordinate (module docstring).

    Attributes:
        offset: q_0 (n,), rad or m.
        a, b: coefficients (n, H), rad/s or m/s.
        period: of the fundamental, s.
    """

    offset: np.ndarray
    a: np.ndarray
    b: np.ndarray
    period: float

    def __post_init__(self) -> None:
        n = len(np.atleast_1d(self.offset))
        if np.shape(self.a) != np.shape(self.b) or np.ndim(self.a) != 2 or np.shape(self.a)[0] != n:
            raise BadShape(f"Fourier trajectory: a {np.shape(self.a)} and b {np.shape(self.b)} must both be "
                           f"(n, H) with n = {n} offsets")
        if not self.period > 0.0:
            raise InvalidArgument(f"Fourier trajectory: the period must be > 0 s, got {self.period}")

    @property
    def harmonics(self) -> np.ndarray:
        """``omega_f l`` for l = 1..H (H,), rad/s."""
        return 2.0 * np.pi / self.period * np.arange(1, np.shape(self.a)[1] + 1)

    def __call__(self, t: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, qdot, qddot)`` at times t (N,) (each (N, n)), or at one time (each (n,))."""
        w = self.harmonics
        phase = np.multiply.outer(np.asarray(t, float), w)          # (..., H)
        s, c = np.sin(phase), np.cos(phase)
        q = np.asarray(self.offset, float) + s @ (self.a / w).T - c @ (self.b / w).T
        return q, c @ self.a.T + s @ self.b.T, (s @ (-self.a * w).T) + c @ (self.b * w).T

    def displacement_bound(self) -> np.ndarray:
        """Largest ``|q_i - q_i0|`` any time can reach (n,) (module docstring)."""
        return (np.abs(self.a) + np.abs(self.b)) @ (1.0 / self.harmonics)

    def rate_bound(self) -> np.ndarray:
        """Largest ``|qdot_i|`` any time can reach (n,)."""
        return (np.abs(self.a) + np.abs(self.b)).sum(axis=1)

    def bounded(self, displacement: np.ndarray | float, rate: np.ndarray | float) -> FourierTrajectory:
        """The same series with each coordinate's coefficients scaled down (never up) until its
        displacement and rate bounds are within ``displacement`` and ``rate`` ((n,) or scalars)."""
        with np.errstate(divide="ignore"):
            scale = np.minimum(1.0, np.minimum(np.asarray(displacement, float) / self.displacement_bound(),
                                               np.asarray(rate, float) / self.rate_bound()))
        scale = np.where(np.isfinite(scale), scale, 1.0)[:, None]
        return replace(self, a=self.a * scale, b=self.b * scale)

    def sample(self, samples: int) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """``(t, (q, qdot, qddot))``: ``samples`` times evenly over one period (end excluded)."""
        t = np.arange(samples) * self.period / samples
        return t, self(t)


def random_trajectory(offset: np.ndarray, harmonics: int, period: float, displacement: np.ndarray | float,
                      rate: np.ndarray | float, rng: np.random.Generator) -> FourierTrajectory:
    """Normal coefficients from ``rng``, scaled within the bounds (:meth:`FourierTrajectory.bounded`)
    and then up to them where both allow."""
    n = len(np.atleast_1d(offset))
    a, b = rng.normal(size=(n, harmonics)), rng.normal(size=(n, harmonics))
    raw = FourierTrajectory(np.asarray(offset, float), 1e3 * a, 1e3 * b, period)
    return raw.bounded(displacement, rate)


@single_blas_thread
def optimise(start: FourierTrajectory, cost: Callable[[FourierTrajectory], float], displacement: np.ndarray | float,
             rate: np.ndarray | float, iterations: int = 40) -> tuple[FourierTrajectory, float]:
    """Coefficients that lower ``cost`` (typically the condition number of the base regressor
    along the trajectory) from ``start``, within the bounds: L-BFGS (finite-difference gradients,
    at most ``iterations`` iterations) on the coefficients, each candidate bounded by
    :meth:`FourierTrajectory.bounded` before it is costed. A local search: it returns
    the best point it evaluated, never worse than the start.

    Returns:
        ``(trajectory, cost)``.
    """
    shape = start.a.shape
    best = [start.bounded(displacement, rate), float("inf")]
    best[1] = cost(best[0])

    def candidate(x: np.ndarray) -> FourierTrajectory:
        return replace(start, a=x[: x.size // 2].reshape(shape), b=x[x.size // 2:].reshape(shape)).bounded(
            displacement, rate)

    def objective(x: np.ndarray) -> float:
        trajectory = candidate(x)
        value = cost(trajectory)
        if value < best[1]:
            best[:] = [trajectory, value]
        return np.log(value) if np.isfinite(value) and value > 0 else 1e3

    x0 = np.concatenate((best[0].a.ravel(), best[0].b.ravel()))
    scipy.optimize.minimize(objective, x0, method="L-BFGS-B", options={"maxiter": iterations})
    return best[0], best[1]
