"""The simulation loop: conservation laws, telemetry against Pinocchio, wrenches, failures."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings

from freefloat.dynamics.integrators import RungeKutta4, make_integrator
from freefloat.dynamics.models import ExactModel
from freefloat.dynamics.plants import vector_space
from freefloat.dynamics.simulation import run
from freefloat.dynamics.wrenches import ExternalWrench
from freefloat.robot.conventions import base_state

from .conftest import random_robots, random_state, robot_from_case

BOTH = pytest.mark.parametrize("backend", ["python", "compiled"])


def torque_free(robot, q0, v0, duration=0.5, period=0.01, substeps=4, **kwargs):
    integrator = make_integrator("rkmk4", robot.model, substeps=substeps)
    return run(robot, q0, v0, duration, period, integrator, ExactModel(robot), **kwargs)


@BOTH
@settings(max_examples=15, deadline=None)
@given(random_robots(max_links=6))
def test_torque_free_motion_conserves_momentum_and_energy(tmp_path_factory, backend, case):
    """Random robots tumbling freely keep their momentum (about the origin) and energy, in
    either loop."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q0, v0 = random_state(robot, rng, speed=0.5)
    tel = torque_free(robot, q0, v0, backend=backend).telemetry
    scale = max(1.0, np.abs(tel.momentum[0]).max())
    assert np.abs(tel.momentum - tel.momentum[0]).max() < 1e-7 * scale
    assert np.abs(tel.energy - tel.energy[0]).max() < 1e-5 * max(1.0, tel.energy[0])
    np.testing.assert_allclose(tel.com, tel.com[0] + np.outer(tel.t, tel.momentum[0, :3]) / pin.computeTotalMass(robot.model), atol=1e-7)


