"""Batched Newton solutions of a mechanism's closure for the coordinates left free, many starts at
once, each start kept or dropped on its own (unlike
:meth:`~freefloat.parallel.mechanism.ParallelMechanism.assemble`, which fails on the first point
out of reach)."""

from __future__ import annotations

import numpy as np

from ..mechanism import ParallelMechanism
from .jacobians import closure

#: Largest Newton step (rad or m) per coordinate: keeps starts far from a solution in its basin.
MAX_STEP = 0.5
#: Levenberg-Marquardt damping of the Newton steps (units of J^T J: m^2 or m^2/rad^2).
DAMPING = 1e-14
#: Closure residual (m, rad) below which a solution counts as found.
TOLERANCE = 1e-11


def newton(mech: ParallelMechanism, q: np.ndarray, free: np.ndarray, tol: float = TOLERANCE,
           iterations: int = 60, groups: list[np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Drive the closure residual to zero over the coordinates ``free`` (f,) of ``q`` (N, n_q),
    the others held; damped least-squares steps ``(J^T J + mu 1)^-1 J^T r`` (mu =
    :data:`DAMPING`, so that singular poses do not stop the batch), clipped to :data:`MAX_STEP`
    group by group: ``groups`` are index sets into ``free`` that move independently (the legs'
    joints in the inverse kinematics, so that one leg's long step does not shorten another's;
    default: one group).

    Returns:
        ``(q, converged)``: the coordinates (N, n_q) (in :func:`canonical` form) and
        whether the residual fell below ``tol`` (m, rad) (N,); a start out of reach ends at
        its least-squares point with ``converged`` False.
    """
    q = np.array(q, float)
    groups = [np.arange(len(free))] if groups is None else groups
    active = np.arange(len(q))
    converged = np.zeros(len(q), bool)
    for _ in range(iterations):
        residual, A = closure(mech, q[active])
        done = np.abs(residual).max(axis=-1) < tol
        converged[active[done]] = True
        active, residual, A = active[~done], residual[~done], A[~done]
        if not len(active):
            break
        J = A[:, :, free]
        JT = J.swapaxes(1, 2)
        step = np.linalg.solve(JT @ J + DAMPING * np.eye(len(free)), JT @ residual[:, :, None])[..., 0]
        for group in groups:
            block = step[:, group]
            block *= np.minimum(1.0, MAX_STEP / np.maximum(np.abs(block).max(axis=-1, keepdims=True), 1e-300))
            step[:, group] = block
        q[active[:, None], free] -= step
    return canonical(mech, q), converged


def revolute(mech: ParallelMechanism) -> np.ndarray:
    """Mask of the revolute joints' coordinates in q (n_q,) (platform coordinates False)."""
    return np.concatenate([np.zeros(mech.p, bool)] + [~np.asarray(c.prismatic, bool) for c in mech.chains])


def wrap(mech: ParallelMechanism, q: np.ndarray) -> np.ndarray:
    """``q`` (..., n_q) with its revolute joints wrapped to (-pi, pi]."""
    rev = revolute(mech)
    out = np.array(q, float)
    out[..., rev] = np.pi - np.mod(np.pi - out[..., rev], 2.0 * np.pi)
    return out


def spherical_triples(mech: ParallelMechanism) -> list[int]:
    """Indices in q of the first joint of each spherical joint modelled as three revolutes with a
    common centre and mutually orthogonal axes (Tait-Bryan angles a, b, c: the 2RSU+PPaP's
    ``s1, s2, s3``), read from the chains at zero joint angles."""
    out, start = [], mech.p
    for chain in mech.chains:
        J = chain.frames(np.zeros(chain.dof))[1]
        for i in range(chain.dof - 2):
            axes, centres = J[i:i + 3, :3, 2], J[i:i + 3, :3, 3]
            if (not chain.prismatic[i:i + 3].any() and np.allclose(centres, centres[0], atol=1e-12)
                    and np.allclose(axes @ axes.T, np.eye(3), atol=1e-12)):
                out.append(start + i)
        start += chain.dof
    return out


def canonical(mech: ParallelMechanism, q: np.ndarray) -> np.ndarray:
    """``q`` (..., n_q) with revolute joints wrapped to (-pi, pi] and each spherical joint's angles
    (a, b, c) (:func:`spherical_triples`) taken with ``|b| <= pi/2``: the same pose has the angles
    (a + pi, pi - b, c + pi) too, whose middle axis points the other way (and flips the sign of
    every determinant it enters)."""
    out = wrap(mech, q)
    for i in spherical_triples(mech):
        flip = np.abs(out[..., i + 1]) > 0.5 * np.pi
        out[..., i] += np.where(flip, np.pi, 0.0)
        out[..., i + 1] = np.where(flip, np.pi - out[..., i + 1], out[..., i + 1])
        out[..., i + 2] += np.where(flip, np.pi, 0.0)
    return wrap(mech, out)
