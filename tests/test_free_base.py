"""A parallel mechanism on a moving base (freefloat.parallel.free_base): the plant meets its closures
and equals an independent KKT solve, conserves momentum at zero gravity, the controller reads the
base frame, and a very heavy base behaves as the ground."""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from freefloat import FreefloatError, InvalidArgument
from freefloat.dynamics.closures import closure_drift
from freefloat.dynamics.plants import ConstraintDynamicsPlant
from freefloat.dynamics.simulation import run_plant
from freefloat.parallel.closed_chain import read_closures
from freefloat.parallel.five_bar import TRUE_PARAMETERS, five_bar
from freefloat.parallel.free_base import BaseBody, BaseFrameControl, FloatingMechanism, track
from freefloat.parallel.platform_control import CircleReference
from freefloat.parallel.registry import REGISTRY
from freefloat.parallel.sliding_mode import PlatformControl, printed_gains
from freefloat.paths import URDF_DIR

#: (mechanism, base kind) pairs the tests draw from, with the platform point about which states are drawn.
CASES = {("five_bar", "planar"): np.array([0.0, 0.17]), ("five_bar", "free"): np.array([0.0, 0.17]),
         ("rsu_ppap", "free"): np.array([0.0, 0.0, 0.40]), ("rsu_ppap", "planar"): np.array([0.0, 0.0, 0.40])}
SATELLITE = {"mass": 7.0, "inertia": (0.3, 0.4, 0.5), "com": (0.01, -0.02, 0.005)}


def closure(name: str):
    return URDF_DIR / f"{name}.closure.toml"


@functools.cache
def built(name: str, plant: str = "nominal"):
    """The registry's mechanism ``name`` built for ``plant`` (not ``setup``: pytest before 8.1
    calls a module's ``setup`` before its tests, nose's way)."""
    return REGISTRY[name].build(closure(name), plant)


@functools.cache
def floating(name: str, kind: str, gravity: tuple | None = None, plant: str = "nominal", **body) -> FloatingMechanism:
    """The registry's mechanism on a base of ``kind`` (a 7 kg satellite unless ``body`` says)."""
    s = built(name, plant)
    return FloatingMechanism(s.display, closure(name), BaseBody(kind, gravity=gravity, **(body or SATELLITE)),
                             s.tree_inertias)


def consistent_state(fm: FloatingMechanism, name: str, offset, rates, base_pose, base_twist):
    """A tree state meeting the closures (positions and velocities): the mechanism assembled at
    the case's point + ``offset`` with platform ``rates``, the base at ``base_pose`` (6,: xyz and
    a rotation vector; planar: x, y, yaw) moving at ``base_twist`` (root joint's velocity)."""
    s, home = built(name), CASES[(name, fm.base.kind)]
    point = home + np.asarray(offset)[:len(home)]
    q_o = s.plant.assemble(point, s.guess(point))
    q, v = fm.tree_state(q_o, s.plant.velocity_map(q_o) @ np.asarray(rates)[:len(home)])
    pose = np.asarray(base_pose)
    if fm.base.kind == "free":
        q[:7] = pin.SE3ToXYZQUAT(pin.SE3(pin.exp3(pose[3:]), pose[:3]))
    else:
        q[:4] = [pose[0], pose[1], np.cos(pose[5]), np.sin(pose[5])]
    v[:fm.root_nv] = np.asarray(base_twist)[:fm.root_nv]
    return q, v


