"""Tests of freefloat.app.viz.floor: the grid a page draws under the motion."""

from __future__ import annotations

import numpy as np

from freefloat.app.viz.camera import frame_motion
from freefloat.app.viz.floor import CLEARANCE, MARGIN, floor, grid_lines


def _points(seed: int, flat: bool = False) -> np.ndarray:
    """Random points of a motion (200, 3), m; in the plane z = 0.3 when ``flat``."""
    points = np.random.default_rng(seed).normal(size=(200, 3)) * [2.0, 1.0, 0.5] + [1.0, -2.0, 0.3]
    if flat:
        points[:, 2] = 0.3
    return points


def test_a_planar_motion_gets_its_grid_in_its_own_plane():
    """Points in z = 0.3: the grid's lines all lie in z = 0.3, and cover the points' xy box."""
    points = _points(0, flat=True)
    grid = floor(points, frame_motion(points, direction=np.array([0.0, 0.0, 1.0])))
    ends = grid_lines(grid)
    np.testing.assert_array_equal(ends[:, 2], 0.3)
    assert (grid.low <= points[:, :2].min(axis=0)).all() and (points[:, :2].max(axis=0) <= grid.high).all()


def test_a_3d_motion_gets_its_grid_under_its_lowest_point():
    """Points spread in z: the grid lies at their lowest z."""
    points = _points(1)
    assert floor(points, frame_motion(points)).z == points[:, 2].min()


def test_every_line_ends_in_front_of_the_camera():
    """From the default oblique view and from a low one, every line's ends lie at least
    CLEARANCE of the camera's distance in front of the camera's plane."""
    points = _points(2)
    for direction in (None, np.array([1.0, -0.2, 0.05])):
        framing = frame_motion(points) if direction is None else frame_motion(points, direction=direction)
        look = framing.target - framing.position
        distance = np.linalg.norm(look)
        depth = (grid_lines(floor(points, framing)) - framing.position) @ (look / distance)
        assert depth.min() >= CLEARANCE * distance * (1 - 1e-9)


def test_far_edges_keep_their_margin_around_the_motion():
    """The edges away from the camera lie MARGIN framed radii beyond the points."""
    points = _points(3)
    framing = frame_motion(points)  # from +x, -y: the far edges are low x and high y
    grid = floor(points, framing)
    assert np.isclose(grid.low[0], points[:, 0].min() - MARGIN * framing.radius)
    assert np.isclose(grid.high[1], points[:, 1].max() + MARGIN * framing.radius)


def test_lines_lie_on_multiples_of_a_round_cell():
    """The cell is 1, 2 or 5 times a power of ten, and every line sits at a multiple of it."""
    for seed, scale in ((4, 0.01), (5, 1.0), (6, 30.0)):
        points = _points(seed) * scale
        grid = floor(points, frame_motion(points))
        mantissa = grid.cell / 10.0 ** np.floor(np.log10(grid.cell))
        assert min(abs(mantissa - m) for m in (1.0, 2.0, 5.0)) < 1e-9
        ends = grid_lines(grid).reshape(-1, 2, 3)
        along_y = ends[:, 0, 0] == ends[:, 1, 0]  # lines x = const
        for coordinate in (ends[along_y, 0, 0], ends[~along_y, 0, 1]):
            np.testing.assert_allclose(coordinate / grid.cell, np.round(coordinate / grid.cell), atol=1e-9)
