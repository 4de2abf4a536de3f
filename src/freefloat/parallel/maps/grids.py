"""Every mode of a mechanism over a grid: working modes over platform points (task space),
assembly modes over actuated joints (joint space), with both singularity measures at each
solution; the workspace (points where some working mode exists) and its boundary on the grid."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..mechanism import ParallelMechanism
from .jacobians import Singularity, closure, partition, singularity
from .modes import Modes, assembly_modes, working_modes

#: Points solved per batch (memory: each carries ``count`` starts and an (m, n_q) Jacobian).
BATCH = 1024


class ModeMap(NamedTuple):
    """One kinematics solved over N grid points, for M modes.

    Attributes:
        coordinates: the grid points (N, d): platform coordinates (m) in task space, actuated
            joints (rad or m, ``mech.actuated`` order) in joint space.
        modes: the solutions (labels (M,), q (N, M, n_q), found (N, M)).
        singular: both singularity measures of each solution (arrays (N, M); ``legs``
            (N, M, n_legs)); meaningless where not found.
    """

    coordinates: np.ndarray
    modes: Modes
    singular: Singularity


def task_map(mech: ParallelMechanism, points: np.ndarray, count: int = 16, seed: int = 0) -> ModeMap:
    """Every working mode at each platform point (N, p), m (:func:`~.modes.working_modes`)."""
    return _solved(mech, points, lambda chunk: working_modes(mech, chunk, count, seed))


def joint_map(mech: ParallelMechanism, actuated: np.ndarray, box: np.ndarray, count: int = 32, seed: int = 0) -> ModeMap:
    """Both assembly modes at each set of actuated joints (N, k) (:func:`~.modes.assembly_modes`;
    ``box`` (p, 2): where the platform's starts are drawn, m)."""
    return _solved(mech, actuated, lambda chunk: assembly_modes(mech, chunk, box, count, seed))


def _solved(mech: ParallelMechanism, coordinates: np.ndarray, solve) -> ModeMap:
    coordinates = np.asarray(coordinates, float)
    parts = [solve(coordinates[i:i + BATCH]) for i in range(0, len(coordinates), BATCH)]
    modes = Modes(parts[0].labels, np.concatenate([m.q for m in parts]), np.concatenate([m.found for m in parts]))
    return ModeMap(coordinates, modes, singularity(partition(mech), closure(mech, modes.q)[1]))


def axes_grid(axes: list[np.ndarray]) -> np.ndarray:
    """The points (N, d) of the tensor grid of ``axes`` (d 1-D arrays), C order (last axis fastest)."""
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(axes))


def boundary(inside: np.ndarray) -> np.ndarray:
    """Grid cells (grid shape, bool) inside whose neighbour along some axis is outside: the
    workspace's boundary at the grid's resolution (cells on the grid's edge count only if a
    neighbour within the grid is outside)."""
    out = np.zeros_like(inside)
    for axis in range(inside.ndim):
        for shift in (1, -1):
            neighbour = np.roll(inside, shift, axis=axis)
            edge = [slice(None)] * inside.ndim
            edge[axis] = 0 if shift == 1 else -1
            neighbour[tuple(edge)] = True                 # beyond the grid: unknown, not outside
            out |= inside & ~neighbour
    return out
