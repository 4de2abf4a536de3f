"""What an integrator is: something that advances (q, v) over a control period."""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

#: ``f(q, v) -> a``: generalized acceleration (nv,) at configuration q (nq,) and velocity v (nv,),
#: with the torques and external wrenches of the current control period held fixed.
Acceleration = Callable[[np.ndarray, np.ndarray], np.ndarray]
#: ``V(t, q) -> v``: a first-order system's velocity (nv,) (Pinocchio's local velocity) at time
#: t (s) and configuration q (nq,): ``q' = V(t, q)`` (e.g. free-floating kinematics, where the
#: joint rates of a plan move the base).
Velocity = Callable[[float, np.ndarray], np.ndarray]


class Integrator(Protocol):
    """Advances a state on the configuration Lie group.

    Attributes:
        name: registry name.
        order: global order of accuracy on the Lie group.
    """

    name: str
    order: int

    def advance(
        self, f: Acceleration, q: np.ndarray, v: np.ndarray, duration: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """State after ``duration`` seconds: ``(q, v)`` with shapes (nq,), (nv,)."""
        ...

    def evaluations(self) -> int:
        """Number of ``f`` calls since construction (for cost accounting)."""
        ...
