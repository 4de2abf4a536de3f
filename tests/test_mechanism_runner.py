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


FREE_BASE_SCENES = ("five_bar_free_base", "rsu_ppap_free_base")


def _on_base(raw_scene: str, tmp_path, name: str, duration: float, **mechanism):
    """The built-in scene ``raw_scene`` shortened to ``duration`` s, its [mechanism] keys
    replaced by ``mechanism`` (None removes a key), written as ``name`` and loaded."""
    import tomllib

    from freefloat.inputs import toml_text

    raw = tomllib.loads(builtin_scenes()[raw_scene].read_text())
    raw["simulation"]["duration"], raw["metrics"]["reaching_phase"] = duration, duration / 2
    raw["mechanism"].update(mechanism)
    raw["mechanism"] = {k: v for k, v in raw["mechanism"].items() if v is not None}
    path = tmp_path / f"{name}.toml"
    path.write_text(toml_text(raw))
    return load_scene(path)


def test_fixed_base_key_reproduces_todays_run_exactly(tmp_path):
    """``[mechanism] base = "fixed"`` written out runs exactly the run without the key (the
    compiled Orsino loop, bit for bit), and its summary has no base keys."""
    today = runner.simulate(_on_base(SMC, tmp_path, "today", 0.005))
    fixed = runner.simulate(_on_base(SMC, tmp_path, "fixed", 0.005, base="fixed"))
    assert fixed.summary["loop"] == today.summary["loop"] == "compiled"
    for name in ("t", "platform", "joints", "efforts", "drift"):
        np.testing.assert_array_equal(getattr(fixed.telemetry, name), getattr(today.telemetry, name))
    assert not fixed.extra_telemetry and "base_rotation_max" not in fixed.summary


@pytest.mark.slow
@pytest.mark.parametrize("name", FREE_BASE_SCENES)
def test_a_very_heavy_base_is_the_ground(tmp_path, name):
    """With a 1e8 kg base of 1e8 kg m^2, the free-base run (freefloat's constrained dynamics on the
    tree in the compiled loop, the law in the base frame) is the fixed-base run (Orsino's plant) of
    the same scene: the platform to 1e-9 m, the joints to 1e-8 rad, the efforts to 1e-6 of their
    peak; the base barely turns. Pinocchio's constraintDynamics (Python loop) as well."""
    duration = 0.02 if name.startswith("five_bar") else 0.1
    ground = runner.simulate(_on_base(name, tmp_path, "ground", duration, base="fixed", base_mass=None,
                                      base_inertia=None))
    b = ground.telemetry
    peak = np.nanmax(np.abs(b.efforts))
    for dynamics, loop in (("auto", "compiled"), ("constraint_dynamics", "python")):
        heavy = runner.simulate(_on_base(name, tmp_path, f"heavy_{dynamics}", duration, base_mass=1e8,
                                         base_inertia=[1e8] * 3, dynamics=dynamics))
        assert heavy.summary["loop"] == loop and heavy.summary["base_rotation_max"] < 1e-9
        a = heavy.telemetry
        np.testing.assert_allclose(a.platform, b.platform, rtol=0, atol=1e-9)
        np.testing.assert_allclose(a.joints, b.joints, rtol=0, atol=1e-8)
        np.testing.assert_allclose(a.efforts[:-1], b.efforts[:-1], rtol=0, atol=1e-6 * peak)


@pytest.mark.parametrize("name", FREE_BASE_SCENES)
def test_free_base_scenes_track_while_the_base_reacts(tmp_path, name):
    """The built-in free-base scenes, shortened: the base turns and moves (the reaction), the
    momentum stays put to 1e-9 at zero gravity, the loops stay closed, and the base's telemetry
    is returned for telemetry_base.npz with one row per mechanism row."""
    duration = 0.05 if name.startswith("five_bar") else 0.2
    run = runner.simulate(_on_base(name, tmp_path, name, duration))
    summary, base = run.summary, run.extra_telemetry["base"]
    assert run.status == "completed" and summary["base"] in ("planar", "free")
    assert summary["base_rotation_max"] > 1e-3 and summary["base_displacement_max"] > 1e-4
    assert summary["momentum_drift_max"] < 1e-9 and summary["loop_closure_drift_max"] < 1e-9
    assert len(base.t) == len(run.telemetry.t) and np.isfinite(base.momentum).all()
    np.testing.assert_allclose(summary["base_rotation_max"], np.linalg.norm(base.base_rotation, axis=1).max())


@pytest.mark.parametrize(("dynamics", "within", "efforts_within"),
                         [("closed_tree", 1e-12, 1e-6), ("constraint_dynamics", 1e-9, 1e-2)])
def test_the_revolute_closed_5r_tracks_as_the_point_closed_one(tmp_path, dynamics, within, efforts_within):
    """five_bar_revolute (the 5R closed by a revolute, on its spanning tree by freefloat's or by
    Pinocchio's constrained dynamics) tracks the circle as five_bar_sliding_mode (Orsino's compiled
    plant, a point closure) over 0.01 s: platform to 1e-12 m (Pinocchio's: 1e-9 m, its proximal
    mu 1e-4 on the redundant rows), efforts to 1e-6 of their peak (1e-2: the sliding-mode law's
    tanh(100 s) amplifies the state's differences)."""
    revolute = runner.simulate(_on_base("five_bar_revolute", tmp_path, "revolute", 0.01, dynamics=dynamics))
    point = runner.simulate(_on_base(SMC, tmp_path, "point", 0.01))
    assert revolute.summary["loop"] == "python" and point.summary["loop"] == "compiled"
    np.testing.assert_allclose(revolute.telemetry.platform, point.telemetry.platform, rtol=0, atol=within)
    efforts = point.telemetry.efforts[:-1]  # the last row holds no effort
    np.testing.assert_allclose(revolute.telemetry.efforts[:-1], efforts, rtol=0,
                               atol=efforts_within * np.abs(efforts).max())
