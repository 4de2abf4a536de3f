"""The compiled loop (freefloat.dynamics.compiled): the rebuilt model against Pinocchio, every
integrator, the computed-torque and detumbling laws and the wrench profiles against the Python loop
(and the C++ detumbling solve against detumbling.solve), and what it refuses."""

from __future__ import annotations

import re
import warnings
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from freefloat import load_robot
from freefloat.dynamics import gjm
from freefloat.dynamics.compiled import COMPILED_INTEGRATORS, CompiledLoop, law_and_robot, law_of, law_robot
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import ExactModel, make_model
from freefloat.dynamics.simulation import run
from freefloat.dynamics.telemetry import Telemetry
from freefloat.dynamics.wrenches import ExternalWrench
from freefloat.errors import InvalidArgument
from freefloat.paths import URDF_DIR
from freefloat.space.detumbling import METHODS, SECONDARY, solve

from .conftest import random_robots, random_state, robot_from_case

DETUMBLE_SCENES = ("detumble_impulse_arm1_joint3", "detumble_impulse_arm1_joint4", "detumble_impulse_arm2_joint4",
                   "detumble_impulse_both_arms")
#: The detumble scenes' capture impulse: 500 N m about z on arm 1's last link, ramped over 5 ms.
IMPULSE = (ExternalWrench("arm1_link4", torque=(0.0, 0.0, 500.0), start=0.005, end=0.015, rise=0.005),)
FIELDS = ("q", "v", "tau", "joint_positions", "base_position", "base_quaternion", "base_twist", "ee_position",
          "ee_quaternion", "com", "momentum", "energy", "work")


