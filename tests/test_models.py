"""The dynamics-model variants against the exact dynamics (ABA), each on both sides of the
boundary of the regime in which it is valid."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from freefloat import gjm, load_robot
from freefloat.dynamics.models import MODELS, make_model
from freefloat.dynamics.models.selection import ZERO_MOMENTUM, regime_models
from freefloat.lab.reproduce.states import state_with_momentum
from freefloat.robot.conventions import base_state, state_from_base
from freefloat.robot.joints import JointCoordinates

from .conftest import REPO, random_robots, random_state, robot_from_case

EXACT_AT_ZERO_MOMENTUM = ("standard_full_hdot", "standard_corrected", "reduced", "momentum_mono",
                          "momentum_multi", "momentum_routh")


def errors(robot, q, v, rng, names):
    """Relative acceleration error of each named model against ABA at (q, v) under random torques."""
    tau = np.concatenate((np.zeros(6), rng.normal(size=robot.n_joints)))
    exact = make_model("exact", robot).acceleration(q, v, tau)
    return {n: np.abs(make_model(n, robot).acceleration(q, v, tau) - exact).max() / np.abs(exact).max() for n in names}


@pytest.fixture(scope="module")
def four_arm():
    return load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)


@settings(max_examples=15, deadline=None)
@given(random_robots(max_links=6))
def test_zero_momentum_variants_match_exact_on_random_robots(tmp_path_factory, case):
    """At zero momentum the corrected, reduced and momentum models give ABA's accelerations to 1e-8."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = state_with_momentum(robot, rng)
    for name, err in errors(robot, q, v, rng, EXACT_AT_ZERO_MOMENTUM).items():
        assert err < 1e-8, name


def test_printed_standard_model_fails_when_the_base_turns(four_arm):
    """FM-ST-A as printed (Hdot over the joints only) misses the base rotation: wrong at zero momentum."""
    q, v = state_with_momentum(four_arm, np.random.default_rng(1))
    assert np.linalg.norm(base_state(four_arm, q, v)[2][3:]) > 1e-3
    assert errors(four_arm, q, v, np.random.default_rng(2), ["standard"])["standard"] > 1e-4


def test_printed_standard_model_is_exact_while_the_base_does_not_turn(four_arm):
    """With zero momentum and joint rates that leave w0 = 0, FM-ST-A as printed is exact."""
    rng = np.random.default_rng(3)
    q, v = state_with_momentum(four_arm, rng)
    s = gjm.compute(four_arm, q, v)
    null = np.linalg.svd(s.J0[3:])[2][3:].T  # joint rates with no base rotation
    qdot = null @ rng.normal(size=null.shape[1])
    r0, R0, _ = base_state(four_arm, q, v)
    q, v = state_from_base(four_arm, r0, R0, s.J0 @ qdot, q[7:], qdot)
    assert np.abs(base_state(four_arm, q, v)[2][3:]).max() < 1e-12
    assert errors(four_arm, q, v, rng, ["standard"])["standard"] < 1e-8


def test_angular_momentum_only_separates_the_momentum_models(four_arm):
    """With P = 0, L != 0: the Routhian and the c0-free model stay exact, eqs 127/128 and H* do not."""
    rng = np.random.default_rng(4)
    q, v = state_with_momentum(four_arm, rng, L=np.array([3.0, -2.0, 5.0]))
    err = errors(four_arm, q, v, rng, ["standard_corrected", "standard_full_hdot", "momentum_routh",
                                       "momentum_mono", "momentum_multi", "reduced"])
    assert max(err["standard_corrected"], err["standard_full_hdot"], err["momentum_routh"]) < 1e-8
    assert min(err["momentum_mono"], err["momentum_multi"], err["reduced"]) > 1e-4


def test_linear_momentum_breaks_the_c0_claim(four_arm):
    """With P != 0, c0 = 0 (sec 3.5) is wrong; only c0 = [0; v0 x P] stays exact."""
    rng = np.random.default_rng(5)
    q, v = state_with_momentum(four_arm, rng, P=np.array([20.0, -10.0, 5.0]), L=np.array([1.0, 0.0, 2.0]))
    err = errors(four_arm, q, v, rng, ["standard_corrected", "standard_full_hdot", "momentum_routh"])
    assert err["standard_corrected"] < 1e-8
    assert err["standard_full_hdot"] > 1e-4 and err["momentum_routh"] > 1e-4


