"""The 5R's workspace in closed form: each chain reaches the annulus about its base joint between
the radii ``|l1 - l2|`` (folded) and ``l1 + l2`` (stretched); the mechanism reaches their
intersection, and its boundary is made of arcs of those four circles, on each of which one leg
is stretched or folded (a type I singularity)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..five_bar import FiveBarParameters


class Arc(NamedTuple):
    """Boundary arc of the 5R's workspace.

    Attributes:
        leg: 0 (chain 1, base at +l0) or 1 (chain 2, base at -l0).
        stretched: True on the circle of radius l1 + l2, False on |l1 - l2| (folded).
        points: the arc's points (n, 2), m, inertial frame (x, y of the plane).
    """

    leg: int
    stretched: bool
    points: np.ndarray


def bases(p: FiveBarParameters) -> np.ndarray:
    """The base joints' centres A_1 = (l0, 0) and A_2 = (-l0, 0) (2, 2), m."""
    return np.array([[p.l0, 0.0], [-p.l0, 0.0]])


def radii(p: FiveBarParameters) -> tuple[float, float]:
    """``(|l1 - l2|, l1 + l2)``: each annulus' inner and outer radius, m."""
    return abs(p.l1 - p.l2), p.l1 + p.l2


def contains(p: FiveBarParameters, points: np.ndarray) -> np.ndarray:
    """Whether each point (..., 2), m, lies in both annuli (..., ) (boundary included)."""
    inner, outer = radii(p)
    r = np.linalg.norm(np.asarray(points, float)[..., None, :] - bases(p), axis=-1)
    return np.all((r >= inner) & (r <= outer), axis=-1)


def boundary(p: FiveBarParameters, samples: int = 2000) -> list[Arc]:
    """The workspace's boundary as arcs of the four circles: each circle sampled at ``samples``
    angles, kept where it lies in the other annulus (runs of kept samples become arcs)."""
    arcs = []
    inner, outer = radii(p)
    angle = np.linspace(-np.pi, np.pi, samples, endpoint=False)
    ring = np.stack((np.cos(angle), np.sin(angle)), axis=-1)
    for leg, centre in enumerate(bases(p)):
        other = bases(p)[1 - leg]
        for stretched, radius in ((False, inner), (True, outer)):
            points = centre + radius * ring
            r = np.linalg.norm(points - other, axis=-1)
            kept = (r >= inner) & (r <= outer)
            if kept.all():
                arcs.append(Arc(leg, stretched, np.vstack((points, points[:1]))))
                continue
            shift = np.argmin(kept)                      # start the walk outside the other annulus
            kept, points = np.roll(kept, -shift), np.roll(points, -shift, axis=0)
            edges = np.flatnonzero(np.diff(np.concatenate(([0], kept.astype(int), [0]))))
            arcs += [Arc(leg, stretched, points[a:b]) for a, b in zip(edges[::2], edges[1::2]) if b - a > 1]
    return arcs


def area(p: FiveBarParameters) -> float:
    """The workspace's area, m^2: Green's theorem over the boundary arcs is awkward at their
    ends, so this is the exact area of the annuli's intersection from circle-circle lens areas."""
    inner, outer = radii(p)
    d = 2.0 * p.l0
    return _lens(outer, outer, d) - 2.0 * _lens(outer, inner, d) + _lens(inner, inner, d)


def _lens(r1: float, r2: float, d: float) -> float:
    """Area of the intersection of two discs of radii r1, r2 whose centres are d apart, m^2."""
    if d >= r1 + r2:
        return 0.0
    if d <= abs(r1 - r2):
        return np.pi * min(r1, r2) ** 2
    a1 = r1**2 * np.arccos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1))
    a2 = r2**2 * np.arccos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2))
    return a1 + a2 - 0.5 * np.sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2))
