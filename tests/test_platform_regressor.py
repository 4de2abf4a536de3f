"""The platform dynamics of the 5R as a regressor on its base parameters, and the Slotine-Li
regressor built from it by polarisation: against Orsino's numpy platform dynamics (eq 137) of
the nominal and the true plants, and the skew-symmetry of dH/dt - 2 C# by finite differences."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.identification.parameters import model_parameters
from freefloat.errors import BadShape, FreefloatError
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.five_bar import (
    TRUE_PARAMETERS,
    TRUE_PARAMETERS_50,
    FiveBarParameters,
    elbow_guess,
    five_bar,
)
from freefloat.parallel.identification import structural_base
from freefloat.parallel.platform import platform_dynamics
from freefloat.parallel.platform_regressor import (
    PlatformRegressor,
    five_bar_regressor,
    five_bar_theta,
)
from freefloat.parallel.registry import five_bar_inertias
from freefloat.parallel.sliding_mode import workspace_grid
from freefloat.paths import URDF_DIR

PLANTS = {"nominal": FiveBarParameters(), "15 %": TRUE_PARAMETERS, "50 %": TRUE_PARAMETERS_50}


@pytest.fixture(scope="module")
def chain():
    """The 5R's closure file (nominal inertias: the regressor does not read them)."""
    return load_closed_chain(URDF_DIR / "five_bar.closure.toml")


def states(chain, count: int, seed: int):
    """``count`` assembled poses within 5 cm of (0, 0.17) m with standard normal platform rates
    and accelerations."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        x = np.array([0.0, 0.17]) + rng.uniform(-0.05, 0.05, 2)
        yield chain.mechanism.assemble(x, elbow_guess(FiveBarParameters(), x)), rng.normal(size=2), rng.normal(size=2)


@pytest.mark.parametrize("plant", PLANTS)
def test_regressor_times_the_base_parameters_is_the_platform_dynamics(chain, plant):
    """Y*(q, qd#, qdd#) theta(p) equals H qdd# + v_M + g_M of Orsino's numpy model with parameters p
    to 1e-12 of its size, at 10 random states."""
    regressor, theta = five_bar_regressor(chain), five_bar_theta(PLANTS[plant])
    reference = five_bar(PLANTS[plant]).reference()
    for q, xd, xdd in states(chain, 10, 0):
        H, v, g, _ = platform_dynamics(reference, q, xd)
        expected = H @ xdd + v + g
        assert np.abs(regressor.platform(q, xd, xdd) @ theta - expected).max() < 1e-12 * np.abs(expected).max()


def test_base_parameters_of_the_identification_give_the_same_dynamics(chain):
    """On the closure's 11 base parameters (the identification's), Y* beta of the 50 % plant's
    tree equals Orsino's platform dynamics to 1e-12."""
    rng = np.random.default_rng(1)
    points = workspace_grid(FiveBarParameters(), 0.02)
    base = structural_base(chain, points[rng.choice(len(points), 20, replace=False)],
                           lambda x: elbow_guess(FiveBarParameters(), x), rng)
    true = pin.Model(chain.model)
    five_bar_inertias(TRUE_PARAMETERS_50, true)
    regressor, beta = PlatformRegressor.base(chain, base), base.of(model_parameters(true))
    reference = five_bar(TRUE_PARAMETERS_50).reference()
    for q, xd, xdd in states(chain, 5, 2):
        H, v, g, _ = platform_dynamics(reference, q, xd)
        expected = H @ xdd + v + g
        assert np.abs(regressor.platform(q, xd, xdd) @ beta - expected).max() < 1e-12 * np.abs(expected).max()


def test_slotine_li_regressor_at_the_measured_rates_is_the_platform_regressor(chain):
    """W(q, qd#, qd_r = qd#, qdd_r) = Y*(q, qd#, qdd_r): C#(qd#) qd# is the velocity term."""
    regressor = five_bar_regressor(chain)
    for q, xd, xdd in states(chain, 5, 3):
        Y = regressor.platform(q, xd, xdd)
        assert np.abs(regressor.slotine_li(q, xd, xd, xdd) - Y).max() < 1e-12 * np.abs(Y).max()


