"""Tests of freefloat.app.viz.mechanism: the figures of a mechanism run."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.app.viz.mechanism import drift_figure, efforts_figure, tracking_figure, write_base_figures
from freefloat.dynamics.telemetry import MechanismTelemetry
from freefloat.parallel.free_base import BaseTelemetry
from freefloat.parallel.rsu_ppap import load_rsu_ppap


def _telemetry(p: int, k: int, n: int = 50) -> MechanismTelemetry:
    """Synthetic run: p platform coordinates, k actuators, drift exactly 0 then a denormal at t = 0."""
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 1.0, n)
    platform = rng.normal(size=(n, p)) * 0.01
    drift = np.abs(rng.normal(size=n)) * 1e-11
    drift[0] = 1e-312
    return MechanismTelemetry(t=t, platform=platform, platform_reference=platform + 1e-5, joints=np.zeros((n, 4)),
                              efforts=rng.normal(size=(n, k)), drift=drift, orientation_drift=np.zeros(n),
                              sliding=rng.normal(size=(n, p)) * 0.1)


def test_efforts_are_named_by_actuated_joint_with_their_units():
    """The 2RSU+PPaP's cranks are drawn in N m and its rail in N, each labelled by its joint."""
    chain = load_rsu_ppap()
    fig = efforts_figure(_telemetry(3, 3), chain.actuators())
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


@pytest.mark.slow
def test_base_figures_show_the_attitude_and_the_momentum(tmp_path):
    """A moving base's run writes base_attitude (rotation vector, angle turned, displacement) and
    momentum (linear and angular components, and the drift on a log axis), as PNG."""
    n, t = 40, np.linspace(0.0, 0.4, 40)
    base = BaseTelemetry(t=t, q=np.zeros((n, 4)), v=np.zeros((n, 3)), base_position=np.outer(t, [0.01, -0.02, 0.0]),
                         base_rotation=np.outer(t, [0.0, 0.0, 0.3]), momentum=np.full((n, 6), 1e-12),
                         com=np.zeros((n, 3)))
    written = write_base_figures(base, np.linspace(0.0, 1e-12, n), tmp_path)
    assert sorted(p.name for p in written) == ["base_attitude.png", "momentum.png"]
