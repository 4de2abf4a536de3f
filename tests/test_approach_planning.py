"""Pre-capture planning (freefloat.space.planning): the reaction null space against Pinocchio, the
planned approach met in a simulated run, the optimiser's limits, refusals and the min-norm ratio."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings

from freefloat import load_robot
from freefloat.errors import InfeasiblePlan, InvalidArgument, SceneError
from freefloat.robot.joints import JointCoordinates
from freefloat.space.capture import Target, TargetBody
from freefloat.space.planning import (
    PLANNERS,
    ApproachRequest,
    GraspMotion,
    Limits,
    TaskRows,
    evaluate,
    plan_approach,
)
from freefloat.space.planning.floating_kinematics import FloatingKinematics, rollout
from freefloat.space.planning.reaction_null_space import RATE_LAWS, reaction_null_space_rates

from .conftest import REPO, quiet_scene, random_robots, random_state, robot_from_case

PLANAR_START = np.deg2rad([30, -60, 60, -30, -30, 60, -60, 30])


def _load(name: str, base: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(REPO / "urdf" / name, base=base, visuals=False)


@pytest.fixture(scope="module")
def planar():
    """The two-arm planar robot, bent (away from the stretched singularity), at rest."""
    robot = _load("two_arm_planar.urdf", "planar")
    q = robot.neutral()
    JointCoordinates(robot).set(q, PLANAR_START)
    return robot, q, np.zeros(robot.model.nv)


@pytest.fixture(scope="module")
def satellite():
    """The dual-arm satellite, both arms bent."""
    robot = _load("dual_arm_satellite.urdf", "free")
    q = robot.neutral()
    JointCoordinates(robot).set(q, np.deg2rad([0, -60, 90, -30, 90, 0] * 2))
    return robot, q


def request_for(robot, q0, v0, end_effector: str, reach, T: float, spin: float = 0.3, joints=None,
                **limits) -> ApproachRequest:
    """A request whose target's grasp point meets the hand's start position + ``reach`` at T."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q0)
    point = data.oMf[robot.model.getFrameId(end_effector)].translation + np.asarray(reach, float)
    target = Target.meeting(point, T, 50.0, (2.0, 2.5, 3.0), (-0.25, 0.0, 0.0), (-0.1, 0.05, 0.0), (0.0, 0.0, spin))
    return ApproachRequest(robot, q0, v0, (end_effector,), (GraspMotion.of(target),), T, Limits.of(robot, **limits),
                           joints, steps=60)


def pinocchio_base_velocity(robot, q: np.ndarray, qdot: np.ndarray, momentum_origin: np.ndarray) -> np.ndarray:
    """Pinocchio's base velocity (n_base,) for joint rates ``qdot`` at the momentum [P; L_o]: the
    base rows of the generalized momentum ``M v`` (CRBA) are that momentum in the base-link frame."""
    model, data = robot.model, robot.model.createData()
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    nb = robot.n_base
    pin.forwardKinematics(model, data, q)
    local = data.oMi[1].actInv(pin.Force(momentum_origin[:3], momentum_origin[3:])).vector
    rows = np.arange(6) if robot.base == "free" else np.array([0, 1, 5])
    return np.linalg.solve(M[:nb, :nb], local[rows] - M[:nb, nb:] @ qdot)


