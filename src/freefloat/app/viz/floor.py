"""The grid a page draws: a floor just under the motion, around it, wholly in front of the camera.

Meshcat's own grid is 20 m wide at z = 0 with 0.5 m cells, whatever the run. It cut through a
3-D robot, and its lines that passed behind the camera were not drawn (headless Chromium's
software GL): only a few far lines were left, floating above the robot. A page replaces it
with this one (meshcat node ``/Grid``): in the plane z = the lowest point of the motion (a
planar motion's own plane), over the motion's xy bounding box widened by :data:`MARGIN` framed
radii on each side, less what lies within :data:`CLEARANCE` of the camera's distance from the
camera's plane (the edges nearest the camera are moved back until every line's ends are in
front), with lines at the multiples of a round cell (1, 2 or 5 times a power of ten, m, about
:data:`CELLS` to the framed diameter), so that they read as a ruler. Points are in the inertial
frame (z up), m.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import meshcat.geometry as mg
import numpy as np

from .camera import Framing

#: Room around the motion's xy bounding box, in framed radii.
MARGIN = 0.5
#: Smallest depth of a grid line's end in front of the camera, as a fraction of the camera's
#: distance to its target.
CLEARANCE = 0.05
#: Cells across the framed diameter, about.
CELLS = 20
#: Line colour, 0xRRGGBB (meshcat's grid's).
COLOR = 0x888888


class Floor(NamedTuple):
    """The grid of a page: the rectangle ``low`` to ``high`` in the plane z = ``z``.

    Attributes:
        low: smallest x and y (2,), inertial frame, m.
        high: largest x and y (2,), m.
        z: the floor's height, m.
        cell: spacing of the lines, m.
    """

    low: np.ndarray
    high: np.ndarray
    z: float
    cell: float


def floor(points: np.ndarray, framing: Framing) -> Floor:
    """The grid under ``points`` (every point the motion visits, (N, 3), inertial frame, m) seen
    by the camera ``framing``: see the module's docstring."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    z = float(points[:, 2].min())
    low = points[:, :2].min(axis=0) - MARGIN * framing.radius
    high = points[:, :2].max(axis=0) + MARGIN * framing.radius
    look = framing.target - framing.position
    distance = float(np.linalg.norm(look))
    look /= distance
    # the corner nearest the camera's plane: where look . (x, y) is least
    toward = look[:2] >= 0.0
    near = np.where(toward, low, high)
    depth = float((np.array([*near, z]) - framing.position) @ look)
    shortfall = CLEARANCE * distance - depth
    spread = float(np.abs(look[:2]).sum())
    if shortfall > 0.0 and spread > 0.0:  # move the near edges away from the camera, together
        moved = np.where(toward, low, high) + np.where(toward, 1.0, -1.0) * shortfall / spread
        far = np.where(toward, high, low)
        moved = np.where(toward, np.minimum(moved, far), np.maximum(moved, far))
        low, high = np.where(toward, moved, low), np.where(toward, high, moved)
    return Floor(low, high, z, _round_length(2.0 * framing.radius / CELLS))


def grid_lines(grid: Floor) -> np.ndarray:
    """The ends of the grid's lines, pairs of points (2 K, 3), inertial frame, m: the lines
    x = k cell and y = k cell (k integer) inside the rectangle, each across the whole of it."""
    low, high, z, cell = grid
    xs = cell * np.arange(math.ceil(low[0] / cell), math.floor(high[0] / cell) + 1)
    ys = cell * np.arange(math.ceil(low[1] / cell), math.floor(high[1] / cell) + 1)
    x_lines = [[(x, low[1], z), (x, high[1], z)] for x in xs]
    y_lines = [[(low[0], y, z), (high[0], y, z)] for y in ys]
    return np.array(x_lines + y_lines, dtype=float).reshape(-1, 3)


def grid_object(grid: Floor) -> mg.LineSegments:
    """The grid as a meshcat object (line segments, inertial frame)."""
    ends = grid_lines(grid)
    return mg.LineSegments(mg.PointsGeometry(ends.T.astype(np.float32)), mg.LineBasicMaterial(color=COLOR))


def _round_length(length: float) -> float:
    """The largest of 1, 2, 5 times a power of ten that is at most ``length`` (> 0), m."""
    power = 10.0 ** math.floor(math.log10(length))
    return max(step * power for step in (1.0, 2.0, 5.0) if step * power <= length * (1 + 1e-12))