def robot_named(name: str, base: str = "free"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(URDF_DIR / name, base=base, visuals=False)


def both_loops(robot, q0, v0, integrator: str, duration=0.05, period=0.005, **kwargs):
    """The same run in the Python and the compiled loop."""
    return [run(robot, q0, v0, duration, period, make_integrator(integrator, robot.model, substeps=2),
                ExactModel(robot), backend=backend, **kwargs) for backend in ("python", "compiled")]


def assert_same_telemetry(a, b, tol=1e-10):
    assert len(a.t) == len(b.t)
    for name in FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        np.testing.assert_allclose(y, x, atol=tol * max(1.0, np.abs(x).max()), err_msg=name)


@settings(max_examples=25, deadline=None)
@given(random_robots(max_links=8))
def test_rebuilt_model_aba_equals_pinocchio(tmp_path_factory, case):
    """The model rebuilt in C++ from arrays gives pin.aba's accelerations on random trees, free
    and planar bases, revolute, prismatic and continuous joints."""
    seed, _ = case
    robot, rng = robot_from_case(tmp_path_factory, case, base="planar" if seed % 2 else "free")
    loop = CompiledLoop(robot, make_integrator("rkmk4", robot.model), 1e-3)
    for _ in range(3):
        q, v = random_state(robot, rng)
        tau = rng.normal(size=robot.model.nv)
        expected = pin.aba(robot.model, robot.model.createData(), q, v, tau)
        np.testing.assert_allclose(loop.sim.acceleration(q, v, tau), expected, atol=1e-10 * max(1.0, np.abs(expected).max()))


@pytest.mark.parametrize("integrator", COMPILED_INTEGRATORS)
def test_every_integrator_matches_the_python_loop(integrator):
    """Each integrator of the compiled loop follows the Python one to round-off on a tumbling
    robot (same tableau, dexp^-1 series and, for dopri5, the same step-size control)."""
    robot = robot_named("two_arm_planar.urdf")
    q0, v0 = random_state(robot, np.random.default_rng(3), speed=1.0)
    python, compiled = both_loops(robot, q0, v0, integrator)
    assert (python.backend, compiled.backend) == ("python", "compiled")
    assert compiled.evaluations == python.evaluations
    assert_same_telemetry(python.telemetry, compiled.telemetry)


@settings(max_examples=10, deadline=None)
@given(random_robots(max_links=6))
def test_random_robots_tumble_alike_in_both_loops(tmp_path_factory, case):
    """On random trees (planar bases, continuous joints included) the two loops agree."""
    seed, _ = case
    robot, rng = robot_from_case(tmp_path_factory, case, base="planar" if seed % 2 else "free")
    q0, v0 = random_state(robot, rng, speed=0.5)
    python, compiled = both_loops(robot, q0, v0, "rkmk4")
    assert_same_telemetry(python.telemetry, compiled.telemetry)


def test_computed_torque_matches_the_python_controller():
    """The default scene's computed torque (quintic reference, exact H* and c*, planar base)
    gives the Python loop's torques, states and work."""
    from freefloat.app.experiments import joint_space
    from freefloat.app.experiments.robot_run import run_loop
    from freefloat.app.scenes import find_scene

    scene = find_scene("four_arm_joint_space")
    short = replace(scene, simulation=replace(scene.simulation, duration=0.3))
    runs = [run_loop(joint_space.prepare(replace(short, simulation=replace(short.simulation, backend=b))), None, None)
            for b in ("python", "compiled")]
    assert [r.backend for r in runs] == ["python", "compiled"]
    assert np.abs(runs[0].telemetry.tau).max() > 1e-3  # the law acts
    assert_same_telemetry(runs[0].telemetry, runs[1].telemetry, tol=1e-9)
    np.testing.assert_allclose(runs[1].telemetry.joint_reference, runs[0].telemetry.joint_reference, atol=1e-15)


def heavier(model: pin.Model, factor: float = 1.2) -> pin.Model:
    """``model`` with every body's mass and rotational inertia times ``factor`` (a batch's varied masses)."""
    model = pin.Model(model)
    for j in range(1, model.njoints):
        body = model.inertias[j]
        model.inertias[j] = pin.Inertia(factor * body.mass, body.lever, factor * body.inertia)
    return model


def test_a_controller_on_other_masses_than_the_plant_keeps_its_own_model():
    """Computed torque designed on the nominal robot driving a plant 20 % heavier: the compiled
    run, its law in C++ on the nominal model (the controller's Python torque is never called),
    gives the Python loop's torques and states, where the law on the plant's own masses tracks over
    10x closer (16x here)."""
    from freefloat.space.control import ComputedTorque, QuinticTrajectory

    nominal = robot_named("four_arm_planar.urdf")
    plant = replace(nominal, model=heavier(nominal.model))
    start = np.zeros(nominal.n_joints)
    law = ComputedTorque(nominal, QuinticTrajectory(start, start + 0.1, 1.0), 100.0, 20.0, "exact")
    runs = []
    for backend in ("python", "compiled"):
        if backend == "compiled":
            law.torque = never
        runs.append(run(plant, plant.neutral(), np.zeros(nominal.model.nv), 0.1, 1e-3,
                        make_integrator("rkmk4", plant.model), ExactModel(plant), law, backend=backend))
    assert_same_telemetry(runs[0].telemetry, runs[1].telemetry, tol=1e-9)
    own = run(plant, plant.neutral(), np.zeros(nominal.model.nv), 0.1, 1e-3, make_integrator("rkmk4", plant.model),
              ExactModel(plant), ComputedTorque(plant, law.trajectory, 100.0, 20.0, "exact"))
    error = [np.abs(r.telemetry.joint_positions - r.telemetry.joint_reference).max() for r in (runs[1], own)]
    assert error[0] > 10 * error[1]


def test_a_law_compiles_on_its_own_model_only_for_the_plants_structure():
    """law_of keeps a computed-torque law whose robot has the plant's joints and frames and other
    masses (law_robot and law_and_robot then name that robot), and gives None for a robot of
    another structure (its law runs in Python); with the plant's own robot, law_robot is None."""
    from freefloat.space.control import ComputedTorque, QuinticTrajectory
    from freefloat.space.control.computed_torque import QuinticComputedTorqueLaw

    four, two = robot_named("four_arm_planar.urdf"), robot_named("two_arm_planar.urdf")
    plant = replace(four, model=heavier(four.model))

    def controller(robot):
        start = np.zeros(robot.n_joints)
        return ComputedTorque(robot, QuinticTrajectory(start, start + 0.1, 1.0), 100.0, 20.0, "exact")

    assert isinstance(law_of(controller(four), plant), QuinticComputedTorqueLaw)
    assert law_robot(controller(four), plant) is four
    assert law_robot(controller(plant), plant) is None
    assert law_of(controller(two), plant) is None
    assert law_and_robot(controller(four), plant)[1] is four and law_and_robot(controller(two), plant) == (None, None)


@pytest.mark.slow
def test_a_detumbling_controller_on_other_masses_than_the_plant_keeps_its_own_model():
    """The detumbling law designed on the nominal robot, the plant 20 % heavier: the compiled run
    (the law in C++, H*, c* and the generalized Jacobian on the nominal model) gives the Python
    loop's telemetry and solver residuals, and differs from a run whose law knows the plant."""
    from freefloat.app.experiments import experiment_for
    from freefloat.app.experiments.robot_run import run_loop
    from freefloat.app.scenes import find_scene
    from freefloat.space.control.detumbling_control import DetumblingController

    scene = find_scene(DETUMBLE_SCENES[0])
    runs, controllers = [], []
    for backend, knows_plant in (("python", False), ("compiled", False), ("compiled", True)):
        sim = replace(scene.simulation, backend=backend, model="exact", duration=1.0)
        setup = experiment_for(scene).prepare(replace(scene, simulation=sim))
        plant = replace(setup.robot, model=heavier(setup.robot.model))
        setup = replace(setup, robot=plant, model=ExactModel(plant))
        if knows_plant:
            c = setup.controller
            setup = replace(setup, controller=DetumblingController(plant, c.rows, c.joints, c.start, c.T, c.method,
                                                                   c.kp, c.kd))
        elif backend == "compiled":
            setup.controller.torque = never
        runs.append(run_loop(setup, None, None))
        controllers.append(setup.controller)
    python, compiled, knowing = runs
    assert np.abs(compiled.telemetry.tau).max() > 1.0  # the law acts
    assert_same_telemetry(python.telemetry, compiled.telemetry, tol=1e-9)
    np.testing.assert_allclose(controllers[1].residuals, controllers[0].residuals, atol=1e-12)
    assert np.abs(knowing.telemetry.tau - compiled.telemetry.tau).max() > 1e-3


@settings(max_examples=25, deadline=None)
@given(random_robots(max_links=8))
def test_generalized_jacobian_from_pinocchio_equals_gjm_compute(tmp_path_factory, case):
    """J*, J0, the drift J0E H0^-1 M and H0^-1 M built from Pinocchio's centroidal map and frame
    Jacobians equal gjm.compute's on random trees, free and planar bases."""
    seed, _ = case
    robot, rng = robot_from_case(tmp_path_factory, case, base="planar" if seed % 2 else "free")
    loop = CompiledLoop(robot, make_integrator("rkmk4", robot.model), 1e-3)
    q, v = random_state(robot, rng)
    state = gjm.compute(robot, q, v)
    free = np.linalg.solve(state.H0, state.momentum_base)
    for got, expected in zip(loop.generalized_jacobian(q, v), (state.Jstar, state.J0, state.J0E @ free, free)):
        np.testing.assert_allclose(got, expected, atol=1e-10 * max(1.0, np.abs(expected).max()))


def task_shape(rng: np.random.Generator, method: str, secondary: str, n: int, k: int) -> tuple[int, int]:
    """Random (rows, mission joints) counts ``solve`` takes: one of each for ``single``, any rows
    for ``least_squares``, no more rows than joints otherwise, leaving ``null_space`` as many spare
    joints as its objective has rows."""
    if method == "single":
        return 1, 1
    s = int(rng.integers(1, n + 1))
    if method == "least_squares":
        return int(rng.integers(1, 6 * k + 1)), s
    most = min(6 * k, s - ({"base_angular_velocity": 3, "base_twist": 6}[secondary] if method == "null_space" else 0))
    assume(most >= 1)
    return int(rng.integers(1, most + 1)), s


def condition(state, rows: np.ndarray, joints: np.ndarray, method: str, secondary: str, rcond: float = 1e-10) -> float:
    """The solve's round-off amplification: the condition number of A = J*{k, S} over its kept
    singular values, times that of C N for ``null_space`` (1 for ``single``)."""
    def kept(M: np.ndarray) -> float:
        s = np.linalg.svd(M, compute_uv=False)
        s = s[s > rcond * s.max()] if s.size and s.max() > 0 else np.ones(1)
        return s.max() / s.min()

    if method == "single":
        return 1.0
    A = state.Jstar[np.ix_(rows, joints)]
    if method != "null_space":
        return kept(A)
    N = np.eye(len(joints)) - np.linalg.pinv(A, rcond=rcond) @ A
    C = state.J0[3 if secondary == "base_angular_velocity" else 0:][:, joints]
    return kept(A) * kept(C @ N)


@settings(max_examples=40, deadline=None)
@given(random_robots(max_links=8), st.sampled_from(METHODS), st.sampled_from(SECONDARY), st.integers(0, 2**16))
def test_compiled_detumbling_solve_equals_the_python_solver(tmp_path_factory, case, method, secondary, pick):
    """The C++ detumbling solve gives detumbling.solve's joint rates and residual to round-off on
    random robots (free and planar bases), random rows, mission joints, methods and secondary
    objectives; where the Python solver refuses 'single', so does the C++ one, with its message."""
    seed, _ = case
    robot, rng = robot_from_case(tmp_path_factory, case, base="planar" if seed % 2 else "free")
    choose = np.random.default_rng(pick)
    k = len(robot.end_effectors)
    r, s = task_shape(choose, method, secondary, robot.n_joints, k)
    rows = np.sort(choose.choice(6 * k, size=r, replace=False))
    joints = np.sort(choose.choice(robot.n_joints, size=s, replace=False))
    q, v = random_state(robot, rng)
    state = gjm.compute(robot, q, v)
    loop = CompiledLoop(robot, make_integrator("rkmk4", robot.model), 1e-3)
    try:
        expected = solve(state, rows, joints, method, secondary)
    except ValueError as exc:
        with pytest.raises(ValueError, match=re.escape(str(exc))):
            loop.detumbling_solve(q, v, rows, joints, method, secondary)
        return
    qdot, residual = loop.detumbling_solve(q, v, rows, joints, method, secondary)
    tol = 1e-12 * condition(state, rows, joints, method, secondary) * max(1.0, np.abs(expected.qdot).max())
    np.testing.assert_allclose(qdot, expected.qdot, atol=tol)
    np.testing.assert_allclose(residual, expected.residual, atol=tol)


def never(*args, **kwargs):
    raise AssertionError("the compiled run called Python between periods")


@pytest.mark.slow
@pytest.mark.parametrize("name", DETUMBLE_SCENES)
def test_detumble_scene_runs_whole_chunks_like_the_python_loop(name, monkeypatch):
    """A detumble_impulse scene (a ramped 500 N m impulse, then the detumbling law) gives the
    Python loop's telemetry and solver residuals with the law and the wrench profiles in C++ (the
    Python controller and wrench selection are never called)."""
    from freefloat.app.experiments import experiment_for
    from freefloat.app.experiments.robot_run import run_loop
    from freefloat.app.scenes import find_scene
    from freefloat.dynamics.wrenches import WrenchProfiles

    scene = find_scene(name)
    runs, controllers = [], []
    for backend in ("python", "compiled"):
        sim = replace(scene.simulation, backend=backend, model="exact")
        setup = experiment_for(scene).prepare(replace(scene, simulation=sim))
        if backend == "compiled":
            setup.controller.torque = never
            monkeypatch.setattr(WrenchProfiles, "activate", never)
        runs.append(run_loop(setup, None, None))
        controllers.append(setup.controller)
    python, compiled = runs
    assert [python.status, compiled.status] == ["completed", "completed"]
    assert np.abs(compiled.telemetry.momentum[-1] - compiled.telemetry.momentum[0]).max() > 1.0  # the impulse acts
    assert np.abs(compiled.telemetry.tau).max() > 1.0  # the law acts
    assert_same_telemetry(python.telemetry, compiled.telemetry, tol=1e-9)
    np.testing.assert_allclose(compiled.telemetry.joint_reference, python.telemetry.joint_reference, atol=1e-12)
    assert len(controllers[1].residuals) == len(controllers[0].residuals) > 900
    np.testing.assert_allclose(controllers[1].residuals, controllers[0].residuals, atol=1e-12)


def test_detumbling_with_another_controller_model_falls_back_to_python():
    """A detumbling controller on the nidc model has no compiled law: the run drives the compiled
    plant one period at a time with the Python law and the wrenches selected in Python, and still
    gives the Python loop's telemetry."""
    from freefloat.space.control.detumbling_control import DetumblingController
    from freefloat.space.detumbling import joint_indices, task_rows

    robot = robot_named("two_arm_planar.urdf", base="planar")
    results = []
    for backend in ("python", "compiled"):
        ctrl = DetumblingController(robot, task_rows(robot, [("arm1_ee", "wz")]), joint_indices(robot, None), 0.01,
                                    1e-3, model="nidc")
        assert ctrl.compiled_law() is None
        results.append(run(robot, robot.neutral(), np.zeros(robot.model.nv), 0.03, 1e-3,
                           make_integrator("rkmk4", robot.model), ExactModel(robot), ctrl, IMPULSE, backend=backend))
    assert [r.backend for r in results] == ["python", "compiled"]
    assert_same_telemetry(results[0].telemetry, results[1].telemetry)


def test_chained_compiled_runs_keep_the_detumbling_state():
    """One controller over two chained runs (the second starting where the first ended) holds the
    first run's posture and differences against its last rates, in both loops alike."""
    from freefloat.space.control.detumbling_control import DetumblingController
    from freefloat.space.detumbling import joint_indices, task_rows

    robot = robot_named("two_arm_planar.urdf", base="planar")
    q0, v0 = random_state(robot, np.random.default_rng(5), speed=0.3)
    second, residuals = [], []
    for backend in ("python", "compiled"):
        ctrl = DetumblingController(robot, task_rows(robot, [("arm1_ee", "wz"), ("arm2_ee", "wz")]),
                                    joint_indices(robot, None), 0.025, 1e-3, method="null_space")
        first = run(robot, q0, v0, 0.03, 1e-3, make_integrator("rkmk4", robot.model), ExactModel(robot), ctrl,
                    backend=backend)
        tel = first.telemetry
        second.append(run(robot, tel.q[-1], tel.v[-1], 0.02, 1e-3, make_integrator("rkmk4", robot.model),
                          ExactModel(robot), ctrl, start_time=0.03, backend=backend))
        residuals.append(ctrl.residuals)
    assert_same_telemetry(second[0].telemetry, second[1].telemetry)
    np.testing.assert_allclose(second[1].telemetry.joint_reference, second[0].telemetry.joint_reference)
    assert len(residuals[1]) == len(residuals[0]) >= 20
    np.testing.assert_allclose(residuals[1], residuals[0], atol=1e-12)


def test_a_failing_detumbling_solve_stops_the_compiled_run_like_the_python_one():
    """'single' with a mission joint that cannot move its row (a planar arm and a vz row) stops
    both loops as diverged at the first detumbling period, with the solver's message."""
    from freefloat.space.control.detumbling_control import DetumblingController
    from freefloat.space.detumbling import joint_indices, task_rows

    robot = robot_named("two_arm_planar.urdf", base="planar")
    results = []
    for backend in ("python", "compiled"):
        ctrl = DetumblingController(robot, task_rows(robot, [("arm1_ee", "vz")]), joint_indices(robot, ["arm1_joint4"]),
                                    0.005, 1e-3, method="single")
        results.append(run(robot, robot.neutral(), np.full(robot.model.nv, 0.1), 0.02, 1e-3,
                           make_integrator("rkmk4", robot.model), ExactModel(robot), ctrl, backend=backend))
    python, compiled = results
    assert python.status == compiled.status == "diverged"
    assert compiled.message == python.message and "does not move row" in python.message
    assert_same_telemetry(python.telemetry, compiled.telemetry)


def test_wrench_profiles_in_the_compiled_loop_match_the_python_selection(monkeypatch):
    """Ramped, stepped and finished wrenches (forces and torques, on a link and on the base) give
    the Python loop's telemetry with the selection made in C++."""
    from freefloat.dynamics.wrenches import ExternalWrench, WrenchProfiles

    robot = robot_named("two_arm_planar.urdf")
    wrenches = (ExternalWrench("arm2_link3", force=(3.0, -1.0, 2.0), torque=(0.5, 0.0, -1.0), start=0.004, end=0.02,
                               rise=0.0063),
                ExternalWrench(robot.base_link, force=(0.0, 5.0, 0.0), start=0.01, end=0.014),
                *IMPULSE)
    python = run(robot, robot.neutral(), np.full(robot.model.nv, 0.05), 0.03, 1e-3,
                 make_integrator("rkmk4", robot.model), ExactModel(robot), wrenches=wrenches, backend="python")
    monkeypatch.setattr(WrenchProfiles, "activate", never)
    compiled = run(robot, robot.neutral(), np.full(robot.model.nv, 0.05), 0.03, 1e-3,
                   make_integrator("rkmk4", robot.model), ExactModel(robot), wrenches=wrenches, backend="compiled")
    assert np.abs(python.telemetry.momentum[-1] - python.telemetry.momentum[0]).max() > 1e-2
    assert_same_telemetry(python.telemetry, compiled.telemetry)


def runs_by_setting(monkeypatch, base: str, setting: str, values: tuple[str, ...]) -> dict:
    """A computed-torque scene (0.2 s) and a run under external wrench profiles (dopri5), compiled,
    once with each of ``values`` of ``compiled.<setting>``: their telemetry by value."""
    from freefloat.app.experiments import joint_space
    from freefloat.app.experiments.robot_run import run_loop
    from freefloat.app.scenes import find_scene
    from freefloat.dynamics import compiled

    scene = find_scene("four_arm_joint_space")
    short = replace(scene, robot=replace(scene.robot, base=base),
                    simulation=replace(scene.simulation, duration=0.2, backend="compiled"))
    robot = robot_named("two_arm_planar.urdf", base=base)
    wrenches = (ExternalWrench("arm2_link3", force=(3.0, -1.0, 2.0), torque=(0.5, 0.0, -1.0), start=0.004, end=0.02),
                *IMPULSE)
    runs = {}
    for value in values:
        monkeypatch.setattr(compiled, setting, value)
        compiled.clear_loops()
        controlled = run_loop(joint_space.prepare(short), None, None)
        wrenched = run(robot, robot.neutral(), np.full(robot.model.nv, 0.05), 0.03, 1e-3,
                       make_integrator("dopri5", robot.model, rtol=1e-9), ExactModel(robot), wrenches=wrenches,
                       backend="compiled")
        runs[value] = (controlled.telemetry, wrenched.telemetry)
    assert np.abs(runs[values[0]][0].tau).max() > 1e-3 and np.abs(runs[values[0]][1].momentum[-1]).max() > 1e-3
    return runs


@pytest.mark.parametrize("base", ["free", "planar"])
def test_world_and_local_conventions_give_the_same_run(monkeypatch, base):
    """Pinocchio's WORLD and LOCAL conventions in the compiled loop (the plant's ABA, Pinocchio's
    rather than the dynamics kernel, with and without external wrenches, and the computed torque's
    CRBA) give the same trajectory to 1e-12."""
    from freefloat.dynamics import compiled

    monkeypatch.setattr(compiled, "TREE_ABA", "pinocchio")
    runs = runs_by_setting(monkeypatch, base, "CONVENTION", ("local", "world"))
    robot = robot_named("two_arm_planar.urdf", base=base)
    for convention in ("local", "world"):
        monkeypatch.setattr(compiled, "CONVENTION", convention)
        assert CompiledLoop(robot, make_integrator("rkmk4", robot.model), 1e-3).sim.convention == convention
    for local, world in zip(runs["local"], runs["world"]):
        assert_same_telemetry(local, world, tol=1e-12)


@pytest.mark.parametrize("base", ["free", "planar"])
def test_the_kernel_plant_runs_as_pinocchios_aba(monkeypatch, base):
    """The compiled loop with the dynamics kernel as its tree's dynamics gives the telemetry of the
    same loop on Pinocchio's ABA to round-off: a computed-torque scene (0.2 s) and a run under
    external wrench profiles with adaptive steps."""
    runs = runs_by_setting(monkeypatch, base, "TREE_ABA", ("kernel", "pinocchio"))
    for kernel_run, pinocchio_run in zip(runs["kernel"], runs["pinocchio"]):
        assert_same_telemetry(pinocchio_run, kernel_run, tol=1e-11)


@settings(max_examples=8, deadline=None)
@given(random_robots(max_links=8))
def test_random_trees_tumble_alike_on_the_kernel_and_pinocchio(tmp_path_factory, case):
    """Torque-free tumbling of random trees (free and planar bases) on the kernel and on Pinocchio's
    ABA, compiled: the same telemetry to round-off."""

    seed, _ = case
    robot, rng = robot_from_case(tmp_path_factory, case, base="planar" if seed % 2 else "free")
    q0, v0 = random_state(robot, rng, speed=0.5)
    runs = []
    for tree_aba in ("kernel", "pinocchio"):
        loop = CompiledLoop(robot, make_integrator("rkmk4", robot.model), 5e-3, record_every=1)
        loop.sim.tree_aba = tree_aba
        chunk = Telemetry.allocate(11, robot.model.nq, robot.model.nv, robot.n_joints, len(robot.end_effectors))
        loop.start(q0, v0)
        assert loop.run(10, chunk, 0) == (10, None)
        loop.bind(chunk)
        loop.record(10)
        runs.append(chunk)
    assert_same_telemetry(runs[1], runs[0], tol=1e-11)


def test_the_plant_is_the_kernel_where_the_tree_allows(monkeypatch):
    """The compiled plant's tree dynamics are the dynamics kernel's on a robot's tree; a tree with
    a joint the kernel does not have (a planar joint that is not the root) keeps Pinocchio's ABA,
    the kernel's refusal naming the joint; TREE_ABA = "pinocchio" takes Pinocchio's everywhere."""
    from freefloat.dynamics import _sim, compiled

    robot = robot_named("two_arm_planar.urdf")
    loop = CompiledLoop(robot, make_integrator("rkmk4", robot.model), 1e-3)
    assert (loop.sim.tree_aba, loop.sim.kernel_refusal) == ("kernel", None)
    with pytest.raises(ValueError, match="'kernel' or 'pinocchio'"):
        loop.sim.tree_aba = "mujoco"
    model = pin.Model(robot.model)
    joint = model.addJoint(3, pin.JointModelPlanar(), pin.SE3.Random(), "skate")
    model.appendBodyToJoint(joint, pin.Inertia.Random(), pin.SE3.Identity())
    arrays = compiled.model_arrays(replace(robot, model=model))
    skating = _sim.Simulation(**arrays, joints=_sim.JointMap([], [], [], [], 0), n_base=model.nv, integrator="rkmk4",
                              substeps=1, rtol=1e-10, atol=1e-12, control_period=1e-3, start_time=0.0,
                              record_every=1, base_frame=0, ee_frames=[])
    assert skating.tree_aba == "pinocchio" and "joint 'skate'" in skating.kernel_refusal
    with pytest.raises(ValueError, match="joint 'skate'"):
        skating.tree_aba = "kernel"
    q, v = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)), np.ones(model.nv)
    expected = pin.aba(model, model.createData(), q, v, np.zeros(model.nv))
    np.testing.assert_allclose(skating.acceleration(q, v, np.zeros(model.nv)), expected, atol=1e-12 * np.abs(expected).max())
    monkeypatch.setattr(compiled, "TREE_ABA", "pinocchio")
    assert CompiledLoop(robot, make_integrator("rkmk4", robot.model), 1e-3).sim.tree_aba == "pinocchio"


