"""Redundant actuation: sharing a required platform force among more actuators than platform
coordinates (thesis proposal sec 2's objective; eq 137 assumes none).

Eq 136 asks the actuator efforts ``tau`` (k,) for ``Z^T tau = u*`` with ``Z^T = C^T U`` (p, k)
and ``u* = C^T (M' qddot + v' + g')`` (p,). With k > p and ``Z^T`` of full row rank the solutions
are ``tau = tau_0 + N lambda``, N (k, k - p) spanning the null space of ``Z^T``: efforts along N
load the closed chain without moving it, the internal forces. :class:`EffortDistribution` picks one:

.. math:: \\min_\\tau \\tfrac12 \\sum_i w_i \\tau_i^2 \\quad \\text{s.t.} \\quad Z^T \\tau = u^*,
          \\quad \\tau_{lo} \\le \\tau \\le \\tau_{hi}.

Without limits, ``tau = W^-1 Z (Z^T W^-1 Z)^-1 u*``; with unit weights it is the minimum-norm
solution ``(Z^T)^+ u*``, which has no internal part. With limits it is a strictly convex
quadratic programme: a start within the limits (the efforts past a limit held at it, the rest
solving the equality; where that start leaves the limits, scipy's ``linprog`` (HiGHS) finds one or
proves there is none), then a primal active-set method on the limits ends on the optimum, computed
exactly from its active set (the free efforts solve the equality with the active ones at their
limits), so ``Z^T tau = u*`` holds to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..errors import BadShape, InfeasiblePlan, InvalidArgument

#: Most active-set iterations (each adds or drops one limit; k actuators need at most a few k).
MAX_ITERATIONS = 200


class Distributed(NamedTuple):
    """Efforts sharing one required platform force.

    Attributes:
        efforts: actuator efforts ``tau`` (k,), N m or N, in the mechanism's actuator order.
        internal: their internal part (k,): the projection of ``tau`` on the null space of
            ``Z^T`` (efforts that produce no platform force); zero for the minimum-norm solution.
        at_limit: which efforts sit at a limit (k,) (bool).
    """

    efforts: np.ndarray
    internal: np.ndarray
    at_limit: np.ndarray


@dataclass(frozen=True)
class EffortDistribution:
    """How a required platform force is shared among k >= p actuators.

    Attributes:
        weights: ``w_i`` (k,), positive, of the cost ``sum w_i tau_i^2``; None: all 1 (minimum norm).
        lower, upper: effort limits (k,), N m or N (``-inf``/``inf`` for none); None: unlimited.

    Raises:
        InvalidArgument: for weights that are not positive and finite, or limits with a lower
            above its upper or a NaN.
    """

    weights: np.ndarray | None = None
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.weights is not None and not (np.all(np.isfinite(self.weights)) and np.all(np.asarray(self.weights) > 0.0)):
            raise InvalidArgument(f"effort distribution: weights must be positive and finite, got {self.weights}")
        for name in ("lower", "upper"):
            if getattr(self, name) is not None and np.isnan(getattr(self, name)).any():
                raise InvalidArgument(f"effort distribution: '{name}' has a NaN: {getattr(self, name)}")
        if self.lower is not None and self.upper is not None and np.any(np.asarray(self.lower) > np.asarray(self.upper)):
            raise InvalidArgument(f"effort distribution: a lower limit is above its upper limit (lower {self.lower}, "
                                  f"upper {self.upper})")

    @property
    def limited(self) -> bool:
        """True when some effort has a finite limit."""
        return any(b is not None and np.isfinite(b).any() for b in (self.lower, self.upper))

    def efforts(self, ZT: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Efforts (..., k) for actuation maps ``Z^T`` (..., p, k) and required forces ``u``
        (..., p), any leading batch axes (a closed form without limits, one programme per point
        with them).

        Raises:
            BadShape: for shapes that do not agree; InfeasiblePlan (reason ``"torque"``) where no
                efforts within the limits give ``u``.
        """
        ZT, u = np.asarray(ZT, float), np.asarray(u, float)
        if ZT.shape[:-2] != u.shape[:-1] or ZT.shape[-2] != u.shape[-1] or ZT.shape[-1] < ZT.shape[-2]:
            raise BadShape(f"effort distribution: Z^T {ZT.shape} and u* {u.shape} must be (..., p, k) and (..., p) "
                           "with k >= p")
        if not self.limited:
            Winv_Z = self._inverse_weights(ZT.shape[-1])[:, None] * ZT.swapaxes(-1, -2)
            return (Winv_Z @ np.linalg.solve(ZT @ Winv_Z, u[..., None]))[..., 0]
        flat = [self.solve(z, f).efforts for z, f in zip(ZT.reshape(-1, *ZT.shape[-2:]), u.reshape(-1, u.shape[-1]))]
        return np.array(flat).reshape(u.shape[:-1] + (ZT.shape[-1],))

    def solve(self, ZT: np.ndarray, u: np.ndarray) -> Distributed:
        """The efforts for one point, ``Z^T`` (p, k) and ``u`` (p,), with their internal part.

        Raises:
            InfeasiblePlan: (reason ``"torque"``) when no efforts within the limits give ``u``,
                naming the limits and by how much the nearest efforts within them miss it.
        """
        ZT, u = np.asarray(ZT, float), np.asarray(u, float)
        k = ZT.shape[1]
        lower = np.full(k, -np.inf) if self.lower is None else np.asarray(self.lower, float)
        upper = np.full(k, np.inf) if self.upper is None else np.asarray(self.upper, float)
        if lower.shape != (k,) or upper.shape != (k,) or (self.weights is not None and np.shape(self.weights) != (k,)):
            raise BadShape(f"effort distribution: weights and limits need one entry per actuator ({k})")
        tau = self.efforts(ZT, u) if not self.limited else _active_set(ZT, u, self._inverse_weights(k), lower, upper)
        projector = np.linalg.pinv(ZT) @ ZT
        return Distributed(tau, tau - projector @ tau, (tau <= lower) | (tau >= upper))

    def _inverse_weights(self, k: int) -> np.ndarray:
        return np.ones(k) if self.weights is None else 1.0 / np.asarray(self.weights, float)


