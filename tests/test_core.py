"""The compiled core (freefloat.dynamics._core) against the numpy reference of freefloat.gjm.

test_gjm.py pins both backends to Pinocchio and the derivatives to central differences; here the
two implementations are pinned to each other to 1e-12 on random trees (branches, fixed and prismatic
joints, offset base CoM), free and planar bases.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from freefloat import gjm, load_robot

from .conftest import REPO, load_text, random_robots, random_state, robot_from_case

KINEMATICS = ("r0", "R0", "rotation", "origin", "joint_position", "joint_axis", "com", "inertia")


def close(a: np.ndarray, b: np.ndarray) -> bool:
    """Same shape, and equal to 1e-12 relative to the larger magnitude (at least 1)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.abs(a - b).max(initial=0.0) <= 1e-12 * max(1.0, np.abs(b).max(initial=0.0))


def both_backends(factory, case, base, fn):
    """``fn(robot, q, v, backend)`` for the compiled and the numpy backend at a random state of the drawn robot."""
    robot, rng = robot_from_case(factory, case, base=base)
    q, v = random_state(robot, rng)
    return fn(robot, q, v, "compiled"), fn(robot, q, v, "numpy")


@settings(max_examples=40, deadline=None)
@given(random_robots(), st.sampled_from(["free", "planar"]))
def test_compiled_state_equals_numpy_reference(tmp_path_factory, case, base):
    """Every GJMState field and every body kinematics array agrees between the backends to 1e-12."""
    compiled, numpy = both_backends(tmp_path_factory, case, base, gjm.compute)
    for name in gjm.GJMState._fields[:-1]:
        assert close(getattr(compiled, name), getattr(numpy, name)), name
    for name in KINEMATICS:
        assert close(getattr(compiled.kinematics, name), getattr(numpy.kinematics, name)), name


@settings(max_examples=40, deadline=None)
@given(random_robots(), st.sampled_from(["free", "planar"]))
def test_compiled_derivatives_equal_numpy_reference(tmp_path_factory, case, base):
    """dH0, dH0m, dHm and the time derivatives agree between the backends to 1e-12."""
    compiled, numpy = both_backends(tmp_path_factory, case, base, gjm.derivatives)
    for name in gjm.GJMDerivatives._fields:
        assert close(getattr(compiled, name), getattr(numpy, name)), name


def test_state_and_derivatives_come_from_one_state():
    """state_and_derivatives returns the state compute() gives and the derivatives derivatives() gives."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    q, v = random_state(robot, np.random.default_rng(2))
    state, deriv = gjm.state_and_derivatives(gjm.model_of(robot), q, v)
    np.testing.assert_array_equal(state.Hstar, gjm.compute(robot, q, v).Hstar)
    np.testing.assert_array_equal(deriv.dHm, gjm.derivatives(robot, q, v).dHm)


def test_unknown_backend_is_refused():
    """An unknown backend name raises ValueError listing the valid ones."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    with pytest.raises(ValueError, match="compiled, numpy"):
        gjm.compute(robot, robot.neutral(), np.zeros(robot.model.nv), backend="fortran")


