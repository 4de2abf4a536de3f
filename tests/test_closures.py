"""Loop closures on any tree (freefloat.dynamics.closures) against Pinocchio and finite differences."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import example, given, settings

from freefloat.dynamics.closures import KINDS, Closure, closing_impulse, closure_kind, kinematics, solve, stacked
from freefloat.robot.conventions import momentum_about_origin

from .conftest import random_robots, random_state, random_urdf, robot_from_case

PROXIMAL = pin.ProximalSettings(1e-14, 1e-12, 200)
#: Damping of Pinocchio's explicit-Jacobian impulseDynamics (rows may be redundant).
DAMPING = 1e-12
PINOCCHIO_TYPES = {"point": pin.ContactType.CONTACT_3D, "weld": pin.ContactType.CONTACT_6D}


def closed_case(factory, case, kind: str, offset: float = 0.0):
    """A random tree, a random state, and a closure of ``kind`` between two random bodies whose
    frames coincide at that state (shifted by ``offset`` m along frame 2's x when asked)."""
    robot, rng = robot_from_case(factory, case)
    model, data = robot.model, robot.model.createData()
    q, v = random_state(robot, rng)
    pin.forwardKinematics(model, data, q)
    bodies = rng.choice(np.arange(1, model.njoints), 2, replace=False)
    j1, j2 = int(bodies[0]), int(bodies[1])
    placement1 = pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-0.3, 0.3, 3))
    placement2 = data.oMi[j2].actInv(data.oMi[j1] * placement1) * pin.SE3(np.eye(3), np.array([offset, 0.0, 0.0]))
    return robot, Closure("c", KINDS[kind], j1, placement1, j2, placement2), q, v, rng


def consistent(model, closure, q, v):
    """``v`` projected on the velocities the closure allows at ``q``."""
    data = model.createData()
    kinematics(model, data, q, v)
    J = stacked([closure], model, data)[1]
    return v - np.linalg.pinv(J) @ (J @ v)


def pinocchio_constraints(model, closure):
    """Pinocchio's constraint models for ``closure``: one 3-D or 6-D contact; a revolute closure as
    two point contacts half a metre apart on the hinge (the same motions allowed)."""
    def contact(kind, shift):
        lift = pin.SE3(np.eye(3), np.array([0.0, 0.0, shift]))
        return pin.RigidConstraintModel(PINOCCHIO_TYPES[kind], model, closure.joint1, closure.placement1 * lift,
                                        closure.joint2, closure.placement2 * lift, pin.LOCAL)
    if closure.kind.name == "revolute":
        return [contact("point", 0.0), contact("point", 0.5)]
    return [contact(closure.kind.name, 0.0)]


def constraint_dynamics(model, q, v, tau, constraints):
    data, datas = model.createData(), [c.createData() for c in constraints]
    pin.initConstraintDynamics(model, data, constraints, datas)
    return pin.constraintDynamics(model, data, q, v, tau, constraints, datas, PROXIMAL)


@pytest.mark.parametrize("kind", ["point", "weld", "revolute"])
@settings(max_examples=12, deadline=None)
@given(case=random_robots(min_links=2, max_links=7))
def test_accelerations_meet_the_constrained_equations(tmp_path_factory, kind, case):
    """On random trees with a random closure between two bodies, the accelerations meet the
    equations themselves to 1e-12 (relative): ``J a + gamma = 0``, and ``M a + h - tau`` is a
    closure force ``J^T lambda`` (900 random cases: 5e-13 and 3e-14 at worst)."""
    robot, closure, q, v, rng = closed_case(tmp_path_factory, case, kind)
    model, data = robot.model, robot.model.createData()
    v = consistent(model, closure, q, v)
    tau = rng.normal(size=model.nv)
    a = solve(model, data, q, v, tau, [closure]).acceleration
    kinematics(model, data, q, v)
    _, J, gamma = stacked([closure], model, data)
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    unbalanced = M @ a + pin.rnea(model, data, q, v, np.zeros(model.nv)) - tau
    force = np.linalg.lstsq(J.T, unbalanced, rcond=None)[0]
    assert np.abs(J @ a + gamma).max() <= 1e-12 * max(1.0, np.abs(gamma).max(), np.abs(J).max() * np.abs(a).max())
    assert np.abs(unbalanced - J.T @ force).max() <= 1e-12 * max(1.0, np.abs(tau).max(), np.abs(M @ a).max())


