"""The worst-case gain design of any mechanism linear in its parameters (eqs 154-170): the 5R's
gains as the 5R-only code gave them, the vertices of the parameter box, the feasibility of eq 161
as the spectral radius of |Delta|_max, and the sliding condition on the 2RSU+PPaP."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from freefloat.errors import InvalidArgument
from freefloat.parallel import gain_design
from freefloat.parallel.five_bar import FiveBarParameters
from freefloat.parallel.platform import platform_dynamics
from freefloat.parallel.rsu_ppap import load_data, load_rsu_ppap
from freefloat.parallel.rsu_ppap_masses import RsuPpapModel, with_masses
from freefloat.parallel.sliding_mode import FiveBarModel, PlatformControl, design_gains

#: The 5R-only design's output (commit ac0848c) on the 3 cm grid with cond < 6 (60 points).
REGRESSION = json.loads((Path(__file__).parent / "data" / "five_bar_gains_regression.json").read_text())
EQ_187 = {"n": [75.3, 108.0], "T": [[1.25, 0.92], [1.68, 1.65]],
          (0, 0): [37.0, 54.1], (1, 0): [22.7, 35.5], (1, 1): [17.5, 28.5]}


@pytest.fixture(scope="module")
def five_bar_gains():
    return gain_design.design_gains(FiveBarModel(FiveBarParameters()), np.array(REGRESSION["points"]), eta=20.0)


@pytest.fixture(scope="module")
def rsu():
    data = load_data()
    return RsuPpapModel(load_rsu_ppap().mechanism, data)


def design_condition(model: FiveBarModel, points: np.ndarray,
                     gains: gain_design.SlidingModeGains) -> float:
    """The product of the condition numbers of the design's linear solves in series: the worst of
    those ``model.coefficients`` makes at the points (recorded by wrapping ``numpy.linalg.solve``;
    the fit on the six base parameters dominates: 1.5e4 with its columns scaled to unit largest
    entry, as partial pivoting does not see column scales), the worst ``H`` over the points and
    vertices (``H^-1``), and ``1 - |Delta|_max``."""
    solved = []
    solve = np.linalg.solve
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(np.linalg, "solve", lambda a, b: solved.append(a / np.abs(a).max(axis=0)) or solve(a, b))
        coefficients = [model.coefficients(model.assemble(point))[0] for point in points]
    pis = [model.linear_parameters(theta) for theta in gain_design.vertices(model)]
    worst_H = max(np.linalg.cond(np.tensordot(pi, H_c, 1)) for H_c in coefficients for pi in pis)
    return max(map(np.linalg.cond, solved)) * worst_H * np.linalg.cond(np.eye(model.p) - gains.Delta_max)


def test_generic_design_gives_the_5r_only_codes_gains(five_bar_gains):
    """n, T, n_ij and the worst cases equal the stored output of the 5R-only design within the
    first-order bound on their relative rounding error: the unit roundoff times the product of
    the condition numbers of the design's solves (``design_condition``: 1.5e4 x 15 x 1.9, so
    about 1e-10), compared normwise. numpy 2.4.6 and scipy 1.17.1 moved them by 1.4e-14 to 2.6e-14
    of their norms; eta off by 1e-8 moves n by 4e-10."""
    g = five_bar_gains
    points = np.array(REGRESSION["points"])
    tolerance = np.finfo(float).eps * design_condition(FiveBarModel(FiveBarParameters()), points, g)
    assert tolerance < 1e-9  # still far below any change of the method (a vertex, a term, eta)
    pairs = [(g.n, REGRESSION["n"]), (g.T, REGRESSION["T"]), (g.Delta_max, REGRESSION["Delta_max"]),
             (g.delta0_max, REGRESSION["delta0_max"])]
    pairs += [(g.n_ij[tuple(int(i) for i in key.split(","))], value) for key, value in REGRESSION["n_ij"].items()]
    for ours, stored in pairs:
        assert np.linalg.norm(ours - np.asarray(stored)) <= tolerance * np.linalg.norm(stored), (ours, stored)


def test_5r_wrapper_is_the_generic_design(five_bar_gains):
    """sliding_mode.design_gains (the 5R's parameters) gives the generic design's gains."""
    g = design_gains(FiveBarParameters(), np.array(REGRESSION["points"]))
    assert np.array_equal(g.n, five_bar_gains.n) and np.array_equal(g.T, five_bar_gains.T)


def test_5r_gains_have_eq_187s_magnitudes(five_bar_gains):
    """Every gain is of the order of eq 187's printed one, within a factor 4 (the document's grid
    is not stated, so the numbers can only agree in magnitude: on this 3 cm grid the ratios are
    0.31 to 1.4; docs/parallel.md gives both sets)."""
    g = five_bar_gains
    pairs = [(g.n, EQ_187["n"]), (g.T, EQ_187["T"])] + [(g.n_ij[k], EQ_187[k]) for k in ((0, 0), (1, 0), (1, 1))]
    for ours, printed in pairs:
        ratio = np.asarray(ours) / np.asarray(printed)
        assert np.all((ratio > 0.25) & (ratio < 4.0)), (ours, printed)


def test_vertices_are_every_sign_combination(rsu):
    """2^7 distinct mass sets, each mass at nominal +- its half-width."""
    v = gain_design.vertices(rsu)
    assert v.shape == (128, 7) and len(np.unique(v, axis=0)) == 128
    deviation = np.abs(v - rsu.nominal)
    np.testing.assert_allclose(deviation, np.broadcast_to(rsu.uncertainty, v.shape), rtol=1e-12)


def test_sampled_vertices_are_distinct_vertices(rsu):
    """A sample of 10 gives 10 distinct rows of the full vertex set, the same for the same seed."""
    full = {tuple(r) for r in gain_design.vertices(rsu)}
    sample = gain_design.vertices(rsu, sample=10, seed=3)
    assert len({tuple(r) for r in sample}) == 10 and all(tuple(r) in full for r in sample)
    assert np.array_equal(sample, gain_design.vertices(rsu, sample=10, seed=3))


def test_too_many_vertices_are_refused_unless_sampled(rsu, monkeypatch):
    """Above MAX_VERTICES the design names the count and how to sample."""
    monkeypatch.setattr(gain_design, "MAX_VERTICES", 64)
    with pytest.raises(InvalidArgument, match="128 vertices.*sample=N"):
        gain_design.vertices(rsu)
    assert len(gain_design.vertices(rsu, sample=64)) == 64


def test_worst_cases_of_split_point_sets_combine(rsu):
    """The worst case over two points is the element-wise maximum of each point's."""
    points = np.array([[0.0, 0.0, 0.40], [0.03, -0.02, 0.38]])
    both = gain_design.worst_case(rsu, points)
    one, two = (gain_design.worst_case(rsu, points[i:i + 1]) for i in range(2))
    combined = one.combine(two)
    assert np.array_equal(both.Delta, combined.Delta) and np.array_equal(both.delta0, combined.delta0)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.0, 1.2), min_size=4, max_size=4))
