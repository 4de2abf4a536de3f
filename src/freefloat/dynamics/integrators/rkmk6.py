"""Runge-Kutta-Munthe-Kaas of order 6: Butcher's 7-stage explicit method in the exponential chart."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .fixed_step import FixedStep
from .stages import chart_velocity, rkmk_stages

# Butcher (1964), 7 stages, order 6 (Hairer, Norsett & Wanner, Solving ODEs I, Sec. II.5).
_ROWS = tuple(np.array(r) for r in (
    (),
    (1 / 3,),
    (0.0, 2 / 3),
    (1 / 12, 1 / 3, -1 / 12),
    (-1 / 16, 9 / 8, -3 / 16, -3 / 8),
    (0.0, 9 / 8, -3 / 8, -3 / 4, 1 / 2),
    (9 / 44, -9 / 11, 63 / 44, 18 / 11, 0.0, -16 / 11),
))
_B = np.array([11 / 120, 0.0, 27 / 40, 27 / 40, -4 / 15, -4 / 15, 11 / 120])


class RungeKuttaMuntheKaas6(FixedStep):
    """RKMK6: 7 evaluations per step, 6th order on the group.

    The ``dexp^{-1}`` series of :mod:`~freefloat.dynamics.integrators.lie` stops at ``ad^4``; its
    first omitted term is O(|theta|^6) = O(h^6), a local error O(h^7), so order 6 holds (an RKMK
    method of order p needs the terms up to ``ad^(p-2)``: Hairer, Lubich & Wanner, Sec. IV.8).
    """

    name = "rkmk6"
    order = 6

    def __init__(self, model: pin.Model, substeps: int = 1):
        super().__init__(model, substeps)
        self._dexpinv = chart_velocity(model)

    def step(self, f, q, v, h):
        K, Acc = rkmk_stages(f, self.model, self._dexpinv, q, v, h, _ROWS)
        self._calls += len(_ROWS)
        return pin.integrate(self.model, q, h * (_B @ K)), v + h * (_B @ Acc)