def test_nidc_starts_as_the_standard_model_and_departs_as_D_grows(four_arm):
    """FM-NIC-A equals FM-ST-A while D = 0; one eq-67 step makes D = dt dxdot0/dq and changes it."""
    rng = np.random.default_rng(6)
    q, v = state_with_momentum(four_arm, rng)
    tau = np.concatenate((np.zeros(6), rng.normal(size=16)))
    nidc, standard = make_model("nidc", four_arm), make_model("standard", four_arm)
    np.testing.assert_allclose(nidc.acceleration(q, v, tau), standard.acceleration(q, v, tau), rtol=1e-12, atol=1e-12)
    sensitivity = nidc.xdot0_sensitivity(nidc.terms(q, v))
    nidc.end_period(q, v, 0.01)
    np.testing.assert_allclose(nidc.D, 0.01 * sensitivity, rtol=1e-12)
    assert np.abs(nidc.acceleration(q, v, tau) - standard.acceleration(q, v, tau)).max() > 1e-8


def still_base_state(robot, rng, zero_momentum: bool):
    """A state whose base does not turn (w0 = 0) and whose linear momentum is zero: with zero
    momentum (joint rates in the null space of J0's angular rows), or with angular momentum only
    (any joint rates, v0 = -H0m[:3] qdot / m so that P = 0)."""
    q, v = state_with_momentum(robot, rng)
    s = gjm.compute(robot, q, v)
    if zero_momentum:
        null = np.linalg.svd(s.J0[3:])[2][3:].T
        qdot = null @ rng.normal(size=null.shape[1])
        x0dot = s.J0 @ qdot
    else:
        qdot = rng.normal(size=robot.n_joints)
        x0dot = np.concatenate((-s.H0m[:3] @ qdot / s.H0[0, 0], np.zeros(3)))
    r0, R0, _ = base_state(robot, q, v)
    q, v = state_from_base(robot, r0, R0, x0dot, q[7:], qdot)
    M = gjm.compute(robot, q, v).momentum_base
    assert np.abs(base_state(robot, q, v)[2][3:]).max() < 1e-12 and np.abs(M[:3]).max() < 1e-9
    assert (np.abs(M[3:]).max() < 1e-9) == zero_momentum
    return q, v


@pytest.mark.parametrize("name", ["nidc", "nidc_translation"])
def test_fresh_nidc_is_exact_at_zero_momentum_with_the_base_still(four_arm, name):
    """Inside its row (zero momentum, w0 = 0, D = 0) FM-NIC-A gives ABA's accelerations."""
    rng = np.random.default_rng(10)
    q, v = still_base_state(four_arm, rng, zero_momentum=True)
    assert errors(four_arm, q, v, rng, [name])[name] < 1e-8


@pytest.mark.parametrize("name", ["nidc", "nidc_translation"])
def test_fresh_nidc_fails_with_angular_momentum_where_standard_is_exact(four_arm, name):
    """With w0 = 0, P = 0, L != 0 and D = 0, FM-ST-A is exact but FM-NIC-A is not: its extra
    c_m term 2 (dxdot0/dq_k) . M needs M = 0."""
    rng = np.random.default_rng(11)
    q, v = still_base_state(four_arm, rng, zero_momentum=False)
    err = errors(four_arm, q, v, rng, ["standard", name])
    assert err["standard"] < 1e-8 and err[name] > 1e-3


def test_printed_standard_model_fails_with_linear_momentum_while_the_base_is_still(four_arm):
    """With w0 = 0 but P != 0 (so v0 x P != 0), FM-ST-A as printed is wrong."""
    rng = np.random.default_rng(12)
    q, v = still_base_state(four_arm, rng, zero_momentum=False)
    r0, R0, x0dot = base_state(four_arm, q, v)
    x0dot[:3] += np.array([0.3, -0.2, 0.1])  # adds P = m dv0, keeps w0 = 0
    q, v = state_from_base(four_arm, r0, R0, x0dot, q[7:], v[6:])
    assert np.linalg.norm(np.cross(x0dot[:3], gjm.compute(four_arm, q, v).momentum_base[:3])) > 1e-3
    assert errors(four_arm, q, v, rng, ["standard"])["standard"] > 1e-4


