"""Figures of a closed loop (freefloat.app.viz.loop_figures)."""

from __future__ import annotations

import numpy as np

from freefloat.app.viz.loop_figures import loop_figure


def test_a_held_squeeze_reads_as_its_value_from_zero():
    """A squeeze held at 20 N to 1e-11 is drawn on an axis from zero past 20 N (no offset notation
    that would show the round-off as the signal), above a log panel of the drift."""
    t = np.linspace(0.0, 1.0, 50)
    squeeze = 20.0 + 1e-11 * np.sin(t)
    fig = loop_figure(t, squeeze, np.abs(squeeze), np.full(50, 1e-14), np.full(50, 1e-15))
    force, drift = fig.axes
    low, high = force.get_ylim()
    assert low <= 0.0 and high > 20.0 and drift.get_yscale() == "log"


def test_without_forces_only_the_drift_is_drawn():
    """A [[closures]] run has no squeeze: one panel, the closures' drift."""
    t = np.linspace(0.0, 1.0, 50)
    fig = loop_figure(t, None, None, np.full(50, 1e-13), np.full(50, 1e-14))
    assert len(fig.axes) == 1 and fig.axes[0].get_yscale() == "log"
