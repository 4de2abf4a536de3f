"""A robot tree with actuator inertias and joint friction (dynamics.models.friction, plants.tree):
accelerations against Pinocchio's CRBA and RNEA, and the energy balance of a run."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import simpson

from freefloat import InvalidArgument
from freefloat.dynamics.friction import JointFriction
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import ExactModel
from freefloat.dynamics.models.friction import WithFriction
from freefloat.dynamics.plants.tree import TreePlant
from freefloat.dynamics.simulation import run, run_plant
from freefloat.robot.loading import load_robot

from .conftest import REPO

pytestmark = pytest.mark.filterwarnings("ignore")  # the planar robot's printed inertias


@pytest.fixture(scope="module")
def robot():
    """The two-arm planar robot with rotors on its joints (armature 0.01-0.05 kg m^2)."""
    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    robot.model.armature[robot.n_base:] = np.linspace(0.01, 0.05, robot.n_joints)
    return robot


def friction_of(robot, coulomb=0.05):
    nv, n = robot.model.nv, robot.n_base
    return JointFriction(np.r_[np.zeros(n), np.full(nv - n, 0.02)], np.r_[np.zeros(n), np.full(nv - n, coulomb)])


def state(robot, seed=0):
    rng = np.random.default_rng(seed)
    q = pin.randomConfiguration(robot.model, -np.ones(robot.model.nq), np.ones(robot.model.nq))
    return q, 0.2 * rng.normal(size=robot.model.nv)


def test_accelerations_equal_crba_and_rnea_with_the_same_terms(robot):
    """ABA with the armature, under tau - f(v), equals M^-1 (tau - f(v) - b) from CRBA (armature on
    its diagonal) and RNEA, to round-off."""
    model, friction = WithFriction(ExactModel(robot), friction_of(robot)), friction_of(robot)
    data = robot.model.createData()
    for seed in range(5):
        q, v = state(robot, seed)
        tau = np.r_[np.zeros(robot.n_base), np.random.default_rng(seed).normal(size=robot.n_joints)]
        M = pin.crba(robot.model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        expected = np.linalg.solve(M, tau - friction.force(v) - pin.rnea(robot.model, data, q, v, np.zeros(robot.model.nv)))
        np.testing.assert_allclose(model.acceleration(q, v, tau), expected, atol=1e-10 * np.abs(expected).max())
        H, c = model.joint_space_at(q, v)
        a = model.acceleration(q, v, tau)
        np.testing.assert_allclose(H @ a[robot.n_base:] + c, tau[robot.n_base:], atol=1e-9 * np.abs(tau).max())


def test_a_tumbling_run_loses_what_friction_dissipates(robot):
    """0.5 s torque-free from a random state (Python loop: the compiled one has no friction; RK4
    at 1 ms): 1/2 v^T M v (armature included) falls by the work of friction (Simpson's rule on the
    recorded rates) to 1e-8 of it (7.6e-10 measured), and the momentum is kept (internal forces) to 1e-11."""
    friction = friction_of(robot)
    q0, v0 = state(robot, 1)
    result = run(robot, q0, v0, 0.5, 1e-3, make_integrator("rkmk4", robot.model), WithFriction(ExactModel(robot), friction))
    tel, data = result.telemetry, robot.model.createData()
    assert result.backend == "python" and result.status == "completed"
    kinetic = np.array([pin.computeKineticEnergy(robot.model, data, q, v) for q, v in zip(tel.q, tel.v)])
    lost = simpson(friction.power(tel.v), x=tel.t)
    assert lost > 1e-3 * kinetic[0]
    assert abs(kinetic[0] - kinetic[-1] - lost) < 1e-8 * lost
    assert np.abs(tel.momentum - tel.momentum[0]).max() < 1e-11 * np.abs(tel.momentum[0]).max()


def test_tree_plant_follows_the_robot_loop(robot):
    """The same robot as a TreePlant in run_plant, under held joint torques, follows run()'s
    Python loop step for step (the same integrator on the same group)."""
    from .loops import Law

    model = WithFriction(ExactModel(robot), friction_of(robot))
    q0, v0 = state(robot, 2)
    torques = lambda t, q, v: np.sin(10.0 * t + np.arange(robot.n_joints))
    ours = run_plant(TreePlant(robot, model), q0, v0, 0.05, 1e-3, "rkmk4", Law(torques)).telemetry
    theirs = run(robot, q0, v0, 0.05, 1e-3, make_integrator("rkmk4", robot.model), model, Law(torques)).telemetry
    np.testing.assert_allclose(ours.q, theirs.q, atol=1e-12)
    np.testing.assert_allclose(ours.v, theirs.v, atol=1e-10)


def test_friction_on_the_base_or_of_the_wrong_size_is_refused(robot):
    """Friction on a floating base's coordinates, or for another nv: InvalidArgument naming it."""
    nv = robot.model.nv
    with pytest.raises(InvalidArgument, match="floating base"):
        WithFriction(ExactModel(robot), JointFriction(np.ones(nv), np.zeros(nv)))
    with pytest.raises(InvalidArgument, match="nv = "):
        WithFriction(ExactModel(robot), JointFriction(np.ones(2), np.zeros(2)))
    with pytest.raises(InvalidArgument, match="distinct joint velocity indices"):
        TreePlant(robot, ExactModel(robot), actuated=[0])