def test_wrong_state_size_is_named():
    """A configuration of the wrong size raises ValueError naming q and both sizes, not a crash,
    in the core itself (internal callers skip gjm.compute's own check, test_state.py)."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    with pytest.raises(ValueError, match=r"q: expected 23 numbers, got 22"):
        gjm.model_of(robot).core.compute(robot.neutral()[:-1], np.zeros(robot.model.nv))


def test_a_used_model_pickles_and_gives_the_same_accelerations():
    """A GJM model whose compiled core has run survives pickling (for worker processes) unchanged."""
    import pickle

    from freefloat.dynamics.models import make_model

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    q, v = random_state(robot, np.random.default_rng(3))
    tau = np.concatenate((np.zeros(6), np.ones(robot.n_joints)))
    model = make_model("standard_corrected", robot)
    before = model.acceleration(q, v, tau)
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(model)).acceleration(q, v, tau), before)


def test_continuous_joints_read_their_angle_from_cos_and_sin(tmp_path):
    """A tree of continuous joints (q holds cos, sin) gives the same GJM in both backends."""
    from .conftest import random_urdf

    text = random_urdf(np.random.default_rng(7), 5, fixed_share=0.0).replace('type="revolute"', 'type="continuous"')
    text = text.replace('type="prismatic"', 'type="continuous"')
    robot = load_text(tmp_path, text)
    assert robot.model.nq == robot.model.nv + 1 + robot.n_joints
    q, v = random_state(robot, np.random.default_rng(8))
    compiled, numpy = gjm.compute(robot, q, v), gjm.compute(robot, q, v, backend="numpy")
    for name in gjm.GJMState._fields[:-1]:
        assert close(getattr(compiled, name), getattr(numpy, name)), name


#: Damage done to a valid state: (what, which of q / v, value or scale of a unit-norm block).
DAMAGES = (("nan", "q", np.nan), ("nan", "v", np.nan), ("inf", "v", -np.inf), ("large", "q", 2e15),
           ("large", "v", -2e15), ("unit", "q", 1.0 + 3e-6), ("unit", "q", 1.0 - 3e-6),
           ("unit", "q", 1.0 + 3e-7), ("unit", "q", 0.0))


@settings(max_examples=60, deadline=None)
@given(random_robots(max_links=5), st.sampled_from(["free", "planar"]), st.booleans(),
       st.sampled_from((None, *DAMAGES)), st.integers(0, 2**16))
def test_core_admits_exactly_the_states_check_state_accepts(tmp_path_factory, case, base, continuous, damage, where):
    """GJM.admissible, the compiled check gjm.compute and gjm.derivatives run instead of
    check_state, is True exactly when check_state accepts the state: valid states, a NaN, an
    infinity or a value above 1e15 anywhere in q or v, a unit-norm block (base quaternion or
    (cos, sin), a continuous joint's (cos, sin)) scaled off norm 1 by more or less than 1e-6."""
    from freefloat.errors import InvalidArgument
    from freefloat.robot.state import check_state

    seed, text = case
    if continuous:
        text = text.replace('type="revolute"', 'type="continuous"')
    robot = load_text(tmp_path_factory.mktemp("r"), text, base=base)
    q, v = random_state(robot, np.random.default_rng(seed))
    if damage is not None:
        kind, target, value = damage
        if kind == "unit":
            model = robot.model
            blocks = [(model.idx_qs[j], model.nqs[j]) for j in range(1, model.njoints) if model.nqs[j] != model.nvs[j]]
            start, size = blocks[where % len(blocks)]
            unit = 4 if size == 7 else 2  # the free-flyer's quaternion, else a (cos, sin) pair
            q[start + size - unit:start + size] *= value
        else:
            array = q if target == "q" else v
            array[where % len(array)] = value
    try:
        check_state(robot, q, v)
        accepted = True
    except InvalidArgument:
        accepted = False
    assert gjm.model_of(robot).admissible(q, v) == accepted


def test_compute_results_are_not_overwritten_by_the_next_call():
    """The dense outputs the core hands to numpy without a copy (Hm, H*, Jm, J*) belong to the
    returned state: a second compute at another state leaves the first state's arrays as they
    were, and they can be written to."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    rng = np.random.default_rng(4)
    first = gjm.compute(robot, *random_state(robot, rng))
    kept = {name: getattr(first, name).copy() for name in ("Hm", "Hstar", "Jm", "Jstar")}
    second = gjm.compute(robot, *random_state(robot, rng))
    for name, value in kept.items():
        assert np.array_equal(getattr(first, name), value) and not np.array_equal(getattr(second, name), value), name
        getattr(first, name)[0, 0] += 1.0
