"""The platform dynamics of a closed chain as a regressor on chosen parameters, and its
Slotine-Li form (the regressor an adaptive law needs).

Eq 137's ``H qddot# + v_M + g_M = u*`` is linear in the spanning tree's dynamic parameters
(:mod:`freefloat.parallel.identification`: ``u* = C^T S Y(q°, qdot°, qddot°) pi``, Pinocchio's
``computeJointTorqueRegressor``). With the tree's parameters a linear image of fewer ones,
``pi = P theta`` (the closure's base parameters, or a mechanism's physical combinations),

.. math:: u^* = Y^*(q, \\dot q^\\#, \\ddot q^\\#)\\, \\theta, \\qquad
          Y^* = C^T S\\, Y(q°, C \\dot q^\\#, C \\ddot q^\\# + c(\\dot q^\\#))\\, P,

``c(a) = [0; A°^-1 b(q, C a)]`` (eqs 120, 130). The velocity term ``v_M(a)`` is a quadratic
form in the platform rates. Where q° is a function of q# (A° non-singular) the platform
coordinates are minimal coordinates of a Lagrangian system with kinetic energy
``qdot#^T H qdot# / 2``, so ``v_M(a) = B(a, a)`` with ``B`` the symmetric bilinear form of
H's Christoffel symbols, ``B_i(a, r) = sum_jk Gamma_ijk a_j r_k``, and the matrix
``C#(q, a) r = B(a, r)`` makes ``dH/dt - 2 C#`` skew-symmetric (Slotine and Li, 1987). By
polarisation, from two evaluations of the velocity term:

.. math:: W(q, \\dot q^\\#, \\dot q_r, \\ddot q_r)\\, \\theta = H \\ddot q_r + C^\\#(q, \\dot q^\\#)
          \\dot q_r + g_M, \\qquad
          W = Y^*(q, 0, \\ddot q_r) + \\tfrac14 \\left[Y^*(q, \\dot q^\\# + \\dot q_r, 0)
          - Y^*(q, \\dot q^\\# - \\dot q_r, 0)\\right].

Covers mechanisms whose platform is a massless point joining the chains' tips (the 5R; the
regressor of a massive platform is not the tree's).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..dynamics.identification.base import BaseParameters
from ..dynamics.identification.parameters import PARAMETER_NAMES
from ..errors import BadShape, FreefloatError
from .closed_chain import ClosedChain
from .five_bar import FiveBarParameters
from .identification import effort_map


@dataclass(frozen=True, eq=False)
class PlatformRegressor:
    """``Y*`` and ``W`` (module docstring) of a closed chain on parameters theta (l,).

    Attributes:
        chain: the mechanism (its geometry and coordinates ``q = [q#; q°]``; the tree's inertias
            play no part).
        structure: ``P`` (10 nb, l): the tree's parameters (Pinocchio's order,
            :mod:`~freefloat.dynamics.identification.parameters`) are ``P theta``.
        names: the parameters theta (l,).

    Raises:
        FreefloatError: for a platform with mass (see the module docstring).
        BadShape: for a structure whose rows are not the tree's 10 nb parameters, or names that
            do not match its columns.
    """

    chain: ClosedChain
    structure: np.ndarray
    names: tuple[str, ...]

    def __post_init__(self) -> None:
        rows = 10 * (self.chain.model.njoints - 1)
        if self.structure.ndim != 2 or self.structure.shape[0] != rows or self.structure.shape[1] != len(self.names):
            raise BadShape(f"platform regressor: structure must be ({rows}, {len(self.names)}) (the tree's 10 x "
                           f"{rows // 10} parameters by the {len(self.names)} names), got {self.structure.shape}")
        effort_map(self.chain)  # refuses a platform with mass

    @classmethod
    def base(cls, chain: ClosedChain, base: BaseParameters) -> PlatformRegressor:
        """On the closure's base parameters (:func:`~freefloat.parallel.identification.structural_base`):
        ``P`` selects the independent columns (``W_2 = W_1 K``, so ``Y_1 beta = Y pi``)."""
        P = np.zeros((len(base.names), base.rank))
        P[base.independent, np.arange(base.rank)] = 1.0
        return cls(chain, P, base.labels())

    @property
    def p(self) -> int:
        """Platform coordinates."""
        return self.chain.mechanism.p

    @functools.cached_property
    def _rows(self) -> np.ndarray:
        """Orsino's coordinate of each of Pinocchio's velocity indices (nv,): ``S^T C = C[rows]``."""
        S = effort_map(self.chain)
        return np.argmax(S, axis=0)

    @functools.cached_property
    def _data(self) -> pin.Data:
        return self.chain.model.createData()

    def _tree(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """``Y P`` (nv, l) at Orsino's q, qdot, qddot (n_q,) each."""
        rows = self._rows
        return pin.computeJointTorqueRegressor(self.chain.model, self._data, q[rows], qd[rows], qdd[rows]) @ self.structure

    def _velocity_parts(self, q: np.ndarray, C: np.ndarray, rates: list[np.ndarray]) -> list[np.ndarray]:
        """``Y*(q, a, 0)`` (p, l) for each platform rate ``a`` of ``rates``: ``v_M(a) + g_M`` on
        theta, the chain's accelerations ``c(a)`` from one solve."""
        mech = self.chain.mechanism
        velocities = [C @ a for a in rates]
        A, b = None, []
        for qd in velocities:
            A, bias = _terms(mech, q, qd)
            b.append(bias)
        passive = mech.passive_solve(A, np.array(b).T)
        top, rows = np.zeros(mech.p), self._rows
        return [C[rows].T @ self._tree(q, qd, np.concatenate((top, c))) for qd, c in zip(velocities, passive.T)]

    def velocity_map(self, q: np.ndarray) -> np.ndarray:
        """``C`` (n_q, p) at assembled q (n_q,)."""
        return self.chain.mechanism.velocity_map(q)

    def platform(self, q: np.ndarray, qd_sharp: np.ndarray, qdd_sharp: np.ndarray) -> np.ndarray:
        """``Y*`` (p, l) at assembled q (n_q,), platform rates and accelerations (p,) each:
        ``Y* theta = H qdd# + v_M(qd#) + g_M``."""
        C = self.velocity_map(q)
        moving, still = self._velocity_parts(q, C, [qd_sharp, np.zeros(self.p)])
        return C[self._rows].T @ self._tree(q, np.zeros(len(q)), C @ qdd_sharp) + moving - still

    def slotine_li(self, q: np.ndarray, qd_sharp: np.ndarray, qd_r: np.ndarray, qdd_r: np.ndarray) -> np.ndarray:
        """``W`` (p, l) at assembled q (n_q,), platform rates ``qd_sharp`` and reference rates and
        accelerations ``qd_r``, ``qdd_r`` (p,) each: ``W theta = H qdd_r + C#(q, qd#) qd_r + g_M``
        (module docstring)."""
        C = self.velocity_map(q)
        plus, minus = self._velocity_parts(q, C, [qd_sharp + qd_r, qd_sharp - qd_r])
        return C[self._rows].T @ self._tree(q, np.zeros(len(q)), C @ qdd_r) + 0.25 * (plus - minus)


