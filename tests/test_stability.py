"""The bisection for the largest stable step, on x' = -lambda x where the limits are known."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.dynamics.stability import largest_stable_step
from freefloat.errors import InvalidArgument

LAMBDA = 50.0


def euler_step(x: float, h: float) -> float:
    """Explicit Euler on x' = -LAMBDA x."""
    return x - h * LAMBDA * x


def rk4_step(x: float, h: float) -> float:
    """Classical RK4 on x' = -LAMBDA x, written out stage by stage."""
    k1 = -LAMBDA * x
    k2 = -LAMBDA * (x + h / 2 * k1)
    k3 = -LAMBDA * (x + h / 2 * k2)
    k4 = -LAMBDA * (x + h * k3)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def bounded(step, steps: int = 20000):
    """``stable(h)``: after ``steps`` steps from x = 1, |x| has not grown."""
    def stable(h: float) -> bool:
        x = 1.0
        for _ in range(steps):
            x = step(x, h)
            if not abs(x) <= 1.0:
                return False
        return True
    return stable


@pytest.mark.parametrize("step, boundary", [(euler_step, 2.0), (rk4_step, 2.785293563405282)],
                         ids=["euler", "rk4"])
def test_bisection_finds_the_analytic_limit(step, boundary):
    """Explicit Euler is stable for h < 2/lambda, RK4 for h < 2.7853/lambda: the bracket holds the limit."""
    limit = largest_stable_step(bounded(step), 1e-4, 1.0, rtol=1e-4)
    assert limit.stable < boundary / LAMBDA <= limit.unstable
    assert limit.unstable / limit.stable - 1.0 <= 1e-4


def test_bisection_reaches_the_relative_bracket_in_few_calls():
    """A bracket of 1e-4 across four decades takes the log2 of ln(1e4)/1e-4 calls, about 17."""
    limit = largest_stable_step(lambda h: h < 0.01234, 1e-4, 1.0, rtol=1e-4)
    assert limit.stable < 0.01234 <= limit.unstable
    assert limit.evaluations <= int(np.ceil(np.log2(np.log(1e4) / 1e-4))) + 1


def test_all_stable_gives_an_open_bracket_at_high():
    """When even the highest step is stable, the result says so (no unstable step)."""
    limit = largest_stable_step(lambda h: True, 1e-3, 1.0)
    assert limit.stable == 1.0 and limit.unstable is None and not limit.bracketed


def test_all_unstable_gives_an_open_bracket_at_low():
    """When even the lowest step is unstable, the result says so (no stable step)."""
    limit = largest_stable_step(lambda h: False, 1e-3, 1.0)
    assert limit.stable is None and limit.unstable == 1e-3 and not limit.bracketed


@pytest.mark.parametrize("low, high, rtol", [(0.0, 1.0, 0.1), (1.0, 0.5, 0.1), (1e-3, float("nan"), 0.1),
                                             (1e-3, 1.0, 0.0)])
def test_bad_search_settings_are_refused(low, high, rtol):
    """A bracket that is not 0 < low < high, or rtol <= 0, is refused with the values named."""
    with pytest.raises(InvalidArgument, match="stability search"):
        largest_stable_step(lambda h: True, low, high, rtol)