@settings(max_examples=25, deadline=None)
@given(random_robots(min_links=2, max_links=8))
def test_null_space_rates_leave_no_base_rotation_on_random_trees(tmp_path_factory, case):
    """At zero momentum the reaction-null-space rates (built from the hand-built J0) leave the base
    angular velocity zero to round-off, with the base velocity from Pinocchio's CRBA."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, _ = random_state(robot, rng)
    kin = FloatingKinematics(robot, np.zeros(6))
    state = kin.matrices(q)
    task = TaskRows.position(robot, robot.end_effectors[:1])
    qdot = reaction_null_space_rates(state, np.zeros(6), rng.normal(size=len(task.rows)), task)
    base = pinocchio_base_velocity(robot, q, qdot, np.zeros(6))
    scale = max(1.0, np.abs(qdot).max())
    assert np.abs(base[3:]).max() < 1e-10 * scale


@pytest.mark.parametrize("fixture", ["planar", "satellite"])
def test_null_space_rates_meet_the_task_with_a_still_base_at_nonzero_momentum(fixture, request):
    """With a drifting and turning robot (nonzero momentum) the rates hold the base attitude still
    and give the end-effector the asked linear velocity, both from Pinocchio (CRBA base velocity,
    frame velocity)."""
    robot, q = request.getfixturevalue(fixture)[:2]
    rng = np.random.default_rng(3)
    v_start = 0.05 * rng.normal(size=robot.model.nv)
    momentum = FloatingKinematics.at_state(robot, q, v_start).momentum_origin
    kin = FloatingKinematics(robot, momentum)
    state = kin.matrices(q)
    task = TaskRows.position(robot, robot.end_effectors[:1])
    wanted = rng.normal(size=len(task.rows)) * 0.1
    qdot = reaction_null_space_rates(state, kin.momentum_base(state), wanted, task)
    v = np.concatenate((pinocchio_base_velocity(robot, q, qdot, momentum), qdot))
    angular = v[3:6] if robot.base == "free" else v[2:3]
    assert np.abs(angular).max() < 1e-12
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q, v)
    linear = pin.getFrameVelocity(robot.model, data, robot.model.getFrameId(robot.end_effectors[0]),
                                  pin.LOCAL_WORLD_ALIGNED).linear
    np.testing.assert_allclose(linear[: len(wanted)], wanted, atol=1e-12)


def test_min_norm_rates_turn_the_base(planar):
    """The minimum-norm rates of the same task do turn the base (what the null space avoids)."""
    robot, q, _ = planar
    kin = FloatingKinematics(robot, np.zeros(6))
    state = kin.matrices(q)
    task = TaskRows.position(robot, ("arm1_ee",))
    qdot = RATE_LAWS["min_norm"](state, np.zeros(6), np.array([0.1, 0.1]), task)
    assert abs(pinocchio_base_velocity(robot, q, qdot, np.zeros(6))[2]) > 1e-3


def test_grasp_motion_follows_the_target_body_integrated_by_pinocchio():
    """The closed-form grasp-point flight equals the target body's free motion (Pinocchio ABA,
    RK4 at 1 ms), position and velocity, after 1 s."""
    target = Target.meeting((1.0, 0.5, 0.2), 1.0, 20.0, (1.0, 1.5, 2.0), (-0.3, 0.1, 0.05), (0.1, -0.2, 0.05),
                            (0.0, 0.0, 0.7), rpy_at_contact=(0.0, 0.0, 0.4))
    body = TargetBody(target)
    q, v = body.initial_state()
    zero, h = np.zeros(6), 1e-3
    f = lambda qs, vs: pin.aba(body.model, body.data, qs, vs, zero)  # noqa: E731
    for _ in range(1000):
        k1q, k1v = v, f(q, v)
        k2q, k2v = v + h / 2 * k1v, f(pin.integrate(body.model, q, h / 2 * k1q), v + h / 2 * k1v)
        k3q, k3v = v + h / 2 * k2v, f(pin.integrate(body.model, q, h / 2 * k2q), v + h / 2 * k2v)
        k4q, k4v = v + h * k3v, f(pin.integrate(body.model, q, h * k3q), v + h * k3v)
        q = pin.integrate(body.model, q, h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q))
        v = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
    pin.forwardKinematics(body.model, body.data, q, v)
    p = pin.updateFramePlacement(body.model, body.data, body.grasp_id).translation
    velocity = pin.getFrameVelocity(body.model, body.data, body.grasp_id, pin.LOCAL_WORLD_ALIGNED).linear
    p_ref, v_ref, _ = GraspMotion.of(target).at(1.0)
    np.testing.assert_allclose(p, p_ref, atol=1e-9)
    np.testing.assert_allclose(velocity, v_ref, atol=1e-9)
    np.testing.assert_allclose(p_ref, (1.0, 0.5, 0.2), atol=1e-12)  # Target.meeting's contact point


def test_rollout_keeps_the_momentum(satellite):
    """Along a roll-out with arbitrary joint rates, Pinocchio's momentum about the origin stays the
    start's (1e-10)."""
    robot, q = satellite
    rng = np.random.default_rng(5)
    v0 = 0.05 * rng.normal(size=robot.model.nv)
    kin = FloatingKinematics.at_state(robot, q, v0)
    qs, vs = rollout(kin, q, lambda t, _q: 0.3 * np.sin(np.arange(1, robot.n_joints + 1) * t), np.linspace(0, 1, 21))
    data = robot.model.createData()
    for qk, vk in zip(qs, vs):
        hg = pin.computeCentroidalMomentum(robot.model, data, qk, vk)
        np.testing.assert_allclose(pin.SE3(np.eye(3), data.com[0]).act(hg).vector, kin.momentum_origin, atol=1e-10)


