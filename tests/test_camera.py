"""Tests of freefloat.app.viz.camera: the camera framed on the motion's bounding box."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from freefloat.app.viz.camera import ASPECT, FIELD_OF_VIEW, VIEW_DIRECTION, frame_motion

points = arrays(np.float64, st.tuples(st.integers(1, 30), st.just(3)),
                elements=st.floats(-50.0, 50.0, allow_nan=False, allow_infinity=False))


@settings(max_examples=60, deadline=None)
@given(points)
def test_every_point_is_in_view(cloud):
    """Every point projects inside a picture of aspect ASPECT, in front of the camera (z up)."""
    framing = frame_motion(cloud)
    forward = (framing.target - framing.position) / np.linalg.norm(framing.target - framing.position)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rays = cloud - framing.position
    depth = rays @ forward
    assert np.all(depth > 0)
    tan_half = np.tan(FIELD_OF_VIEW / 2)
    assert np.all(np.abs(rays @ up) <= depth * tan_half * (1 + 1e-9))
    assert np.all(np.abs(rays @ right) <= depth * ASPECT * tan_half * (1 + 1e-9))


def test_target_is_the_box_centre_seen_obliquely():
    """The camera looks at the bounding box's centre from the fixed oblique direction."""
    cloud = np.array([[-7.75, 0.0, 0.0], [7.75, 0.0, 0.0], [0.0, -7.75, 0.0], [0.0, 7.75, 1.0]])
    framing = frame_motion(cloud)
    np.testing.assert_allclose(framing.target, [0.0, 0.0, 0.5])
    direction = (framing.position - framing.target) / np.linalg.norm(framing.position - framing.target)
    np.testing.assert_allclose(direction, VIEW_DIRECTION / np.linalg.norm(VIEW_DIRECTION))


def test_scale_follows_the_motion():
    """A motion ten times larger puts the camera ten times farther from the target."""
    cloud = np.random.default_rng(0).normal(size=(20, 3))
    near, far = frame_motion(cloud), frame_motion(10.0 * cloud)
    assert np.linalg.norm(far.position - far.target) == pytest.approx(10.0 * np.linalg.norm(near.position - near.target))


def test_a_single_point_gets_the_minimum_radius():
    """A motionless point is framed at the minimum radius, not at zero distance."""
    framing = frame_motion(np.ones((5, 3)), min_radius=0.2)
    assert framing.radius == 0.2 and np.linalg.norm(framing.position - framing.target) >= 0.4


def test_non_finite_points_are_rejected():
    """A NaN in the motion raises ValueError instead of a NaN camera."""
    with pytest.raises(ValueError, match="not finite"):
        frame_motion(np.array([[0.0, 0.0, np.nan]]))
