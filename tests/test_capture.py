"""Capture of a tumbling target: exact impulse, momentum balance, the merged robot."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.space.capture import Target, TargetBody, attach, impact, robot_momentum

from .conftest import REPO


@pytest.fixture(scope="module")
def setup():
    """Two-arm robot (free base) moving, and a spinning target whose grasp point is at arm 1's end-effector."""
    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    rng = np.random.default_rng(0)
    q = robot.neutral()
    q[7:] = rng.uniform(-0.3, 0.3, robot.n_joints)
    v = rng.normal(size=robot.model.nv) * 0.1
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    ee = data.oMf[robot.model.getFrameId("arm1_ee")].translation
    target = Target(mass=20.0, inertia=(1.0, 1.5, 2.0), grasp=(-0.3, 0.0, 0.0), position=tuple(ee + [0.3, 0.0, 0.0]),
                    rpy=(0.0, 0.0, 0.0), velocity=(-0.05, 0.02, 0.0), angular_velocity=(0.0, 0.0, 0.5))
    body = TargetBody(target)
    q_t, v_t = body.initial_state()
    return robot, q, v, body, q_t, v_t


def test_grasp_point_starts_on_the_end_effector(setup):
    """The fixture's target grasp point coincides with the end-effector origin."""
    robot, q, _, body, q_t, _ = setup
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    np.testing.assert_allclose(body.grasp_point(q_t), data.oMf[robot.model.getFrameId("arm1_ee")].translation, atol=1e-12)


def test_impact_conserves_total_momentum_exactly(setup):
    """The grasp impulse is internal: robot + target momentum about the origin is unchanged."""
    robot, q, v, body, q_t, v_t = setup
    hit = impact(robot, "arm1_ee", q, v, body, q_t, v_t)
    np.testing.assert_allclose(hit.momentum_after, hit.momentum_before, atol=1e-11 * np.abs(hit.momentum_before).max())
    assert np.abs(hit.impulse).max() > 1e-3  # something happened


def test_after_impact_grasp_point_moves_with_the_end_effector(setup):
    """The weld holds: end-effector and grasp point have the same twist after the impact."""
    robot, q, v, body, q_t, v_t = setup
    hit = impact(robot, "arm1_ee", q, v, body, q_t, v_t)
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q, hit.v_robot)
    ee = pin.getFrameVelocity(robot.model, data, robot.model.getFrameId("arm1_ee"), pin.LOCAL_WORLD_ALIGNED).vector
    pin.forwardKinematics(body.model, body.data, q_t, hit.v_target)
    grasp = pin.getFrameVelocity(body.model, body.data, body.grasp_id, pin.LOCAL_WORLD_ALIGNED).vector
    np.testing.assert_allclose(ee, grasp, atol=1e-12)


def test_merged_robot_carries_the_post_impact_momentum(setup):
    """The robot with the target appended has exactly the robot + target momentum after the impact."""
    robot, q, v, body, q_t, v_t = setup
    hit = impact(robot, "arm1_ee", q, v, body, q_t, v_t)
    merged = attach(robot, "arm1_ee", q, body, q_t)
    assert pin.computeTotalMass(merged.model) == pytest.approx(pin.computeTotalMass(robot.model) + 20.0)
    np.testing.assert_allclose(robot_momentum(merged, q, hit.v_robot), hit.momentum_after, atol=1e-10)


def test_grasp_balance_holds_for_the_exact_impulse(setup):
    """The merged robot's momentum after the exact grasp equals robot + target before (1e-10)."""
    from freefloat.space.capture import grasp_balance_error

    robot, q, v, body, q_t, v_t = setup
    hit = impact(robot, "arm1_ee", q, v, body, q_t, v_t)
    merged = attach(robot, "arm1_ee", q, body, q_t)
    assert grasp_balance_error(merged, q, hit.v_robot, hit.momentum_before) < 1e-10


