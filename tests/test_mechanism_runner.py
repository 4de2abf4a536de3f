"""Mechanism scenes end to end: the run is the direct simulation with the same controller, keeps
the loop closed, tracks to hundredths of a millimetre under sliding mode with 15 % errors, keeps
what it computed when it blows up or is interrupted, and names bad sizes."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat import SceneError
from freefloat.app import runner
from freefloat.app.experiments.mechanism import prepare
from freefloat.app.scenes import MechanismScene, builtin_scenes, load_scene
from freefloat.parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.sliding_mode import PlatformControl, circle_reference, printed_gains

from .conftest import scene_variant
from .loops import simulate

SMC = "five_bar_sliding_mode"
#: Eq 187's gains, as the built-in scene prints them.
EQ_187 = printed_gains(np.array([75.3, 108.0]), np.array([[1.25, 0.92], [1.68, 1.65]]),
                       {(0, 0): [37.0, 54.1], (1, 0): [22.7, 35.5], (1, 1): [17.5, 28.5]})


MECHANISM_SCENES = sorted(n for n, p in builtin_scenes().items() if isinstance(load_scene(p), MechanismScene))


def _scene(tmp_path, builtin=SMC, **sections):
    return load_scene(scene_variant(tmp_path / "scene.toml", builtin, **sections))


@pytest.fixture(scope="module")
def on_circle(tmp_path_factory):
    """Sliding mode against the 15 % plant for 0.05 s, starting on the circle with its velocity
    (0, r w) = (0, 1.9999) m/s, so the reaching phase is short."""
    scene = _scene(tmp_path_factory.mktemp("s"), initial={"platform_velocity": [0.0, 1.9999]},
                   simulation={"duration": 0.05}, metrics={"reaching_phase": 0.01})
    return runner.simulate(scene)


def test_run_is_the_numpy_reference_loop_with_the_5r_controller(tmp_path):
    """The scene (the compiled loop: plant, RK4 and sliding-mode law in C++) equals the Python
    loop on the numpy reference of the 15 % 5R driven by the numpy sliding-mode law with eq 187's
    gains, to round-off."""
    run = runner.simulate(_scene(tmp_path, simulation={"duration": 0.005}))
    assert run.summary["loop"] == "compiled"
    control = PlatformControl(five_bar(FiveBarParameters()).reference(), circle_reference, 40.0, EQ_187)
    plant = five_bar(TRUE_PARAMETERS).reference()
    q0 = plant.assemble(np.array([0.07, 0.17]), elbow_guess(TRUE_PARAMETERS, np.array([0.07, 0.17])))
    python = simulate(plant, q0, np.zeros(6), control.torque, 0.005, 1e-4, 100.0, backend="python")
    assert python.backend == "python"
    tel, ref = run.telemetry, python.telemetry
    np.testing.assert_allclose(tel.t, ref.t, rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.hstack((tel.platform, tel.joints)), ref.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tel.efforts[:-1], ref.efforts[:-1], rtol=1e-9)
    np.testing.assert_allclose(tel.drift, ref.drift, rtol=0, atol=1e-14)


def test_stabilised_loop_stays_closed(on_circle):
    """With Baumgarte lambda = 100 and RK4 at 0.1 ms, the loop-closure residual stays below 1e-9 m."""
    run, summary = on_circle, on_circle.summary
    assert run.status == "completed" and summary["loop_closure_drift_max"] < 1e-9
    assert summary["loop_closure_drift_max"] == run.telemetry.drift.max()


def test_sliding_mode_tracks_to_hundredths_of_a_millimetre(on_circle):
    """With 15 % parameter errors, sliding mode keeps each platform coordinate within 0.05 mm of
    the circle after the reaching phase (sec 5.6: errors in the hundredths of a millimetre)."""
    run, summary = on_circle, on_circle.summary
    tel = run.telemetry
    late = tel.t >= 0.01
    error = np.abs(tel.platform_reference[late] - tel.platform[late]).max(axis=0)
    np.testing.assert_allclose(summary["tracking_error_max"], error)
    assert np.all(error < 5e-5)


def test_diverging_run_keeps_its_samples(tmp_path):
    """Semi-implicit Euler with lambda = 1/h comes apart: status 'diverged', a message naming the
    residual, and every computed row kept (fewer than the run's 500 steps)."""
    scene = _scene(tmp_path, "five_bar_computed_torque",
                   simulation={"integrator": "euler", "step": 1e-3, "baumgarte": 1000.0})
    run = runner.simulate(scene)
    summary = run.summary
    assert run.status == summary["status"] == "diverged" and "loop-closure residual" in run.message
    assert 2 < len(run.telemetry.t) < 501 and run.steps == len(run.telemetry.t) - 1


def test_interrupted_run_keeps_its_samples(tmp_path):
    """Ctrl-C during the run returns the rows started so far, each with its efforts."""
    def interrupt(k):
        if k == 10:
            raise KeyboardInterrupt

    run = runner.simulate(_scene(tmp_path, simulation={"duration": 0.005}), progress=interrupt)

    summary = run.summary
    assert run.status == summary["status"] == "interrupted" and "interrupted by the user" in run.message
    assert len(run.telemetry.t) == 10 and np.isfinite(run.telemetry.efforts).all()


@pytest.mark.parametrize(("sections", "message"), [
    ({"trajectory": {"center": [0.0, 0.17, 0.0]}}, "'trajectory.center' must have shape (2,)"),
    ({"controller": {"T": [[1.0, 2.0]]}}, "'controller.T' must have shape (2, 2)"),
    ({"controller": {"n_ij": {"2,0": [1.0, 1.0]}}}, "'controller.n_ij' key '2,0'"),
    ({"trajectory": {"axes": [0, 2]}}, "'trajectory.axes' [0, 2] must index"),
    ({"initial": {"platform": [0.5, 0.5]}}, "'initial.platform': 5R: point"),
])
def test_sizes_and_start_are_checked_against_the_mechanism(tmp_path, sections, message):
    """Sizes that do not fit the 5R's two platform coordinates, and an unreachable start, fail
    naming the scene file and the key."""
    with pytest.raises(SceneError) as err:
        prepare(_scene(tmp_path, **sections))
    assert str(tmp_path / "scene.toml") in str(err.value) and message in str(err.value)


@pytest.mark.parametrize("name", MECHANISM_SCENES)
def test_builtin_mechanism_scenes_assemble(name):
    """Every built-in mechanism scene assembles its plant at the start with the loop closed."""
    prepared = prepare(load_scene(builtin_scenes()[name]))
    assert np.abs(prepared.setup.plant.constraint(prepared.q0)).max() < 1e-12
