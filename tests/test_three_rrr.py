"""The 3-RRR: a platform that turns (angular constraints with P != 0, thesis proposal eqs 101-102),
Orsino's model against Pinocchio's constraint dynamics on the same URDF and closure file."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import FreefloatError
from freefloat.dynamics.plants import ConstraintDynamicsPlant
from freefloat.dynamics.simulation import run_plant
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.closed_loop import track
from freefloat.parallel.platform_control import CircleReference
from freefloat.parallel.sliding_mode import PlatformControl
from freefloat.parallel.three_rrr import (
    CLOSURE,
    ThreeRRRParameters,
    assembly_guess,
    load_three_rrr,
    three_rrr_spec,
)
from freefloat.robot.builders import build_urdf, urdf_xml

from .conftest import REPO
from .loops import simulate

PARAMETERS = ThreeRRRParameters()
POSES = ([0.0, 0.0, 0.0], [0.01, -0.02, 0.3], [-0.02, 0.015, -0.5])


@pytest.fixture(scope="module")
def loaded():
    return load_three_rrr()


def assembled(mech, pose, rates):
    """Assembled q (12,) at ``pose`` (x, y, rz) and qd = C qd# for platform ``rates`` (3,)."""
    q = mech.assemble(np.array(pose, float), assembly_guess(PARAMETERS, pose))
    return q, mech.velocity_map(q) @ np.asarray(rates, float)


def pinocchio_forward(loaded, q, qd, tau):
    """``pin.constraintDynamics`` (proximal, mu 1e-12) on the spanning tree with the file's two
    welds: the accelerations (nv,) and a Data holding the motion at them (frames updated)."""
    model, cms = loaded.model, loaded.constraints
    data, cds = model.createData(), [c.createData() for c in cms]
    pin.initConstraintDynamics(model, data, cms, cds)
    tau_pin = np.zeros(model.nv)
    tau_pin[[model.idx_vs[j] for j in loaded.actuated]] = tau
    q_pin, qd_pin = loaded.pinocchio_q(q), loaded.pinocchio_q(qd)
    ddq = pin.constraintDynamics(model, data, q_pin, qd_pin, tau_pin, cms, cds, pin.ProximalSettings(1e-14, 1e-12, 50))
    kinematics = model.createData()
    pin.forwardKinematics(model, kinematics, q_pin, qd_pin, ddq)
    pin.updateFramePlacements(model, kinematics)
    return ddq.copy(), kinematics


def test_committed_urdf_is_what_the_parameters_generate():
    """urdf/three_rrr.urdf is exactly the spanning tree freefloat.parallel.three_rrr describes."""
    assert urdf_xml(build_urdf(three_rrr_spec(PARAMETERS))) == (REPO / "urdf" / "three_rrr.urdf").read_text()


def test_the_platform_coordinates_are_the_welded_frames_pose(loaded):
    """Assembled at (x, y, rz), every chain's tip frame (Pinocchio's forward kinematics) sits at
    (x, y) turned by rz about z, the three welds closed; the exact guess is already assembled."""
    mech, model = loaded.mechanism, loaded.model
    data = model.createData()
    for pose in POSES:
        q, _ = assembled(mech, pose, np.zeros(3))
        np.testing.assert_allclose(q[3:], assembly_guess(PARAMETERS, pose), atol=1e-12)
        pin.framesForwardKinematics(model, data, loaded.pinocchio_q(q))
        for name in ("c1_ee", "c2_ee", "c3_ee"):
            frame = data.oMf[model.getFrameId(name)]
            np.testing.assert_allclose(frame.translation, [pose[0], pose[1], 0.0], atol=1e-12)
            np.testing.assert_allclose(frame.rotation, pin.rpy.rpyToMatrix(0.0, 0.0, pose[2]), atol=1e-12)


def test_forward_dynamics_equal_pinocchios_constraint_dynamics(loaded):
    """At assembled states of a turned platform with random rates and efforts, Orsino's eq 129
    gives Pinocchio's constrained accelerations (two 6-D welds, 6 rows redundant in the plane) to
    1e-11 relative, and the platform's angular acceleration is rz's."""
    rng = np.random.default_rng(0)
    for pose in POSES:
        q, qd = assembled(loaded.mechanism, pose, rng.normal(size=3))
        tau = rng.normal(size=3) * 0.5
        ours = loaded.mechanism.forward(q, qd, tau)
        expected, data = pinocchio_forward(loaded, q, qd, tau)
        assert np.abs(loaded.pinocchio_q(ours) - expected).max() <= 1e-11 * np.abs(expected).max()
        platform = pin.getFrameAcceleration(loaded.model, data, loaded.model.getFrameId("c1_ee"), pin.LOCAL_WORLD_ALIGNED)
        assert abs(platform.angular[2] - ours[2]) <= 1e-11 * np.abs(expected).max()


def test_inverse_dynamics_efforts_give_the_platform_motion_in_pinocchio(loaded):
    """The efforts of eqs 130-140 for a platform acceleration (translation and turn), applied in
    Pinocchio's constraint dynamics, give back that acceleration: the tip frame's classical linear
    acceleration and its angular acceleration about z."""
    rng = np.random.default_rng(1)
    model = loaded.model
    for pose in POSES:
        qd_sharp, qdd_sharp = rng.normal(size=3), rng.normal(size=3)
        q, _ = assembled(loaded.mechanism, pose, qd_sharp)
        tau, qd, _ = loaded.mechanism.inverse(q, qd_sharp, qdd_sharp)
        _, data = pinocchio_forward(loaded, q, qd, tau)
        frame = model.getFrameId("c1_ee")
        linear = pin.getFrameClassicalAcceleration(model, data, frame, pin.LOCAL_WORLD_ALIGNED).linear
        angular = pin.getFrameAcceleration(model, data, frame, pin.LOCAL_WORLD_ALIGNED).angular
        np.testing.assert_allclose([linear[0], linear[1], angular[2]], qdd_sharp, atol=1e-10)