@pytest.mark.parametrize("kind", ["point", "weld", "revolute"])
@settings(max_examples=12, deadline=None)
@given(case=random_robots(min_links=2, max_links=7))
def test_accelerations_equal_pinocchio_constraint_dynamics(tmp_path_factory, kind, case):
    """The same cases against Pinocchio's constraintDynamics (a revolute closure: two point
    contacts on its hinge): equal to 1e-9 relative, or, where the two differ more (nearly singular
    or fully rigid loops: 900 random cases gave up to 3.6e-10; one loop that leaves three joints
    almost no motion 1.3e-8), still within 1e-6 and with ours meeting the closure's acceleration
    rows ``J a + gamma = 0`` at least as closely as Pinocchio's proximal solver does."""
    robot, closure, q, v, rng = closed_case(tmp_path_factory, case, kind)
    model = robot.model
    v = consistent(model, closure, q, v)
    tau = rng.normal(size=model.nv)
    ours = solve(model, model.createData(), q, v, tau, [closure]).acceleration
    reference = constraint_dynamics(model, q, v, tau, pinocchio_constraints(model, closure))
    assert_equal_to_pinocchio_or_closer(model, closure, q, v, ours, reference, 1e-9)


def assert_equal_to_pinocchio_or_closer(model, closure, q, v, ours, reference, tolerance):
    """Accelerations ``ours`` equal Pinocchio's ``reference`` to ``tolerance`` relative, or, on a
    nearly rigid or ill-conditioned loop where the two solves part by the conditioning (seen: 1.3e-8
    and 2.2e-9 relative, Pinocchio's proximal solver stopping short or both rows met to 1e-12),
    within 1e-6 and meeting the closure's acceleration rows ``J a + gamma = 0`` as closely as
    Pinocchio's does, or to 1e-11 of their scale."""
    scale = max(1.0, np.abs(reference).max())
    difference = np.abs(ours - reference).max()
    if difference <= tolerance * scale:
        return
    assert difference <= 1e-6 * scale
    data = model.createData()
    kinematics(model, data, q, v)
    _, J, gamma = stacked([closure], model, data)
    rows_scale = max(1.0, np.abs(gamma).max(), np.abs(J).max() * np.abs(ours).max())
    assert np.abs(J @ ours + gamma).max() <= max(np.abs(J @ reference + gamma).max(), 1e-11 * rows_scale)


@pytest.mark.parametrize("kind", ["point", "weld", "revolute"])
@settings(max_examples=10, deadline=None)
@given(case=random_robots(min_links=2, max_links=7))
@example(case=(1994051, random_urdf(np.random.default_rng(1994051), 2)))  # a point closure across two joints
def test_closure_forces_are_internal(tmp_path_factory, kind, case):
    """Without gravity, under any joint torques and at any state (the loop open or not, Baumgarte
    on), the momentum of a floating tree with a closure between two bodies does not change: its
    rate at the constrained acceleration (Pinocchio's centroidal momentum time variation) is zero
    to 1e-10 of the torques' scale."""
    robot, closure, q, v, rng = closed_case(tmp_path_factory, case, kind, offset=0.02)
    model = robot.model
    tau = np.concatenate((np.zeros(robot.n_base), rng.normal(size=model.nv - robot.n_base)))
    a = solve(model, model.createData(), q, v, tau, [closure], 10.0).acceleration
    data = model.createData()
    pin.computeCentroidalMomentumTimeVariation(model, data, q, v, a)
    assert np.abs(data.dhg.vector).max() <= 1e-10 * max(1.0, np.abs(tau).max(), np.abs(a).max())


@pytest.mark.parametrize("kind", ["point", "weld", "revolute"])
@settings(max_examples=8, deadline=None)
@given(case=random_robots(min_links=2, max_links=6))
def test_jacobian_and_drift_are_the_rows_derivatives(tmp_path_factory, kind, case):
    """Along q(t) = q (+) (v t + a t^2 / 2), the rows' rate J v changes at J a + gamma (central
    differences, 1e-6 relative), and the position rows change at their Jacobian rows."""
    robot, closure, q, v, rng = closed_case(tmp_path_factory, kind=kind, case=case, offset=0.05)
    model, data = robot.model, robot.model.createData()
    a, h = rng.normal(size=model.nv), 1e-5

    def at(t):
        qt = pin.integrate(model, q, v * t + 0.5 * a * t * t)
        vt = v + a * t  # q(t)'s rate to O(t^2) on the base's group too: ad_v v = 0
        kinematics(model, data, qt, vt)
        e, J, gamma = stacked([closure], model, data)
        return e, J, gamma, vt

    e0, J0, gamma0, _ = at(0.0)
    rate = [J @ vt for _, J, _, vt in (at(h), at(-h))]
    position = [e for e, *_ in (at(h), at(-h))]
    scale = max(1.0, np.abs(J0 @ a + gamma0).max())
    assert np.abs((rate[0] - rate[1]) / (2 * h) - (J0 @ a + gamma0)).max() <= 1e-6 * scale
    assert np.abs((position[0][:3] - position[1][:3]) / (2 * h) - J0[:3] @ v).max() <= 1e-6 * max(1.0, np.abs(J0 @ v).max())


