"""Models on the generalized inertia H*: the stand-alone reduced model and the non-zero,
conserved-momentum models (dissertation secs 3.4, 3.9.4; eqs 92-94, 127, 128; appendix C).

With ``M = H0 x0dot + H0m qdot`` (momentum about the base CoM, inertial frame, held conserved)
the base follows ``x0dot = -H0^-1 H0m qdot + H0^-1 M`` (eq 84), whose time derivative gives
``xddot0 = -H0^-1 (H0m qddot + H0dot x0dot + H0mdot qdot)``. The joint equations:

- ``reduced`` (eq 93, M = 0): ``H* qddot + H*dot qdot - 1/2 d/dq (qdot^T H* qdot) = tau``;
- ``momentum_mono`` (eq 127, the constraint put into the Lagrangian first):
  ``... - 1/2 M^T d(H0^-1)/dq M``;
- ``momentum_multi`` (eq 128): ``... + d/dt (H0m^T H0^-1 M)``;
- ``momentum_routh`` (the Routhian, derived here as the correction): ``... + d/dt (H0m^T H0^-1 M)
  - d/dq (qdot^T H0m^T H0^-1 M) + 1/2 M^T d(H0^-1)/dq M``: the gyroscopic pair and the amended
  potential with the sign Routh reduction gives. Exact while M is conserved, i.e. while
  ``v0 x P = 0`` (zero linear momentum).
"""

from __future__ import annotations

import numpy as np

from ...errors import UnknownName
from ...robot.robot import Robot
from .gjm_base import GJMModelBase, Terms

VARIANTS = ("reduced", "momentum_mono", "momentum_multi", "momentum_routh")


class GeneralizedInertiaModel(GJMModelBase):
    """The H*-based models.

    Args:
        robot: the robot.
        variant: one of :data:`VARIANTS`.
        backend: ``"compiled"`` or ``"numpy"``, the reference.
    """

    def __init__(self, robot: Robot, variant: str, backend: str = "compiled"):
        if variant not in VARIANTS:
            raise UnknownName("H* model", variant, VARIANTS)
        super().__init__(robot, backend)
        self.name = variant

    def joint_space(self, t: Terms) -> tuple[np.ndarray, np.ndarray]:
        s, d = t.s, t.d
        A = t.solve0(s.H0m)                                    # H0^-1 H0m (6, n)
        # dH*/dq_k = dHm_k - dH0m_k^T A - A^T dH0m_k + A^T dH0_k A
        dHstar = d.dHm - d.dH0m.transpose(0, 2, 1) @ A - A.T @ d.dH0m + A.T @ d.dH0 @ A
        qd = s.qdot
        c = np.tensordot(qd, dHstar, 1) @ qd - 0.5 * (dHstar @ qd) @ qd
        if self.name != "reduced":
            M = s.momentum_base
            invM = t.solve0(M)                                 # H0^-1 M
            amended = -(d.dH0 @ invM) @ invM                   # M^T d(H0^-1)/dq_k M
            rate = d.H0mdot.T @ invM - s.H0m.T @ t.solve0(d.H0dot @ invM)  # d/dt(H0m^T H0^-1 M)
            gyro = (d.dH0m @ qd) @ invM - (d.dH0 @ invM) @ (A @ qd)  # d/dq_k (qdot^T H0m^T H0^-1 M)
            if self.name == "momentum_mono":
                c = c - 0.5 * amended
            elif self.name == "momentum_multi":
                c = c + rate
            else:
                c = c + rate - gyro + 0.5 * amended
        return s.Hstar, c

    def base_acceleration(self, t: Terms, qddot: np.ndarray) -> np.ndarray:
        s, d = t.s, t.d
        x0dot = s.x0dot if self.name != "reduced" else -t.solve0(s.H0m @ s.qdot)  # eq 84 / eq 71
        return -t.solve0(s.H0m @ qddot + d.H0dot @ x0dot + d.H0mdot @ s.qdot)
