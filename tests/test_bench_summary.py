"""The cheapest method per accuracy band: log-log interpolation along each curve, and the ratio."""

from __future__ import annotations

import math

import pytest

from freefloat.lab.bench.race.scene import Method
from freefloat.lab.bench.race.summary import band_rows, cheapest, summary_lines, time_to_reach
from freefloat.lab.bench.race.sweep import Point


def _curve(package: str, integrator: str, c: float, order: float) -> list[Point]:
    """Points on ``time = c * error^(-1/order)`` at errors 1e-2 ... 1e-10."""
    return [Point(Method(package, integrator, 10.0 ** -k), c * (10.0 ** -k) ** (-1.0 / order),
                  {"state_error": 10.0 ** -k})
            for k in range(2, 11, 2)]


def test_time_to_reach_interpolates_a_power_law_exactly():
    """Between measured points of a power law the interpolated time is the law's time."""
    curve = _curve("freefloat", "rkmk4", 2e-3, 4.0)
    assert time_to_reach(curve, 1e-5) == pytest.approx(2e-3 * 1e5 ** 0.25, rel=1e-12)


def test_time_to_reach_is_infinite_below_the_curve():
    """A band tighter than every measured error is not reached."""
    assert math.isinf(time_to_reach(_curve("mujoco", "RK4", 1e-3, 4.0), 1e-12))


def test_cheapest_picks_the_faster_method_of_a_package():
    """Of two curves of one package, the one with the lower time at the band wins."""
    points = _curve("freefloat", "euler", 1e-3, 1.0) + _curve("freefloat", "rkmk4", 1e-3, 4.0)
    assert cheapest(points, "freefloat", 1e-6).label == "freefloat rkmk4"
    assert cheapest(points, "mujoco", 1e-6) is None


def test_band_ratio_says_which_package_is_faster():
    """The ratio is freefloat's time over MuJoCo's; the line names the faster one and by how much."""
    points = _curve("freefloat", "rkmk4", 3e-3, 4.0) + _curve("mujoco", "RK4", 1e-3, 4.0)
    rows = band_rows(points, (1e-5,))
    assert rows[0]["mujoco_speedup"] == pytest.approx(3.0, rel=1e-12)
    assert summary_lines("s", rows) == [
        f"s error <= 1e-05: freefloat rkmk4 {3e-3 * 1e5 ** 0.25 * 1e3:.3g} ms, "
        f"mujoco RK4 {1e-3 * 1e5 ** 0.25 * 1e3:.3g} ms: MuJoCo 3.00x faster"]


def test_band_met_by_the_coarsest_point_is_an_upper_bound():
    """A band the coarsest measured setting already meets is flagged and said "at most"."""
    rows = band_rows(_curve("freefloat", "rkmk4", 1e-3, 4.0) + _curve("mujoco", "RK4", 1e-3, 4.0), (1e-1,))
    assert rows[0]["freefloat"]["upper_bound"] and rows[0]["mujoco"]["upper_bound"]
    assert "rkmk4 at most" in summary_lines("s", rows)[0]
    assert not band_rows(_curve("mujoco", "RK4", 1e-3, 4.0), (1e-5,))[0]["mujoco"]["upper_bound"]
