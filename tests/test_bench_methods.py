"""Each bench method runs the scene from its initial state: MuJoCo and freefloat reach the same
final state, the Runge-Kutta methods' errors fall with the step at their order, and on the
controlled scene both packages apply the same law."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from freefloat.lab.bench.in_mujoco.mjcf import mjcf_from_model
from freefloat.lab.bench.in_mujoco.state import to_mujoco
from freefloat.lab.bench.race.scene import Method
from freefloat.lab.bench.race.sweep import measure as measure_point
from freefloat.lab.bench.scenes.controlled import controlled_scene, mujoco_law
from freefloat.lab.bench.scenes.free_floating import FreeFloatingBench
from freefloat.lab.bench.scenes.methods import methods, reference
from freefloat.lab.bench.scenes.tumbling import tumbling_scene


def measure(scene, method, ref, repeats):
    """:func:`freefloat.lab.bench.race.sweep.measure` of ``method`` on a bare free-floating scene."""
    return measure_point(FreeFloatingBench(scene, "", (), {}), method, ref, repeats)


@pytest.fixture(scope="module")
def scene():
    """The balanced four-arm robot tumbling for 0.2 s (fast enough that errors sit above round-off)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return tumbling_scene("four_arm", duration=0.2, seed=1)


@pytest.fixture(scope="module")
def ref(scene):
    """The scene's dopri5 reference at rtol 1e-13."""
    return reference(scene)


@pytest.mark.parametrize(("package", "integrator"), [("freefloat", "rkmk4"), ("mujoco", "RK4")])
def test_rk4_errors_fall_at_fourth_order(scene, ref, package, integrator):
    """Halving the step divides the final-state error of an RK4 by more than 10 (2^4 = 16)."""
    coarse, fine = (measure(scene, Method(package, integrator, h), ref, 1).state_error for h in (0.02, 0.01))
    assert 1e-13 < fine < coarse / 10.0


def test_mujoco_rk4_reaches_the_freefloat_reference(scene, ref):
    """MuJoCo's RK4 at 1 ms ends within 1e-9 of freefloat's reference: same model, same start."""
    point = measure(scene, Method("mujoco", "RK4", 1e-3), ref, 1)
    assert point.state_error < 1e-9 and point.errors["momentum_error"] < 1e-9


def test_euler_at_equal_steps_agrees_between_packages(scene, ref):
    """Both semi-implicit Eulers are first order with the same error to 5 % at equal step."""
    ff = measure(scene, Method("freefloat", "euler", 1e-3), ref, 1).state_error
    mj = measure(scene, Method("mujoco", "Euler", 1e-3), ref, 1).state_error
    assert ff == pytest.approx(mj, rel=0.05)


def test_sweep_covers_every_integrator_and_step():
    """The sweep holds each fixed-step method at each step and dopri5 at each tolerance, in both
    of freefloat's loops, with the bare Pinocchio loop and MuJoCo."""
    points = methods((1e-2, 1e-3), (1e-6,))
    assert len(points) == 3 * 2 + 1 + 5 * 2 + 2 + 2 + 3 * 2
    assert {p.label for p in points} == {
        "freefloat euler", "freefloat rkmk4", "freefloat rk4_naive", "freefloat dopri5", "freefloat euler compiled",
        "freefloat rkmk3 compiled", "freefloat rkmk4 compiled", "freefloat rkmk6 compiled", "freefloat rkmk8 compiled",
        "freefloat dopri5 compiled", "freefloat bs32 compiled", "pinocchio euler", "mujoco Euler",
        "mujoco implicitfast", "mujoco RK4"}


@pytest.mark.parametrize("integrator", ["euler", "rkmk4", "dopri5"])
def test_compiled_loop_ends_where_the_python_loop_does(scene, ref, integrator):
    """Each compiled bench method ends at the Python method's final state (same steps or the same
    adaptive path), so their errors agree to round-off."""
    setting = 1e-8 if integrator == "dopri5" else 2e-3
    python, compiled = (measure(scene, Method("freefloat", integrator, setting, loop), ref, 1)
                        for loop in ("python", "compiled"))
    assert compiled.state_error == pytest.approx(python.state_error, rel=1e-6, abs=1e-13)


