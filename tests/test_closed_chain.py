"""Mechanisms as data: the 5R's URDF spanning tree plus its closure file, loaded into both models."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from freefloat import FreefloatError
from freefloat.dynamics.plants import ConstraintDynamicsPlant
from freefloat.dynamics.simulation import run_plant
from freefloat.parallel.closed_chain import chain_from_tree, load_closed_chain
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar, five_bar_spec
from freefloat.robot.builders import build_urdf, urdf_xml

from .conftest import REPO
from .loops import simulate

CLOSURE = REPO / "urdf" / "five_bar.closure.toml"
P = FiveBarParameters()


@pytest.fixture(scope="module")
def loaded():
    return load_closed_chain(CLOSURE)


def state(mech, point=(0.07, 0.17), rates=(0.3, -0.2)):
    point = np.array(point)
    q = mech.assemble(point, elbow_guess(P, point))
    _, _, C, *_ = mech.terms(q, np.zeros(len(q)))
    return q, C @ np.array(rates)


def test_committed_urdf_is_what_the_data_generates():
    """urdf/five_bar.urdf is exactly the spanning tree freefloat.parallel.five_bar describes."""
    assert urdf_xml(build_urdf(five_bar_spec(P))) == (REPO / "urdf" / "five_bar.urdf").read_text()


def test_urdf_model_matches_the_model_built_from_data(loaded):
    """Orsino's model read from the URDF and the closure file gives the data-built 5R's accelerations."""
    q, qd = state(five_bar(P))
    tau = np.array([0.02, -0.01])
    a_ref = five_bar(P).forward(q, qd, tau)
    np.testing.assert_allclose(loaded.mechanism.forward(q, qd, tau), a_ref, atol=1e-12 * np.abs(a_ref).max())


def test_pinocchio_with_the_closure_file_matches_orsino(loaded):
    """Pinocchio's constraintDynamics on the URDF with the file's loop closure equals Orsino's model."""
    rng = np.random.default_rng(0)
    model, cms = loaded.model, loaded.constraints
    data, cds = model.createData(), [c.createData() for c in cms]
    pin.initConstraintDynamics(model, data, cms, cds)
    for point in ([0.07, 0.17], [-0.03, 0.2], [0.02, 0.13]):
        q, qd = state(loaded.mechanism, point, rng.normal(size=2))
        tau = rng.normal(size=2) * 0.05
        ours = loaded.mechanism.forward(q, qd, tau)
        tau_pin = np.zeros(model.nv)
        for j, t in zip(loaded.actuated, tau):
            tau_pin[model.idx_vs[j]] = t
        ddq = pin.constraintDynamics(model, data, loaded.pinocchio_q(q), loaded.pinocchio_q(qd), tau_pin, cms, cds,
                                     pin.ProximalSettings(1e-14, 1e-12, 50))
        np.testing.assert_allclose(loaded.pinocchio_q(ours), ddq, atol=1e-10 * np.abs(ddq).max())


