"""Tests of freefloat.space.orbit: the circular reference orbit and its LVLH frame, the tidal
field (against extended-precision inverse-square sums and a cloud of point masses), a free body
against the Clohessy-Wiltshire closed form, the pitch libration against its closed forms, and the
Earth-centred energy and angular momentum conserved in the full two-body field."""

from __future__ import annotations

import math
from decimal import Decimal, getcontext

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot, run
from freefloat.errors import InvalidArgument
from freefloat.paths import URDF_DIR
from freefloat.space.orbit import (
    EARTH_MU,
    EARTH_RADIUS,
    CircularOrbit,
    OrbitField,
    OrbitSettings,
    base_in_lvlh,
    clohessy_wiltshire,
    free_flyer_state,
    in_lvlh,
    orbit_field,
)
from freefloat.space.orbit.libration import (
    libration_period,
    measure_libration,
    rigid_satellite,
    rigid_satellite_urdf,
)
from freefloat.space.orbit.lvlh import root_in_lvlh
from freefloat.space.orbit.propagation import propagate
from freefloat.space.orbit.summary import SUMMARY_UNITS, orbit_summary

ORBIT = CircularOrbit(altitude=400e3, phase=0.7)


def two_body_robot() -> pin.Model:
    """A 120 kg bus with a 15 kg arm link on a revolute joint, no gravity (built in code)."""
    model = pin.Model()
    model.gravity.linear[:] = 0.0
    base = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
    model.appendBodyToJoint(base, pin.Inertia(120.0, np.array([0.05, 0.0, 0.0]), np.diag([30.0, 45.0, 50.0])),
                            pin.SE3.Identity())
    arm = model.addJoint(base, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0.6, 0.0, 0.0])), "shoulder")
    model.appendBodyToJoint(arm, pin.Inertia(15.0, np.array([0.5, 0.0, 0.0]), np.diag([0.1, 1.3, 1.3])),
                            pin.SE3.Identity())
    return model


def test_altitude_and_mean_motion_give_the_same_orbit():
    """An orbit given by its altitude and one given by its mean motion are the same circle, and
    both obey Kepler's third law n^2 a^3 = mu."""
    by_mean_motion = CircularOrbit(mean_motion=ORBIT.mean_motion)
    assert by_mean_motion.altitude == pytest.approx(400e3, rel=1e-12)
    assert ORBIT.mean_motion**2 * (EARTH_RADIUS + 400e3) ** 3 == pytest.approx(EARTH_MU, rel=1e-14)
    assert ORBIT.period == pytest.approx(2.0 * math.pi * math.sqrt(ORBIT.radius**3 / EARTH_MU), rel=1e-14)


@pytest.mark.parametrize("keys, words", [({}, "exactly one"), ({"altitude": 4e5, "mean_motion": 1e-3}, "exactly one"),
                                         ({"altitude": -10.0}, "'altitude'"), ({"mean_motion": 0.0}, "'mean_motion'"),
                                         ({"mean_motion": 2e-3}, "inside the Earth")])
def test_a_bad_orbit_is_refused_by_name(keys, words):
    """Neither or both of altitude and mean motion, a non-positive one, or an orbit inside the
    Earth is refused with the key named."""
    with pytest.raises(InvalidArgument, match=words):
        CircularOrbit(**keys)


def test_a_robot_with_gravity_is_refused():
    """A model that keeps a uniform gravity (a URDF's default -9.81 z) is refused, gravity named."""
    model = rigid_satellite()
    model.gravity.linear[:] = [0.0, 0.0, -9.81]
    with pytest.raises(InvalidArgument, match="gravity"):
        OrbitField(model, ORBIT)


def test_a_scenes_orbit_settings_build_the_field():
    """Orbit settings (a scene's keys) build the same orbit as the constructor, and the field on a
    robot; a wrong key is named."""
    field = orbit_field(rigid_satellite(), OrbitSettings(altitude=400e3, phase=0.7))
    assert field.orbit.mean_motion == ORBIT.mean_motion
    np.testing.assert_allclose(field.orbit.position(10.0), ORBIT.position(10.0), rtol=1e-15)
    with pytest.raises(InvalidArgument, match="'mean_motion'"):
        OrbitSettings(mean_motion=-1.0).orbit()


