"""Forward dynamics of a tree with loop closures (numpy; the readable reference).

.. math::
    M(q)\\,a + h(q, v) = \\tau + J^T \\lambda, \\qquad
    J a = -\\gamma - 2\\beta J v - \\beta^2 e,

with ``M`` from CRBA, ``h`` from RNEA (Coriolis, gravity, external wrenches), ``J``, ``gamma``,
``e`` the stacked closure rows (:mod:`.closure`) and ``beta`` the Baumgarte rate (1/s; 0: none).
Solved through the Delassus matrix ``D = J M^-1 J^T``: ``lambda = D^+ (rhs - J M^-1 (tau - h))``,
a pseudo-inverse so that redundant rows (a planar loop closed by a weld) are allowed; the
accelerations are unique whenever ``M`` is positive definite. Pinocchio's ``constraintDynamics``
is the reference for point and weld closures (tests/test_closures.py).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...errors import SimulationDiverged
from ...robot.robot import Robot
from ..models.base import checked
from ..models.exact import joint_space_dynamics
from .closure import Closure, kinematics, stacked

#: Relative eigenvalue below which a Delassus direction is a redundant row (no force along it).
REDUNDANT = 1e-12


@dataclass
class ConstrainedSolution:
    """The constrained dynamics at one state.

    Attributes:
        acceleration: ``a`` (nv,).
        force: ``lambda`` (m,): closure forces, frame 1 axes, on frame 2's body (N, N m);
            ``J^T lambda`` is their generalized force.
        residual: closure residuals ``e`` (m,).
        rank: rank of the Delassus matrix (m when no row is redundant).
    """

    acceleration: np.ndarray
    force: np.ndarray
    residual: np.ndarray
    rank: int


def delassus_solve(D: np.ndarray, rhs: np.ndarray) -> tuple[np.ndarray, int]:
    """``D^+ rhs`` for a symmetric positive semi-definite ``D`` (m, m), and its rank: Cholesky when
    ``D`` is surely well conditioned (``1 / trace(D^-1)``, at most its least eigenvalue, above
    :data:`REDUNDANT` times ``trace(D)``, at least its largest), otherwise an eigen-decomposition
    whose directions under :data:`REDUNDANT` times the largest eigenvalue carry no force. (A
    small Cholesky pivot is no bound: a singular ``D`` factored with a least pivot^2 of 1.8e-12
    times its largest diagonal, and the force came out at 1e18 N.)"""
    from scipy.linalg import cho_factor, cho_solve  # here: scipy is 0.3 s of start-up for runs without closures

    if D.size == 0:
        return np.zeros(0), 0
    try:
        factor = cho_factor(D)
        trace_inverse = np.trace(cho_solve(factor, np.eye(len(D))))
        if trace_inverse > 0.0 and 1.0 / trace_inverse > REDUNDANT * np.trace(D):
            return cho_solve(factor, rhs), len(rhs)
    except np.linalg.LinAlgError:
        pass
    w, V = np.linalg.eigh(D)
    keep = w > REDUNDANT * max(w.max(), 0.0)
    return V[:, keep] @ ((V[:, keep].T @ rhs) / w[keep]), int(keep.sum())


def solve(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
          closures: Sequence[Closure], baumgarte: float = 0.0,
          fext: Sequence[pin.Force] | None = None) -> ConstrainedSolution:
    """The constrained dynamics (module docstring) at ``(q, v)`` under generalized forces ``tau``
    (nv,) and external wrenches ``fext`` (one per joint, joint frames), Baumgarte rate ``baumgarte``.

    Raises:
        SimulationDiverged: when ``M`` is not positive definite or the result is not finite.
    """
    from scipy.linalg import cho_factor, cho_solve  # here: scipy is 0.3 s of start-up for runs without closures

    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    zero = np.zeros(model.nv)
    h = pin.rnea(model, data, q, v, zero) if fext is None else pin.rnea(model, data, q, v, zero, fext)
    kinematics(model, data, q, v)
    e, J, gamma = stacked(closures, model, data)
    try:
        factor = cho_factor(M)
    except np.linalg.LinAlgError as exc:
        raise SimulationDiverged(f"the mass matrix is not positive definite: {exc}") from exc
    a_free = cho_solve(factor, tau - h)
    MinvJt = cho_solve(factor, J.T)
    rhs = -gamma - 2.0 * baumgarte * (J @ v) - baumgarte**2 * e - J @ a_free
    force, rank = delassus_solve(J @ MinvJt, rhs)
    a = a_free + MinvJt @ force
    if not np.isfinite(a).all():
        raise SimulationDiverged("constrained dynamics: accelerations are not finite")
    return ConstrainedSolution(a, force, e, rank)


class ClosedModel:
    """A robot's exact dynamics with loop closures, as a dynamics model of the one loop
    (:class:`~freefloat.dynamics.models.base.DynamicsModel`).

    Args:
        robot: the robot (its tree).
        closures: the closures, all active.
        baumgarte: Baumgarte rate beta, 1/s (``Kp = beta^2``, ``Kd = 2 beta``).
    """

    name = "exact_closed"

    def __init__(self, robot: Robot, closures: Sequence[Closure], baumgarte: float = 0.0):
        self.robot, self.model = robot, robot.model
        self.closures, self.baumgarte = tuple(closures), float(baumgarte)
        self.data = robot.model.createData()
        self.last: ConstrainedSolution | None = None

    @checked
    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
                     fext: Sequence[pin.Force] | None = None) -> np.ndarray:
        self.last = solve(self.model, self.data, q, v, tau, self.closures, self.baumgarte, fext)
        return self.last.acceleration

    def joint_space_at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(H*, c*)`` of the tree without its closures (n, n), (n,): what a tree controller sees."""
        return joint_space_dynamics(self.robot, self.data, q, v)

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """Largest position residual (m) and rotation residual (rad) over the closures at ``q``."""
        return closure_drift(self.model, self.data, q, self.closures)


def closure_drift(model: pin.Model, data: pin.Data, q: np.ndarray, closures: Sequence[Closure]) -> tuple[float, float]:
    """Largest closure position residual (m) and rotation residual (rad) at ``q``."""
    position = rotation = 0.0
    kinematics(model, data, q, np.zeros(model.nv))
    for closure in closures:
        e = stacked([closure], model, data, drift=False)[0]
        position = max(position, float(np.linalg.norm(e[:3])))
        rotation = max(rotation, float(np.linalg.norm(e[3:]))) if len(e) > 3 else rotation
    return position, rotation
