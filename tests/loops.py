"""A plain efforts function as a controller of the one loop, and the closed-chain runs the tests
make with it (the engine under test is freefloat.dynamics.simulation.run_plant)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from freefloat.dynamics.result import Result
from freefloat.parallel.closed_loop import track


@dataclass
class Law:
    """``efforts(t, q, qd) -> u`` as a controller (no reference)."""

    efforts: Callable[[float, np.ndarray, np.ndarray], np.ndarray]

    def torque(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return self.efforts(t, q, qd)

    def reference(self, t: float) -> None:
        return None


def simulate(mechanism, q0: np.ndarray, qd0: np.ndarray, efforts, duration: float, step: float,
             baumgarte: float = 0.0, integrator: str = "rkmk4", backend: str = "auto") -> Result:
    """The mechanism under ``efforts`` held over each ``step`` s."""
    return track(mechanism, Law(efforts), q0, duration, step, step, baumgarte, integrator, qd0, backend=backend)
