"""Fourier-series exciting trajectories: derivatives, bounds, and the optimisation of the
regressor's condition number."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.identification.excitation import (
    FourierTrajectory,
    optimise,
    random_trajectory,
)
from freefloat.dynamics.identification.regressors import torque_regressor
from freefloat.dynamics.identification.tree import structural_base
from freefloat.errors import BadShape, InvalidArgument


@pytest.fixture
def series():
    """Three coordinates, four harmonics, a 2 s period."""
    return random_trajectory(np.array([0.1, -0.2, 0.3]), 4, 2.0, 0.5, 2.0, np.random.default_rng(0))


def test_rates_and_accelerations_are_the_derivatives(series):
    """qdot and qddot equal central differences of q and qdot (step 1e-5 s: error below 1e-8)."""
    t, h = np.linspace(0.0, 2.0, 37), 1e-5
    q, qd, qdd = series(t)
    np.testing.assert_allclose(qd, (series(t + h)[0] - series(t - h)[0]) / (2 * h), atol=1e-8)
    np.testing.assert_allclose(qdd, (series(t + h)[1] - series(t - h)[1]) / (2 * h), atol=1e-7)
    assert q.shape == (37, 3) and series(0.3)[0].shape == (3,)


def test_the_series_is_periodic_and_within_its_bounds(series):
    """q(t + T) = q(t); on a dense grid the displacement and rate stay within the bounds, which
    the construction met (one of them exactly)."""
    t = np.linspace(0.0, 2.0, 4001)
    q, qd, _ = series(t)
    np.testing.assert_allclose(series(t + 2.0)[0], q, atol=1e-12)
    assert np.all(np.abs(q - series.offset).max(axis=0) <= series.displacement_bound() + 1e-12)
    assert np.all(np.abs(qd).max(axis=0) <= series.rate_bound() + 1e-12)
    assert np.all(series.displacement_bound() <= 0.5 + 1e-12) and np.all(series.rate_bound() <= 2.0 + 1e-12)
    assert np.all(np.isclose(series.displacement_bound(), 0.5) | np.isclose(series.rate_bound(), 2.0))


def test_optimising_lowers_the_condition_number_within_the_bounds():
    """On a planar-gravity RR arm, a few L-BFGS iterations lower the base regressor's condition
    number from a random start, and the result keeps the bounds."""
    model = pin.Model()
    j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j1")
    model.appendBodyToJoint(j1, pin.Inertia(2.0, np.array([0.2, 0.03, 0.0]), np.diag([0.01, 0.02, 0.03])), pin.SE3.Identity())
    j2 = model.addJoint(j1, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([0.5, 0.0, 0.0])), "j2")
    model.appendBodyToJoint(j2, pin.Inertia(1.0, np.array([0.25, -0.02, 0.0]), np.diag([0.01, 0.01, 0.02])), pin.SE3.Identity())
    model.gravity = pin.Motion(np.array([0.0, -9.81, 0.0]), np.zeros(3))
    base = structural_base(model, np.random.default_rng(0))

    def cost(trajectory):
        _, (q, v, a) = trajectory.sample(50)
        return np.linalg.cond(base.regressor(torque_regressor(model, q, v, a)))

    start = random_trajectory(np.zeros(2), 3, 4.0, 1.0, 2.0, np.random.default_rng(1))
    best, value = optimise(start, cost, 1.0, 2.0, iterations=5)
    assert value == pytest.approx(cost(best)) and value < 0.8 * cost(start)
    assert np.all(best.displacement_bound() <= 1.0 + 1e-12) and np.all(best.rate_bound() <= 2.0 + 1e-12)


def test_bad_series_are_refused():
    """Coefficients of other shapes than the offsets, or a period that is not positive."""
    with pytest.raises(BadShape, match="offsets"):
        FourierTrajectory(np.zeros(2), np.zeros((3, 2)), np.zeros((3, 2)), 1.0)
    with pytest.raises(InvalidArgument, match="period"):
        FourierTrajectory(np.zeros(2), np.zeros((2, 2)), np.zeros((2, 2)), 0.0)
