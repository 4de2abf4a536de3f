"""The stages of one explicit Runge-Kutta-Munthe-Kaas step, in the exponential chart at q."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin

from .base import StageAcceleration, Velocity
from .lie import ChartCorrection

#: ``dexp^{-1}_{-theta}(velocity)`` (nv,) from theta (nv,) and a local velocity (nv,).
ChartVelocity = Callable[[np.ndarray, np.ndarray], np.ndarray]


def chart_velocity(model: pin.Model, degree: int = 4) -> ChartVelocity:
    """The model's ``dexp^{-1}_{-theta}`` to ``ad^degree``, or the identity when every joint commutes."""
    chart = ChartCorrection(model, degree)
    return chart.apply if chart.needed else (lambda theta, velocity: velocity)


def rkmk_stages(
    at: StageAcceleration,
    model: pin.Model,
    dexpinv: ChartVelocity,
    q: np.ndarray,
    v: np.ndarray,
    t: float,
    h: float,
    rows: Sequence[np.ndarray],
    nodes: Sequence[float],
    a0: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Chart velocities ``K`` and accelerations ``Acc`` (both (s, nv)) of an s-stage explicit tableau.

    Stage i sits at ``q * exp(theta_i)``, ``theta_i = h sum_j rows[i][j] K[j]`` (local frame of q),
    with velocity ``v_i = v + h sum_j rows[i][j] Acc[j]``, at time ``t + nodes[i] h``
    (``nodes[i] = sum_j rows[i][j]``); ``K[i] = dexp^{-1}_{-theta_i}(v_i)`` and
    ``Acc[i] = at(t + nodes[i] h, q * exp(theta_i), v_i)``. ``rows[0]`` is empty; ``a0`` is
    ``at(t, q, v)`` when already known (first stage same as the last of the previous step), so
    that it costs no call.
    """
    nv = v.size
    KA = np.empty((len(rows), 2 * nv))  # [K | Acc], one product per stage for both
    KA[0, :nv] = v
    KA[0, nv:] = at(t, q, v) if a0 is None else a0
    for i in range(1, len(rows)):
        increment = h * (rows[i] @ KA[:i])
        theta, vel = increment[:nv], v + increment[nv:]
        KA[i, :nv] = dexpinv(theta, vel)
        KA[i, nv:] = at(t + nodes[i] * h, pin.integrate(model, q, theta), vel)
    return KA[:, :nv], KA[:, nv:]


def rkmk_flow_step(
    velocity: Velocity,
    model: pin.Model,
    dexpinv: ChartVelocity,
    q: np.ndarray,
    t: float,
    h: float,
    rows: Sequence[np.ndarray],
    weights: np.ndarray,
    nodes: Sequence[float],
    v0: np.ndarray | None = None,
) -> np.ndarray:
    """One step of an s-stage explicit tableau for the first-order system ``q' = velocity(t, q)``
    (Munthe-Kaas's RKMK, of which :func:`rkmk_stages` is the second-order form): the
    configuration (nq,) at ``t + h``.

    Stage i sits at ``q * exp(theta_i)``, ``theta_i = h sum_j rows[i][j] K[j]``, at time
    ``t + nodes[i] h`` (``nodes[i] = sum_j rows[i][j]``); ``K[i] = dexp^{-1}_{-theta_i}(velocity(
    t + nodes[i] h, q * exp(theta_i)))``; the step ends at ``q * exp(h sum_i weights[i] K[i])``.
    ``v0`` is ``velocity(t, q)`` when already known, so that it costs no call.
    """
    K = np.empty((len(rows), model.nv))
    K[0] = velocity(t, q) if v0 is None else v0
    for i in range(1, len(rows)):
        theta = h * (rows[i] @ K[:i])
        K[i] = dexpinv(theta, velocity(t + h * nodes[i], pin.integrate(model, q, theta)))
    return pin.integrate(model, q, h * (weights @ K))