@pytest.mark.slow
def test_capture_scene_detumbles_alike_in_both_loops(monkeypatch):
    """The capture_planar scene (grasp, then min-norm detumbling of the merged robot, compiled
    after the grasp) gives the Python loop's post-capture telemetry and solver residual."""
    from freefloat.app.experiments import experiment_for
    from freefloat.app.scenes import find_scene
    from freefloat.dynamics import simulation
    from freefloat.space.capture import capture_and_detumble

    scene = find_scene("capture_planar")
    setup = experiment_for(scene).prepare(replace(scene, simulation=replace(scene.simulation, model="exact")))
    python_run = simulation.run

    def capture():
        return capture_and_detumble(setup.robot, setup.target, "arm1_ee", [("arm1_ee", "wz")], None,
                                    approach_time=0.6, detumble_time=0.2, q0=setup.q0, v0=setup.v0)

    compiled = capture()
    monkeypatch.setattr(simulation, "run", lambda *a, **k: python_run(*a, **k, backend="python"))
    python = capture()
    assert compiled.summary["status"] == python.summary["status"] == "completed"
    assert compiled.summary["solver_residual_max"] > 0.0
    np.testing.assert_allclose(compiled.summary["solver_residual_max"], python.summary["solver_residual_max"],
                               atol=1e-12)
    assert_same_telemetry(python.post, compiled.post)


