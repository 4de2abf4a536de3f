"""Closing loops at an instant: the perfectly inelastic impulse that brings the closures'
relative velocities to zero all at once (a grasp with both hands, numpy reference).

.. math::
    M (v^+ - v^-) = J^T \\Lambda, \\qquad J v^+ = 0
    \\;\\Rightarrow\\; \\Lambda = -D^+ J v^-, \\quad v^+ = v^- + M^{-1} J^T \\Lambda,

with ``D = J M^-1 J^T`` over every closing closure together (not one after the other). The impulse
is internal to the system, so its momentum is kept exactly. Pinocchio's ``impulseDynamics``
(restitution 0) is the reference for point and weld closures.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .closure import Closure, kinematics, stacked
from .constrained import delassus_solve


@dataclass
class ClosingImpulse:
    """Velocities across the closing instant.

    Attributes:
        v_after: ``v+`` (nv,).
        impulse: ``Lambda`` (m,): the closures' impulses, frame 1 axes, on frame 2's body (N s, N m s).
        gap_speed_before: ``|J v-|`` (m/s and rad/s rows together), what the impact stopped.
    """

    v_after: np.ndarray
    impulse: np.ndarray
    gap_speed_before: float


def closing_impulse(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray,
                    closures: Sequence[Closure]) -> ClosingImpulse:
    """The impulse closing every closure of ``closures`` at once at ``(q, v)`` (module docstring)."""
    from scipy.linalg import cho_factor, cho_solve  # here: scipy is 0.3 s of start-up for runs without closures

    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    kinematics(model, data, q, v)
    _, J, _ = stacked(closures, model, data, drift=False)
    factor = cho_factor(M)
    MinvJt = cho_solve(factor, J.T)
    gap = J @ v
    impulse, _ = delassus_solve(J @ MinvJt, -gap)
    return ClosingImpulse(v + MinvJt @ impulse, impulse, float(np.linalg.norm(gap)))
