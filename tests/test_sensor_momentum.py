"""The momentum estimator: its map against the hand-built GJM's momentum, its configuration
derivative against finite differences, its error against Pinocchio's centroidal momentum under
noise, its restarts at impulses, and the velocity it hands a law carrying its estimate."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics import gjm
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import make_model
from freefloat.dynamics.sensors import Channel, MomentumKalman, Sensors, SensorSettings
from freefloat.dynamics.sensors.momentum import CONSERVED, configuration_derivative, origin_map
from freefloat.dynamics.simulation import run
from freefloat.robot.conventions import momentum_about_origin

from .conftest import random_state

T = 1e-3


def robot_of(name: str, base: str = "free", gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)):
    """A catalogue robot without visuals (its inertia warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(name, base=base, visuals=False, gravity=gravity)


@pytest.fixture(scope="module", params=[("dual_arm_satellite", "free"), ("two_arm_planar", "planar")])
def robot(request):
    """A free-floating robot on a free base, and a planar one."""
    return robot_of(*request.param)


def tumbling(robot, seconds: float, seed: int):
    """A torque-free run of ``robot`` from a random state (1 kHz rows): its telemetry."""
    q0, v0 = random_state(robot, np.random.default_rng(seed))
    result = run(robot, q0, v0, seconds, T, make_integrator("rkmk4", robot.model), make_model("exact", robot))
    return result.telemetry


def noisy_settings(robot, level: float, seed: int = 0, **estimator) -> SensorSettings:
    """Every channel with noise of ``level`` (rad, m, rad/s, m/s) and the Kalman estimator."""
    channel = Channel(noise=level)
    return SensorSettings(channel, channel, channel, channel, MomentumKalman(**estimator), seed=seed)


def test_the_map_is_the_gjm_momentum_about_the_origin(robot):
    """``A_O(q) v`` equals the hand-built GJM's ``[P; L_O]`` (eqs 23, 69 shifted to the origin) at
    random states, to round-off."""
    data = robot.model.createData()
    rng = np.random.default_rng(1)
    for _ in range(5):
        q, v = random_state(robot, rng)
        expected = gjm.compute(robot, q, v).momentum_origin
        np.testing.assert_allclose(origin_map(robot.model, data, q) @ v, expected, atol=1e-11 * np.abs(expected).max())


def test_the_configuration_derivative_matches_finite_differences(robot):
    """``d(A_O v)/dq`` equals central differences of the map along ``pin.integrate``'s tangent
    (step 1e-6: error of order 1e-12 relative, round-off 1e-10)."""
    model, data = robot.model, robot.model.createData()
    q, v = random_state(robot, np.random.default_rng(2))
    eps = 1e-6
    fd = np.column_stack([(momentum_about_origin(model, data, pin.integrate(model, q, eps * e), v)
                           - momentum_about_origin(model, data, pin.integrate(model, q, -eps * e), v)) / (2 * eps)
                          for e in np.eye(model.nv)])
    D = configuration_derivative(model, data, q, v)
    assert np.abs(D - fd).max() < 1e-7 * np.abs(fd).max()


def test_the_estimate_converges_to_pinocchios_momentum_within_its_spread(robot):
    """Torque-free tumbling read with 1e-3 noise on every channel (1 kHz, 2 s): the estimate of each
    conserved component ends within 4 of its own standard deviations of Pinocchio's centroidal
    momentum (shifted to the origin), and at least 20 times closer than a single reading (2000
    readings average the noise down by sqrt(2000) = 45)."""
    tel = tumbling(robot, 2.0, seed=3)
    sensors = Sensors(robot, noisy_settings(robot, 1e-3), T)
    seen = [sensors.read(t, q, v) for t, q, v in zip(tel.t, tel.q, tel.v)]
    model, data = robot.model, robot.model.createData()
    truth = momentum_about_origin(model, data, tel.q[-1], tel.v[-1])
    rows = CONSERVED[robot.base]
    last = seen[-1]
    error = np.abs(last.estimate - truth)[rows]
    assert np.all(error < 4 * last.spread[rows])
    single = np.sqrt(np.mean([(m.momentum - truth)[rows] ** 2 for m in seen], axis=0))
    assert np.all(error < single / 20), (error, single)
    assert sensors.estimator.resets == 0


def test_gravity_is_predicted(robot):
    """A robot falling under gravity (momentum growing by m g per second): the estimate after 1 s
    is within 4 standard deviations of the truth, and no reading restarted the filter."""
    falling = robot_of("dual_arm_satellite" if robot.base == "free" else "two_arm_planar", robot.base,
                       gravity=(0.0, -9.81, 0.0))
    tel = tumbling(falling, 1.0, seed=4)
    sensors = Sensors(falling, noisy_settings(falling, 1e-3), T)
    last = [sensors.read(t, q, v) for t, q, v in zip(tel.t, tel.q, tel.v)][-1]
    truth = momentum_about_origin(falling.model, falling.model.createData(), tel.q[-1], tel.v[-1])
    rows = CONSERVED[falling.base]
    assert np.all(np.abs(last.estimate - truth)[rows] < 4 * last.spread[rows])
    assert sensors.estimator.resets == 0


def test_an_impulse_restarts_the_filter_and_noise_does_not(robot):
    """A jump of the true momentum (the base velocity changed between two readings, many reading
    deviations in size) restarts the filter at that reading; the 300 readings before it do not
    (false-alarm probability 1e-6 each)."""
    rng = np.random.default_rng(5)
    q, v = random_state(robot, rng)
    kicked = v.copy()
    kicked[: robot.n_base] += 1.0
    sensors = Sensors(robot, noisy_settings(robot, 1e-3, seed=6), T)
    seen = [sensors.read(k * T, q, v if k < 300 else kicked) for k in range(310)]
    assert [k for k, m in enumerate(seen) if m.reset] == [300]


def test_a_known_impulse_restarts_the_filter_at_the_first_reading_after_it(robot):
    """``restart = (0.0205,)`` with readings every 10 periods: the filter restarts at the reading
    taken at 0.03 s (2 periods late: read at 0.032 s), and at no other."""
    q, v = random_state(robot, np.random.default_rng(7))
    settings = noisy_settings(robot, 1e-3, restart=(0.0205,))
    slow = Channel(noise=1e-3, delay=2, every=10)
    settings = SensorSettings(settings.base_pose, slow, settings.joint_position, slow, settings.momentum)
    sensors = Sensors(robot, settings, T)
    seen = [sensors.read(k * T, q, v) for k in range(60)]
    assert [k for k, m in enumerate(seen) if m.reset] == [32]


def test_the_law_is_handed_a_state_that_carries_the_estimate(robot):
    """The velocity handed to the law (base rates replaced) gives, through the hand-built GJM, the
    estimated momentum on the conserved components, the measured joint rates unchanged."""
    tel = tumbling(robot, 0.05, seed=8)
    sensors = Sensors(robot, noisy_settings(robot, 1e-2), T)
    for t, q, v in zip(tel.t, tel.q, tel.v):
        seen = sensors.read(t, q, v)
        carried = gjm.compute(robot, seen.q, seen.v).momentum_origin
        rows = CONSERVED[robot.base]
        np.testing.assert_allclose(carried[rows], seen.estimate[rows], atol=1e-10 * np.abs(seen.estimate).max())
        assert np.array_equal(seen.v[robot.n_base:], sensors.groups[3].held)
