"""ParallelMechanism's numerics beside the mechanisms: batches, rotation logs, singular and bad input."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

from freefloat import FreefloatError
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.mechanism import BACKENDS, AngularConstraints, log3
from freefloat.parallel.rsu_ppap import assembly_guess, load_data, load_rsu_ppap, reference_path

from .loops import simulate

P = FiveBarParameters()
DATA = load_data()


@pytest.fixture(scope="module")
def rsu_ppap():
    return load_rsu_ppap().mechanism


def test_rotation_log_matches_pinocchio_up_to_pi():
    """log3 equals Pinocchio's log3 at random rotations, tiny ones and ones 1e-9 rad short of pi."""
    rng = np.random.default_rng(0)
    axes = rng.normal(size=(20, 3))
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    vectors = np.vstack((rng.normal(size=(20, 3)), 1e-9 * axes, (np.pi - 1e-9) * axes))
    R = np.array([pin.exp3(v) for v in vectors])
    np.testing.assert_allclose(log3(R), [pin.log3(r) for r in R], atol=1e-6)
    np.testing.assert_allclose(log3(R[:40]), vectors[:40], atol=1e-12)


def test_batched_terms_and_inverse_equal_point_by_point(rsu_ppap):
    """terms() and inverse() on a (2, 2) batch of states equal the same calls point by point."""
    rng = np.random.default_rng(1)
    x = np.array(DATA["home"]) + rng.uniform(-0.04, 0.04, (2, 2, 3))
    q = rsu_ppap.assemble(x, assembly_guess(DATA, DATA["home"]))
    qd = np.einsum("...ij,...j->...i", rsu_ppap.velocity_map(q), rng.normal(size=(2, 2, 3)))
    qdd_sharp = rng.normal(size=(2, 2, 3))
    batched = rsu_ppap.terms(q, qd)
    tau, *_ = rsu_ppap.inverse(q, qd[..., :3], qdd_sharp)
    for i in range(2):
        for j in range(2):
            for ours, single in zip(batched, rsu_ppap.terms(q[i, j], qd[i, j])):
                np.testing.assert_allclose(ours[i, j], single, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(tau[i, j], rsu_ppap.inverse(q[i, j], qd[i, j, :3], qdd_sharp[i, j])[0], rtol=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
def test_path_through_a_stretched_pose_follows_point_by_point_continuation(rsu_ppap, backend):
    """A path that touches the parallelogram's stretched pose (radius 8 cm, 2000 points; numpy:
    blocks of 512 halved where the prediction fails, compiled: continuation point by point) gives
    the poses of assembling point by point from the previous pose (no jump in the joint path), and
    at each pose the point-by-point efforts (near the stretched pose they reach 1.5 kN m and turn
    1e-9 pose differences into 1 %, so they are compared at the same pose)."""
    x, xd, xdd = reference_path(np.linspace(0.0, 1.0, 2000), DATA, radius=0.08)
    tau, q = replace(rsu_ppap, backend=backend).inverse_trajectory(x, xd, xdd, assembly_guess(DATA, x[0]))
    pose = q[0]
    for i in range(0, len(x)):
        pose = rsu_ppap.assemble(x[i], pose[3:])
        if i % 100 == 0:
            np.testing.assert_allclose(q[i], pose, atol=1e-8)
            np.testing.assert_allclose(tau[i], rsu_ppap.inverse(q[i], xd[i], xdd[i])[0], rtol=1e-9,
                                       atol=1e-9 * np.abs(tau[i]).max())
    np.testing.assert_allclose(q[-1], pose, atol=1e-8)


def test_singular_passive_jacobian_is_an_error():
    """C and the inverse dynamics are refused, not least-squared, where A° is singular."""
    mech = five_bar(P)
    A = np.zeros((4, 6))
    A[:, :2] = 1.0
    with pytest.raises(FreefloatError, match="singular"):
        mech.passive_solve(A, A[:, :2])


@pytest.mark.parametrize(("q_sharp", "guess", "message"), [
    (np.array([0.07, 0.17, 0.0]), np.zeros(4), "need 2 entries and the guess 4"),
    (np.array([0.07, np.nan]), np.zeros(4), "not finite"),
])
def test_assemble_names_bad_input(q_sharp, guess, message):
    """Wrong sizes or NaN platform coordinates fail with a message, not an IndexError or NaN."""
    with pytest.raises(FreefloatError, match=message):
        five_bar(P).assemble(q_sharp, guess)


def test_path_arrays_must_match():
    """inverse_trajectory refuses rates of another length than the positions."""
    x = np.array([[0.07, 0.17], [0.07, 0.171]])
    with pytest.raises(FreefloatError, match=r"shape \(N, 2\)"):
        five_bar(P).inverse_trajectory(x, x[:1], x, elbow_guess(P, x[0]))


def test_simulation_stops_when_an_angular_constraint_comes_apart(rsu_ppap):
    """A start with the parallelogram's coupler turned 1.5 rad (an angular constraint off by more
    than 1 rad) stops in the first step, keeping the start, instead of running on."""
    q0 = rsu_ppap.assemble(np.array(DATA["home"]), assembly_guess(DATA, DATA["home"]))
    q0[3 + 12 + 2] += 1.5                       # ppap_coupler
    run = simulate(rsu_ppap, q0, np.zeros_like(q0), lambda *_: np.zeros(3), 0.01, 1e-3)
    assert run.status == "diverged" and "came apart" in run.message
    assert len(run.telemetry.t) == 1


def test_angular_constraints_check_their_shapes():
    """Q with a column count that does not fit the tip references fails naming the shapes."""
    with pytest.raises(FreefloatError, match="shapes do not agree"):
        AngularConstraints(P=np.zeros((1, 3)), Q=np.zeros((1, 6)), R=np.zeros((1, 16)), reference=np.tile(np.eye(3), (3, 1, 1)),
                           offset=np.zeros(1))


def test_simulation_keeps_its_samples_when_a_singular_pose_stops_it(monkeypatch):
    """When the forward dynamics fail on the 4th step (a singular pose), the loop returns the
    three steps it finished (and the start) instead of raising and losing them."""
    mech = five_bar(P)
    q0 = mech.assemble(np.array([0.07, 0.17]), elbow_guess(P, np.array([0.07, 0.17])))
    calls = {"n": 0}
    forward = type(mech).forward

    def failing(self, q, qd, tau, baumgarte=0.0):
        calls["n"] += 1
        if calls["n"] > 12:   # RK4: 4 evaluations per step
            raise FreefloatError("singular")
        return forward(self, q, qd, tau, baumgarte)

    monkeypatch.setattr(type(mech), "forward", failing)
    run = simulate(mech, q0, np.zeros(6), lambda *_: np.zeros(2), 0.01, 1e-3, backend="python")
    assert run.status == "diverged" and "singular" in run.message
    tel = run.telemetry
    assert len(tel.t) == len(tel.q) == len(tel.drift) == 4
    assert np.isfinite(tel.q).all()


@pytest.mark.slow
def test_blocks_grow_back_after_successes_on_a_coarse_path(monkeypatch):
    """On eq 189's circle wound 8 times in 4000 points, inverse_trajectory assembles fewer than
    twice the points asked (resetting to 512 after each block assembled 7.7 times as many), and
    its efforts equal point-by-point continuation."""
    from freefloat.parallel.mechanism import ParallelMechanism
    from freefloat.parallel.sliding_mode import circle_reference

    mech = five_bar(P).reference()  # the numpy blocks; the compiled path goes point by point
    x, xd, xdd = (np.array(v) for v in zip(*(circle_reference(t) for t in np.linspace(0.0, 8 * 2 * np.pi / 28.57, 4000))))
    assembled, assemble = [0], ParallelMechanism.assemble

    def counting(self, q_sharp, guess, *args, **kwargs):
        assembled[0] += len(np.atleast_2d(q_sharp))
        return assemble(self, q_sharp, guess, *args, **kwargs)

    monkeypatch.setattr(ParallelMechanism, "assemble", counting)
    tau, _ = mech.inverse_trajectory(x, xd, xdd, elbow_guess(P, x[0]))
    assert assembled[0] < 2 * len(x)
    monkeypatch.setattr(ParallelMechanism, "assemble", assemble)
    looped = []
    q = np.concatenate((x[0], elbow_guess(P, x[0])))
    for i in range(len(x)):
        q = mech.assemble(x[i], q[mech.p:])
        looped.append(mech.inverse(q, xd[i], xdd[i])[0])
    assert np.abs(np.array(looped) - tau).max() < 1e-9 * max(1.0, np.abs(tau).max())


def mechanisms_on_their_paths():
    """(name, mechanism, (x, xd, xdd), guess) for the 5R on eq 189's circle and the 2RSU+PPaP on its path."""
    from freefloat.parallel.sliding_mode import circle_reference

    five = five_bar(P)
    x5 = [np.array(v) for v in zip(*(circle_reference(t) for t in np.linspace(0.0, 0.22, 300)))]
    xr = reference_path(np.linspace(0.0, 1.0, 300), DATA)
    return [("5R", five, x5, elbow_guess(P, x5[0][0])),
            ("2RSU+PPaP", load_rsu_ppap().mechanism, xr, assembly_guess(DATA, xr[0][0]))]


@pytest.mark.parametrize(("name", "mech", "path", "guess"), mechanisms_on_their_paths())
def test_compiled_points_equal_the_numpy_reference(name, mech, path, guess):
    """At poses along each path, the compiled assembly, closure (residual and A), terms
    (A, b, C, M', v', g'), forward dynamics (eq 129, Baumgarte 100) and inverse dynamics
    (eqs 130-140) equal the numpy reference to 1e-12 relative."""
    assert mech.core is not None and mech.reference().core is None
    ref, rng = mech.reference(), np.random.default_rng(5)
    x, xd, xdd = path
    for i in range(0, len(x), 37):
        q = mech.assemble(x[i], guess)
        np.testing.assert_allclose(q, ref.assemble(x[i], guess), atol=1e-12)
        qd = ref.velocity_map(q) @ xd[i]
        perturbed = q + 1e-3 * rng.normal(size=len(q))  # off the manifold: a nonzero residual
        for ours, theirs in [*zip(mech._closure(perturbed), ref._closure(perturbed)), *zip(mech.terms(q, qd), ref.terms(q, qd))]:
            assert np.abs(ours - theirs).max() <= 1e-12 * max(1.0, np.abs(theirs).max()), name
        tau = rng.normal(size=len(mech.actuated))
        expected = ref.forward(q, qd, tau, 100.0)
        assert np.abs(mech.forward(q, qd, tau, 100.0) - expected).max() <= 1e-12 * np.abs(expected).max(), name
        for ours, theirs in zip(mech.inverse(q, xd[i], xdd[i]), ref.inverse(q, xd[i], xdd[i])):
            assert np.abs(ours - theirs).max() <= 1e-12 * max(1.0, np.abs(theirs).max()), name


@pytest.mark.parametrize(("name", "mech", "path", "guess"), mechanisms_on_their_paths())
def test_compiled_trajectory_equals_the_numpy_blocks(name, mech, path, guess):
    """inverse_trajectory by compiled continuation equals the numpy blocks: poses to 1e-10 and
    efforts to 1e-9 relative (both Newton solutions stop at a 1e-12 residual)."""
    tau, q = mech.inverse_trajectory(*path, guess)
    tau_ref, q_ref = mech.reference().inverse_trajectory(*path, guess)
    assert np.abs(q - q_ref).max() < 1e-10, name
    assert np.abs(tau - tau_ref).max() < 1e-9 * np.abs(tau_ref).max(), name


def test_compiled_forward_refuses_a_singular_pose():
    """The compiled forward dynamics raises FreefloatError naming the singular A°, not a NaN."""
    mech = five_bar(P)
    q = np.zeros(6)  # all links folded on the x axis: A° singular
    with pytest.raises(FreefloatError, match="singular"):
        mech.forward(q, np.zeros(6), np.zeros(2), 0.0)


def test_compiled_trajectory_names_an_unreachable_pose():
    """A path leaving the workspace fails with the numpy reference's message, naming the pose."""
    mech = five_bar(P)
    x = np.array([[0.07, 0.17], [0.07, 0.5]])
    with pytest.raises(FreefloatError, match=r"cannot assemble the mechanism at platform coordinates \[0.07, 0.5\]"):
        mech.inverse_trajectory(x, np.zeros_like(x), np.zeros_like(x), elbow_guess(P, x[0]))


def test_unknown_mechanism_backend_is_refused():
    """A mechanism with an unknown backend raises FreefloatError listing the valid ones."""
    with pytest.raises(FreefloatError, match="compiled, numpy"):
        replace(five_bar(P), backend="cuda")


def test_a_used_mechanism_pickles_and_gives_the_same_dynamics():
    """A mechanism whose compiled core has run survives pickling (for Dask workers) unchanged."""
    import pickle

    mech = five_bar(P)
    x = np.array([0.07, 0.17])
    q = mech.assemble(x, elbow_guess(P, x))
    qd = mech.velocity_map(q) @ np.array([0.1, -0.2])
    before = mech.forward(q, qd, np.array([0.3, -0.1]), 100.0)
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(mech)).forward(q, qd, np.array([0.3, -0.1]), 100.0), before)
