"""The two partitions of a mechanism's constraint Jacobian and Gosselin & Angeles' singularity
types (thesis proposal eqs 105-124; C. Gosselin, J. Angeles, IEEE Trans. Robot. Autom. 6(3), 1990).

``A (..., m, n_q)`` is the Jacobian of the constraints ``qbar`` (and of the angular constraints'
position form) over ``q = [q#; q°]`` (:class:`~freefloat.parallel.mechanism.ParallelMechanism`),
its columns ordered [platform coordinates; chain 1 joints; chain 2 joints; ...]. The thesis splits
``A = [A#, A°]`` into the independent coordinates' columns and the dependent ones' (eq 120:
``C = [1; -A°^+ A#]``); which coordinates are independent decides which kinematics is solved:

* **inverse kinematics** (q# = the platform coordinates, the thesis's own choice): A° = the chain
  joints' columns ``A[:, p:]``. It loses rank where the joints cannot follow some platform
  velocity (or can move with the platform held): a **type I** (serial) singularity, a leg
  stretched or folded, on the boundary of the workspace and of each working mode.
* **direct kinematics** (q# = the actuated joints, A# = ``A[:, actuated]``): A° = every other
  column, the platform's and the passive joints'. It loses rank where the platform can move with
  the actuators locked: a **type II** (parallel) singularity, where eq 136's actuation map
  ``C^T U`` is singular too and the direct kinematics' Jacobian blows up.

Both blocks are square for a mechanism without redundancy (as many constraints as chain joints,
as many actuators as platform coordinates: the 5R and the 2RSU+PPaP). Where a leg's rows touch
no other chain's columns (both mechanisms), the inverse block is block-diagonal over the legs and
its determinant the product of the legs' (:attr:`Partition.legs`): the leg that is stretched
or folded is named by its own block.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...errors import InvalidArgument
from ..mechanism import ParallelMechanism


class Leg(NamedTuple):
    """One leg's share of the constraint Jacobian.

    Attributes:
        rows: constraint rows it alone touches (r,).
        columns: its joints' columns in q (r,).
    """

    rows: np.ndarray
    columns: np.ndarray


class Partition(NamedTuple):
    """Column sets of ``A`` (indices into q, n_q = p + n°).

    Attributes:
        platform: the platform coordinates q# (p,).
        actuated: the actuated joints (k,), in the order of ``mech.actuated``.
        passive: the other chain joints (n° - k,).
        legs: per chain, its rows and columns (the inverse block's diagonal blocks).
    """

    platform: np.ndarray
    actuated: np.ndarray
    passive: np.ndarray
    legs: tuple[Leg, ...]

    @property
    def joints(self) -> np.ndarray:
        """Every chain joint's column (n°,), the inverse kinematics' dependent coordinates."""
        return np.arange(len(self.platform), len(self.platform) + len(self.actuated) + len(self.passive))

    @property
    def unactuated(self) -> np.ndarray:
        """The direct kinematics' dependent coordinates: platform and passive joints (n_q - k,)."""
        return np.concatenate((self.platform, self.passive))


def closure(mech: ParallelMechanism, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``([qbar; orientation residual], A)`` at ``q`` (..., n_q): (..., m) in m and rad, and
    (..., m, n_q), any leading batch axes: point by point in the compiled core when the
    mechanism has one (3-6x faster than the batched numpy reference, which it equals to 1e-15),
    else the reference."""
    q = np.asarray(q, float)
    core = mech.core
    if core is None or not q.size:
        return mech.reference()._closure(q)
    rows = [core.closure(x) for x in q.reshape(-1, q.shape[-1])]
    residual, A = np.array([r for r, _ in rows]), np.array([a for _, a in rows])
    return residual.reshape(q.shape[:-1] + residual.shape[-1:]), A.reshape(q.shape[:-1] + A.shape[-2:])


def partition(mech: ParallelMechanism) -> Partition:
    """The column sets and the legs of ``mech``.

    Raises:
        FreefloatError: when the inverse or direct block is not square (a redundantly actuated
            or constrained mechanism, which these maps do not cover).
    """
    p, n_q = mech.p, mech.n_q
    actuated = np.asarray(mech.actuated, int)
    passive = np.setdiff1d(np.arange(p, n_q), actuated)
    m = len(mech.d) + (0 if mech.angular is None else len(mech.angular.offset))
    if m != n_q - p or len(actuated) != p:
        raise InvalidArgument(f"mechanism maps need as many constraints as chain joints and as many actuators as "
                              f"platform coordinates: {m} constraints, {n_q - p} chain joints, {len(actuated)} actuators, "
                              f"{p} platform coordinates")
    A = closure(mech, np.random.default_rng(0).uniform(-1.0, 1.0, n_q))[1]
    legs, start = [], p
    for chain in mech.chains:
        columns = np.arange(start, start + chain.dof)
        others = np.setdiff1d(np.arange(p, n_q), columns)
        rows = np.flatnonzero(np.any(A[:, columns] != 0.0, axis=1) & ~np.any(A[:, others] != 0.0, axis=1))
        legs.append(Leg(rows, columns))
        start += chain.dof
    if sum(len(leg.rows) for leg in legs) != m or any(len(leg.rows) != len(leg.columns) for leg in legs):
        legs = [Leg(np.arange(m), np.arange(p, n_q))]   # coupled legs: the mechanism is one leg
    return Partition(np.arange(p), actuated, passive, tuple(legs))


class Singularity(NamedTuple):
    """The two blocks' determinants and conditioning at a batch of assembled poses (...,).

    Attributes:
        inverse: ``det A[:, joints]``, zero at type I (units: m and rad as the rows and columns).
        direct: ``det A[:, unactuated]``, zero at type II.
        legs: each leg's ``det A[rows, columns]`` (..., n_legs); their product is ``inverse``
            up to the sign of the row order.
        inverse_ratio, direct_ratio: ``sigma_min / sigma_max`` of each block (1 / condition
            number), 0 at the singularity.
    """

    inverse: np.ndarray
    direct: np.ndarray
    legs: np.ndarray
    inverse_ratio: np.ndarray
    direct_ratio: np.ndarray


def singularity(part: Partition, A: np.ndarray) -> Singularity:
    """Measures of both singularity types from the constraint Jacobian A (..., m, n_q)."""
    inverse, direct = A[..., part.joints], A[..., part.unactuated]
    legs = np.stack([np.linalg.det(A[..., leg.rows[:, None], leg.columns]) for leg in part.legs], axis=-1)
    return Singularity(np.linalg.det(inverse), np.linalg.det(direct), legs, _ratio(inverse), _ratio(direct))


def _ratio(M: np.ndarray) -> np.ndarray:
    s = np.linalg.svd(M, compute_uv=False)
    return s[..., -1] / s[..., 0]
