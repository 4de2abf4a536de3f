"""Tests of freefloat.app.viz.screenshot, and through it a look at real pages: the run fills a
reasonable part of the picture and the picture changes over time. Skipped without Chromium."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from freefloat.app.viz import write_trajectory_html
from freefloat.app.viz.mechanism_page import write_mechanism_html
from freefloat.app.viz.screenshot import browser, changed, extent, look
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.robot.loading import load_robot

from .conftest import REPO

needs_browser = pytest.mark.skipif(
    browser() is None, reason="no Chromium: install one to look at pages (Debian: apt-get install chromium)")


def test_changed_and_extent_measure_the_differing_pixels():
    """A 10 x 20 px patch in a 100 x 100 picture changes 2 % of the pixels and its box covers 2 %."""
    a = np.zeros((100, 100, 3))
    b = a.copy()
    b[10:20, 30:50] = 1.0
    assert changed(a, b) == pytest.approx(0.02) and extent(a, b) == pytest.approx(0.02)
    assert changed(a, a) == 0.0 and extent(a, a) == 0.0


@pytest.mark.slow
@needs_browser
def test_robot_page_frames_the_robot_and_moves(tmp_path):
    """The four-arm robot (arms to 7.75 m) spans over a tenth of the picture, and the picture
    changes between the start and the end of a 30 deg swing of every joint."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", base="planar")
    t = np.linspace(0.0, 2.0, 41)
    q = np.tile(robot.neutral(), (len(t), 1))
    q[:, robot.model.nq - robot.n_joints:] += np.radians(30.0) * (t / 2.0)[:, None]
    seen = look(write_trajectory_html(robot, t, q, tmp_path / "robot.html"), 0.0, 2.0)
    assert seen["extent"] > 0.1 and seen["motion"] > 0.002


@pytest.mark.slow
@needs_browser
def test_mechanism_page_frames_the_mechanism_and_moves(tmp_path):
    """The 5R (links of 0.12-0.15 m) spans over a tenth of the picture and moves, drawn as thin
    bars: under 3 % of the pixels (its URDF's link cylinders, 0.05 m in radius, covered 7.8 %)."""
    chain = load_closed_chain(REPO / "urdf" / "five_bar.closure.toml")
    n_q = max(chain.joint_coordinates.values()) + 1
    t = np.linspace(0.0, 1.0, 21)
    q = np.outer(t, np.full(n_q, 0.8)) + 0.3
    seen = look(write_mechanism_html(chain, t, q, tmp_path / "five_bar.html", fps=20.0), 0.0, 1.0)
    assert seen["extent"] > 0.1 and seen["motion"] > 0.002
    assert 0.002 < seen["coverage"] < 0.03
