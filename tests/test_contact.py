"""Tests of freefloat.space.contact: coal's signed distance against the closed forms of the
primitives, a head-on rebound against Hunt-Crossley's exact restitution, robot + target momentum
kept by the contact forces, the velocity jump converging to Newton's rigid impulse as the
stiffness grows, and the latch closing the weld on a held contact."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot, run
from freefloat.errors import InvalidArgument
from freefloat.paths import URDF_DIR
from freefloat.robot.conventions import momentum_about_origin, skew
from freefloat.space.contact import ContactLaw, ContactSettings, Shape, contact_field, proximity, restitution
from freefloat.space.contact.latch import Latch, LatchWatch, close_weld
from freefloat.space.contact.target import target_state, with_free_target
from freefloat.space.orbit.libration import rigid_satellite_urdf

RNG = np.random.default_rng(39)


def random_pose() -> pin.SE3:
    """A seeded random pose within 0.3 m of the origin."""
    return pin.SE3(pin.exp3(RNG.normal(size=3)), 0.1 * RNG.normal(size=3))


def test_sphere_sphere_matches_closed_form():
    """Depth, normal and midpoint of two overlapping spheres equal the closed form to round-off."""
    a, b = Shape("sphere", (0.2,)), Shape("sphere", (0.15,))
    for _ in range(20):
        pa, pb = random_pose(), random_pose()
        near = proximity(a.geometry(), pa, b.geometry(), pb)
        gap = pb.translation - pa.translation
        normal = gap / np.linalg.norm(gap)
        point = 0.5 * (pa.translation + 0.2 * normal + pb.translation - 0.15 * normal)
        assert near.depth == pytest.approx(0.35 - np.linalg.norm(gap), abs=1e-12)
        np.testing.assert_allclose(near.normal, normal, atol=1e-12)
        np.testing.assert_allclose(near.point, point, atol=1e-12)


def test_sphere_box_matches_closed_form():
    """A sphere against a box face, edge or corner: coal's depth and normal equal the closed form
    (closest point of the box, clamped in its frame) to 1e-9."""
    sides = np.array([0.4, 0.3, 0.2])
    box, sphere = Shape("box", tuple(sides)), Shape("sphere", (0.1,))
    for _ in range(50):
        pose = random_pose()
        local = RNG.uniform(-1.0, 1.0, 3) * (0.5 * sides + 0.08)
        if np.all(np.abs(local) <= 0.5 * sides):
            continue  # centre inside: the deep case, whose closest face the closed form does not pick uniquely
        centre = pose.act(local)
        closest = np.clip(local, -0.5 * sides, 0.5 * sides)
        away = local - closest
        depth = 0.1 - np.linalg.norm(away)
        if depth <= 1e-6:
            continue
        near = proximity(box.geometry(), pose, sphere.geometry(), pin.SE3(np.eye(3), centre))
        assert near.depth == pytest.approx(depth, abs=1e-9)
        np.testing.assert_allclose(near.normal, pose.rotation @ away / np.linalg.norm(away), atol=1e-9)


def test_restitution_first_order():
    """The exact restitution tends to 1 - (2/3) c v / k for small c v / k (error second order)."""
    law = ContactLaw(1e5, 1.5, 1e3)
    for speed in (1e-3, 1e-2):
        alpha = law.damping * speed / law.stiffness
        assert restitution(law, speed) == pytest.approx(1.0 - 2.0 / 3.0 * alpha, abs=alpha**2)


@pytest.fixture(scope="module")
def ball(tmp_path_factory):
    """A free 1 kg ball (joint 1) as a robot."""
    path = tmp_path_factory.mktemp("ball") / "ball.urdf"
    path.write_text(rigid_satellite_urdf(1.0, (0.004, 0.004, 0.004)).replace("satellite", "ball"))
    return load_robot(path, visuals=False, end_effectors=["ball"])


@pytest.mark.parametrize("exponent", [1.0, 1.5])
def test_rebound_matches_hunt_crossley(ball, exponent):
    """A 10 kg sphere hitting the 1 kg ball head-on leaves with the relative speed of the exact
    Hunt-Crossley restitution (to 1e-6, whatever the exponent) and the momentum it came with."""
    two = with_free_target(ball, 10.0, (0.1, 0.1, 0.1))
    settings = ContactSettings("ball", "target", first_size=(0.1,), second_size=(0.1,), stiffness=1e5,
                               exponent=exponent, damping=2e5)
    field = contact_field(two, settings)
    qt, vt = target_state((0.2005, 0.0, 0.0), (-0.2, 0.0, 0.0))
    q0, v0 = np.concatenate((ball.neutral(), qt)), np.concatenate((np.zeros(6), vt))
    result = run(two, q0, v0, 0.1, 1e-3, integrator="dop853", rtol=1e-12, atol=1e-14, environment=[field])
    v = result.telemetry.v[-1]
    assert field.contact(result.telemetry.q[-1], v) is None  # apart again
    e = (v[6] - v[0]) / 0.2
    assert restitution(settings.law(), 0.2) < 0.8  # a damping that matters
    assert e == pytest.approx(restitution(settings.law(), 0.2), abs=1e-6)
    assert 10.0 * v[6] + v[0] == pytest.approx(-2.0, abs=1e-12)


@pytest.fixture(scope="module")
def robot_and_target():
    """The two-arm robot with a free 5 kg target."""
    robot = load_robot(URDF_DIR / "two_arm_planar.urdf", visuals=False)
    return robot, with_free_target(robot, 5.0, (0.05, 0.05, 0.05))


#: The target's start and touching y (m): its centre 0.3001 m, then 0.3 m (the radii's sum) from the
#: hand's, 0.05 m off the arm's axis.
START_Y, TOUCH_Y = np.sqrt(0.3001**2 - 0.05**2), np.sqrt(0.3**2 - 0.05**2)


def hand_strike(robot, merged, stiffness: float, friction: float = 0.0, damping_ratio: float = 0.5):
    """The field and state of a target sphere striking the still first hand sideways, 0.05 m off
    the arm's axis, 0.1 mm before contact at 0.1 m/s (c / k = ``damping_ratio`` s/m)."""
    settings = ContactSettings("arm1_ee", "target", first_size=(0.1,), second_size=(0.2,), stiffness=stiffness,
                               damping=damping_ratio * stiffness, friction=friction)
    qt, vt = target_state((7.8, START_Y, 0.0), (0.0, -0.1, 0.0))
    return settings, contact_field(merged, settings), np.concatenate((robot.neutral(), qt)), \
        np.concatenate((np.zeros(robot.model.nv), vt))