def _former_rollout(kin, q0, rates, times):
    """The hand-written roll-out the planner had before it used the engine's integrators:
    classical RK4 adding the stage velocities through ``pin.integrate`` without ``dexp^-1``."""
    model = kin.robot.model

    def f(t, q):
        return kin.velocity(q, rates(t, q))

    qs, vs = [np.asarray(q0, float)], [f(times[0], q0)]
    for k in range(len(times) - 1):
        t, h, q = times[k], times[k + 1] - times[k], qs[-1]
        k1 = vs[-1]
        k2 = f(t + h / 2, pin.integrate(model, q, k1 * h / 2))
        k3 = f(t + h / 2, pin.integrate(model, q, k2 * h / 2))
        k4 = f(t + h, pin.integrate(model, q, k3 * h))
        qs.append(pin.integrate(model, q, (k1 + 2 * k2 + 2 * k3 + k4) * h / 6))
        vs.append(f(t + h, qs[-1]))
    return np.array(qs), np.array(vs)


def test_the_rollout_through_the_engine_moves_within_the_former_rk4s_error(satellite):
    """On a plan's grid (a 2 s approach in 40 steps, the base spinning), the engine's RKMK4 puts
    the base within the former hand-written RK4's own error of it (both against RKMK8 on a 16x
    finer grid; 1.7e-6 apart, the former's error 1.7e-6), at a twentieth of that error (5.4e-8:
    the chart's dexp^-1, which the former lacked); the joints take the same tableau's quadrature
    in both. The engine's uncorrected RK4 (``rk4_naive``) is the former roll-out to round-off."""
    from freefloat.dynamics import flow

    robot, q = satellite
    v0 = np.zeros(robot.model.nv)
    v0[3:6] = [0.2, -0.1, 0.3]
    kin = FloatingKinematics.at_state(robot, q, v0)
    rates = lambda t, _q: 0.4 * np.sin(np.arange(1, robot.n_joints + 1) * t)  # noqa: E731
    velocity = lambda t, q_: kin.velocity(q_, rates(t, q_))  # noqa: E731
    times = np.linspace(0.0, 2.0, 41)
    former = _former_rollout(kin, q, rates, times)[0][-1]
    now = rollout(kin, q, rates, times)[0][-1]
    naive = flow.rollout(velocity, robot.model, q, times, "rk4_naive")[0][-1]
    truth = flow.rollout(velocity, robot.model, q, np.linspace(0.0, 2.0, 641), "rkmk8")[0][-1]

    def gap(a, b):  # the base's pose: [translation; rotation] in the local frame, m and rad
        return float(np.abs(pin.difference(robot.model, a, b)[:6]).max())

    assert float(np.abs(pin.difference(robot.model, naive, former)).max()) < 1e-12
    assert gap(now, former) <= 1.05 * gap(former, truth)
    assert gap(now, truth) < gap(former, truth) / 20


