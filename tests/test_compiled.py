"""The compiled loop (freefloat.dynamics.compiled): the rebuilt model against Pinocchio, every
integrator and the computed-torque law against the Python loop, and what it refuses."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings

from freefloat.dynamics.compiled import COMPILED_INTEGRATORS, CompiledLoop
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import ExactModel, make_model
from freefloat.dynamics.simulation import run
from freefloat.errors import InvalidArgument
from freefloat.paths import URDF_DIR

from freefloat import load_robot

from .conftest import random_robots, random_state, robot_from_case

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
    from freefloat.app.experiments.robot_run import simulate
    from freefloat.app.scenes import find_scene

    scene = find_scene("four_arm_joint_space")
    short = replace(scene, simulation=replace(scene.simulation, duration=0.3))
    runs = [simulate(joint_space.prepare(replace(short, simulation=replace(short.simulation, backend=b))), None, None)
            for b in ("python", "compiled")]
    assert [r.backend for r in runs] == ["python", "compiled"]
    assert np.abs(runs[0].telemetry.tau).max() > 1e-3  # the law acts
    assert_same_telemetry(runs[0].telemetry, runs[1].telemetry, tol=1e-9)
    np.testing.assert_allclose(runs[1].telemetry.joint_reference, runs[0].telemetry.joint_reference, atol=1e-15)


def scene_in_both_loops(name: str, duration: float):
    """A built-in scene over ``duration`` s in the Python and in the compiled loop."""
    from freefloat.app.experiments import experiment_for
    from freefloat.app.experiments.robot_run import simulate
    from freefloat.app.scenes import find_scene

    scene = find_scene(name)
    runs = []
    for backend in ("python", "compiled"):
        sim = replace(scene.simulation, duration=duration, backend=backend, model="exact")
        runs.append(simulate(experiment_for(scene).prepare(replace(scene, simulation=sim)), None, None))
    return runs


def test_detumbling_with_an_impulse_matches_the_python_loop():
    """The detumbling scene (a 500 N m impulse on a link, the Python detumbling controller between
    compiled periods) gives the Python loop's telemetry."""
    python, compiled = scene_in_both_loops("detumble_impulse_arm1_joint4", 0.05)
    assert [python.backend, compiled.backend] == ["python", "compiled"]
    assert np.abs(compiled.telemetry.momentum[-1] - compiled.telemetry.momentum[0]).max() > 1.0  # the impulse acts
    assert_same_telemetry(python.telemetry, compiled.telemetry, tol=1e-9)
    np.testing.assert_allclose(compiled.telemetry.joint_reference, python.telemetry.joint_reference, atol=1e-12)


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


def test_an_unsupported_joint_is_named():
    """A joint kind the compiled loop does not rebuild (a 3-dof translation) is refused with its name."""
    robot = robot_named("two_arm_planar.urdf")
    model = pin.Model(robot.model)
    joint = model.addJoint(1, pin.JointModelTranslation(), pin.SE3.Identity(), "slider")
    model.appendBodyToJoint(joint, pin.Inertia.Random(), pin.SE3.Identity())
    with pytest.raises(InvalidArgument, match="joint .slider.*JointModelTranslation"):
        CompiledLoop(replace(robot, model=model), make_integrator("euler", model), 1e-3)


def test_a_blow_up_keeps_every_row_of_its_chunk():
    """A run that blows up in the middle of a compiled chunk keeps the rows before it and says
    where, exactly as the Python loop does."""
    robot = robot_named("two_arm_planar.urdf")
    q0, v0 = robot.neutral(), np.full(robot.model.nv, 1.0)  # Euler at 50 ms: blows up after ~15 periods
    python, compiled = (run(robot, q0, v0, 50.0, 0.05, make_integrator("euler", robot.model), ExactModel(robot),
                            backend=backend) for backend in ("python", "compiled"))
    assert python.status == compiled.status == "diverged" and compiled.message == python.message
    assert 5 < len(compiled.telemetry.t) == len(python.telemetry.t) < 1000
    assert_same_telemetry(python.telemetry, compiled.telemetry)
