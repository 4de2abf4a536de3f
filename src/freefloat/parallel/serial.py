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

Actuator inertias and joint friction (thesis proposal sec 9, items 4-5): a joint driven through a
gear of ratio ``N`` by a rotor of inertia ``J_m`` adds ``N^2 J_m`` (its armature) to ``M``'s
diagonal, the rotor's gyroscopic coupling with the link carrying it neglected (as Pinocchio's
``model.armature``; exact for a motor fixed to the ground, the parallel mechanisms' case); joint
friction (:class:`~freefloat.dynamics.friction.JointFriction`) is a generalised force
``-f(qdot)`` on the joint rows, kept apart from ``v`` (it is not quadratic in the rates).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..dynamics.friction import JointFriction
from ..errors import InvalidArgument
from ..robot.conventions import cross_rows


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
        armature: reflected actuator inertia ``N^2 J_m`` added to M's diagonal (nu,), kg m^2 or kg
            (prismatic); None: none.
        friction: the joints' friction (nu joints); None: none.

    Raises:
        InvalidArgument: for an armature that is not nu finite numbers >= 0, or a friction of
            another number of joints.
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
    armature: np.ndarray | None = None
    friction: JointFriction | None = None

    def __post_init__(self) -> None:
        if self.armature is not None:
            armature = np.asarray(self.armature, dtype=float)
            if armature.shape != (self.dof,) or not (np.isfinite(armature).all() and (armature >= 0.0).all()):
                raise InvalidArgument(f"serial chain: 'armature' must be {self.dof} finite numbers >= 0 (one per joint), "
                                      f"got {np.asarray(self.armature).tolist()}")
            object.__setattr__(self, "armature", armature)
        if self.friction is not None and self.friction.n != self.dof:
            raise InvalidArgument(f"serial chain: 'friction' is for {self.friction.n} joints; the chain has {self.dof}")

    @property
    def rigid(self) -> bool:
        """True without armature or friction (the rigid-body terms of eqs 61-64 alone)."""
        return (self.armature is None or not self.armature.any()) and not self.friction

    def joint_friction(self, qd: np.ndarray) -> np.ndarray:
        """The joints' friction forces ``f(qdot)`` (..., nu), N m or N (zero without friction)."""
        qd = np.asarray(qd, dtype=float)
        return self.friction.force(qd) if self.friction else np.zeros_like(qd)

    @classmethod
    def from_dh(cls, a, alpha, d, theta, prismatic, mass, com, inertia, base=None, gravity=None) -> SerialChain:
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
        """Link frames ``[1]^H_{N|B_i}`` for i = 0..nu (..., nu + 1, 4, 4) (eq 23) and joint frames
        J_i (..., nu, 4, 4), all in N, for joint coordinates ``q`` (..., nu) (any leading batch
        axes). ``J_{i+1} = J_i M(q_i) (L_i P_{i+1})`` with the joint motion ``M`` applied to J's
        columns and the constant products on the right as one matrix product over the batch."""
        q = np.asarray(q, float)
        batch = q.shape[:-1]
        links, joints = [np.broadcast_to(self.base, batch + (4, 4))], []
        J = np.broadcast_to(self.base @ self.placement[0], batch + (4, 4))
        for i in range(self.dof):
            joints.append(J)
            moved = _joint_motion(J, q[..., i], self.prismatic[i])
            links.append(_times_constant(moved, self.link[i]))
            if i + 1 < self.dof:
                J = _times_constant(moved, self.link[i] @ self.placement[i + 1])
        return np.stack(links, axis=-3), np.stack(joints, axis=-3)

    def tip(self, q: np.ndarray) -> np.ndarray:
        """End-effector point in N (..., 3), eq 25 (``o_nu`` for DH chains)."""
        B = self.frames(q)[0][..., -1, :, :]
        return B[..., :3, :3] @ self.tip_point + B[..., :3, 3]

    def kinematics(self, q: np.ndarray, qd: np.ndarray, frames: tuple[np.ndarray, np.ndarray] | None = None):
        """Everything eqs 26-60 give at (q, qd) (..., nu), any leading batch axes (written ``...``
        below, omitted for one point); ``frames``: :meth:`frames` at q, if already evaluated.

        Returns:
            dict with ``frames`` (nu+1, 4, 4); ``g`` CoMs in N (nu, 3); ``Jv`` CoM Jacobians in N
            (nu, 3, nu); ``Jw_N`` angular Jacobians in N (nu, 3, nu); ``Jw`` in B_i (nu, 3, nu);
            ``c`` CoM acceleration bias in N (nu, 3); ``dw0`` angular acceleration bias in B_i
            (nu, 3); ``tip_Jv`` (3, nu) and ``tip_c`` (3,) of the end-effector point; ``tip_Jw``
            (3, nu) and ``tip_dw`` (3,), angular Jacobian and acceleration bias of the last link
            in N; ``w`` link angular velocities in B_i (nu, 3).
        """
        n = self.dof
        qd = np.asarray(qd, float)
        H, J = self.frames(q) if frames is None else frames
        k = J[..., :3, 2]                                   # joint axes in N (..., n, 3): k_{j-1} of DH
        o = J[..., :3, 3]                                   # points on them (..., n, 3): o_{j-1} of DH
        R = H[..., 1:, :3, :3]
        g = (R @ self.com[:, :, None])[..., 0] + H[..., 1:, :3, 3]
        x = H[..., -1, :3, :3] @ self.tip_point + H[..., -1, :3, 3]
        rev = ~np.asarray(self.prismatic, dtype=bool)
        lower = np.tril(np.ones((n, n), dtype=bool))        # joint j moves link i iff j <= i
        k_rev = np.where(rev[:, None], k, 0.0)              # angular part of each joint's axis

        def point_jacobian(points: np.ndarray, mask: np.ndarray) -> np.ndarray:
            return _point_jacobian(points, k, o, rev, mask)

        Jv = point_jacobian(g, lower)
        Jw_N = (k_rev[..., None, :, :] * lower[:, :, None]).swapaxes(-1, -2)
        Rt = R.swapaxes(-1, -2)
        Jw = Rt @ Jw_N
        # angular velocity of link j-1 (frame B_{j-1}) in N: w_{j-1} = sum_{l < j} k_{l-1} qd_l (revolute)
        w_N = np.cumsum(k_rev * qd[..., :, None], axis=-2)                           # w_j for j = 1..n
        w_prev = np.concatenate((np.zeros_like(w_N[..., :1, :]), w_N[..., :-1, :]), axis=-2)
        tip_Jv = point_jacobian(x[..., None, :], np.ones((1, n), dtype=bool))[..., 0, :, :]

        def bias(points: np.ndarray, jac: np.ndarray, mask: np.ndarray) -> np.ndarray:
            # eq 50: sum_j k x (k x (p - o_{j-1})) qd_j^2 (revolute) + 2 w_{j-1} x j_v,j qd_j
            lever = points[..., :, None, :] - o[..., None, :, :]
            kk = k_rev[..., None, :, :]
            centripetal = cross_rows(kk, cross_rows(kk, lever)) * (qd**2)[..., None, :, None]
            coriolis = 2.0 * cross_rows(w_prev[..., None, :, :], jac.swapaxes(-1, -2)) * qd[..., None, :, None]
            return ((centripetal + coriolis) * mask[:, :, None]).sum(axis=-2)

        c = bias(g, Jv, lower)
        tip_c = bias(x[..., None, :], tip_Jv[..., None, :, :], np.ones((1, n), dtype=bool))[..., 0, :]
        # eq 56: dw_i^0 = sum_{j <= i} w_{j-1} x k_{j-1} qd_j (revolute), then to B_i (eq 60)
        dw0_N = np.cumsum(cross_rows(w_prev, k_rev) * qd[..., :, None], axis=-2)
        dw0 = (Rt @ dw0_N[..., None])[..., 0]
        w = (Rt @ w_N[..., None])[..., 0]
        return {"frames": H, "g": g, "Jv": Jv, "Jw_N": Jw_N, "Jw": Jw, "c": c, "dw0": dw0,
                "tip_Jv": tip_Jv, "tip_c": tip_c, "tip_Jw": Jw_N[..., -1, :, :], "tip_dw": dw0_N[..., -1, :], "w": w}

    def tip_jacobians(self, q: np.ndarray, frames: tuple[np.ndarray, np.ndarray] | None = None):
        """What assembly needs, from one pass over the frames at ``q`` (..., nu) (``frames``:
        :meth:`frames` at q, if already evaluated): the tip point (..., 3) and the last link's
        rotation (..., 3, 3) in N, the tip's linear Jacobian and the last link's angular Jacobian
        (..., 3, nu), in N."""
        H, J = self.frames(q) if frames is None else frames
        k, o = J[..., :3, 2], J[..., :3, 3]
        rev = ~np.asarray(self.prismatic, dtype=bool)
        x = H[..., -1, :3, :3] @ self.tip_point + H[..., -1, :3, 3]
        Jv = _point_jacobian(x[..., None, :], k, o, rev, np.ones((1, self.dof), dtype=bool))[..., 0, :, :]
        return x, H[..., -1, :3, :3], Jv, np.where(rev[:, None], k, 0.0).swapaxes(-1, -2)

    def dynamics(self, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(M, v, g)`` of eqs 61-64: (..., nu, nu), (..., nu), (..., nu)."""
        return self.dynamics_from(self.kinematics(q, qd))

    def dynamics_from(self, kin: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(M, v, g)`` of eqs 61-64 from :meth:`kinematics` already evaluated at (q, qd); M with
        the armature on its diagonal."""
        m, inertia, nu = self.mass, self.inertia, self.dof
        # stack the links' rows: (..., nu, 3, nu) -> (..., 3 nu, nu), so each sum over links is one matmul
        Jv = kin["Jv"].reshape(kin["Jv"].shape[:-3] + (3 * nu, nu))
        Jw = kin["Jw"].reshape(Jv.shape)
        JvT, JwT = Jv.swapaxes(-1, -2), Jw.swapaxes(-1, -2)
        mass_rows = np.repeat(m, 3)
        IJw = (inertia @ kin["Jw"]).reshape(Jv.shape)
        M = JvT @ (mass_rows[:, None] * Jv) + JwT @ IJw
        w = kin["w"]
        torque = (inertia @ kin["dw0"][..., None])[..., 0] + cross_rows(w, (inertia @ w[..., None])[..., 0])
        force = m[:, None] * kin["c"]
        v = (JvT @ force.reshape(force.shape[:-2] + (3 * nu, 1)) + JwT @ torque.reshape(force.shape[:-2] + (3 * nu, 1)))[..., 0]
        gvec = -(JvT @ (mass_rows * np.tile(self.gravity, nu)))
        M = 0.5 * (M + M.swapaxes(-1, -2))
        if self.armature is not None:
            M = M + np.diag(self.armature)
        return M, v, gvec


def _point_jacobian(points: np.ndarray, k: np.ndarray, o: np.ndarray, rev: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Linear Jacobians (..., P, 3, n) in N of points (..., P, 3) on a chain with joint axes ``k``
    through ``o`` (..., n, 3), revolute where ``rev`` (n,); ``mask`` (P, n) says which joints move
    which point."""
    lever = points[..., :, None, :] - o[..., None, :, :]
    cols = np.where(rev[:, None], cross_rows(k[..., None, :, :], lever), k[..., None, :, :])
    return (cols * mask[:, :, None]).swapaxes(-1, -2)


def _joint_motion(J: np.ndarray, q: np.ndarray, prismatic: bool) -> np.ndarray:
    """``J Tz(q)`` or ``J Rz(q)`` (..., 4, 4) for frames J (..., 4, 4) and coordinates q (...)."""
    out = J.copy()
    if prismatic:
        out[..., :3, 3] += J[..., :3, 2] * q[..., None]
    else:
        c, s = np.cos(q)[..., None], np.sin(q)[..., None]
        out[..., :, 0] = J[..., :, 0] * c + J[..., :, 1] * s
        out[..., :, 1] = J[..., :, 1] * c - J[..., :, 0] * s
    return out


def _times_constant(A: np.ndarray, C: np.ndarray) -> np.ndarray:
    """``A C`` for matrices A (..., 4, 4) and one constant C (4, 4), as a single BLAS product."""
    return (A.reshape(-1, 4) @ C).reshape(A.shape)
