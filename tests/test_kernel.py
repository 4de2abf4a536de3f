"""The dynamics kernel (freefloat.dynamics.kernel) against Pinocchio's ABA on random trees: one
state and four in lockstep, with gravity, joint forces and external wrenches, in both instruction
sets; and what it refuses."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings

from freefloat.dynamics import kernel
from freefloat.dynamics.kernel import LANES, Kernel
from freefloat.errors import InvalidArgument

from .conftest import random_trees

#: The instruction sets this CPU runs (the baseline always; AVX2 where it has it).
ISAS = ["baseline"] + (["avx2"] if kernel.isa() == "avx2" else [])
#: Largest difference to pin.aba, relative to the largest acceleration (or 1).
TOLERANCE = 1e-12
ROOTS = {"free": pin.JointModelFreeFlyer(), "planar": pin.JointModelPlanar()}


@pytest.fixture(params=ISAS)
def isa(request):
    """Every kernel of the test evaluates with this instruction set; the default after it."""
    default = kernel.isa()
    kernel.set_isa(request.param)
    yield request.param
    kernel.set_isa(default)


def tree_model(text: str, base: str) -> pin.Model:
    """Pinocchio's model of the URDF ``text`` on a free, planar or fixed base, gravity on."""
    return pin.buildModelFromXML(text, ROOTS[base]) if base in ROOTS else pin.buildModelFromXML(text)


def random_inputs(model: pin.Model, rng: np.random.Generator):
    """A random state (unit quaternion, unit (cos, sin) of continuous joints), joint forces, and
    external wrenches on every body: q, v, tau, and fext as pin.aba takes it and as (njoints - 1, 6)."""
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    v, tau = rng.normal(size=model.nv), 10.0 * rng.normal(size=model.nv)
    forces = 10.0 * rng.normal(size=(model.njoints - 1, 6))
    return q, v, tau, [pin.Force.Zero(), *(pin.Force(f) for f in forces)], forces


def assert_aba_equal(got: np.ndarray, expected: np.ndarray) -> None:
    assert np.abs(got - expected).max() <= TOLERANCE * max(1.0, np.abs(expected).max())


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(random_trees(max_links=10))
def test_kernel_equals_pinocchio_on_random_trees(isa, case):
    """On random trees (free, planar and fixed bases; revolute, continuous, prismatic and fixed
    joints on general and frame axes) the kernel gives pin.aba's accelerations, with gravity, joint
    forces and external wrenches, to 1e-12 relative."""
    seed, text, base = case
    model = tree_model(text, base)
    data, k = model.createData(), Kernel(model)
    rng = np.random.default_rng(seed)
    assert k.root == base
    for _ in range(3):
        q, v, tau, fext, forces = random_inputs(model, rng)
        assert_aba_equal(k.aba(q, v, tau), pin.aba(model, data, q, v, tau))
        assert_aba_equal(k.aba(q, v, tau, forces), pin.aba(model, data, q, v, tau, fext))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(random_trees(max_links=10))
def test_lockstep_lanes_each_equal_pinocchio(isa, case):
    """Four states of one tree in lockstep, each with its own wrenches, give pin.aba's
    accelerations state by state, to 1e-12 relative."""
    seed, text, base = case
    model = tree_model(text, base)
    data, k = model.createData(), Kernel(model)
    rng = np.random.default_rng(seed)
    inputs = [random_inputs(model, rng) for _ in range(LANES)]
    q, v, tau, forces = (np.array([x[i] for x in inputs]) for i in (0, 1, 2, 4))
    with_wrenches = k.aba_lanes(q, v, tau, forces)
    without = k.aba_lanes(q, v, tau)
    for lane, (q1, v1, tau1, fext, _) in enumerate(inputs):
        assert_aba_equal(with_wrenches[lane], pin.aba(model, data, q1, v1, tau1, fext))
        assert_aba_equal(without[lane], pin.aba(model, data, q1, v1, tau1))


@settings(max_examples=20, deadline=None)
@given(random_trees(max_links=10))
def test_a_state_gets_the_same_numbers_alone_or_in_a_lane_in_either_instruction_set(case):
    """The kernel rounds every product and sum on its own: a state's accelerations, with wrenches,
    are the same bit for bit alone and in any lane of the lockstep, in the baseline and in AVX2
    (what makes a lockstep run equal its own run bit for bit)."""
    seed, text, base = case
    model = tree_model(text, base)
    rng = np.random.default_rng(seed)
    inputs = [random_inputs(model, rng) for _ in range(LANES)]
    q, v, tau, forces = (np.array([x[i] for x in inputs]) for i in (0, 1, 2, 4))
    default, k = kernel.isa(), Kernel(model)
    try:
        got = []
        for name in ISAS:
            kernel.set_isa(name)
            got.append(k.aba_lanes(q, v, tau, forces))
            got.append(np.array([k.aba(*(x[lane] for x in (q, v, tau, forces))) for lane in range(LANES)]))
            got.append(k.aba_lanes(q[::-1], v[::-1], tau[::-1], forces[::-1])[::-1])  # other lanes
    finally:
        kernel.set_isa(default)
    for other in got[1:]:
        np.testing.assert_array_equal(other, got[0])


def test_a_far_robot_has_the_numbers_of_a_near_one():
    """The kernel's numbers do not depend on where the free-flying robot is: 1e6 m from the origin
    it gives the accelerations it gives at the origin to round-off (pin.aba in the WORLD
    convention, at the world origin, was off by 1.6e-2 relative there)."""
    from .conftest import random_urdf

    model = tree_model(random_urdf(np.random.default_rng(4), 8), "free")
    q, v, tau, _, _ = random_inputs(model, np.random.default_rng(5))
    far = q.copy()
    far[:3] += 1e6
    k = Kernel(model)
    assert_aba_equal(k.aba(far, v, tau), k.aba(q, v, tau))


def test_other_bodies_give_the_other_models_accelerations():
    """set_bodies (a batch's varied masses) gives the accelerations of the model with those
    bodies, as a kernel built from it."""
    from .conftest import random_urdf

    model = tree_model(random_urdf(np.random.default_rng(6), 6), "free")
    heavier = model.copy()
    for inertia in heavier.inertias[1:]:
        inertia.mass *= 1.7
        inertia.lever *= 0.5
    q, v, tau, _, _ = random_inputs(model, np.random.default_rng(7))
    k = Kernel(model)
    k.set_bodies(heavier)
    assert_aba_equal(k.aba(q, v, tau), pin.aba(heavier, heavier.createData(), q, v, tau))


def test_a_joint_the_kernel_does_not_have_is_named():
    """A tree with a spherical joint, or a planar joint that is not the root, is refused with the
    joint named; the compiled plant then keeps Pinocchio's ABA."""
    for joint, name in ((pin.JointModelSpherical(), "ball"), (pin.JointModelPlanar(), "slider")):
        model = pin.Model()
        body = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
        model.appendBodyToJoint(body, pin.Inertia.Random(), pin.SE3.Identity())
        child = model.addJoint(body, joint, pin.SE3.Random(), name)
        model.appendBodyToJoint(child, pin.Inertia.Random(), pin.SE3.Identity())
        reason = kernel.refusal(model)
        assert reason is not None and f"joint '{name}'" in reason
        with pytest.raises(InvalidArgument, match=f"joint '{name}'"):
            Kernel(model)


def test_an_unknown_instruction_set_is_refused():
    """set_isa names what it takes."""
    with pytest.raises(InvalidArgument, match="'avx2' or 'baseline'"):
        kernel.set_isa("sse9")