@pytest.mark.slow
@BOTH
@settings(max_examples=10, deadline=None)
@given(random_robots(max_links=6))
def test_telemetry_matches_independent_pinocchio_calls(tmp_path_factory, backend, case):
    """Recorded momentum, base state and end-effector poses equal direct computations (CCRBA,
    FK), in either loop."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q0, v0 = random_state(robot, rng, speed=0.5)
    tel = torque_free(robot, q0, v0, duration=0.05, backend=backend).telemetry
    data = robot.model.createData()
    k = len(tel.t) - 1
    q, v = tel.q[k], tel.v[k]
    pin.ccrba(robot.model, data, q, v)
    hg = data.Ag @ v
    com = data.com[0]
    np.testing.assert_allclose(tel.momentum[k, :3], hg[:3], atol=1e-10)
    np.testing.assert_allclose(tel.momentum[k, 3:], hg[3:] + np.cross(com, hg[:3]), atol=1e-10)
    r0, R0, x0dot = base_state(robot, q, v)
    np.testing.assert_allclose(tel.base_position[k], r0, atol=1e-12)
    np.testing.assert_allclose(tel.base_twist[k], x0dot, atol=1e-10)
    np.testing.assert_allclose(pin.Quaternion(tel.base_quaternion[k]).matrix(), R0, atol=1e-12)
    pin.framesForwardKinematics(robot.model, data, q)
    for i, fid in enumerate(robot.end_effector_frame_ids):
        np.testing.assert_allclose(tel.ee_position[k, i], data.oMf[fid].translation, atol=1e-12)


@BOTH
def test_external_force_changes_momentum_by_its_impulse(backend):
    """A force F on a link during [0.1, 0.3) s changes the linear momentum by F * 0.2 s exactly,
    in either loop."""
    from freefloat import load_robot

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    q0, v0 = random_state(robot, np.random.default_rng(4), speed=0.1)
    force = np.array([3.0, -2.0, 1.0])
    wrench = ExternalWrench("arm2_link3", force=tuple(force), torque=(0.0, 0.5, 0.0), start=0.1, end=0.3)
    tel = torque_free(robot, q0, v0, duration=0.4, period=0.01, wrenches=(wrench,), backend=backend).telemetry
    np.testing.assert_allclose(tel.momentum[-1, :3] - tel.momentum[0, :3], force * 0.2, atol=1e-9)


def test_unknown_wrench_link_is_rejected(tmp_path):
    """A wrench on a link that does not exist fails naming it."""
    from freefloat import FreefloatError, load_robot

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    with pytest.raises(FreefloatError, match="link 'arm9' does not exist"):
        torque_free(robot, robot.neutral(), np.zeros(robot.model.nv), wrenches=(ExternalWrench("arm9"),))


@BOTH
def test_blow_up_stops_with_a_message_and_keeps_the_samples(backend):
    """An unstable run (Euler, huge step, fast spin) stops as 'diverged' and returns its samples,
    in either loop."""
    from freefloat import load_robot

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    q0, v0 = robot.neutral(), np.full(robot.model.nv, 50.0)
    result = run(robot, q0, v0, 50.0, 0.5, make_integrator("euler", robot.model), ExactModel(robot), backend=backend)
    assert result.status == "diverged" and result.backend == backend and "t = " in result.message
    assert 0 < len(result.telemetry.t) < 101
    assert np.isfinite(result.telemetry.q).all()


def test_duration_must_be_a_whole_number_of_periods():
    """A duration that is not a multiple of the control period is refused, not rounded."""
    model = pin.buildSampleModelManipulator()
    with pytest.raises(ValueError, match="whole number"):
        run(None, np.zeros(model.nq), np.zeros(model.nv), 1.0005, 0.001, None, None)


@pytest.mark.parametrize("duration, period", [(1e9, 0.001), (1.0, 1e-12)])
def test_a_run_too_long_for_memory_is_refused_at_once(duration, period):
    """A run whose telemetry would not fit in memory is refused before it starts, naming its
    duration and period (run(duration=1e9) grew by 23 MB/s until memory ran out)."""
    import time

    from freefloat import InvalidArgument, load_robot

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    started = time.perf_counter()
    with pytest.raises(InvalidArgument, match=f"duration {duration} s in control periods of {period} s.* GB"):
        run(robot, robot.neutral(), np.zeros(robot.model.nv), duration, period,
            make_integrator("rkmk4", robot.model), ExactModel(robot))
    assert time.perf_counter() - started < 1.0


@pytest.mark.parametrize("q0, v0, period, message", [(None, None, 0.001, "'v0' must hold real numbers"),
                                                     ("q", None, 0.001, "'v0' must hold real numbers"),
                                                     (None, 0, None, "'control_period' must be a real number")])
def test_a_run_refuses_arguments_that_are_no_numbers(q0, v0, period, message):
    """A missing velocity, a configuration of strings or a period of None is refused naming it
    (the compiled loop's ValueError, numpy's message or a TypeError, before)."""
    from freefloat import InvalidArgument, load_robot

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    q0 = robot.neutral() if q0 is None else np.full(robot.model.nq, q0)
    v0 = np.zeros(robot.model.nv) if v0 == 0 else v0
    with pytest.raises(InvalidArgument, match=message):
        run(robot, q0, v0, 0.01, period, make_integrator("rkmk4", robot.model), ExactModel(robot))


def test_recording_less_often_than_the_run_is_long_keeps_its_ends():
    """record_every above the number of periods records the first and the last row, as the
    number of periods does (10**12 overflowed the compiled loop's constructor)."""
    from freefloat import load_robot

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    args = (robot, robot.neutral(), np.full(robot.model.nv, 0.1), 0.01, 0.001, make_integrator("rkmk4", robot.model),
            ExactModel(robot))
    assert np.array_equal(run(*args, record_every=10**12).telemetry.t, run(*args, record_every=10).telemetry.t)


def test_interrupted_run_keeps_what_it_computed():
    """Ctrl-C during a run stops it as 'interrupted' with the samples recorded so far."""
    from freefloat import load_robot

    from .conftest import REPO

    class InterruptAt:
        def __init__(self, t_stop):
            self.t_stop = t_stop

        def torque(self, t, q, v):
            if t >= self.t_stop:
                raise KeyboardInterrupt
            return np.zeros(robot.n_joints)

        def reference(self, t):
            return None

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    result = run(robot, robot.neutral(), np.zeros(robot.model.nv), 1.0, 0.01,
                 make_integrator("rkmk4", robot.model), ExactModel(robot), controller=InterruptAt(0.25))
    assert result.status == "interrupted" and "t = 0.25" in result.message
    assert len(result.telemetry.t) == 25 and result.telemetry.t[-1] == pytest.approx(0.24)


def test_a_sample_interrupted_half_way_is_not_kept(monkeypatch):
    """Ctrl-C while a telemetry row is being written leaves that row out: every kept row is a
    whole sample (a zero quaternion from a half-written row crashed the figures)."""
    import warnings

    from freefloat import load_robot
    from freefloat.dynamics import simulation
    from freefloat.dynamics.integrators import make_integrator
    from freefloat.dynamics.models import make_model
    from freefloat.paths import URDF_DIR

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(URDF_DIR / "two_arm_planar.urdf", visuals=False)
    real, calls = simulation.Recorder.record, []

    def record(self, row, t, *args):
        calls.append(row)
        if len(calls) == 7:
            self.tel.t[row] = t  # half a row, then Ctrl-C
            raise KeyboardInterrupt
        return real(self, row, t, *args)

    monkeypatch.setattr(simulation.Recorder, "record", record)
    result = run(robot, robot.neutral(), np.zeros(robot.model.nv), 0.05, 1e-3,
                 make_integrator("rkmk4", robot.model), make_model("exact", robot), backend="python")
    assert result.status == "interrupted" and len(result.telemetry.t) == 6
    assert np.allclose(np.linalg.norm(result.telemetry.base_quaternion, axis=1), 1.0)


def test_without_progress_the_compiled_loop_returns_to_python_every_thousand_periods(monkeypatch):
    """With no progress to report, the compiled loop returns to Python at most every
    UNREPORTED_PERIODS periods (and at each full telemetry chunk), not 200 times a run, and the
    run is the same bit for bit as one reporting progress."""
    from freefloat import load_robot
    from freefloat.dynamics import compiled, simulation

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    q0, v0 = random_state(robot, np.random.default_rng(6), speed=0.5)
    calls = []
    original = compiled.CompiledLoop.run
    monkeypatch.setattr(compiled.CompiledLoop, "run", lambda loop, *a: calls.append(a[0]) or original(loop, *a))

    def tumble(progress):
        calls.clear()
        return run(robot, q0, v0, 2.5, 0.001, make_integrator("rkmk4", robot.model), ExactModel(robot),
                   backend="compiled", record_every=10, progress=progress).telemetry

    reported = tumble(lambda k: None)
    assert len(calls) >= 200
    quiet = tumble(None)
    assert calls == [1000, 2000, 2500]
    assert simulation.UNREPORTED_PERIODS == 1000
    for field in ("q", "v", "momentum", "energy"):
        assert np.array_equal(getattr(quiet, field), getattr(reported, field))


@pytest.mark.parametrize("backend", ["python", "compiled"])
def test_progress_reports_the_loop_s_start_and_its_end(backend):
    """``progress`` hears 0 as the loop starts (when its wall time starts) and the last period
    when it ends, also when the periods are no multiple of the report interval (the bar of a
    403-period run stopped at 402), counting up in between."""
    from freefloat import load_robot

    from .conftest import REPO

    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    calls = []
    result = run(robot, robot.neutral(), np.full(robot.model.nv, 0.1), 0.403, 1e-3,
                 make_integrator("rkmk4", robot.model), ExactModel(robot), progress=calls.append, backend=backend)
    assert result.steps == 403 and result.backend == backend
    assert calls[0] == 0 and calls[-1] == 403 and calls == sorted(set(calls)) and len(calls) > 100


def test_one_call_runs_a_robot_and_a_plant_alike():
    """``run`` on a robot's tree wrapped as a plant (the plant loop) ends where ``run`` on the
    robot (its own loop) ends, both with the integrator and model given by name."""
    from freefloat import load_robot
    from freefloat.dynamics.plants.tree import TreePlant
    from freefloat.paths import URDF_DIR

    robot = load_robot(URDF_DIR / "dual_arm_satellite.urdf", visuals=False)
    q0, v0 = robot.neutral(), np.full(robot.model.nv, 0.2)
    alone = run(robot, q0, v0, 0.05, 1e-3, "rkmk4", "exact", backend="python")
    plant = run(TreePlant(robot, ExactModel(robot)), q0, v0, 0.05, 1e-3, "rkmk4", backend="python")
    assert alone.status == plant.status == "completed" and len(alone.telemetry.t) == len(plant.telemetry.t) == 51
    np.testing.assert_allclose(plant.telemetry.q, alone.telemetry.q, rtol=0, atol=1e-12)
    assert alone.summary == alone.loop_summary() and alone.summary["steps"] == 50 and alone.folder is None


@pytest.mark.parametrize("given, named", [({"model": "exact"}, "model"), ({"wrenches": (None,)}, "wrenches"),
                                          ({"integrator": RungeKutta4(vector_space(1))}, "integrator")])
def test_an_argument_a_plant_does_not_take_is_named(given, named):
    """A robot's argument handed with a plant is refused naming it, not ignored."""
    from freefloat import InvalidArgument

    class Still:  # the smallest plant: one coordinate, no force
        name, space, n_efforts, max_drift = "still", vector_space(1), 0, np.inf

        def acceleration(self, q, v, u):
            return np.zeros(1)

    with pytest.raises(InvalidArgument, match=f"^{named}: "):
        run(Still(), np.zeros(1), np.zeros(1), 0.01, 1e-3, **given)


@pytest.mark.parametrize("argument, value", [("integrator", None), ("integrator", {}), ("model", {}),
                                             ("controller", "pd")])
def test_run_refuses_an_integrator_model_or_controller_that_is_not_one(argument, value):
    """run with None, a dict or a string where an integrator, a model or a controller belongs is
    refused naming the argument, before any step."""
    from freefloat import load_robot
    from freefloat.errors import InvalidArgument

    robot = load_robot("two_arm_planar", visuals=False)
    with pytest.raises(InvalidArgument, match=f"'{argument}' takes "):
        run(robot, robot.neutral(), np.zeros(robot.model.nv), 0.1, 0.01, **{argument: value})


@BOTH
def test_a_controller_giving_the_wrong_number_of_torques_is_an_error_not_a_divergence(backend):
    """A torque vector of the wrong length raises BadShape naming both lengths, instead of a run 'diverged'."""
    from freefloat import load_robot
    from freefloat.errors import BadShape

    class ThreeTorques:
        def torque(self, t, q, v):
            return np.zeros(3)

        def reference(self, t):
            return None

    robot = load_robot("two_arm_planar", visuals=False)
    with pytest.raises(BadShape, match=r"torque\(t, q, v\) gave \(3,\) at t = 0 s; the robot takes \(8,\)"):
        run(robot, robot.neutral(), np.zeros(robot.model.nv), 0.1, 0.01, controller=ThreeTorques(), backend=backend)