def test_planned_approach_meets_the_grasp_in_a_simulated_run(planar):
    """Tracked by computed torque through the one loop, the null-space plan puts the hand on the
    target's grasp point at the grasp instant with its velocity (the target integrated on its
    own), within the contact tolerance; the base barely turns."""
    from freefloat.space.capture import approach
    from freefloat.space.planning.tracking import PlanTracking

    robot, q0, v0 = planar
    req = request_for(robot, q0, v0, "arm1_ee", (0.3, 0.4, 0.0), 1.0)
    plan = plan_approach(req, "null_space")
    body = TargetBody(Target.meeting(req.grasps[0].at(1.0)[0], 1.0, 50.0, (2.0, 2.5, 3.0), (-0.25, 0.0, 0.0),
                                     (-0.1, 0.05, 0.0), (0.0, 0.0, 0.3)))
    pre, flight = approach(robot, body, ("arm1_ee",), 1e-3, 1.2, 1e-3, "rkmk4", q0, v0, 10.0, 100.0, "exact",
                           PlanTracking(robot, plan.path, 10.0, 100.0), not_before=1.0)
    assert pre.telemetry.t[-1] == pytest.approx(1.0)
    q, v = pre.telemetry.q[-1], pre.telemetry.v[-1]
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q, v)
    fid = robot.model.getFrameId("arm1_ee")
    p_E = pin.updateFramePlacement(robot.model, data, fid).translation
    v_E = pin.getFrameVelocity(robot.model, data, fid, pin.LOCAL_WORLD_ALIGNED).linear
    pin.forwardKinematics(body.model, body.data, flight.q, flight.v)
    p_g = pin.updateFramePlacement(body.model, body.data, body.grasp_id).translation
    v_g = pin.getFrameVelocity(body.model, body.data, body.grasp_id, pin.LOCAL_WORLD_ALIGNED).linear
    assert np.linalg.norm(p_E - p_g) < 1e-4
    assert np.linalg.norm(v_E - v_g) < 1e-3
    yaw = np.arctan2(pre.telemetry.q[:, 3], pre.telemetry.q[:, 2])
    assert np.abs(yaw - yaw[0]).max() < 1e-4


def test_null_space_turns_the_base_far_less_than_min_norm(satellite):
    """On the same approach, the reaction-null-space plan's base attitude change is at least 5x
    smaller than the minimum-norm plan's (the dissertation's sec 3.8.1 claim, computed)."""
    robot, q0 = satellite
    req = request_for(robot, q0, np.zeros(robot.model.nv), "left_tool0", (0.1, 0.2, 0.2), 1.5)
    rns, mn = (evaluate(req, PLANNERS[m](req), m) for m in ("null_space", "min_norm"))
    assert rns.position_error < req.tolerance and mn.position_error < req.tolerance
    assert mn.attitude_change > 5 * rns.attitude_change


@pytest.mark.slow
def test_optimised_plan_keeps_the_limits_where_min_norm_breaks_them(planar):
    """With a torque limit the minimum-norm plan exceeds, the optimised plan meets the grasp
    within tolerance, keeps every joint rate and torque within the limits on the fine grid, and
    turns the base less than the minimum-norm plan."""
    from freefloat.space.planning.optimised import optimised_path

    robot, q0, v0 = planar
    free = request_for(robot, q0, v0, "arm1_ee", (0.2, 0.3, 0.0), 1.0, joints=np.arange(4))
    mn = evaluate(free, PLANNERS["min_norm"](free), "min_norm")
    limit = 0.9 * np.abs(mn.torque).max()
    req = request_for(robot, q0, v0, "arm1_ee", (0.2, 0.3, 0.0), 1.0, joints=np.arange(4), torque=limit)
    plan = evaluate(req, optimised_path(req, degree=5, samples=12, ftol=1e-4), "optimised")
    assert plan.position_error < req.tolerance and plan.velocity_error < req.velocity_tolerance
    assert np.abs(plan.torque).max() <= limit
    assert (np.abs(plan.joint_rate) <= req.limits.joint_rate).all()
    assert plan.attitude_change < mn.attitude_change
    with pytest.raises(InfeasiblePlan, match="torque limit violated"):
        plan_approach(req, "min_norm")


