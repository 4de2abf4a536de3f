"""Identification of a closed chain's dynamic parameters: the spanning tree's regressor carried
through the closures by Orsino's coupling (thesis proposal eqs 120-140), then least squares.

The spanning tree's joint efforts are linear in its bodies' parameters, ``tau_tree = Y pi``
(Pinocchio's ``computeJointTorqueRegressor``, :mod:`freefloat.dynamics.identification`). In
Orsino's coordinates ``q = [q#; q°]`` the generalised forces are ``u' = S Y pi`` (``S`` (n_q, nv)
places each tree joint's effort on its coordinate; the platform of a tip-to-tip mechanism is a
massless point, so it adds nothing), and the coupled dynamics (eq 124 with eq 137's actuation,
``C^T u' = C^T U tau``) eliminate the constraint forces:

.. math:: u^* = C^T S\\, Y(q°, \\dot q°, \\ddot q°)\\, \\pi = Y^*\\, \\pi, \\qquad
          \\tau = (C^T U)^{-1}\\, Y^*\\, \\pi,

``Y*`` (p, 10 nb) the platform regressor (what eq 137's ``H qddot# + v_M + g_M`` is linear in)
and ``(C^T U)^-1 Y*`` (k, 10 nb) the actuator regressor, with ``qdot = C qdot#`` and ``qddot =
C qddot# + [0; A°^+ b]`` (eqs 120, 130). The closure makes more combinations unidentifiable
than the open tree has (a point mass at the closure point belongs to either chain), so the
estimate is in the structural base parameters of the actuator regressor.

:class:`RegressorModel` is the same regressor as the gain design's
:class:`~freefloat.parallel.gain_design.LinearParameterModel`: its parameters are the base
parameters, their nominal values and intervals an identification's (eqs 156-170 then take the
uncertainty that the data leave).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ..dynamics.identification.base import BaseParameters, base_parameters, preferred_order
from ..dynamics.identification.least_squares import Estimate, fit
from ..dynamics.identification.parameters import parameter_names, with_parameters
from ..errors import FreefloatError
from .closed_chain import ClosedChain, chain_from_tree
from .mechanism import ParallelMechanism


def effort_map(chain: ClosedChain) -> np.ndarray:
    """``S`` (n_q, nv): tree joint efforts (Pinocchio's velocity order) into Orsino's generalised
    forces ``u'``.

    Raises:
        FreefloatError: for a platform with mass (its dynamics are not in the tree's regressor).
    """
    mech, model = chain.mechanism, chain.model
    if np.any(mech.platform_mass != 0.0) or np.any(mech.platform_gravity != 0.0):
        raise FreefloatError("closed-chain regressor: the platform has mass; this regressor covers tip-to-tip "
                             "mechanisms whose platform is a massless point")
    S = np.zeros((mech.n_q, model.nv))
    for joint, coordinate in chain.joint_coordinates.items():
        S[coordinate, model.idx_vs[joint]] += 1.0
    return S


def platform_regressor(chain: ClosedChain, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                       data: pin.Data | None = None) -> np.ndarray:
    """``Y*`` (p, 10 nb) at one assembled state: Orsino's q, qdot, qddot (n_q,) each, on the
    constraint manifold (module docstring)."""
    model = chain.model
    data = model.createData() if data is None else data
    Y = pin.computeJointTorqueRegressor(model, data, chain.pinocchio_q(q), chain.pinocchio_q(qd),
                                        chain.pinocchio_q(qdd))
    return chain.mechanism.velocity_map(q).T @ effort_map(chain) @ Y


def actuator_regressor(chain: ClosedChain, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                       data: pin.Data | None = None) -> np.ndarray:
    """``(C^T U)^-1 Y*`` (k, 10 nb) at one assembled state, stacked sample-major for states
    (N, n_q) each ((N k, 10 nb)): the actuator efforts are this times the tree's parameters."""
    mech = chain.mechanism
    data = chain.model.createData() if data is None else data
    rows = []
    for qk, qdk, qddk in zip(np.atleast_2d(q), np.atleast_2d(qd), np.atleast_2d(qdd)):
        B = mech.velocity_map(qk).T @ mech.selection()
        rows.append(np.linalg.solve(B, platform_regressor(chain, qk, qdk, qddk, data)))
    return np.vstack(rows)


def platform_states(chain: ClosedChain, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray,
                    guess: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, qdot, qddot)`` (N, n_q) each along platform coordinates x, rates xd and accelerations
    xdd (N, p): the chain assembled point after point from ``guess`` (n_q - p,)
    (:meth:`~freefloat.parallel.mechanism.ParallelMechanism.inverse_trajectory`), then eqs 120 and
    130.

    Raises:
        FreefloatError: where the chain does not assemble or its joint path jumps.
    """
    mech = chain.mechanism
    _, q = mech.inverse_trajectory(x, xd, xdd, guess)
    _, qd, qdd = mech.reference().inverse(q, np.asarray(xd, float), np.asarray(xdd, float))
    return q, qd, qdd


def structural_base(chain: ClosedChain, points: np.ndarray, guess: Callable[[np.ndarray], np.ndarray],
                    rng: np.random.Generator) -> BaseParameters:
    """The base parameters of the actuator regressor from states at ``points`` (N, p) (assembled
    from ``guess(point)``) with standard normal platform rates and accelerations: random states
    over the workspace, so every dependency found is the structure's."""
    mech = chain.mechanism
    q = np.array([mech.assemble(point, guess(point)) for point in np.asarray(points, float)])
    xd, xdd = rng.normal(size=(len(q), mech.p)), rng.normal(size=(len(q), mech.p))
    _, qd, qdd = mech.reference().inverse(q, xd, xdd)
    return base_parameters(actuator_regressor(chain, q, qd, qdd), parameter_names(chain.model),
                           order=preferred_order(chain.model.njoints - 1))


def identify(chain: ClosedChain, base: BaseParameters, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
             tau: np.ndarray, weighting: str = "block") -> Estimate:
    """The base parameters' estimate from measured assembled states q, qd, qdd (N, n_q) and
    actuator efforts tau (N, k) (:func:`~freefloat.dynamics.identification.least_squares.fit`, one
    block of k rows per sample)."""
    W = base.regressor(actuator_regressor(chain, q, qd, qdd))
    tau = np.asarray(tau, float)
    return fit(W, tau.ravel(), tau.shape[1], base.labels(), weighting)


def with_tree_parameters(chain: ClosedChain, parameters: np.ndarray) -> ParallelMechanism:
    """Orsino's mechanism of ``chain`` with the tree's bodies set to ``parameters`` (10 nb,)
    (e.g. :meth:`~freefloat.dynamics.identification.base.BaseParameters.preimage` of an
    estimate): each chain rebuilt from the tree (:func:`~.closed_chain.chain_from_tree`) to its
    closure frame, in the closure file's order, the coupling unchanged."""
    model = with_parameters(chain.model, parameters)
    tips = list(dict.fromkeys(name for closure in chain.closures for name in closure.frames))
    return replace(chain.mechanism, chains=tuple(chain_from_tree(model, model.getFrameId(tip))[0] for tip in tips))


@dataclass(frozen=True, eq=False)
class RegressorModel:
    """A closed chain as a :class:`~freefloat.parallel.gain_design.LinearParameterModel` whose
    parameters are its base parameters: ``pi(theta) = theta``, and H, g_M and delta_ij's
    coefficients (eq 162) from the platform regressor ``Y*`` restricted to them, by
    ``H e_i = Y*(q, 0, C e_i + 0) - g``, ``g = Y*(q, 0, 0)`` and the polarisation of
    ``v_M(qdot#) = Y*(q, C qdot#, [0; A°^+ b]) - g``.

    Attributes:
        chain: the mechanism (its geometry; its inertias play no part).
        base: the base parameters.
        nominal: their values theta^ (r,), e.g. an identification's estimate.
        uncertainty: half-widths of their intervals (r,).
        guess: ``q# (p,) -> q° (n_q - p,)``, Newton's start for :meth:`assemble`.
    """

    chain: ClosedChain
    base: BaseParameters
    nominal: np.ndarray
    uncertainty: np.ndarray
    guess: Callable[[np.ndarray], np.ndarray]

    @classmethod
    def identified(cls, chain: ClosedChain, base: BaseParameters, estimate: Estimate,
                   guess: Callable[[np.ndarray], np.ndarray], level: float = 0.95, joint: bool = True) -> RegressorModel:
        """The model an identification leaves: nominal the estimate, intervals its ``level``
        confidence half-widths (``joint``: the box enclosing the joint confidence ellipsoid, so
        that the true parameter vector lies inside with that probability, which is what a
        worst-case design needs; else each parameter's own interval)."""
        return cls(chain, base, estimate.values.copy(), estimate.half_width(level, joint), guess)

    @property
    def names(self) -> tuple[str, ...]:
        return self.base.labels()

    @property
    def p(self) -> int:
        return self.chain.mechanism.p

    def linear_parameters(self, theta: np.ndarray) -> np.ndarray:
        """The base parameters themselves (r,)."""
        return np.asarray(theta, float)

    def assemble(self, point: np.ndarray) -> np.ndarray:
        return self.chain.mechanism.assemble(point, self.guess(point))

    @functools.cached_property
    def _data(self) -> pin.Data:
        return self.chain.model.createData()

    def _regressor(self, q: np.ndarray, xd: np.ndarray, xdd: np.ndarray) -> np.ndarray:
        """``Y*`` on the base parameters (p, r) at assembled q, platform rates and accelerations."""
        _, qd, qdd = self.chain.mechanism.reference().inverse(q, xd, xdd)
        return self.base.regressor(platform_regressor(self.chain, q, qd, qdd, self._data))

    def coefficients(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        """At assembled q (n_q,): H (r, p, p), g_M (r, p), delta_ij {(i, j): (r, p)}, i >= j."""
        p, zero, unit = self.p, np.zeros(self.p), np.eye(self.p)
        g = self._regressor(q, zero, zero)
        H = np.stack([self._regressor(q, zero, unit[i]) - g for i in range(p)], axis=1)   # (p rows, p cols, r)
        single = [self._regressor(q, unit[i], zero) - g for i in range(p)]
        quad = {}
        for i in range(p):
            quad[(i, i)] = single[i].T
            for j in range(i):
                quad[(i, j)] = (self._regressor(q, unit[i] + unit[j], zero) - g - single[i] - single[j]).T
        return H.transpose(2, 0, 1), g.T, quad
