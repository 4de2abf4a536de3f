"""Thrusters on the base (freefloat.space.thrusters) and the laws that command them
(freefloat.space.control.thruster_control): the allocation against the geometry, the pulses'
minimum impulse bit, the propellant's closed form, the momentum balance with the thrusters'
impulse, the pose hold and the wheels' momentum dump."""

from __future__ import annotations

import dataclasses
import math
import re
import tomllib

import numpy as np
import pinocchio as pin
import pytest

import freefloat
from freefloat import InvalidArgument, SceneError
from freefloat.app.experiments import summary_units
from freefloat.app.scenes import builtin_scenes, find_scene, parse_scene
from freefloat.dynamics.metrics import summarize
from freefloat.paths import URDF_DIR
from freefloat.robot.wheels import WheelSpec, mount_wheels
from freefloat.space.control.thruster_control import ThrusterHold
from freefloat.space.thrusters import G0, ThrusterSet, ThrusterSettings, thruster_summary

PERIOD = 1e-3


@pytest.fixture(scope="module")
def satellite():
    """The UR5 dual-arm satellite (free base)."""
    return freefloat.load_robot(URDF_DIR / "dual_arm_satellite.urdf", visuals=False)


@pytest.fixture(scope="module")
def with_wheels(satellite):
    """The satellite with three wheels on its base, axes x, y, z."""
    specs = [WheelSpec(f"wheel_{a}", max_momentum=5.0, max_torque=2.0, axis=tuple(np.eye(3)[i]),
                       position=(0.0, 0.0, 0.2), mass=2.0, inertia=0.05) for i, a in enumerate("xyz")]
    return mount_wheels(satellite, specs)


def attitude_error(q: np.ndarray) -> float:
    """The base's rotation from the identity, rad."""
    return float(np.linalg.norm(pin.log3(pin.Quaternion(q[3:7]).toRotationMatrix())))


def test_allocation_reproduces_a_feasible_wrench(satellite):
    """Wrenches the twelve thrusters can give are allocated exactly (|B F - w| <= 1e-9), F >= 0."""
    thrusters = ThrusterSet(satellite, ThrusterSettings(arm=0.7, max_thrust=10.0))
    rng = np.random.default_rng(1)
    for _ in range(50):
        wrench = thrusters.B @ rng.uniform(0.0, 4.0, thrusters.count)
        thrusts = thrusters.allocate(wrench)
        assert thrusts.min() >= 0.0 and thrusts.max() <= 10.0
        np.testing.assert_allclose(thrusters.B @ thrusts, wrench, rtol=0, atol=1e-9)


def test_allocation_never_asks_a_negative_thrust(satellite):
    """Any wrench, reachable or not (six thrusters, one way each), gets thrusts in [0, max_thrust];
    a reachable one too large for the thrusters is scaled down along itself."""
    positions = np.vstack((0.5 * np.eye(3), -0.5 * np.eye(3)))
    directions = np.roll(np.eye(3), 1, axis=0).repeat(1, axis=0)
    directions = np.vstack((directions, directions))
    thrusters = ThrusterSet(satellite, ThrusterSettings(tuple(map(tuple, positions)), tuple(map(tuple, directions)),
                                                        max_thrust=2.0))
    rng = np.random.default_rng(2)
    for _ in range(50):
        thrusts = thrusters.allocate(rng.normal(0.0, 10.0, 6))
        assert thrusts.min() >= 0.0 and thrusts.max() <= 2.0 + 1e-12
    wanted = thrusters.B @ np.full(6, 5.0)
    np.testing.assert_allclose(thrusters.B @ thrusters.allocate(wanted), 0.4 * wanted, rtol=0, atol=1e-9)