def test_spectral_radius_below_one_iff_eq_161_has_a_solution(entries):
    """For a non-negative |Delta|_max, (1 - |Delta|_max)^-1 exists and is non-negative exactly
    when the spectral radius is below 1 (checked by inverting)."""
    D = np.array(entries).reshape(2, 2)
    radius = gain_design.spectral_radius(D)
    if abs(radius - 1.0) < 1e-9:
        return
    A = np.eye(2) - D
    solvable = abs(np.linalg.det(A)) > 1e-12 and bool((np.linalg.inv(A) >= -1e-12).all())
    assert solvable == (radius < 1.0)


def test_infeasible_worst_case_is_refused():
    """|Delta|_max with spectral radius >= 1 is refused, naming eq 161."""
    worst = gain_design.WorstCase(np.array([[0.5, 0.72], [1.01, 0.5]]), np.zeros(2), {})
    with pytest.raises(InvalidArgument, match="eq 161 has no solution"):
        gain_design.gains_from_worst_case(worst, 20.0, np.zeros((1, 2)))


def test_sliding_condition_holds_on_the_2rsu_ppap(rsu):
    """At the design points, for each of the 128 extreme plants built by scaling the bodies (not
    through the coefficients), the sliding-mode law (PlatformControl, f = sign) with the designed
    gains gives s^T sdot <= -eta sum |s| (eq 144), sdot = qddot# - sigma from the plant's own
    dynamics, for random errors, error rates, reference accelerations and platform rates."""
    points = np.array([[0.03, 0.0, 0.40], [-0.02, 0.03, 0.43]])
    gains = gain_design.design_gains(rsu, points, eta=20.0)
    rng = np.random.default_rng(1)
    lam = 40.0
    for point in points:
        q = rsu.assemble(point)
        for theta in gain_design.vertices(rsu):
            rates, e, edot, qdd_d = (rng.normal(size=3) * w for w in (0.3, 0.01, 0.1, 5.0))
            reference = lambda t: (q[:3] + e, rates + edot, qdd_d)
            law = PlatformControl(rsu.mechanism, reference, lam, gains, "sign")
            tau, _, s = law.law(0.0, q, rsu.mechanism.velocity_map(q) @ rates)
            H, v, g, B = platform_dynamics(with_masses(rsu.mechanism, rsu.data, dict(zip(rsu.names, theta))), q, rates)
            sdot = np.linalg.solve(H, B @ tau - v - g) - (qdd_d + lam * edot)
            assert s @ sdot <= -gains.eta * np.abs(s).sum() + 1e-9


@pytest.mark.parametrize("eta", [float("nan"), -20.0, 0.0, 1e-300, float("inf")])
def test_a_reaching_rate_not_finite_and_positive_is_refused(eta):
    """eta NaN, negative, zero, below MIN_REACHING_RATE or infinite is refused naming eta, not turned
    into NaN, negative or meaningless gains."""
    with pytest.raises(InvalidArgument, match="'eta' must be"):
        design_gains(FiveBarParameters(), np.array([[0.0, 0.2]]), eta=eta)


def test_one_point_as_a_flat_list_is_refused_with_the_shape_expected():
    """A single point given flat, [x, y], is refused as a BadShape naming (N, 2) and the nesting that works."""
    from freefloat.errors import BadShape

    with pytest.raises(BadShape, match=r"array \(N, 2\).*got shape \(2,\) \(one point is \[\[\.\.\., \.\.\.\]\]\)"):
        design_gains(FiveBarParameters(), [0.0, 0.2])


def test_an_unknown_uncertain_parameter_is_refused_with_the_nearest_name():
    """An uncertainty key that is not a FiveBarParameters field is an UnknownName with a did-you-mean."""
    from freefloat.errors import UnknownName

    with pytest.raises(UnknownName, match="unknown uncertain parameter .* 'l11'; did you mean 'l1'"):
        design_gains(FiveBarParameters(), np.array([[0.0, 0.2]]), uncertainty={"l11": 0.01})