def test_a_grasp_point_out_of_reach_is_refused(planar):
    """A grasp point 20 m away is refused, naming the end-effector, the miss and the reach."""
    robot, q0, v0 = planar
    req = request_for(robot, q0, v0, "arm1_ee", (20.0, 0.0, 0.0), 1.0)
    with pytest.raises(InfeasiblePlan, match=r"out of reach of 'arm1_ee'.*reach is"):
        plan_approach(req, "null_space")


def test_a_rate_limit_is_refused_naming_the_joint_and_the_deadline(planar):
    """A joint-rate limit the plan exceeds is refused with the joint, the time and the deadline."""
    robot, q0, v0 = planar
    req = request_for(robot, q0, v0, "arm1_ee", (0.3, 0.4, 0.0), 1.0, joint_rate=0.05)
    message = r"joint rate limit violated: joint 'arm\d_joint\d'.*deadline of 1 s is too short"
    with pytest.raises(InfeasiblePlan, match=message):
        plan_approach(req, "null_space")


def test_a_deadline_too_short_is_refused(planar):
    """The same approach in 0.05 s needs torques beyond the URDF's limits: refused."""
    robot, q0, v0 = planar
    req = request_for(robot, q0, v0, "arm1_ee", (0.3, 0.4, 0.0), 0.05)
    with pytest.raises(InfeasiblePlan, match="limit violated.*too short"):
        plan_approach(req, "min_norm")


def test_an_unknown_method_is_named():
    """plan_approach lists the methods for an unknown one."""
    from freefloat.errors import UnknownName

    with pytest.raises(UnknownName, match="null_space"):
        plan_approach(None, "fastest")  # type: ignore[arg-type]


def test_scene_approach_without_a_target_is_refused(tmp_path):
    """An [approach] section needs a [target]."""
    with pytest.raises(SceneError, match=r"\[approach\] plans the approach to a \[target\]"):
        quiet_scene(tmp_path, "four_arm_joint_space", approach={"method": "null_space"})


def test_scene_with_an_unreachable_grasp_is_refused_before_running(tmp_path):
    """Preparing a planned capture scene whose grasp point is out of reach names [approach]."""
    from freefloat.app.runner import prepare

    scene = quiet_scene(tmp_path, "capture_planned_planar", approach={"reach": [30.0, 0.0, 0.0]})
    with pytest.raises(SceneError, match=r"\[approach\].*out of reach"):
        prepare(scene)


@pytest.mark.slow
def test_planned_capture_scene_runs_its_three_phases(tmp_path):
    """capture_planned_planar, detumbling shortened: the grasp at the planned instant within the
    contact tolerance, the approach's simulated base rotation below the minimum-norm plan's by
    the summary's ratio's aim (5x), the target stopped, one outcome with the pre-capture telemetry."""
    from freefloat.app.runner import simulate

    scene = quiet_scene(tmp_path, "capture_planned_planar", simulation={"duration": 0.2}, target={"contact_time": 1.0},
                        approach={"steps": 100})
    out = simulate(scene)
    s = out.summary
    assert s["impact_time"] == pytest.approx(scene.target.contact_time)
    assert s["grasp_position_mismatch"] < scene.target.tolerance
    assert s["approach_method"] == "null_space" and s["approach_attitude_ratio"] > 5
    assert 5 * s["approach_base_attitude_change"] < s["approach_min_norm_attitude_change"]
    assert s["target_angular_velocity_final"] < 1e-6
    assert out.extra_telemetry["pre_capture"].t[-1] == pytest.approx(scene.target.contact_time)