def test_pulses_round_below_the_minimum_impulse_bit(satellite):
    """An impulse below the minimum impulse bit becomes 0 or the bit, whichever is nearer; thrusts are
    clipped to [0, max_thrust]; a bit larger than one period can give is refused."""
    thrusters = ThrusterSet(satellite, ThrusterSettings(max_thrust=10.0, min_impulse_bit=2e-3))
    asked = np.array([-1.0, 0.5, 1.0, 1.5, 2.5, 12.0, 0.0, 0.99, 1.01, 3.0, 10.0, 0.2])
    expected = np.array([0.0, 0.0, 2.0, 2.0, 2.5, 10.0, 0.0, 0.0, 2.0, 3.0, 10.0, 0.0])
    np.testing.assert_array_equal(thrusters.pulses(asked, PERIOD), expected)
    with pytest.raises(InvalidArgument, match="min_impulse_bit"):
        thrusters.pulses(asked, 1e-4)


def test_commands_are_held_until_the_next_and_a_restart_forgets_later_ones(satellite):
    """A command holds from its time to the next one's, nothing fires before the first, and a
    command at an earlier time (a run started again) drops the commands after it."""
    thrusters = ThrusterSet(satellite, ThrusterSettings())
    one, two = np.full(thrusters.count, 1.0), np.full(thrusters.count, 2.0)
    for t, thrusts in ((0.0, one), (PERIOD, two), (2 * PERIOD, one)):
        thrusters.command(t, thrusts, PERIOD)
    assert not thrusters.thrust(-PERIOD).any()
    np.testing.assert_array_equal(thrusters.thrust(1.5 * PERIOD), two)
    np.testing.assert_array_equal(thrusters.total_impulse(3 * PERIOD), np.full(thrusters.count, 4 * PERIOD))
    thrusters.command(PERIOD, one, PERIOD)
    assert thrusters.times == [0.0, PERIOD]
    np.testing.assert_array_equal(thrusters.thrust(5 * PERIOD), one)


def test_settings_refuse_what_is_no_thruster(satellite):
    """Directions that are not unit vectors, positions without directions and a planar base are refused."""
    with pytest.raises(InvalidArgument, match=r"directions\[0\]"):
        ThrusterSettings(((0.0, 0.0, 1.0),), ((0.0, 2.0, 0.0),))
    with pytest.raises(InvalidArgument, match="both"):
        ThrusterSettings(positions=((0.0, 0.0, 1.0),))
    planar = freefloat.load_robot(URDF_DIR / "two_arm_planar.urdf", base="planar", visuals=False, inertias="balanced")
    with pytest.raises(InvalidArgument, match="free-flyer"):
        ThrusterSet(planar, ThrusterSettings())


class ConstantThrust:
    """A law that asks the same thrusts every period (no joint torque)."""

    def __init__(self, robot, thrusters, thrusts):
        self.n, self.thrusters, self.thrusts = robot.n_joints, thrusters, thrusts

    def reference(self, t):
        return None

    def torque(self, t, q, v):
        self.thrusters.command(t, self.thrusts, PERIOD)
        return np.zeros(self.n)


def test_propellant_and_delta_v_follow_the_closed_form(satellite):
    """Constant thrusts F_i over T s burn m_p = sum F_i T / (I_sp g0) kg and give Tsiolkovsky's
    delta-v I_sp g0 ln(m0 / (m0 - m_p)), and the momentum changes by the thrusters' impulse."""
    thrusters = ThrusterSet(satellite, ThrusterSettings(specific_impulse=230.0))
    thrusts = np.zeros(thrusters.count)
    thrusts[[0, 5, 9]] = (3.0, 1.5, 0.5)
    duration = 0.4
    tel = freefloat.run(satellite, satellite.neutral(), np.zeros(satellite.model.nv), duration, PERIOD,
                        controller=ConstantThrust(satellite, thrusters, thrusts), environment=(thrusters,),
                        backend="python").telemetry
    summary = thruster_summary(thrusters, satellite, tel)
    impulse = thrusts.sum() * duration
    assert summary["thruster_impulse_total"] == pytest.approx(impulse, rel=1e-12)
    assert summary["propellant_mass"] == pytest.approx(impulse / (230.0 * G0), rel=1e-12)
    m0 = pin.computeTotalMass(satellite.model)
    assert summary["thruster_delta_v"] == pytest.approx(230.0 * G0 * math.log(m0 / (m0 - impulse / (230.0 * G0))),
                                                        rel=1e-12)
    assert summarize(tel, satellite, (), PERIOD, (thrusters,))["momentum_balance_max"] < 1e-10


