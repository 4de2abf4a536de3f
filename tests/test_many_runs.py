"""Many runs in one compiled call on C++ threads (freefloat.dynamics.many_runs): each run equals
simulation.run of the same inputs bit for bit (random trees, computed torque with each run's own
quintic, wrench profiles, the closed plant, adaptive steps), one loop per thread or four in
lockstep; a blow-up stays in its run (in lockstep its lane takes the next run), a stop request
keeps the finished rows, and what cannot share one call is refused with the reason."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from freefloat.app.runner import resolved_setup
from freefloat.app.scenes import find_scene
from freefloat.dynamics import stop_request
from freefloat.dynamics.compiled import clear_loops
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.many_runs import run_many, start_runs
from freefloat.dynamics.models import ExactModel
from freefloat.dynamics.simulation import run
from freefloat.errors import InvalidArgument
from freefloat.space.control import ComputedTorque, QuinticTrajectory

from .conftest import random_robots, random_state, robot_from_case
from .test_compiled_reuse import IMPULSE, assert_identical, robot_named

#: Whether runs go in lockstep: both ways for the tests that take ``lockstep``.
LOCKSTEP = [False, True]


@pytest.fixture(autouse=True)
def no_kept_loops():
    clear_loops()
    yield
    clear_loops()


def states(robot, runs: int, seed: int, speed: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    pairs = [random_state(robot, rng, speed) for _ in range(runs)]
    return np.array([q for q, _ in pairs]), np.array([v for _, v in pairs])


def one_by_one(robot, q0, v0, duration, integrator, model, controllers=None, **kwargs):
    return [run(robot, q, v, duration, 1e-3, integrator, model, None if controllers is None else controllers[i],
                backend="compiled", **kwargs) for i, (q, v) in enumerate(zip(q0, v0))]


@pytest.mark.slow
@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=random_robots(max_links=6), integrator=st.sampled_from(["rkmk4", "dopri5", "euler", "rkmk8"]),
       threads=st.integers(1, 3), lockstep=st.sampled_from([False, None]))
def test_each_run_equals_its_own_run_on_random_trees(tmp_path_factory, case, integrator, threads, lockstep):
    """Seven torque-free runs from random states on 1-3 threads, their slots reused (keep=False), one
    loop per thread or, where the runs go in lockstep (the default with a fixed step), groups of four
    lanes, the last lanes refilled or left out: every run's telemetry, steps and evaluations are
    simulation.run's, bit for bit."""
    robot, _ = robot_from_case(tmp_path_factory, case, visuals=False)
    q0, v0 = states(robot, 7, case[0] % 1000)
    steps = make_integrator(integrator, robot.model)
    got: dict[int, object] = {}
    run_many(robot, q0, v0, 0.03, 1e-3, steps, ExactModel(robot), threads=threads, record_every=2,
             on_result=got.__setitem__, keep=False, lockstep=lockstep)
    expected = one_by_one(robot, q0, v0, 0.03, steps, ExactModel(robot), record_every=2)
    assert sorted(got) == list(range(7))
    for i, result in got.items():
        assert_identical(result, expected[i])


@pytest.mark.parametrize("lockstep", LOCKSTEP)
def test_computed_torque_runs_each_follow_their_own_quintic(lockstep):
    """Computed torque from four different starts, each run's quintic from its own start, with the
    wrench profiles of an impulse: equal to each run alone, and the runs differ."""
    robot = robot_named("four_arm_planar.urdf")
    rng = np.random.default_rng(5)
    q0 = np.array([robot.neutral() for _ in range(4)])
    q0[:, robot.model.nqs[1]:] = rng.uniform(-0.5, 0.5, (4, robot.n_joints))
    v0 = np.zeros((4, robot.model.nv))
    model = ExactModel(robot)
    controllers = [ComputedTorque(robot, QuinticTrajectory(q[robot.model.nqs[1]:], q[robot.model.nqs[1]:] + 0.3, 0.04),
                                  100.0, 20.0, "exact") for q in q0]
    steps = make_integrator("rkmk4", robot.model)
    results = run_many(robot, q0, v0, 0.05, 1e-3, steps, model, controllers, IMPULSE, threads=1 + (not lockstep),
                       lockstep=lockstep)
    expected = one_by_one(robot, q0, v0, 0.05, steps, model, controllers, wrenches=IMPULSE)
    for got, alone in zip(results, expected):
        assert_identical(got, alone)
    assert not np.array_equal(results[0].telemetry.tau, results[1].telemetry.tau)


