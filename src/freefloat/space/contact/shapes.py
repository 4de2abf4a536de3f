"""Primitive shapes and their signed distance through coal (Pinocchio's collision library, which
``pin`` brings): ``coal.distance`` gives the signed distance of two convex shapes (negative when
they overlap: minus the penetration depth), the two witness points and the normal from the first
shape to the second (GJK/EPA; exact to round-off for spheres, tested against the closed forms in
tests/test_contact.py)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import coal
import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument, did_you_mean

#: Shape kind -> (number of sizes, what they are, coal constructor).
SHAPES = {
    "sphere": (1, "radius, m", lambda s: coal.Sphere(s[0])),
    "box": (3, "side lengths along the shape frame's x, y, z, m", lambda s: coal.Box(*s)),
    "capsule": (2, "radius and length of the segment along z, m", lambda s: coal.Capsule(s[0], s[1])),
    "cylinder": (2, "radius and length along z, m", lambda s: coal.Cylinder(s[0], s[1])),
}


@dataclass(frozen=True)
class Shape:
    """A primitive shape fixed to a body.

    Attributes:
        kind: a name of :data:`SHAPES`.
        size: its sizes (:data:`SHAPES` says which), m.
        where: a text naming it in errors (scene key, link).
    """

    kind: str
    size: tuple[float, ...]
    where: str = "contact"

    def __post_init__(self) -> None:
        if self.kind not in SHAPES:
            raise InvalidArgument(f"{self.where}: unknown shape '{self.kind}'{did_you_mean(self.kind, list(SHAPES), 'shapes')}")
        count, meaning, _ = SHAPES[self.kind]
        if len(self.size) != count or not all(np.isfinite(s) and s > 0.0 for s in self.size):
            raise InvalidArgument(f"{self.where}: a {self.kind} takes {count} positive size(s) ({meaning}), "
                                  f"got {list(self.size)}")

    def geometry(self) -> coal.ShapeBase:
        """The coal shape, centred at the shape frame's origin."""
        return SHAPES[self.kind][2](tuple(float(s) for s in self.size))


class Proximity(NamedTuple):
    """Where two shapes are closest.

    Attributes:
        depth: penetration depth, m (minus the signed distance: > 0 when they overlap).
        normal: unit normal from the first shape to the second, inertial frame (3,).
        point: contact point, the midpoint of the two witness points, inertial frame, m (3,).
    """

    depth: float
    normal: np.ndarray
    point: np.ndarray


def proximity(first: coal.ShapeBase, pose_first: pin.SE3, second: coal.ShapeBase, pose_second: pin.SE3,
              request: coal.DistanceRequest | None = None) -> Proximity:
    """Signed distance of two coal shapes at their inertial poses (coal's GJK/EPA)."""
    result = coal.DistanceResult()
    distance = coal.distance(first, coal.Transform3s(pose_first.rotation, pose_first.translation),
                             second, coal.Transform3s(pose_second.rotation, pose_second.translation),
                             request or coal.DistanceRequest(), result)
    point = 0.5 * (result.getNearestPoint1() + result.getNearestPoint2())
    return Proximity(-float(distance), np.array(result.normal), point)
