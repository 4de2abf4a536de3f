"""The sliding variables s of a mechanism run (thesis sec 5.5-5.6, figs 14-15 and 20-21):
recorded in the telemetry for sliding-mode and computed-torque runs, saved, and drawn."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.app import runner
from freefloat.app.scenes import load_scene
from freefloat.dynamics.telemetry import MechanismTelemetry
from freefloat.parallel.five_bar import TRUE_PARAMETERS, elbow_guess, five_bar

from .conftest import scene_variant
from .loops import simulate

#: The built-in scenes' circle: centre (m), radius (m), rate (rad/s); and lambda (1/s).
CENTER, RADIUS, RATE, LAM = np.array([0.0, 0.17]), 0.07, 28.57, 40.0


@pytest.mark.slow
@pytest.mark.parametrize("name", ["five_bar_sliding_mode", "five_bar_computed_torque"])
def test_recorded_s_is_the_law_definition_from_the_platform_error_and_its_rate(tmp_path, name):
    """s = -(edot + lambda e), e = q#_d - q#, recomputed from the recorded error and the platform
    rate of the same run in the Python loop under the recorded efforts, equals the recorded s."""
    run = runner.simulate(load_scene(scene_variant(tmp_path / "s.toml", name, simulation={"duration": 0.02})))
    tel = run.telemetry
    q0 = np.hstack((tel.platform[0], tel.joints[0]))
    plant = five_bar(TRUE_PARAMETERS).reference()
    np.testing.assert_allclose(plant.assemble(tel.platform[0], elbow_guess(TRUE_PARAMETERS, tel.platform[0])), q0,
                               atol=1e-12)
    efforts = {round(t / 1e-4): u for t, u in zip(tel.t, tel.efforts)}
    replay = simulate(plant, q0, np.zeros(6), lambda t, q, qd: efforts[round(t / 1e-4)], 0.02, 1e-4, 100.0,
                      backend="python")
    np.testing.assert_allclose(replay.telemetry.q[:, :2], tel.platform, atol=1e-10)
    angle = RATE * tel.t
    e = tel.platform_reference - tel.platform
    np.testing.assert_allclose(tel.platform_reference, CENTER + RADIUS * np.column_stack((np.cos(angle), np.sin(angle))),
                               atol=1e-15)
    rate_d = RADIUS * RATE * np.column_stack((-np.sin(angle), np.cos(angle)))
    edot = rate_d - replay.telemetry.v[:, :2]
    np.testing.assert_allclose(tel.sliding, -(edot + LAM * e), rtol=0, atol=1e-8 * np.abs(tel.sliding).max())
    assert np.abs(tel.sliding).max() > 0.1  # the start is off the circle's velocity: s is not trivially 0


def test_s_is_saved_and_drawn(tmp_path):
    """telemetry.npz carries ``sliding`` (N, 2) and the run folder has the figure sliding_variables."""
    out = tmp_path / "run"
    runner.simulate(load_scene(scene_variant(tmp_path / "s.toml", "five_bar_sliding_mode",
                                             simulation={"duration": 0.01})), out=out)
    saved = MechanismTelemetry.load(out / "telemetry.npz")
    assert saved.sliding.shape == saved.platform.shape
    assert (out / "sliding_variables.png").is_file()


@pytest.fixture(scope="module")
def rsu_ppap_study():
    """The study's design (2 cm grid of home +- 4 cm) and the built-in 2RSU+PPaP scene."""
    from freefloat.app.scenes import builtin_scenes
    from freefloat.lab.reproduce.rsu_ppap_sliding_report import SCENE, design

    return design(), load_scene(builtin_scenes()[SCENE])


@pytest.mark.slow
def test_rsu_ppap_scene_prints_the_worst_case_design(rsu_ppap_study):
    """The scene's n, T and n_ij are the design's rounded to 4 significant digits."""
    gains, scene = rsu_ppap_study
    ctrl = scene.controller
    np.testing.assert_allclose(ctrl.n, gains.n, rtol=5e-4)
    np.testing.assert_allclose(ctrl.T, gains.T, rtol=5e-4)
    assert set(ctrl.n_ij) == {f"{i},{j}" for i, j in gains.n_ij}
    for (i, j), value in gains.n_ij.items():
        np.testing.assert_allclose(ctrl.n_ij[f"{i},{j}"], value, rtol=5e-4)


@pytest.mark.slow
@pytest.mark.parametrize("plant", ["true_15", "true_50"])
def test_rsu_ppap_sliding_mode_out_tracks_computed_torque(rsu_ppap_study, plant):
    """On the plant 15 % or 50 % off, the scene under sliding mode (the designed gains) keeps each
    platform coordinate within 0.3 times computed torque's max error (eq 190, same lambda, same
    plant) after the reaching phase, both run through the one loop."""
    from freefloat.lab.reproduce.rsu_ppap_sliding_report import variant

    gains, scene = rsu_ppap_study
    smc, ct = (runner.simulate(variant(scene, plant, g)).summary for g in (gains, None))
    assert smc["status"] == ct["status"] == "completed"
    assert np.all(np.array(smc["tracking_error_max"]) < 0.3 * np.array(ct["tracking_error_max"]))
