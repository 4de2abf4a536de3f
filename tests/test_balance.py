"""Tests of freefloat.dynamics.balance: with external wrenches, the momentum changes by the
impulse the loop applied and the energy by their work; a wrong impulse breaks the balance."""

from __future__ import annotations

import dataclasses
import tomllib
import warnings

import numpy as np
import pytest

from freefloat import load_robot, make_integrator, make_model, run
from freefloat.app.runner import prepare, simulate
from freefloat.app.scenes import builtin_scenes, parse_scene
from freefloat.dynamics.balance import balance, profile_scales
from freefloat.dynamics.metrics import conservation
from freefloat.dynamics.wrenches import ExternalWrench
from freefloat.robot.catalog import find_robot

SCENE = "detumble_impulse_arm1_joint3"


@pytest.fixture(scope="module")
def detumble():
    """The 500 N m capture impulse of sec 5.3 and the first 50 ms of its detumbling, integrated
    finely (40 RKMK4 steps per 1 ms period) so that the loop's own error is ~1e-11: (setup, outcome)."""
    raw = tomllib.loads(builtin_scenes()[SCENE].read_text())
    raw["simulation"].update(duration=0.05, substeps=40)
    scene = parse_scene(raw, source=builtin_scenes()[SCENE])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare(scene), simulate(scene)


@pytest.fixture(scope="module")
def satellite_run():
    """The dual-arm satellite tumbling while a ramped force and torque push one of its links
    (3-D: the link's CoM moves and its rotation axis turns during each period): (robot, wrenches,
    telemetry)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(find_robot("dual_arm_satellite"))
    v0 = np.random.default_rng(1).normal(size=robot.model.nv) * 0.3
    wrenches = (ExternalWrench("left_upper_arm_link", force=(30.0, -10.0, 20.0), torque=(5.0, 0.0, -3.0),
                               start=0.004, end=0.03, rise=0.01),)
    result = run(robot, robot.neutral(), v0, 0.05, 1e-3, make_integrator("rkmk4", robot.model),
                 make_model("exact", robot), None, wrenches=wrenches)
    return robot, wrenches, result.telemetry


def test_detumble_momentum_balances_the_applied_impulse(detumble):
    """The momentum changes by the impulse of the torque pulse, sampled at each period's start
    (500 N m x 7 ms of profile), to 1e-9 of it: a conservation law, not a drift."""
    _, outcome = detumble
    s = outcome.summary
    assert s["external_impulse"][5] == pytest.approx(500.0 * 0.007, rel=1e-12)
    assert s["momentum_balance_relative"] < 1e-9
    assert s["momentum_balance_max"] < 1e-9 * s["external_impulse"][5]


def test_detumble_energy_balances_the_work_of_the_torque(detumble):
    """The energy changes by the joint torques' work plus the impulse's work (126 J), to 1e-9 of it."""
    s = detumble[1].summary
    assert s["external_work"] == pytest.approx(126.0, abs=0.5)
    assert s["energy_balance_max"] < 1e-9 * s["external_work"]


def test_a_run_with_wrenches_reports_no_drift(detumble):
    """With external wrenches nothing is called a drift: the momentum, energy and CoM keys are balances."""
    assert not [key for key in detumble[1].summary if "drift" in key]


@pytest.mark.parametrize("wrong", [
    {"torque": (0.0, 0.0, 501.0)},             # 0.2 % too strong
    {"start": 0.006, "end": 0.016},          # the profile sampled one period late
])
def test_a_planted_wrong_impulse_breaks_the_balance(detumble, wrong):
    """Balanced against a wrench the loop did not apply, the momentum is off by far more than 1e-9."""
    setup, outcome = detumble
    planted = tuple(dataclasses.replace(w, **wrong) for w in setup.wrenches)
    s = conservation(outcome.telemetry, setup.robot, planted, setup.scene.simulation.control_period)
    assert s["momentum_balance_relative"] > 1e-4


def test_profile_scales_sample_the_ramp_like_the_loop():
    """The vectorised profile is ExternalWrench.scale at every time, ramp and edges included."""
    w = ExternalWrench("link", start=0.005, end=0.015, rise=0.005)
    step = ExternalWrench("link", start=0.002, end=0.004)
    t = np.arange(20) * 1e-3
    np.testing.assert_array_equal(profile_scales([w, step], t), [[w.scale(x), step.scale(x)] for x in t])


@pytest.mark.slow
def test_a_force_on_a_moving_link_balances_in_3d(satellite_run):
    """A force at a moving link CoM and a torque on a link whose axis turns: momentum (the
    force's moment integrated on the Hermite cubic) and energy (the torque's work by Magnus'
    expansion) balance to 1e-11, at one RKMK4 step per period."""
    robot, wrenches, tel = satellite_run
    res = balance(robot, tel, wrenches, 1e-3)
    assert np.abs(res.momentum).max() < 1e-11 and np.abs(res.energy).max() < 1e-11
    assert np.abs(res.com).max() < 1e-12
    assert np.abs(res.applied.work[-1]) > 0.1 and np.linalg.norm(res.applied.impulse[-1, 3:]) > 0.1


@pytest.mark.slow
def test_the_moment_of_the_force_is_not_negligible(satellite_run):
    """The angular momentum changes by far more than the torque's impulse alone: the force's
    moment about the origin, which the balance integrates, matters (so the test above can fail)."""
    _, wrenches, tel = satellite_run
    torque_only = profile_scales(wrenches, np.arange(50) * 1e-3).sum() * 1e-3 * np.array(wrenches[0].torque)
    assert np.linalg.norm(tel.momentum[-1, 3:] - tel.momentum[0, 3:] - torque_only) > 1e-2
