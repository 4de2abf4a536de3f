"""A controller sampled slower than the loop's control period: a digital law updated every
``every`` periods and held in between, while the loop records (and the plant is integrated over)
every period."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np


class Sampled:
    """``controller`` evaluated every ``every`` control periods, its efforts held in between.

    The loop calls :meth:`torque` once per period, in order (as
    :func:`freefloat.dynamics.simulation.run` and ``run_plant`` do); the compiled closed-chain
    loop takes the same schedule from :meth:`compiled_law`.

    Args:
        controller: anything with ``torque(t, q, v)`` and ``reference(t)``.
        every: periods per law update (>= 1).

    Raises:
        ValueError: for ``every`` < 1.
    """

    def __init__(self, controller: Any, every: int):
        if not (isinstance(every, int) and every >= 1):
            raise ValueError(f"every must be an integer >= 1, got {every!r}")
        self.controller, self.every = controller, every
        self.calls = 0
        self.held: np.ndarray | None = None

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The law's efforts at every ``every``-th call, the held ones otherwise."""
        if self.calls % self.every == 0:
            self.held = self.controller.torque(t, q, v)
        self.calls += 1
        return self.held

    def reference(self, t: float) -> np.ndarray | None:
        """The controller's reference at ``t``."""
        return self.controller.reference(t)

    def compiled_law(self) -> Any:
        """The controller's compiled law with this schedule (its ``every`` replaced), or None."""
        law = getattr(self.controller, "compiled_law", lambda: None)()
        return None if law is None else dataclasses.replace(law, every=self.every)