@pytest.mark.parametrize(("edit", "message"), [
    (lambda s: s.replace('frames = ["c1_ee", "c2_ee"]', 'frames = ["c1_ee", "c3_ee"]'), "'closures\\[0\\].frames' names frame 'c3_ee'"),
    (lambda s: s.replace('actuated = ["c1_joint1", "c2_joint1"]', 'actuated = ["c1_joint9"]'), "'actuated' names joint 'c1_joint9'"),
    (lambda s: s.replace('coordinates = ["x", "y"]', 'coordinates = ["x", "w"]'), "'platform.coordinates' must be a list of x, y, z"),
    (lambda s: s.replace('urdf = "five_bar.urdf"', 'urdf = "six_bar.urdf"'), "'urdf' file .*six_bar.urdf does not exist"),
    (lambda s: s.replace('frames = ["c1_ee", "c2_ee"]', 'frames = ["c1_ee"]'), "must name two frames"),
    (lambda s: s + 'kind = "hinge"\n', "'closures\\[0\\].kind' is 'hinge'; valid: point, revolute, weld, frame"),
    (lambda s: s + 'kind = "frame"\n', "'closures\\[0\\].kind' is a weld; tip-to-tip mechanisms take point or planar revolute"),
    (lambda s: s.replace("gravity =", "gravty ="), "unknown top-level key 'gravty'; did you mean 'gravity'\\? "
                                                  "\\(allowed: actuated, closures, gravity, joints, platform, slip_speed, urdf\\)"),
    (lambda s: s + "[joints.c1_jiont1]\narmature = 1e-3\n", "'\\[joints.c1_jiont1\\]' names no joint of the URDF; did you "
                                                               "mean 'c1_joint1'"),
    (lambda s: s + "[joints.c1_joint1]\narmature = -1e-3\n", "'joints.c1_joint1.armature' must be a finite number >= 0"),
    (lambda s: s + "[joints.c1_joint1]\ninertia = 1e-3\n", "unknown \\[joints.c1_joint1\\] key 'inertia'; allowed: armature, "
                                                           "damping, friction"),
    (lambda s: "slip_speed = 0.0\n" + s, "'slip_speed' must be a positive speed"),
    (lambda s: s.replace("coordinates =", "coordinate ="), "unknown \\[platform\\] key 'coordinate'.*allowed: "
                                                           "coordinates, frame"),
    (lambda s: s + "stiffness = 1e6\n", "unknown \\[closures\\[0\\]\\] key 'stiffness'; allowed: frames, kind"),
    (lambda s: "a = " + "[" * 5000 + "]" * 5000 + "\n" + s, "nested too deeply"),
    (lambda s: s.replace('frames = ["c1_ee", "c2_ee"]', 'frames = ["c1_ee", "c1_ee"]'), "joins frame 'c1_ee' to itself"),
    (lambda s: s.replace('frames = ["c1_ee", "c2_ee"]', 'frames = ["c1_ee", "c2_link1"]'),
     "joints c2_joint2 of five_bar.urdf lie on no chain"),
])
def test_bad_closure_files_name_the_key(tmp_path, edit, message):
    """Unknown frames or joints, bad coordinates, a missing URDF, a one-frame closure, an unknown
    closure kind, a frame closure given to the tip-to-tip loader, a misspelt key, a file nested
    too deeply to parse, a joint term for no joint, negative or unknown, a slip speed of zero:
    named errors."""
    (tmp_path / "five_bar.urdf").write_text((REPO / "urdf" / "five_bar.urdf").read_text())
    (tmp_path / "m.toml").write_text(edit(CLOSURE.read_text()))
    with pytest.raises(FreefloatError, match=message):
        load_closed_chain(tmp_path / "m.toml")


def test_five_bar_animation_places_the_joints_where_orsino_does(tmp_path):
    """The meshcat page of a 5R run animates chain 1's second joint at Orsino's joint frame."""
    from freefloat.lab.reproduce.five_bar_report import animate
    from freefloat.parallel.closed_loop import track_five_bar
    from freefloat.parallel.sliding_mode import PlatformControl, circle_reference

    from .pages import animation as _animation
    from .pages import packets as _packets

    tel = track_five_bar(P, PlatformControl(five_bar(P), circle_reference, 40.0), 0.01, 1e-3).telemetry
    t, qs = tel.t, tel.q
    page = animate(t, qs, tmp_path / "five_bar.html")
    tracks = {path: tr for path, tr in _animation(_packets(page)).items() if path.endswith("c1_joint2")}
    assert len(tracks) == 1
    (tr,) = tracks.values()
    _, joints = five_bar(P).chains[0].frames(qs[-1, 2:4])
    np.testing.assert_allclose(tr[".position"][-1][1], joints[1][:3, 3], atol=1e-9)