@pytest.mark.slow
def test_a_planned_capture_draws_its_approach_tracking(tmp_path):
    """A planned capture written to a folder has the approach's joint tracking figure, whose
    data is the pre-capture phase's plan minus its positions, and its summary points there for the
    joint errors the phase after the grasp cannot have."""
    from freefloat.app.runner import simulate

    scene = quiet_scene(tmp_path, "capture_planned_planar", simulation={"duration": 0.02}, target={"contact_time": 1.0},
                        approach={"steps": 100}, output={"figures": ["joint_errors", "approach_joint_errors"],
                                                         "html": False})
    done = simulate(scene, out=tmp_path / "out")
    pre = done.extra_telemetry["pre_capture"]
    assert np.abs(pre.joint_reference - pre.joint_positions).max() > 0.0
    assert (tmp_path / "out" / "approach_joint_errors.png").is_file()
    assert not (tmp_path / "out" / "joint_errors.png").exists()
    assert "approach_joint_errors" in done.summary["figures_not_drawn"]["joint_errors"]


def test_two_hand_plan_puts_both_hands_on_their_grasp_points(planar):
    """Planned for both hands at once, the null-space path ends with each hand on its own grasp
    point with its velocity (Pinocchio's frame placements and velocities at the plan's last state)
    and the base still."""
    robot, q0, v0 = planar
    one = request_for(robot, q0, v0, "arm1_ee", (0.2, 0.3, 0.0), 1.5)
    second = dataclasses.replace(one.grasps[0], grasp=one.grasps[0].grasp + np.array([0.0, 0.4, 0.0]))
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q0)
    start_2 = data.oMf[robot.model.getFrameId("arm2_ee")].translation
    second = dataclasses.replace(second, com=second.com + (start_2 + (0.2, 0.3, 0.0)) - second.at(1.5)[0])
    req = dataclasses.replace(one, end_effectors=("arm1_ee", "arm2_ee"), grasps=(one.grasps[0], second))
    plan = plan_approach(req, "null_space")
    pin.forwardKinematics(robot.model, data, plan.q[-1], plan.v[-1])
    for hand, grasp in zip(req.end_effectors, req.grasps):
        fid = robot.model.getFrameId(hand)
        p_g, v_g, _ = grasp.at(1.5)
        assert np.linalg.norm(pin.updateFramePlacement(robot.model, data, fid).translation[:2] - p_g[:2]) < 1e-4
        velocity = pin.getFrameVelocity(robot.model, data, fid, pin.LOCAL_WORLD_ALIGNED).linear
        assert np.linalg.norm(velocity[:2] - v_g[:2]) < 1e-3
    assert plan.attitude.max() < 1e-6


@pytest.mark.slow
def test_planned_two_hand_capture_scene_grasps_at_the_planned_instant(tmp_path):
    """capture_planned_two_hands_planar, detumbling cut short: both hands grasp at the contact
    time within the contact tolerance, the base turned far less than by the minimum-norm plan."""
    from freefloat.app.runner import simulate

    scene = quiet_scene(tmp_path, "capture_planned_two_hands_planar", simulation={"duration": 0.02},
                        target={"contact_time": 1.0}, approach={"steps": 100})
    s = simulate(scene).summary
    assert s["impact_time"] == pytest.approx(scene.target.contact_time)
    assert s["grasp_position_mismatch"] < scene.target.tolerance
    assert 5 * s["approach_base_attitude_change"] < s["approach_min_norm_attitude_change"]


def test_shifted_grasp_motion_moves_its_time_origin():
    """GraspMotion.shifted(s).at(t) equals at(s + t): position, velocity and acceleration."""
    target = Target.meeting((1.0, 0.5, 0.2), 1.0, 20.0, (1.0, 1.5, 2.0), (-0.3, 0.1, 0.05), (0.1, -0.2, 0.05),
                            (0.0, 0.0, 0.7))
    motion = GraspMotion.of(target)
    for a, b in zip(motion.shifted(0.4).at(0.35), motion.at(0.75)):
        np.testing.assert_allclose(a, b, atol=1e-14)


