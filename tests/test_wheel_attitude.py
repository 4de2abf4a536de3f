"""Base attitude control with reaction wheels (freefloat.space.control.wheel_attitude) through the
one loop: the law's accelerations against Pinocchio's ABA, momentum conserved with the wheels
torqued, the attitude held where free wheels let it drift, saturation reported, the run folder."""

from __future__ import annotations

import dataclasses
import tomllib

import numpy as np
import pinocchio as pin
import pytest

from freefloat.app.experiments.joint_space import prepare
from freefloat.app.runner import simulate
from freefloat.app.scenes import load_scene
from freefloat.dynamics.metrics import rotation_angle
from freefloat.robot.wheels import Wheels
from freefloat.space.control.wheel_attitude import WheelAttitudeControl

from .conftest import random_state, scene_variant, toml_text

#: The satellite wheel scene shortened: arms swing 20 deg in 1 s, 1.2 s run.
SHORT = {"task": {"duration": 1.0}, "simulation": {"duration": 1.2}}
#: Wheel limits no test motion reaches.
UNLIMITED = {"max_torque": 1e3, "max_momentum": 1e3}


def short_scene(tmp_path, builtin: str = "satellite_wheels", wheels: dict | None = None, **sections: dict):
    """A built-in wheel scene (the satellite's shortened), without figures or page, with the given
    keys of each section and of every ``[[wheels]]`` table replaced (written in ``tmp_path``, made
    if need be)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    merged = {key: dict(value) for key, value in SHORT.items()} if builtin == "satellite_wheels" else {}
    merged["output"] = {"figures": False, "html": False}
    for section, values in sections.items():
        merged.setdefault(section, {}).update(values)
    path = scene_variant(tmp_path / "s.toml", builtin, **merged)
    raw = tomllib.loads(path.read_text())
    for table in raw["wheels"]:
        table.update(wheels or {})
    path.write_text(toml_text(raw))
    return load_scene(path)


def test_the_law_gives_the_attitude_acceleration_and_keeps_the_arms_law(tmp_path):
    """At a random state, Pinocchio's ABA under the composed torques gives the base the angular
    acceleration of the attitude law (``Kp log(R^T R_d) - Kd omega``, base frame) and the arm
    joints the accelerations its computed-torque law asks at the arm's view of the state (wheel
    rates zero): ``qddot_d + Kp e + Kd edot``."""
    setup = prepare(short_scene(tmp_path))
    arm = setup.controller
    wheels = Wheels(setup.wheels.robot, tuple(dataclasses.replace(w, max_torque=1e9, max_momentum=1e9)
                                              for w in setup.wheels.wheels))  # no limit in the way
    target = pin.rpy.rpyToMatrix(0.1, -0.2, 0.3)
    law = WheelAttitudeControl(wheels, arm, target, kp=7.0, kd=3.0)
    model = wheels.robot.model
    q, v = random_state(wheels.robot, np.random.default_rng(2), speed=0.5)
    t = 0.3
    tau = np.concatenate((np.zeros(6), law.torque(t, q, v)))
    a = pin.aba(model, model.createData(), q, v, tau)
    rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
    alpha_d = 7.0 * pin.log3(rotation.T @ target) - 3.0 * v[3:6]
    assert not law.events
    assert np.allclose(a[3:6], alpha_d, rtol=0.0, atol=1e-9 * max(1.0, np.abs(alpha_d).max()))
    q_d, qdot_d, qddot_d = arm.trajectory(t)
    columns = wheels.arm_columns
    intended = (qddot_d + arm.kp * (q_d - arm.joints.get(q)) + arm.kd * (qdot_d - wheels.without_rates(v)[6:]))[columns]
    assert np.allclose(a[6:][columns], intended, rtol=0.0, atol=1e-9 * max(1.0, np.abs(intended).max()))


@pytest.mark.slow
def test_momentum_is_conserved_with_the_wheels_torqued(tmp_path):
    """The wheel torques are internal: over a run with the attitude held, the momentum about the
    origin drifts only by the integrator's error (it falls at least 8x when the step is halved:
    RKMK4's fourth order, no modelling leak), and the wheels' stored momentum is the rest of the
    robot's reaction to that same accuracy (``wheel_momentum_balance_max``, from Pinocchio's
    momentum of the robot with the wheels not spinning)."""
    drifts = []
    for period in (1e-3, 5e-4):
        outcome = simulate(short_scene(tmp_path / str(period), task={"duration": 0.3},
                                       simulation={"duration": 0.3, "control_period": period}))
        tel, summary = outcome.telemetry, outcome.summary
        assert outcome.status == "completed" and summary["wheel_momentum_max"]["wheel_z"] > 1e-3
        drift = np.abs(tel.momentum - tel.momentum[0]).max()
        scale = np.abs(outcome.extra_telemetry["wheels"].stored).max()
        assert summary["wheel_momentum_balance_max"] <= 2.0 * drift + 1e-13 * scale
        assert np.allclose(summary["wheel_stored_momentum_change"], -np.array(summary["arm_reaction_momentum"]),
                           rtol=0.0, atol=2.0 * drift + 1e-13 * scale)
        drifts.append(drift)
    assert drifts[1] < drifts[0] / 8.0


@pytest.mark.slow
def test_the_wheels_hold_the_attitude_that_free_wheels_let_drift(tmp_path):
    """On the same arm motion, the base turns under free wheels (``[attitude] kind = "none"``) by
    more than ten times what it turns with the attitude held; the arms track as well either way."""
    held = simulate(short_scene(tmp_path / "h", wheels=UNLIMITED)).summary
    free = simulate(short_scene(tmp_path / "f", wheels=UNLIMITED, attitude={"kind": "none"})).summary
    bound = 0.1 * free["base_rotation_max"]
    assert held["base_rotation_max"] < bound < free["base_rotation_max"]
    assert held["tracking_rms_overall"] < 2.0 * free["tracking_rms_overall"]


@pytest.mark.slow
def test_a_torque_limit_is_reported_and_kept(tmp_path):
    """Wheels whose torque limit is below what the law asks keep it, and the run says so: an
    event per wheel (its time and what was asked), periods counted, ``wheel_saturated``."""
    limit = 0.05
    outcome = simulate(short_scene(tmp_path, wheels={"max_torque": limit}))
    summary, rows = outcome.summary, outcome.extra_telemetry["wheels"]
    assert summary["wheel_saturated"] and summary["wheel_saturation_events"]
    assert np.abs(rows.torque[:-1]).max() <= limit * (1 + 1e-12)
    event = summary["wheel_saturation_events"][0]
    assert event["limit"] == "torque" and abs(event["asked"]) > limit
    assert sum(summary["wheel_saturated_periods"].values()) > 0


@pytest.mark.slow
def test_a_momentum_limit_stops_the_wheel_spinning_up(tmp_path):
    """A wheel at its stored-momentum limit gets no torque that would spin it faster: the event
    is reported and its momentum stays within one period's growth of the limit."""
    limit = 0.05
    outcome = simulate(short_scene(tmp_path, wheels={"max_momentum": limit, "max_torque": 1e3}))
    summary, rows = outcome.summary, outcome.extra_telemetry["wheels"]
    assert any(e["limit"] == "momentum" for e in summary["wheel_saturation_events"])
    growth = np.abs(np.diff(rows.momentum, axis=0)).max()
    assert np.abs(rows.momentum).max() <= limit + growth