def closure_rows(fm: FloatingMechanism, name: str, q: np.ndarray, v: np.ndarray):
    """Independent closure kinematics: ``(J, gamma)`` with ``J a + gamma`` the relative
    acceleration of each closure's two frames (linear for a point closure, spatial for a frame
    closure; inertial axes), from Pinocchio's frame Jacobians and the accelerations at a = 0."""
    model, data = fm.model, fm.model.createData()
    spec = read_closures(closure(name)).spec
    pin.computeJointJacobians(model, data, q)
    pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
    pin.updateFramePlacements(model, data)
    J, gamma = [], []
    for entry in spec["closures"]:
        ids = [model.getFrameId(f) for f in entry["frames"]]
        rows = slice(0, 3) if entry.get("kind", "point") == "point" else slice(0, 6)
        jac = [pin.getFrameJacobian(model, data, i, pin.LOCAL_WORLD_ALIGNED)[rows] for i in ids]
        if rows.stop == 3:
            acc = [pin.getFrameClassicalAcceleration(model, data, i, pin.LOCAL_WORLD_ALIGNED).linear for i in ids]
        else:
            acc = [pin.getFrameAcceleration(model, data, i, pin.LOCAL_WORLD_ALIGNED).vector for i in ids]
        J.append(jac[0] - jac[1])
        gamma.append(acc[0] - acc[1])
    return np.vstack(J), np.concatenate(gamma)


def kkt_acceleration(fm: FloatingMechanism, name: str, q, v, u) -> np.ndarray:
    """``M a + h = S^T u + J^T lambda``, ``J a = -gamma``, solved by the Schur complement from
    CRBA, the nonlinear effects and the frame Jacobians (least squares for the redundant row of the
    2RSU+PPaP's parallelogram: ``a`` is unique, ``lambda`` is not)."""
    model, data = fm.model, fm.model.createData()
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    h = pin.nonLinearEffects(model, data, q, v)
    tau = np.zeros(model.nv)
    tau[fm.actuated] = u
    J, gamma = closure_rows(fm, name, q, v)
    free = np.linalg.solve(M, tau - h)
    MinvJt = np.linalg.solve(M, J.T)
    lam = np.linalg.lstsq(J @ MinvJt, -gamma - J @ free, rcond=1e-12)[0]
    return free + MinvJt @ lam


STATES = st.tuples(st.sampled_from(sorted(CASES)),
                   st.lists(st.floats(-0.01, 0.01), min_size=3, max_size=3),
                   st.lists(st.floats(-0.3, 0.3), min_size=3, max_size=3),
                   st.lists(st.floats(-1.0, 1.0), min_size=6, max_size=6),
                   st.lists(st.floats(-0.5, 0.5), min_size=6, max_size=6),
                   st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3),
                   st.sampled_from([0.0, 100.0]))


@settings(max_examples=25, deadline=None)
@given(STATES)
def test_plant_accelerations_meet_the_closures_and_equal_a_kkt_solve(drawn):
    """On random consistent states (random base pose and twist, efforts, Baumgarte 0 or 100, the
    closure file's gravity), the plant's accelerations give zero relative acceleration at every
    closure and equal the KKT solve from CRBA, nonlinear effects and frame Jacobians."""
    (name, kind), offset, rates, pose, twist, u, baumgarte = drawn
    fm = floating(name, kind)
    q, v = consistent_state(fm, name, offset, rates, pose, twist)
    u = np.asarray(u)[:len(fm.actuated)]
    a = fm.plant(baumgarte).acceleration(q, v, u)
    J, gamma = closure_rows(fm, name, q, v)
    scale = max(1.0, np.abs(a).max())
    assert np.abs(J @ a + gamma).max() < 1e-9 * scale
    np.testing.assert_allclose(a, kkt_acceleration(fm, name, q, v, u), rtol=0, atol=1e-8 * scale)


@settings(max_examples=25, deadline=None)
@given(STATES)
def test_momentum_does_not_change_at_zero_gravity(drawn):
    """At zero gravity, on random consistent states under random efforts, the time derivative of
    the system's momentum from the plant's accelerations (Pinocchio's centroidal momentum
    variation) is zero in every component the base leaves free, to 1e-10."""
    (name, kind), offset, rates, pose, twist, u, baumgarte = drawn
    fm = floating(name, kind, gravity=(0.0, 0.0, 0.0))
    q, v = consistent_state(fm, name, offset, rates, pose, twist)
    a = fm.plant(baumgarte).acceleration(q, v, np.asarray(u)[:len(fm.actuated)])
    data = fm.model.createData()
    pin.computeCentroidalMomentumTimeVariation(fm.model, data, q, v, a)
    assert np.abs(data.dhg.vector[list(fm.conserved)]).max() < 1e-10


