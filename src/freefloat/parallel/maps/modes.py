"""Working modes (the inverse kinematics' solutions at one platform point) and assembly modes (the
direct kinematics' solutions at one set of actuated joints) of any mechanism, found by Newton
from many starts (:func:`~.solve.newton`) and named by the signs of the blocks that separate them.

Two working modes differ in at least one leg, and a leg can only pass from one of its solutions
to another through a type I singularity, where its block of the inverse Jacobian is singular
(:mod:`.jacobians`): so a working mode is named by the signs of the legs' determinants, one
``+`` or ``-`` per leg (the 5R's four elbow combinations "++", "+-", "-+", "--"). Assembly modes
are separated by type II singularities: they are named by the sign of the direct block's
determinant. Of the starts that reach one sign, the one whose joints (wrapped to (-pi, pi]) have
the least norm represents it, so that a spherical joint's second set of angles for the same pose
is not taken for another mode.
"""

from __future__ import annotations

import itertools
from typing import NamedTuple

import numpy as np

from ...errors import BadShape
from ..mechanism import ParallelMechanism
from .jacobians import closure, partition, singularity
from .solve import TOLERANCE, newton, revolute

#: Signs in the order of a mode's name characters.
SIGNS = {"+": 1.0, "-": -1.0}
#: The assembly modes' names: the direct block's sign.
ASSEMBLY_NAMES = ("+", "-")


class Modes(NamedTuple):
    """Solutions of one kinematics at N points, one per mode.

    Attributes:
        labels: the modes' names (M,).
        q: each mode's assembled coordinates at each point (N, M, n_q); meaningless where not
            ``found``.
        found: whether the mode exists there (N, M).
    """

    labels: tuple[str, ...]
    q: np.ndarray
    found: np.ndarray

    def mode(self, label: str) -> tuple[np.ndarray, np.ndarray]:
        """``(q (N, n_q), found (N,))`` of the mode called ``label``."""
        i = self.labels.index(label)
        return self.q[:, i], self.found[:, i]


def starts(mech: ParallelMechanism, count: int, seed: int = 0) -> np.ndarray:
    """``count`` chain-joint starts (count, n°): revolute joints uniform in (-pi, pi], prismatic 0 m
    (they enter the closure linearly, so Newton needs no spread of them)."""
    rev = revolute(mech)[mech.p:]
    return np.random.default_rng(seed).uniform(-np.pi, np.pi, (count, len(rev))) * rev


def working_names(mech: ParallelMechanism) -> tuple[str, ...]:
    """The working modes' names (2^n_legs): every combination of one sign per leg."""
    return tuple("".join(s) for s in itertools.product("+-", repeat=len(partition(mech).legs)))


def working_label(mech: ParallelMechanism, q: np.ndarray) -> np.ndarray:
    """The working-mode name of each assembled ``q`` (..., n_q): one sign per leg (str array (...,))."""
    legs = singularity(partition(mech), closure(mech, q)[1]).legs
    names = ["".join(s) for s in np.where(legs >= 0.0, "+", "-").reshape(-1, legs.shape[-1])]
    return np.array(names).reshape(legs.shape[:-1])


def assembly_label(mech: ParallelMechanism, q: np.ndarray) -> np.ndarray:
    """The assembly-mode name (the direct block's sign, str array (...,)) of each assembled ``q``."""
    return np.where(singularity(partition(mech), closure(mech, q)[1]).direct >= 0.0, "+", "-")


def working_modes(mech: ParallelMechanism, points: np.ndarray, count: int = 16, seed: int = 0) -> Modes:
    """Every working mode at each platform point (N, p) (m): Newton from ``count`` starts per point
    (:func:`starts`), each leg's solutions sorted by its sign (a leg counts where its own rows
    converged, whatever the other legs did); a mode exists where each of its legs has a solution
    of its sign."""
    points = _rows(points, mech.p, "points")
    part = partition(mech)
    q0 = np.concatenate((np.repeat(points[:, None], count, axis=1),
                         np.broadcast_to(starts(mech, count, seed), (len(points), count, mech.n_q - mech.p))), axis=-1)
    legs_free = [leg.columns - mech.p for leg in part.legs]
    q = newton(mech, q0.reshape(-1, mech.n_q), part.joints, groups=legs_free)[0].reshape(q0.shape)
    residual, A = closure(mech, q)
    legs = singularity(part, A).legs
    labels = working_names(mech)
    out = np.repeat(q[:, :1], len(labels), axis=1)
    found = np.ones((len(points), len(labels)), bool)
    converged = [np.abs(residual[..., block.rows]).max(axis=-1) < TOLERANCE for block in part.legs]  # each on its own
    for j, label in enumerate(labels):
        for leg, (sign, block) in enumerate(zip(label, part.legs)):
            best, exists = _least_norm(q[..., block.columns], converged[leg] & (np.sign(legs[..., leg]) == SIGNS[sign]))
            out[:, j][:, block.columns] = np.take_along_axis(q[..., block.columns], best[:, None, None], axis=1)[:, 0]
            found[:, j] &= exists
    return Modes(labels, out, found)


