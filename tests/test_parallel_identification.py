"""A closed chain's parameters identified through Orsino's coupling (the 5R), and the worst-case
gain design fed by the identified intervals."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.identification.excitation import random_trajectory
from freefloat.dynamics.identification.measurements import channel_scale, noisy
from freefloat.dynamics.identification.parameters import model_parameters
from freefloat.parallel import gain_design
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.identification import (
    RegressorModel,
    actuator_regressor,
    identify,
    platform_states,
    structural_base,
    with_tree_parameters,
)
from freefloat.parallel.platform import platform_dynamics, quadratic_coefficients
from freefloat.parallel.registry import five_bar_inertias
from freefloat.parallel.sliding_mode import design_gains, workspace_grid
from freefloat.paths import URDF_DIR


def guess(point):
    """Outward elbows (the geometry is the nominal one's; only the inertias are off)."""
    return elbow_guess(FiveBarParameters(), point)


@pytest.fixture(scope="module")
def five_bar_case():
    """The 5R's closure file, its base parameters, the true plant's (15 % off, sec 5.6) values
    and a design grid (every 20th point of the 1 cm workspace grid)."""
    chain = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
    rng = np.random.default_rng(0)
    points = workspace_grid(FiveBarParameters(), 0.01)
    base = structural_base(chain, points[rng.choice(len(points), 40, replace=False)], guess, rng)
    true_model = pin.Model(chain.model)
    five_bar_inertias(TRUE_PARAMETERS, true_model)
    return chain, base, model_parameters(true_model), points[::20]


@pytest.fixture(scope="module")
def identified(five_bar_case):
    """Two periods (0.5 s) of a Fourier platform motion within 5 cm and 1 m/s of (0, 0.17) m,
    2000 samples; the true plant's actuator efforts (Orsino's inverse dynamics); 1 % noise on the
    platform coordinates, rates and efforts (accelerations from the known trajectory)."""
    chain, base, _, _ = five_bar_case
    trajectory = random_trajectory(np.array([0.0, 0.17]), 5, 0.5, 0.05, 1.0, np.random.default_rng(2))
    _, (x, xd, xdd) = trajectory.sample(2000)
    q, _, _ = platform_states(chain, x, xd, xdd, guess(x[0]))
    tau = five_bar(TRUE_PARAMETERS).reference().inverse(q, xd, xdd)[0]
    rng = np.random.default_rng(5)
    x_m = noisy(x, 0.01, rng, channel_scale(x, positions=True))
    states = platform_states(chain, x_m, noisy(xd, 0.01, rng), xdd, guess(x_m[0]))
    return identify(chain, base, *states, noisy(tau, 0.01, rng))


def test_actuator_regressor_gives_orsinos_inverse_dynamics(five_bar_case):
    """(C^T U)^-1 C^T S Y pi at random assembled states equals Orsino's inverse dynamics
    (eqs 130-140, the numpy reference) of the nominal and of the true 5R (round-off)."""
    chain, _, pi_true, points = five_bar_case
    rng = np.random.default_rng(1)
    q = np.array([chain.mechanism.assemble(x, guess(x)) for x in points[:15]])
    xd, xdd = rng.normal(size=(15, 2)), rng.normal(size=(15, 2))
    tau, qd, qdd = chain.mechanism.reference().inverse(q, xd, xdd)
    W = actuator_regressor(chain, q, qd, qdd)
    np.testing.assert_allclose(W @ model_parameters(chain.model), tau.ravel(), atol=1e-12 * np.abs(tau).max())
    tau_true = five_bar(TRUE_PARAMETERS).reference().inverse(q, xd, xdd)[0]
    np.testing.assert_allclose(W @ pi_true, tau_true.ravel(), atol=1e-12 * np.abs(tau_true).max())


def test_the_closure_leaves_eleven_base_parameters(five_bar_case):
    """Two planar RR chains have 6 base parameters each under in-plane gravity; the shared tip
    (a mass there belongs to either chain) takes one: 11, grouped as Khalil's."""
    base = five_bar_case[1]
    assert base.rank == 11
    assert "c1_joint1.Izz + 0.0144 c1_joint2.m + 0.096 c2_joint2.mcx" in base.labels()


def test_noisy_identification_holds_the_truth_in_its_intervals(five_bar_case, identified):
    """Every base parameter's 95 % interval holds its true value, and each estimate is within 1 %
    of it or of the largest (the first moments about y are zero)."""
    base, pi_true = five_bar_case[1], five_bar_case[2]
    beta = base.of(pi_true)
    lower, upper = identified.interval(0.95)
    assert np.all((lower <= beta) & (beta <= upper))
    assert np.all(np.abs(identified.values - beta) <= 0.01 * np.maximum(np.abs(beta), np.abs(beta).max()))


def test_identified_mechanism_has_the_true_dynamics(five_bar_case):
    """Orsino's mechanism rebuilt from any preimage of the true base parameters gives the true
    plant's efforts: the dynamics depend on the base parameters only."""
    chain, base, pi_true, points = five_bar_case
    mech = with_tree_parameters(chain, base.preimage(base.of(pi_true), model_parameters(chain.model)))
    rng = np.random.default_rng(3)
    q = np.array([chain.mechanism.assemble(x, guess(x)) for x in points[:5]])
    xd, xdd = rng.normal(size=(5, 2)), rng.normal(size=(5, 2))
    expected = five_bar(TRUE_PARAMETERS).reference().inverse(q, xd, xdd)[0]
    np.testing.assert_allclose(mech.reference().inverse(q, xd, xdd)[0], expected, atol=1e-12 * np.abs(expected).max())


def test_regressor_model_coefficients_are_eq_137s_terms(five_bar_case):
    """At the true base parameters, the coefficients give H, g_M and delta_ij of the true 5R's
    platform dynamics (eqs 137, 162), computed by Orsino's reference."""
    chain, base, pi_true, points = five_bar_case
    beta = base.of(pi_true)
    model = RegressorModel(chain, base, beta, np.zeros_like(beta), guess)
    true = five_bar(TRUE_PARAMETERS).reference()
    for x in points[:3]:
        q = model.assemble(x)
        H_c, g_c, quad_c = model.coefficients(q)
        H, _, g, _ = platform_dynamics(true, q, np.zeros(2))
        np.testing.assert_allclose(np.tensordot(beta, H_c, 1), H, atol=1e-12 * np.abs(H).max())
        np.testing.assert_allclose(beta @ g_c, g, atol=1e-12 * np.abs(g).max())
        for key, value in quadratic_coefficients(true, q).items():
            np.testing.assert_allclose(beta @ quad_c[key], value, atol=1e-11 * max(1.0, np.abs(value).max()))


def test_identified_intervals_give_a_feasible_design_with_smaller_gains(five_bar_case, identified):
    """The worst-case design over the identified 95 % joint box (2^11 vertices) has a solution,
    its box holds the true base parameters, and its gains are below those of the thesis's
    stated 15 % intervals on the same points (eqs 156-170)."""
    chain, base, pi_true, points = five_bar_case
    model = RegressorModel.identified(chain, base, identified, guess, level=0.95)
    assert np.all(np.abs(base.of(pi_true) - model.nominal) <= model.uncertainty)
    gains = gain_design.design_gains(model, points, eta=20.0)
    thesis = design_gains(FiveBarParameters(), points, eta=20.0)
    assert gain_design.spectral_radius(gains.Delta_max) < 1.0
    assert np.all(gains.n < thesis.n) and np.all(gains.T < thesis.T)