def test_momentum_is_conserved_to_1e_12_without_efforts():
    """The 5R on a free base, its joints moving at 0.3 m/s of the platform and the base tumbling,
    zero gravity, no efforts, RK4 at 0.1 ms for 0.05 s: the momentum changes by less than 1e-12."""
    fm = floating("five_bar", "free", gravity=(0.0, 0.0, 0.0))
    q, v = consistent_state(fm, "five_bar", (0.0, 0.0, 0.0), (0.3, -0.2, 0.0), np.zeros(6), (0.1, 0, 0, 0.2, -0.1, 0.3))
    result = run_plant(fm.plant(100.0), q, v, 0.05, 1e-4, "rkmk4")
    base = fm.describe(result.telemetry)
    assert result.status == "completed"
    assert np.abs(base.momentum).max() > 1e-3  # something to conserve
    assert fm.momentum_drift(base).max() < 1e-12


@pytest.mark.parametrize("case", sorted(CASES))
def test_relative_coordinates_are_orsinos_wherever_the_base_is(case):
    """The tree's state built from Orsino's (q, qd), the base then moved, turned and set moving,
    reads back as the same Orsino coordinates relative to the base."""
    name, kind = case
    fm, s = floating(name, kind), built(name)
    point = CASES[case] + 0.005
    q_o = s.plant.assemble(point, s.guess(point))
    rates = np.array([0.1, -0.2, 0.15])
    qd_o = s.plant.velocity_map(q_o) @ rates[:s.nominal.p]
    q, v = consistent_state(fm, name, np.full(3, 0.005), rates, (0.3, -0.2, 0.1, 0.4, -0.7, 1.2),
                            (1.0, -2.0, 0.5, 0.3, 0.2, -0.4))
    back_q, back_qd = fm.relative(q, v)
    np.testing.assert_allclose(back_q, q_o, rtol=0, atol=1e-12)
    np.testing.assert_allclose(back_qd[:s.nominal.p], qd_o[:s.nominal.p], rtol=0, atol=1e-12)


