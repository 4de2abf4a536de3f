"""Serial chains from Denavit-Hartenberg parameters by Orsino's subsystem coupling (thesis
proposal sec 5.3, eqs 22-64).

Standard DH: ``B_{i-1} -> B_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)`` with ``theta_i = q_i +
theta0_i`` (revolute) or ``d_i = q_i + d0_i`` (prismatic); eq 22 as printed has
``sin(theta) cos(alpha)`` in entry (1, 3) where the standard matrix (used here) has
``sin(theta) sin(alpha)``. Joint i turns about (or slides along) ``k_{i-1}``. Link i has its
CoM ``g_i`` and inertia ``I_i`` (about the CoM) in frame B_i. The model (eqs 61-64):

.. math::
    M = \\sum_i m_i J_{v,i}^T J_{v,i} + J_{w,i}^T I_i J_{w,i}, \\quad
    v = \\sum_i m_i J_{v,i}^T c_i + J_{w,i}^T (I_i \\dot w_i^0 + w_i \\times I_i w_i), \\quad
    g = -\\sum_i m_i J_{v,i}^T g_N

with ``J_{w,i}`` and ``w_i`` in frame B_i (eqs 44-45), ``c_i`` the velocity-product part of the
CoM acceleration (eq 50) and ``dw_i^0`` that of the angular acceleration (eqs 56, 60), all by the
composition of motions. (Eq 64 as printed lacks the transpose on ``J_{v,i}``.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from freefloat.conventions import cross_rows


def dh_matrix(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """Standard DH homogeneous transform ``Rz(theta) Tz(d) Tx(a) Rx(alpha)`` (4, 4)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct],
                     [st, ct * ca, -ct * sa, a * st],
                     [0.0, sa, ca, d],
                     [0.0, 0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class SerialChain:
    """A serial chain: joint frames ``J_i = B_{i-1} P_i``, link frames ``B_i = J_i Rz(q_i) L_i``
    (revolute about z of J_i) or ``J_i Tz(q_i) L_i`` (prismatic along it), ``B_0`` = ``base``.

    DH rows (:meth:`from_dh`) give ``P_i = I``, ``L_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``;
    a URDF chain gives ``P_i`` = the joint origins and ``L_i = I``.

    Attributes:
        placement: P_i (nu, 4, 4).
        link: L_i (nu, 4, 4).
        prismatic: joint kinds (nu,), False for revolute.
        mass: link masses, kg (nu,).
        com: link CoMs in their frames B_i, m (nu, 3).
        inertia: link inertias about their CoMs in B_i, kg m^2 (nu, 3, 3).
        base: pose of B_0 in the inertial frame N (4, 4).
        tip_point: the end-effector point in B_nu, m (3,).
        gravity: gravity in N, m/s^2 (3,).
    """

    placement: np.ndarray
    link: np.ndarray
    prismatic: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    base: np.ndarray = field(default_factory=lambda: np.eye(4))
    tip_point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @classmethod
    def from_dh(cls, a, alpha, d, theta, prismatic, mass, com, inertia, base=None, gravity=None) -> "SerialChain":
        """A chain from standard DH rows (theta or d is the offset added to the joint coordinate)."""
        n = len(a)
        return cls(placement=np.tile(np.eye(4), (n, 1, 1)),
                   link=np.array([dh_matrix(theta[i], d[i], a[i], alpha[i]) for i in range(n)]),
                   prismatic=np.asarray(prismatic, dtype=bool), mass=np.asarray(mass, float), com=np.asarray(com, float),
                   inertia=np.asarray(inertia, float), base=np.eye(4) if base is None else np.asarray(base, float),
                   gravity=np.zeros(3) if gravity is None else np.asarray(gravity, float))

    @property
    def dof(self) -> int:
        return len(self.mass)

    def frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Link frames ``[1]^H_{N|B_i}`` for i = 0..nu (nu + 1, 4, 4) (eq 23) and joint frames
        J_i (nu, 4, 4), all in N."""
        links, joints = [self.base], []
        for i in range(self.dof):
            J = links[-1] @ self.placement[i]
            motion = dh_matrix(0.0, q[i], 0.0, 0.0) if self.prismatic[i] else dh_matrix(q[i], 0.0, 0.0, 0.0)
            joints.append(J)
            links.append(J @ motion @ self.link[i])
        return np.array(links), np.array(joints)

    def tip(self, q: np.ndarray) -> np.ndarray:
        """End-effector point in N (3,), eq 25 (``o_nu`` for DH chains)."""
        B = self.frames(q)[0][-1]
        return B[:3, :3] @ self.tip_point + B[:3, 3]

    def kinematics(self, q: np.ndarray, qd: np.ndarray):
        """Everything eqs 26-60 give at (q, qd).

        Returns:
            dict with ``frames`` (nu+1, 4, 4); ``g`` CoMs in N (nu, 3); ``Jv`` CoM Jacobians in N
            (nu, 3, nu); ``Jw_N`` angular Jacobians in N (nu, 3, nu); ``Jw`` in B_i (nu, 3, nu);
            ``c`` CoM acceleration bias in N (nu, 3); ``dw0`` angular acceleration bias in B_i
            (nu, 3); ``tip_Jv`` (3, nu) and ``tip_c`` (3,) of the end-effector point; ``tip_Jw``
            (3, nu) and ``tip_dw`` (3,), angular Jacobian and acceleration bias of the last link
            in N; ``w`` link angular velocities in B_i (nu, 3).
        """
        n = self.dof
        H, J = self.frames(q)
        k = J[:, :3, 2]                                     # joint axes in N (n, 3): k_{j-1} of DH
        o = J[:, :3, 3]                                     # points on them (n, 3): o_{j-1} of DH
        g = np.einsum("nij,nj->ni", H[1:, :3, :3], self.com) + H[1:, :3, 3]
        x = H[-1, :3, :3] @ self.tip_point + H[-1, :3, 3]
        rev = ~np.asarray(self.prismatic, dtype=bool)
        lower = np.tril(np.ones((n, n), dtype=bool))        # joint j moves link i iff j <= i

        def point_jacobian(points: np.ndarray, mask: np.ndarray) -> np.ndarray:
            lever = points[:, None, :] - o[None, :, :]
            cols = np.where(rev[None, :, None], cross_rows(k[None], lever), k[None])
            return (cols * mask[:, :, None]).transpose(0, 2, 1)

        Jv = point_jacobian(g, lower)
        Jw_N = (np.where(rev[None, :, None], k[None], 0.0) * lower[:, :, None]).transpose(0, 2, 1)
        R = H[1:, :3, :3]
        Jw = np.einsum("nji,njk->nik", R, Jw_N)
        # angular velocity of link j-1 (frame B_{j-1}) in N: w_{j-1} = sum_{l < j} k_{l-1} qd_l (revolute)
        w_N = np.cumsum(np.where(rev[:, None], k * qd[:, None], 0.0), axis=0)        # w_j for j = 1..n
        w_prev = np.vstack((np.zeros(3), w_N[:-1]))                                   # w_{j-1}
        tip_Jv = point_jacobian(x[None], np.ones((1, n), dtype=bool))[0]

        def bias(points: np.ndarray, jac: np.ndarray, mask: np.ndarray) -> np.ndarray:
            # eq 50: sum_j k x (k x (p - o_{j-1})) qd_j^2 (revolute) + 2 w_{j-1} x j_v,j qd_j
            lever = points[:, None, :] - o[None, :, :]
            centripetal = np.where(rev[None, :, None], cross_rows(k[None], cross_rows(k[None], lever)), 0.0) * (qd**2)[None, :, None]
            coriolis = 2.0 * cross_rows(w_prev[None], jac.transpose(0, 2, 1)) * qd[None, :, None]
            return ((centripetal + coriolis) * mask[:, :, None]).sum(axis=1)

        c = bias(g, Jv, lower)
        tip_c = bias(x[None], tip_Jv[None], np.ones((1, n), dtype=bool))[0]
        # eq 56: dw_i^0 = sum_{j <= i} w_{j-1} x k_{j-1} qd_j (revolute), then to B_i (eq 60)
        terms = np.where(rev[:, None], cross_rows(w_prev, k) * qd[:, None], 0.0)
        dw0_N = np.cumsum(terms, axis=0)
        dw0 = np.einsum("nji,nj->ni", R, dw0_N)
        w = np.einsum("nji,nj->ni", R, w_N)
        return {"frames": H, "g": g, "Jv": Jv, "Jw_N": Jw_N, "Jw": Jw, "c": c, "dw0": dw0,
                "tip_Jv": tip_Jv, "tip_c": tip_c, "tip_Jw": Jw_N[-1], "tip_dw": dw0_N[-1], "w": w}

    def dynamics(self, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(M, v, g)`` of eqs 61-64: (nu, nu), (nu,), (nu,)."""
        return self.dynamics_from(self.kinematics(q, qd))

    def dynamics_from(self, kin: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(M, v, g)`` of eqs 61-64 from :meth:`kinematics` already evaluated at (q, qd)."""
        Jv, Jw, m, inertia = kin["Jv"], kin["Jw"], self.mass, self.inertia
        M = np.einsum("n,nki,nkj->ij", m, Jv, Jv) + np.einsum("nki,nkl,nlj->ij", Jw, inertia, Jw)
        Iw = np.einsum("nkl,nl->nk", inertia, kin["w"])
        torque = np.einsum("nkl,nl->nk", inertia, kin["dw0"]) + cross_rows(kin["w"], Iw)
        v = np.einsum("n,nki,nk->i", m, Jv, kin["c"]) + np.einsum("nki,nk->i", Jw, torque)
        gvec = -np.einsum("n,nki,k->i", m, Jv, self.gravity)
        return 0.5 * (M + M.T), v, gvec