def test_the_reference_point_moves_on_the_keplerian_circle():
    """R0's velocity is its time derivative and its acceleration (second differences) the
    inverse-square gravity -mu R0 / |R0|^3."""
    t, h = 1234.5, 0.5
    R = [ORBIT.position(t + k * h) for k in (-1, 0, 1)]
    np.testing.assert_allclose(ORBIT.velocity(t), (R[2] - R[0]) / (2 * h), rtol=1e-7)
    np.testing.assert_allclose((R[2] - 2 * R[1] + R[0]) / h**2, -EARTH_MU * R[1] / np.linalg.norm(R[1]) ** 3,
                               rtol=1e-6, atol=1e-6)


def test_an_orbit_started_later_is_the_same_orbit_further_on():
    """``later(start)`` is the same circle on a clock started ``start`` s later: its R0(t), V0(t)
    and LVLH axes are the original's at start + t."""
    later = ORBIT.later(1234.5)
    assert (later.radius, later.mean_motion) == (ORBIT.radius, ORBIT.mean_motion)
    for t in (0.0, 77.0, 3000.0):
        np.testing.assert_allclose(later.position(t), ORBIT.position(1234.5 + t), rtol=0, atol=1e-8)
        np.testing.assert_allclose(later.velocity(t), ORBIT.velocity(1234.5 + t), rtol=0, atol=1e-11)
        np.testing.assert_allclose(later.lvlh_rotation(t), ORBIT.lvlh_rotation(1234.5 + t), atol=1e-15)


def test_lvlh_axes_are_radial_along_track_and_normal():
    """The LVLH rotation's columns are R0 / |R0|, V0 / |V0| and their cross product, at any time."""
    for t in (0.0, 800.0, 4000.0):
        R = ORBIT.lvlh_rotation(t)
        np.testing.assert_allclose(R[:, 0], ORBIT.position(t) / ORBIT.radius, atol=1e-15)
        np.testing.assert_allclose(R[:, 1], ORBIT.velocity(t) / np.linalg.norm(ORBIT.velocity(t)), atol=1e-15)
        np.testing.assert_allclose(R[:, 2], np.cross(R[:, 0], R[:, 1]), atol=1e-15)


def test_lvlh_velocity_is_the_rate_of_the_lvlh_position():
    """A point moving in the simulation frame: its LVLH velocity equals the time derivative of its
    LVLH position (central differences), and from_lvlh inverts to_lvlh."""
    def path(t):
        return np.array([3.0 * np.cos(0.01 * t), 2.0 + 0.05 * t, -0.02 * t]), \
            np.array([-0.03 * np.sin(0.01 * t), 0.05, -0.02])

    t, h = np.array([99.0, 100.0, 101.0]), 1.0
    points, rates = map(np.array, zip(*(path(s) for s in t)))
    p, v = ORBIT.to_lvlh(t, points, rates)
    np.testing.assert_allclose(v[1], (p[2] - p[0]) / (2 * h), rtol=1e-4)
    back = ORBIT.from_lvlh(100.0, p[1], v[1])
    np.testing.assert_allclose(back[0], points[1], atol=1e-14)
    np.testing.assert_allclose(back[1], rates[1], atol=1e-15)


def test_clohessy_wiltshire_solves_its_equations():
    """The closed form starts at its initial state, its velocities are its positions' rates, and
    its accelerations (second differences) satisfy the Hill equations."""
    n, p0, v0 = ORBIT.mean_motion, np.array([1.0, -2.0, 0.5]), np.array([0.01, -0.003, 0.002])
    h, t = 1.0, np.array([699.0, 700.0, 701.0])
    p, v = clohessy_wiltshire(n, p0, v0, np.r_[0.0, t])
    np.testing.assert_allclose(p[0], p0, atol=1e-15)
    np.testing.assert_allclose(v[0], v0, atol=1e-15)
    np.testing.assert_allclose(v[2], (p[3] - p[1]) / (2 * h), rtol=1e-6)
    a = (p[3] - 2 * p[2] + p[1]) / h**2
    (x, _, z), (xd, yd, _) = p[2], v[2]
    np.testing.assert_allclose(a, [2 * n * yd + 3 * n * n * x, -2 * n * xd, -n * n * z], atol=1e-10)


def exact_tidal(mu: float, R0: np.ndarray, c: np.ndarray, mass: float) -> np.ndarray:
    """-mu m (rho / |rho|^3 - R0 / |R0|^3) in 50-digit decimal arithmetic (3,), N."""
    getcontext().prec = 50
    R, C = [Decimal(float(x)) for x in R0], [Decimal(float(x)) for x in c]
    rho = [a + b for a, b in zip(R, C)]

    def cube(u):
        return sum(x * x for x in u).sqrt() ** 3

    r3, R3 = cube(rho), cube(R)
    return np.array([float(-Decimal(mu) * Decimal(mass) * (a / r3 - b / R3)) for a, b in zip(rho, R)])


