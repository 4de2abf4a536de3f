"""The gain-feasibility map (issue 21 item 5): its infeasible points violate eq 161's condition and
its feasible ones meet it, evaluated independently (each extreme 5R built and its H computed
directly); the critical scale brackets the change; the pooled radius is the design's; the atlas
kind through the engine."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from freefloat.app.atlas.engine import run_atlas
from freefloat.app.atlas.kinds import Options
from freefloat.errors import InvalidArgument, UnknownName
from freefloat.parallel import gain_design
from freefloat.parallel.five_bar import FiveBarParameters, five_bar
from freefloat.parallel.gain_feasibility import (
    BISECTIONS,
    delta_max,
    feasibility,
    largest_scale,
    region_radius,
    scaled_vertices,
)
from freefloat.parallel.platform import platform_dynamics
from freefloat.parallel.sliding_mode import UNCERTAINTY, FiveBarModel

NOMINAL = FiveBarParameters()
#: Two points near the 5R's lower singular region (critical scales 1.06 and 1.41), two far
#: from it (2.66, 2.62), and one out of reach.
POINTS = np.array([[0.032, 0.032], [-0.032, 0.048], [0.16, 0.08], [0.0, 0.224], [0.30, 0.30]])
#: The stated uncertainties grown by half: the first two points become infeasible.
WIDE = FiveBarModel(NOMINAL, {k: 1.5 * v for k, v in UNCERTAINTY.items()})


@pytest.fixture(scope="module")
def wide_map():
    return feasibility(WIDE, POINTS)


def independent_delta_max(model: FiveBarModel, point: np.ndarray) -> np.ndarray:
    """|Delta|_max at ``point`` over the 64 extreme 5Rs, each built from its parameters and its H
    from platform_dynamics (no coefficients, no linearity)."""
    est = five_bar(model.params)
    q = model.assemble(point)
    H_hat = platform_dynamics(est, q, np.zeros(2))[0]
    out = np.zeros((2, 2))
    for theta in gain_design.vertices(model):
        true = five_bar(replace(model.params, **dict(zip(model.names, theta))))
        out = np.maximum(out, np.abs(np.linalg.solve(platform_dynamics(true, q, np.zeros(2))[0], H_hat) - np.eye(2)))
    return out


def eq_161_solvable(D: np.ndarray) -> bool:
    """(1 - D)^-1 exists and has no negative entry."""
    A = np.eye(len(D)) - D
    if abs(np.linalg.det(A)) < 1e-12:
        return False
    return bool((np.linalg.inv(A) >= 0.0).all())


def test_map_marks_unreachable_points(wide_map):
    """The point out of either chain's reach is not assembled, its radius NaN, not feasible."""
    assert wide_map.assembled.tolist() == [True, True, True, True, False]
    assert np.isnan(wide_map.radius[4]) and not wide_map.feasible[4]


def test_infeasible_points_violate_eq_161_and_feasible_ones_meet_it(wide_map):
    """With the uncertainties x 1.5 the first two points are infeasible, and there (1 - |Delta|_max)^-1
    from the independent evaluation is singular or has a negative entry; at the others it is
    non-negative."""
    assert wide_map.feasible.tolist() == [False, False, True, True, False]
    for k in range(4):
        D = independent_delta_max(WIDE, POINTS[k])
        np.testing.assert_allclose(wide_map.Delta[k], D, rtol=1e-9, atol=1e-12)
        assert eq_161_solvable(D) == bool(wide_map.feasible[k])


def test_batched_delta_is_the_gain_designs(wide_map):
    """The map's |Delta|_max equals the design's worst case at the same point (loop over vertices)."""
    design = gain_design.worst_case(WIDE, POINTS[2:3])
    np.testing.assert_allclose(wide_map.Delta[2], design.Delta, rtol=1e-12, atol=1e-15)


def test_critical_scale_brackets_the_change(wide_map):
    """Feasible with the half-widths scaled by s* (in units of the wide model's), infeasible one
    bisection step above; feasible at the stated uncertainty exactly where s* > 1."""
    step = wide_map.s_max * 2.0**-BISECTIONS
    signs = np.sign(gain_design.vertices(WIDE) - WIDE.nominal)
    for k in range(4):
        H_c = WIDE.coefficients(WIDE.assemble(POINTS[k]))[0]
        s = wide_map.scale[k]
        assert gain_design.spectral_radius(delta_max(WIDE, H_c, scaled_vertices(WIDE, signs, s))) < 1.0
        above = gain_design.spectral_radius(delta_max(WIDE, H_c, scaled_vertices(WIDE, signs, s + 1.01 * step)))
        assert above >= 1.0
        assert (s > 1.0) == bool(wide_map.feasible[k])
    assert wide_map.s_max == pytest.approx(largest_scale(WIDE))


def test_pooled_radius_is_the_designs_over_those_points(wide_map):
    """region_radius over the feasible points is the spectral radius of the design's |Delta|_max
    over them; the design there succeeds exactly when it is below 1."""
    mask = wide_map.feasible
    design = gain_design.worst_case(WIDE, POINTS[mask])
    assert region_radius(wide_map.Delta, mask) == pytest.approx(gain_design.spectral_radius(design.Delta), rel=1e-12)
    assert np.isnan(region_radius(wide_map.Delta, np.zeros(len(POINTS), bool)))


@pytest.mark.slow
def test_atlas_kind_maps_the_2rsu_ppap(tmp_path):
    """``freefloat atlas feasibility rsu_ppap --axes x y --grid 4`` through the engine: the arrays
    on the grid, every assembled point feasible at the stated +-15 % masses (critical scale up to
    1 / (2 x 0.15): all masses halved gives Delta = 1)."""
    run = run_atlas("feasibility", "rsu_ppap", Options(grid=4, axes=("x", "y")), tmp_path / "a")
    assert run.result["radius"].shape == (16,) and run.result["Delta"].shape == (16, 3, 3)
    s = run.summary["summary"]
    assert s["assembled"] > 0 and s["feasible"] == s["assembled"]
    assert s["scale_median"] <= 1.0 / 0.3 + 1e-6
    assert (run.folder / "feasibility.png").exists()


@pytest.mark.parametrize("target, options, error, match", [
    ("four_arm", Options(), UnknownName, "five_bar, rsu_ppap"),
    ("five_bar", Options(axes=("x", "z")), InvalidArgument, "two distinct platform coordinates of x, y"),
    ("rsu_ppap", Options(axes=("x", "x")), InvalidArgument, "got x, x"),
])
def test_bad_targets_and_axes_are_named(tmp_path, target, options, error, match):
    with pytest.raises(error, match=match):
        run_atlas("feasibility", target, options, tmp_path / "b")
