"""Adaptive Dormand-Prince 5(4) in the Munthe-Kaas chart: error-controlled, 5th order on the group."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...errors import SimulationDiverged
from .base import Acceleration
from .lie import ChartCorrection

# Dormand-Prince 5(4) tableau (Hairer, Norsett & Wanner, Table II.5.2).
_A = (
    (),
    (1 / 5,),
    (3 / 40, 9 / 40),
    (44 / 45, -56 / 15, 32 / 9),
    (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
    (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656),
    (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84),
)
_B = np.array([35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0.0])
_B_LOW = np.array([5179 / 57600, 0.0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])


class DormandPrince45:
    """Adaptive RKMK Dormand-Prince 5(4) with standard step-size control.

    Each step works in the exponential chart at its start point; the error estimate is the
    difference of the 5th- and 4th-order solutions in the chart (theta) and in v, scaled by
    ``atol + rtol * |x|``. The step size carries over between :meth:`advance` calls.

    Args:
        model: Pinocchio model.
        rtol: relative tolerance.
        atol: absolute tolerance.
        max_steps: steps allowed per :meth:`advance` call before giving up.
    """

    name = "dopri5"
    order = 5

    def __init__(self, model: pin.Model, rtol: float = 1e-10, atol: float = 1e-12, max_steps: int = 100_000):
        if not (rtol > 0.0 and atol > 0.0):
            raise ValueError(f"rtol and atol must be > 0, got {rtol}, {atol}")
        self.model, self.rtol, self.atol, self.max_steps = model, rtol, atol, max_steps
        chart = ChartCorrection(model)
        self._dexpinv = chart.apply if chart.needed else (lambda theta, vel: vel)
        self._h: float | None = None
        self._calls = 0
        self.accepted = 0
        self.rejected = 0

    def evaluations(self) -> int:
        return self._calls

    def advance(self, f: Acceleration, q: np.ndarray, v: np.ndarray, duration: float):
        t, h = 0.0, self._h or duration
        for _ in range(self.max_steps):
            if t >= duration * (1.0 - 1e-12):
                return q, v
            h_try = min(h, duration - t)
            q_new, v_new, err = self._attempt(f, q, v, h_try)
            factor = 0.9 * err ** -0.2 if err > 0.0 else 5.0
            if err <= 1.0:
                t, q, v = t + h_try, q_new, v_new
                self.accepted += 1
                h = h_try * min(5.0, max(0.2, factor))
                self._h = h
            else:
                self.rejected += 1
                h = h_try * max(0.1, factor)
        raise SimulationDiverged(
            f"dopri5: {self.max_steps} steps did not cover {duration} s (last step {h:.3g} s)"
        )

    def _attempt(self, f: Acceleration, q: np.ndarray, v: np.ndarray, h: float):
        ks, accs = [], []
        for row in _A:
            theta = h * sum((a * k for a, k in zip(row, ks)), np.zeros_like(v))
            vel = v + h * sum((a * acc for a, acc in zip(row, accs)), np.zeros_like(v))
            accs.append(f(pin.integrate(self.model, q, theta) if ks else q, vel))
            ks.append(self._dexpinv(theta, vel) if ks else vel)
        self._calls += len(_A)
        K, Acc = np.array(ks), np.array(accs)
        theta, v_new = h * (_B @ K), v + h * (_B @ Acc)
        err_theta, err_v = h * ((_B - _B_LOW) @ K), h * ((_B - _B_LOW) @ Acc)
        scale_v = self.atol + self.rtol * np.maximum(np.abs(v), np.abs(v_new))
        scale_theta = self.atol + self.rtol * np.abs(theta)
        err = np.sqrt(np.mean(np.concatenate((err_theta / scale_theta, err_v / scale_v)) ** 2))
        return pin.integrate(self.model, q, theta), v_new, float(err)