def test_free_motion_agrees_with_pinocchio(loaded):
    """Falling and turning for 0.1 s from a turned pose with the platform spinning at 2 rad/s (RK4,
    1 ms, no stabilisation), Orsino's 3-RRR and Pinocchio's constrained dynamics follow the same
    joint trajectory to 1e-8 rad (each moves by about 1e-8 when the step is halved: RK4's own
    error on two coordinate sets); the platform turns by more than 0.3 rad."""
    mech, model = loaded.mechanism, loaded.model
    q0, qd0 = assembled(mech, POSES[1], [0.0, 0.0, 2.0])
    orsino = simulate(mech, q0, qd0, lambda *_: np.zeros(3), 0.1, 1e-3).telemetry.q
    plant = ConstraintDynamicsPlant(model, loaded.constraints, [], accuracy=1e-14)
    pinocchio = run_plant(plant, loaded.pinocchio_q(q0), loaded.pinocchio_q(qd0), 0.1, 1e-3, "rkmk4").telemetry.q
    assert np.abs(orsino[-1, 2] - orsino[0, 2]) > 0.3
    assert max(np.abs(p - loaded.pinocchio_q(o)).max() for p, o in zip(pinocchio, orsino)) < 1e-8


def test_computed_torque_on_the_angle_follows_its_closed_form(loaded):
    """The platform law (eq 190, lambda = 40, exact model, evaluated at every RK4 stage) on the
    rotating platform's coordinates, a 2 cm circle in (x, y) with rz held at 0.2 rad, from rest
    5 mm and 0.05 rad off: every coordinate's error follows the critically damped closed form
    ``e(t) = (e0 + (edot0 + lambda e0) t) exp(-lambda t)`` to 1e-7 (m, rad) over 0.3 s."""
    mech, lam = loaded.mechanism, 40.0
    reference = CircleReference(np.array([0.0, 0.0, 0.2]), 0.02, 10.0)
    start, rates, _ = reference(0.0)
    q0, _ = assembled(mech, start + np.array([0.005, 0.0, -0.05]), np.zeros(3))
    control = PlatformControl(mech, reference, lam)
    tel = track(mech, control, q0, 0.3, 2e-3, None).telemetry
    e = control.sliding_variables(tel.t, tel.q, tel.v)[0]
    e0, edot0 = start - q0[:3], rates
    closed_form = (e0 + np.outer(tel.t, edot0 + lam * e0)) * np.exp(-lam * tel.t)[:, None]
    assert np.abs(e - closed_form).max() < 1e-7


def test_a_rotating_platform_on_a_base_body_is_refused(loaded):
    """The base-body model (free_base) reads platform translations only: the angle is named."""
    from freefloat.parallel.free_base import BaseBody, FloatingMechanism

    with pytest.raises(FreefloatError, match="include its angle \\('rz'\\); a mechanism on a base body takes"):
        FloatingMechanism(loaded, CLOSURE, BaseBody("fixed"))


def test_a_rotating_platform_runs_on_the_numpy_core(loaded):
    """P != 0 has no compiled core (its closure residual lacks P q#), so every call is the numpy
    reference."""
    assert loaded.mechanism.rotates and loaded.mechanism.core is None


@pytest.mark.parametrize(("edit", "message"), [
    (lambda s: s.replace('coordinates = ["x", "y", "rz"]', 'coordinates = ["x", "y"]'),
     ("'closures\\[0\\].kind' is a weld; tip-to-tip mechanisms take point or planar revolute closures, or weld "
      "closures of a platform whose angle 'rz'")),
    (lambda s: s.replace('kind = "weld"', 'kind = "point"'),
     "'platform.coordinates' has 'rz', the platform's angle, but 'closures\\[0\\].kind' is point"),
    (lambda s: s.replace('coordinates = ["x", "y", "rz"]', 'coordinates = ["x", "rz", "rz"]'),
     "'platform.coordinates' must be a list of x, y, z \\(and at most one 'rz'"),
])
def test_bad_rotating_platform_files_name_the_key(tmp_path, edit, message):
    """A weld without the platform angle, the angle with point closures, two angles: named errors."""
    (tmp_path / "three_rrr.urdf").write_text((REPO / "urdf" / "three_rrr.urdf").read_text())
    (tmp_path / "m.toml").write_text(edit(CLOSURE.read_text()))
    with pytest.raises(FreefloatError, match=message):
        load_closed_chain(tmp_path / "m.toml")


def test_a_tip_frame_out_of_the_plane_is_named(tmp_path):
    """A welded tip frame rolled about x (its z axis no longer N's) cannot carry the angle: named."""
    urdf = (REPO / "urdf" / "three_rrr.urdf").read_text()
    start = urdf.index('<joint name="c2_ee_fixed"')
    origin = urdf.index('rpy="', start)
    end = urdf.index('"', origin + 5)
    (tmp_path / "three_rrr.urdf").write_text(urdf[:origin] + 'rpy="0.3 0 0' + urdf[end:])
    (tmp_path / "m.toml").write_text(CLOSURE.read_text())
    with pytest.raises(FreefloatError, match="frame 'c2_ee' has its z axis along .* need N's z axis"):
        load_closed_chain(tmp_path / "m.toml")
