"""Simulated measurements: seeded noise of the stated size, configurations kept on their
group, and Savitzky-Golay derivatives and smoothing exact on cubics."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.identification.measurements import (
    channel_scale,
    differentiate,
    noisy,
    noisy_configurations,
    smooth,
    smooth_configurations,
)
from freefloat.errors import InvalidArgument


def test_noise_has_the_stated_size_per_channel():
    """1 % noise: its standard deviation per channel is 1 % of the channel's RMS (within 3 %
    over 20 000 samples; standard error 0.5 %), and a seed repeats it."""
    x = np.column_stack((np.sin(np.linspace(0, 20, 20000)) * 5.0, np.full(20000, 0.1)))
    noise = noisy(x, 0.01, np.random.default_rng(1)) - x
    np.testing.assert_allclose(noise.std(axis=0), 0.01 * channel_scale(x), rtol=0.03)
    np.testing.assert_array_equal(noisy(x, 0.01, np.random.default_rng(1)), noisy(x, 0.01, np.random.default_rng(1)))


def test_noisy_configurations_stay_on_the_group_with_the_stated_spread():
    """A free-flyer's noisy configurations keep unit quaternions; their tangent offsets from the
    true ones have 1 % of each coordinate's spread."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
    rng = np.random.default_rng(2)
    q = np.array([pin.integrate(model, pin.neutral(model), np.sin(0.001 * k + np.arange(6))) for k in range(5000)])
    noisy_q = noisy_configurations(model, q, 0.01, rng)
    np.testing.assert_allclose(np.linalg.norm(noisy_q[:, 3:], axis=1), 1.0, atol=1e-14)
    offsets = np.array([pin.difference(model, a, b) for a, b in zip(q, noisy_q)])
    spread = channel_scale(np.array([pin.difference(model, q[0], x) for x in q]), positions=True)
    np.testing.assert_allclose(offsets.std(axis=0), 0.01 * spread, rtol=0.05)


def test_derivative_and_smoothing_are_exact_on_a_cubic():
    """A cubic in time: the filter's derivative and its smoothed values are the cubic's own."""
    t = np.arange(200) * 1e-3
    x = np.column_stack((1.0 + 2.0 * t - 3.0 * t**2 + 4.0 * t**3, t**2))
    dx = np.column_stack((2.0 - 6.0 * t + 12.0 * t**2, 2.0 * t))
    np.testing.assert_allclose(differentiate(t, x, window=21), dx, atol=1e-9)
    index, values = smooth(x, window=21)
    np.testing.assert_allclose(values, x[index], atol=1e-12)
    assert index[0] == 10 and np.all(np.diff(index) == 21)


def test_smoothing_configurations_keeps_a_uniform_rotation():
    """A body turning at a constant rate about a fixed axis (a geodesic: linear in its own
    tangent space) is unchanged by the smoothing, through more than a half turn."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
    twist = np.array([0.1, 0.0, -0.2, 0.3, 0.5, 0.4])
    q = np.array([pin.integrate(model, pin.neutral(model), twist * s) for s in np.linspace(0.0, 6.0, 303)])
    index, values = smooth_configurations(model, q, window=101)
    for k, value in zip(index, values):
        np.testing.assert_allclose(pin.difference(model, q[k], value), 0.0, atol=1e-12)


def test_bad_filters_are_refused():
    """An even window, one longer than the record, or uneven sampling."""
    t = np.arange(50) * 0.01
    with pytest.raises(InvalidArgument, match="window"):
        differentiate(t, np.zeros((50, 1)), window=20)
    with pytest.raises(InvalidArgument, match="window"):
        smooth(np.zeros((10, 1)), window=21)
    with pytest.raises(InvalidArgument, match="evenly"):
        differentiate(t**2, np.zeros((50, 1)), window=21)
