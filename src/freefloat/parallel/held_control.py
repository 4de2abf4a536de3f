"""A mechanism's closed loop with the control period apart from the integration step.

The plant is integrated by classical RK4 at a fixed step ``h`` on ``q = [q#; q°]``
(Baumgarte-stabilised, eq 129). The control law is either evaluated every ``period`` s (a whole
number of steps) and held in between (zero-order hold, as a digital controller does), or, with
``period`` None, evaluated at every RK4 stage at the stage's time and state ("continuous", the
law as the document's analysis assumes it).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import FreefloatError
from .mechanism import ParallelMechanism, rk4_step
from .sliding_mode import PlatformControl


@dataclass(frozen=True)
class HeldRun:
    """What :func:`track_held` computed (to where the run stopped).

    Attributes:
        t: times of the integration steps, s (N,).
        e: tracking error ``q#_d - q#`` at ``t``, m (N, p).
        s: sliding variable ``-(edot + lambda e)`` at ``t`` (N, p).
        update_t: times the law was evaluated and its efforts held from, s (M,); with a
            continuous law, each step's first stage.
        efforts: the efforts evaluated at ``update_t`` (M, k), N m or N.
        completed: False when the plant came apart or reached a singular pose.
    """

    t: np.ndarray
    e: np.ndarray
    s: np.ndarray
    update_t: np.ndarray
    efforts: np.ndarray
    completed: bool


def steps_per_period(period: float, step: float) -> int:
    """Integration steps in one control period.

    Raises:
        FreefloatError: unless ``period`` is a whole number (>= 1) of ``step``.
    """
    n = round(period / step)
    if n < 1 or abs(n * step - period) > 1e-9 * period:
        raise FreefloatError(f"control period {period} s must be a whole number of integration steps ({step} s)")
    return n


def held_dynamics(plant: ParallelMechanism, u: np.ndarray, baumgarte: float) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """``qddot = f(q, qdot)`` of the plant under the held efforts ``u`` (k,)."""
    return lambda q, qd: plant.forward(q, qd, u, baumgarte)


def continuous_step(plant: ParallelMechanism, control: PlatformControl, q: np.ndarray, qd: np.ndarray, t: float,
                    h: float, baumgarte: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One RK4 step of ``h`` s from time ``t`` with the law evaluated at each stage's time and
    state; returns ``(q, qdot, efforts at the first stage)``."""
    times = iter((t, t + h / 2, t + h / 2, t + h))  # rk4_step evaluates its stages in this order
    stages: list[np.ndarray] = []

    def f(qq: np.ndarray, vv: np.ndarray) -> np.ndarray:
        stages.append(control.efforts(next(times), qq, vv))
        return plant.forward(qq, vv, stages[-1], baumgarte)

    q, qd = rk4_step(f, q, qd, h)
    return q, qd, stages[0]


def track_held(plant: ParallelMechanism, control: PlatformControl, q0: np.ndarray, duration: float, step: float,
               period: float | None, baumgarte: float = 100.0) -> HeldRun:
    """Closed loop from ``q0`` (n_q,) at rest for ``duration`` s: RK4 at ``step`` s, the law held
    over ``period`` s or, for None, evaluated at every RK4 stage.

    Raises:
        FreefloatError: for a period that is not a whole number of steps.
    """
    hold = None if period is None else steps_per_period(period, step)
    n = round(duration / step)
    lam, p = control.lam, plant.p
    q, qd = np.array(q0, float), np.zeros(len(q0))
    t_out, e_out, s_out, update_t, efforts = [], [], [], [], []
    completed = True
    u = np.zeros(len(plant.actuated))
    for k in range(n + 1):
        t = k * step
        q_d, qd_d, _ = control.reference(t)
        e = q_d - q[:p]
        t_out.append(t)
        e_out.append(e)
        s_out.append(-(qd_d - qd[:p] + lam * e))
        if k == n:
            break
        if hold is not None and k % hold == 0:
            u = control.efforts(t, q, qd)
            update_t.append(t)
            efforts.append(u)
        try:
            if hold is None:
                q, qd, u = continuous_step(plant, control, q, qd, t, step, baumgarte)
                update_t.append(t)
                efforts.append(u)
            else:
                q, qd = rk4_step(held_dynamics(plant, u, baumgarte), q, qd, step)
        except (FreefloatError, np.linalg.LinAlgError):
            completed = False
            break
        if not (np.isfinite(q).all() and np.isfinite(qd).all() and np.abs(plant.constraint(q)).max() <= 1.0):
            completed = False
            break
    return HeldRun(np.array(t_out), np.array(e_out), np.array(s_out), np.array(update_t), np.array(efforts), completed)