@pytest.mark.slow
def test_a_late_start_holds_the_posture_then_grasps_at_the_contact(tmp_path):
    """approach.start = 0.5 s with contact at 1.2 s: the joints stay at the start posture until
    0.5 s, move after it, and the hand grasps at the contact time within the tolerance."""
    from freefloat.app.runner import simulate

    scene = quiet_scene(tmp_path, "capture_planned_planar", simulation={"duration": 0.02}, target={"contact_time": 1.2},
                        approach={"steps": 100, "start": 0.5})
    out = simulate(scene)
    pre = out.extra_telemetry["pre_capture"]
    still = pre.t <= 0.5
    assert np.abs(pre.q[still, 4:] - pre.q[0, 4:]).max() < 1e-12
    assert np.abs(pre.q[-1, 4:] - pre.q[0, 4:]).max() > 0.01
    assert out.summary["impact_time"] == pytest.approx(1.2)
    assert out.summary["grasp_position_mismatch"] < scene.target.tolerance


@pytest.mark.parametrize(("sections", "message"), [
    ({"approach": {"start": 1.0}}, "must come before 'target.contact_time'"),
    ({"approach": {"start": 0.5}, "initial": {"joint_velocities": {"arm1_joint1": 1.0}}}, "at rest"),
])
def test_a_bad_start_is_refused(tmp_path, sections, message):
    """approach.start at or after the contact, or later than 0 from a moving robot, is refused."""
    from freefloat.app.runner import prepare

    sections.setdefault("target", {"contact_time": 1.0})
    scene = quiet_scene(tmp_path, "capture_planned_planar", **sections)
    with pytest.raises(SceneError, match=message):
        prepare(scene)


@pytest.mark.parametrize("fixture", ["planar", "satellite"])
def test_a_pose_plan_puts_the_hand_on_its_handle(fixture, request):
    """With match = "pose" the null-space plan ends with the hand's frame on the handle (the hand's
    start orientation turned, then carried by the target) and turning with the target, from
    Pinocchio's frame placement and velocity at the plan's last state; the base still."""
    robot, q0 = request.getfixturevalue(fixture)[:2]
    hand = robot.end_effectors[0]
    position_only = request_for(robot, q0, np.zeros(robot.model.nv), hand, (0.1, 0.2, 0.0), 1.5)
    grasp = position_only.grasps[0]
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q0)
    fid = robot.model.getFrameId(hand)
    turn = np.array([0.0, 0.0, 0.3]) if robot.base == "planar" else np.array([0.05, -0.1, 0.2])
    at_contact = pin.exp3(grasp.angular_velocity * 1.5) @ grasp.rotation
    grasp = dataclasses.replace(grasp, handle=at_contact.T @ pin.exp3(turn) @ data.oMf[fid].rotation)
    req = dataclasses.replace(position_only, grasps=(grasp,), match="pose")
    plan = evaluate(req, PLANNERS["null_space"](req), "null_space")
    pin.forwardKinematics(robot.model, data, plan.q[-1], plan.v[-1])
    rotation = pin.updateFramePlacement(robot.model, data, fid).rotation
    angle = np.linalg.norm(pin.log3(rotation @ grasp.orientation(1.5).T))
    spin = pin.getFrameVelocity(robot.model, data, fid, pin.LOCAL_WORLD_ALIGNED).angular
    assert angle < 1e-4 and np.linalg.norm(spin - grasp.angular_velocity) < 1e-4
    assert plan.position_error < req.tolerance and plan.attitude.max() < 1e-6


