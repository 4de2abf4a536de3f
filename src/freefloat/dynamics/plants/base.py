"""What a plant is for the one simulation loop."""

from __future__ import annotations

from typing import Protocol

import numpy as np
import pinocchio as pin


class Plant(Protocol):
    """A system the loop integrates under efforts held over each control period.

    Attributes:
        name: the plant kind (a key of :data:`freefloat.dynamics.plants.PLANTS`).
        space: the configuration space the integrators step on (``nq``, ``nv`` and the group's
            ``integrate``); for Euclidean coordinates a :func:`~.vector_space.vector_space`.
        n_efforts: number of efforts ``u`` (actuators).
        max_drift: a position residual above this (m) is a blow-up (the loop came apart).
    """

    name: str
    space: pin.Model
    n_efforts: int
    max_drift: float

    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Generalized acceleration (nv,) at (q (nq,), v (nv,)) under efforts ``u`` (n_efforts,)."""
        ...

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """Constraint residuals at ``q``: largest position residual (m) and largest orientation
        residual (rad); ``(0, 0)`` without constraints."""
        ...
