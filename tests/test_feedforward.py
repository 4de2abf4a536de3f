"""Computed torque with feedforward (CTCp): the table against Orsino's inverse dynamics and
platform dynamics point by point, the law against its feedback-linearising twins (eqs 190 and
153) on the reference, interpolation and refusals."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.errors import FreefloatError
from freefloat.parallel.feedforward import FeedforwardControl, FeedforwardTable
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar, redundant_five_bar
from freefloat.parallel.platform import platform_dynamics
from freefloat.parallel.sliding_mode import PlatformControl, circle_reference, design_gains

START = circle_reference(0.0)[0]


@pytest.fixture(scope="module")
def model():
    return five_bar(FiveBarParameters())


@pytest.fixture(scope="module")
def table(model):
    """Sec 5.6's circle over 0.05 s every 1 ms on the nominal 5R."""
    return FeedforwardTable.along(model, circle_reference, elbow_guess(FiveBarParameters(), START), 0.05, 1e-3)


@pytest.fixture(scope="module")
def gains():
    """Eq 167's gains from two points of the circle."""
    return design_gains(FiveBarParameters(), np.array([[0.07, 0.17], [0.0, 0.24]]))


def test_table_holds_the_inverse_dynamics_along_the_reference(model, table):
    """Each row's efforts are the numpy reference's eqs 130-140 at the reference's pose, and its
    G_d is (C^T U)^-1 H from eq 137 there (1e-10 of their size)."""
    reference = model.reference()
    assert len(table.efforts) == 51
    for i in range(0, 51, 10):
        x, xd, xdd = circle_reference(0.001 * i)
        assert np.allclose(table.reference[i], [x, xd, xdd], rtol=0.0, atol=1e-15)
        q = reference.assemble(x, elbow_guess(FiveBarParameters(), x))
        tau = reference.inverse(q, xd, xdd)[0]
        H, _, _, B = platform_dynamics(reference, q, np.zeros(2))
        assert np.abs(table.efforts[i] - tau).max() < 1e-10 * np.abs(tau).max()
        G = np.linalg.solve(B, H)
        assert np.abs(table.inertia[i] - G).max() < 1e-10 * np.abs(G).max()


@pytest.mark.parametrize("sliding", [False, True])
def test_on_the_reference_the_law_is_its_feedback_linearising_twin(model, table, gains, sliding):
    """At a state on the reference (pose and rates of a table row) the PD law's efforts equal
    computed torque's (eq 190) and the sliding law's equal eq 153's (same gains) to 1e-10: the
    model terms at the reference are the measured state's. Off it (1 mm, 1 cm/s) they differ."""
    chosen = gains if sliding else None
    twin = PlatformControl(model, circle_reference, 40.0, chosen)
    law = FeedforwardControl(twin, table)
    for i in (3, 17, 40):
        t = 0.001 * i
        x, xd, _ = circle_reference(t)
        q = model.assemble(x, elbow_guess(FiveBarParameters(), x))
        qd = model.velocity_map(q) @ xd
        expected = twin.torque(t, q, qd)
        assert np.abs(law.torque(t, q, qd) - expected).max() < 1e-10 * np.abs(expected).max()
        off = model.assemble(x + 1e-3, q[2:])
        shifted = model.velocity_map(off) @ (xd + 1e-2)
        assert np.abs(law.torque(t, off, shifted) - twin.torque(t, off, shifted)).max() > 1e-6


def test_between_rows_the_table_is_interpolated_linearly(table):
    """At 40 % of the way from row 7 to row 8 every entry is 0.6 row 7 + 0.4 row 8."""
    reference, tau, G = table.at(0.0074)
    assert np.allclose(tau, 0.6 * table.efforts[7] + 0.4 * table.efforts[8], rtol=1e-12)
    assert np.allclose(G, 0.6 * table.inertia[7] + 0.4 * table.inertia[8], rtol=1e-12)
    assert np.allclose(reference, 0.6 * table.reference[7] + 0.4 * table.reference[8], rtol=1e-12)


@pytest.mark.parametrize("t", [-1e-4, 0.0501])
def test_a_time_outside_the_table_is_refused(table, t):
    """Before the first row or past the last the law names the table's span."""
    with pytest.raises(FreefloatError, match=r"outside the table \[0.0, 0.05"):
        table.at(t)


def test_redundant_actuation_is_refused():
    """The table inverts C^T U: three actuators for two coordinates are refused by name."""
    with pytest.raises(FreefloatError, match="as many actuators"):
        FeedforwardTable.along(redundant_five_bar(), circle_reference, elbow_guess(FiveBarParameters(), START),
                               0.01, 1e-3)


def test_along_tabulates_the_twins_model_and_reference(model, table):
    """FeedforwardControl.along builds the same table from the twin's model and reference."""
    law = FeedforwardControl.along(PlatformControl(model, circle_reference, 40.0), elbow_guess(FiveBarParameters(), START),
                                   0.05, 1e-3)
    assert np.array_equal(law.table.efforts, table.efforts) and np.array_equal(law.table.inertia, table.inertia)