def velocity_matrix(regressor, q, xd, theta):
    """C#(q, qd#) (p, p) column by column from W."""
    zero = np.zeros(2)
    static = regressor.slotine_li(q, xd, zero, zero) @ theta
    return np.stack([regressor.slotine_li(q, xd, e, zero) @ theta - static for e in np.eye(2)], axis=1)


def inertia(regressor, q, theta):
    """H(q) (p, p) column by column from W."""
    zero = np.zeros(2)
    static = regressor.slotine_li(q, zero, zero, zero) @ theta
    return np.stack([regressor.slotine_li(q, zero, zero, e) @ theta - static for e in np.eye(2)], axis=1)


def test_velocity_matrix_makes_dH_dt_minus_twice_it_skew_symmetric(chain):
    """x^T (dH/dt - 2 C#) x = 0 (what the adaptive law's Lyapunov argument needs): dH/dt by central
    differences of H along qd# (h = 1e-6 s, the poses assembled), its symmetric part below 1e-7 of
    the size of dH/dt and 2 C# (the differences' round-off is about 1e-10 of it), at 5 random
    states of the 15 % plant."""
    regressor, theta = five_bar_regressor(chain), five_bar_theta(TRUE_PARAMETERS)
    h = 1e-6
    for q, xd, _ in states(chain, 5, 4):
        ahead = chain.mechanism.assemble(q[:2] + h * xd, q[2:])
        behind = chain.mechanism.assemble(q[:2] - h * xd, q[2:])
        Hdot = (inertia(regressor, ahead, theta) - inertia(regressor, behind, theta)) / (2 * h)
        C = velocity_matrix(regressor, q, xd, theta)
        N = Hdot - 2.0 * C
        assert np.abs(N + N.T).max() < 1e-7 * (np.abs(Hdot).max() + 2.0 * np.abs(C).max())


def test_polarised_velocity_matrix_is_not_any_factorisation(chain):
    """The symmetric split v_M = C(qd#) qd# with C = B(qd#, .) only: a different factorisation
    of the same v_M (C# plus a matrix S(qd#) with S qd# = 0) breaks the skew-symmetry (so the test
    above can fail)."""
    regressor, theta = five_bar_regressor(chain), five_bar_theta(TRUE_PARAMETERS)
    q, xd, _ = next(states(chain, 1, 5))
    h = 1e-6
    ahead = chain.mechanism.assemble(q[:2] + h * xd, q[2:])
    behind = chain.mechanism.assemble(q[:2] - h * xd, q[2:])
    Hdot = (inertia(regressor, ahead, theta) - inertia(regressor, behind, theta)) / (2 * h)
    n = np.array([-xd[1], xd[0]])
    other = velocity_matrix(regressor, q, xd, theta) + np.outer(np.ones(2), n)   # same C qd#: n . qd# = 0
    N = Hdot - 2.0 * other
    assert np.abs(N + N.T).max() > 1e-2 * (np.abs(Hdot).max() + 2.0 * np.abs(other).max())


def test_a_platform_with_mass_is_refused(chain):
    """A 5R whose platform point carries 0.1 kg: its dynamics are not the tree's regressor."""
    heavy = replace(chain, mechanism=replace(chain.mechanism, platform_mass=0.1 * np.eye(2)))
    with pytest.raises(FreefloatError, match="platform has mass"):
        PlatformRegressor(heavy, np.zeros((40, 1)), ("x",))


def test_structure_of_the_wrong_shape_is_refused(chain):
    """A structure without the tree's 40 rows, or names not matching its columns, names both."""
    with pytest.raises(BadShape, match=r"\(40, 2\)"):
        PlatformRegressor(chain, np.zeros((30, 2)), ("a", "b"))
    with pytest.raises(BadShape, match=r"\(40, 1\)"):
        PlatformRegressor(chain, np.zeros((40, 2)), ("a",))
