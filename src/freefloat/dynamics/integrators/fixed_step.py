"""Fixed-step integrators: semi-implicit Euler and Runge-Kutta 4 on the Lie group."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .base import Acceleration
from .lie import ChartCorrection


class FixedStep:
    """Shared stepping loop: ``substeps`` equal steps per :meth:`advance` call."""

    name = ""
    order = 0

    def __init__(self, model: pin.Model, substeps: int = 1):
        if substeps < 1:
            raise ValueError(f"substeps must be >= 1, got {substeps}")
        self.model = model
        self.substeps = substeps
        self._calls = 0

    def advance(
        self, f: Acceleration, q: np.ndarray, v: np.ndarray, duration: float
    ) -> tuple[np.ndarray, np.ndarray]:
        h = duration / self.substeps
        for _ in range(self.substeps):
            q, v = self.step(f, q, v, h)
        return q, v

    def evaluations(self) -> int:
        return self._calls

    def step(self, f: Acceleration, q: np.ndarray, v: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


class SemiImplicitEuler(FixedStep):
    """Symplectic (semi-implicit) Euler, the dissertation's scheme: ``v+ = v + h a``, ``q+ = q * exp(h v+)``.

    First order.
    """

    name = "euler"
    order = 1

    def step(self, f, q, v, h):
        self._calls += 1
        v_next = v + h * f(q, v)
        return pin.integrate(self.model, q, h * v_next), v_next


class ExplicitEuler(FixedStep):
    """Explicit (forward) Euler: ``q+ = q * exp(h v)``, ``v+ = v + h a``, the old rate moving q.

    First order; kept to show where it fails against the semi-implicit scheme (it gains energy on
    oscillators and opens closed loops).
    """

    name = "explicit_euler"
    order = 1

    def step(self, f, q, v, h):
        self._calls += 1
        return pin.integrate(self.model, q, h * v), v + h * f(q, v)


class RungeKutta4(FixedStep):
    """Classical RK4 in the exponential chart at q: Runge-Kutta-Munthe-Kaas, 4th order on the group.

    Stage configurations are ``q * exp(theta_i)``; the chart velocities are corrected by
    ``dexp^{-1}`` (see :mod:`freefloat.dynamics.integrators.lie`). With ``lie_correction=False`` the stage
    velocities are added uncorrected, the common mistake, which is only 2nd order on SE(3).
    """

    name = "rkmk4"
    order = 4

    def __init__(self, model: pin.Model, substeps: int = 1, lie_correction: bool = True):
        super().__init__(model, substeps)
        chart = ChartCorrection(model)
        self._dexpinv = chart.apply if (lie_correction and chart.needed) else None
        if not lie_correction:
            self.name, self.order = "rk4_naive", 2

    def step(self, f, q, v, h):
        model, dexpinv = self.model, self._dexpinv
        self._calls += 4
        a1 = f(q, v)
        k1 = v
        v2 = v + 0.5 * h * a1
        th2 = 0.5 * h * k1
        a2 = f(pin.integrate(model, q, th2), v2)
        k2 = v2 if dexpinv is None else dexpinv(th2, v2)
        v3 = v + 0.5 * h * a2
        th3 = 0.5 * h * k2
        a3 = f(pin.integrate(model, q, th3), v3)
        k3 = v3 if dexpinv is None else dexpinv(th3, v3)
        v4 = v + h * a3
        th4 = h * k3
        a4 = f(pin.integrate(model, q, th4), v4)
        k4 = v4 if dexpinv is None else dexpinv(th4, v4)
        theta = (h / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
        return pin.integrate(model, q, theta), v + (h / 6.0) * (a1 + 2.0 * (a2 + a3) + a4)