@pytest.mark.parametrize("offset", [1e-3, 1.0, 1e3, 1e5])
def test_tidal_force_is_the_exact_inverse_square_difference(offset):
    """A body of isotropic inertia (no quadrupole force) feels the inverse-square difference at its
    CoM summed in 50-digit arithmetic, to 1e-13 relative, from 1 mm to 100 km off the reference."""
    model = rigid_satellite(mass=7.0, inertia=(2.0, 2.0, 2.0))
    field = OrbitField(model, ORBIT)
    c = offset * np.array([0.6, -0.48, 0.64])
    q = np.r_[c, 0.0, 0.0, 0.0, 1.0]
    force = field.wrench(321.0, q)[:3]
    expected = exact_tidal(EARTH_MU, ORBIT.position(321.0), c, 7.0)
    np.testing.assert_allclose(force, expected, rtol=1e-13, atol=0.0)


def test_the_wrench_on_a_body_matches_a_cloud_of_point_masses():
    """Six point masses with a body's mass and inertia, symmetric about its CoM (no octupole), at a
    random attitude: the exact inverse-square forces summed over them give the field's torque about
    the CoM to 1e-9, and its force's quadrupole part (what differs from a point mass at the CoM,
    a part in 1e8) to 1e-6 of that part."""
    mass, (a, b, c) = 60.0, (0.5, 1.2, 2.0)
    points = np.array([[a, 0, 0], [-a, 0, 0], [0, b, 0], [0, -b, 0], [0, 0, c], [0, 0, -c]], dtype=float)
    inertia = sum(mass / 6 * (p @ p * np.eye(3) - np.outer(p, p)) for p in points)
    model = pin.Model()
    model.gravity.linear[:] = 0.0
    joint = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "body")
    model.appendBodyToJoint(joint, pin.Inertia(mass, np.zeros(3), inertia), pin.SE3.Identity())
    rotation = pin.exp3(np.random.default_rng(5).normal(size=3))
    com, t = np.array([4.0, -3.0, 2.0]), 77.0
    wrench = OrbitField(model, ORBIT).wrench(t, np.r_[com, pin.Quaternion(rotation).coeffs()])
    cloud = [rotation @ p for p in points]
    forces = [exact_tidal(EARTH_MU, ORBIT.position(t), com + p, mass / 6) for p in cloud]
    torque = sum(np.cross(p, f) for p, f in zip(cloud, forces))
    np.testing.assert_allclose(wrench[3:] - np.cross(com, wrench[:3]), torque, rtol=1e-9, atol=1e-9 * np.abs(torque).max())
    quadrupole = sum(forces) - exact_tidal(EARTH_MU, ORBIT.position(t), com, mass)
    assert np.linalg.norm(wrench[:3] - sum(forces)) < 1e-6 * np.linalg.norm(quadrupole)


