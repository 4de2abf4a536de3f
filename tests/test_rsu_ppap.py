"""The 2RSU+PPaP: Orsino's model against Pinocchio's constrained dynamics on the same URDF."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import FreefloatError
from freefloat.dynamics.plants import ConstraintDynamicsPlant
from freefloat.dynamics.simulation import run_plant
from freefloat.parallel.rsu_ppap import (
    CLOSURE,
    assembly_guess,
    load_data,
    load_rsu_ppap,
    reference_path,
    rsu_ppap_urdf,
)
from freefloat.robot.builders import urdf_xml

from .loops import Law, simulate

DATA = load_data()
HOME = np.array(DATA["home"])


@pytest.fixture(scope="module")
def loaded():
    return load_rsu_ppap()


@pytest.fixture(scope="module")
def pinocchio_side(loaded):
    model, cms = loaded.model, loaded.constraints
    data, cds = model.createData(), [c.createData() for c in cms]
    pin.initConstraintDynamics(model, data, cms, cds)
    settings = pin.ProximalSettings(1e-14, 1e-12, 100)

    def accelerations(q, qd, tau):
        tau_pin = np.zeros(model.nv)
        for j, t in zip(loaded.actuated, tau):
            tau_pin[model.idx_vs[j]] = t
        return pin.constraintDynamics(model, data, q, qd, tau_pin, cms, cds, settings).copy()
    return accelerations


def assembled(loaded, offset, rates=(0.0, 0.0, 0.0)):
    q_sharp = HOME + np.asarray(offset)
    q = loaded.mechanism.assemble(q_sharp, assembly_guess(DATA, q_sharp))
    return q, loaded.mechanism.velocity_map(q) @ np.asarray(rates)


def test_committed_urdf_is_what_the_data_generates():
    """urdf/rsu_ppap.urdf is exactly the spanning tree rsu_ppap.data.toml describes."""
    assert urdf_xml(rsu_ppap_urdf(DATA)) == (CLOSURE.parent / "rsu_ppap.urdf").read_text()


def test_assembly_closes_every_loop_in_pinocchio(loaded):
    """At an assembled pose the closure frames coincide in Pinocchio's kinematics (6-D and 3-D)."""
    q, _ = assembled(loaded, (0.03, -0.02, 0.04))
    model = loaded.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, loaded.pinocchio_q(q))
    for closure, cm in zip(("rsu1", "rsu2", "ppap"), loaded.constraints):
        a = data.oMi[cm.joint1_id] * cm.joint1_placement
        b = data.oMi[cm.joint2_id] * cm.joint2_placement
        assert np.abs(a.translation - b.translation).max() < 1e-12, closure
        if cm.type == pin.ContactType.CONTACT_6D:
            assert np.abs(pin.log3(a.rotation.T @ b.rotation)).max() < 1e-12, closure
    platform = data.oMf[model.getFrameId("platform")]
    np.testing.assert_allclose(platform.translation, q[:3], atol=1e-12)
    np.testing.assert_allclose(platform.rotation, np.eye(3), atol=1e-12)


def test_velocity_map_satisfies_pinocchios_closure_jacobian(loaded):
    """qdot = C qdot# moves no closure: Pinocchio's constraint Jacobian annihilates it."""
    q, qd = assembled(loaded, (-0.02, 0.03, -0.01), (0.2, -0.1, 0.3))
    model = loaded.model
    data = model.createData()
    cds = [c.createData() for c in loaded.constraints]
    pin.computeJointJacobians(model, data, loaded.pinocchio_q(q))
    for cm, cd in zip(loaded.constraints, cds):
        cm.calc(model, data, cd)
    J = pin.getConstraintsJacobian(model, data, loaded.constraints, cds)
    assert J.shape == (15, model.nv)
    assert np.abs(J @ loaded.pinocchio_q(qd)).max() < 1e-12


def test_forward_dynamics_match_pinocchio_at_random_assembled_states(loaded, pinocchio_side):
    """Orsino's accelerations (eq 129, lambda = 0) equal Pinocchio's constraintDynamics."""
    rng = np.random.default_rng(0)
    for _ in range(10):
        q, qd = assembled(loaded, rng.uniform(-0.05, 0.05, 3), rng.normal(size=3) * 0.3)
        tau = rng.normal(size=3)
        ddq = pinocchio_side(loaded.pinocchio_q(q), loaded.pinocchio_q(qd), tau)
        ours = loaded.pinocchio_q(loaded.mechanism.forward(q, qd, tau))
        assert np.abs(ours - ddq).max() < 1e-10 * np.abs(ddq).max()


def test_inverse_dynamics_returns_the_requested_platform_acceleration(loaded):
    """Efforts from eqs 130-140, fed to the forward dynamics, give back qddot#."""
    q, _ = assembled(loaded, (0.01, 0.02, -0.03))
    qd_sharp, qdd_sharp = np.array([0.1, -0.2, 0.05]), np.array([1.0, 0.5, -2.0])
    tau, qd, _ = loaded.mechanism.inverse(q, qd_sharp, qdd_sharp)
    np.testing.assert_allclose(loaded.mechanism.forward(q, qd, tau)[:3], qdd_sharp, atol=1e-9)


def held(loaded, q0):
    """Actuator efforts ``f(q_a, qd_a)``: PD springs (50 N m/rad or N/m, 1 N m s/rad) about the
    holding efforts at q0, from the actuated joints' coordinates and rates (3,)."""
    mech = loaded.mechanism
    tau0, *_ = mech.inverse(q0, np.zeros(3), np.zeros(3))
    q_a0 = q0[mech.actuated]
    return lambda q_a, qd_a: tau0 - 50.0 * (q_a - q_a0) - 1.0 * qd_a