@pytest.mark.slow
def test_baumgarte_closes_a_point_gap_as_a_critically_damped_system():
    """The dual-arm satellite's two tool frames joined by a point closure opened by 1 cm, at rest:
    the gap closes as (1 + beta t) exp(-beta t) under the constrained dynamics (beta = 20/s),
    integrated at 0.1 ms (to 1e-6 of the gap)."""
    from freefloat import load_robot
    from freefloat.dynamics.integrators import make_integrator

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "dual_arm_satellite.urdf", visuals=False)
    model, data = robot.model, robot.model.createData()
    q = pin.neutral(model)
    q[7:] = np.random.default_rng(3).uniform(-1.0, 1.0, model.nq - 7)
    pin.framesForwardKinematics(model, data, q)
    left, right = (model.frames[model.getFrameId(name)] for name in ("left_tool0", "right_tool0"))
    gap = pin.SE3(np.eye(3), np.array([0.01, 0.0, 0.0]))
    placement2 = data.oMi[right.parentJoint].actInv(data.oMi[left.parentJoint] * left.placement * gap)
    closure = Closure("c", KINDS["point"], left.parentJoint, left.placement, right.parentJoint, placement2)
    beta, dt, steps = 20.0, 1e-4, 1000
    step = make_integrator("rkmk4", model)
    v, gaps = np.zeros(model.nv), []
    for _ in range(steps + 1):
        kinematics(model, data, q, v)
        gaps.append(stacked([closure], model, data, drift=False)[0])
        q, v = step.advance(lambda qs, vs: solve(model, data, qs, vs, np.zeros(model.nv), [closure], beta).acceleration,
                            q, v, dt)
    t = dt * np.arange(steps + 1)
    expected = np.outer((1 + beta * t) * np.exp(-beta * t), gaps[0])
    assert np.abs(np.array(gaps) - expected).max() <= 1e-6 * 0.01


@pytest.mark.parametrize("kind", ["point", "weld", "revolute"])
@settings(max_examples=10, deadline=None)
@given(case=random_robots(min_links=2, max_links=7))
def test_closing_impulse_stops_the_gap_and_keeps_momentum(tmp_path_factory, kind, case):
    """The closing impulse leaves J v+ = 0 and the momentum [P; L] of the whole tree unchanged
    (an internal impulse), to 1e-11."""
    robot, closure, q, v, _ = closed_case(tmp_path_factory, case, kind)
    model, data = robot.model, robot.model.createData()
    hit = closing_impulse(model, data, q, v, [closure])
    kinematics(model, data, q, hit.v_after)
    J = stacked([closure], model, data, drift=False)[1]
    before, after = (momentum_about_origin(model, model.createData(), q, w) for w in (v, hit.v_after))
    assert np.abs(J @ hit.v_after).max() <= 1e-11 * max(1.0, hit.gap_speed_before)
    assert np.abs(after - before).max() <= 1e-11 * max(1.0, np.abs(before).max())


