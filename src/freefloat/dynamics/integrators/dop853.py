"""Adaptive Dormand-Prince 8(5,3) (scipy's DOP853, the thesis's integrator) in the Munthe-Kaas
chart at the start of each control period: the chart coordinates ``theta`` (nv,) and the velocity
``v`` obey ``theta' = dexp^-1_{-theta}(v)``, ``v' = f(q exp(theta), v)`` (dexp^-1 to ``ad^6``; a
time-varying ``f`` at scipy's stage times from the call's start).
On Euclidean coordinates (a closed chain) the chart is the identity and this is scipy's DOP853.
Used as a tight reference; not compiled."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...errors import SimulationDiverged
from .base import Acceleration, TimeVarying, at_stage_time
from .stages import chart_velocity


class DormandPrince853:
    """scipy's DOP853 over each :meth:`advance` call, at ``rtol`` and ``atol``.

    Raises (from :meth:`advance`):
        SimulationDiverged: when scipy's solver fails (its message), e.g. a step size underflow.
    """

    name = "dop853"
    order = 8

    def __init__(self, model: pin.Model, rtol: float = 1e-10, atol: float = 1e-12):
        self.model, self.rtol, self.atol = model, rtol, atol
        self._dexpinv = chart_velocity(model, degree=6)
        self._calls = 0

    def evaluations(self) -> int:
        return self._calls

    def advance(self, f: Acceleration | TimeVarying, q: np.ndarray, v: np.ndarray,
                duration: float) -> tuple[np.ndarray, np.ndarray]:
        from scipy.integrate import solve_ivp  # here: scipy.integrate is 0.4 s of every command's start-up

        nv = len(v)
        model, dexpinv, at = self.model, self._dexpinv, at_stage_time(f)

        def rhs(t: float, y: np.ndarray) -> np.ndarray:
            theta, velocity = y[:nv], y[nv:]
            return np.concatenate((dexpinv(theta, velocity), at(t, pin.integrate(model, q, theta), velocity)))

        solution = solve_ivp(rhs, (0.0, duration), np.concatenate((np.zeros(nv), v)), method="DOP853",
                             rtol=self.rtol, atol=self.atol)
        self._calls += solution.nfev
        if not solution.success:
            raise SimulationDiverged(f"DOP853 failed: {solution.message}")
        end = solution.y[:, -1]
        return pin.integrate(model, q, end[:nv]), end[nv:].copy()