def test_bare_pinocchio_loop_is_freefloats_euler(scene, ref):
    """The bare Python loop of pin.aba and pin.integrate is the same semi-implicit Euler as
    freefloat's: the same final-state error."""
    bare = measure(scene, Method("pinocchio", "euler", 1e-3), ref, 1).state_error
    ff = measure(scene, Method("freefloat", "euler", 1e-3), ref, 1).state_error
    assert bare == pytest.approx(ff, rel=1e-9)


def test_compiled_blow_up_counts_as_diverged(scene, ref):
    """A compiled run that blows up (Euler at 0.1 s from a 300x faster start) gets infinite errors."""
    fast = dataclasses.replace(scene, v0=300.0 * scene.v0)
    point = measure(fast, Method("freefloat", "euler", 0.1, "compiled"), ref, 1)
    assert np.isinf(point.state_error)


def test_reference_is_reproducible(scene, ref):
    """A second reference run gives the same final state to the last bit (no hidden state)."""
    again = reference(scene)
    assert np.array_equal(again[0], ref[0]) and np.array_equal(again[1], ref[1])


def test_unstable_mujoco_run_counts_as_diverged(scene, ref, tmp_path, monkeypatch):
    """MuJoCo's Euler at 50 ms on a 300x faster start blows up: the point gets infinite errors,
    not the error of the rest state MuJoCo silently resets to, and no MUJOCO_LOG.TXT is left."""
    monkeypatch.chdir(tmp_path)
    fast = dataclasses.replace(scene, v0=300.0 * scene.v0)
    point = measure(fast, Method("mujoco", "Euler", 0.05), ref, 1)
    assert np.isinf(point.state_error) and point.wall_time > 0.0
    assert not any(tmp_path.iterdir())


def test_both_packages_end_at_the_same_time_when_the_step_does_not_divide(scene, ref):
    """At a step that does not divide the duration (30 ms into 0.2 s) both RK4s take 7 equal
    steps and end with the same error to 1 %."""
    ff = measure(scene, Method("freefloat", "rkmk4", 0.03), ref, 1).state_error
    mj = measure(scene, Method("mujoco", "RK4", 0.03), ref, 1).state_error
    assert ff == pytest.approx(mj, rel=0.01)


@pytest.fixture(scope="module")
def controlled():
    """The controlled scene over 0.1 s."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return controlled_scene(0.1)


def test_mujoco_law_is_freefloats_computed_torque(controlled):
    """The law written on MuJoCo's own mass matrix and bias forces gives freefloat's
    computed-torque torques (Pinocchio's CRBA and RNEA) at the same moving state."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(mjcf_from_model(controlled.model, "controlled", 1e-3, "RK4"))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(2)
    q = controlled.q0.copy()
    q[7:] += rng.uniform(-0.3, 0.3, q.size - 7)
    v = rng.normal(0.0, 0.5, controlled.model.nv)
    data.qpos[:], data.qvel[:] = to_mujoco(q, v)
    data.time = 0.03
    mujoco.mj_forward(model, data)
    expected = controlled.make_controller().torque(0.03, q, v)
    np.testing.assert_allclose(mujoco_law(controlled, model, data), expected, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("loop", ["python", "native"])
def test_controlled_rk4s_end_alike(controlled, loop):
    """Under the same law held over 1 ms, MuJoCo's RK4 (either controller) and freefloat's
    compiled RKMK4 end with the same error against the reference to 1 %."""
    ref = reference(controlled)
    ff = measure(controlled, Method("freefloat", "rkmk4", 1e-3, "compiled"), ref, 1).state_error
    mj = measure(controlled, Method("mujoco", "RK4", 1e-3, loop), ref, 1).state_error
    assert 1e-14 < ff == pytest.approx(mj, rel=0.01)


def test_controlled_python_and_compiled_loops_agree(controlled):
    """freefloat's Python and compiled loops end at the same state under computed torque."""
    ref = reference(controlled)
    python, compiled = (measure(controlled, Method("freefloat", "rkmk4", 5e-4, loop), ref, 1).state_error
                        for loop in ("python", "compiled"))
    assert compiled == pytest.approx(python, rel=1e-6, abs=1e-13)