def test_one_second_trajectories_agree_with_pinocchio(loaded):
    """Falling for 1 s from rest (RK4, 1 ms, no stabilisation in either), Orsino's 5R and Pinocchio's
    constrained dynamics follow the same joint trajectory to 1e-9 rad."""
    mech, model, cms = loaded.mechanism, loaded.model, loaded.constraints
    q0, _ = state(mech, rates=(0.0, 0.0))
    qs = simulate(mech, q0, np.zeros(6), lambda *_: np.zeros(2), 1.0, 1e-3).telemetry.q
    plant = ConstraintDynamicsPlant(model, cms, [], accuracy=1e-14)
    pinocchio = run_plant(plant, loaded.pinocchio_q(q0), np.zeros(model.nv), 1.0, 1e-3, "rkmk4").telemetry.q
    assert len(pinocchio) == len(qs) == 1001
    assert max(np.abs(q - loaded.pinocchio_q(orsino)).max() for q, orsino in zip(pinocchio, qs)) < 1e-9


JOINT_TYPES = (pin.JointModelRX, pin.JointModelRY, pin.JointModelRZ, pin.JointModelPX, pin.JointModelPY, pin.JointModelPZ)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 6))
def test_chains_read_from_a_tree_match_pinocchio(seed, n):
    """chain_from_tree on random chains of revolute and prismatic joints along x, y or z, random
    placements, inertias, armature and gravity: M equals CRBA (the armature on its diagonal), v + g
    equals RNEA(q, qd, 0), and the joints' damping and friction are the chain's."""
    rng = np.random.default_rng(seed)
    model = pin.Model()
    model.gravity = pin.Motion(rng.normal(size=3), np.zeros(3))
    parent = 0
    for i in range(n):
        placement = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3) * 0.3)
        parent = model.addJoint(parent, JOINT_TYPES[rng.integers(6)](), placement, f"j{i}")
        A = rng.normal(size=(3, 3))
        model.appendBodyToJoint(parent, pin.Inertia(rng.uniform(0.2, 2.0), rng.normal(size=3) * 0.2, A @ A.T + 0.05 * np.eye(3)),
                                pin.SE3.Identity())
    model.addFrame(pin.Frame("tip", parent, 0, pin.SE3(np.eye(3), rng.normal(size=3) * 0.1), pin.FrameType.OP_FRAME))
    model.armature[:] = rng.uniform(0.0, 0.5, n)
    model.damping[:], model.friction[:] = rng.uniform(0.0, 0.1, n), rng.uniform(0.0, 0.1, n)
    chain, joints = chain_from_tree(model, model.getFrameId("tip"))
    np.testing.assert_array_equal(chain.friction.viscous, model.damping)
    np.testing.assert_array_equal(chain.friction.coulomb, model.friction)
    data = model.createData()
    q, qd = rng.uniform(-1, 1, n), rng.normal(size=n)
    M, v, g = chain.dynamics(q, qd)
    M_ref = pin.crba(model, data, q)
    M_ref = np.triu(M_ref) + np.triu(M_ref, 1).T
    assert joints == list(range(1, n + 1))
    np.testing.assert_allclose(M, M_ref, atol=1e-10 * max(1.0, np.abs(M_ref).max()))
    rnea = pin.rnea(model, data, q, qd, np.zeros(n))
    np.testing.assert_allclose(v + g, rnea, atol=1e-9 * max(1.0, np.abs(rnea).max()))
    pin.framesForwardKinematics(model, data, q)
    np.testing.assert_allclose(chain.tip(q), data.oMf[model.getFrameId("tip")].translation, atol=1e-12)


@pytest.mark.parametrize(("edit", "message"), [
    (lambda s: s.update(actuated="crank_left"), "'actuated' must be a list of joint names"),
    (lambda s: s.update(platform=3), "'platform' must be a table"),
    (lambda s: s["closures"].__setitem__(0, "oops"), r"'closures\[0\]' must be a table"),
    (lambda s: s.update(gravity=[0.0, "down", 0.0]), "'gravity' must be three finite numbers"),
])
def test_closure_files_of_the_wrong_types_are_named(tmp_path, edit, message):
    """A closure file whose keys have the wrong types is refused naming the key, not an
    AttributeError."""
    import shutil
    import tomllib

    from freefloat import FreefloatError
    from freefloat.parallel.closed_chain import read_closures
    from freefloat.paths import URDF_DIR

    from .conftest import toml_text

    spec = tomllib.loads((URDF_DIR / "five_bar.closure.toml").read_text())
    edit(spec)
    shutil.copy(URDF_DIR / "five_bar.urdf", tmp_path / "five_bar.urdf")
    (tmp_path / "c.toml").write_text(toml_text(spec))
    with pytest.raises(FreefloatError, match=message):
        read_closures(tmp_path / "c.toml")