def test_a_stop_event_ends_the_compiled_run_where_the_python_one_ends():
    """A stop event evaluated between compiled periods ends the run at the same period."""
    robot = robot_named("two_arm_planar.urdf")
    q0, v0 = robot.neutral(), np.full(robot.model.nv, 0.3)
    results = [run(robot, q0, v0, 0.5, 0.01, make_integrator("rkmk4", robot.model), ExactModel(robot),
                   stop=lambda t, q, v: t >= 0.2 - 1e-12, backend=backend) for backend in ("python", "compiled")]
    assert [r.status for r in results] == ["stopped", "stopped"]
    assert results[0].steps == results[1].steps == 20
    assert_same_telemetry(results[0].telemetry, results[1].telemetry)


def test_compiled_refuses_what_it_does_not_have():
    """Asking for the compiled loop with a GJM plant names the reason; 'auto' falls back."""
    robot = robot_named("two_arm_planar.urdf")
    q0, v0 = robot.neutral(), np.full(robot.model.nv, 0.1)
    args = (robot, q0, v0, 0.01, 0.005, make_integrator("rkmk4", robot.model), make_model("nidc", robot))
    with pytest.raises(InvalidArgument, match="plant model is 'nidc'"):
        run(*args, backend="compiled")
    assert run(*args).backend == "python"