def varied_plants(robot, count: int, seed: int) -> list[pin.Model]:
    """``count`` copies of ``robot.model``, each body's mass and rotational inertia times a seeded
    factor in [0.8, 1.2] (a batch's --vary mass)."""
    rng = np.random.default_rng(seed)
    plants = []
    for _ in range(count):
        model = pin.Model(robot.model)
        for j in range(1, model.njoints):
            f = rng.uniform(0.8, 1.2)
            model.inertias[j] = pin.Inertia(f * model.inertias[j].mass, model.inertias[j].lever, f * model.inertias[j].inertia)
        plants.append(model)
    return plants


@pytest.mark.parametrize("lockstep", LOCKSTEP)
def test_runs_of_other_masses_each_equal_their_plant_alone(lockstep):
    """Torque-free runs whose plants have their own masses and inertias (a batch's --vary mass; in
    lockstep, each lane its own): each equals simulation.run of its own plant, and the loops kept
    after them give the nominal robot's run again."""
    robot = robot_named("four_arm_planar.urdf")
    plants = varied_plants(robot, 6, seed=8)
    q0, v0 = states(robot, 6, 9, speed=0.5)
    steps = make_integrator("rkmk4", robot.model)
    results = run_many(robot, q0, v0, 0.05, 1e-3, steps, ExactModel(robot), threads=2, plants=plants, lockstep=lockstep)
    for i, got in enumerate(results):
        plant = replace(robot, model=plants[i])
        alone = run(plant, q0[i], v0[i], 0.05, 1e-3, steps, ExactModel(plant), backend="compiled")
        assert_identical(got, alone)
    nominal = run_many(robot, q0[:4], v0[:4], 0.05, 1e-3, steps, ExactModel(robot), threads=2, lockstep=lockstep)
    for got, alone in zip(nominal, one_by_one(robot, q0[:4], v0[:4], 0.05, steps, ExactModel(robot))):
        assert_identical(got, alone)


@pytest.mark.parametrize("lockstep", LOCKSTEP)
def test_controlled_runs_of_other_masses_keep_the_nominal_law(lockstep):
    """Computed torque designed on the nominal robot over plants of their own masses (a batch's
    --vary mass under control): each run equals simulation.run of its plant with the nominal
    controller, whose law computes on the nominal model (a law on the plant's masses gives other
    torques)."""
    robot = robot_named("four_arm_planar.urdf")
    plants = varied_plants(robot, 3, seed=11)
    q0, v0 = np.array([robot.neutral()] * 3), np.zeros((3, robot.model.nv))
    start = np.zeros(robot.n_joints)
    controllers = [ComputedTorque(robot, QuinticTrajectory(start, start + 0.1 * (i + 1), 0.04), 100.0, 20.0, "exact")
                   for i in range(3)]
    steps = make_integrator("rkmk4", robot.model)
    results = run_many(robot, q0, v0, 0.05, 1e-3, steps, ExactModel(robot), controllers, threads=2, plants=plants,
                       lockstep=lockstep)
    for i, got in enumerate(results):
        plant = replace(robot, model=plants[i])
        assert_identical(got, run(plant, q0[i], v0[i], 0.05, 1e-3, steps, ExactModel(plant), controllers[i],
                                 backend="compiled"))
    own = run(replace(robot, model=plants[0]), q0[0], v0[0], 0.05, 1e-3, steps,
              ExactModel(replace(robot, model=plants[0])),
              ComputedTorque(replace(robot, model=plants[0]), controllers[0].trajectory, 100.0, 20.0, "exact"))
    assert np.abs(own.telemetry.tau - results[0].telemetry.tau).max() > 1e-6


