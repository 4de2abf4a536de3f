"""The stability study's cases: a step just below a found limit is stable, just above it is not."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.dynamics.stability import largest_stable_step
from freefloat.errors import FreefloatError
from freefloat.lab.reproduce.stability_cases import ClosedChain, Detumbling, Tumbling, whole_steps


def test_tumbling_limit_separates_stable_from_unstable_steps():
    """Dual-arm satellite at 30 rad/s with RKMK4: 3 % below the bisected limit is stable, 3 % above it is not."""
    case = Tumbling("dual_arm_satellite", 30.0, "rkmk4")
    limit = largest_stable_step(case.stable, 1e-4, 1.0 / 30.0, rtol=0.01)
    assert limit.bracketed
    below, above = case.measure(0.97 * limit.stable), case.measure(1.03 * limit.unstable)
    assert case.passes(below) and not case.passes(above)
    assert below["energy_drift"] < above["energy_drift"]


def test_tumbling_faster_is_the_same_motion_in_shorter_time():
    """Torque-free without gravity, ten times the rate at a tenth of the step gives the same drifts
    (time scaling maps one motion onto the other), so the limit scales as 1/rate."""
    slow, fast = Tumbling("dual_arm_satellite", 3.0, "rkmk4"), Tumbling("dual_arm_satellite", 30.0, "rkmk4")
    a, b = slow.measure(0.05), fast.measure(0.005)
    assert a["steps"] == b["steps"]
    assert b["energy_drift"] == pytest.approx(a["energy_drift"], rel=1e-6)
    assert b["momentum_drift"] == pytest.approx(a["momentum_drift"], rel=1e-6)
    assert a["energy_drift"] > 1e-5


def test_tumbling_start_has_the_stated_rate():
    """The base starts turning at the stated rate, joints at rest relative to it."""
    case = Tumbling("dual_arm_satellite", 3.0, "euler")
    assert np.linalg.norm(case.v0[3:6]) == pytest.approx(3.0, rel=1e-12)
    assert not case.v0[6:].any()


def test_held_impulse_is_the_left_riemann_sum_of_the_ramp():
    """Both arms' 500 N m ramps (5 ms rise, 5 to 15 ms): held over 1 ms they give 2 x 500 x 7 ms = 7 N m s,
    and the exact integral 2 x 500 x 7.5 ms as the step shrinks."""
    case = Detumbling("detumble_impulse_both_arms", "rkmk4")
    assert case.held_impulse(1e-3, 20) == pytest.approx([0.0, 0.0, 7.0], abs=1e-9)
    assert case.held_impulse(1e-6, 20000) == pytest.approx([0.0, 0.0, 7.5], abs=1e-3)


def test_detumbling_is_stable_at_the_scene_period_and_not_at_ten_times_it():
    """RKMK4 keeps the post-impulse momentum within 1 % at 1 ms and misses it by far more at 10 ms."""
    case = Detumbling("detumble_impulse_both_arms", "rkmk4", duration=0.1)
    fine, coarse = case.measure(1e-3), case.measure(1e-2)
    assert case.passes(fine) and not case.passes(coarse)
    assert fine["momentum_drift"] < 1e-3 and coarse["momentum_drift"] > 1e-1


def test_detumbling_needs_an_impulse_of_pure_torques():
    """A scene without impulses is refused, naming it."""
    with pytest.raises(FreefloatError, match="four_arm_joint_space"):
        Detumbling("four_arm_joint_space", "rkmk4")


def test_baumgarte_keeps_the_semi_implicit_euler_5r_closed():
    """At 1 ms, lambda = 100 cuts the 5R's loop-closure drift under semi-implicit Euler several-fold."""
    bare = ClosedChain("five_bar_computed_torque", "euler", 0.0, duration=0.1).measure(1e-3)
    held = ClosedChain("five_bar_computed_torque", "euler", 100.0, duration=0.1).measure(1e-3)
    assert bare["status"] == held["status"] == "completed"
    assert held["closure_drift"] < bare["closure_drift"] / 3


def test_closed_chain_comes_apart_beyond_its_limit():
    """The 5R under RK4 without Baumgarte holds together at 10 ms and does not at 30 ms."""
    case = ClosedChain("five_bar_computed_torque", "rk4", 0.0)
    assert case.stable(0.01) and not case.stable(0.03)


@pytest.mark.parametrize("duration, h, expected", [(1.0, 0.3, (4, 1.2)), (1.0, 0.25, (4, 1.0)), (0.1, 1.0, (1, 1.0))])
def test_whole_steps_cover_the_duration(duration, h, expected):
    """A run lasts the fewest whole steps that reach the duration."""
    n, total = whole_steps(duration, h)
    assert (n, total) == (expected[0], pytest.approx(expected[1]))


@pytest.mark.parametrize("make, message", [
    (lambda: Tumbling("dual_arm_satellite", 0.0, "rkmk4"), "rate must be finite and > 0"),
    (lambda: Tumbling("dual_arm_satellite", 3.0, "rk5"), "unknown integrator 'rk5'; valid: euler"),
    (lambda: Detumbling("detumble_impulse_both_arms", "rk4"), "unknown integrator 'rk4'"),
    (lambda: ClosedChain("five_bar_computed_torque", "rk45", 0.0), "unknown integrator 'rk45'; valid: rk4, euler, explicit_euler"),
])
def test_bad_case_settings_are_refused_naming_them(make, message):
    """A rate that is not > 0 or an integrator the scene kind does not have is refused before any run."""
    with pytest.raises(FreefloatError, match=message):
        make()
