"""Adaptive embedded Runge-Kutta pairs in the Munthe-Kaas chart, error-controlled: Dormand-Prince
5(4) (5th order on the group, dense output) and Bogacki-Shampine 3(2) (3rd order, three
evaluations per accepted step: the cheap pair for loose tolerances)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pinocchio as pin

from ...errors import SimulationDiverged
from .base import Acceleration, TimeVarying, at_stage_time
from .stages import chart_velocity, rkmk_stages

# Dormand-Prince 5(4) tableau (Hairer, Norsett & Wanner, Table II.5.2).
_ROWS = tuple(np.array(r) for r in (
    (),
    (1 / 5,),
    (3 / 40, 9 / 40),
    (44 / 45, -56 / 15, 32 / 9),
    (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
    (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656),
    (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84),
))
_B = np.array([35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0.0])
_B_LOW = np.array([5179 / 57600, 0.0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])
# Continuous extension of order 4 (Shampine 1986; Hairer & Wanner's DOPRI5 code, CONTD5).
_D = np.array([-12715105075 / 11282082432, 0.0, 87487479700 / 32700410799, -10690763975 / 1880347072,
               701980252875 / 199316789632, -1453857185 / 822651844, 69997945 / 29380423])


def _interpolate(y0: np.ndarray, y1: np.ndarray, K: np.ndarray, h: float, s: float) -> np.ndarray:
    """Dense output at ``t0 + s h`` (0 <= s <= 1) of a step from y0 to y1 with stage slopes K (7, n)."""
    dy = y1 - y0
    c3 = h * K[0] - dy
    c4 = dy - h * K[6] - c3
    return y0 + s * (dy + (1.0 - s) * (c3 + s * (c4 + (1.0 - s) * h * (_D @ K))))


class EmbeddedRKMK:
    """An adaptive explicit RKMK pair (``_ROWS``, ``_B``, ``_B_LOW``, first stage same as last) with
    standard step-size control.

    Each step works in the exponential chart at its start point; the error estimate is the
    difference of the higher- and lower-order solutions in the chart (theta) and in v, scaled by
    ``atol + rtol * |x|``, and the next step is ``0.9 err^(-1 / (low order + 1))`` times this one
    (between 0.2x and 5x; a rejected step shrinks by at most 10x). The last stage is evaluated at
    the new state, so within one call it is the next step's first. The step size carries over
    between calls. A trial step from time t (s, of the call) evaluates a
    :class:`~.base.TimeVarying` acceleration at ``t + c_i h`` (``c_i``: :attr:`nodes`).

    Args:
        model: Pinocchio model.
        rtol: relative tolerance.
        atol: absolute tolerance.
        max_steps: steps allowed per call before giving up.
    """

    name = ""
    order = 0
    _ROWS: tuple[np.ndarray, ...] = ()
    _B = _B_LOW = np.zeros(0)
    #: The step-size control's exponent, -1 / (lower order + 1).
    _EXPONENT = -0.2

    def __init__(self, model: pin.Model, rtol: float = 1e-10, atol: float = 1e-12, max_steps: int = 100_000):
        if not (rtol > 0.0 and atol > 0.0):
            raise ValueError(f"rtol and atol must be > 0, got {rtol}, {atol}")
        self.model, self.rtol, self.atol, self.max_steps = model, rtol, atol, max_steps
        self._dexpinv = chart_velocity(model)
        self._h: float | None = None
        self._calls = 0
        #: The stage times of one step as fractions of it, ``c_i`` (the row sums of ``_ROWS``).
        self.nodes = tuple(float(row.sum()) for row in self._ROWS)
        self.accepted = 0
        self.rejected = 0

    def evaluations(self) -> int:
        return self._calls

    def advance(self, f: Acceleration | TimeVarying, q: np.ndarray, v: np.ndarray, duration: float):
        end = q, v
        for _t, _h, q_new, v_new, _step in self._steps(f, q, v, duration):
            end = q_new, v_new
        return end

    def _steps(self, f: Acceleration | TimeVarying, q: np.ndarray, v: np.ndarray,
               duration: float) -> Iterator[tuple]:
        """Accepted steps: ``(t, h, q_new, v_new, (q, v, theta, K, Acc))``, t the step's start."""
        t, h, a0, at = 0.0, self._h or duration, None, at_stage_time(f)
        rows, b, b_error = self._ROWS, self._B, self._B - self._B_LOW
        for _ in range(self.max_steps):
            if t >= duration * (1.0 - 1e-12):
                return
            h_try = min(h, duration - t)
            K, Acc = rkmk_stages(at, self.model, self._dexpinv, q, v, t, h_try, rows, self.nodes, a0)
            self._calls += len(rows) - (a0 is not None)
            a0 = Acc[0]
            theta, v_new = h_try * (b @ K), v + h_try * (b @ Acc)
            err = self._error(h_try * (b_error @ K), h_try * (b_error @ Acc), theta, v, v_new)
            # err NaN (a stage left the dynamics' domain: the step was far too long): shrink 10x
            factor = 0.9 * err ** self._EXPONENT if err > 0.0 else (5.0 if err == 0.0 else 0.1)
            if err <= 1.0:
                q_new = pin.integrate(self.model, q, theta)
                yield t, h_try, q_new, v_new, (q, v, theta, K, Acc)
                t, q, v, a0 = t + h_try, q_new, v_new, Acc[-1]
                self.accepted += 1
                h = h_try * min(5.0, max(0.2, factor))
                self._h = h
            else:
                self.rejected += 1
                h = h_try * max(0.1, factor)
        raise SimulationDiverged(
            f"{self.name}: {self.max_steps} steps did not cover {duration} s (last step {h:.3g} s)"
        )

    def _error(self, err_theta, err_v, theta, v, v_new) -> float:
        """RMS of the error estimate scaled by ``atol + rtol * |x|`` (1 = at tolerance)."""
        scale_v = self.atol + self.rtol * np.maximum(np.abs(v), np.abs(v_new))
        scale_theta = self.atol + self.rtol * np.abs(theta)
        return float(np.sqrt(np.mean(np.concatenate((err_theta / scale_theta, err_v / scale_v)) ** 2)))


