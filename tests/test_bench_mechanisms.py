"""The closed-chain bench scenes: convergence of every formulation to the reference, RK4's order,
Baumgarte's effect on drift, the shared coordinates, and bad input."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from freefloat.dynamics.plants import CoupledChainPlant
from freefloat.errors import InvalidArgument
from freefloat.lab.bench.race.scene import Method
from freefloat.lab.bench.scenes.mechanism_plants import constraint_dynamics_plant
from freefloat.lab.bench.scenes.mechanisms import MECHANISM_SCENES, held_run, mechanism_scene

STABILISED = "orsino baumgarte 100"


@pytest.fixture(scope="module")
def scenes():
    """Both scenes over 20 ms (20 control periods)."""
    return {name: mechanism_scene(name, 0.02) for name in MECHANISM_SCENES}


@pytest.fixture(scope="module")
def references(scenes):
    return {name: scene.reference() for name, scene in scenes.items()}


def state_error(scene, reference, method: Method) -> float:
    return scene.errors(scene.run(method)(), reference)["state_error"]


@pytest.mark.parametrize("name", list(MECHANISM_SCENES))
def test_rk4_error_falls_at_fourth_order(scenes, references, name):
    """Halving RK4's step from the control period (the law held) divides the final-state error by about 16."""
    scene, ref = scenes[name], references[name]
    steps = [scene.period / 2**k for k in range(3)]
    errors = [state_error(scene, ref, Method("freefloat", "rkmk4", h, "compiled", STABILISED)) for h in steps]
    orders = [math.log2(a / b) for a, b in itertools.pairwise(errors)]
    assert all(3.6 < order < 4.4 for order in orders), (errors, orders)


@pytest.mark.parametrize("name", list(MECHANISM_SCENES))
@pytest.mark.parametrize("package, model", [("freefloat", STABILISED), ("pinocchio", "constraintDynamics baumgarte 100")])
def test_formulations_converge_to_the_reference(scenes, references, name, package, model):
    """Orsino's model and Pinocchio's constraint dynamics (independent), RK4 at 20 us, end within
    1e-9 of the DOP853 reference in the shared coordinates."""
    loop = "compiled" if package == "freefloat" else "python"
    assert state_error(scenes[name], references[name], Method(package, "rkmk4", 2e-5, loop, model)) < 1e-9


def test_numpy_backend_runs_the_same_loop_as_the_compiled_core(scenes, references):
    """The Python loop on the numpy reference backend and the compiled loop (plant, RKMK4 and the
    computed-torque law in C++) give the same 2RSU+PPaP run to 1e-12."""
    scene, ref = scenes["rsu_ppap"], references["rsu_ppap"]
    compiled, numpy = (scene.run(Method("freefloat", "rkmk4", 1e-3, loop, STABILISED))() for loop in ("compiled", "python"))
    assert np.abs(compiled.q - numpy.q).max() < 1e-12
    assert scene.errors(compiled, ref)["state_error"] > 0.0


def test_baumgarte_holds_the_loop_tighter_with_euler(scenes):
    """Semi-implicit Euler at 0.1 ms: the 5R's loop opens at least 1.5x wider without Baumgarte than with lambda = 100."""
    scene = scenes["five_bar"]
    drift = {model: scene.errors(scene.run(Method("freefloat", "euler", 1e-4, "compiled", model))(),
                                 scene.reference())["constraint_drift"] for model in (STABILISED, "orsino")}
    assert drift["orsino"] > 1.5 * drift[STABILISED] > 0.0, drift


@pytest.mark.slow
@pytest.mark.parametrize("name", list(MECHANISM_SCENES))
def test_pinocchio_baumgarte_gains_match_eq_129(scenes, name):
    """Pinocchio's correctors at Kp = lambda^2, Kd = 2 lambda open the loop as far as Orsino's eq 129 with the same
    lambda (semi-implicit Euler at the control period, within 5 %), and lambda = 0 opens it wider."""
    scene = scenes[name]
    drift = {model: scene.errors(scene.run(Method(package, "euler", scene.period, loop, model))(),
                                 scene.reference())["constraint_drift"]
             for package, loop, model in (("freefloat", "compiled", STABILISED), ("pinocchio", "python", "baumgarte 100"),
                                          ("pinocchio", "python", "no stabilisation"))}
    assert abs(drift["baumgarte 100"] / drift[STABILISED] - 1.0) < 0.05, drift
    assert drift["no stabilisation"] > 1.5 * drift["baumgarte 100"], drift


@pytest.mark.parametrize("name", list(MECHANISM_SCENES))
def test_shared_coordinates_read_the_assembled_start(scenes, name):
    """At the start, the tree's platform point, actuated joints and their rates equal Orsino's q#, actuated coordinates and rates."""
    scene = scenes[name]
    q0, qd0, tree = scene.prepared.q0, scene.prepared.qd0, scene.tree
    p, actuated = len(tree.axes), scene.prepared.setup.plant.actuated
    expected = np.concatenate((q0[:p], q0[actuated], qd0[:p], qd0[actuated]))
    np.testing.assert_allclose(tree.shared(q0[tree.from_orsino], qd0[tree.from_orsino]), expected, atol=1e-12)
    assert tree.gap(q0[tree.from_orsino]) < 1e-12