@settings(max_examples=10, deadline=None)
@given(case=random_robots(min_links=2, max_links=7))
@example(case=(13483, random_urdf(np.random.default_rng(13483), 5)))  # redundant rows: damping moved v+ by 1.9e-9
def test_closing_impulse_equals_pinocchio_impulse_dynamics(tmp_path_factory, case):
    """Two closures closed at once (often with redundant rows on these small trees) equal Pinocchio's
    impulseDynamics on the stacked constraint Jacobian (its explicit-Jacobian form, damped by DAMPING, to the share the damping may move it: :func:`_damping_share`), and a contact with the inertial frame equals its
    constraint-model form (Pinocchio 4.1's impulseDynamics with constraint models acts on the
    first body only, so loop closures are checked through the first form)."""
    robot, weld, q, v, rng = closed_case(tmp_path_factory, case, "weld")
    model, data = robot.model, robot.model.createData()
    pin.forwardKinematics(model, data, q)
    j = int(rng.integers(1, model.njoints))
    ground = Closure("g", KINDS["point"], 0, data.oMi[j] * pin.SE3.Identity(), j, pin.SE3.Identity())
    both = closing_impulse(model, data, q, v, [weld, ground])
    kinematics(model, data, q, v)
    J = stacked([weld, ground], model, data, drift=False)[1]
    reference = model.createData()
    pin.crba(model, reference, q)
    explicit = pin.impulseDynamics(model, reference, q, v, J, 0.0, DAMPING)  # damped: rows may be redundant
    assert np.abs(both.v_after - explicit).max() <= _damping_share(reference.M, J, v) + 1e-12 * max(1.0, np.abs(v).max())
    contact = [pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, j, pin.SE3.Identity(), pin.LOCAL)]
    datas, pdata = [c.createData() for c in contact], model.createData()
    pin.initConstraintDynamics(model, pdata, contact, datas)
    pinocchio = pin.impulseDynamics(model, pdata, q, v, contact, datas, 0.0, PROXIMAL)
    ours = closing_impulse(model, data, q, v, [ground]).v_after
    assert np.abs(ours - pinocchio).max() <= 1e-9 * max(1.0, np.abs(v).max())  # its proximal mu 1e-12


def _damping_share(mass: np.ndarray, jacobian: np.ndarray, v: np.ndarray) -> float:
    """How far Pinocchio's damped impulse (``(A + mu I) lambda = -J v``, A = J M^-1 J^T, mu =
    DAMPING) may put ``v+`` from the exact one: each eigen-component of lambda shrinks by
    mu / (sigma + mu) <= mu / sigma, so |dv| <= |M^-1 J^T| mu |lambda| / sigma, sigma the least
    eigenvalue of A above its redundant rows' round-off (1e-10 sigma_max), lambda the least-norm
    impulse; ten times that (upper triangle of M filled as crba leaves it)."""
    mass = np.triu(mass) + np.triu(mass, 1).T
    m_inv_jt = np.linalg.solve(mass, jacobian.T)
    sigma = np.linalg.eigvalsh(jacobian @ m_inv_jt)
    kept = sigma[sigma > 1e-10 * sigma.max()]
    impulse = np.linalg.lstsq(jacobian @ m_inv_jt, -jacobian @ v, rcond=1e-10)[0]
    return 10.0 * np.linalg.norm(m_inv_jt, 2) * DAMPING * np.linalg.norm(impulse) / kept.min()


def test_a_planar_loop_closed_by_a_weld_has_redundant_rows():
    """Three parallel revolute joints closed back on the fixed frame by a weld: 3 of the 6 rows are
    redundant (rank 3), and the accelerations still equal constraintDynamics."""
    model = pin.Model()
    parent = 0
    for i in range(4):
        parent = model.addJoint(parent, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([0.5 if i else 0.0, 0, 0])), f"j{i}")
        model.appendBodyToJoint(parent, pin.Inertia(1.0 + i, np.array([0.25, 0, 0]), np.diag([0.01, 0.02, 0.03])),
                                pin.SE3.Identity())
    data = model.createData()
    q = np.array([0.3, 1.2, -0.7, 0.4])
    pin.forwardKinematics(model, data, q)
    tip = pin.SE3(np.eye(3), np.array([0.5, 0, 0]))
    weld = Closure("w", KINDS["weld"], 0, data.oMi[4] * tip, 4, tip)
    v = consistent(model, weld, q, np.array([1.0, -0.5, 0.3, 0.2]))
    tau = np.array([0.5, -1.0, 0.2, 0.7])
    ours = solve(model, data, q, v, tau, [weld])
    constraint = [pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, model, 4, tip, pin.LOCAL)]
    reference = constraint_dynamics(model, q, v, tau, constraint)
    assert ours.rank == 3 and np.abs(ours.acceleration - reference).max() <= 1e-10


def test_closure_kinds_resolve_names_and_aliases():
    """``frame`` (the mechanisms' closure files) is a weld; an unknown name is None."""
    assert closure_kind("frame") is KINDS["weld"] and closure_kind("revolute").size == 5
    assert closure_kind("hinge") is None
