"""The 5R by Orsino's coupling against Pinocchio's constrained dynamics, and its constraints."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import FreefloatError
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar

from .loops import simulate
from .test_serial import pinocchio_chain

P = FiveBarParameters()


@pytest.fixture(scope="module")
def mech():
    return five_bar(P)


def assembled(mech, point):
    return mech.assemble(np.asarray(point, float), elbow_guess(P, point))


def pinocchio_five_bar(mech):
    """Both chains in one fixed-base model and a 3-D point constraint between their tips."""
    model = pin.Model()
    model.gravity = pin.Motion(mech.chains[0].gravity, np.zeros(3))
    tips = []
    for chain in mech.chains:
        model = _append(model, pinocchio_chain(chain))
        tip = chain.link[-1].copy()  # B_nu in the last joint's frame, then the tip point in B_nu
        tip[:3, 3] = tip[:3, :3] @ chain.tip_point + tip[:3, 3]
        tips.append((model.njoints - 1, pin.SE3(tip)))
    cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, tips[0][0], tips[0][1], tips[1][0], tips[1][1],
                                  pin.ReferenceFrame.LOCAL)
    return model, cm


def _append(model, single):
    """Copy the joints and bodies of a chain model (attached to the universe) into ``model``."""
    parent_map = {0: 0}
    for j in range(1, single.njoints):
        jid = model.addJoint(parent_map[single.parents[j]], single.joints[j], single.jointPlacements[j], f"{single.names[j]}_{model.njoints}")
        model.appendBodyToJoint(jid, single.inertias[j], pin.SE3.Identity())
        parent_map[j] = jid
    return model


def test_constraint_complement_annihilates_a(mech):
    """A C = 0 at assembled configurations of the workspace (eq 121)."""
    for point in ([0.07, 0.17], [0.0, 0.2], [-0.05, 0.12]):
        q = assembled(mech, point)
        A, _, C, *_ = mech.terms(q, np.zeros(6))
        np.testing.assert_allclose(A @ C, 0.0, atol=1e-12)


def test_forward_dynamics_match_pinocchio_constraint_dynamics(mech):
    """Joint accelerations of the coupled model equal Pinocchio's constraintDynamics (loop-closure contact)."""
    model, cm = pinocchio_five_bar(mech)
    data = model.createData()
    cms = [cm]
    cds = [cm.createData()]
    pin.initConstraintDynamics(model, data, cms, cds)
    rng = np.random.default_rng(0)
    for point in ([0.07, 0.17], [0.0, 0.2], [-0.05, 0.12]):
        q = assembled(mech, point)
        _, _, C, *_ = mech.terms(q, np.zeros(6))
        qd = C @ rng.normal(size=2)
        tau = rng.normal(size=2) * 0.05
        ours = mech.forward(q, qd, tau)
        q4, v4 = q[2:], qd[2:]
        tau4 = mech.selection()[2:] @ tau
        settings = pin.ProximalSettings(1e-14, 1e-12, 50)
        ddq = pin.constraintDynamics(model, data, q4, v4, tau4, cms, cds, settings)
        np.testing.assert_allclose(ours[2:], ddq, atol=1e-8 * max(1.0, np.abs(ddq).max()))


def test_inverse_dynamics_efforts_reproduce_the_platform_acceleration(mech):
    """Efforts from the inverse dynamics, fed to the forward dynamics, give the asked platform acceleration."""
    q = assembled(mech, [0.07, 0.17])
    tau, qd, qdd = mech.inverse(q, np.array([0.1, -0.2]), np.array([2.0, 1.0]))
    np.testing.assert_allclose(mech.forward(q, qd, tau)[:2], [2.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(qdd[:2], [2.0, 1.0])


def test_out_of_reach_pose_cannot_be_assembled():
    """A point farther than l1 + l2 from a base joint fails naming the point."""
    with pytest.raises(FreefloatError, match="out of reach"):
        elbow_guess(P, np.array([0.0, 0.4]))


def test_failed_assembly_names_the_residual(mech):
    """Newton from a hopeless guess at an unreachable point reports the residual."""
    with pytest.raises(FreefloatError, match="cannot assemble.*residual"):
        mech.assemble(np.array([0.0, 0.4]), np.zeros(4), iterations=10)


def test_baumgarte_stabilisation_holds_the_loop_closed(mech):
    """Falling freely for 1 s (RK4, 1 ms), lambda = 100 keeps the loop 10x tighter than no stabilisation."""
    q0 = assembled(mech, [0.07, 0.17])
    zero = lambda t, q, qd: np.zeros(2)  # noqa: E731
    loose = drift(simulate(mech, q0, np.zeros(6), zero, 1.0, 1e-3, baumgarte=0.0))
    held = drift(simulate(mech, q0, np.zeros(6), zero, 1.0, 1e-3, baumgarte=100.0))
    assert held.max() < 0.1 * loose.max() and loose.max() > 1e-7


def test_lambda_one_over_h_makes_euler_diverge_and_rk4_worse(mech):
    """The document's lambda = 1/h: semi-implicit Euler blows up; RK4 drifts more than with lambda = 100."""
    q0 = assembled(mech, [0.07, 0.17])
    zero = lambda t, q, qd: np.zeros(2)  # noqa: E731
    assert simulate(mech, q0, np.zeros(6), zero, 0.3, 1e-3, baumgarte=1e3, integrator="euler").status == "diverged"
    one_over_h = drift(simulate(mech, q0, np.zeros(6), zero, 0.1, 1e-3, baumgarte=1e3))
    moderate = drift(simulate(mech, q0, np.zeros(6), zero, 0.1, 1e-3, baumgarte=100.0))
    assert moderate.max() < 0.1 * one_over_h.max()


def test_rk4_at_0_2_ms_keeps_the_loop_closed_below_1e_9_m(mech):
    """RK4 at 0.2 ms with lambda = 100 keeps |qbar| below 1e-9 m while the 5R falls for 0.1 s."""
    run = simulate(mech, assembled(mech, [0.07, 0.17]), np.zeros(6), lambda *_: np.zeros(2), 0.1, 2e-4, baumgarte=100.0)
    assert drift(run).max() < 1e-9


def test_lambda_one_over_h_is_best_with_explicit_euler(mech):
    """With explicit Euler (the old rate moves q) lambda = 1/h holds the loop tighter than 100 or 0:
    the document's rule fails only for the semi-implicit method."""
    q0 = assembled(mech, [0.07, 0.17])
    zero = lambda t, q, qd: np.zeros(2)  # noqa: E731
    worst = {lam: drift(simulate(mech, q0, np.zeros(6), zero, 0.1, 1e-3, baumgarte=lam, integrator="explicit_euler")).max()
             for lam in (0.0, 100.0, 1e3)}
    assert worst[1e3] < 0.5 * worst[100.0] < 0.5 * worst[0.0]


def drift(run) -> np.ndarray:
    """The loop-closure residual of every recorded step of a completed run, m."""
    assert run.status == "completed", run.message
    return run.telemetry.drift


@pytest.mark.parametrize("field, value, message", [("l1", -0.12, "l1' must be > 0"),
                                                   ("m2", -0.1, "m2' must be >= 0"),
                                                   ("lg1", float("nan"), "lg1' must be finite")])
def test_parameters_no_mechanism_has_are_refused_naming_the_field(field, value, message):
    """A negative length or mass, or a NaN, in FiveBarParameters is refused naming the field."""
    from dataclasses import replace

    from freefloat.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match=f"FiveBarParameters.{message}"):
        five_bar(replace(FiveBarParameters(), **{field: value}))