def test_motion_follows_pinocchio_for_one_second(loaded):
    """From a pushed start with PD-held actuators (efforts held over each step), RK4 at 2 ms, no stabilisation, the two models'
    trajectories stay together to 1e-9 over 1 s (both integrate the same ODE the same way)."""
    q0, qd0 = assembled(loaded, (0.02, -0.03, 0.03), (0.03, -0.03, 0.03))
    mech, h, efforts = loaded.mechanism, 2e-3, held(loaded, q0)
    a = mech.actuated
    qs = simulate(mech, q0, qd0, lambda t, q, qd: efforts(q[a], qd[a]), 1.0, h).telemetry.q
    model = loaded.model
    a_pin = [model.idx_qs[j] for j in loaded.actuated]
    plant = ConstraintDynamicsPlant(model, loaded.constraints, [model.idx_vs[j] for j in loaded.actuated], accuracy=1e-14,
                                    iterations=100)
    law = Law(lambda t, q, v: efforts(q[a_pin], v[a_pin]))
    pinocchio = run_plant(plant, loaded.pinocchio_q(q0), loaded.pinocchio_q(qd0), 1.0, h, "rkmk4", law).telemetry.q
    worst = max(np.abs(q - loaded.pinocchio_q(orsino)).max() for q, orsino in zip(pinocchio, qs))
    assert len(qs) == len(pinocchio) == 501
    assert np.ptp(qs[:, :3], axis=0).max() > 0.01   # it really moved
    assert worst < 1e-9


def test_baumgarte_closes_an_opened_loop(loaded):
    """Started 1e-6 rad off the closure, lambda = 100 brings the loop-closure residual below
    1e-9 m within 0.5 s; the orientation residual (velocity-level term only, as eq 129 prints)
    does not grow."""
    q0, _ = assembled(loaded, (0.02, -0.03, 0.03))
    mech, efforts = loaded.mechanism, held(loaded, q0)
    opened = q0 + np.concatenate((np.zeros(3), np.full(len(q0) - 3, 1e-6)))
    a = mech.actuated
    tel = simulate(mech, opened, np.zeros_like(q0), lambda t, q, qd: efforts(q[a], qd[a]), 0.5, 2e-3,
                   baumgarte=100.0).telemetry
    qs, drift = tel.q, tel.drift
    assert len(qs) == 251
    assert drift[0] > 1e-7
    assert drift[-1] < 1e-9
    start = np.abs(mech.orientation_residual(opened)).max()
    assert np.abs(mech.orientation_residual(qs[-1])).max() <= 1.01 * start


def test_unreachable_pose_is_refused_naming_the_leg():
    """A platform centre out of an RSU leg's reach fails with the leg's name."""
    with pytest.raises(FreefloatError, match="rsu1"):
        assembly_guess(DATA, HOME + np.array([0.0, 0.0, 0.4]))


@pytest.mark.parametrize(("edit", "message"), [
    (lambda s: s.replace("rod_length", "rod_len"), r"unknown \[rsu\] key 'rod_len'; did you mean 'rod_length'\?"),
    (lambda s: s.replace("rod_length = 0.36", ""), r"missing key 'rsu\.rod_length'"),
    (lambda s: s.replace("rod_length = 0.36", 'rod_length = "0.36"'), r"'rsu\.rod_length' must be numeric"),
    (lambda s: s.replace("rod_length = 0.36", "rod_length = -0.36"), r"'rsu\.rod_length' must be a positive number"),
    (lambda s: s.replace("rail = [-0.30, 0.0, 0.05]", "rail = [-0.30, 0.0]"), r"'ppap\.rail' must be finite numbers of shape \(3,\)"),
    (lambda s: s.replace("crank = [[1.0, 0.0, 0.0]", "crank = [[2.0, 0.0, 0.0]"), r"'rsu\.crank' \[0\] must be a unit vector"),
])
def test_bad_data_is_named(tmp_path, edit, message):
    """A missing, non-numeric, non-positive, misshapen or unusable value fails naming the file and key."""
    (tmp_path / "d.toml").write_text(edit((CLOSURE.parent / "rsu_ppap.data.toml").read_text()))
    with pytest.raises(FreefloatError, match=r"d\.toml.*" + message):
        load_data(tmp_path / "d.toml")


def test_batched_inverse_dynamics_drive_the_path(loaded):
    """Efforts for a whole path at once (inverse_trajectory), fed to the forward dynamics point
    by point, give back the path's platform accelerations; the assembled poses close the loops."""
    t = np.linspace(0.0, 1.0, 40)
    x, xd, xdd = reference_path(t, DATA)
    mech = loaded.mechanism
    tau, q = mech.inverse_trajectory(x, xd, xdd, assembly_guess(DATA, x[0]), block=16)
    assert np.abs(mech.constraint(q)).max() < 1e-12
    for i in range(0, len(t), 7):
        qd = mech.velocity_map(q[i]) @ xd[i]
        np.testing.assert_allclose(mech.forward(q[i], qd, tau[i])[:3], xdd[i], atol=1e-9 * np.abs(xdd).max())


def test_angular_constraints_of_the_wrong_width_are_named(loaded):
    """Angular constraints whose P does not have one column per platform coordinate fail, naming P
    and the width the mechanism needs."""
    from dataclasses import replace

    angular = replace(loaded.mechanism.angular, P=np.ones((7, 2)))
    with pytest.raises(FreefloatError, match="angular constraints: P has 2 columns; this mechanism needs 3"):
        replace(loaded.mechanism, angular=angular)