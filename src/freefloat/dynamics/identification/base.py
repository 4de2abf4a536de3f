"""Base parameters: the combinations of a regressor's parameters that its data can identify.

Some columns of a regressor ``W`` (rows, n) are zero (a parameter that never acts, such as the
inertia about a horizontal axis of a link that turns about a vertical one) or linear combinations
of others (a link's mass that shows up only together with its neighbour's first moment). By QR
of ``W`` with its columns scaled to unit norm (Gautier's numerical method, 1991), taken in an
order of preference: a column is kept when its distance to the span of the columns kept before
it (``|R_ii|``) exceeds ``tol``. The kept columns ``W_1`` are independent, the others are
``W_2 = W_1 K`` exactly, so

.. math:: W \\pi = W_1 \\pi_1 + W_2 \\pi_2 = W_1 (\\pi_1 + K \\pi_2) = W_1 \\beta ,

and ``beta = pi_1 + K pi_2`` (rank,) are the base parameters: what least squares estimates from
``W_1``. ``tol`` defaults to 1e-8: Pinocchio's regressors are exact to round-off, so a dependent
column's distance sits near 1e-15. The order decides which parameter of a dependent group
stands for it: :func:`preferred_order` keeps each body's inertia and first moments before its
mass, so that masses are regrouped onto them (Khalil and Dombre's grouped parameters, e.g.
``Izz_1 + m_2 l_1^2``). Build ``W`` from samples that excite everything the structure allows
(random states), so that a dependency found is structural, not one of a poor trajectory.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ...errors import BadShape, InvalidArgument
from ..threads import single_blas_thread


@dataclass(frozen=True)
class BaseParameters:
    """The base parameters of a regressor's parameters (module docstring).

    Attributes:
        names: the full parameters' names (n,).
        independent: columns kept, ascending (rank,).
        dependent: the other columns, ascending (n - rank,).
        K: ``W_2 = W_1 K`` (rank, n - rank); entries below ``tol`` (relative to its largest) set to 0.
    """

    names: tuple[str, ...]
    independent: np.ndarray
    dependent: np.ndarray
    K: np.ndarray

    @property
    def rank(self) -> int:
        """Number of base parameters."""
        return len(self.independent)

    def of(self, parameters: np.ndarray) -> np.ndarray:
        """``beta = pi_1 + K pi_2`` (..., rank) of full parameters (..., n)."""
        parameters = np.asarray(parameters, float)
        return parameters[..., self.independent] + parameters[..., self.dependent] @ self.K.T

    def regressor(self, W: np.ndarray) -> np.ndarray:
        """The base regressor ``W_1`` (rows, rank) of a full regressor (rows, n)."""
        return np.asarray(W)[:, self.independent]

    def preimage(self, beta: np.ndarray, reference: np.ndarray | None = None) -> np.ndarray:
        """Full parameters (n,) with base parameters ``beta`` (rank,): the dependent ones taken
        from ``reference`` (n,) (zero by default), the independent ones ``beta - K pi_2``. Linear
        in beta; every preimage gives the same ``W pi``."""
        full = np.zeros(len(self.names)) if reference is None else np.array(reference, float)
        full[self.independent] = np.asarray(beta, float) - self.K @ full[self.dependent]
        return full

    def labels(self, digits: int = 4) -> tuple[str, ...]:
        """Each base parameter as its combination, e.g. ``"j1.Izz + 0.0144 j2.m"``."""
        out = []
        for row, i in enumerate(self.independent):
            terms = [self.names[i]] + [f"{self.K[row, c]:+.{digits}g} {self.names[d]}"
                                       for c, d in enumerate(self.dependent) if self.K[row, c] != 0.0]
            out.append(" ".join(terms).replace(" +", " + ").replace(" -", " - "))
        return tuple(out)


@single_blas_thread
def base_parameters(W: np.ndarray, names: tuple[str, ...], tol: float = 1e-8,
                    order: np.ndarray | None = None) -> BaseParameters:
    """The base parameters of regressor ``W`` (rows, n) whose columns are ``names`` (n,), by QR
    of its columns in ``order`` of preference (n,) (default: as they come; module docstring).

    Raises:
        BadShape: for names that do not match the columns, or fewer rows than columns.
        InvalidArgument: for a tolerance outside (0, 1), a regressor that is zero or not finite, or
            an order that is not a permutation of the columns.
    """
    W = np.asarray(W, float)
    if W.ndim != 2 or W.shape[1] != len(names):
        raise BadShape(f"base parameters: the regressor needs one column per name ({len(names)}), got shape {W.shape}")
    if W.shape[0] < W.shape[1]:
        raise BadShape(f"base parameters: {W.shape[0]} rows cannot show the dependencies of {W.shape[1]} columns; "
                       "stack more samples")
    if not 0.0 < tol < 1.0:
        raise InvalidArgument(f"base parameters: tol must be in (0, 1), got {tol}")
    if not np.isfinite(W).all():
        raise InvalidArgument("base parameters: the regressor has non-finite entries")
    norms = np.linalg.norm(W, axis=0)
    if not norms.max() > 0.0:
        raise InvalidArgument("base parameters: the regressor is zero (the samples excite nothing)")
    order = np.arange(W.shape[1]) if order is None else np.asarray(order)
    if sorted(order.tolist()) != list(range(W.shape[1])):
        raise InvalidArgument(f"base parameters: order must list each of the {W.shape[1]} columns once")
    scaled = W[:, order] / np.where(norms[order] > 0.0, norms[order], 1.0)
    distance = np.abs(np.diag(scipy.linalg.qr(scaled, mode="r")[0]))
    independent, dependent = np.sort(order[distance > tol]), np.sort(order[distance <= tol])
    K = np.linalg.lstsq(W[:, independent], W[:, dependent], rcond=None)[0]
    K[np.abs(K) < tol * max(1.0, np.abs(K).max(initial=0.0))] = 0.0
    return BaseParameters(tuple(names), independent, dependent, K)


def preferred_order(bodies: int) -> np.ndarray:
    """A tree's columns (10 bodies,) body by body, each body's ten reversed: ``Izz, Iyz, Ixz,
    Iyy, Ixy, Ixx, mcz, mcy, mcx, m`` (its mass last, see the module docstring)."""
    return (10 * np.arange(bodies)[:, None] + np.arange(9, -1, -1)).ravel()