REVOLUTE = REPO / "urdf" / "five_bar_revolute.closure.toml"


@pytest.mark.parametrize("dynamics", ["closed_tree", "constraint_dynamics"])
def test_the_5r_closed_by_a_revolute_moves_as_the_point_closed_5r(loaded, dynamics):
    """The 5R closed by a revolute (5 rows, 3 of them redundant in the plane) on its spanning tree,
    by freefloat's constrained dynamics and by Pinocchio's (the hinge as two point contacts), has
    Orsino's accelerations of the point-closed 5R (to 1e-9 relative) at assembled states."""
    from freefloat.parallel.free_base import BaseBody, FloatingMechanism

    revolute = load_closed_chain(REVOLUTE)
    tree = FloatingMechanism(revolute, REVOLUTE, BaseBody("fixed"))
    plant = tree.plant(dynamics=dynamics)
    rng = np.random.default_rng(4)
    for point in ([0.07, 0.17], [-0.03, 0.2], [0.02, 0.13]):
        q, qd = state(loaded.mechanism, point, rng.normal(size=2))
        u = rng.normal(size=2) * 0.05
        ours = plant.acceleration(*tree.tree_state(q, qd), u)
        orsino = loaded.pinocchio_q(loaded.mechanism.forward(q, qd, u))
        assert np.abs(ours - orsino).max() <= 1e-9 * np.abs(orsino).max()


def test_a_revolute_closure_out_of_the_loop_plane_is_refused(tmp_path):
    """A hinge turned into the 5R's plane (its tip frame rolled 90 deg): Orsino's point model would
    not be exact, so loading it as a tip-to-tip mechanism names the closure and the first joint."""
    urdf = (REPO / "urdf" / "five_bar.urdf").read_text()
    old = '<child link="c1_ee"/>\n    <origin xyz="0.15 0 0" rpy="0 0 0"/>'
    assert old in urdf
    (tmp_path / "five_bar.urdf").write_text(urdf.replace(old, old.replace('rpy="0 0 0"', 'rpy="1.5707963267948966 0 0"')))
    (tmp_path / "c.toml").write_text(REVOLUTE.read_text())
    with pytest.raises(FreefloatError, match=r"'closures\[0\]' is a revolute closure, but joint 'c1_joint1' turns "
                                             r"about a direction out of its hinge's plane"):
        load_closed_chain(tmp_path / "c.toml")


JOINT_TERMS = """slip_speed = 0.02
[joints.c1_joint1]
armature = 2.0e-3
damping = 1.0e-3
friction = 0.04
[joints.c2_joint1]
armature = 3.0e-3
damping = 2.0e-3
friction = 0.03
[joints.c1_joint2]
damping = 5.0e-4
friction = 0.01
"""


@pytest.fixture(scope="module")
def with_terms(tmp_path_factory):
    """The 5R's closure file with armature and friction on three joints (``[joints]``)."""
    folder = tmp_path_factory.mktemp("terms")
    (folder / "five_bar.urdf").write_text((REPO / "urdf" / "five_bar.urdf").read_text())
    (folder / "m.toml").write_text(CLOSURE.read_text().replace("[platform]", JOINT_TERMS + "\n[platform]"))
    return load_closed_chain(folder / "m.toml")


