"""What an integrator is: something that advances (q, v) over a control period."""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

#: ``f(q, v) -> a``: generalized acceleration (nv,) at configuration q (nq,) and velocity v (nv,),
#: with the torques and external wrenches of the current control period held fixed (autonomous);
#: or a :class:`TimeVarying` acceleration, which every integrator evaluates at each stage's time.
Acceleration = Callable[[np.ndarray, np.ndarray], np.ndarray]
#: ``a(t, q, v) -> a``: generalized acceleration (nv,) at time t (s, counted from the start of the
#: :meth:`Integrator.advance` call), configuration q (nq,) and velocity v (nv,).
StageAcceleration = Callable[[float, np.ndarray, np.ndarray], np.ndarray]
#: ``V(t, q) -> v``: a first-order system's velocity (nv,) (Pinocchio's local velocity) at time
#: t (s) and configuration q (nq,): ``q' = V(t, q)`` (e.g. free-floating kinematics, where the
#: joint rates of a plan move the base).
Velocity = Callable[[float, np.ndarray], np.ndarray]


class TimeVarying:
    """An acceleration that depends on time: every integrator calls :attr:`at` with each stage's
    own time (``t0 + c_i h`` of a Runge-Kutta stage, an adaptive step's trial times, every
    sub-step's), counted from the start of its :meth:`Integrator.advance` call. Called as
    ``f(q, v)`` it is the acceleration at that start.

    Args:
        at: ``at(t, q, v) -> a`` (:data:`StageAcceleration`).
    """

    __slots__ = ("at",)

    def __init__(self, at: StageAcceleration):
        self.at = at

    def __call__(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.at(0.0, q, v)


def at_stage_time(f: Acceleration | TimeVarying) -> StageAcceleration:
    """``f`` as ``a(t, q, v)``: a :class:`TimeVarying` one's :attr:`~TimeVarying.at`; an autonomous
    ``f(q, v)`` ignoring t."""
    return f.at if isinstance(f, TimeVarying) else (lambda t, q, v: f(q, v))


class Integrator(Protocol):
    """Advances a state on the configuration Lie group.

    Attributes:
        name: registry name.
        order: global order of accuracy on the Lie group.
    """

    name: str
    order: int

    def advance(
        self, f: Acceleration | TimeVarying, q: np.ndarray, v: np.ndarray, duration: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """State after ``duration`` seconds: ``(q, v)`` with shapes (nq,), (nv,); a
        :class:`TimeVarying` ``f`` is evaluated at every stage's time from the call's start
        (:func:`at_stage_time`)."""
        ...

    def evaluations(self) -> int:
        """Number of ``f`` calls since construction (for cost accounting)."""
        ...
