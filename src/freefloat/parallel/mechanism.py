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
``tau = (C^T U)^-1 C^T (M' qddot + v' + g')`` with ``U`` the actuated coordinates. With more
actuators than platform coordinates (redundant actuation, ``Z^T = C^T U`` wide) the efforts are
shared by the mechanism's :class:`~freefloat.parallel.redundancy.EffortDistribution` (minimum norm
unless it says otherwise).

Angular-velocity constraints (eq 101, optional): ``P qdot# - Q w(q°) - R qdot° = 0`` with ``w``
the chain tips' (last links') angular velocities in N, stacked (3n,); they add the rows
``[P, -(Q J_w + R)]`` to A and ``Q dw°`` to b (eqs 104-113) and, in eq 129, the velocity-level
term ``lambda A_w qdot`` only (the document gives them no position-level term). ``P != 0``
(eq 102's platform with orientation coordinates, e.g. the angle of a planar platform) makes the
angular rows tie those coordinates to the tips' orientations; with constant ``P``, an orientation
coordinate is an angle about a fixed axis of N.

Actuator inertias and joint friction (the chains' ``armature`` and ``friction``,
:class:`~freefloat.parallel.serial.SerialChain`): the armature is part of ``M'``; the friction
``f(qdot)`` (zero on q#) is a generalised force beside the actuators', ``u' = U tau - f``, so
eq 129 reads ``C^T (M' qddot + v' + g' + f) = C^T U tau`` and the inverse dynamics gives the
efforts that overcome it too. The compiled core has neither: a mechanism with them runs its
rigid-body terms (``M'`` without armature, ``v'``, ``g'``, A, b, the closure) in the compiled core
and adds them here (:attr:`ParallelMechanism.rigid`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

import numpy as np

from ..dynamics._core import MechanismCore
from ..errors import FreefloatError, UnknownName
from .redundancy import EffortDistribution
from .serial import SerialChain


@dataclass(frozen=True)
class AngularConstraints:
    """Angular-velocity constraints ``P qdot# - Q w(q°) - R qdot° = 0`` (eq 101).

    Their position form, used to assemble the mechanism and to report orientation drift:
    ``P q# + offset - Q phi(q°) - R q° = 0`` with ``phi`` the tips' rotation vectors
    ``log(R_tip R_ref^T)`` (3n,) in N against the reference orientations ``reference``. It
    differentiates to the velocity form where ``d phi / dt = w``: where the tips sit at their
    references (``P = 0``, the platform only translates), and wherever each row's tips turn about
    one fixed axis of N that the row's Q reads (a planar platform, ``P != 0``: the row ties its
    angle coordinate in q# to the tips' angle about the plane's normal, eq 102). An angle is
    recovered within (-pi, pi) only (``log``).

    Attributes:
        P: (m_w, p) on the platform rates (eq 102); zero for a platform that only translates.
        Q: (m_w, 3n) on the stacked tip angular velocities in N.
        R: (m_w, n°) on the chains' joint rates.
        reference: tip reference orientations in N (n, 3, 3).
        offset: ``Q phi + R q° - P q#`` on the constraint manifold (m_w,).
    """

    P: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    reference: np.ndarray
    offset: np.ndarray

    def __post_init__(self) -> None:
        rows = len(self.offset)
        n_tips = len(self.reference)
        if self.P.ndim != 2 or self.P.shape[0] != rows or self.Q.shape != (rows, 3 * n_tips) or self.R.shape[0] != rows \
                or self.reference.shape != (n_tips, 3, 3):
            raise FreefloatError(f"angular constraints: shapes do not agree: P {self.P.shape}, Q {self.Q.shape}, "
                                 f"R {self.R.shape}, reference {self.reference.shape}, offset {self.offset.shape} "
                                 f"(Q needs 3 columns per tip reference, every matrix one row per offset)")


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
        distribution: how :meth:`inverse` (and the platform laws) share a required platform force
            among the actuators; None: the square solve when there are as many actuators as
            platform coordinates, the minimum-norm efforts when there are more.
        backend: ``"compiled"`` (default): one point at a time (:meth:`forward`, :meth:`inverse`
            and :meth:`assemble` at one q, :meth:`inverse_trajectory`) runs in the compiled core
            (``cpp/chains/mechanism.hpp``) when A° is square; ``"numpy"``: everything in this module and
            serial.py, the reference. Batched calls always use numpy.
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
    distribution: EffortDistribution | None = None
    backend: str = "compiled"

    def __post_init__(self) -> None:
        if self.backend not in BACKENDS:
            raise UnknownName("mechanism backend", self.backend, BACKENDS)
        if self.angular is not None:
            expected = {"P": (self.p,), "Q": (3 * len(self.chains),), "R": (sum(c.dof for c in self.chains),)}
            for name, columns in expected.items():
                if getattr(self.angular, name).shape[1:] != columns:
                    raise FreefloatError(f"angular constraints: {name} has {getattr(self.angular, name).shape[1]} columns; "
                                         f"this mechanism needs {columns[0]} ({self.p} platform coordinates, "
                                         f"{len(self.chains)} chains of {sum(c.dof for c in self.chains)} joints)")

    @property
    def core(self) -> MechanismCore | None:
        """The compiled core of this mechanism, or None: numpy backend, a non-square A°,
        angular constraints with ``P != 0`` (the compiled closure residual has no ``P q#`` term:
        ``cpp/chains/mechanism.cpp``'s ``evaluate_closure``), or armature or friction on a joint (the
        core has neither; see :attr:`rigid`)."""
        return self._compiled if self.rigid else None

    @functools.cached_property
    def _compiled(self) -> MechanismCore | None:
        """The compiled core of the rigid-body terms (no armature, no friction), or None."""
        if self.backend != "compiled" or not self.square or self.rotates:
            return None
        return MechanismCore(*self.core_arrays())

    @property
    def rigid(self) -> bool:
        """True when no joint has armature or friction: everything :attr:`core` computes."""
        return all(c.rigid for c in self.chains)

    def joint_friction(self, qd: np.ndarray) -> np.ndarray:
        """The chains' joint friction forces ``f`` (..., n_q) at rates ``qd`` (..., n_q), zero on
        the platform coordinates, N m or N."""
        qd = np.asarray(qd, dtype=float)
        return np.concatenate([np.zeros(qd.shape[:-1] + (self.p,))]
                              + [c.joint_friction(x) for c, x in zip(self.chains, self.split(qd))], axis=-1)

    def frictionless(self) -> ParallelMechanism:
        """The same mechanism without joint friction (armature kept)."""
        return replace(self, chains=tuple(replace(c, friction=None) for c in self.chains))

    def _armature(self) -> np.ndarray:
        """``M'``'s armature diagonal (n_q,), zero on q#."""
        return np.concatenate([np.zeros(self.p)] + [np.zeros(c.dof) if c.armature is None else c.armature
                                                    for c in self.chains])

    @property
    def redundant(self) -> bool:
        """True when there are more actuators than platform coordinates (k > p)."""
        return len(self.actuated) > self.p

    @property
    def rotates(self) -> bool:
        """True when angular constraints tie orientation coordinates of q# to the tips (``P != 0``)."""
        return self.angular is not None and bool(np.any(self.angular.P != 0.0))

    @property
    def square(self) -> bool:
        """True when A° is square (as many constraints as chain joints): what the compiled paths need."""
        return len(self.d) + (0 if self.angular is None else len(self.angular.offset)) == sum(c.dof for c in self.chains)

    def core_arrays(self) -> tuple[list[dict], dict]:
        """The chains (one dict of arrays each) and the coupling (one dict) that the compiled
        code (the core's ``MechanismCore``, the loop's ``ChainSimulation``) is built from."""
        chains = [{name: getattr(c, name) for name in ("placement", "link", "prismatic", "mass", "com", "inertia", "base",
                                                         "tip_point", "gravity")} for c in self.chains]
        coupling = {"D": self.D, "d": self.d, "E": self.E, "F": self.F, "platform_mass": self.platform_mass,
                    "platform_gravity": self.platform_gravity, "actuated": np.asarray(self.actuated, dtype=np.int64),
                    "offset": None}
        if self.angular is not None:
            coupling.update({name: getattr(self.angular, name) for name in ("P", "Q", "R", "reference", "offset")})
        return chains, coupling

    def __getstate__(self) -> dict:
        """Pickled without the compiled core (rebuilt on first use), so mechanisms travel to
        worker processes."""
        state = self.__dict__.copy()
        state.pop("_compiled", None)
        return state

    def reference(self) -> ParallelMechanism:
        """The same mechanism on the numpy backend (the reference)."""
        return replace(self, backend="numpy")

    def with_gravity(self, gravity: np.ndarray) -> ParallelMechanism:
        """The same mechanism under another gravity (3,), m/s^2, inertial frame (every chain's).

        Raises:
            FreefloatError: for a platform with mass, whose generalized gravity ``g_B0`` is not
                given by a vector alone.
        """
        if np.any(self.platform_mass != 0.0):
            raise FreefloatError("a mechanism whose platform has mass cannot take another gravity here")
        gravity = np.asarray(gravity, dtype=float)
        return replace(self, chains=tuple(replace(c, gravity=gravity.copy()) for c in self.chains))

    def _point_core(self, q: np.ndarray) -> MechanismCore | None:
        """The compiled core of the rigid-body terms when ``q`` is one point, else None."""
        return self._compiled if np.ndim(q) == 1 else None

    @property
    def p(self) -> int:
        """Number of platform coordinates q#."""
        return self.D.shape[1]

    @property
    def n_q(self) -> int:
        """Number of coordinates ``q = [q#; q°]``."""
        return self.p + sum(c.dof for c in self.chains)

    def split(self, q: np.ndarray) -> list[np.ndarray]:
        """The chains' joint coordinates (..., nu_i) from ``q = [q#; q°]`` (..., n_q)."""
        out, start = [], self.p
        for chain in self.chains:
            out.append(q[..., start:start + chain.dof])
            start += chain.dof
        return out

    def constraint(self, q: np.ndarray) -> np.ndarray:
        """``qbar(q) = D q# - d - E x(q°) - F q°`` (..., m) for ``q`` (..., n_q), m."""
        return self._closure(q)[0][..., : len(self.d)]

    def residuals(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(qbar(q), orientation residual)`` (..., m), (..., m_w) from one evaluation of the
        closure (see :meth:`constraint` and :meth:`orientation_residual`)."""
        residual = self._closure(q)[0]
        return residual[..., : len(self.d)], residual[..., len(self.d):]

    def orientation_residual(self, q: np.ndarray) -> np.ndarray:
        """Position form of the angular constraints, ``P q# + offset - Q phi - R q°`` (..., m_w),
        rad; empty without angular constraints."""
        return self._closure(q)[0][..., len(self.d):]

    def terms(self, q: np.ndarray, qd: np.ndarray):
        """``(A, b, C, M', v', g')`` at (q, qd) (..., n_q): constraint Jacobian (..., m, n_q) and
        bias (..., m) with ``A qdd = b`` (linear rows first, then angular); velocity map
        (..., n_q, p) with ``qd = C qd#``; mass matrix (..., n_q, n_q), velocity and gravity
        terms (..., n_q). Coordinates ordered [q#; chain 1; chain 2; ...]; any leading batch axes.
        M' includes the armature; v' has no friction (:meth:`joint_friction`)."""
        if (core := self._point_core(q)) is not None:
            A, b, C, M, v, g = core.terms(q, qd)
            return A, b, C, M + np.diag(self._armature()), v, g
        kins = self._kinematics(q, qd)
        A = self._constraint_jacobian(kins)
        b, blocks, v, g = self._dynamics_terms(kins, np.shape(q)[:-1])
        return A, b, self._velocity_map(A), _block_diag(blocks), v, g

    def _dynamics_terms(self, kins: list[dict], batch: tuple):
        """``(b, blocks of M', v', g')`` from the chains' kinematics (leading batch axes
        ``batch``); ``blocks``: M''s diagonal blocks, platform first."""
        b = np.concatenate([k["tip_c"] for k in kins], axis=-1) @ self.E.T
        if self.angular is not None:
            b = np.concatenate((b, np.concatenate([k["tip_dw"] for k in kins], axis=-1) @ self.angular.Q.T), axis=-1)
        dyn = [c.dynamics_from(k) for c, k in zip(self.chains, kins)]
        blocks = [np.broadcast_to(self.platform_mass, batch + self.platform_mass.shape)] + [m for m, _, _ in dyn]
        v = np.concatenate([np.zeros(batch + (self.p,))] + [v for _, v, _ in dyn], axis=-1)
        g = np.concatenate([np.broadcast_to(self.platform_gravity, batch + (self.p,))] + [g for _, _, g in dyn], axis=-1)
        return b, blocks, v, g

    def velocity_map(self, q: np.ndarray) -> np.ndarray:
        """``C`` (..., n_q, p) with ``qd = C qd#`` on the constraint manifold at ``q``; depends on q only."""
        return self._velocity_map(self._closure(q)[1])

    def _frames(self, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        return [c.frames(qi) for c, qi in zip(self.chains, self.split(q))]

    def _kinematics(self, q: np.ndarray, qd: np.ndarray, frames: list | None = None) -> list[dict]:
        frames = frames or [None] * len(self.chains)
        return [c.kinematics(qi, qdi, f) for c, qi, qdi, f in zip(self.chains, self.split(q), self.split(qd), frames)]

    def _constraint_jacobian(self, kins: list[dict]) -> np.ndarray:
        Jv = _block_diag([k["tip_Jv"] for k in kins])
        D = np.broadcast_to(self.D, Jv.shape[:-2] + self.D.shape)
        A = np.concatenate((D, -(_constant_times(self.E, Jv) + self.F)), axis=-1)
        if self.angular is None:
            return A
        ang = self.angular
        Jw = _block_diag([k["tip_Jw"] for k in kins])
        P = np.broadcast_to(ang.P, Jw.shape[:-2] + ang.P.shape)
        return np.concatenate((A, np.concatenate((P, -(_constant_times(ang.Q, Jw) + ang.R)), axis=-1)), axis=-2)

    def _closure(self, q: np.ndarray, frames: list | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``[qbar; orientation residual]`` (..., m) and the constraint Jacobian A (..., m, n_q)
        at ``q``, from one pass over each chain's frames (what a Newton step needs; ``frames``:
        each chain's :meth:`SerialChain.frames` at q, if already evaluated)."""
        if frames is None and (core := self._point_core(q)) is not None:
            return core.closure(q)
        frames = frames or [None] * len(self.chains)
        tips = [c.tip_jacobians(qi, f) for c, qi, f in zip(self.chains, self.split(q), frames)]
        kins = [{"tip_Jv": Jv, "tip_Jw": Jw} for _, _, Jv, Jw in tips]
        x = np.concatenate([t[0] for t in tips], axis=-1)
        residual = q[..., : self.p] @ self.D.T - self.d - x @ self.E.T - q[..., self.p:] @ self.F.T
        if self.angular is not None:
            ang = self.angular
            phi = np.concatenate([log3(t[1] @ ref.T) for t, ref in zip(tips, ang.reference)], axis=-1)
            residual = np.concatenate((residual, q[..., : self.p] @ ang.P.T + ang.offset - phi @ ang.Q.T
                                       - q[..., self.p:] @ ang.R.T), axis=-1)
        return residual, self._constraint_jacobian(kins)

    def passive_solve(self, A: np.ndarray, rhs: np.ndarray, least_squares: bool = False) -> np.ndarray:
        """``A°^+ rhs`` (..., n°, r) for the constraint Jacobian A (..., m, n_q) and rhs (..., m, r)
        (eqs 120, 130): an LU solve when A° is square, the pseudo-inverse when it is not.

        Raises:
            FreefloatError: when a square A° is singular (a singular pose), unless
                ``least_squares`` (Newton's steps in :meth:`assemble`), which then takes the
                minimum-norm least-squares solution.
        """
        A_passive = A[..., self.p:]
        if A_passive.shape[-1] != A_passive.shape[-2]:
            return np.linalg.pinv(A_passive) @ rhs
        try:
            return np.linalg.solve(A_passive, rhs)
        except np.linalg.LinAlgError:
            if not least_squares:
                raise FreefloatError("the passive joints' constraint Jacobian A° is singular: the mechanism is at a "
                                     "singular pose (C and the inverse dynamics are undefined there)") from None
            return np.linalg.pinv(A_passive) @ rhs

    def _velocity_map(self, A: np.ndarray) -> np.ndarray:
        top = np.broadcast_to(np.eye(self.p), A.shape[:-2] + (self.p, self.p))
        return np.concatenate((top, -self.passive_solve(A, A[..., : self.p])), axis=-2)

    def selection(self) -> np.ndarray:
        """``U`` (n_q, k): actuator efforts into the generalized forces u'."""
        U = np.zeros((self.p + sum(c.dof for c in self.chains), len(self.actuated)))
        U[self.actuated, np.arange(len(self.actuated))] = 1.0
        return U

    def forward(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray, baumgarte: float = 0.0) -> np.ndarray:
        """``qddot`` (n_q,) under actuator efforts ``tau`` (k,), eq 129 with lambda = ``baumgarte``
        (joint friction, if any, beside the efforts)."""
        if (core := self._point_core(q)) is not None:
            if self.rigid:
                return core.forward(q, qd, tau, baumgarte)
            A, b, C, M, v, g = self.terms(q, qd)
            residual = core.closure(q)[0]
        else:
            frames = self._frames(q)
            residual, A = self._closure(q, frames)
            b, blocks, v, g = self._dynamics_terms(self._kinematics(q, qd, frames), ())
            C, M = self._velocity_map(A), _block_diag(blocks)
        u = self.selection() @ tau - self.joint_friction(qd)
        m = len(self.d)
        rates = A @ qd
        rates[:m] *= 2.0
        rhs_c = b - baumgarte * rates
        rhs_c[:m] -= baumgarte**2 * residual[:m]
        return np.linalg.solve(np.vstack((C.T @ M, A)), np.concatenate((C.T @ (u - v - g), rhs_c)))

    def inverse(self, q: np.ndarray, qd_sharp: np.ndarray, qdd_sharp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Actuator efforts for platform motion (eqs 130-140) at assembled ``q`` (..., n_q), from
        the platform rates ``qd_sharp`` and accelerations ``qdd_sharp`` (..., p); any leading
        batch axes (a whole trajectory at once). Shared by :attr:`distribution` (:meth:`efforts`).

        Returns:
            ``(tau, qd, qdd)``: efforts (..., k) and the full velocity and acceleration (..., n_q).

        Raises:
            InfeasiblePlan: where the distribution's effort limits cannot give the motion.
        """
        if self.square_actuation and self.rigid and (core := self._point_core(q)) is not None:
            return core.inverse(q, qd_sharp, qdd_sharp)
        u, ZT, qd, qdd = self.required_force(q, qd_sharp, qdd_sharp)
        return self.efforts(ZT, u), qd, qdd

    @property
    def square_actuation(self) -> bool:
        """As many actuators as platform coordinates and no distribution: efforts by ``(C^T U)^-1``
        (what the compiled core's inverse dynamics and platform law do)."""
        return not self.redundant and self.distribution is None

    def efforts(self, ZT: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Actuator efforts (..., k) giving the platform forces ``u`` (..., p) through the actuation
        maps ``Z^T = C^T U`` (..., p, k) (eq 136): the square solve, or :attr:`distribution`'s
        sharing (minimum norm when it is None and k > p).

        Raises:
            InfeasiblePlan: where the distribution's effort limits cannot give ``u``.
        """
        if self.square_actuation:
            return np.linalg.solve(ZT, u[..., None])[..., 0]
        return (self.distribution or EffortDistribution()).efforts(ZT, u)

    def required_force(self, q: np.ndarray, qd_sharp: np.ndarray,
                       qdd_sharp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """What platform motion asks of the actuators (eqs 130-136) at assembled ``q`` (..., n_q),
        platform rates and accelerations (..., p): ``(u*, Z^T, qd, qdd)`` with ``u* = C^T (M'
        qddot + v' + g' + f)`` (..., p) (``f`` the joint friction), ``Z^T = C^T U`` (..., p, k) and
        the full velocity and acceleration (..., n_q); any efforts with ``Z^T tau = u*`` produce
        the motion."""
        frames = self._frames(q)
        A = self._closure(q, frames)[1]
        C = self._velocity_map(A)
        qd = _matvec(C, qd_sharp)
        b, blocks, v, g = self._dynamics_terms(self._kinematics(q, qd, frames), np.shape(q)[:-1])
        passive = self.passive_solve(A, b[..., None])[..., 0]
        qdd = _matvec(C, qdd_sharp) + np.concatenate((np.zeros(passive.shape[:-1] + (self.p,)), passive), axis=-1)
        Mqdd = np.concatenate([_matvec(M, x) for M, x in zip(blocks, [qdd[..., : self.p]] + self.split(qdd))], axis=-1)
        CT = C.swapaxes(-1, -2)
        return _matvec(CT, Mqdd + v + g + self.joint_friction(qd)), CT @ self.selection(), qd, qdd

    def assemble(self, q_sharp: np.ndarray, guess: np.ndarray, tol: float = 1e-12, iterations: int = 50) -> np.ndarray:
        """Solve ``qbar = 0`` (and the angular constraints' position form) for the chains' joints
        at platform coordinates ``q_sharp`` (..., p) (Newton from ``guess`` (..., n_q - p),
        all points at once); returns the assembled ``q`` (..., n_q).

        Raises:
            FreefloatError: when it does not converge (pose out of reach or singular), with the
                residual and the (first failing) platform coordinates.
        """
        if (core := self._point_core(q_sharp)) is not None and np.ndim(guess) == 1:
            try:
                q, converged = core.assemble(q_sharp, guess, tol, iterations)
            except ValueError:  # wrong sizes: the reference names them
                converged = False
            if converged:
                return q
            return self.reference().assemble(q_sharp, guess, tol, iterations)  # raises, naming the problem
        q_sharp, guess = np.asarray(q_sharp, float), np.asarray(guess, float)
        n_passive = sum(c.dof for c in self.chains)
        if q_sharp.shape[-1:] != (self.p,) or guess.shape[-1:] != (n_passive,):
            raise FreefloatError(f"assemble: platform coordinates need {self.p} entries and the guess {n_passive} "
                                 f"(got shapes {q_sharp.shape} and {guess.shape})")
        if not (np.isfinite(q_sharp).all() and np.isfinite(guess).all()):
            raise FreefloatError("assemble: the platform coordinates or the guess are not finite")
        q = np.concatenate((q_sharp, np.broadcast_to(guess, q_sharp.shape[:-1] + guess.shape[-1:])), axis=-1)
        for _ in range(iterations):
            residual, A = self._closure(q)
            if np.abs(residual).max(initial=0.0) < tol:
                return q
            q[..., self.p:] -= self.passive_solve(A, residual[..., None], least_squares=True)[..., 0]
        worst = np.unravel_index(np.argmax(np.abs(residual).max(axis=-1)), residual.shape[:-1])
        raise FreefloatError(f"cannot assemble the mechanism at platform coordinates {np.round(q_sharp[worst], 6).tolist()}: "
                             f"loop-closure residual {np.abs(self.constraint(q[worst])).max():.3g} m, orientation "
                             f"{np.abs(self.orientation_residual(q[worst])).max(initial=0.0):.3g} rad after {iterations} Newton steps")

    def inverse_trajectory(self, q_sharp: np.ndarray, qd_sharp: np.ndarray, qdd_sharp: np.ndarray, guess: np.ndarray,
                           block: int = 512, jump: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
        """Inverse dynamics along a platform trajectory (N, p) (positions, rates, accelerations),
        block by block (up to ``block`` points at once): each block's Newton starts from the
        first-order prediction ``q°_0 + C°(q_0) (q#_i - q#_0)`` off the previous block's last pose
        ``q_0`` (the first block: off ``guess`` (n_q - p,) assembled at the first point), then
        eqs 130-140 for the whole block. A block whose solution strays more than ``jump`` (rad
        or m) from its prediction (a jump in the joint path: another assembly mode, or joints wound
        by a turn near a singular pose) is halved and redone; a single point that still strays is
        an error. After an accepted block the size doubles again (up to ``block``), so a coarse
        path settles near the largest block it allows instead of falling back to ``block`` and
        halving anew every time. The compiled backend walks the path one point at a time (each
        point's Newton from the prediction off the previous point), with the same jump guard.

        Returns:
            ``(tau, q)``: efforts (N, k) and assembled coordinates (N, n_q).

        Raises:
            FreefloatError: for mismatched or empty inputs, a pose that does not assemble, or a
                jump in the joint path, naming the platform coordinates.
        """
        q_sharp, qd_sharp, qdd_sharp = (np.asarray(a, float) for a in (q_sharp, qd_sharp, qdd_sharp))
        if not len(q_sharp) or not q_sharp.shape == qd_sharp.shape == qdd_sharp.shape == (len(q_sharp), self.p):
            raise FreefloatError(f"inverse_trajectory: positions, rates and accelerations must be non-empty arrays of shape "
                                 f"(N, {self.p}); got {q_sharp.shape}, {qd_sharp.shape}, {qdd_sharp.shape}")
        if self.core is not None and self.square_actuation:
            return self._compiled_trajectory(q_sharp, qd_sharp, qdd_sharp, np.asarray(guess, float), jump)
        q = np.empty((len(q_sharp), self.p + len(guess)))
        tau = np.empty((len(q_sharp), len(self.actuated)))
        anchor, first = self.assemble(q_sharp[0], guess), 0
        size = block
        while first < len(q_sharp):
            rows = slice(first, first + size)
            x = q_sharp[rows]
            predicted = anchor[self.p:] + (x - anchor[: self.p]) @ self.velocity_map(anchor)[self.p:].T
            try:
                q[rows] = self.assemble(x, predicted)
                strays = np.abs(q[rows, self.p:] - predicted).max() > jump
            except FreefloatError:
                if size == 1:
                    raise
                strays = True
            if strays:
                if size == 1:
                    raise FreefloatError(f"inverse_trajectory: at platform coordinates {np.round(x[0], 6).tolist()} the "
                                         f"joint path jumps (another assembly mode, or a turn near a singular pose): "
                                         f"the joints move more than {jump} from the prediction in one step")
                size = max(1, size // 2)
                continue
            tau[rows] = self.inverse(q[rows], qd_sharp[rows], qdd_sharp[rows])[0]
            anchor, first, size = q[first + len(x) - 1], first + len(x), min(block, size + size // 4 + 1)
        return tau, q

    def _compiled_trajectory(self, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray, guess: np.ndarray,
                             jump: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`inverse_trajectory` by the compiled core's continuation, point by point."""
        tau, q, status, index = self.core.trajectory(x, xd, xdd, guess, jump, 1e-12, 50)
        if status == 1:  # the numpy Newton from the same start raises, naming the pose
            self.reference().assemble(x[index], q[index, self.p:])
        if status:
            raise FreefloatError(f"inverse_trajectory: at platform coordinates {np.round(x[index], 6).tolist()} the "
                                 f"joint path jumps (another assembly mode, or a turn near a singular pose): "
                                 f"the joints move more than {jump} from the prediction in one step")
        return tau, q


#: Implementations of the one-point paths: the compiled core (default) and the numpy reference.
BACKENDS = ("compiled", "numpy")


def _matvec(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``A x`` over leading batch axes: (..., m, n) and (..., n) -> (..., m)."""
    return (A @ x[..., None])[..., 0]


def _constant_times(C: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``C X`` for one constant matrix C (r, m) and matrices X (..., m, c), as a single BLAS product."""
    Xt = np.swapaxes(X, -1, -2)
    return np.swapaxes((Xt.reshape(-1, X.shape[-2]) @ C.T).reshape(Xt.shape[:-1] + (C.shape[0],)), -1, -2)


def _block_diag(blocks: list[np.ndarray]) -> np.ndarray:
    """Block-diagonal matrices (..., sum r_i, sum c_i) from blocks (..., r_i, c_i) sharing batch axes."""
    batch = np.broadcast_shapes(*[b.shape[:-2] for b in blocks])
    out = np.zeros(batch + (sum(b.shape[-2] for b in blocks), sum(b.shape[-1] for b in blocks)))
    r = c = 0
    for b in blocks:
        out[..., r:r + b.shape[-2], c:c + b.shape[-1]] = b
        r, c = r + b.shape[-2], c + b.shape[-1]
    return out


def log3(R: np.ndarray) -> np.ndarray:
    """Rotation vectors (..., 3) of rotation matrices (..., 3, 3), for angles below pi (the axis
    is lost at pi itself); the angle from ``atan2(|vee|, (tr - 1) / 2)``, a series below 1e-6 rad."""
    vee = 0.5 * np.stack((R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]), axis=-1)
    sin = np.linalg.norm(vee, axis=-1)
    angle = np.arctan2(sin, 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0))
    small = angle < 1e-6
    scale = np.where(small, 1.0 + angle**2 / 6.0, angle / np.where(small, 1.0, sin))
    return scale[..., None] * vee
