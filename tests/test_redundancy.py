"""Redundant actuation: the effort distribution (minimum norm, weighted, limited) against closed
forms, and the redundantly actuated 5R against Pinocchio and in closed loop."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.closures import kinematics, stacked
from freefloat.errors import BadShape, InfeasiblePlan, InvalidArgument
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.closed_loop import track
from freefloat.parallel.five_bar import (
    REDUNDANT_ACTUATED,
    TRUE_PARAMETERS,
    FiveBarParameters,
    elbow_guess,
    five_bar,
    redundant_five_bar,
)
from freefloat.parallel.platform import platform_dynamics
from freefloat.parallel.redundancy import EffortDistribution, null_space
from freefloat.parallel.sliding_mode import (
    PlatformControl,
    circle_reference,
    design_gains,
)

from .conftest import REPO

NOMINAL = FiveBarParameters()
CLOSURE = REPO / "urdf" / "five_bar_redundant.closure.toml"
POINTS = np.array([[0.07, 0.17], [0.0, 0.22], [-0.05, 0.13]])


def problem(rng: np.random.Generator, p: int, k: int) -> tuple[np.ndarray, np.ndarray]:
    """A random actuation map Z^T (p, k) and required force u* (p,)."""
    return rng.normal(size=(p, k)), rng.normal(size=p)


def motion(mech, point, rng):
    """An assembled 5R pose at ``point`` with random platform rates and accelerations."""
    q = mech.assemble(np.asarray(point, float), elbow_guess(NOMINAL, np.asarray(point, float)))
    return q, rng.normal(size=2), 10.0 * rng.normal(size=2)


def test_minimum_norm_is_the_pseudo_inverse_solution_without_internal_forces():
    """Unit weights, no limits: the efforts are (Z^T)^+ u* (to 1e-14) and their internal part is zero."""
    rng = np.random.default_rng(0)
    for p, k in ((2, 3), (3, 5), (2, 2)):
        ZT, u = problem(rng, p, k)
        shared = EffortDistribution().solve(ZT, u)
        np.testing.assert_allclose(shared.efforts, np.linalg.pinv(ZT) @ u, atol=1e-14 * np.abs(u).max())
        assert np.abs(shared.internal).max() < 1e-14 * np.abs(shared.efforts).max()


def test_weighted_efforts_keep_the_force_and_their_internal_part_is_the_null_space_difference():
    """Weights change the efforts by an internal part alone: Z^T tau = u* to round-off, the internal
    part lies in the null space of Z^T and is tau minus the minimum-norm efforts."""
    rng = np.random.default_rng(1)
    ZT, u = problem(rng, 2, 4)
    shared = EffortDistribution(weights=np.array([1.0, 10.0, 0.1, 3.0])).solve(ZT, u)
    np.testing.assert_allclose(ZT @ shared.efforts, u, atol=1e-14 * np.abs(shared.efforts).max())
    np.testing.assert_allclose(shared.internal, shared.efforts - np.linalg.pinv(ZT) @ u, atol=1e-14)
    N = null_space(ZT)
    np.testing.assert_allclose(N @ (N.T @ shared.internal), shared.internal, atol=1e-14)
    assert np.abs(shared.internal).max() > 0.01


def test_limited_efforts_are_the_closed_form_optimum_with_one_redundant_actuator():
    """With k = p + 1 the efforts are tau_0 + n lambda along the one null direction n; the limited
    weighted optimum clips the unlimited lambda into the interval the limits allow. 200 random
    problems (limits cutting the unlimited solution): efforts equal that closed form to 1e-12,
    within the limits, Z^T tau = u* to round-off."""
    rng = np.random.default_rng(2)
    checked = 0
    while checked < 200:
        ZT, u = problem(rng, 2, 3)
        weights = rng.uniform(0.2, 5.0, 3)
        free = EffortDistribution(weights=weights).solve(ZT, u).efforts
        bound = np.abs(free).max() * rng.uniform(0.5, 0.99)
        n, tau0 = null_space(ZT)[:, 0], np.linalg.pinv(ZT) @ u
        ends = np.sort(np.stack(((-bound - tau0) / n, (bound - tau0) / n)), axis=0)
        low, high = ends[0].max(), ends[1].min()
        if low > high:
            continue
        expected = tau0 + n * np.clip(-(weights * tau0) @ n / ((weights * n) @ n), low, high)
        limited = EffortDistribution(weights=weights, lower=np.full(3, -bound), upper=np.full(3, bound))
        tau = limited.solve(ZT, u).efforts
        np.testing.assert_allclose(tau, expected, atol=1e-12 * bound)
        assert np.all(np.abs(tau) <= bound) and np.abs(ZT @ tau - u).max() <= 1e-13 * bound * np.abs(ZT).max()
        checked += 1


def cost(tau: np.ndarray, weights: np.ndarray) -> float:
    """The distribution's cost ``sum w_i tau_i^2 / 2``."""
    return 0.5 * weights @ tau**2


