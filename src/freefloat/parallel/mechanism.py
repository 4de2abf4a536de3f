"""Parallel mechanisms by coupling serial subsystems (thesis proposal sec 5.4, eqs 90-140).

Coordinates ``q = [q#; q°]``: the platform's ``q#`` (the independent coordinates, e.g. the
end-effector point of the 5R) and the chains' joints ``q° = [q_1; ...; q_n]``. Position
constraints ``qbar(q) = D q# - d - E x(q°) - F q° = 0`` (eqs 90-96) with ``x`` the stacked chain
tips in N; differentiated, ``A qdot = 0`` with ``A = [A#, A°] = [D, -(E J_v + F)]`` (eqs 105-108)
and ``A qddot = b = E o°`` (eqs 109-113, ``o°`` the tips' acceleration bias). The orthogonal
complement ``C = [I; -A°^+ A#]`` (eq 120) gives ``qdot = C qdot#`` and the coupled dynamics
``C^T (M' qddot + v' + g') = C^T u'`` (eq 124), simulated with Baumgarte stabilisation (eq 129):

.. math::
    \\begin{bmatrix} C^T M' \\\\ A \\end{bmatrix} \\ddot q =
    \\begin{bmatrix} C^T (u' - v' - g') \\\\ b - 2\\lambda A \\dot q - \\lambda^2 \\bar q \\end{bmatrix}.

Inverse dynamics (eqs 130-140): ``q`` by solving ``qbar = 0``, ``qdot = C qdot#``,
``qddot = C qddot# + [0; A°^+ b]``, then the actuator efforts
``tau = (C^T U)^-1 C^T (M' qddot + v' + g')`` with ``U`` the actuated coordinates.

Angular-velocity constraints (eq 101, optional): ``P qdot# - Q w(q°) - R qdot° = 0`` with ``w``
the chain tips' (last links') angular velocities in N, stacked (3n,); they add the rows
``[P, -(Q J_w + R)]`` to A and ``Q dw°`` to b (eqs 104-113) and, in eq 129, the velocity-level
term ``lambda A_w qdot`` only (the document gives them no position-level term).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.linalg import block_diag

from ..errors import FreefloatError
from .serial import SerialChain


@dataclass(frozen=True)
class AngularConstraints:
    """Angular-velocity constraints ``P qdot# - Q w(q°) - R qdot° = 0`` (eq 101).

    Their position form, used to assemble the mechanism and to report orientation drift, needs
    ``P = 0``: ``Q phi(q°) + R q° = offset`` with ``phi`` the tips' rotation vectors
    ``log(R_tip R_ref^T)`` (3n,) in N against the reference orientations ``reference``
    (it differentiates to ``Q w + R qdot°`` where the tips sit at their references).

    Attributes:
        P: (m_w, p); must be zero (a platform that rotates would need orientation coordinates).
        Q: (m_w, 3n) on the stacked tip angular velocities in N.
        R: (m_w, n°) on the chains' joint rates.
        reference: tip reference orientations in N (n, 3, 3).
        offset: ``Q phi + R q°`` on the constraint manifold (m_w,).
    """

    P: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    reference: np.ndarray
    offset: np.ndarray


@dataclass(frozen=True)
class ParallelMechanism:
    """Serial chains joined through a platform.

    Attributes:
        chains: the serial subsystems B_1..B_n.
        platform_mass: ``M_B0`` of the platform coordinates q# (p, p); zero for a massless point.
        platform_gravity: ``g_B0`` (p,), the platform's generalized gravity.
        D, d, E, F: constant constraint matrices of eq 96 ((m, p), (m,), (m, 3n), (m, n°)).
        actuated: indices of the actuated coordinates in ``q`` (k,).
        angular: the angular-velocity constraints, if any.
    """

    chains: tuple[SerialChain, ...]
    platform_mass: np.ndarray
    platform_gravity: np.ndarray
    D: np.ndarray
    d: np.ndarray
    E: np.ndarray
    F: np.ndarray
    actuated: np.ndarray
    angular: AngularConstraints | None = None

    @property
    def p(self) -> int:
        """Number of platform coordinates q#."""
        return self.D.shape[1]

    def split(self, q: np.ndarray) -> list[np.ndarray]:
        """The chains' joint coordinates from ``q = [q#; q°]``."""
        out, start = [], self.p
        for chain in self.chains:
            out.append(q[start:start + chain.dof])
            start += chain.dof
        return out

    def constraint(self, q: np.ndarray) -> np.ndarray:
        """``qbar(q) = D q# - d - E x(q°) - F q°`` (m,)."""
        x = np.concatenate([c.tip(qi) for c, qi in zip(self.chains, self.split(q))])
        return self.D @ q[: self.p] - self.d - self.E @ x - self.F @ q[self.p:]

    def orientation_residual(self, q: np.ndarray) -> np.ndarray:
        """Position form of the angular constraints, ``offset - Q phi - R q°`` (m_w,), rad; empty
        without angular constraints."""
        if self.angular is None:
            return np.zeros(0)
        ang = self.angular
        tips = [c.frames(qi)[0][-1, :3, :3] for c, qi in zip(self.chains, self.split(q))]
        phi = np.concatenate([pin.log3(R @ ref.T) for R, ref in zip(tips, ang.reference)])
        return ang.offset - ang.Q @ phi - ang.R @ q[self.p:]

    def terms(self, q: np.ndarray, qd: np.ndarray):
        """``(A, b, C, M', v', g')`` at (q, qd): constraint Jacobian (m, n_q) and bias (m,) with
        ``A qdd = b`` (linear rows first, then angular); velocity map (n_q, p) with
        ``qd = C qd#``; mass matrix (n_q, n_q), velocity and gravity terms (n_q,). Coordinates
        ordered [q#; chain 1; chain 2; ...]."""
        kins = self._kinematics(q, qd)
        A = self._constraint_jacobian(kins)
        b = self.E @ np.concatenate([k["tip_c"] for k in kins])
        if self.angular is not None:
            b = np.concatenate((b, self.angular.Q @ np.concatenate([k["tip_dw"] for k in kins])))
        dyn = [c.dynamics_from(k) for c, k in zip(self.chains, kins)]
        M = block_diag(self.platform_mass, *[m for m, _, _ in dyn])
        v = np.concatenate([np.zeros(self.p)] + [v for _, v, _ in dyn])
        g = np.concatenate([self.platform_gravity] + [g for _, _, g in dyn])
        return A, b, self._velocity_map(A), M, v, g

    def velocity_map(self, q: np.ndarray) -> np.ndarray:
        """``C`` (n_q, p) with ``qd = C qd#`` on the constraint manifold at ``q``; depends on q only."""
        return self._velocity_map(self._constraint_jacobian(self._kinematics(q, np.zeros_like(q))))

    def _kinematics(self, q: np.ndarray, qd: np.ndarray) -> list[dict]:
        return [c.kinematics(qi, qdi) for c, qi, qdi in zip(self.chains, self.split(q), self.split(qd))]

    def _constraint_jacobian(self, kins: list[dict]) -> np.ndarray:
        Jv = block_diag(*[k["tip_Jv"] for k in kins])
        A = np.hstack((self.D, -(self.E @ Jv + self.F)))
        if self.angular is None:
            return A
        ang = self.angular
        Jw = block_diag(*[k["tip_Jw"] for k in kins])
        return np.vstack((A, np.hstack((ang.P, -(ang.Q @ Jw + ang.R)))))

    def _velocity_map(self, A: np.ndarray) -> np.ndarray:
        return np.vstack((np.eye(self.p), -np.linalg.pinv(A[:, self.p:]) @ A[:, : self.p]))

    def selection(self) -> np.ndarray:
        """``U`` (n_q, k): actuator efforts into the generalized forces u'."""
        U = np.zeros((self.p + sum(c.dof for c in self.chains), len(self.actuated)))
        U[self.actuated, np.arange(len(self.actuated))] = 1.0
        return U

    def forward(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray, baumgarte: float = 0.0) -> np.ndarray:
        """``qddot`` (n_q,) under actuator efforts ``tau`` (k,), eq 129 with lambda = ``baumgarte``."""
        A, b, C, M, v, g = self.terms(q, qd)
        u = self.selection() @ tau
        m = len(self.d)
        rates = A @ qd
        rates[:m] *= 2.0
        rhs_c = b - baumgarte * rates
        rhs_c[:m] -= baumgarte**2 * self.constraint(q)
        return np.linalg.solve(np.vstack((C.T @ M, A)), np.concatenate((C.T @ (u - v - g), rhs_c)))

    def inverse(self, q: np.ndarray, qd_sharp: np.ndarray, qdd_sharp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Actuator efforts for platform motion (eqs 130-140) at an assembled ``q`` (n_q,), from
        the platform rates ``qd_sharp`` and accelerations ``qdd_sharp`` (p,).

        Returns:
            ``(tau, qd, qdd)``: efforts (k,) and the full velocity and acceleration (n_q,).
        """
        qd = self.velocity_map(q) @ qd_sharp
        A, b, C, M, v, g = self.terms(q, qd)
        qdd = C @ qdd_sharp + np.concatenate((np.zeros(self.p), np.linalg.pinv(A[:, self.p:]) @ b))
        tau = np.linalg.solve(C.T @ self.selection(), C.T @ (M @ qdd + v + g))
        return tau, qd, qdd

    def assemble(self, q_sharp: np.ndarray, guess: np.ndarray, tol: float = 1e-12, iterations: int = 50) -> np.ndarray:
        """Solve ``qbar = 0`` (and the angular constraints' position form) for the chains' joints
        at platform coordinates ``q_sharp`` (p,) (Newton from ``guess`` (n_q - p,)); returns the
        assembled ``q`` (n_q,).

        Raises:
            FreefloatError: when it does not converge (pose out of reach or singular), with the
                residual and the platform coordinates.
        """
        q = np.concatenate((q_sharp, guess))
        for _ in range(iterations):
            residual = np.concatenate((self.constraint(q), self.orientation_residual(q)))
            if np.abs(residual).max() < tol:
                return q
            A = self._constraint_jacobian(self._kinematics(q, np.zeros_like(q)))
            q[self.p:] -= np.linalg.lstsq(A[:, self.p:], residual, rcond=None)[0]
        raise FreefloatError(f"cannot assemble the mechanism at platform coordinates {np.round(q_sharp, 6).tolist()}: "
                             f"loop-closure residual {np.abs(self.constraint(q)).max():.3g} m, orientation "
                             f"{np.abs(self.orientation_residual(q)).max(initial=0.0):.3g} rad after {iterations} Newton steps")


def simulate(mechanism: ParallelMechanism, q0: np.ndarray, qd0: np.ndarray, tau, duration: float, step: float,
             baumgarte: float = 0.0, method: str = "rk4") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Classical RK4 (or semi-implicit Euler) on the coupled coordinates (all Euclidean),
    Baumgarte-stabilised. A run that blows up stops there (the arrays end early).

    Args:
        tau: ``tau(t, q, qd) -> efforts`` (k,), held over each step.
        method: ``"rk4"`` or ``"euler"`` (semi-implicit).

    Returns:
        ``(t, q, drift)``: times (N,), coordinates (N, n_q), loop-closure residual max |qbar| (N,).
    """
    steps = int(round(duration / step))
    t = np.arange(steps + 1) * step
    qs, drift = np.empty((steps + 1, len(q0))), np.empty(steps + 1)
    q, qd = np.array(q0, float), np.array(qd0, float)
    qs[0], drift[0] = q, np.abs(mechanism.constraint(q)).max()
    for k in range(steps):
        u = tau(t[k], q, qd)
        f = lambda qq, vv: mechanism.forward(qq, vv, u, baumgarte)  # noqa: E731
        if method == "euler":
            qd = qd + step * f(q, qd)
            q = q + step * qd
            qs[k + 1], drift[k + 1] = q, np.abs(mechanism.constraint(q)).max()
            if not np.isfinite(drift[k + 1]) or drift[k + 1] > 1.0:
                return t[: k + 2], qs[: k + 2], drift[: k + 2]
            continue
        k1q, k1v = qd, f(q, qd)
        k2q, k2v = qd + step / 2 * k1v, f(q + step / 2 * k1q, qd + step / 2 * k1v)
        k3q, k3v = qd + step / 2 * k2v, f(q + step / 2 * k2q, qd + step / 2 * k2v)
        k4q, k4v = qd + step * k3v, f(q + step * k3q, qd + step * k3v)
        q = q + step / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
        qd = qd + step / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        qs[k + 1], drift[k + 1] = q, np.abs(mechanism.constraint(q)).max()
        if not np.isfinite(drift[k + 1]) or drift[k + 1] > 1.0:
            return t[: k + 2], qs[: k + 2], drift[: k + 2]
    return t, qs, drift