def test_nidc_sensitivity_is_eq_64():
    """dxdot0/dq_k (eq 64) at D = 0 equals the derivative of J0 qdot along joint k by differences."""
    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    rng = np.random.default_rng(7)
    q, v = state_with_momentum(robot, rng)
    nidc = make_model("nidc", robot)
    sens = nidc.xdot0_sensitivity(nidc.terms(q, v))
    coords, h = JointCoordinates(robot), 1e-6
    theta, qdot = coords.get(q), v[6:]
    for k in range(robot.n_joints):
        plus, minus = q.copy(), q.copy()
        coords.set(plus, theta + h * np.eye(robot.n_joints)[k])
        coords.set(minus, theta - h * np.eye(robot.n_joints)[k])
        fd = (gjm.compute(robot, plus, v).J0 @ qdot - gjm.compute(robot, minus, v).J0 @ qdot) / (2 * h)
        np.testing.assert_allclose(sens[k], fd, atol=1e-6 * max(1.0, np.abs(fd).max()))


def test_computed_torque_on_a_matching_model_imposes_the_servo_acceleration(four_arm):
    """A controller built on standard_corrected drives the exact plant to qddot = qddot_d + Kp e + Kd edot."""
    from freefloat.space.control import ComputedTorque, QuinticTrajectory

    rng = np.random.default_rng(8)
    q, v = state_with_momentum(four_arm, rng)
    traj = QuinticTrajectory(rng.normal(size=16), rng.normal(size=16), 2.0)
    ctrl = ComputedTorque(four_arm, traj, 10.0, 100.0, model="standard_corrected")
    a = make_model("exact", four_arm).acceleration(q, v, np.concatenate((np.zeros(6), ctrl.torque(0.7, q, v))))
    q_d, qd_d, qdd_d = traj(0.7)
    expected = qdd_d + 10.0 * (q_d - q[7:]) + 100.0 * (qd_d - v[6:])
    np.testing.assert_allclose(a[6:], expected, atol=1e-8 * np.abs(expected).max())


def test_every_registered_model_is_constructible_and_unknown_names_list_them(four_arm):
    """Each registry name builds its model; an unknown one is refused with the list."""
    for name in MODELS:
        assert make_model(name, four_arm).name == name
    with pytest.raises(ValueError, match="valid: exact, standard"):
        make_model("fm-st-a", four_arm)


def test_nidc_readings_differ_only_through_the_base_translation(four_arm):
    """The two readings of eqs 55-58 agree while D has no translation and differ once it has."""
    rng = np.random.default_rng(9)
    q, v = state_with_momentum(four_arm, rng, L=np.array([1.0, 2.0, -1.0]))
    tau = np.concatenate((np.zeros(6), rng.normal(size=16)))
    plain, shifted = make_model("nidc", four_arm), make_model("nidc_translation", four_arm)
    plain.D[:, 3:] = shifted.D[:, 3:] = rng.normal(size=(16, 3)) * 1e-2
    np.testing.assert_allclose(shifted.acceleration(q, v, tau), plain.acceleration(q, v, tau), rtol=1e-12, atol=1e-12)
    shifted.D[:, :3] = rng.normal(size=(16, 3)) * 1e-2
    assert np.abs(shifted.acceleration(q, v, tau) - plain.acceleration(q, v, tau)).max() > 1e-8


def test_corrected_c0_without_the_full_hdot_is_refused(four_arm):
    """The corrected base term is only defined with the full Hdot; the half combination is named."""
    from freefloat.dynamics.models.underactuated import UnderactuatedGJM

    with pytest.raises(ValueError, match="corrected_c0 implies full_hdot"):
        UnderactuatedGJM(four_arm, full_hdot=False, corrected_c0=True)


GJM_MODELS = tuple(name for name in MODELS if name != "exact")


def with_gravity_and_wrenches(robot, rng):
    """Gravity on (a copy of the model's setting is restored by the caller) and one random wrench per joint."""
    import pinocchio as pin

    robot.model.gravity.linear[:] = rng.normal(size=3)
    return [pin.Force(rng.normal(size=6)) for _ in range(robot.model.njoints)]


