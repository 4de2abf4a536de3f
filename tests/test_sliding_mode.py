"""Sliding-mode control of the 5R: the designed gains satisfy the sliding condition at the design
points for every extreme plant, and the law out-tracks computed torque with 15 % errors."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.errors import FreefloatError
from freefloat.parallel.closed_loop import track_five_bar
from freefloat.parallel.five_bar import (
    TRUE_PARAMETERS,
    FiveBarParameters,
    elbow_guess,
    five_bar,
    redundant_five_bar,
)
from freefloat.parallel.platform import platform_dynamics
from freefloat.parallel.redundancy import EffortDistribution
from freefloat.parallel.sliding_mode import (
    PlatformControl,
    chattering,
    circle_reference,
    design_gains,
    extreme_parameters,
)

NOMINAL = FiveBarParameters()
POINTS = np.array([[0.07, 0.17], [0.0, 0.22]])


@pytest.fixture(scope="module")
def gains():
    return design_gains(NOMINAL, POINTS, eta=20.0)


def test_design_gives_positive_finite_gains(gains):
    """n, T and n_ij are finite and non-negative; |Delta|_max < 1 so eq 161 applies."""
    assert np.all(np.isfinite(gains.n)) and np.all(gains.n > gains.eta)
    assert np.all(gains.T >= 0) and np.all(np.abs(np.linalg.eigvals(gains.Delta_max)) < 1)


@pytest.mark.parametrize("estimate", [
    lambda params: five_bar(params),
    lambda params: redundant_five_bar(params, EffortDistribution(weights=np.array([1.0, 1.0, 4.0]),
                                                                 lower=np.full(3, -8.0), upper=np.full(3, 8.0))),
], ids=["square", "redundant_shared"])
def test_sliding_condition_holds_at_the_design_points(gains, estimate):
    """For every extreme plant at the design points, the law (eq 153, f = sign) gives
    s^T sdot <= -eta sum |s| (eq 144) for random s, sigma and platform rates; also on the 5R with a
    third actuator, the law's force shared (weighted 1:1:4, limited to 8 N m) and applied through
    the true plant's actuation map: the gains designed on u*'s dynamics carry over."""
    est = estimate(NOMINAL)
    rng = np.random.default_rng(0)
    for point in POINTS:
        q = est.assemble(point, elbow_guess(NOMINAL, point))
        for params in extreme_parameters(NOMINAL):
            true = estimate(params)
            for _ in range(3):
                qd, sigma, s = rng.normal(size=2) * 0.5, rng.normal(size=2) * 20, rng.normal(size=2)
                H, v, g, B = platform_dynamics(true, q, qd)
                H_hat, v_hat, g_hat, B_hat = platform_dynamics(est, q, qd)
                tau = est.efforts(B_hat, v_hat + g_hat + H_hat @ (sigma - gains.k(sigma, qd) * np.sign(s)))
                sdot = np.linalg.solve(H, B @ tau - v - g) - sigma
                assert s @ sdot <= -gains.eta * np.abs(s).sum() + 1e-9


def test_sliding_mode_tracks_better_than_computed_torque(gains):
    """With the 15 % parameter errors of sec 5.6, sliding mode keeps the circle far closer than
    computed torque (eq 190, lambda = 40) once settled on the sliding surface (after 0.2 s)."""
    def late_error(control):
        tel = track_five_bar(TRUE_PARAMETERS, control, 0.3, 2e-4).telemetry
        e = control.sliding_variables(tel.t, tel.q, tel.v)[0]
        return np.abs(e[tel.t > 0.2]).max(axis=0)

    smc = late_error(PlatformControl(five_bar(NOMINAL), circle_reference, 40.0, gains))
    ct = late_error(PlatformControl(five_bar(NOMINAL), circle_reference, 40.0, None))
    assert np.all(smc < 0.3 * ct)


def test_dynamics_are_linear_in_the_six_base_parameters():
    """H, g_M and delta_ij at a point, rebuilt from the six base parameters, match a direct evaluation."""
    from freefloat.parallel.platform import quadratic_coefficients
    from freefloat.parallel.sliding_mode import base_parameters, point_coefficients

    q = five_bar(NOMINAL).assemble(POINTS[0], elbow_guess(NOMINAL, POINTS[0]))
    H_c, g_c, quad_c = point_coefficients(NOMINAL, q)
    pi = base_parameters(TRUE_PARAMETERS)
    H, _, g, _ = platform_dynamics(five_bar(TRUE_PARAMETERS), q, np.zeros(2))
    np.testing.assert_allclose(np.tensordot(pi, H_c, 1), H, rtol=1e-9)
    np.testing.assert_allclose(pi @ g_c, g, rtol=1e-9)
    for key, coef in quadratic_coefficients(five_bar(TRUE_PARAMETERS), q).items():
        np.testing.assert_allclose(pi @ quad_c[key], coef, rtol=1e-8, atol=1e-12)


def test_chattering_measures_effort_jumps_and_sign_changes():
    """On efforts alternating +-1 every period and s = sin(2 pi 5 t) sampled at 1 kHz, the
    chattering measures give a median jump of 2 and the zeros of s in the window (t = 1.1 ... 1.9,
    nine) over its length (0.999 s)."""
    t = np.arange(0.0, 2.0, 1e-3) + 5e-4        # offset: no sample falls on a zero of s
    efforts = np.where(np.arange(len(t)) % 2 == 0, 1.0, -1.0)[:, None] * np.array([1.0, 3.0])
    s = np.sin(2 * np.pi * 5 * t)[:, None]
    out = chattering(t, efforts, s, after=1.0)
    np.testing.assert_allclose(out["effort_jump_median"], [2.0, 6.0])
    assert out["s_sign_changes_per_s"][0] == pytest.approx(9 / 0.999)
    assert out["s_max"][0] == pytest.approx(1.0, abs=1e-3)


def test_chattering_takes_effort_jumps_between_control_updates():
    """Efforts updated every 10 ms and s sampled every 1 ms: jumps and their sum per second are
    taken over the updates (alternating +-1: jump 2, 2 x 9 jumps in 0.09 s), sign changes over the samples."""
    t = np.arange(0.0, 0.2, 1e-3) + 5e-4
    updates = np.arange(0.0, 0.2, 1e-2) + 5e-4
    efforts = np.where(np.arange(len(updates)) % 2 == 0, 1.0, -1.0)[:, None]
    s = np.sin(2 * np.pi * 50 * t)[:, None]
    out = chattering(t, efforts, s, after=0.1, effort_times=updates)
    assert out["effort_jump_median"] == [2.0]
    assert out["effort_variation_per_s"][0] == pytest.approx(2.0 * 9 / 0.09)
    assert out["s_sign_changes_per_s"][0] == pytest.approx(9 / 0.099)


def test_chattering_needs_two_updates_in_the_window():
    """One control update after the start of the window is refused, naming the window."""
    t = np.linspace(0.0, 1.0, 101)
    with pytest.raises(FreefloatError, match="after t = 0.5 s"):
        chattering(t, np.zeros((2, 1)), np.zeros((101, 1)), 0.5, effort_times=np.array([0.0, 0.6]))


@pytest.mark.parametrize("lam", [float("nan"), -40.0, float("inf")])
def test_a_lambda_not_finite_and_non_negative_is_refused_naming_it(lam):
    """lam NaN, negative or infinite is refused naming lambda, not reported later as a singular pose."""
    from freefloat.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match=r"'lam' must be"):
        PlatformControl(five_bar(), circle_reference, lam)
