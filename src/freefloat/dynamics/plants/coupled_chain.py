"""A closed chain by Orsino's subsystem coupling (thesis proposal eqs 114-129) as a plant."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import FreefloatError, SimulationDiverged
from .vector_space import vector_space


class CoupledChainPlant:
    """Eq 129 on Orsino's coordinates ``q = [q#; q°]`` (n_q,, all Euclidean), Baumgarte-stabilised.

    Args:
        mechanism: a :class:`freefloat.parallel.mechanism.ParallelMechanism` (anything with its
            ``forward(q, qd, tau, baumgarte)``, ``residuals(q)``, ``n_q`` and ``actuated``).
        baumgarte: lambda of eq 129, 1/s (0: no stabilisation).
        max_drift: a loop-closure residual above this (m), or an orientation residual above this
            (rad), is a blow-up.
    """

    name = "coupled_chain"

    def __init__(self, mechanism: Any, baumgarte: float = 0.0, max_drift: float = 1.0):
        self.mechanism, self.baumgarte, self.max_drift = mechanism, float(baumgarte), float(max_drift)
        self.space = vector_space(mechanism.n_q)
        self.n_efforts = len(mechanism.actuated)

    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """``qddot`` (n_q,) under actuator efforts ``u`` (k,), eq 129.

        Raises:
            SimulationDiverged: at a singular pose, where eq 129 has no solution.
        """
        try:
            return self.mechanism.forward(q, v, u, self.baumgarte)
        except (np.linalg.LinAlgError, RuntimeError, FreefloatError) as exc:  # numpy or compiled core
            raise SimulationDiverged(f"singular pose, eq 129 has no solution: {exc}") from exc

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """``(max |qbar(q)|, max |orientation residual|)``, m and rad."""
        position, orientation = self.mechanism.residuals(q)
        return float(np.abs(position).max(initial=0.0)), float(np.abs(orientation).max(initial=0.0))