@settings(max_examples=10, deadline=None)
@given(random_robots(max_links=6))
def test_models_auto_treats_as_exact_match_aba_with_gravity_or_wrenches(tmp_path_factory, case):
    """With gravity or a wrench on every joint (eqs 95-99), the models ``regime_models(None)`` keeps
    match ABA with the same forces to 1e-10; those that assume conserved momentum are off by > 1e-4."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    for forces in ("gravity", "wrenches"):
        fext = with_gravity_and_wrenches(robot, rng)
        if forces == "gravity":
            fext = None
        else:
            robot.model.gravity.linear[:] = 0.0
        models = {name: make_model(name, robot) for name in MODELS}  # built after gravity is set
        for state in ("zero momentum", "random"):
            q, v = state_with_momentum(robot, rng) if state == "zero momentum" else random_state(robot, rng)
            tau = np.concatenate((np.zeros(6), rng.normal(size=robot.n_joints)))
            exact = models["exact"].acceleration(q, v, tau, fext)
            err = {n: np.abs(models[n].acceleration(q, v, tau, fext) - exact).max() / max(1.0, np.abs(exact).max())
                   for n in MODELS}
            assert all(err[n] < 1e-10 for n in regime_models(None)), (forces, state, err)
            if state == "zero momentum":  # exact at this instant, but the forces change P
                assert err["standard_full_hdot"] < 1e-10, (forces, err)
                assert min(err[n] for n in (*ZERO_MOMENTUM, "momentum_routh")) > 1e-4, (forces, err)
            else:
                assert err["standard_full_hdot"] > 1e-4, (forces, err)


@pytest.mark.slow
@settings(max_examples=15, deadline=None)
@given(random_robots(max_links=6))
def test_compiled_models_equal_the_numpy_reference(tmp_path_factory, case):
    """Every GJM model's acceleration (gravity and wrenches on), joint-space form and NIDC update
    agree between the compiled core and the numpy reference to 1e-12 relative, free and planar bases."""
    for base in ("free", "planar"):
        robot, rng = robot_from_case(tmp_path_factory, case, base=base)
        q, v = random_state(robot, rng)
        tau = np.concatenate((np.zeros(robot.n_base), rng.normal(size=robot.n_joints)))
        fext = with_gravity_and_wrenches(robot, rng)
        D = 0.1 * rng.normal(size=(robot.n_joints, 6))
        for name in GJM_MODELS:
            compiled, numpy = make_model(name, robot), make_model(name, robot, backend="numpy")
            if name.startswith("nidc"):
                compiled.D[:], numpy.D[:] = D, D
                compiled.end_period(q, v, 0.01)
                numpy.end_period(q, v, 0.01)
                assert np.abs(compiled.D - numpy.D).max() < 1e-12 * max(1.0, np.abs(numpy.D).max()), name
            a, b = compiled.acceleration(q, v, tau, fext), numpy.acceleration(q, v, tau, fext)
            assert np.abs(a - b).max() < 1e-12 * max(1.0, np.abs(b).max()), (base, name)
            (H1, c1), (H2, c2) = compiled.joint_space_at(q, v), numpy.joint_space_at(q, v)
            assert np.abs(H1 - H2).max() < 1e-12 * max(1.0, np.abs(H2).max()), (base, name)
            assert np.abs(c1 - c2).max() < 1e-12 * max(1.0, np.abs(c2).max()), (base, name)


def test_unknown_model_backend_is_refused(four_arm):
    """A GJM model with an unknown backend raises ValueError listing the valid ones."""
    with pytest.raises(ValueError, match="compiled, numpy"):
        make_model("standard", four_arm, backend="julia")


def test_the_compiled_core_has_the_registrys_compiled_models():
    """The C++ core's model names (cpp/gjm/models.hpp) are the registry's compiled hand-built models."""
    from freefloat.dynamics import _core
    from freefloat.dynamics.models import MODELS

    assert list(_core.MODELS) == [name for name, spec in MODELS.items() if spec.compiled and name != "exact"]


@pytest.mark.parametrize("name", ["exact", "standard_corrected", "reduced"])
@pytest.mark.parametrize(("argument", "bad", "message"), [
    ("tau", lambda a: np.full_like(a, np.nan), "'tau' must be finite"),
    ("v", lambda a: a[:-1], r"'v' must have shape \(\d+,\), got \(\d+,\)"),
    ("q", lambda a: np.append(a, 0.0), r"'q' must have shape"),
    ("v", lambda a: a + 1j, "'v' must hold real numbers, got complex numbers"),
    ("q", lambda a: np.full_like(a, 1e300), "'q' must be at most 1e\\+15 in size"),
])
def test_acceleration_refuses_bad_arguments_naming_them(four_arm, name, argument, bad, message):
    """A NaN torque, a wrong-sized array, complex velocities (their imaginary parts were dropped)
    or a configuration of 1e300 (NaN accelerations) gives InvalidArgument naming the argument, not
    NaN accelerations or Pinocchio's C++ message."""
    from freefloat.errors import InvalidArgument

    model = make_model(name, four_arm)
    args = {"q": four_arm.neutral(), "v": np.zeros(four_arm.model.nv), "tau": np.zeros(four_arm.model.nv)}
    args[argument] = bad(args[argument])
    with pytest.raises(InvalidArgument, match=message):
        model.acceleration(args["q"], args["v"], args["tau"])


