"""Shared machinery of the GJM dynamics models: terms at a state, base row, conversions.

Every GJM variant writes the joint dynamics as ``tau = H qddot + c`` (joint order of the
Pinocchio model) and the base row as ``xddot0 = f(qddot)``; forward dynamics then solves
``qddot = H^-1 (tau + Q_q - c)`` and maps ``xddot0`` (base CoM, inertial) back to Pinocchio's
base acceleration. ``Q`` are the generalized forces of external wrenches and gravity,
``Q = J^T f - g(q)`` (Pinocchio RNEA at zero velocity and acceleration), mapped to the GJM base
rows by ``F = T^-T Q_b``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...errors import UnknownName
from ...robot.conventions import (
    PLANAR_ROWS,
    base_link_placement,
    local_base_acceleration,
    twist_map,
)
from ...robot.robot import Robot
from ..gjm import BACKENDS, GJMDerivatives, GJMState, model_of, state_and_derivatives
from .base import checked


@dataclass
class Terms:
    """GJM quantities at one state, with the derived vectors every variant needs.

    Attributes:
        s: the GJM state (H0, H0m, Hm, H*, momenta, x0dot, qdot, ...).
        d: joint and time derivatives of H0, H0m, Hm.
        c_m: ``-1/2 z^T dH/dq_k z`` with ``z = [x0dot; qdot]``, partials at fixed base pose
            (eq 25 with dx0/dq = 0) (n,).
        F: generalized external and gravity force on the base rows, conjugate to x0dot (6,).
        Q_q: the same on the joints (n,).
    """

    s: GJMState
    d: GJMDerivatives
    c_m: np.ndarray
    F: np.ndarray
    Q_q: np.ndarray

    def solve0(self, x: np.ndarray) -> np.ndarray:
        """``H0^-1 x``."""
        return np.linalg.solve(self.s.H0, x)


def quadratic_form(s: GJMState, dH0: np.ndarray, dH0m: np.ndarray, dHm: np.ndarray) -> np.ndarray:
    """``z^T dH_k z`` for each k, ``z = [x0dot; qdot]`` (n,)."""
    x, qd = s.x0dot, s.qdot
    return ((dH0 @ x) @ x + 2.0 * (dH0m @ qd) @ x + (dHm @ qd) @ qd)


class GJMModelBase:
    """Base class: builds :class:`Terms`, solves the joint-space form, returns ``a`` (nv,).

    Subclasses implement :meth:`joint_space` (``H, c`` with ``tau = H qddot + c``) and
    :meth:`base_acceleration` (xddot0 given qddot): the numpy reference. With
    ``backend="compiled"`` (the default) the same equations run in the compiled core
    (``cpp/gjm/models.hpp``), one call per acceleration; ``backend="numpy"`` runs this reference on the
    numpy GJM.

    Args:
        robot: the robot.
        backend: ``"compiled"`` or ``"numpy"`` (see :data:`freefloat.gjm.BACKENDS`).
    """

    name = ""

    def __init__(self, robot: Robot, backend: str = "compiled"):
        if backend not in BACKENDS:
            raise UnknownName("model backend", backend, BACKENDS)
        self.robot = robot
        self.backend = backend
        self.gjm = model_of(robot)
        self.data = robot.model.createData()
        self._zeros = np.zeros(robot.model.nv)
        self._no_force = (np.zeros(6), np.zeros(robot.n_joints))
        self._gravity = bool(np.any(robot.model.gravity.linear != 0.0))

    def generalized_forces(self, q: np.ndarray, fext: Sequence[pin.Force] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(F, Q_q)`` (6,), (n,): generalized forces of ``fext`` and gravity on the GJM base rows
        (conjugate to x0dot) and on the joints."""
        if fext is None and not self._gravity:
            return self._no_force
        model = self.robot.model
        Q = -(pin.rnea(model, self.data, q, self._zeros, self._zeros, fext) if fext is not None
              else pin.rnea(model, self.data, q, self._zeros, self._zeros))
        nb = self.robot.n_base
        T = twist_map(base_link_placement(self.robot, q).rotation, self.robot.base_com)
        TE = T if self.robot.base == "free" else T[:, PLANAR_ROWS]
        return np.linalg.pinv(TE).T @ Q[:nb], Q[nb:]

    def terms(self, q: np.ndarray, v: np.ndarray, fext: Sequence[pin.Force] | None = None) -> Terms:
        """All GJM quantities at (q, v), with the generalized forces of ``fext`` and gravity."""
        s, d = state_and_derivatives(self.gjm, q, v, self.backend)
        F, Q_q = self.generalized_forces(q, fext)
        return Terms(s=s, d=d, c_m=-0.5 * quadratic_form(s, d.dH0, d.dH0m, d.dHm), F=F, Q_q=Q_q)

    def sensitivities(self) -> np.ndarray:
        """The model's integrated sensitivities handed to the compiled core: none here (0, 6)."""
        return np.zeros((0, 6))

    def joint_space(self, t: Terms) -> tuple[np.ndarray, np.ndarray]:
        """``(H, c)`` with ``tau + Q_q = H qddot + c`` (n, n), (n,)."""
        raise NotImplementedError

    def base_acceleration(self, t: Terms, qddot: np.ndarray) -> np.ndarray:
        """``xddot0`` (6,), base CoM, inertial frame."""
        raise NotImplementedError

    def joint_space_at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(H, c)`` at (q, v) without external forces: what a computed-torque law uses. Gravity,
        when on, enters c through the base rows only."""
        if self.backend == "compiled":
            return self.gjm.core.joint_space(self.name, q, v, self.generalized_forces(q)[0], self.sensitivities())
        return self.joint_space(self.terms(q, v))

    @checked
    def acceleration(self, q, v, tau, fext=None) -> np.ndarray:
        """Forward dynamics (nv,), Pinocchio convention (see :class:`~freefloat.models.DynamicsModel`)."""
        if self.backend == "compiled":
            F, Q_q = self.generalized_forces(q, fext)
            return self.gjm.core.acceleration(self.name, q, v, tau, F, Q_q, self.sensitivities())
        t = self.terms(q, v, fext)
        H, c = self.joint_space(t)
        nb = self.robot.n_base
        qddot = np.linalg.solve(H, tau[nb:] + t.Q_q - c)
        return np.concatenate((local_base_acceleration(self.robot, q, v, self.base_acceleration(t, qddot)), qddot))
