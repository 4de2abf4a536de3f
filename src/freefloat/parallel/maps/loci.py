"""Points on the singularity loci, refined by bisection between grid neighbours.

On a :class:`~.grids.ModeMap`, a locus shows up in one of two ways along a grid edge of one mode:

* a **sign change** of a determinant with the mode present at both ends: the direct block's
  (type II) in task space, the inverse block's (type I) in joint space;
* the mode's **end**: present at one end, absent at the other. A working mode ends where a leg
  stretches or folds (type I: the workspace's and the mode's boundary); an assembly mode ends
  where two assembly modes meet (type II: the boundary of the actuated joints' domain).

Each such edge is bisected ``iterations`` times: the midpoint is solved by Newton from the kept
end's solution (:func:`~.solve.newton`) and, for a sign change, the determinant's sign there
decides; for an end, whether Newton converges in the same mode.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from ..mechanism import ParallelMechanism
from .grids import ModeMap
from .jacobians import closure, partition, singularity
from .modes import assembly_label, working_label
from .solve import newton


class Locus(NamedTuple):
    """Points on one singularity locus.

    Attributes:
        kind: ``"I"`` or ``"II"``.
        space: ``"task"`` (coordinates: platform, m) or ``"joint"`` (actuated joints).
        mode: the mode's label at each point (K,).
        coordinates: (K, d).
        q: the assembled coordinates there (K, n_q).
    """

    kind: str
    space: str
    mode: np.ndarray
    coordinates: np.ndarray
    q: np.ndarray


def loci(mech: ParallelMechanism, grid_map: ModeMap, shape: tuple[int, ...], space: str, iterations: int = 30) -> list[Locus]:
    """Type I and type II loci (one :class:`Locus` each) of a map over a tensor grid of ``shape``
    (C order), in ``space`` (``"task"``: working modes over platform points; ``"joint"``:
    assembly modes over actuated joints)."""
    part = partition(mech)
    task = space == "task"
    coords = part.platform if task else part.actuated
    free = part.joints if task else part.unactuated
    label = (lambda q: working_label(mech, q)) if task else (lambda q: assembly_label(mech, q))
    measure = "direct" if task else "inverse"
    field = lambda q: getattr(singularity(part, closure(mech, q)[1]), measure)
    sign_kind, end_kind = ("II", "I") if task else ("I", "II")
    found = grid_map.modes.found.reshape(shape + (-1,))
    value = getattr(grid_map.singular, measure).reshape(shape + (-1,))
    x = grid_map.coordinates.reshape(shape + (-1,))
    q = grid_map.modes.q.reshape(shape + grid_map.modes.q.shape[1:])
    changes, ends = [], []
    for j, name in enumerate(grid_map.modes.labels):
        for axis in range(len(shape)):
            a, b = _pairs(shape, axis)
            both = found[a + (j,)] & found[b + (j,)]
            flip = both & (np.sign(value[a + (j,)]) != np.sign(value[b + (j,)]))
            changes.append((name, x[a][flip], x[b][flip], q[a + (j,)][flip]))
            for first, second in ((a, b), (b, a)):
                end = found[first + (j,)] & ~found[second + (j,)]
                ends.append((name, x[first][end], x[second][end], q[first + (j,)][end]))
    out = []
    for kind, edges, test in ((sign_kind, changes, "sign"), (end_kind, ends, "end")):
        mode = np.concatenate([np.full(len(e[1]), e[0]) for e in edges]) if edges else np.array([], str)
        xa, xb, qa = (np.concatenate([e[i] for e in edges]) for i in (1, 2, 3))
        xs, qs = _bisect(mech, coords, free, xa, xb, qa, mode, label, field, test, iterations)
        out.append(Locus(kind, space, label(qs) if len(qs) else mode[:0], xs, qs))
    return out


def _pairs(shape: tuple[int, ...], axis: int) -> tuple[tuple, tuple]:
    """Index tuples of the grid's neighbour pairs along ``axis``."""
    a = [slice(None)] * len(shape)
    b = list(a)
    a[axis], b[axis] = slice(0, -1), slice(1, None)
    return tuple(a), tuple(b)


def _bisect(mech: ParallelMechanism, coords: np.ndarray, free: np.ndarray, xa: np.ndarray, xb: np.ndarray,
            qa: np.ndarray, mode: np.ndarray, label: Callable, field: Callable, test: str,
            iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """Bisect the edges (xa -> xb) (K, d): ``xa`` keeps the mode (solution ``qa`` (K, n_q)) and
    the field's sign at ``xa``; returns the kept ends (K', d) and their solutions (K', n_q),
    without the sign edges whose far end is not reached in the same mode (the mode ends first).
    Hence the locus' mode labels are filtered the same way: see :func:`loci`."""
    xa, xb, qa = xa.copy(), xb.copy(), qa.copy()
    if not len(xa):
        return xa, qa
    sign_a = np.sign(field(qa))
    for _ in range(iterations):
        xm = 0.5 * (xa + xb)
        start = qa.copy()
        start[:, coords] = xm
        qm, ok = newton(mech, start, free)
        keep = ok & (label(qm) == mode)
        if test == "sign":
            keep &= np.sign(field(qm)) == sign_a
        xa[keep], qa[keep] = xm[keep], qm[keep]
        xb[~keep] = xm[~keep]
    if test == "sign":   # an edge along which the mode ends before the sign changes holds no locus point
        start = qa.copy()
        start[:, coords] = xb
        qb, ok = newton(mech, start, free)
        crossed = ok & (label(qb) == mode) & (np.sign(field(qb)) == -sign_a)
        xa, qa = xa[crossed], qa[crossed]
    return xa, qa