def test_momentum_projection_stays_in_python():
    """A projected integrator is not compiled: 'auto' runs it in Python."""
    robot = robot_named("two_arm_planar.urdf")
    integrator = make_integrator("rkmk4", robot.model, project_momentum=True)
    result = run(robot, robot.neutral(), np.full(robot.model.nv, 0.1), 0.01, 0.005, integrator, ExactModel(robot))
    assert result.backend == "python"


def test_interrupted_compiled_run_keeps_whole_rows():
    """Ctrl-C between compiled chunks stops the run as 'interrupted' with every row written."""
    robot = robot_named("two_arm_planar.urdf")
    calls = []

    def progress(done):
        calls.append(done)
        if len(calls) == 3:
            raise KeyboardInterrupt

    result = run(robot, robot.neutral(), np.full(robot.model.nv, 0.1), 1.0, 1e-3,
                 make_integrator("rkmk4", robot.model), ExactModel(robot), progress=progress, backend="compiled")
    assert result.status == "interrupted" and result.steps == calls[-1]
    assert len(result.telemetry.t) == result.steps
    assert np.allclose(np.linalg.norm(result.telemetry.base_quaternion, axis=1), 1.0)
    np.testing.assert_allclose(result.telemetry.t, np.arange(result.steps) * 1e-3, atol=1e-12)


