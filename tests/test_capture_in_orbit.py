"""The one-hand capture in orbit (issue 39 item 1: freefloat.space.capture with an environment,
the capture experiment's orbit, the built-in capture_in_orbit scene): out of orbit it is the
inertial capture; in orbit the target's flight follows Clohessy-Wiltshire, the momentum balances
against the orbit's impulse, and the relative_orbit figure draws the telemetry in LVLH."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest

import freefloat
from freefloat import SceneError
from freefloat.app.experiments.capture import capture_fields
from freefloat.app.runner import prepare
from freefloat.app.scenes import find_scene
from freefloat.space.capture import TargetBody
from freefloat.space.orbit import base_in_lvlh, clohessy_wiltshire
from freefloat.space.orbit.lvlh import root_in_lvlh

#: A shortened capture_in_orbit: the grasp after 5 s of flight, 0.2 s of detumbling.
CONTACT, AFTER = 5.0, 0.2


def short_scene(orbit: bool = True):
    """capture_in_orbit with the grasp at CONTACT s and AFTER s after it, no files; without
    ``orbit``, its environment removed (the inertial capture)."""
    scene = find_scene("capture_in_orbit")
    return dataclasses.replace(
        scene, target=dataclasses.replace(scene.target, contact_time=CONTACT),
        simulation=dataclasses.replace(scene.simulation, duration=AFTER),
        output=dataclasses.replace(scene.output, figures=False, html=False),
        environment=scene.environment if orbit else ())


@pytest.fixture(scope="module")
def in_orbit():
    """The shortened capture in orbit: its setup and outcome."""
    setup = prepare(short_scene())
    return setup, freefloat.simulate(setup.scene, setup=setup)


@pytest.mark.slow
def test_out_of_orbit_the_capture_conserves_momentum_and_in_orbit_balances_it(in_orbit):
    """With the orbit removed the same capture conserves momentum after the grasp as the inertial
    capture does (no external wrench: RKMK4's drift, 2e-11 N s); in orbit the momentum changes by
    the orbit's impulse, and the balance against it closes as the inertial run conserves (within
    10x of its drift, 1e-5 of the impulse); the grasp impulse balances exactly in both."""
    _, orbit_run = in_orbit
    inertial = freefloat.simulate(short_scene(orbit=False)).summary
    drift = inertial["momentum_drift_after_impact"]
    assert drift < 1e-10
    assert "momentum_balance_max" not in inertial and "target_lvlh_relative_grasp" not in inertial
    summary = orbit_run.summary
    impulse = np.linalg.norm(summary["external_impulse"])
    assert impulse > 1e-6  # N s: the orbit's tidal impulse over the detumbling
    assert summary["momentum_balance_max"] < max(10.0 * drift, 1e-5 * impulse)
    assert "momentum_drift_after_impact" not in summary
    for run in (inertial, summary):
        assert run["momentum_balance_error"] < 1e-12 and run["status"] == "completed"
    assert inertial["impact_time"] == pytest.approx(summary["impact_time"], abs=0.01)


@pytest.mark.slow
def test_the_targets_flight_in_orbit_is_clohessy_wiltshire(in_orbit):
    """The target's CoM over its 5 s flight, in LVLH, stays within 1e-10 m of the CW closed form
    from its initial LVLH state (the linearisation's error, O(n^2 |p|^2 t^2 / R), is 1e-13 m),
    while it leaves the straight line it was aimed along by over 1e-5 m (the tidal drift)."""
    setup, outcome = in_orbit
    orbit = setup.environment[0].orbit
    rows = outcome.figures.lvlh
    grasp = len(outcome.extra_telemetry["pre_capture"].t)
    t, flight = rows.t[:grasp], rows.positions[:grasp, 1]
    q0, v0 = TargetBody(setup.target).initial_state()
    start = root_in_lvlh(orbit, t[:1], q0[None], v0[None])
    expected, _ = clohessy_wiltshire(orbit.mean_motion, start.position[0], start.velocity[0], t)
    assert np.abs(flight - expected).max() < 1e-10
    target = setup.target
    straight = orbit.to_lvlh(t, np.asarray(target.position) + np.outer(t, target.velocity))[0]
    assert np.abs(flight - straight).max() > 1e-5


@pytest.mark.slow
def test_the_relative_orbit_figure_draws_the_telemetry_in_lvlh(in_orbit):
    """The relative_orbit figure's base curves are lvlh.py's transform of the telemetry (before
    the grasp on the scene's orbit, after it on the same orbit's clock started at the grasp), and
    the summary's target-to-base LVLH offsets are the figure's rows at the grasp and the end."""
    from freefloat.app.viz.lvlh_figures import lvlh_figure

    setup, outcome = in_orbit
    orbit, rows = setup.environment[0].orbit, outcome.figures.lvlh
    pre, post = outcome.extra_telemetry["pre_capture"], outcome.telemetry
    t_hit = outcome.summary["impact_time"]
    expected = np.vstack((base_in_lvlh(orbit, pre).position, base_in_lvlh(orbit.later(t_hit), post).position[1:]))
    fig = lvlh_figure(*rows)
    for axis, ax in enumerate(fig.axes[:3]):
        t, drawn = ax.lines[0].get_data()
        np.testing.assert_allclose(drawn, expected[np.searchsorted(rows.t, t), axis], rtol=0, atol=1e-12)
    relative = rows.positions[:, 1] - rows.positions[:, 0]
    np.testing.assert_allclose(outcome.summary["target_lvlh_relative_grasp"], relative[len(pre.t) - 1], atol=1e-15)
    np.testing.assert_allclose(outcome.summary["target_lvlh_relative_final"], relative[-1], atol=1e-15)
    assert {"base_lvlh_position_final", "base_lvlh_quaternion_final"} <= set(outcome.summary)


def test_a_capture_refuses_a_field_it_does_not_apply():
    """A capture scene with thrusters in its environment is refused, the kind named (the capture
    applies only an orbit, to the robot, the target and the merged robot); without an orbit it
    flies in no field."""
    scene = find_scene("capture_in_orbit")
    thrusters = find_scene("satellite_thruster_hold").environment[0]
    with pytest.raises(SceneError, match="kind 'thrusters' is not applied by a capture"):
        capture_fields(SimpleNamespace(scene=dataclasses.replace(scene, environment=(*scene.environment, thrusters)),
                                       environment=()))
    assert capture_fields(SimpleNamespace(scene=dataclasses.replace(scene, environment=()), environment=())) is None