def null_space(ZT: np.ndarray) -> np.ndarray:
    """An orthonormal basis (k, k - rank) of the null space of ``Z^T`` (p, k): the directions of
    the internal forces."""
    _, s, Vt = np.linalg.svd(ZT)
    rank = int((s > s.max(initial=0.0) * max(ZT.shape) * np.finfo(float).eps).sum())
    return Vt[rank:].T


def _equality_solution(ZT: np.ndarray, u: np.ndarray, winv: np.ndarray, fixed: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """The minimiser of ``sum w_i tau_i^2`` over the free efforts with ``Z^T tau = u`` and the
    ``fixed`` ones (bool, (k,)) held at their values in ``tau``; minimum weighted norm among the
    solutions (a pseudo-inverse) when the free columns are rank-deficient."""
    free = ~fixed
    out = tau.copy()
    scale = np.sqrt(winv[free])
    rest = u - ZT[:, fixed] @ tau[fixed]
    out[free] = scale * (np.linalg.pinv(ZT[:, free] * scale) @ rest)
    return out


def _active_set(ZT: np.ndarray, u: np.ndarray, winv: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The optimum of the limited programme (module docstring) by a primal active-set method on the
    limits, from a point within them that ``scipy.optimize.linprog`` finds.

    Raises:
        InfeasiblePlan: when there is no point within the limits (linprog's status 2), naming the
            limits and the nearest miss (``scipy.optimize.lsq_linear`` within the limits).
    """
    from scipy.optimize import linprog, lsq_linear  # here: scipy is 0.3 s of start-up

    k = len(winv)
    free_optimum = _equality_solution(ZT, u, winv, np.zeros(k, bool), np.zeros(k))
    if np.all(free_optimum >= lower) and np.all(free_optimum <= upper):
        return free_optimum
    # a start within the limits: the efforts past a limit held at it, the others solving the
    # equality (usually within the limits too); else whatever point linprog finds
    at_lower, at_upper = free_optimum < lower, free_optimum > upper
    tau = _equality_solution(ZT, u, winv, at_lower | at_upper, np.clip(free_optimum, lower, upper))
    tol = 1e-12 * max(1.0, np.abs(tau).max())
    if np.any(tau < lower - tol) or np.any(tau > upper + tol) or np.abs(ZT @ tau - u).max() > tol * np.abs(ZT).max():
        start = linprog(np.zeros(k), A_eq=ZT, b_eq=u, bounds=list(zip(lower, upper)), method="highs")
        if start.status != 0:
            nearest = lsq_linear(ZT, u, bounds=(lower, upper))
            raise InfeasiblePlan(f"effort distribution: no efforts within the limits (lower {lower.tolist()}, upper "
                                 f"{upper.tolist()}) give the platform force u* = {np.round(u, 6).tolist()}; the "
                                 f"nearest within them misses it by {np.linalg.norm(ZT @ nearest.x - u):.3g}", "torque")
        tau = np.clip(start.x, lower, upper)
        tol = 1e-12 * max(1.0, np.abs(tau).max())
        at_lower, at_upper = tau <= lower + tol, tau >= upper - tol
    for _ in range(MAX_ITERATIONS):
        fixed = at_lower | at_upper
        tau = np.where(at_lower, lower, np.where(at_upper, upper, tau))
        target = _equality_solution(ZT, u, winv, fixed, tau)
        step = target - tau
        if np.abs(step).max() <= tol:
            # multipliers: w tau - Z mu = nu with nu >= 0 at a lower limit and <= 0 at an upper one
            mu = np.linalg.lstsq(ZT[:, ~fixed].T, target[~fixed] / winv[~fixed], rcond=None)[0] if (~fixed).any() \
                else np.linalg.lstsq(ZT.T, target / winv, rcond=None)[0]
            nu = target / winv - ZT.T @ mu
            wrong = np.where(at_lower, -nu, np.where(at_upper, nu, 0.0))
            if wrong.max() <= 1e-10 * max(1.0, np.abs(nu).max()):
                return target
            release = int(np.argmax(wrong))
            at_lower[release] = at_upper[release] = False
            tau = target
            continue
        ratios = np.full(k, np.inf)
        down, up = (~fixed) & (step < 0), (~fixed) & (step > 0)
        ratios[down] = (lower[down] - tau[down]) / step[down]
        ratios[up] = (upper[up] - tau[up]) / step[up]
        blocking = int(np.argmin(ratios))
        if ratios[blocking] >= 1.0:
            tau = target
            continue
        tau = tau + ratios[blocking] * step
        at_lower[blocking], at_upper[blocking] = step[blocking] < 0, step[blocking] > 0
    raise InfeasiblePlan(f"effort distribution: the active-set method did not settle in {MAX_ITERATIONS} iterations "
                         f"(limits lower {lower.tolist()}, upper {upper.tolist()}, u* = {np.round(u, 6).tolist()})",
                         "optimiser")
