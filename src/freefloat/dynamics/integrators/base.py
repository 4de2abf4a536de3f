"""What an integrator is: something that advances (q, v) over a control period."""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

#: ``f(q, v) -> a``: generalized acceleration (nv,) at configuration q (nq,) and velocity v (nv,),
#: with the torques and external wrenches of the current control period held fixed.
Acceleration = Callable[[np.ndarray, np.ndarray], np.ndarray]


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