@pytest.mark.slow
def test_matching_the_pose_shrinks_the_grasp_impulse(tmp_path):
    """capture_planned_planar with match = "pose": the hand turns with the target at the grasp
    (angular velocity mismatch below 1e-3 rad/s, against the target's 17 deg/s with position
    only) and the grasp impulse is smaller than with position matching, both simulated."""
    from freefloat.app.runner import simulate

    runs = {}
    for match in ("position", "pose"):
        (tmp_path / match).mkdir()
        runs[match] = simulate(quiet_scene(tmp_path / match, "capture_planned_planar", simulation={"duration": 0.02},
                                           target={"contact_time": 1.0},
                                           approach={"steps": 100, "match": match, "reach": [0.2, 0.3, 0.0]})).summary
    assert runs["pose"]["grasp_angular_velocity_mismatch"] < 1e-3 < runs["position"]["grasp_angular_velocity_mismatch"]
    assert runs["pose"]["grasp_impulse"] < runs["position"]["grasp_impulse"]
    assert runs["pose"]["grasp_position_mismatch"] < 1e-3


def test_a_diverging_plan_is_refused_not_returned(planar, monkeypatch):
    """A planner whose linear algebra fails, or whose path is not finite, is refused as out of reach
    (the path met a singularity), never handed on with NaN."""
    from scipy.interpolate import PPoly

    from freefloat.space.planning import JointPath

    robot, q0, v0 = planar
    req = request_for(robot, q0, v0, "arm1_ee", (0.3, 0.4, 0.0), 1.0)

    def failing(_request):
        raise np.linalg.LinAlgError("SVD did not converge")

    def not_finite(request_):
        return JointPath(PPoly(np.full((4, 1, robot.n_joints), np.nan), [0.0, request_.duration]))

    for planner in (failing, not_finite):
        monkeypatch.setitem(PLANNERS, "null_space", planner)
        with pytest.raises(InfeasiblePlan, match="out of reach: the plan diverged") as caught:
            plan_approach(req, "null_space")
        assert caught.value.reason == "reach"


def test_a_planning_grid_beyond_its_bound_is_refused_before_planning(planar):
    """steps of 200,000,000 is refused naming 'steps' and the bound, before any planning."""
    robot, q0, v0 = planar
    with pytest.raises(InvalidArgument, match="'steps' must be an integer from 4 to 100,000"):
        dataclasses.replace(request_for(robot, q0, v0, "arm1_ee", (0.3, 0.4, 0.0), 1.0), steps=200_000_000)


def test_a_mission_joint_given_twice_is_refused_naming_it(planar):
    """A duplicate mission joint is refused as such (naming the joint), not as a grasp out of reach."""
    robot, q0, v0 = planar
    with pytest.raises(InvalidArgument, match=f"mission joint\\(s\\) '{robot.joint_names[1]}' given twice"):
        request_for(robot, q0, v0, "arm1_ee", (0.3, 0.4, 0.0), 1.0, joints=np.array([0, 1, 1]))


def test_a_turn_under_position_matching_is_refused_naming_it(tmp_path):
    """approach.turn with match = "position" (which plans no orientation) is refused naming 'turn'."""
    from freefloat.app.runner import prepare

    scene = quiet_scene(tmp_path, "capture_planned_planar", approach={"turn": [0.0, 0.0, 20.0]})
    with pytest.raises(SceneError, match=r"\[approach\] 'turn' \[0.0, 0.0, 20.0\] turns the hand's handle"):
        prepare(scene)


def test_a_planned_capture_without_a_controller_is_refused(tmp_path):
    """A planned approach with controller.kind = "none" (which would still track the plan) is refused naming the key."""
    from freefloat.app.runner import prepare

    scene = quiet_scene(tmp_path, "capture_planned_planar", controller={"kind": "none"})
    with pytest.raises(SceneError, match=r"'controller.kind' is \"none\""):
        prepare(scene)


def test_a_scene_planning_grid_beyond_its_bound_is_refused_naming_the_file_and_key(tmp_path):
    """[approach] steps = 200000000 in a scene file is refused before planning, naming the file, [approach] and 'steps'."""
    from freefloat.app.runner import prepare

    scene = quiet_scene(tmp_path, "capture_planned_planar", approach={"steps": 200_000_000})
    with pytest.raises(SceneError, match=r"s.toml: \[approach\] 'steps' must be an integer from 4 to 100,000"):
        prepare(scene)
