"""Identification of a kinematic tree's (a robot's) base parameters from measured joint efforts:
the joint-torque regressor (:mod:`.regressors`) at the measured states, restricted to the
structural base parameters (:mod:`.base`), and least squares with its noise covariance per
sample (:mod:`.least_squares`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...errors import BadShape
from .base import BaseParameters, base_parameters, preferred_order
from .least_squares import Estimate, fit
from .parameters import parameter_names
from .regressors import torque_regressor


def random_states(model: pin.Model, samples: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, v, a)`` (samples, nq), (samples, nv) x 2: configurations ``neutral (+) N(0, 1)`` and
    standard normal rates: states that excite every dependency the structure allows."""
    q = np.array([pin.integrate(model, pin.neutral(model), rng.normal(size=model.nv)) for _ in range(samples)])
    return q, rng.normal(size=(samples, model.nv)), rng.normal(size=(samples, model.nv))


def structural_base(model: pin.Model, rng: np.random.Generator, samples: int = 200,
                    rows: np.ndarray | None = None) -> BaseParameters:
    """The base parameters of ``model``'s joint efforts (of the velocity ``rows`` only, e.g. the
    actuated joints; default all) from its regressor at ``samples`` :func:`random_states`."""
    W = torque_regressor(model, *random_states(model, samples, rng))
    if rows is not None:
        W = W.reshape(samples, model.nv, -1)[:, rows].reshape(-1, W.shape[1])
    return base_parameters(W, parameter_names(model), order=preferred_order(model.njoints - 1))


def identify(model: pin.Model, base: BaseParameters, q: np.ndarray, v: np.ndarray, a: np.ndarray, tau: np.ndarray,
             weighting: str = "block") -> Estimate:
    """The base parameters' estimate from measured states q (N, nq), v, a (N, nv) and joint
    efforts tau (N, nv) (:func:`~.least_squares.fit`, one block per sample).

    Raises:
        BadShape: for efforts of another shape than v's.
    """
    tau = np.asarray(tau, float)
    if tau.shape != np.shape(v):
        raise BadShape(f"identify: efforts must have the velocities' shape {np.shape(v)}, got {tau.shape}")
    W = base.regressor(torque_regressor(model, q, v, a))
    return fit(W, tau.ravel(), model.nv, base.labels(), weighting)
