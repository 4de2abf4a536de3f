"""Least squares with the noise covariance estimated from the residuals: exact on exact data,
and intervals that hold the truth as often as they claim (seeded Monte-Carlo)."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.dynamics.identification.least_squares import fit
from freefloat.errors import BadShape, InvalidArgument, UnknownName

#: Three rows per sample: a loud row, a quiet row correlated with it, a middling one.
NOISE = np.array([[1.0, 0.002, 0.0], [0.002, 1e-4, 0.0], [0.0, 0.0, 0.04]])
THETA = np.array([2.0, -1.0, 0.5, 3.0, 0.01])


def regressor(samples: int, rng: np.random.Generator, rows: tuple = (3.0, 0.1, 1.0)) -> np.ndarray:
    """A random regressor (3 samples, 5) whose columns load the three rows as ``rows`` says."""
    return rng.normal(size=(3 * samples, 5)) * np.tile(np.array(rows)[:, None], (samples, 1))


def test_exact_data_give_the_parameters_to_round_off():
    """No noise: the estimate is theta to 1e-12 relative."""
    rng = np.random.default_rng(0)
    W = regressor(200, rng)
    est = fit(W, W @ THETA, 3)
    np.testing.assert_allclose(est.values, THETA, rtol=1e-12, atol=1e-14)


def test_intervals_hold_the_truth_as_often_as_claimed():
    """Over 400 seeded data sets (200 samples each, correlated noise of very unequal rows), each
    parameter's 95 % interval holds the truth in 95 % +- 2 % of them (binomial standard error of
    the 2000 checks: 0.5 %), and the z-scores have unit spread within 10 %."""
    rng = np.random.default_rng(1)
    W = regressor(200, rng)
    chol = np.linalg.cholesky(NOISE)
    hits, z = [], []
    for _ in range(400):
        y = W @ THETA + (rng.normal(size=(200, 3)) @ chol.T).ravel()
        est = fit(W, y, 3)
        lower, upper = est.interval(0.95)
        hits.append((lower <= THETA) & (THETA <= upper))
        z.append((est.values - THETA) / est.std)
    assert abs(np.mean(hits) - 0.95) < 0.02
    assert np.all(np.abs(np.std(z, axis=0) - 1.0) < 0.1)


def test_one_pass_would_overstate_the_quiet_rows_noise():
    """The estimated per-sample covariance matches the true one (the passes converged), where
    the first pass's residuals alone overstate the quiet row's variance (every row sees every
    parameter alike, so the loud row's error leaks into the quiet row's residual)."""
    rng = np.random.default_rng(2)
    W = regressor(400, rng, (1.0, 1.0, 1.0))
    y = W @ THETA + (rng.normal(size=(400, 3)) @ np.linalg.cholesky(NOISE).T).ravel()
    est = fit(W, y, 3)
    first = (y - W @ np.linalg.lstsq(W, y, rcond=None)[0]).reshape(-1, 3)
    assert est.noise[1, 1] == pytest.approx(NOISE[1, 1], rel=0.15)
    assert np.mean(first[:, 1] ** 2) > 2.0 * NOISE[1, 1]


def test_the_joint_box_is_wider_than_each_interval():
    """The box enclosing the joint confidence ellipsoid is sqrt(n F) standard deviations wide,
    more than each parameter's own t interval."""
    rng = np.random.default_rng(3)
    W = regressor(100, rng)
    est = fit(W, W @ THETA + rng.normal(size=300) * 0.1, 3, weighting="none")
    assert np.all(est.half_width(0.95, joint=True) > 1.5 * est.half_width(0.95))


def test_rank_deficient_data_name_the_parameters_that_cannot_be_told_apart():
    """Two equal columns: an error naming them."""
    rng = np.random.default_rng(4)
    W = regressor(50, rng)
    W[:, 4] = W[:, 2]
    with pytest.raises(InvalidArgument, match="theta2|theta4"):
        fit(W, W @ THETA + rng.normal(size=150), 3)


def test_bad_arguments_are_named():
    """Unknown weighting, rows not a whole number of blocks, too few rows."""
    rng = np.random.default_rng(5)
    W = regressor(10, rng)
    with pytest.raises(UnknownName, match="diagonal"):
        fit(W, W @ THETA, 3, weighting="diag")
    with pytest.raises(BadShape, match="blocks"):
        fit(W, W @ THETA, 4)
    with pytest.raises(BadShape, match="rows cannot estimate"):
        fit(W[:3], W[:3] @ THETA, 3)
