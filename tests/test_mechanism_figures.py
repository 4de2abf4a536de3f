"""Tests of freefloat.app.viz.mechanism: the figures of a mechanism run and the closure points
its page follows."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.app.viz.mechanism import (
    closure_markers,
    drift_figure,
    efforts_figure,
    tracking_figure,
)
from freefloat.dynamics.telemetry import MechanismTelemetry
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.five_bar import elbow_guess
from freefloat.parallel.rsu_ppap import load_rsu_ppap

from .conftest import REPO


@pytest.fixture(scope="module")
def five_bar():
    return load_closed_chain(REPO / "urdf" / "five_bar.closure.toml")


def _telemetry(p: int, k: int, n: int = 50) -> MechanismTelemetry:
    """Synthetic run: p platform coordinates, k actuators, drift exactly 0 then a denormal at t = 0."""
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 1.0, n)
    platform = rng.normal(size=(n, p)) * 0.01
    drift = np.abs(rng.normal(size=n)) * 1e-11
    drift[0] = 1e-312
    return MechanismTelemetry(t=t, platform=platform, platform_reference=platform + 1e-5, joints=np.zeros((n, 4)),
                              efforts=rng.normal(size=(n, k)), drift=drift, orientation_drift=np.zeros(n))


def test_efforts_are_named_by_actuated_joint_with_their_units():
    """The 2RSU+PPaP's cranks are drawn in N m and its rail in N, each labelled by its joint."""
    chain = load_rsu_ppap()
    fig = efforts_figure(_telemetry(3, 3), chain)
    panels = {ax.get_ylabel(): [line.get_label() for line in ax.get_lines()] for ax in fig.axes}
    names = [chain.model.names[j] for j in chain.actuated]
    assert set(panels) == {"effort (N m)", "effort (N)"} and sorted(name for labels in panels.values() for name in labels) == sorted(names)


def test_tracking_names_coordinates_and_draws_three_in_3d():
    """Two platform coordinates give an xy panel, three a 3-D one; errors are labelled x, y (, z) in m."""
    flat, deep = tracking_figure(_telemetry(2, 2)), tracking_figure(_telemetry(3, 3))
    assert flat.axes[0].name == "rectilinear" and deep.axes[0].name == "3d"
    assert [line.get_label() for line in deep.axes[1].get_lines()] == ["x", "y", "z"]
    assert deep.axes[1].get_ylabel() == "|q#_d - q#| (m)"


def test_drift_axis_is_clipped_to_the_data():
    """The denormal drift at t = 0 does not stretch the log axis below the data."""
    tel = _telemetry(2, 2)
    low, high = drift_figure(tel).axes[0].get_ylim()
    assert low > 1e-13 * tel.drift.max() and high < 10 * tel.drift.max()


def test_closure_points_meet_on_an_assembled_mechanism_and_part_on_a_broken_one(five_bar):
    """Both points of the 5R's closure coincide (1e-9 m) at an assembled configuration and are
    apart when a joint is moved off it."""
    from freefloat.parallel.five_bar import FiveBarParameters

    point = np.array([0.07, 0.17])
    q = five_bar.mechanism.assemble(point, elbow_guess(FiveBarParameters(), point))
    tree_q = np.array([five_bar.pinocchio_q(q), five_bar.pinocchio_q(q + np.r_[0.0, 0.0, 0.1, 0.0, 0.0, 0.0])])
    first, second = (m.positions for m in closure_markers(five_bar, tree_q))
    assert np.linalg.norm(first[0] - second[0]) < 1e-9 and np.linalg.norm(first[1] - second[1]) > 1e-3
