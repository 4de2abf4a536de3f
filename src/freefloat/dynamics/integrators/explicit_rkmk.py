"""Fixed-step explicit Runge-Kutta-Munthe-Kaas methods of order 3, 6 and 8, given by their tableaus."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .fixed_step import FixedStep
from .stages import chart_velocity, rkmk_stages

_R21 = np.sqrt(21.0)


class ExplicitRKMK(FixedStep):
    """An explicit RK tableau (``_ROWS``, ``_B``) run in the exponential chart at each step's start.

    The ``dexp^{-1}`` series keeps ``ad`` up to ``order - 2``, at least 4 (see
    :mod:`~freefloat.dynamics.integrators.lie`), which is what the order needs.
    """

    _ROWS: tuple[np.ndarray, ...] = ()
    _B = np.zeros(0)

    def __init__(self, model: pin.Model, substeps: int = 1):
        super().__init__(model, substeps)
        self._dexpinv = chart_velocity(model, degree=max(4, self.order - 2))

    def step(self, at, q, v, h, t):
        K, Acc = rkmk_stages(at, self.model, self._dexpinv, q, v, t, h, self._ROWS, self.nodes)
        self._calls += len(self._ROWS)
        return pin.integrate(self.model, q, h * (self._B @ K)), v + h * (self._B @ Acc)


class RungeKuttaMuntheKaas3(ExplicitRKMK):
    """RKMK3: Kutta's 3-stage 3rd-order method (Hairer, Norsett & Wanner, Solving ODEs I, II.1),
    three evaluations a step: at loose accuracy fewer than RKMK4's four for the same error."""

    name, order = "rkmk3", 3
    _ROWS = tuple(np.array(r) for r in ((), (1 / 2,), (-1.0, 2.0)))
    _B = np.array([1 / 6, 2 / 3, 1 / 6])


class RungeKuttaMuntheKaas6(ExplicitRKMK):
    """RKMK6: Butcher's 7-stage 6th-order method (Hairer, Norsett & Wanner, Solving ODEs I, II.5)."""

    name, order = "rkmk6", 6
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


class RungeKuttaMuntheKaas8(ExplicitRKMK):
    """RKMK8: Cooper and Verner's 11-stage 8th-order method (SIAM J. Numer. Anal. 9, 1972)."""

    name, order = "rkmk8", 8
    _ROWS = tuple(np.array(r) for r in (
        (),
        (1 / 2,),
        (1 / 4, 1 / 4),
        (1 / 7, -(7 + 3 * _R21) / 98, (21 + 5 * _R21) / 49),
        ((11 + _R21) / 84, 0.0, (18 + 4 * _R21) / 63, (21 - _R21) / 252),
        ((5 + _R21) / 48, 0.0, (9 + _R21) / 36, (-231 + 14 * _R21) / 360, (63 - 7 * _R21) / 80),
        ((10 - _R21) / 42, 0.0, (-432 + 92 * _R21) / 315, (633 - 145 * _R21) / 90, (-504 + 115 * _R21) / 70,
         (63 - 13 * _R21) / 35),
        (1 / 14, 0.0, 0.0, 0.0, (14 - 3 * _R21) / 126, (13 - 3 * _R21) / 63, 1 / 9),
        (1 / 32, 0.0, 0.0, 0.0, (91 - 21 * _R21) / 576, 11 / 72, -(385 + 75 * _R21) / 1152, (63 + 13 * _R21) / 128),
        (1 / 14, 0.0, 0.0, 0.0, 1 / 9, -(733 + 147 * _R21) / 2205, (515 + 111 * _R21) / 504, -(51 + 11 * _R21) / 56,
         (132 + 28 * _R21) / 245),
        (0.0, 0.0, 0.0, 0.0, (-42 + 7 * _R21) / 18, (-18 + 28 * _R21) / 45, -(273 + 53 * _R21) / 72,
         (301 + 53 * _R21) / 72, (28 - 28 * _R21) / 45, (49 - 7 * _R21) / 18),
    ))
    _B = np.array([1 / 20, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 49 / 180, 16 / 45, 49 / 180, 1 / 20])
