"""The two-hand capture bench scene: MuJoCo's model is the same system as the merged robot (mass
matrix, free-motion acceleration at the post-grasp state), the weld holds at the start on both
sides, both sides converge to the reference, and methods taking turns give the sweep's points."""

from __future__ import annotations

import math

import numpy as np
import pytest

from freefloat.dynamics.closures import closure_drift, kinematics, stacked
from freefloat.errors import InvalidArgument
from freefloat.lab.bench.race.scene import Method
from freefloat.lab.bench.race.sweep import sweep
from freefloat.lab.bench.scenes.mechanisms import MechanismResult
from freefloat.lab.bench.scenes.two_hand_capture import two_hand_capture_scene

mujoco = pytest.importorskip("mujoco")
from freefloat.lab.bench.in_mujoco.mechanism import MujocoMechanism  # noqa: E402  (needs mujoco)

NAME = "capture_two_hands_satellite"


@pytest.fixture(scope="module")
def scene():
    """The post-grasp phase over 20 control periods (20 ms)."""
    return two_hand_capture_scene(NAME, 0.02)


@pytest.fixture(scope="module")
def reference(scene):
    """DOP853 on freefloat's plant."""
    return scene.reference()


@pytest.mark.slow
def test_mujoco_has_the_merged_robots_mass_matrix_and_free_motion(scene):
    """At the post-grasp state MuJoCo's joint-space mass matrix equals Pinocchio's CRBA of the merged robot
    (the box's inertia on the left hand's body), and with the weld off its acceleration under efforts on
    the twelve joints equals Pinocchio's ABA."""
    sim = MujocoMechanism(scene.tree, "RK4", scene.start.period)
    s = scene.start
    assert sim.mass_matrix_gap(s.q0) < 1e-12
    assert sim.free_acceleration_gap(s.q0, s.v0, np.linspace(-5.0, 5.0, 12)) < 1e-10


def test_the_weld_holds_at_the_start_on_both_sides(scene):
    """Right after the grasp impulse the weld is closed and not opening: freefloat's closure residual and
    relative velocity, and MuJoCo's weld residual and its rate, all vanish."""
    s = scene.start
    model = s.merged.model
    data = model.createData()
    assert max(closure_drift(model, data, s.q0, [s.closure])) < 1e-12
    kinematics(model, data, s.q0, s.v0)
    _, J, _ = stacked([s.closure], model, data)
    assert np.abs(J @ s.v0).max() < 1e-12
    sim = MujocoMechanism(scene.tree, "RK4", s.period)
    sim.set_state(s.q0, s.v0)
    mujoco.mj_forward(sim.model, sim.data)
    assert sim.data.nefc == 6
    assert np.abs(sim.data.efc_pos).max() < 1e-12 and np.abs(sim.data.efc_vel).max() < 1e-12


@pytest.mark.slow
def test_both_sides_converge_to_the_reference(scene, reference):
    """freefloat's compiled Euler comes closer as its step shrinks and its RKMK4 at the period ends within
    1e-11; MuJoCo's RK4 and Euler come closer as their steps shrink."""
    period = scene.start.period

    def error(package, integrator, h, loop="python"):
        result = scene.run(Method(package, integrator, h, loop))()
        assert isinstance(result, MechanismResult)
        return scene.errors(result, reference)["state_error"]

    euler = [error("freefloat", "euler", h, "compiled") for h in (period, period / 10)]
    assert euler[1] < euler[0] / 5, euler
    assert error("freefloat", "rkmk4", period, "compiled") < 1e-11
    for integrator in ("RK4", "Euler"):
        theirs = [error("mujoco", integrator, h) for h in (period, period / 10)]
        assert theirs[1] < theirs[0] / 5, (integrator, theirs)


def test_freefloat_runs_the_compiled_loop(scene):
    """freefloat's methods run the compiled loop (plant and loop law in C++)."""
    s = scene.start
    from freefloat.dynamics.closures import ClosedModel
    from freefloat.dynamics.integrators import make_integrator
    from freefloat.dynamics.simulation import run

    result = run(s.merged, s.q0, s.v0, 2 * s.period, s.period, make_integrator("rkmk4", s.merged.model),
                 ClosedModel(s.merged, [s.closure], s.baumgarte), s.law(), backend="compiled")
    assert result.status == "completed" and result.backend == "compiled"


@pytest.mark.slow
def test_quick_sweep_taking_turns_gives_every_point():
    """The quick sweep, the methods taking turns over two rounds, gives one point per method, freefloat and
    MuJoCo, each with finite errors, the loop closed to 1e-6 m and a positive time."""
    scene = two_hand_capture_scene(NAME, quick=True)
    assert scene.turns
    points = list(sweep(scene, scene.reference(), repeats=2))
    assert [p.method for p in points] == scene.methods()
    assert {p.method.package for p in points} == {"freefloat", "mujoco"}
    for p in points:
        assert set(p.errors) == {"state_error", "constraint_drift"}
        assert all(math.isfinite(e) for e in p.errors.values()) and p.errors["constraint_drift"] < 1e-6, p
        assert p.wall_time > 0.0


@pytest.mark.slow
def test_unknown_scene_bad_duration_and_unknown_method_are_refused(scene):
    """An unknown name lists the valid one; a duration that is not whole periods and a method the scene
    does not sweep are named."""
    with pytest.raises(InvalidArgument, match=NAME):
        two_hand_capture_scene("capture_three_hands")
    with pytest.raises(InvalidArgument, match="whole number of 0.001 s control periods"):
        two_hand_capture_scene(NAME, 0.0105)
    with pytest.raises(InvalidArgument, match="pinocchio rkmk4"):
        scene.run(Method("pinocchio", "rkmk4", 1e-3))