@pytest.mark.parametrize("name", ["exact", "standard_corrected"])
def test_acceleration_takes_lists(four_arm, name):
    """Plain lists give the accelerations numpy arrays give (the exact model raised Pinocchio's
    C++ signature error)."""
    model = make_model(name, four_arm)
    q, v, tau = four_arm.neutral(), np.full(four_arm.model.nv, 0.1), np.full(four_arm.model.nv, 0.2)
    assert np.array_equal(model.acceleration(list(q), list(v), list(tau)), model.acceleration(q, v, tau))


def as_chain(text: str) -> str:
    """A random tree of ``random_urdf`` rewired so that link i hangs from link i - 1: one branch
    as deep as the robot."""
    return re.sub(r'<joint name="j(\d+)"(.*?)<parent link="[^"]*"/>',
                  lambda m: f'<joint name="j{m[1]}"{m[2]}<parent link="{"base" if m[1] == "1" else f"l{int(m[1]) - 1}"}"/>',
                  text)


@pytest.mark.slow
@settings(max_examples=8, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(12, 40), st.booleans())
def test_tree_sparse_models_equal_the_dense_reference_and_aba_on_large_trees(tmp_path_factory, seed, links, chain):
    """On random trees and chains of 12 to 40 links, every compiled model (H* qddot = tau - c
    solved through the tree-sparse factorisation of the whole mass matrix, H* never formed)
    gives the numpy reference's accelerations (dense H* solved) and standard_corrected gives
    ABA's, to 1e-14 times H*'s condition number (at least 1e-12), relative."""
    from .conftest import load_text, random_urdf

    rng = np.random.default_rng(seed)
    text = random_urdf(rng, links)
    robot = load_text(tmp_path_factory.mktemp("r"), as_chain(text) if chain else text)
    q, v = random_state(robot, rng)
    tau = np.concatenate((np.zeros(6), rng.normal(size=robot.n_joints)))
    tolerance = max(1e-12, 1e-14 * np.linalg.cond(gjm.compute(robot, q, v).Hstar))
    exact = make_model("exact", robot).acceleration(q, v, tau)
    for name in GJM_MODELS:
        a, b = make_model(name, robot).acceleration(q, v, tau), make_model(name, robot, backend="numpy").acceleration(q, v, tau)
        assert np.abs(a - b).max() <= tolerance * max(1.0, np.abs(b).max()), name
        if name == "standard_corrected":
            assert np.abs(a - exact).max() <= tolerance * max(1.0, np.abs(exact).max())


@pytest.mark.parametrize("robot", [None, "four_arm_planar", {}])
def test_make_model_refuses_a_robot_that_is_not_a_robot(robot):
    """A model of None, a robot's name or a dict is refused naming 'robot' and freefloat.load_robot."""
    from freefloat.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match=r"'robot' takes a Robot \(freefloat.load_robot\)"):
        make_model("standard", robot)


def test_the_exact_model_allocates_its_data_on_first_use(four_arm):
    """ExactModel builds its pin.Data only when an evaluation needs it (a compiled run never
    does), and then gives Pinocchio's ABA."""
    import pinocchio as pin

    from freefloat.dynamics.models.exact import ExactModel

    model = ExactModel(four_arm)
    assert "data" not in vars(model)
    q, v = random_state(four_arm, np.random.default_rng(0))
    tau = np.zeros(four_arm.model.nv)
    a = model.acceleration(q, v, tau)
    assert "data" in vars(model)
    np.testing.assert_allclose(a, pin.aba(four_arm.model, four_arm.model.createData(), q, v, tau), rtol=0, atol=1e-12)