def test_grasp_balance_fails_for_a_halved_impulse(setup):
    """With the impulse halved the merged-robot balance is off by far more than rounding, while
    the two-free-bodies sum (momentum_after) still balances."""
    from freefloat.space.capture import grasp_balance_error

    robot, q, v, body, q_t, v_t = setup
    hit = impact(robot, "arm1_ee", q, v, body, q_t, v_t)
    merged = attach(robot, "arm1_ee", q, body, q_t)
    half = v + (hit.v_robot - v) / 2  # v+ is linear in the impulse
    scale = np.abs(hit.momentum_before).max()
    assert grasp_balance_error(merged, q, half, hit.momentum_before) > 1e-3 * scale
    np.testing.assert_allclose(hit.momentum_after, hit.momentum_before, atol=1e-10 * max(scale, 1.0))


def planar_capture_setup():
    """Two-arm planar robot at rest; a spinning target that meets arm 1's end-effector at 0.5 s."""
    from freefloat.space.capture import Target

    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", base="planar", visuals=False)
    target = Target.meeting((7.75, 0.0, 0.0), 0.5, mass=50.0, inertia=(2.0, 2.5, 3.0), grasp=(-0.25, 0.0, 0.0),
                            velocity=(-0.4, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.3))
    return robot, target


def test_capture_then_detumbling_stops_the_target():
    """After the grasp the target's angular velocity falls below 1e-6 rad/s; momentum balances exactly."""
    from freefloat.space.capture import capture_and_detumble

    robot, target = planar_capture_setup()
    res = capture_and_detumble(robot, target, "arm1_ee", [("arm1_ee", "wz")], None, detumble_time=0.5)
    s = res.summary
    assert abs(s["impact_time"] - 0.5) < 5e-3
    assert s["momentum_balance_error"] < 1e-10 and s["momentum_drift_after_impact"] < 1e-8
    assert s["target_angular_velocity_at_impact"] > 0.1 and s["target_angular_velocity_final"] < 1e-6
    assert s["settling_time"] is not None and s["settling_time"] < 0.5


def test_a_target_that_never_arrives_is_reported():
    """A target flying away fails with the closest approach and its time."""
    from freefloat import FreefloatError
    from freefloat.space.capture import Target, capture_and_detumble

    robot, _ = planar_capture_setup()
    away = Target(mass=50.0, inertia=(2.0, 2.5, 3.0), grasp=(-0.25, 0.0, 0.0), position=(9.0, 0.0, 0.0), velocity=(0.5, 0.0, 0.0))
    with pytest.raises(FreefloatError, match=r"never reaches 'arm1_ee'.*closest approach 1\.0\d* m at t = 0\.001"):
        capture_and_detumble(robot, away, "arm1_ee", [("arm1_ee", "wz")], None, approach_time=0.2)


def test_meeting_refuses_a_precessing_spin():
    """Back-propagation needs the spin along a principal axis; otherwise it says so."""
    from freefloat import FreefloatError
    from freefloat.space.capture import Target

    with pytest.raises(FreefloatError, match="principal axis"):
        Target.meeting((0, 0, 0), 1.0, mass=1.0, inertia=(1.0, 2.0, 3.0), grasp=(0, 0, 0), velocity=(0, 0, 0),
                       angular_velocity=(0.3, 0.4, 0.0))


def test_an_approach_too_long_to_simulate_is_refused_naming_the_contact_time(tmp_path):
    """A contact a million seconds away: the approach alone would run for days, and preparing the
    scene says so, naming 'target.contact_time' (the detumbling's 'simulation.duration' is short)."""
    from freefloat.app import runner
    from freefloat.errors import SceneError

    from .conftest import quiet_scene

    scene = quiet_scene(tmp_path, "capture_planar", target={"contact_time": 1e6})
    with pytest.raises(SceneError, match=r"'target.contact_time' ask for a run that needs"):
        runner.prepare(scene)


def test_an_interrupted_approach_is_an_interrupt_not_a_missed_target(monkeypatch):
    """Ctrl-C during the approach (the loop returns status 'interrupted') stops the capture as an
    interrupt, not with 'target never reaches' (which would blame the scene)."""
    from freefloat.dynamics import simulation
    from freefloat.space import capture

    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", base="planar", visuals=False)
    target = capture.Target.meeting([7.75, 0.0, 0.0], 0.5, 50.0, (2.0, 2.5, 3.0), (-0.25, 0.0, 0.0),
                                    (-0.4, 0.0, 0.0), (0.0, 0.0, 0.3))
    real_run = simulation.run

    def interrupted(*args, **kwargs):  # the approach's loop, Ctrl-C at its first period
        return real_run(*args, **{**kwargs, "stop": lambda t, q, v: (_ for _ in ()).throw(KeyboardInterrupt())})

    monkeypatch.setattr(simulation, "run", interrupted)
    with pytest.raises(KeyboardInterrupt):
        capture.capture_and_detumble(robot, target, "arm1_ee", [("arm1_ee", "wz")], None, approach_time=0.2)


