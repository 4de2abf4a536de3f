"""Reuse of compiled loops across runs (freefloat.dynamics.compiled): a run on a kept loop gives
the same numbers bit for bit as one on a new loop, whatever ran on it before (another integrator,
a law, wrenches, another plant's masses, an interrupted or diverged run), and a process keeps one
loop per robot structure, never shared by two live runs."""

from __future__ import annotations

import warnings
from dataclasses import fields, replace

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics import _sim, compiled
from freefloat.dynamics.compiled import CompiledLoop, clear_loops
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import ExactModel
from freefloat.dynamics.simulation import run
from freefloat.dynamics.wrenches import ExternalWrench
from freefloat.paths import URDF_DIR
from freefloat.space.control import ComputedTorque, QuinticTrajectory

IMPULSE = (ExternalWrench("arm1_link4", torque=(0.0, 0.0, 50.0), start=0.005, end=0.015, rise=0.005),)


@pytest.fixture(autouse=True)
def no_kept_loops():
    clear_loops()
    yield
    clear_loops()


def robot_named(name: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(URDF_DIR / name, visuals=False)


def start_of(robot):
    rng = np.random.default_rng(3)
    return robot.neutral(), rng.normal(0.0, 0.3, robot.model.nv)


def tumble(robot, integrator="rkmk4", **kwargs):
    q0, v0 = start_of(robot)
    return run(robot, q0, v0, 0.05, 1e-3, make_integrator(integrator, robot.model), ExactModel(robot),
               backend="compiled", **kwargs)


def assert_identical(a, b):
    assert (a.status, a.steps, a.evaluations) == (b.status, b.steps, b.evaluations)
    for f in fields(a.telemetry):
        np.testing.assert_array_equal(getattr(a.telemetry, f.name), getattr(b.telemetry, f.name), err_msg=f.name)


def controlled(robot):
    """A computed-torque run (the law compiled) with the impulse's wrench profile."""
    start = np.zeros(robot.n_joints)
    law = ComputedTorque(robot, QuinticTrajectory(start, start + 0.1, 0.05), 10.0, 100.0)
    return tumble(robot, "dopri5", controller=law, wrenches=IMPULSE)


def test_a_kept_loop_runs_as_a_new_one_bit_for_bit():
    """A torque-free run on a loop that ran a controlled, wrenched dopri5 run before equals the
    same run on a new loop to the last bit (law, wrenches, step size and counts all reset)."""
    robot = robot_named("four_arm_planar.urdf")
    fresh = tumble(robot)
    controlled(robot)
    again = tumble(robot)
    assert_identical(fresh, again)
    clear_loops()
    assert_identical(controlled(robot), (tumble(robot), controlled(robot))[1])


def test_the_loop_is_built_once_per_structure(monkeypatch):
    """Runs on one robot (and on a copy with other masses) build one compiled loop, not one per run."""
    built = []
    make = _sim.Simulation

    def counted(*args, **kwargs):
        built.append(1)
        return make(*args, **kwargs)

    monkeypatch.setattr(compiled._sim, "Simulation", counted)
    robot = robot_named("two_arm_planar.urdf")
    for _ in range(3):
        tumble(robot)
    tumble(heavier(robot))
    assert len(built) == 1


def heavier(robot, factor=1.3):
    """The robot with its second body's mass and inertia scaled (the plant of ``--vary mass``)."""
    model = pin.Model(robot.model)
    body = model.inertias[2]
    model.inertias[2] = pin.Inertia(body.mass * factor, body.lever, body.inertia * factor)
    return replace(robot, model=model)


def test_other_masses_on_a_kept_loop_equal_a_new_loop():
    """A kept loop given another plant's inertias runs it exactly as a loop built for it, and back."""
    robot = robot_named("four_arm_planar.urdf")
    nominal = tumble(robot)
    kept = tumble(heavier(robot))
    clear_loops()
    new = tumble(heavier(robot))
    assert_identical(kept, new)
    assert not np.array_equal(kept.telemetry.v, nominal.telemetry.v)
    assert_identical(tumble(robot), nominal)


def test_a_run_after_an_interrupted_run_starts_clean():
    """Ctrl-C in the middle of a run leaves nothing behind for the next run on the same loop."""
    robot = robot_named("four_arm_planar.urdf")
    fresh = tumble(robot)

    def interrupt(done: int) -> None:
        if done > 10:
            raise KeyboardInterrupt

    assert controlled(robot).status == "completed"
    q0, v0 = start_of(robot)
    stopped = run(robot, q0, v0, 0.05, 1e-3, make_integrator("rkmk8", robot.model), ExactModel(robot),
                  progress=interrupt, wrenches=IMPULSE, backend="compiled")
    assert stopped.status == "interrupted"
    assert_identical(tumble(robot), fresh)


def test_a_run_after_a_diverged_run_starts_clean():
    """A blow-up (Euler at 50 ms) leaves nothing behind for the next run on the same loop."""
    robot = robot_named("two_arm_planar.urdf")
    fresh = tumble(robot)
    q0, v0 = robot.neutral(), np.full(robot.model.nv, 1.0)
    blown = run(robot, q0, v0, 50.0, 0.05, make_integrator("euler", robot.model), ExactModel(robot), backend="compiled")
    assert blown.status == "diverged"
    assert_identical(tumble(robot), fresh)


def test_live_loops_are_never_shared():
    """Two loops alive at once get two compiled simulations; a released one is taken by the next."""
    robot = robot_named("two_arm_planar.urdf")
    rkmk4 = make_integrator("rkmk4", robot.model)
    a, b = CompiledLoop(robot, rkmk4, 1e-3), CompiledLoop(robot, rkmk4, 1e-3)
    assert a.sim is not b.sim
    a.release()
    a.release()  # twice: kept once
    c = CompiledLoop(robot, rkmk4, 1e-3)
    assert c.sim is a.sim
    assert CompiledLoop(robot, rkmk4, 1e-3).sim not in (a.sim, b.sim)


def test_kept_loops_are_bounded():
    """A process keeps at most MAX_IDLE idle loops, the least recently released dropped first."""
    robot = robot_named("two_arm_planar.urdf")
    loops = [CompiledLoop(robot, make_integrator("euler", robot.model), 1e-3) for _ in range(compiled.MAX_IDLE + 2)]
    for loop in loops:
        loop.release()
    assert sum(len(kept) for kept in compiled._idle.values()) == compiled.MAX_IDLE
    assert {id(sim) for sim, _ in compiled._idle[loops[0]._structure]} == {id(loop.sim) for loop in loops[2:]}


def test_another_structure_is_refused_by_a_loop():
    """The compiled side refuses a model whose joints differ from the loop's (its Data would not fit)."""
    small, big = robot_named("two_arm_planar.urdf"), robot_named("four_arm_planar.urdf")
    loop = CompiledLoop(small, make_integrator("euler", small.model), 1e-3)
    with pytest.raises(ValueError, match="joints or frames differ"):
        loop.sim.set_model(**compiled.model_arrays(big))