@pytest.mark.slow
def test_runs_of_the_closed_plant_equal_their_own_runs():
    """The two hands joined by a weld (the constrained dynamics with Baumgarte): three runs from
    the scene's start with other joint rates, equal to each run alone."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        setup = resolved_setup(find_scene("satellite_hands_joined"))
    q, v = setup.plant_state()
    q0 = np.array([q] * 3)
    v0 = np.array([v] * 3) * np.array([1.0, 0.5, -1.0])[:, None]
    results = run_many(setup.plant, q0, v0, 0.02, 1e-3, setup.integrator, setup.model, threads=2)
    expected = one_by_one(setup.plant, q0, v0, 0.02, setup.integrator, setup.model)
    for got, alone in zip(results, expected):
        assert_identical(got, alone)


@pytest.mark.parametrize("lockstep", LOCKSTEP)
def test_a_run_that_blows_up_is_diverged_and_leaves_the_others(lockstep):
    """One run at absurd joint rates blows up with simulation.run's message and rows; the others
    complete as alone (in lockstep on one thread, the diverged run's lane takes the next runs)."""
    robot = robot_named("four_arm_planar.urdf")
    q0, v0 = states(robot, 6, 7, speed=0.5)
    v0[1, robot.n_base:] = 1e5
    steps = make_integrator("rkmk4", robot.model)
    results = run_many(robot, q0, v0, 0.05, 1e-3, steps, ExactModel(robot), threads=1 + (not lockstep),
                       lockstep=lockstep)
    expected = one_by_one(robot, q0, v0, 0.05, steps, ExactModel(robot))
    assert [r.status for r in results] == ["completed", "diverged"] + ["completed"] * 4
    assert [(r.status, r.message) for r in results] == [(r.status, r.message) for r in expected]
    for got, alone in zip(results, expected):
        if got.status == "completed":
            assert_identical(got, alone)
    assert results[1].steps == expected[1].steps


@pytest.mark.parametrize("lockstep", LOCKSTEP)
def test_a_stop_request_ends_the_runs_and_keeps_their_rows(lockstep):
    """Runs of 50 s stopped by a stop request: each started run ends 'interrupted' within a slice of
    periods, its rows those of the same run alone up to there; none started after."""
    robot = robot_named("four_arm_planar.urdf")
    q0, v0 = states(robot, 4 + 4 * lockstep, 2, speed=0.3)
    steps = make_integrator("rkmk4", robot.model)
    runs = start_runs(robot, q0, v0, 50.0, 1e-3, steps, ExactModel(robot), threads=2, lockstep=lockstep)
    with stop_request.stopping():
        results = runs.finish()
    started = [r for r in results if r is not None]
    assert runs.interrupted and 1 <= len(started) <= (8 if lockstep else 2)
    for i, got in enumerate(results):
        if got is None:
            continue
        assert got.status == "interrupted" and 0 < got.steps < 50_000 and "interrupted by the user" in got.message
        alone = run(robot, q0[i], v0[i], got.steps * 1e-3, 1e-3, steps, ExactModel(robot), backend="compiled")
        for name in ("q", "v", "momentum", "energy"):
            np.testing.assert_array_equal(getattr(got.telemetry, name), getattr(alone.telemetry, name)[:-1])


@pytest.mark.parametrize("cause", [KeyboardInterrupt(), KeyboardInterrupt("SIGTERM")], ids=["ctrl-c", "sigterm"])
def test_an_interrupted_run_says_what_the_same_run_interrupted_alone_says(monkeypatch, cause):
    """A run stopped in run_many (by Ctrl-C, or SIGTERM as freefloat's handler raises it) and the
    same run stopped alone in simulation.run at the same period end with one status and message."""
    robot = robot_named("four_arm_planar.urdf")
    q0, v0 = states(robot, 1, 3, speed=0.3)
    steps = make_integrator("rkmk4", robot.model)

    def stop(*args) -> None:
        raise cause

    with monkeypatch.context() as patched:
        patched.setattr(stop_request, "check", stop)
        [got] = start_runs(robot, q0, v0, 50.0, 1e-3, steps, ExactModel(robot), threads=1).finish()
    assert got is not None and 0 < got.steps < 50_000

    def progress(periods: int) -> None:
        if periods == got.steps:
            raise cause

    alone = run(robot, q0[0], v0[0], 50.0, 1e-3, steps, ExactModel(robot), progress=progress, backend="compiled")
    assert (got.status, got.message, got.steps) == (alone.status, alone.message, alone.steps)
    assert got.status == "interrupted" and got.message.startswith("stopped by SIGTERM" if cause.args else "interrupted")


def test_runs_stopped_by_sigterm_name_it(monkeypatch):
    """Runs stopped by SIGTERM (KeyboardInterrupt carrying the signal's name, as freefloat's handler
    raises it in the waiting thread) say so instead of "interrupted by the user"."""
    robot = robot_named("four_arm_planar.urdf")
    q0, v0 = states(robot, 2, 5, speed=0.3)
    runs = start_runs(robot, q0, v0, 50.0, 1e-3, make_integrator("rkmk4", robot.model), ExactModel(robot), threads=2)

    def sigterm() -> None:
        raise KeyboardInterrupt("SIGTERM")

    monkeypatch.setattr(stop_request, "check", sigterm)
    stopped = [r for r in runs.finish() if r is not None]
    assert stopped and all(r.status == "interrupted" and r.message.startswith("stopped by SIGTERM at t = ")
                           for r in stopped)


def test_an_error_of_the_caller_stops_the_runs_and_propagates():
    """on_result raising stops the other runs and raises; the loops are free for the next call."""
    robot = robot_named("four_arm_planar.urdf")
    q0, v0 = states(robot, 6, 4, speed=0.3)
    steps = make_integrator("rkmk4", robot.model)

    def fail(index, result):
        raise RuntimeError("caller's error")

    with pytest.raises(RuntimeError, match="caller's error"):
        run_many(robot, q0, v0, 0.5, 1e-3, steps, ExactModel(robot), threads=2, on_result=fail)
    again = run_many(robot, q0[:2], v0[:2], 0.01, 1e-3, steps, ExactModel(robot), threads=2)
    assert [r.status for r in again] == ["completed", "completed"]


@pytest.mark.parametrize("change, message", [
    (dict(q0=np.zeros((2, 3))), "run 0"),
    (dict(v0=np.full((2, 22), np.nan)), "run 0"),
    (dict(v0=np.zeros((3, 22))), "one state per run"),
    (dict(integrator="momentum"), "cannot run this"),
    (dict(gains=(100.0, 30.0)), "run 1: its quintic's duration and gains"),
    (dict(threads=0), "threads"),
    (dict(threads=1000), "threads must be at most 256"),
    (dict(plants="controlled"), "run 1: its controller's robot has other numbers"),
    (dict(plants="moved"), "run 1: its plant differs"),
    (dict(lockstep=True, integrator="dopri5"), "cannot run in lockstep: integrator 'dopri5' has no fixed step"),
])
def test_what_cannot_share_one_call_is_refused_with_the_reason(change, message):
    robot = robot_named("four_arm_planar.urdf")
    q0 = np.array([robot.neutral()] * 2)
    v0 = np.zeros((2, robot.model.nv))
    gains = [(100.0, 20.0), change.pop("gains", (100.0, 20.0))]
    start = np.zeros(robot.n_joints)
    controllers = [ComputedTorque(robot, QuinticTrajectory(start, start + 0.1, 0.04), kp, kd, "exact") for kp, kd in gains]
    kind = change.pop("integrator", None)
    integrator = make_integrator("dopri5" if kind == "dopri5" else "rkmk4", robot.model, project_momentum=kind == "momentum")
    plants = None
    if "plants" in change:
        moved = pin.Model(robot.model)
        moved.jointPlacements[3] = pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1]))
        plants = [robot.model, moved]
        if change.pop("plants") == "moved":
            controllers = None
        else:  # run 1's controller designed on a heavier robot
            plants = [robot.model, robot.model]
            heavier = pin.Model(robot.model)
            heavier.inertias[2] = pin.Inertia(2.0 * heavier.inertias[2].mass, heavier.inertias[2].lever,
                                              2.0 * heavier.inertias[2].inertia)
            controllers[1] = ComputedTorque(replace(robot, model=heavier), controllers[1].trajectory, 100.0, 20.0,
                                            "exact")
    arguments = dict(q0=q0, v0=v0, threads=2) | change
    with pytest.raises(InvalidArgument, match=message):
        run_many(robot, arguments["q0"], arguments["v0"], 0.01, 1e-3, integrator, ExactModel(robot), controllers,
                 threads=arguments["threads"], plants=plants, lockstep=arguments.get("lockstep"))


def test_runs_whose_telemetry_cannot_fit_are_refused_before_any_starts():
    """A million kept runs of 100 s at 1 ms would need petabytes: refused naming the way out."""
    robot = robot_named("four_arm_planar.urdf")
    q0 = np.broadcast_to(robot.neutral(), (10**6, robot.model.nq))
    v0 = np.zeros((10**6, robot.model.nv))
    with pytest.raises(InvalidArgument, match="keep=False"):
        run_many(robot, q0, v0, 100.0, 1e-3, make_integrator("rkmk4", robot.model), ExactModel(robot))