def test_law_on_the_base_ignores_where_the_base_is_and_how_it_moves():
    """The adapted law's efforts depend on the joints alone: the same joint state with the base
    elsewhere, turned and moving gives the same efforts, equal to the fixed-base law's at
    Orsino's coordinates (its numpy form exactly, its compiled form to round-off)."""
    fm, s = floating("rsu_ppap", "free"), built("rsu_ppap")
    law = PlatformControl(s.nominal, CircleReference(np.array([0.0, 0.0, 0.4]), 0.03, 6.28), 40.0)
    control, numpy_law = BaseFrameControl(law, fm), BaseFrameControl(law, fm, compiled=False)
    still = consistent_state(fm, "rsu_ppap", (0.004, 0.0, -0.003), (0.1, 0.2, 0.0), np.zeros(6), np.zeros(6))
    moved = consistent_state(fm, "rsu_ppap", (0.004, 0.0, -0.003), (0.1, 0.2, 0.0), (1.0, 2.0, -1.0, 0.5, 0.3, -2.0),
                             (0.4, -0.3, 0.2, 1.0, -0.5, 0.7))
    np.testing.assert_allclose(control.torque(0.1, *moved), control.torque(0.1, *still), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(numpy_law.torque(0.1, *still), law.torque(0.1, *fm.relative(*still)), rtol=0, atol=0)
    np.testing.assert_allclose(control.torque(0.1, *still), law.torque(0.1, *fm.relative(*still)), rtol=1e-13,
                               atol=1e-12)


@pytest.mark.parametrize("case", sorted(CASES))
@settings(max_examples=10, deadline=None)
@given(offset=st.lists(st.floats(-0.01, 0.01), min_size=3, max_size=3),
       rates=st.lists(st.floats(-0.5, 0.5), min_size=3, max_size=3), t=st.floats(0.0, 1.0))
def test_compiled_law_equals_the_numpy_law(case, offset, rates, t):
    """Both thesis laws (computed torque, sliding mode with sign or tanh) evaluated by their
    compiled form give the numpy law's efforts to 1e-12 of their size at random states."""
    name, kind = case
    fm, s = floating(name, kind), built(name)
    center = CASES[case]
    p = len(center)
    q, v = consistent_state(fm, name, offset, rates, np.zeros(6), np.zeros(6))
    gains = printed_gains(np.full(p, 50.0), np.eye(p), {(0, 0): np.full(p, 20.0)})
    for law in (PlatformControl(s.nominal, CircleReference(center, 0.03, 6.28), 40.0),
                PlatformControl(s.nominal, CircleReference(center, 0.03, 6.28), 40.0, gains, "sign"),
                PlatformControl(s.nominal, CircleReference(center, 0.03, 6.28), 40.0, gains)):
        fast, numpy_law = BaseFrameControl(law, fm).torque(t, q, v), BaseFrameControl(law, fm, False).torque(t, q, v)
        np.testing.assert_allclose(fast, numpy_law, rtol=0, atol=1e-12 * max(1.0, np.abs(numpy_law).max()))


@pytest.mark.parametrize("case", sorted(CASES))
def test_compiled_loop_is_the_python_loop(case):
    """closed_tree on a moving base through the compiled robot loop (the law from Python each
    period) gives the Python loop's run with the same plant and law, 30 steps of RK4 from a moving
    base: states, efforts, references and closure drift to round-off (the 2RSU+PPaP's 15 closure
    rows are rank-deficient, the Delassus solve's cut directions at 1e-22 of the largest: its rates
    differ by up to 3e-10 of their size, the 5R's by 4e-16)."""
    name, kind = case
    fm, s = floating(name, kind), built(name)
    center = CASES[case]
    law = PlatformControl(s.nominal, CircleReference(center, 0.01, 6.28), 40.0)
    q, v = consistent_state(fm, name, (0.002, -0.001, 0.001), (0.1, 0.2, -0.1), (0.1, -0.2, 0.05, 0.3, -0.2, 0.4),
                            (0.2, -0.1, 0.05, 0.3, 0.2, -0.4))
    step = 1e-3 if name == "rsu_ppap" else 1e-4
    runs = [track(fm, law, q, v, 30 * step, step, 100.0, "rkmk4", "closed_tree", backend=backend)
            for backend in ("compiled", "python")]
    assert [r.backend for r in runs] == ["compiled", "python"] and all(r.status == "completed" for r in runs)
    a, b = runs[0].telemetry, runs[1].telemetry
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-11)
    np.testing.assert_allclose(a.v, b.v, rtol=0, atol=1e-9 * max(1.0, np.abs(b.v).max()))
    np.testing.assert_allclose(a.efforts, b.efforts, rtol=0, atol=1e-9 * np.abs(b.efforts).max())
    np.testing.assert_allclose(a.reference, b.reference, rtol=0, atol=0)
    np.testing.assert_allclose(a.drift, b.drift, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a.orientation_drift, b.orientation_drift, rtol=0, atol=1e-12)


def test_drift_from_placements_is_closure_drift():
    """The mechanism's closure drift from the placements alone equals the closures module's
    (Jacobians and all) at random configurations, points, welds and a revolute."""
    rng = np.random.default_rng(3)
    revolute = FloatingMechanism(built("five_bar").display, URDF_DIR / "five_bar_revolute.closure.toml",
                                 BaseBody("free", **SATELLITE))
    for fm in (floating("five_bar", "planar"), floating("rsu_ppap", "free"), revolute):
        q0 = fm.tree_state(*[np.zeros(fm.chain.mechanism.n_q)] * 2)[0]
        for _ in range(20):
            q = pin.integrate(fm.model, q0, 0.3 * rng.standard_normal(fm.model.nv))
            np.testing.assert_allclose(fm.drift(q), closure_drift(fm.model, fm.data, q, fm.closures), rtol=1e-12,
                                       atol=1e-15)