def test_the_target_flies_in_the_engine_as_it_flew_beside_it():
    """The target as a plant of the engine (run on its own before the approach, which reads it)
    takes the steps the former stop event took (the registry's RKMK4 once per control period, to
    1e-15), and with its spin on a principal axis keeps the closed-form torque-free motion
    (Target.meeting's: the CoM on its line, R(t) = exp(w t) R0) to 1e-12."""
    from freefloat import run
    from freefloat.dynamics.integrators import make_integrator

    _, target = planar_capture_setup()
    body = TargetBody(target)
    q0, v0 = body.initial_state()
    flight = run(body, q0, v0, 0.5, 1e-3, "rkmk4")
    assert flight.status == "completed" and flight.telemetry.q.shape == (501, 7)
    step, q, v = make_integrator("rkmk4", body.model), q0, v0
    for _ in range(500):  # the former per-period integration inside the approach's stop event
        q, v = step.advance(lambda qs, vs: pin.aba(body.model, body.data, qs, vs, np.zeros(6)), q, v, 1e-3)
    np.testing.assert_allclose(flight.telemetry.q[-1], q, rtol=0, atol=1e-15)
    np.testing.assert_allclose(flight.telemetry.v[-1], v, rtol=0, atol=1e-15)
    R0, w = pin.rpy.rpyToMatrix(*target.rpy), np.array(target.angular_velocity)
    pose = pin.XYZQUATToSE3(flight.telemetry.q[-1])
    np.testing.assert_allclose(pose.translation, np.array(target.position) + 0.5 * np.array(target.velocity), atol=1e-12)
    np.testing.assert_allclose(pose.rotation, pin.exp3(0.5 * w) @ R0, atol=1e-12)


def test_grasp_mismatch_vanishes_on_the_weld_after_the_impact(setup):
    """grasp_mismatch: zero gap on the fixture (grasp point on the hand), relative linear and
    angular speeds that are the twist differences before the impact and zero after it (the weld)."""
    from freefloat.space.capture import grasp_mismatch

    robot, q, v, body, q_t, v_t = setup
    gap, before, spin_before = grasp_mismatch(robot, "arm1_ee", q, v, body, q_t, v_t)
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q, v)
    ee = pin.getFrameVelocity(robot.model, data, robot.model.getFrameId("arm1_ee"), pin.LOCAL_WORLD_ALIGNED).linear
    pin.forwardKinematics(body.model, body.data, q_t, v_t)
    grasp = pin.getFrameVelocity(body.model, body.data, body.grasp_id, pin.LOCAL_WORLD_ALIGNED).linear
    assert gap < 1e-12 and before == pytest.approx(np.linalg.norm(ee - grasp), rel=1e-12) and before > 1e-3
    hit = impact(robot, "arm1_ee", q, v, body, q_t, v_t)
    assert spin_before > 1e-3
    assert max(grasp_mismatch(robot, "arm1_ee", q, hit.v_robot, body, q_t, hit.v_target)[1:]) < 1e-12


def test_attitude_change_is_the_angle_between_first_and_last_quaternions():
    """attitude_change: a turn of 0.3 rad about a tilted axis, whatever lies between."""
    from freefloat.space.capture import attitude_change

    axis = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    start = pin.Quaternion(pin.exp3(np.array([0.1, -0.4, 0.2])))
    middle = pin.Quaternion(pin.exp3(np.array([2.0, 0.0, 0.0])))
    end = pin.Quaternion(pin.exp3(0.3 * axis) @ start.matrix())
    quats = np.array([start.coeffs(), middle.coeffs(), end.coeffs()])
    assert attitude_change(quats) == pytest.approx(0.3, rel=1e-12)