def test_limited_efforts_are_no_costlier_than_a_general_solvers():
    """With k - p = 2 and 3 (more active limits), the active-set optimum is within the limits,
    gives u* to round-off and costs no more than scipy's SLSQP optimum of the same programme."""
    from scipy.optimize import minimize

    rng = np.random.default_rng(3)
    for p, k in ((2, 4), (3, 6)):
        for _ in range(40):
            ZT, u = problem(rng, p, k)
            weights = rng.uniform(0.2, 5.0, k)
            bound = np.abs(np.linalg.pinv(ZT) @ u).max() * rng.uniform(0.6, 0.95)
            limited = EffortDistribution(weights=weights, lower=np.full(k, -bound), upper=np.full(k, bound))
            try:
                tau = limited.solve(ZT, u).efforts
            except InfeasiblePlan:
                continue
            reference = minimize(cost, np.clip(np.linalg.pinv(ZT) @ u, -bound, bound), args=(weights,), method="SLSQP",
                                 constraints={"type": "eq", "fun": lambda x, ZT=ZT, u=u: ZT @ x - u},
                                 bounds=[(-bound, bound)] * k, options={"ftol": 1e-14, "maxiter": 500})
            assert np.all(np.abs(tau) <= bound) and np.abs(ZT @ tau - u).max() <= 1e-12 * bound * np.abs(ZT).max()
            assert cost(tau, weights) <= cost(reference.x, weights) * (1.0 + 1e-9) + 1e-15


def test_limits_that_cannot_give_the_force_are_refused_by_name():
    """Limits too tight for u*: InfeasiblePlan (reason torque) naming the limits, u* and the miss."""
    ZT, u = np.array([[1.0, 1.0, 0.0], [0.0, 1.0, 1.0]]), np.array([3.0, 3.0])
    with pytest.raises(InfeasiblePlan, match=r"no efforts within the limits \(lower \[-1.0, -1.0, -1.0\], upper "
                                             r"\[1.0, 1.0, 1.0\]\) give the platform force u\* = \[3.0, 3.0\]; the "
                                             r"nearest within them misses it by 1.41") as caught:
        EffortDistribution(lower=-np.ones(3), upper=np.ones(3)).solve(ZT, u)
    assert caught.value.reason == "torque"


@pytest.mark.parametrize(("kwargs", "error", "message"), [
    ({"weights": np.array([1.0, 0.0, 1.0])}, InvalidArgument, "weights must be positive"),
    ({"lower": np.array([0.0, 2.0, 0.0]), "upper": np.ones(3)}, InvalidArgument, "a lower limit is above its upper"),
    ({"lower": np.array([np.nan, 0.0, 0.0])}, InvalidArgument, "'lower' has a NaN"),
])
def test_bad_distributions_are_named(kwargs, error, message):
    """Non-positive weights, crossed limits, a NaN limit: named at construction."""
    with pytest.raises(error, match=message):
        EffortDistribution(**kwargs)


def test_shapes_that_do_not_agree_are_named():
    """Fewer actuators than coordinates, or a force of the wrong size, names both shapes."""
    with pytest.raises(BadShape, match=r"Z\^T \(3, 2\) and u\* \(3,\)"):
        EffortDistribution().efforts(np.ones((3, 2)), np.ones(3))