def test_the_thrusters_figure_draws_the_propellant_integral(satellite):
    """The ``thrusters`` figure of a run of the pose hold (pulses with a minimum impulse bit, rows
    recorded every third period) draws the thrusts held and a propellant curve equal to the
    rectangle-rule integral of sum |F_i| / (I_sp g0) over the control periods; its last point is the
    summary's propellant_mass."""
    from freefloat.app.viz.thruster_figures import thruster_figure

    thrusters = ThrusterSet(satellite, ThrusterSettings(min_impulse_bit=5e-4, specific_impulse=230.0))
    law = ThrusterHold(satellite, thrusters, PERIOD, kp=4.0, kd=4.0)
    v0 = np.zeros(satellite.model.nv)
    v0[:6] = (0.01, 0.0, -0.005, 0.02, -0.01, 0.03)
    tel = freefloat.run(satellite, satellite.neutral(), v0, 0.3, PERIOD, controller=law, environment=(thrusters,),
                        record_every=3, backend="python").telemetry
    starts = np.arange(round(0.3 / PERIOD)) * PERIOD
    burnt = np.cumsum([np.abs(thrusters.thrust(s)).sum() * PERIOD for s in starts]) / (230.0 * G0)
    expected = np.interp(tel.t, starts + PERIOD, burnt, left=0.0)  # held thrusts: linear within a period
    fig = thruster_figure(tel.t, *thrusters.rows(tel.t), thrusters.specific_impulse)
    thrust_ax, propellant_ax = fig.axes
    t, grams = propellant_ax.lines[0].get_data()
    rows = np.searchsorted(tel.t, t)
    np.testing.assert_allclose(grams / 1e3, expected[rows], rtol=1e-12, atol=1e-15)
    assert grams[-1] / 1e3 == pytest.approx(thruster_summary(thrusters, satellite, tel)["propellant_mass"], rel=1e-12)
    drawn = {line.get_label(): line.get_ydata() for line in thrust_ax.lines}
    for i in range(thrusters.count):
        held = np.array([thrusters.thrust(s)[i] for s in tel.t])
        assert (f"thruster {i}" in drawn) == held.any()
    assert burnt[-1] > 0.0


@pytest.mark.slow
def test_hold_brings_a_perturbed_base_back(satellite):
    """A base pushed off its pose (linear and angular velocity) is brought back: the attitude error
    falls to a tenth of its largest; the momentum and energy balances with the thrusters' own
    impulse and work close."""
    thrusters = ThrusterSet(satellite, ThrusterSettings())
    law = ThrusterHold(satellite, thrusters, PERIOD, kp=4.0, kd=4.0)
    v0 = np.zeros(satellite.model.nv)
    v0[:6] = (0.01, 0.0, -0.005, 0.02, -0.01, 0.03)
    tel = freefloat.run(satellite, satellite.neutral(), v0, 4.0, PERIOD, controller=law, environment=(thrusters,),
                        backend="python").telemetry
    errors = np.array([attitude_error(q) for q in tel.q])
    assert errors[-1] < 0.1 * errors.max()
    assert np.linalg.norm(tel.q[-1, :3]) < 0.2 * np.linalg.norm(tel.q[:, :3], axis=1).max()
    balances = summarize(tel, satellite, (), PERIOD, (thrusters,))
    assert balances["momentum_balance_max"] < 1e-10 and balances["energy_balance_max"] < 1e-8
    impulse = thruster_summary(thrusters, satellite, tel)["thruster_impulse"]
    np.testing.assert_allclose(impulse, tel.momentum[-1] - tel.momentum[0], rtol=0, atol=1e-10)