def test_contact_keeps_momentum(robot_and_target):
    """Through a sliding, eccentric contact robot + target momentum drifts < 1e-9 N s (internal
    forces, dop853 at rtol 1e-11)."""
    robot, merged = robot_and_target
    _, field, q0, v0 = hand_strike(robot, merged, 1e5, friction=0.3)
    v0[-6:-3] += (0.05, 0.0, 0.02)  # sliding
    result = run(merged, q0, v0, 0.1, 1e-3, integrator="dop853", rtol=1e-11, atol=1e-13, environment=[field])
    momentum = result.telemetry.momentum
    touched = [field.contact(q, v) is not None for q, v in zip(result.telemetry.q, result.telemetry.v)]
    assert any(touched)
    assert np.abs(momentum - momentum[0]).max() < 1e-9
    assert np.abs(result.telemetry.v[-1, :-6]).max() > 1e-3  # the robot was pushed


def newton_jump(merged, field, settings, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The velocity jump (nv,) of Newton's frictionless rigid impact with the Hunt-Crossley
    restitution at the touching state: ``M^-1 J_n^T (1 + e) s / (J_n M^-1 J_n^T)``, s = -J_n v the
    approach speed, J_n the normal row of the relative contact-point Jacobian (Pinocchio's)."""
    model, data = merged.model, merged.model.createData()
    pin.forwardKinematics(model, data, q, v)
    a, b = field.joints
    near = proximity(field.geometries[0], data.oMi[a] * field.placements[0], field.geometries[1],
                     data.oMi[b] * field.placements[1])
    pin.computeJointJacobians(model, data, q)

    def point_jacobian(joint: int) -> np.ndarray:
        J = pin.getJointJacobian(model, data, joint, pin.LOCAL_WORLD_ALIGNED)
        return J[:3] - skew(near.point - data.oMi[joint].translation) @ J[3:]

    Jn = near.normal @ (point_jacobian(b) - point_jacobian(a))
    M = pin.crba(model, data, q)
    w = np.linalg.solve(np.triu(M) + np.triu(M, 1).T, Jn)
    speed = -Jn @ v
    return w * (1.0 + restitution(settings.law(), speed)) * speed / (Jn @ w)


@pytest.mark.slow
def test_velocity_jump_converges_to_rigid_impulse(robot_and_target):
    """As the stiffness grows 1e4 -> 1e7 N/m^1.5 (c / k fixed), the robot + target velocity jump
    through the contact approaches Newton's rigid impact, within 1 % at the stiffest."""
    robot, merged = robot_and_target
    errors = []
    for stiffness in (1e4, 1e7):
        settings, field, q0, v0 = hand_strike(robot, merged, stiffness)
        touching = q0.copy()
        touching[-5] = TOUCH_Y
        rigid = newton_jump(merged, field, settings, touching, v0)
        seen: list[float] = []

        def apart_again(t, q, v, field=field, seen=seen):
            touch = field.contact(q, v) is not None
            seen.extend([t] if touch else [])
            return bool(seen) and not touch

        result = run(merged, q0, v0, 1.0, 1e-3, integrator="dop853", rtol=1e-11, atol=1e-13, environment=[field],
                     stop=apart_again)
        assert result.status == "stopped"
        errors.append(np.linalg.norm(result.telemetry.v[-1] - v0 - rigid) / np.linalg.norm(rigid))
    assert errors[1] < 0.01
    assert errors[1] < errors[0]


def test_unknown_link_is_named(robot_and_target):
    """A contact on a link the model lacks is refused with the nearest names."""
    _, merged = robot_and_target
    with pytest.raises(InvalidArgument, match="arm1_ee"):
        contact_field(merged, ContactSettings("arm1_e", "target"))


def test_bad_shape_is_refused():
    """A box with one size, or an unknown shape, is refused naming the key."""
    with pytest.raises(InvalidArgument, match="first_size"):
        ContactSettings("a", "b", first_shape="box", first_size=(0.1,))
    with pytest.raises(InvalidArgument, match="sphere"):
        ContactSettings("a", "b", first_shape="spere")


@pytest.mark.parametrize(("damping_ratio", "closes"), [(20.0, True), (0.0, False)])
def test_latch_closes_the_weld_on_a_held_contact(robot_and_target, damping_ratio, closes):
    """A damped strike (c / k = 20 s/m) is held below 0.05 m/s for 0.05 s and latches; the weld's
    impulse then stops the hand-target relative twist (to 1e-12) and keeps robot + target momentum
    (to 1e-12 N s). An elastic strike bounces off before the hold time and never latches."""
    robot, merged = robot_and_target
    _, field, q0, v0 = hand_strike(robot, merged, 1e4, friction=0.5, damping_ratio=damping_ratio)
    watch = LatchWatch(field, Latch(0.05, 0.05))
    result = run(merged, q0, v0, 0.4, 1e-3, integrator="dop853", rtol=1e-10, atol=1e-12, environment=[field],
                 stop=watch)
    assert (watch.closed_at is not None) == closes and (result.status == "stopped") == closes
    if closes:
        q, v = result.telemetry.q[-1], result.telemetry.v[-1]
        hit = close_weld(merged.model, "arm1_ee", q, v)
        assert hit.gap_speed_before > 0.1
        assert close_weld(merged.model, "arm1_ee", q, hit.v_after).gap_speed_before < 1e-12
        data = merged.model.createData()
        before, after = (momentum_about_origin(merged.model, data, q, u) for u in (v, hit.v_after))
        assert np.abs(after - before).max() < 1e-12


def test_latch_refuses_a_bad_setting():
    """A hold time or speed that is not positive is refused naming it."""
    with pytest.raises(InvalidArgument, match="hold_time"):
        Latch(0.0, 0.01)