def test_a_run_stopped_by_sigterm_names_it():
    """A run stopped by SIGTERM (KeyboardInterrupt carrying the signal's name, as freefloat's handler
    raises it) says so instead of "interrupted by the user"."""
    robot = robot_named("two_arm_planar.urdf")

    def progress(done):
        raise KeyboardInterrupt("SIGTERM")

    result = run(robot, robot.neutral(), np.full(robot.model.nv, 0.1), 1.0, 1e-3,
                 make_integrator("rkmk4", robot.model), ExactModel(robot), progress=progress, backend="compiled")
    assert result.status == "interrupted" and result.message.startswith(f"stopped by SIGTERM at t = {result.steps * 1e-3:.6g} s")


def test_an_unsupported_joint_is_named():
    """A joint kind the compiled loop does not rebuild (a 3-dof translation) is refused with its name."""
    robot = robot_named("two_arm_planar.urdf")
    model = pin.Model(robot.model)
    joint = model.addJoint(1, pin.JointModelTranslation(), pin.SE3.Identity(), "slider")
    model.appendBodyToJoint(joint, pin.Inertia.Random(), pin.SE3.Identity())
    with pytest.raises(InvalidArgument, match="joint .slider.*JointModelTranslation"):
        CompiledLoop(replace(robot, model=model), make_integrator("euler", model), 1e-3)