@pytest.mark.slow
def test_detumbling_with_a_wheel_leaves_the_capture_in_the_wheel(tmp_path):
    """After the capture impulse, with the detumbling law solving the arm's GJM net of the wheel's
    momentum, the wheel holds the base yaw: the base turns less than with a free wheel, the
    detumbled rows stop, and the wheel's stored momentum balances the impulse against the arm's
    reaction (within the loop's impulse error, the same as the momentum balance's)."""
    held = simulate(short_scene(tmp_path / "h", "detumble_impulse_wheel", simulation={"duration": 0.5}))
    free = simulate(short_scene(tmp_path / "f", "detumble_impulse_wheel", simulation={"duration": 0.5},
                                attitude={"kind": "none"}))
    s = held.summary
    turned = rotation_angle(held.telemetry.base_quaternion, held.telemetry.base_quaternion[0])[-1]
    assert turned < rotation_angle(free.telemetry.base_quaternion, free.telemetry.base_quaternion[0])[-1]
    assert s["detumbled_rows_speed_final"] < 1e-6 * s["detumbled_rows_speed_max"]
    impulse = s["external_impulse"][5]
    assert s["wheel_momentum_balance_max"] <= 2.0 * s["momentum_balance_max"] + 1e-12 * impulse
    assert abs(s["wheel_stored_momentum_change"][2] + s["arm_reaction_momentum"][2] - impulse) \
        <= 2.0 * s["momentum_balance_max"] + 1e-12 * impulse


