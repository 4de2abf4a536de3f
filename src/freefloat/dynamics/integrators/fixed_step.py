"""Fixed-step integrators: semi-implicit Euler and Runge-Kutta 4 on the Lie group, each stage
evaluated at its own time ``t + c_i h``; each also steps a first-order system ``q' = V(t, q)``
with its tableau (:meth:`FixedStep.flow`)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .base import Acceleration, StageAcceleration, TimeVarying, Velocity, at_stage_time
from .lie import ChartCorrection
from .stages import rkmk_flow_step

#: The one-stage tableau (Euler's): rows and weights.
_EULER_ROWS, _EULER_B = (np.zeros(0),), np.ones(1)


class FixedStep:
    """Shared stepping loop: ``substeps`` equal steps per :meth:`advance` call, step k from time
    ``k h`` of the call (a :class:`~.base.TimeVarying` acceleration sees it); its tableau
    (``_ROWS``, ``_B``) also steps first-order systems (:meth:`flow`)."""

    name = ""
    order = 0
    _ROWS: tuple[np.ndarray, ...] = _EULER_ROWS
    _B = _EULER_B
    _dexpinv = None  # dexp^-1_{-theta}(velocity) of the chart, None where every joint commutes

    def __init__(self, model: pin.Model, substeps: int = 1):
        if substeps < 1:
            raise ValueError(f"substeps must be >= 1, got {substeps}")
        self.model = model
        self.substeps = substeps
        self._calls = 0
        #: The stage times of one step as fractions of it, ``c_i`` (:meth:`step` asks the
        #: acceleration, :meth:`flow` the velocity, at ``t + c_i h``).
        self.nodes = tuple(float(row.sum()) for row in self._ROWS)

    def advance(
        self, f: Acceleration | TimeVarying, q: np.ndarray, v: np.ndarray, duration: float
    ) -> tuple[np.ndarray, np.ndarray]:
        h, at = duration / self.substeps, at_stage_time(f)
        for k in range(self.substeps):
            q, v = self.step(at, q, v, h, k * h)
        return q, v

    def evaluations(self) -> int:
        return self._calls

    def step(self, at: StageAcceleration, q: np.ndarray, v: np.ndarray, h: float,
             t: float) -> tuple[np.ndarray, np.ndarray]:
        """``(q, v)`` one step of ``h`` s after the state ``(q, v)`` at time ``t`` s (of the
        :meth:`advance` call), the accelerations ``at(t + c_i h, q_i, v_i)`` of its stages."""
        raise NotImplementedError

    def flow(self, velocity: Velocity, q: np.ndarray, t: float, duration: float,
             v: np.ndarray | None = None) -> np.ndarray:
        """The configuration (nq,) after ``duration`` s of the first-order system
        ``q' = velocity(t, q)`` from ``q`` (nq,) at time ``t`` s: ``substeps`` steps of this
        method's tableau in the exponential chart (:func:`~.stages.rkmk_flow_step`; its order on
        the group as :attr:`order`). ``v`` is ``velocity(t, q)`` when already known."""
        h = duration / self.substeps
        dexpinv = self._dexpinv or (lambda theta, velocity: velocity)
        nodes = self.nodes
        for k in range(self.substeps):
            self._calls += len(nodes) - (k == 0 and v is not None)
            q = rkmk_flow_step(velocity, self.model, dexpinv, q, t + k * h, h, self._ROWS, self._B, nodes,
                               v if k == 0 else None)
        return q


class SemiImplicitEuler(FixedStep):
    """Symplectic (semi-implicit) Euler, the dissertation's scheme: ``v+ = v + h a``, ``q+ = q * exp(h v+)``.

    First order.
    """

    name = "euler"
    order = 1

    def step(self, at, q, v, h, t):
        self._calls += 1
        v_next = v + h * at(t, q, v)
        return pin.integrate(self.model, q, h * v_next), v_next


class ExplicitEuler(FixedStep):
    """Explicit (forward) Euler: ``q+ = q * exp(h v)``, ``v+ = v + h a``, the old rate moving q.

    First order; kept to show where it fails against the semi-implicit scheme (it gains energy on
    oscillators and opens closed loops).
    """

    name = "explicit_euler"
    order = 1

    def step(self, at, q, v, h, t):
        self._calls += 1
        return pin.integrate(self.model, q, h * v), v + h * at(t, q, v)


class RungeKutta4(FixedStep):
    """Classical RK4 in the exponential chart at q: Runge-Kutta-Munthe-Kaas, 4th order on the group.

    Stage configurations are ``q * exp(theta_i)``; the chart velocities are corrected by
    ``dexp^{-1}`` (see :mod:`freefloat.dynamics.integrators.lie`). With ``lie_correction=False`` the stage
    velocities are added uncorrected, the common mistake, which is only 2nd order on SE(3).
    """

    name = "rkmk4"
    order = 4
    _ROWS = (np.zeros(0), np.array([0.5]), np.array([0.0, 0.5]), np.array([0.0, 0.0, 1.0]))
    _B = np.array([1.0, 2.0, 2.0, 1.0]) / 6.0

    def __init__(self, model: pin.Model, substeps: int = 1, lie_correction: bool = True):
        super().__init__(model, substeps)
        chart = ChartCorrection(model)
        self._dexpinv = chart.apply if (lie_correction and chart.needed) else None
        if not lie_correction:
            self.name, self.order = "rk4_naive", 2

    def step(self, at, q, v, h, t):
        model, dexpinv = self.model, self._dexpinv
        self._calls += 4
        a1 = at(t, q, v)
        k1 = v
        v2 = v + 0.5 * h * a1
        th2 = 0.5 * h * k1
        a2 = at(t + 0.5 * h, pin.integrate(model, q, th2), v2)
        k2 = v2 if dexpinv is None else dexpinv(th2, v2)
        v3 = v + 0.5 * h * a2
        th3 = 0.5 * h * k2
        a3 = at(t + 0.5 * h, pin.integrate(model, q, th3), v3)
        k3 = v3 if dexpinv is None else dexpinv(th3, v3)
        v4 = v + h * a3
        th4 = h * k3
        a4 = at(t + h, pin.integrate(model, q, th4), v4)
        k4 = v4 if dexpinv is None else dexpinv(th4, v4)
        theta = (h / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
        return pin.integrate(model, q, theta), v + (h / 6.0) * (a1 + 2.0 * (a2 + a3) + a4)