def test_compiled_loop_refuses_what_it_cannot_run():
    """backend='compiled' names why: Pinocchio's plant, or a fixed base."""
    fm = floating("five_bar", "planar")
    law = PlatformControl(built("five_bar").nominal, CircleReference(CASES[("five_bar", "planar")], 0.01, 6.28), 40.0)
    q, v = consistent_state(fm, "five_bar", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), np.zeros(6), np.zeros(6))
    with pytest.raises(InvalidArgument, match="the plant is 'constraint_dynamics', not 'closed_tree'"):
        track(fm, law, q, v, 1e-3, 1e-4, dynamics="constraint_dynamics", backend="compiled")
    ground = floating("five_bar", "fixed", **{"mass": None, "inertia": None, "com": None})
    assert ground.compiled("closed_tree", "rkmk4") == "the mechanism is on a fixed base"
    with pytest.raises(FreefloatError, match="fixed base is no robot"):
        _ = ground.robot


def test_true_5r_inertias_give_the_true_5r_on_the_ground():
    """The registry's 15 % 5R written into the tree (fixed base) has the forward dynamics of
    Orsino's 15 % 5R: the tree's inertias are the plant's, not the URDF's."""
    s = built("five_bar", "true_15")
    closures = read_closures(closure("five_bar"))
    s.tree_inertias(closures.model)
    plant = ConstraintDynamicsPlant(closures.model, closures.constraints,
                                    [closures.model.idx_vs[j] for j in closures.actuated])
    mech = five_bar(TRUE_PARAMETERS)
    q = mech.assemble(np.array([0.05, 0.18]), s.guess(np.array([0.05, 0.18])))
    qd = mech.velocity_map(q) @ np.array([0.4, -0.3])
    u = np.array([0.2, -0.1])
    chain = s.display
    a = plant.acceleration(chain.pinocchio_q(q), chain.pinocchio_q(qd), u)
    np.testing.assert_allclose(a, chain.pinocchio_q(mech.forward(q, qd, u, 0.0)), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("body, message", [
    ({"kind": "wheeled"}, "'kind' is 'wheeled'; valid: fixed, planar, free"),
    ({"mass": -1.0}, "'mass' must be > 0"),
    ({"inertia": (1.0, 2.0)}, "'inertia' must be three finite numbers"),
    ({"inertia": (1.0, 1.0, 3.0)}, "'inertia' must be three positive principal moments"),
    ({"com": (0.0, float("nan"), 0.0)}, "'com' must be three finite numbers"),
    ({"kind": "fixed", "mass": 5.0}, "'mass' describes the base body, which plays no part on a fixed base"),
])
def test_bad_base_bodies_are_refused_naming_the_field(body, message):
    """A base body that is no rigid body, or no moving base, is refused naming the field."""
    with pytest.raises(FreefloatError, match=message.replace("(", r"\(").replace(")", r"\)")):
        BaseBody(**{"kind": "free", **body})


def test_base_body_replaces_the_urdf_root_link():
    """The base body given is the root joint's inertia; without one, the URDF root link's."""
    given = floating("five_bar", "planar")
    assert given.model.inertias[1].mass == 7.0
    np.testing.assert_allclose(given.model.inertias[1].lever, SATELLITE["com"])
    np.testing.assert_allclose(np.diag(given.model.inertias[1].inertia), SATELLITE["inertia"])
    urdf = FloatingMechanism(built("five_bar").display, closure("five_bar"), BaseBody("planar"))
    assert urdf.model.inertias[1].mass == 1.0  # five_bar.urdf's base_link
