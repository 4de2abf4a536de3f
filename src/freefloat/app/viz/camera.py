"""Where a page's camera looks from: framed on the bounding box of the whole motion.

Points and directions are in the inertial frame (z up), m. Meshcat's camera is a three.js
``PerspectiveCamera`` with a 75 deg vertical field of view; the page converts to three.js's
y-up axes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: Vertical field of view of meshcat's default camera, rad.
FIELD_OF_VIEW = np.radians(75.0)
#: Direction from the target to the camera: front-right, 30 deg above the xy-plane.
VIEW_DIRECTION = np.array([np.cos(np.radians(-55.0)), np.sin(np.radians(-55.0)), np.tan(np.radians(30.0))])
#: Direction for a motion in the xy-plane (a planar mechanism): from above, 75 deg up, tilted
#: towards -y, so that x runs right and y up on the picture, as the plane is drawn on paper.
PLANE_VIEW = np.array([0.0, -np.cos(np.radians(75.0)), np.sin(np.radians(75.0))])
#: Narrowest picture (width / height) the framing must fit; wider windows show more around it.
ASPECT = 4.0 / 3.0
#: Factor on the smallest distance that shows every point (room around the motion).
MARGIN = 1.1


class Framing(NamedTuple):
    """Camera placement.

    Attributes:
        position: camera position (3,), inertial frame, m.
        target: point looked at, the centre of the motion's bounding box (3,), m.
        radius: radius of the bounding sphere of that box, m (at least ``min_radius``).
    """

    position: np.ndarray
    target: np.ndarray
    radius: float


def frame_motion(points: np.ndarray, min_radius: float = 0.05, direction: np.ndarray = VIEW_DIRECTION) -> Framing:
    """Camera that keeps every point of the motion in view, seen obliquely.

    The camera looks at the bounding box's centre ``c`` from ``direction`` ``d`` (default
    :data:`VIEW_DIRECTION`; made unit), with z up on the picture as far as ``d`` allows. A point at offset ``o = p - c``
    is in view at distance ``D`` when
    ``|o . u| <= (D - o . d) tan(fov/2)`` and ``|o . r| <= (D - o . d) ASPECT tan(fov/2)``
    (``u``, ``r`` the picture's up and right); ``D`` is the smallest such distance, at least
    ``2 r_min``, times :data:`MARGIN`.

    Args:
        points: every point the motion visits (joint origins, end-effectors, bodies at every
            shown frame), inertial frame, m (N, 3).
        min_radius: smallest framed radius, m, so that a motionless point still gets a view.

    Returns:
        The camera position and target, and the bounding box's half-diagonal.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(points) == 0 or not np.all(np.isfinite(points)):
        raise ValueError("cannot frame the motion: no points, or points that are not finite")
    low, high = points.min(axis=0), points.max(axis=0)
    target = (low + high) / 2
    radius = max(float(np.linalg.norm(high - low)) / 2, min_radius)
    d = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    right = np.cross(-d, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, -d)
    offsets = points - target
    tan_half = np.tan(FIELD_OF_VIEW / 2)
    needed = offsets @ d + np.maximum(np.abs(offsets @ up) / tan_half, np.abs(offsets @ right) / (ASPECT * tan_half))
    distance = MARGIN * max(float(needed.max()), 2.0 * min_radius)
    return Framing(target + distance * d, target, radius)
