"""Sensor readings: noise and bias of the stated size on the configuration's group, seeded; the
delay and the zero-order hold exact, per channel group; ideal groups read the truth unchanged."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics.sensors import Channel, Sensors, SensorSettings
from freefloat.errors import BadShape, InvalidArgument

from .conftest import random_state

T = 1e-3


@pytest.fixture(scope="module")
def satellite():
    """The dual-arm satellite on a free base."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot("dual_arm_satellite", visuals=False)


def readings(robot, settings, states):
    """What the sensors read of each (q, v) of ``states``, one control period each."""
    sensors = Sensors(robot, settings, T)
    return [sensors.read(k * T, q, v) for k, (q, v) in enumerate(states)]


def test_noise_and_bias_have_the_stated_statistics(satellite):
    """Each component's error (the tangent offset ``q_true (-) q_read`` for poses and joint angles,
    ``v_read - v`` for rates) has the stated bias as its mean, within 4 standard errors, and the
    stated standard deviation, within 4 standard errors of a sample deviation (1/sqrt(2N))."""
    robot, n = satellite, 4000
    nb, nj = robot.n_base, robot.n_joints
    rng = np.random.default_rng(3)
    sd = {"base_pose": rng.uniform(1e-3, 1e-2, nb), "base_twist": rng.uniform(1e-3, 1e-2, nb),
          "joint_position": rng.uniform(1e-3, 1e-2, nj), "joint_rate": rng.uniform(1e-3, 1e-2, nj)}
    bias = {name: rng.uniform(-1e-2, 1e-2, len(s)) for name, s in sd.items()}
    settings = SensorSettings(**{name: Channel(noise=tuple(sd[name]), bias=tuple(bias[name])) for name in sd}, seed=4)
    q, v = random_state(robot, rng)
    seen = readings(robot, settings, [(q, v)] * n)
    tangent = np.array([pin.difference(robot.model, q, m.q) for m in seen])
    rates = np.array([m.v - v for m in seen])
    errors = {"base_pose": tangent[:, :nb], "joint_position": tangent[:, nb:], "base_twist": rates[:, :nb],
              "joint_rate": rates[:, nb:]}
    for name, e in errors.items():
        assert np.all(np.abs(e.mean(axis=0) - bias[name]) < 4 * sd[name] / np.sqrt(n)), name
        assert np.all(np.abs(e.std(axis=0) / sd[name] - 1) < 4 / np.sqrt(2 * n)), name


def test_pose_readings_stay_on_the_group(satellite):
    """Noisy base poses keep a unit quaternion (pin.integrate on SE(3)), even with 0.3 rad noise."""
    q, v = random_state(satellite, np.random.default_rng(5))
    settings = SensorSettings(base_pose=Channel(noise=0.3))
    quaternions = np.array([m.q[3:7] for m in readings(satellite, settings, [(q, v)] * 200)])
    np.testing.assert_allclose(np.linalg.norm(quaternions, axis=1), 1.0, atol=1e-14)


def test_a_seed_repeats_the_noise_and_another_changes_it(satellite):
    """The same seed gives the same readings bit for bit; another seed other readings."""
    q, v = random_state(satellite, np.random.default_rng(6))
    states = [(q, v)] * 5
    noisy = {"joint_rate": Channel(noise=0.01), "base_pose": Channel(noise=0.01)}
    first, again, other = (readings(satellite, SensorSettings(**noisy, seed=s), states) for s in (1, 1, 2))
    assert all(np.array_equal(a.q, b.q) and np.array_equal(a.v, b.v) for a, b in zip(first, again))
    assert not any(np.array_equal(a.v, b.v) for a, b in zip(first, other))


@pytest.mark.parametrize(("delays", "everies"), [((0, 0, 0, 0), (1, 1, 1, 1)), ((2, 0, 3, 1), (1, 10, 4, 3)),
                                                 ((5, 2, 0, 7), (3, 3, 10, 1))])
def test_delay_and_hold_are_exact_per_group(satellite, delays, everies):
    """With delay d and sampling every m periods, period k reads the state of period
    ``max(0, m floor((k - d) / m))`` exactly, each group on its own schedule."""
    robot, n = satellite, 40
    rng = np.random.default_rng(7)
    states = [random_state(robot, rng) for _ in range(n)]
    names = ("base_pose", "base_twist", "joint_position", "joint_rate")
    settings = SensorSettings(**{name: Channel(delay=d, every=m) for name, d, m in zip(names, delays, everies)})
    seen = readings(robot, settings, states)
    nbq, nb = robot.model.nqs[1], robot.n_base
    parts = {"base_pose": (0, slice(0, nbq)), "base_twist": (1, slice(0, nb)),
             "joint_position": (0, slice(nbq, None)), "joint_rate": (1, slice(nb, None))}
    for name, d, m in zip(names, delays, everies):
        which, part = parts[name]
        for k, reading in enumerate(seen):
            source = max(0, m * ((k - d) // m))
            assert np.array_equal(reading[which][part], states[source][which][part]), (name, k, source)


def test_an_ideal_group_reads_the_truth_unchanged(satellite):
    """Noise on the joint rates only: the base pose, base twist and joint positions read are the
    true values bit for bit (no round trip through pin.integrate)."""
    q, v = random_state(satellite, np.random.default_rng(8))
    seen = readings(satellite, SensorSettings(joint_rate=Channel(noise=0.1)), [(q, v)])[0]
    nb = satellite.n_base
    assert np.array_equal(seen.q, q) and np.array_equal(seen.v[:nb], v[:nb]) and not np.array_equal(seen.v, v)


def test_a_noise_of_the_wrong_length_names_the_group_and_its_components(satellite):
    """Three values for the six-component base twist: refused, naming the group and listing its
    components."""
    with pytest.raises(BadShape, match=r"sensors\.base_twist\.noise has 3 values.*vx, vy, vz, wx, wy, wz"):
        Sensors(satellite, SensorSettings(base_twist=Channel(noise=(0.1, 0.1, 0.1))), T)


def test_reading_out_of_turn_is_refused(satellite):
    """A second reading in the same period (a law evaluated per integrator stage) is refused,
    naming the time expected."""
    q, v = random_state(satellite, np.random.default_rng(9))
    sensors = Sensors(satellite, SensorSettings(), T)
    sensors.read(0.0, q, v)
    with pytest.raises(InvalidArgument, match="expected t = 0.001"):
        sensors.read(0.0005, q, v)
