"""The size sweeps' growth exponent (freefloat.lab.bench.suites.growth) on analytic power laws."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.lab.bench.suites.growth import exponent, exponents


@pytest.mark.parametrize("p", [0.0, 1.0, 2.0, 2.7])
def test_exponent_of_a_power_law_is_its_power(p):
    """``t = c nv^p`` gives back p, whatever c."""
    sizes = np.array([14.0, 22.0, 38.0, 70.0, 134.0, 198.0])
    assert exponent(sizes, 3e-6 * sizes**p) == pytest.approx(p, abs=1e-12)


def test_exponents_read_nv_as_joints_plus_six():
    """Rows carry n_joints; the fit is against nv = n_joints + 6, one exponent per key."""
    rows = [{"n_joints": n, "a": (n + 6) ** 1.0, "b": (n + 6) ** 2.0} for n in (8, 16, 32, 64)]
    assert exponents(rows, ["a", "b"], lambda row, key: row[key]) == pytest.approx({"a": 1.0, "b": 2.0})