def assembly_modes(mech: ParallelMechanism, actuated: np.ndarray, box: np.ndarray, count: int = 32,
                   seed: int = 0) -> Modes:
    """Both assembly modes ("+", "-": the direct block's sign) at each set of actuated joints
    (N, k) (rad or m, in the order of ``mech.actuated``): Newton over the platform and passive
    joints from ``count`` starts, the platform's uniform in ``box`` (p, 2) (lower, upper; m)."""
    part = partition(mech)
    q0 = _direct_starts(mech, actuated, box, count, seed)
    q, ok = newton(mech, q0.reshape(-1, mech.n_q), part.unactuated)
    q, ok = q.reshape(q0.shape), ok.reshape(q0.shape[:2])
    direct = singularity(part, closure(mech, q)[1]).direct
    labels = ASSEMBLY_NAMES
    out = np.empty((len(actuated), 2, mech.n_q))
    found = np.empty((len(actuated), 2), bool)
    for j, label in enumerate(labels):
        best, found[:, j] = _least_norm(q[..., part.passive], ok & (np.sign(direct) == SIGNS[label]))
        out[:, j] = np.take_along_axis(q, best[:, None, None], axis=1)[:, 0]
    return Modes(labels, out, found)


def distinct(mech: ParallelMechanism, q: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """The physically distinct poses among assembled ``q`` (N, n_q): poses whose platform point
    and joint origins (every chain's joint frames, m, inertial frame) agree within ``tol`` m are
    one, represented by its member of least joint norm (as :func:`working_modes` picks); (K,
    n_q). Two sets of joint angles of one pose (a spherical joint's second set) are one pose, and
    so is a rod turned half a turn about its own axis (its joints sit where they were), which
    the legs' signs can tell apart: the least norm picks the rod not turned."""
    q = np.asarray(q, float)
    q = q[np.argsort(np.linalg.norm(q[:, mech.p:], axis=1), kind="stable")]
    points = np.concatenate([q[:, : mech.p]] + [c.frames(qi)[1][..., :3, 3].reshape(len(q), -1)
                                                 for c, qi in zip(mech.chains, mech.split(q))], axis=1)
    kept: list[int] = []
    for i, x in enumerate(points):
        if all(np.abs(x - points[j]).max() > tol for j in kept):
            kept.append(i)
    return q[kept]


def direct_solutions(mech: ParallelMechanism, actuated: np.ndarray, box: np.ndarray, count: int = 256,
                     seed: int = 0) -> np.ndarray:
    """Every physically distinct solution of the direct kinematics found at one set of actuated
    joints (k,) from ``count`` starts (platform uniform in ``box`` (p, 2), m): (K, n_q). The two
    assembly-mode names pair them when there are more than two (the 2RSU+PPaP: the platform on
    either side of the cranks' reach, times the parallelogram's bars up or down)."""
    q, ok = newton(mech, _direct_starts(mech, np.asarray(actuated, float)[None], box, count, seed)[0],
                   partition(mech).unactuated)
    return distinct(mech, q[ok])


def _direct_starts(mech: ParallelMechanism, actuated: np.ndarray, box: np.ndarray, count: int, seed: int) -> np.ndarray:
    """Starts of the direct kinematics (N, count, n_q) at the actuated joints (N, k): the platform
    uniform in ``box`` (p, 2), m, the other joints as :func:`starts`.

    Raises:
        BadShape: for actuated joints or a box of the wrong shape.
    """
    actuated = _rows(actuated, len(mech.actuated), "actuated")
    box = np.asarray(box, float)
    if box.shape != (mech.p, 2):
        raise BadShape(f"assembly_modes: box must be (p, 2) = ({mech.p}, 2), got {box.shape}")
    q0 = np.empty((len(actuated), count, mech.n_q))
    q0[..., mech.p:] = starts(mech, count, seed)
    q0[..., : mech.p] = np.random.default_rng(seed).uniform(box[:, 0], box[:, 1], (count, mech.p))
    q0[..., mech.actuated] = actuated[:, None]
    return q0


def _least_norm(values: np.ndarray, valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index (N,) of the start of least norm of ``values`` (N, S, c) among ``valid`` (N, S), and
    whether any is valid (N,)."""
    cost = np.where(valid, np.linalg.norm(values, axis=-1), np.inf)
    return np.argmin(cost, axis=1), valid.any(axis=1)


def _rows(values: np.ndarray, width: int, name: str) -> np.ndarray:
    values = np.asarray(values, float)
    if values.ndim != 2 or values.shape[1] != width or not np.isfinite(values).all():
        raise BadShape(f"{name} must be finite, of shape (N, {width}); got {values.shape}")
    return values