@pytest.mark.slow
def test_a_wheel_run_writes_its_telemetry_and_figure(tmp_path):
    """A wheel scene's run folder holds ``telemetry_wheels.npz`` (one row per sample) and the
    ``reaction_wheels`` figure, and its summary the wheels' keys."""
    scene = short_scene(tmp_path, output={"figures": True})
    run = simulate(scene, out=tmp_path / "run")
    folder = run.folder
    data = np.load(folder / "telemetry_wheels.npz")
    assert data["momentum"].shape == (len(np.load(folder / "telemetry.npz")["t"]), 3)
    assert (folder / "reaction_wheels.png").is_file()
    assert "wheel_saturated" in run.summary


@pytest.mark.slow
def test_free_wheels_get_no_torque(tmp_path):
    """``[attitude] kind = "none"``: the wheels are free (zero torque) while the arms move."""
    outcome = simulate(short_scene(tmp_path, attitude={"kind": "none"}))
    assert np.abs(outcome.extra_telemetry["wheels"].torque).max() == 0.0
    assert not outcome.summary["wheel_saturated"]


@pytest.mark.slow
@pytest.mark.parametrize("rpy", [[0.0, 0.0, 3.0]])
def test_the_attitude_goes_to_a_given_rpy(tmp_path, rpy):
    """``attitude.rpy`` is the base CoM frame's target: the base turns there (to 1 % of the turn)."""
    outcome = simulate(short_scene(tmp_path, wheels=UNLIMITED, attitude={"rpy": rpy, "kp": 25.0, "kd": 10.0},
                                   task={"displacement": {}}, simulation={"duration": 2.0}))
    target = pin.Quaternion(pin.rpy.rpyToMatrix(*np.radians(rpy))).coeffs()
    turned = rotation_angle(outcome.telemetry.base_quaternion[-1:], target)[0]
    assert turned < 0.01 * np.radians(np.linalg.norm(rpy))


def test_wheels_stop_a_tumble_with_the_arms_passive(tmp_path):
    """Without an arm controller the arm joints get no torque, and the wheels alone stop the
    base's tumble: its rate falls a hundredfold and the wheels take the momentum (their stored
    momentum balancing the rest of the robot's to the drift's level)."""
    scene = short_scene(tmp_path, wheels=UNLIMITED, controller={"kind": "none"},
                        task={"kind": "none", "displacement": {}}, initial={"base_angular_velocity": [1.0, -0.5, 2.0]},
                        attitude={"kp": 25.0, "kd": 10.0}, simulation={"duration": 1.5})
    outcome = simulate(scene)
    tel, summary, rows = outcome.telemetry, outcome.summary, outcome.extra_telemetry["wheels"]
    assert np.abs(tel.tau[:, prepare(scene).wheels.arm_columns]).max() == 0.0
    rate = np.linalg.norm(tel.base_twist[:, 3:], axis=1)
    assert rate[-1] < 0.01 * rate[0]
    drift = np.abs(tel.momentum - tel.momentum[0]).max()
    assert summary["wheel_momentum_balance_max"] <= 2.0 * drift + 1e-13 * np.abs(rows.stored).max()
    assert np.linalg.norm(rows.stored[-1]) > 0.5 * np.linalg.norm(tel.momentum[0, 3:])


def test_a_wheel_scene_simulates_the_exact_plant(tmp_path):
    """``simulation.model = "auto"`` picks the exact plant for a scene with wheels (the attitude
    law is built on it), and says why."""
    from freefloat.app.runner import resolved_setup

    setup = resolved_setup(short_scene(tmp_path, simulation={"model": "auto"}))
    assert setup.model.name == "exact"
    assert "reaction wheels" in setup.model_choice["reason"]


def test_tracking_error_counts_the_arm_joints_only(tmp_path):
    """A wheel has no position reference (its telemetry row holds its own angle, a period behind
    at the last sample): ``tracking_error_max`` is the arm joints' largest error, recomputed here
    from the telemetry, not a spinning wheel's last period."""
    scene = short_scene(tmp_path, wheels=UNLIMITED, initial={"base_angular_velocity": [1.0, -0.5, 2.0]})
    outcome = simulate(scene)
    tel = outcome.telemetry
    errors = np.abs(tel.joint_reference - tel.joint_positions)
    arm = prepare(scene).wheels.arm_columns
    assert outcome.summary["tracking_error_max"] == errors[:, arm].max() < errors.max()
