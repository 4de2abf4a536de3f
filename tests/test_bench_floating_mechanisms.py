"""The moving-base mechanism bench scenes: MuJoCo's model is the same system as freefloat's tree
(mass matrix, free-motion acceleration, closures closed at the start, state map both ways),
both sides converge to the reference, and the sweep's rows are consistent."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from freefloat.errors import InvalidArgument
from freefloat.lab.bench.in_mujoco.mechanism import MujocoMechanism
from freefloat.lab.bench.race.scene import Method
from freefloat.lab.bench.scenes.floating_mechanisms import FLOATING_SCENES, floating_mechanism_scene

mujoco = pytest.importorskip("mujoco")


@pytest.fixture(scope="module")
def scenes():
    """Both scenes over 10 control periods."""
    return {name: floating_mechanism_scene(name, 10 * {"five_bar_free_base": 1e-4}.get(name, 1e-3))
            for name in FLOATING_SCENES}


def moving_state(scene, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The scene's start with the base moved, turned and moving, and every joint moving."""
    model = scene.floating.model
    rng = np.random.default_rng(seed)
    base = pin.neutral(model)
    root = scene.floating.root_nv
    base_motion = np.zeros(model.nv)
    base_motion[:root] = rng.uniform(-1.0, 1.0, root)
    q = scene.q0.copy()
    q[:scene.floating.root_nq] = pin.integrate(model, base, base_motion)[:scene.floating.root_nq]
    return q, rng.normal(size=model.nv)


@pytest.mark.parametrize("name", list(FLOATING_SCENES))
def test_mujoco_has_the_trees_mass_matrix_and_free_motion(scenes, name):
    """MuJoCo's joint-space mass matrix equals Pinocchio's CRBA (S^T M S), and with its equalities off its
    acceleration under efforts equals Pinocchio's ABA on the open tree, at a moved, turned and moving base."""
    scene = scenes[name]
    sim = MujocoMechanism(scene.tree(), "RK4", scene.period)
    q, v = moving_state(scene)
    assert sim.mass_matrix_gap(q) < 1e-12
    assert sim.free_acceleration_gap(q, v, np.linspace(-1.0, 1.0, len(scene.floating.actuated))) < 1e-10


@pytest.mark.parametrize("name", list(FLOATING_SCENES))
def test_state_map_goes_both_ways(scenes, name):
    """The tree's state written into MuJoCo and read back is the same state."""
    scene = scenes[name]
    sim = MujocoMechanism(scene.tree(), "Euler", scene.period)
    q, v = moving_state(scene, 1)
    sim.set_state(q, v)
    back_q, back_v = sim.state()
    np.testing.assert_allclose(pin.difference(scene.floating.model, q, back_q), 0.0, atol=1e-14)
    np.testing.assert_allclose(back_v, v, atol=1e-14)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(FLOATING_SCENES))
def test_closures_hold_at_the_start_on_both_sides(scenes, name):
    """At the scene's start every closure is closed: in freefloat's tree and in MuJoCo's equality residuals."""
    scene = scenes[name]
    sim = MujocoMechanism(scene.tree(), "RK4", scene.period)
    sim.set_state(scene.q0, scene.v0)
    mujoco.mj_forward(sim.model, sim.data)
    assert sim.data.nefc > 0 and np.abs(sim.data.efc_pos).max() < 1e-12
    start = scene.reference()
    assert scene.errors(start, start)["state_error"] == 0.0
    assert scene.errors(type(start)(start.q[:1], scene.v0), start)["constraint_drift"] < 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("name", list(FLOATING_SCENES))
def test_both_sides_converge_to_the_reference(scenes, name):
    """freefloat's RK4 at half the period ends within 1e-8 of the DOP853 reference, and MuJoCo's RK4 (soft
    closures) comes closer as its step shrinks."""
    scene = scenes[name]
    ref = scene.reference()
    label = scene.model_label
    ours = scene.errors(scene.run(Method("freefloat", "rkmk4", scene.period / 2, "compiled", label))(), ref)
    assert ours["state_error"] < 1e-8
    theirs = [scene.errors(scene.run(Method("mujoco", "RK4", h))(), ref)["state_error"]
              for h in (scene.period, scene.period / 10)]
    assert theirs[1] < theirs[0], theirs


@pytest.mark.slow
@pytest.mark.parametrize("name", list(FLOATING_SCENES))
def test_quick_sweep_rows_are_consistent(name):
    """The quick sweep has freefloat and MuJoCo rows, each with finite errors and a loop held closed to 0.1 mm,
    and the reference has no error against itself."""
    scene = floating_mechanism_scene(name, quick=True)
    ref = scene.reference()
    methods = scene.methods()
    assert {m.package for m in methods} == {"freefloat", "mujoco"}
    for method in methods:
        errors = scene.errors(scene.run(method)(), ref)
        assert set(errors) == {"state_error", "constraint_drift"}
        assert all(math.isfinite(e) for e in errors.values()) and errors["constraint_drift"] < 1e-4, (method, errors)


def test_unknown_scene_and_bad_duration_are_refused():
    """An unknown name lists the valid ones; a duration that is not whole control periods is named."""
    with pytest.raises(InvalidArgument, match="five_bar_free_base, rsu_ppap_free_base"):
        floating_mechanism_scene("six_bar_free_base")
    with pytest.raises(InvalidArgument, match="whole number of 0.001 s control periods"):
        floating_mechanism_scene("rsu_ppap_free_base", 0.0105)


def test_unknown_method_fails_naming_it(scenes):
    """A method the scene does not sweep fails naming it."""
    with pytest.raises(InvalidArgument, match="pinocchio rkmk4"):
        scenes["five_bar_free_base"].run(Method("pinocchio", "rkmk4", 1e-4))