@pytest.mark.parametrize("name", list(MECHANISM_SCENES))
def test_pinocchio_plant_has_the_plants_dynamics(scenes, name):
    """Pinocchio's tree (the 5R's built from the 15 %-off parameters) gives Orsino's plant's
    accelerations at a moving assembled state."""
    scene = scenes[name]
    plant = scene.prepared.setup.plant
    q = scene.prepared.q0
    qd = plant.velocity_map(q) @ np.linspace(0.1, 0.3, plant.p)
    u = np.linspace(0.5, 1.5, len(plant.actuated))
    orsino = CoupledChainPlant(plant, 0.0)
    pinocchio = constraint_dynamics_plant(scene.tree, 0.0)
    to_tree = scene.tree.from_orsino
    a_pin = pinocchio.acceleration(q[to_tree], qd[to_tree], u)
    np.testing.assert_allclose(a_pin, orsino.acceleration(q, qd, u)[to_tree], atol=1e-9 * np.abs(a_pin).max())


@pytest.mark.slow
@pytest.mark.parametrize("name", list(MECHANISM_SCENES))
def test_quick_sweep_points_are_all_finite(name):
    """Every method of the quick sweep ends with finite errors, the loop held closed to 0.1 mm."""
    scene = mechanism_scene(name, quick=True)
    ref = scene.reference()
    methods = scene.methods()
    assert {m.package for m in methods} == {"freefloat", "pinocchio", "mujoco"}
    for method in methods:
        errors = scene.errors(scene.run(method)(), ref)
        assert all(math.isfinite(e) for e in errors.values()) and errors["constraint_drift"] < 1e-4, (method, errors)


def test_a_run_that_blows_up_raises_an_arithmetic_error(scenes):
    """A plant whose accelerations stop being finite ends the run with an ArithmeticError naming the time."""
    scene = scenes["five_bar"]

    class Broken(CoupledChainPlant):
        def acceleration(self, q, v, u):
            return np.full(len(q), np.inf)

    plant = Broken(scene.prepared.setup.plant, 0.0)
    with pytest.raises(ArithmeticError, match="not finite at t = 0.001 s"):
        held_run(plant, scene.prepared.controller, scene.prepared.q0, scene.prepared.qd0, 0.02, 1e-3, 1e-3, "rkmk4",
                 lambda q: q)


def test_unknown_scene_lists_the_valid_ones():
    """An unknown scene name fails naming the valid ones."""
    with pytest.raises(InvalidArgument, match="five_bar, rsu_ppap"):
        mechanism_scene("six_bar")


@pytest.mark.parametrize("duration", [0.0, -1.0, 0.0105, math.nan])
def test_duration_must_be_whole_control_periods(duration):
    """A duration that is not a positive whole number of the 2RSU+PPaP's 1 ms periods fails naming it."""
    with pytest.raises(InvalidArgument, match="whole number of 0.001 s control periods"):
        mechanism_scene("rsu_ppap", duration)


def test_unknown_method_fails_naming_it(scenes):
    """A method this scene does not sweep (MuJoCo names its RK4 "RK4") fails naming the method."""
    with pytest.raises(InvalidArgument, match="no method mujoco rk4"):
        scenes["five_bar"].run(Method("mujoco", "rk4", 1e-3))


@pytest.mark.parametrize("name", list(MECHANISM_SCENES))
def test_mujoco_tree_has_pinocchios_mass_matrix(scenes, name):
    """MuJoCo's joint-space mass matrix of the written MJCF equals Pinocchio's CRBA at the start (the 5R's planar links balanced)."""
    from freefloat.lab.bench.in_mujoco.mechanism import MujocoMechanism

    scene = scenes[name]
    sim = MujocoMechanism(scene.tree, "RK4", 1e-3)
    assert sim.mass_matrix_gap(scene.prepared.q0[scene.tree.from_orsino]) < 1e-12
    assert sim.model.neq == len(scene.tree.constraints)


def test_mujoco_reaches_the_reference_with_stiff_closures(scenes, references):
    """MuJoCo's RK4 at 20 us (closures' time constant 40 us) ends within 1e-6 of the 2RSU+PPaP reference, its
    loop-closure drift measured and below 1 nm, and its error falls with the step (soft closures: first order)."""
    scene, ref = scenes["rsu_ppap"], references["rsu_ppap"]
    coarse, fine = (scene.errors(scene.run(Method("mujoco", "RK4", h, "python", "soft"))(), ref) for h in (1e-4, 2e-5))
    assert fine["state_error"] < 1e-6 and 0.0 < fine["constraint_drift"] < 1e-9
    assert coarse["state_error"] > 3.0 * fine["state_error"]


def test_mujoco_instability_is_an_arithmetic_error(scenes, tmp_path, monkeypatch):
    """A MuJoCo run its own checks find unstable (a huge applied force) raises an ArithmeticError instead of
    continuing from MuJoCo's reset state."""
    from freefloat.lab.bench.in_mujoco.mechanism import MujocoMechanism

    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warning to MUJOCO_LOG.TXT here
    scene = scenes["five_bar"]
    tree = scene.tree

    class Violent:
        def torque(self, t, q, qd):
            return np.full(len(tree.actuated), 1e30)

    sim = MujocoMechanism(tree, "Euler", 1e-3)
    q0 = scene.prepared.q0[tree.from_orsino]
    with pytest.raises(ArithmeticError, match="unstable"):
        sim.run(Violent(), q0, np.zeros(len(q0)), 0.01, 1e-3, 1e-3)