def test_a_blow_up_keeps_every_row_of_its_chunk(monkeypatch):
    """A run that blows up in the middle of a compiled chunk keeps the rows before it and says
    where, exactly as the Python loop does (both on pin.aba in the LOCAL convention, not the
    dynamics kernel: a diverging run grows any round-off difference to the message's third digit)."""
    from freefloat.dynamics import compiled

    monkeypatch.setattr(compiled, "CONVENTION", "local")
    monkeypatch.setattr(compiled, "TREE_ABA", "pinocchio")
    robot = robot_named("two_arm_planar.urdf")
    q0, v0 = robot.neutral(), np.full(robot.model.nv, 1.0)  # Euler at 50 ms: blows up after ~15 periods
    python, compiled = (run(robot, q0, v0, 50.0, 0.05, make_integrator("euler", robot.model), ExactModel(robot),
                            backend=backend) for backend in ("python", "compiled"))
    assert python.status == compiled.status == "diverged" and compiled.message == python.message
    assert 5 < len(compiled.telemetry.t) == len(python.telemetry.t) < 1000
    assert_same_telemetry(python.telemetry, compiled.telemetry)


def test_each_compiled_law_is_a_record_of_named_fields_with_its_kind():
    """The four compiled law kinds are dataclasses (no tuple or dict read by position), each with
    its own kind (a class constant, not a field) and an install method: what the loop calls."""
    import dataclasses

    from freefloat.parallel.sliding_mode import PlatformLaw
    from freefloat.space.control.computed_torque import QuinticComputedTorqueLaw
    from freefloat.space.control.detumbling_control import DetumblingLaw
    from freefloat.space.control.loop_detumbling import LoopDetumblingLaw

    laws = (QuinticComputedTorqueLaw, DetumblingLaw, LoopDetumblingLaw, PlatformLaw)
    assert all(dataclasses.is_dataclass(law) and callable(law.install) for law in laws)
    assert len({law.kind for law in laws}) == 4
    assert not any("kind" in {f.name for f in dataclasses.fields(law)} for law in laws)