def _terms(mech, q: np.ndarray, qd: np.ndarray):
    """``(A, b)`` at (q, qd) (m, n_q), (m,): the compiled core's when the mechanism has one."""
    core = mech.core
    return core.terms(q, qd)[:2] if core is not None else mech.terms(q, qd)[:2]


#: The 5R's base parameters (both chains alike, CoMs on the links): link 1's first moment and
#: inertia about its joint with link 2's mass lumped at the elbow (``l1`` from the joint), then
#: link 2's first moment and inertia about the elbow (kg m, kg m^2, kg m, kg m^2). Link 1 turns
#: about a fixed axis, so its mass acts only through its moments, and link 2's mass only as a
#: point at the elbow: these four combinations are all the platform dynamics can tell apart.
FIVE_BAR_NAMES = ("m1 lg1 + l1 m2", "m1 lg1^2 + Jz1 + l1^2 m2", "m2 lg2", "m2 lg2^2 + Jz2")


def five_bar_theta(p: FiveBarParameters) -> np.ndarray:
    """The 5R's :data:`FIVE_BAR_NAMES` (4,) of parameters ``p``: a linear image of the gain
    design's :func:`~freefloat.parallel.sliding_mode.base_parameters`."""
    return np.array([p.m1 * p.lg1 + p.l1 * p.m2, p.m1 * p.lg1**2 + p.Jz1 + p.l1**2 * p.m2, p.m2 * p.lg2,
                     p.m2 * p.lg2**2 + p.Jz2])


def five_bar_regressor(chain: ClosedChain) -> PlatformRegressor:
    """The 5R's platform regressor on :data:`FIVE_BAR_NAMES`: each of the tree's links
    ``c<i>_joint<k>`` takes ``mcx`` and ``Izz`` (about its joint) from theta and no mass (link 2's
    is in link 1's moments), the CoM on the link's x axis as
    :func:`~freefloat.parallel.registry.five_bar_inertias` writes it (the other moments do not act
    on joints about z).

    Raises:
        FreefloatError: for a tree without the joints ``c1_joint1`` ... ``c2_joint2``.
    """
    model = chain.model
    P = np.zeros((10 * (model.njoints - 1), len(FIVE_BAR_NAMES)))
    for arm in ("c1", "c2"):
        for link in (1, 2):
            name = f"{arm}_joint{link}"
            if not model.existJointName(name):
                raise FreefloatError(f"5R regressor: the tree has no joint '{name}' (joints: {list(model.names)[1:]})")
            first = 10 * (model.getJointId(name) - 1)
            P[first + PARAMETER_NAMES.index("mcx"), 2 * (link - 1)] = 1.0
            P[first + PARAMETER_NAMES.index("Izz"), 2 * (link - 1) + 1] = 1.0
    return PlatformRegressor(chain, P, FIVE_BAR_NAMES)
