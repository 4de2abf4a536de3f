"""The worst-case gain design with DC-motor drives (freefloat.parallel.drive_gain_design): it reduces to
the thesis's design without motors, its box bounds are exact, and the sliding condition holds at the
design points for extreme plants with extreme motors."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

from freefloat.dynamics.motors import DCMotor
from freefloat.parallel import gain_design
from freefloat.parallel.drive_gain_design import (
    DrivenModel,
    design_gains,
    drive_bounds,
    largest_over_box,
)
from freefloat.parallel.drives import five_bar_motors, motorised
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.platform import platform_dynamics
from freefloat.parallel.sliding_mode import FiveBarModel, extreme_parameters

NOMINAL = FiveBarParameters()
POINTS = np.array([[0.07, 0.17], [0.0, 0.22]])
MOTORS = five_bar_motors()


def test_without_motors_it_is_the_thesis_design():
    """Massless rotors, no motor uncertainty, torque input: the gains of gain_design on the 5R (1e-12)."""
    rigid = DCMotor.stack([replace(MOTORS.motors[i], rotor_inertia=0.0) for i in range(2)])
    ours = design_gains(DrivenModel(FiveBarModel(NOMINAL), rigid, {}, voltage=False), POINTS)
    theirs = gain_design.design_gains(FiveBarModel(NOMINAL), POINTS)
    np.testing.assert_allclose(ours.n, theirs.n, rtol=1e-12)
    np.testing.assert_allclose(ours.T, theirs.T, rtol=1e-12, atol=1e-14)
    for key, value in theirs.n_ij.items():
        np.testing.assert_allclose(ours.n_ij[key], value, rtol=1e-12)
    assert all(np.all(v == 0.0) for v in ours.n_rate.values())


def test_bounds_are_the_torque_constant_and_friction_errors():
    """Voltage input: rho = k_t / k^_t over +-15 %; torque input: rho = 1; beta and gamma are
    rho b^ - b and rho c^ - c at the vertices (their extremes)."""
    m, r = MOTORS.motors, MOTORS.uncertainty
    voltage, torque = drive_bounds(m, r, True), drive_bounds(m, r, False)
    np.testing.assert_allclose(voltage.rho, [[0.85, 0.85], [1.15, 1.15]], rtol=1e-14)
    np.testing.assert_array_equal(torque.rho, np.ones((2, 2)))
    c = m.coulomb
    np.testing.assert_allclose(voltage.gamma, [0.85 * c - 1.15 * c, 1.15 * c - 0.85 * c], rtol=1e-12)
    np.testing.assert_allclose(torque.gamma, [c - 1.15 * c, c - 0.85 * c], rtol=1e-12)


def test_largest_over_box_is_the_vertices_maximum():
    """max |c + s . x| over a box equals the brute-force maximum over its 2^k vertices."""
    rng = np.random.default_rng(0)
    constant, slopes = rng.normal(size=(3, 2)), rng.normal(size=(3, 2, 4))
    box = np.sort(rng.normal(size=(2, 4)), axis=0)
    brute = np.max([np.abs(constant + slopes @ np.array(v)) for v in itertools.product(*box.T)], axis=0)
    np.testing.assert_allclose(largest_over_box(constant, slopes, box), brute, rtol=1e-14)


@pytest.fixture(scope="module")
def gains():
    return design_gains(DrivenModel(FiveBarModel(NOMINAL), MOTORS.motors, MOTORS.uncertainty, voltage=True), POINTS)


def test_sliding_condition_holds_for_extreme_plants_and_drives(gains):
    """At the design points, for 40 vertices (seeded) of the links' six parameters, the rotors'
    inertias and each motor's torque constant, viscous and Coulomb friction: the law (eq 153, f =
    sign) on the motorised nominal 5R, its efforts delivered as (k_t / k^_t) tau_d (the drive's
    current at rest), through the true motorised 5R, gives sign(s_i) sdot_i <= -eta (eq 144, each
    coordinate) for every sign of s and sigma = (+-30, +-30) 1/s^2, at slow and fast rates (the
    friction's tanh at 0.1 and at 1). The torque-input design's gains fail it."""
    assert violations(gains) == 0
    torque = design_gains(DrivenModel(FiveBarModel(NOMINAL), MOTORS.motors, MOTORS.uncertainty, voltage=False), POINTS)
    assert violations(torque) > 0


def violations(gains) -> int:
    """How many (plant, rates, s, sigma) of the test above break the sliding condition."""
    rng = np.random.default_rng(1)
    nominal = motorised(five_bar(NOMINAL), MOTORS.motors)
    extremes = list(extreme_parameters(NOMINAL))
    signs = list(itertools.product((-1.0, 1.0), repeat=8))  # J_m, k_t, b, c of each motor
    corners = [np.array(c) for c in itertools.product((-1.0, 1.0), repeat=2)]
    broken = 0
    for point in POINTS:
        q = nominal.assemble(point, elbow_guess(NOMINAL, point))
        for _ in range(40):
            sign = np.array(signs[rng.integers(len(signs))]).reshape(4, 2)
            true_motors = replace(MOTORS.motors, **{name: getattr(MOTORS.motors, name) * (1.0 + 0.15 * s)
                                                   for name, s in zip(("rotor_inertia", "torque_constant", "viscous",
                                                                       "coulomb"), sign)})
            true = motorised(five_bar(extremes[rng.integers(len(extremes))]), true_motors)
            rho = true_motors.torque_constant / MOTORS.motors.torque_constant
            for speed in (1e-3, 1.0):
                qd = speed * rng.normal(size=2)
                H, v, g, B = platform_dynamics(true, q, qd)
                H_hat, v_hat, g_hat, B_hat = platform_dynamics(nominal, q, qd)
                for s, sigma in itertools.product(corners, corners):
                    sigma = 30.0 * sigma
                    tau = np.linalg.solve(B_hat, v_hat + g_hat + H_hat @ (sigma - gains.k(sigma, qd) * s))
                    sdot = np.linalg.solve(H, B @ (rho * tau) - v - g) - sigma
                    broken += int(np.any(s * sdot > -gains.eta + 1e-9))
    return broken


def test_voltage_input_needs_larger_gains_than_torque_input(gains):
    """The torque constant's 15 % makes every gain larger than torque input's on the same motorised
    5R, and adds gains on the rates (the viscous friction's error)."""
    torque = design_gains(DrivenModel(FiveBarModel(NOMINAL), MOTORS.motors, MOTORS.uncertainty, voltage=False), POINTS)
    assert np.all(gains.n > torque.n) and np.all(gains.T > torque.T)
    assert np.all(gains.n_rate[0] > 0.0) and gains.n_rate[0][0] > torque.n_rate[0][0]
