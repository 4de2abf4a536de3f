"""Momentum projection: a structure-preserving option for long runs without external wrenches.

After each call of the wrapped integrator the velocity is replaced by the nearest one, in the
kinetic-energy metric, that has the system momentum of the call's start:

.. math::
    v \\leftarrow v - M^{-1} A^T (A M^{-1} A^T)^{-1} (A v - h_0),

with ``M`` the joint-space mass matrix and ``A`` the rows of the momentum map
``[P; L about the inertial origin]`` (inertial frame) that the root joint leaves free, both at
the new q (Hairer, Lubich & Wanner, Sec. IV.4, projection methods). Joint torques are internal
forces, so the exact flow keeps ``h_0``; a run with external wrenches (thrusters, contact, a
capture impulse) does not, and must not use this option.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...robot.conventions import PLANAR_ROWS, skew
from .base import Acceleration, Integrator, TimeVarying

#: Rows of ``[P; L]`` that no reaction of the root joint can change, per root-joint kind.
CONSERVED_ROWS = {"JointModelFreeFlyer": np.arange(6), "JointModelPlanar": PLANAR_ROWS}


class MomentumProjection:
    """Wraps an integrator and projects v onto the momentum of each call's start.

    Args:
        inner: the integrator that advances (q, v).
        model: Pinocchio model with a free-flyer or planar root joint.

    Raises:
        ValueError: naming the root joint when it is neither free-flyer nor planar.
    """

    def __init__(self, inner: Integrator, model: pin.Model):
        kind = model.joints[1].shortname() if model.njoints > 1 else "none"
        if kind not in CONSERVED_ROWS:
            root = model.names[1] if model.njoints > 1 else "(no joint)"
            raise ValueError(
                f"momentum projection needs a free-flyer or planar root joint; joint '{root}' is {kind}"
            )
        self.inner, self.model, self._rows = inner, model, CONSERVED_ROWS[kind]
        self._data = model.createData()
        self.name, self.order = f"{inner.name}_projected", inner.order

    def evaluations(self) -> int:
        return self.inner.evaluations()

    def momentum_map(self, q: np.ndarray) -> np.ndarray:
        """Conserved rows of the map ``v -> [P; L about the inertial origin]`` (r, nv), inertial frame."""
        Ag = pin.computeCentroidalMap(self.model, self._data, q)  # at the CoM, world-aligned
        A = Ag.copy()
        A[3:] += skew(self._data.com[0]) @ Ag[:3]
        return A[self._rows]

    def advance(
        self, f: Acceleration | TimeVarying, q: np.ndarray, v: np.ndarray, duration: float
    ) -> tuple[np.ndarray, np.ndarray]:
        h0 = self.momentum_map(q) @ v
        q, v = self.inner.advance(f, q, v, duration)
        A = self.momentum_map(q)
        M = pin.crba(self.model, self._data, q)
        M = np.triu(M) + np.triu(M, 1).T
        MinvAT = np.linalg.solve(M, A.T)
        return q, v - MinvAT @ np.linalg.solve(A @ MinvAT, A @ v - h0)