def test_joint_forces_add_up_to_the_field_wrench():
    """The joint-frame forces of the dual-arm satellite, moved to the simulation origin, sum to
    :meth:`wrench` (force and torque about the origin), at a random configuration."""
    robot = load_robot(URDF_DIR / "dual_arm_satellite.urdf", visuals=False)
    field = OrbitField(robot, ORBIT)
    q = pin.randomConfiguration(robot.model, -4 * np.ones(robot.model.nq), 4 * np.ones(robot.model.nq))
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q)
    total = sum((data.oMi[j].act(f) for j, f in enumerate(field.forces(50.0, q))), pin.Force.Zero())
    expected = field.wrench(50.0, q)
    np.testing.assert_allclose(total.vector, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    assert len(field.forces(50.0, q)) == robot.model.njoints


def test_a_body_at_rest_in_lvlh_is_reported_at_rest():
    """A body held at a fixed LVLH pose, sampled in the simulation frame, is reported at that pose
    with zero LVLH velocity."""
    t = np.linspace(0.0, 3000.0, 7)
    p_lvlh, attitude = np.array([1.0, -2.0, 0.3]), pin.exp3(np.array([0.2, -0.1, 0.4]))
    frames = ORBIT.lvlh_rotation(t)
    position = frames @ p_lvlh
    velocity = np.cross(ORBIT.angular_velocity(), position)
    quaternion = [pin.Quaternion(R @ attitude).coeffs() for R in frames]
    track = in_lvlh(ORBIT, t, position, quaternion, velocity)
    np.testing.assert_allclose(track.position, np.tile(p_lvlh, (7, 1)), atol=1e-14)
    np.testing.assert_allclose(track.velocity, 0.0, atol=1e-15)
    np.testing.assert_allclose(track.rotation, np.tile(attitude, (7, 1, 1)), atol=1e-14)


def test_a_free_flyer_state_set_in_lvlh_reads_back():
    """A free-flyer state built from an LVLH position, velocity, attitude and relative angular
    velocity is reported back in LVLH as given; its angular velocity is the relative one plus n
    about the normal."""
    p, v, attitude, spin = np.array([5.0, -1.0, 2.0]), np.array([0.1, 0.2, -0.3]), pin.exp3(np.array([0.3, 0.2, -0.5])), \
        np.array([0.01, -0.02, 0.03])
    q, w = free_flyer_state(ORBIT, 900.0, p, v, attitude, spin)
    track = root_in_lvlh(ORBIT, np.array([900.0]), q, w)
    np.testing.assert_allclose(track.position[0], p, atol=1e-13)
    np.testing.assert_allclose(track.velocity[0], v, atol=1e-15)
    np.testing.assert_allclose(track.rotation[0], attitude, atol=1e-15)
    world = pin.Quaternion(q[3:]).matrix() @ w[3:]
    np.testing.assert_allclose(world, ORBIT.lvlh_rotation(900.0) @ spin + [0.0, 0.0, ORBIT.mean_motion], atol=1e-16)


def test_a_runs_base_is_reported_in_lvlh_as_its_state_is():
    """The base of an engine run (telemetry's base position, quaternion and twist of the bus CoM,
    which is the bus origin) in LVLH equals its free-flyer state (q, v) put in LVLH."""
    robot = load_robot(URDF_DIR / "dual_arm_satellite.urdf", visuals=False)
    q0 = robot.neutral()
    q0[:3] = [3.0, -2.0, 1.0]
    v0 = np.r_[0.1, -0.2, 0.05, 0.3, -0.1, 0.2, np.full(robot.model.nv - 6, 0.1)]
    telemetry = run(robot, q0, v0, 0.01, 1e-3).telemetry
    reported = base_in_lvlh(ORBIT, telemetry)
    expected = root_in_lvlh(ORBIT, telemetry.t, telemetry.q, telemetry.v)
    np.testing.assert_allclose(reported.position, expected.position, atol=1e-12)
    np.testing.assert_allclose(reported.velocity, expected.velocity, atol=1e-12)
    np.testing.assert_allclose(reported.rotation, expected.rotation, atol=1e-12)


def cw_error(offset: float) -> float:
    """Largest LVLH distance, m, between a free body released ``offset`` times a unit relative
    state and the Clohessy-Wiltshire closed form over one orbit (full two-body field)."""
    model = rigid_satellite(mass=10.0, inertia=(1.0, 2.0, 3.0))
    p0 = offset * np.array([1.0, 0.5, -0.8])
    v0 = offset * ORBIT.mean_motion * np.array([0.3, -1.5, 0.6])  # drifts along-track
    q0, w0 = free_flyer_state(ORBIT, 0.0, p0, v0)
    t = np.linspace(0.0, ORBIT.period, 201)
    Q, V = propagate(model, [OrbitField(model, ORBIT)], q0, w0, t, rtol=1e-10)
    expected, _ = clohessy_wiltshire(ORBIT.mean_motion, p0, v0, t)
    return float(np.linalg.norm(root_in_lvlh(ORBIT, t, Q, V).position - expected, axis=1).max())


@pytest.mark.slow
def test_a_small_free_body_follows_clohessy_wiltshire():
    """Over one orbit a free body released 10 m off (drifting 94 m along-track) stays within 1 mm
    of the CW closed form, and the error grows as the offset squared (x100 for 10x: the
    linearisation's order)."""
    small, large = cw_error(10.0), cw_error(100.0)
    assert small < 1e-3
    assert 95.0 < large / small < 105.0


def test_the_pitch_libration_period_is_the_closed_form():
    """A rigid satellite released 5 deg off its gravity-gradient equilibrium librates with the period
    2 pi / (n sqrt(3 (Iy - Ix) / Iz)) (LVLH axes: x radial, z normal) to within 0.5 %."""
    run = measure_libration(amplitude=math.radians(5.0))
    assert abs(run.period / run.closed_form - 1.0) < 5e-3
    assert run.closed_form == pytest.approx(libration_period(CircularOrbit(altitude=400e3), (20.0, 60.0, 70.0)))


def test_the_built_in_satellite_file_is_the_generators_text():
    """urdf/rigid_satellite.urdf (the orbit_libration scene's robot) is rigid_satellite_urdf()'s
    text after its comment line: one source of the satellite's mass and inertia."""
    text = (URDF_DIR / "rigid_satellite.urdf").read_text().splitlines()
    assert text[0].startswith("<!--") and text[1:] == [rigid_satellite_urdf()]


def test_a_run_too_short_for_two_crossings_reports_no_libration_period():
    """A one-body run that has not crossed its equilibrium upward twice reports no period (None)
    but its final LVLH pose: the satellite released on the reference point stays on it."""
    robot = load_robot(URDF_DIR / "rigid_satellite.urdf", end_effectors=(), visuals=False)
    field = OrbitField(robot, ORBIT)
    q0, v0 = free_flyer_state(ORBIT, 0.0, np.zeros(3), np.zeros(3), pin.utils.rotate("z", 0.1))
    summary = orbit_summary(field, robot, run(robot, q0, v0, 100.0, 10.0, environment=(field,)).telemetry)
    assert summary["libration_period"] is None
    assert np.linalg.norm(summary["base_lvlh_position_final"]) < 1e-6
    assert set(summary) == set(SUMMARY_UNITS)


def test_the_pitch_libration_period_is_the_pendulum_period():
    """At 20 deg the measured period is the finite-amplitude pendulum's (4 / w0) K(sin^2 theta0)
    to 1e-6, 2.5 % above the small-amplitude one: the full nonlinear gradient torque."""
    run = measure_libration(amplitude=math.radians(20.0), cycles=2)
    assert abs(run.period / run.pendulum - 1.0) < 1e-6
    assert run.pendulum / run.closed_form > 1.02


@pytest.mark.slow
@pytest.mark.parametrize("which", ["two_body", "dual_arm"])
def test_energy_and_angular_momentum_about_the_earth_are_conserved(which):
    """A robot tumbling 100 m off the reference point through one orbit of the full two-body field
    (dopri5, rtol 1e-12) keeps its Earth-centred energy and angular momentum to 1e-9 of their size,
    and their parts over the reference orbit (the robot's own, which the field exchanges) to 1e-11
    of theirs (without the quadrupole force they drift 5e-10 and 9e-10 of theirs)."""
    if which == "two_body":
        model = two_body_robot()
        q0 = np.r_[pin.neutral(model)[:7], 0.4]
    else:
        model = load_robot(URDF_DIR / "dual_arm_satellite.urdf", visuals=False).model
        q0 = pin.neutral(model)
        q0[7:] = np.random.default_rng(2).uniform(-1.0, 1.0, model.nq - 7)
    q0[:3] = [60.0, -70.0, 40.0]
    v0 = np.zeros(model.nv)
    v0[:6] = [0.02, 0.05, -0.01, 0.002, -0.003, 0.004]
    v0[6:] = 0.001
    field = OrbitField(model, ORBIT)
    t = np.linspace(0.0, ORBIT.period, 41)
    Q, V = propagate(model, [field], q0, v0, t, rtol=1e-12, atol=1e-12)
    energy = np.array([field.energy(s, q, v) for s, q, v in zip(t, Q, V)])
    momentum = np.array([field.angular_momentum(s, q, v) for s, q, v in zip(t, Q, V)])
    assert np.abs(energy - energy[0]).max() < 1e-9 * abs(energy[0])
    assert np.linalg.norm(momentum - momentum[0], axis=1).max() < 1e-9 * np.linalg.norm(momentum[0])
    excess = np.array([field.energy_over_reference(s, q, v) for s, q, v in zip(t, Q, V)])
    excess_momentum = np.array([field.momentum_over_reference(s, q, v) for s, q, v in zip(t, Q, V)])
    assert np.abs(excess - excess[0]).max() < 1e-11 * np.abs(excess).max()
    assert np.linalg.norm(excess_momentum - excess_momentum[0], axis=1).max() < \
        1e-11 * np.linalg.norm(excess_momentum, axis=1).max()