def test_the_closure_file_gives_the_redundant_5r():
    """five_bar_redundant.closure.toml actuates the base joints and chain 1's elbow, in the order of
    redundant_five_bar, whose forward dynamics it reproduces."""
    loaded = load_closed_chain(CLOSURE)
    assert tuple(loaded.mechanism.actuated) == REDUNDANT_ACTUATED
    rng = np.random.default_rng(4)
    q, rates, _ = motion(loaded.mechanism, POINTS[0], rng)
    qd, tau = loaded.mechanism.velocity_map(q) @ rates, rng.normal(size=3)
    expected = redundant_five_bar(NOMINAL).forward(q, qd, tau)
    np.testing.assert_allclose(loaded.mechanism.forward(q, qd, tau), expected, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("distribution", [
    EffortDistribution(), EffortDistribution(weights=np.array([1.0, 1.0, 20.0])),
    EffortDistribution(lower=np.full(3, -0.25), upper=np.full(3, 0.25)),
], ids=["minimum_norm", "weighted", "limited"])
def test_distributed_efforts_are_pinocchios_inverse_dynamics_up_to_closure_forces(distribution):
    """For platform motions at three poses, the shared efforts of the redundant 5R differ from
    Pinocchio's RNEA of the same tree motion by closure forces alone (J^T lambda: the residual after
    projecting out the closure Jacobian's rows is at round-off), and in pin.constraintDynamics they
    give the platform acceleration back (to 1e-10)."""
    loaded = load_closed_chain(CLOSURE)
    mech, model = replace(loaded.mechanism, distribution=distribution), loaded.model
    data, rng, limits_met = model.createData(), np.random.default_rng(5), 0
    cms = loaded.constraints
    cds = [c.createData() for c in cms]
    pin.initConstraintDynamics(model, data, cms, cds)
    for point in POINTS:
        q, rates, accelerations = motion(mech, point, rng)
        tau, qd, qdd = mech.inverse(q, rates, 0.1 * accelerations)
        if distribution.limited:
            assert np.all(np.abs(tau) <= 0.25)
            limits_met += np.abs(tau).max() == 0.25
        generalized = np.zeros(model.nv)
        generalized[[model.idx_vs[j] for j in loaded.actuated]] = tau
        q_pin, v_pin, a_pin = (loaded.pinocchio_q(x) for x in (q, qd, qdd))
        tree = pin.rnea(model, model.createData(), q_pin, v_pin, a_pin)
        kinematics(model, data, q_pin, v_pin)
        J = stacked(loaded.closures, model, data)[1]
        residual = generalized - tree
        left = residual - J.T @ np.linalg.lstsq(J.T, residual, rcond=None)[0]
        assert np.abs(left).max() <= 1e-12 * np.abs(tree).max()
        back = pin.constraintDynamics(model, data, q_pin, v_pin, generalized, cms, cds, pin.ProximalSettings(1e-14, 1e-12, 50))
        np.testing.assert_allclose(back, a_pin, atol=1e-10 * np.abs(a_pin).max())
    assert limits_met >= distribution.limited


def test_the_gain_design_model_does_not_see_the_actuation():
    """The redundant 5R's platform dynamics (H, v_M, g_M of eq 137, on which eqs 155-170 design the
    gains) equal the square 5R's at random states; only B = C^T U widens."""
    rng = np.random.default_rng(6)
    for point in POINTS:
        q, rates, _ = motion(five_bar(NOMINAL), point, rng)
        square, redundant = platform_dynamics(five_bar(NOMINAL), q, rates), platform_dynamics(redundant_five_bar(NOMINAL), q, rates)
        for a, b in zip(square[:3], redundant[:3]):
            np.testing.assert_allclose(a, b, atol=1e-13 * max(1.0, np.abs(a).max()))
        assert square[3].shape == (2, 2) and redundant[3].shape == (2, 3)


def closed_loop(plant, model, period, duration, gains):
    """Sec 5.6's circle from (0.07, 0.17) at rest: the telemetry and the platform errors (N, 2)."""
    q0 = plant.assemble(np.array([0.07, 0.17]), elbow_guess(TRUE_PARAMETERS, np.array([0.07, 0.17])))
    control = PlatformControl(model, circle_reference, 40.0, gains)
    telemetry = track(plant, control, q0, duration, 2e-4, period, backend="python").telemetry
    return telemetry, control.sliding_variables(telemetry.t, telemetry.q, telemetry.v)[0]


@pytest.fixture(scope="module")
def gains():
    return design_gains(NOMINAL, POINTS[:2], eta=20.0)


def test_a_law_at_every_stage_moves_the_redundant_5r_as_the_square_one(gains):
    """Sliding mode (designed gains, 15 % plant errors) evaluated at every RK4 stage: the redundant
    5R (minimum-norm sharing) follows the square 5R's platform path to round-off (1e-12 m) for
    0.1 s; its peak effort is lower."""
    square, e_square = closed_loop(five_bar(TRUE_PARAMETERS), five_bar(NOMINAL), None, 0.1, gains)
    shared, e_shared = closed_loop(redundant_five_bar(TRUE_PARAMETERS), redundant_five_bar(NOMINAL), None, 0.1, gains)
    assert np.abs(e_square - e_shared).max() < 1e-12
    assert np.abs(shared.efforts).max() < np.abs(square.efforts).max()


def test_the_redundant_5r_tracks_the_circle_as_the_square_one_under_a_held_law(gains):
    """Sec 5.6's closed loop (law held over 0.2 ms, 15 % plant errors, 0.3 s): the redundant 5R
    with effort limits of 3 N m (below the square 5R's peak) tracks the circle after 0.2 s within
    2 % of the square 5R's error, every effort within its limit."""
    limited = EffortDistribution(lower=np.full(3, -3.0), upper=np.full(3, 3.0))
    square, e_square = closed_loop(five_bar(TRUE_PARAMETERS), five_bar(NOMINAL), 2e-4, 0.3, gains)
    shared, e_shared = closed_loop(redundant_five_bar(TRUE_PARAMETERS), redundant_five_bar(NOMINAL, limited), 2e-4, 0.3, gains)
    late = square.t > 0.2
    assert np.abs(square.efforts).max() > 3.0 >= np.abs(shared.efforts).max()
    assert np.all(np.abs(e_shared[late]).max(axis=0) <= 1.02 * np.abs(e_square[late]).max(axis=0))