class DormandPrince45(EmbeddedRKMK):
    """Adaptive RKMK Dormand-Prince 5(4) (6 evaluations per accepted step) with dense output:
    :meth:`solve` samples one run at many times from the 4th-order continuous extension, without
    shortening steps to land on them."""

    name = "dopri5"
    order = 5
    _ROWS, _B, _B_LOW, _EXPONENT = _ROWS, _B, _B_LOW, -0.2

    def solve(
        self, f: Acceleration | TimeVarying, q: np.ndarray, v: np.ndarray, times: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """States at ``times`` (s, increasing, from 0): q (len(times), nq), v (len(times), nv).

        One adaptive run to ``times[-1]`` (a :class:`~.base.TimeVarying` ``f`` sees the time from
        ``times[0] = 0``); the states in between come from the dense output
        ``q0 * exp(theta(s))``, ``v(s)`` of the step that contains them (local frame of q0).
        """
        times = np.asarray(times, dtype=float)
        if times.ndim != 1 or times.size == 0 or times[0] < 0.0 or np.any(np.diff(times) < 0.0):
            raise ValueError("dopri5 solve: times must be a non-empty, increasing 1-D array from 0 on")
        Q, V = np.empty((times.size, q.size)), np.empty((times.size, v.size))
        i, q_new, v_new = 0, q, v
        while i < times.size and times[i] == 0.0:
            Q[i], V[i], i = q, v, i + 1
        for t, h, _q_new, v_new, (q0, v0, theta, K, Acc) in self._steps(f, q, v, float(times[-1])):
            while i < times.size and times[i] <= t + h:
                s = min(1.0, (times[i] - t) / h)
                Q[i] = pin.integrate(self.model, q0, _interpolate(np.zeros_like(theta), theta, K, h, s))
                V[i] = _interpolate(v0, v_new, Acc, h, s)
                i += 1
        Q[i:], V[i:] = q_new, v_new  # the last time, reached within round-off
        return Q, V


class BogackiShampine32(EmbeddedRKMK):
    """Adaptive RKMK Bogacki-Shampine 3(2) (Appl. Math. Lett. 2, 1989): 3rd order with a 2nd-order
    estimate, three evaluations per accepted step (four stages, the last the next step's first).
    Cheaper than ``dopri5`` where the tolerance is loose; no dense output."""

    name = "bs32"
    order = 3
    _ROWS = tuple(np.array(r) for r in ((), (1 / 2,), (0.0, 3 / 4), (2 / 9, 1 / 3, 4 / 9)))
    _B = np.array([2 / 9, 1 / 3, 4 / 9, 0.0])
    _B_LOW = np.array([7 / 24, 1 / 4, 1 / 3, 1 / 8])
    _EXPONENT = -1 / 3