def test_joint_terms_reach_both_models(with_terms):
    """[joints] puts each armature in Pinocchio's model.armature and on Orsino's chains, and each
    friction (slip speed 0.02) in the closed chain's friction and the chains'."""
    mech, model = with_terms.mechanism, with_terms.model
    armature = with_terms.pinocchio_q(np.concatenate([np.zeros(2)] + [c.armature for c in mech.chains]))
    np.testing.assert_array_equal(armature, model.armature)
    np.testing.assert_array_equal(with_terms.friction.coulomb, [0.04, 0.01, 0.03, 0.0])
    assert with_terms.friction.slip_speed == mech.chains[0].friction.slip_speed == 0.02
    assert not mech.rigid and mech.core is None and load_closed_chain(CLOSURE).mechanism.core is not None


def test_forward_dynamics_with_armature_and_friction_matches_pinocchio(with_terms):
    """Orsino's eq 129 with armature and friction (compiled rigid terms plus the joint terms, and
    the numpy reference) equals Pinocchio's constraintDynamics with the same armature and
    ``tau - f(v)``, to round-off, at 10 random assembled states spanning the friction's slope."""
    mech, model = with_terms.mechanism, with_terms.model
    plant = ConstraintDynamicsPlant(model, with_terms.constraints, [model.idx_vs[j] for j in with_terms.actuated],
                                    accuracy=1e-14, friction=with_terms.friction)
    rng = np.random.default_rng(3)
    for scale in np.geomspace(1e-3, 3.0, 10):
        q, qd = state(mech, np.array([0.07, 0.17]) + rng.uniform(-0.03, 0.03, 2), scale * rng.normal(size=2))
        tau = rng.normal(size=2)
        reference = plant.acceleration(with_terms.pinocchio_q(q), with_terms.pinocchio_q(qd), tau)
        for m in (mech, mech.reference()):
            np.testing.assert_allclose(with_terms.pinocchio_q(m.forward(q, qd, tau)), reference,
                                       atol=1e-12 * np.abs(reference).max())


def test_inverse_dynamics_overcomes_the_friction(with_terms):
    """The efforts of eqs 130-140 with armature and friction, fed to the forward dynamics, give
    the platform acceleration asked for (1e-9), and differ from the frictionless ones."""
    mech = with_terms.mechanism
    q, qd = state(mech, rates=(0.4, -0.3))
    qdd_sharp = np.array([2.0, -1.0])
    tau, _, qdd = mech.inverse(q, qd[:2], qdd_sharp)
    np.testing.assert_allclose(mech.forward(q, qd, tau)[:2], qdd_sharp, atol=1e-9)
    np.testing.assert_allclose(mech.forward(q, qd, tau), qdd, atol=1e-9)
    assert np.abs(tau - mech.frictionless().inverse(q, qd[:2], qdd_sharp)[0]).min() > 1e-3


@pytest.mark.slow
def test_falling_with_friction_loses_what_friction_dissipates(with_terms):
    """Falling from a moving start for 0.3 s (RK4 at 0.1 ms, Baumgarte 0), the energy Pinocchio
    computes on the tree (1/2 v^T M v with its armature, plus the potential) falls by the work of
    friction (Simpson's rule on the recorded rates), to the integrator's tolerance (1e-9 of the
    energy lost)."""
    from scipy.integrate import simpson

    mech, model = with_terms.mechanism, with_terms.model
    q0, qd0 = state(mech, rates=(0.5, -0.4))
    tel = simulate(mech, q0, qd0, lambda *_: np.zeros(2), 0.3, 1e-4).telemetry
    data = model.createData()

    def energy(q, qd):
        qp, vp = with_terms.pinocchio_q(q), with_terms.pinocchio_q(qd)
        return pin.computeKineticEnergy(model, data, qp, vp) + pin.computePotentialEnergy(model, data, qp)

    E = np.array([energy(q, qd) for q, qd in zip(tel.q, tel.v)])
    lost = simpson((mech.joint_friction(tel.v) * tel.v).sum(axis=1), x=tel.t)
    assert lost > 1e-3
    assert abs(E[0] - E[-1] - lost) < 1e-9 * lost