@pytest.mark.slow
def test_dump_moves_the_wheels_momentum_out_through_the_thrusters(with_wheels):
    """Wheels spinning with 3 N m s are braked to under 1 % of it while the base stays within 2 mrad
    of its attitude; the system's angular momentum changes by the thrusters' angular impulse."""
    robot = with_wheels.robot
    thrusters = ThrusterSet(robot, ThrusterSettings())
    law = ThrusterHold(robot, thrusters, PERIOD, kp=4.0, kd=4.0, wheels=with_wheels, dump_rate=2.0)
    v0 = np.zeros(robot.model.nv)
    stored = np.array([1.0, -2.0, 2.0])  # N m s, base frame = inertial at the start
    v0[with_wheels.v_indices] = stored / with_wheels.inertias
    tel = freefloat.run(robot, robot.neutral(), v0, 4.0, PERIOD, controller=law, environment=(thrusters,),
                        backend="python").telemetry
    left = with_wheels.momenta(tel.v[-1])
    assert np.abs(left).max() < 0.01 * np.abs(stored).max()
    assert max(attitude_error(q) for q in tel.q) < 2e-3
    assert summarize(tel, robot, (), PERIOD, (thrusters,))["momentum_balance_max"] < 1e-9
    np.testing.assert_allclose(thruster_summary(thrusters, robot, tel)["thruster_impulse"][3:], tel.momentum[-1, 3:] - tel.momentum[0, 3:],
                               rtol=0, atol=1e-9)
    np.testing.assert_allclose(tel.momentum[-1, 3:], 0.0, atol=0.01 * np.abs(stored).max())


@pytest.mark.slow
def test_the_dump_scene_empties_the_wheels_through_the_thrusters():
    """The built-in satellite_momentum_dump, run as a user runs it (3 s of its 12), brakes the
    wheels' stored momentum, holds the base within 1 mrad, balances the momentum against the
    thrusters' impulse and reports the propellant of its closed form, with units."""
    scene = find_scene("satellite_momentum_dump")
    short = dataclasses.replace(scene, output=dataclasses.replace(scene.output, figures=False, html=False),
                                simulation=dataclasses.replace(scene.simulation, duration=3.0))
    summary = freefloat.simulate(short).summary
    stored = np.abs(list(summary["wheel_momentum_max"].values()))
    final = np.abs(list(summary["wheel_momentum_final"].values()))
    assert (final < 0.5 * stored).all()
    assert summary["base_rotation_max"] < 1e-3 and summary["momentum_balance_max"] < 1e-10
    assert summary["wheel_momentum_balance_max"] < 1e-10  # the wheels' balance counts the thrusters' impulse
    settings = scene.environment[0].settings
    assert summary["propellant_mass"] == pytest.approx(
        summary["thruster_impulse_total"] / (settings.specific_impulse * G0), rel=1e-12)
    units = summary_units(scene)
    assert units["propellant_mass"] == "kg" and units["thruster_delta_v"] == "m/s"


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"wheels": None}, "controller 'momentum_dump' dumps the momentum of reaction wheels: give [[wheels]]"),
        ({"environment": None}, "give exactly one [[environment]] kind = \"thrusters\", got 0"),
        ({"thrusters": {"max_thrust": 0.0}}, "'environment.max_thrust' must be > 0"),
        ({"thrusters": {"directions": [[0.0, 0.0, 2.0]], "positions": [[1.0, 0.0, 0.0]]}}, "directions[0]"),
        ({"thrusters": {"min_impulse_bit": 0.05}}, "'min_impulse_bit' 0.05 N s exceeds the most one control period"),
    ],
)
def test_a_thruster_scene_refuses_what_it_cannot_run(change, message):
    """A dump without wheels, a thruster law without thrusters, a thrust that is not positive, a
    direction that is not a unit vector and a bit no period can give are refused by name before
    anything runs."""
    raw = tomllib.loads(builtin_scenes()["satellite_momentum_dump"].read_text())
    for key, value in change.items():
        if key == "thrusters":
            raw["environment"][0].update(value)
        elif value is None:
            raw.pop(key)
            raw["initial"].pop("joint_velocities")
    with pytest.raises(SceneError, match=re.escape(message)):
        freefloat.app.runner.prepare(parse_scene(raw))
