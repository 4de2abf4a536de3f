"""Platform control of a closed chain: the generic laws equal the 5R's own controller, and computed
torque on an exact model gives the commanded platform acceleration."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat import FreefloatError
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.platform_control import CircleReference
from freefloat.parallel.sliding_mode import PlatformControl, circle_reference, printed_gains

P = FiveBarParameters()
CIRCLE = CircleReference(np.array([0.0, 0.17]), 0.07, 28.57)
GAINS = printed_gains(np.array([75.3, 108.0]), np.array([[1.25, 0.92], [1.68, 1.65]]),
                      {(0, 0): [37.0, 54.1], (1, 0): [22.7, 35.5], (1, 1): [17.5, 28.5]})


def _states(mech, n=4, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        point = np.array([0.0, 0.17]) + rng.uniform(-0.05, 0.05, 2)
        q = mech.assemble(point, elbow_guess(P, point))
        yield q, mech.velocity_map(q) @ rng.normal(size=2), rng.uniform(0.0, 0.2)


def test_circle_is_sec_5_6_reference():
    """The circle with eq 189's numbers equals the 5R module's circle_reference, with derivatives."""
    for t in (0.0, 0.013, 0.31):
        for ours, theirs in zip(CIRCLE(t), circle_reference(t)):
            np.testing.assert_allclose(ours, theirs, rtol=1e-14, atol=1e-15)


def test_circle_holds_the_other_coordinates():
    """A circle in coordinates (0, 2) of three keeps coordinate 1 at the centre, at rest."""
    circle = CircleReference(np.array([0.1, 0.2, 0.3]), 0.05, 2.0, axes=(0, 2))
    q, qd, qdd = circle(0.4)
    assert (q[1], qd[1], qdd[1]) == (0.2, 0.0, 0.0)
    np.testing.assert_allclose(q[[0, 2]], [0.1 + 0.05 * np.cos(0.8), 0.3 + 0.05 * np.sin(0.8)])


def test_unknown_switch_is_refused():
    """A saturation other than tanh or sign fails naming the choices instead of falling back to tanh."""
    with pytest.raises(FreefloatError, match="saturation must be one of"):
        PlatformControl(five_bar(P), CIRCLE, 40.0, GAINS, "Sign")


def test_computed_torque_on_the_exact_model_gives_the_commanded_acceleration():
    """With plant = model, the forward dynamics under computed torque accelerate the platform by
    qdd_d + 2 lambda edot + lambda^2 e (eq 190's design)."""
    mech = five_bar(P)
    control = PlatformControl(mech, CIRCLE, 40.0)
    for q, qd, t in _states(mech):
        q_d, qd_d, qdd_d = CIRCLE(t)
        e, edot = q_d - q[:2], qd_d - qd[:2]
        qdd = mech.forward(q, qd, control.torque(t, q, qd))
        np.testing.assert_allclose(qdd[:2], qdd_d + 80.0 * edot + 1600.0 * e, rtol=1e-8)


def test_printed_gains_give_eq_167():
    """The printed gains evaluate eq 167: n + T |sigma| + sum n_ij |qd_i| |qd_j|."""
    sigma, qd = np.array([1.0, -2.0]), np.array([0.5, -0.25])
    expected = (np.array([75.3, 108.0]) + np.array([1.25 + 1.84, 1.68 + 3.3]) + 0.25 * np.array([37.0, 54.1])
                + 0.125 * np.array([22.7, 35.5]) + 0.0625 * np.array([17.5, 28.5]))
    np.testing.assert_allclose(GAINS.k(sigma, qd), expected)
