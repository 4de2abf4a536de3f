"""Reaction wheels combined with a capture, a loop closure and locked joints
(freefloat.app.experiments.wheel_run): the wheels' momentum balance stays at the integrator's error
through each run (across the grasp's impulse, with the loop's constraint forces), the total angular
momentum about the origin is conserved against Pinocchio's centroidal momentum, idle wheels of no
inertia leave a capture as it is without wheels, and the law reads the closed loop."""

from __future__ import annotations

import dataclasses
import tomllib

import numpy as np
import pinocchio as pin
import pytest

from freefloat.app.runner import prepare, simulate
from freefloat.app.scenes import builtin_scenes, load_scene
from freefloat.dynamics.closures import ClosedModel
from freefloat.robot.wheels import Wheels
from freefloat.space.capture import TargetBody
from freefloat.space.control.wheel_attitude import WheelAttitudeControl

from .conftest import random_state, toml_text

#: The capture with wheels shortened: contact at 0.3 s, 0.3 s of detumbling.
SHORT_CAPTURE = {"target": {"contact_time": 0.3}, "simulation": {"duration": 0.3}}


def variant(tmp_path, builtin: str, wheels_from: str | None = None, wheels: dict | None = None,
            drop: tuple[str, ...] = (), **sections: dict):
    """A built-in scene without figures or page, with the given keys of each section replaced,
    the ``[[wheels]]`` and ``[attitude]`` of ``wheels_from`` added, the keys ``wheels`` set in every
    ``[[wheels]]`` table and the top-level tables ``drop`` removed (written in ``tmp_path``)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    raw = tomllib.loads(builtin_scenes()[builtin].read_text())
    if wheels_from is not None:
        other = tomllib.loads(builtin_scenes()[wheels_from].read_text())
        raw["wheels"], raw["attitude"] = other["wheels"], other["attitude"]
    for section, values in {**sections, "output": {"figures": False, "html": False}}.items():
        raw.setdefault(section, {}).update(values)
    for table in raw.get("wheels", []):
        table.update(wheels or {})
    for key in drop:
        raw.pop(key)
    path = tmp_path / "s.toml"
    path.write_text(toml_text(raw))
    return load_scene(path)


def angular_momentum(model: pin.Model, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angular momentum about the inertial origin (3,) from Pinocchio's centroidal momentum:
    ``L_G + c x P``."""
    data = model.createData()
    h = pin.computeCentroidalMomentum(model, data, q, v)
    return h.angular + np.cross(data.com[0], h.linear)


def drift_and_scale(balance: np.ndarray, stored: np.ndarray) -> tuple[float, float]:
    """The wheels' largest balance (N m s) and the scale of their stored momentum (N m s)."""
    return float(np.linalg.norm(balance, axis=1).max()), float(np.abs(stored).max())


@pytest.mark.slow
def test_a_capture_with_wheels_keeps_the_balance_across_the_grasp(tmp_path):
    """Through the approach, the grasp's impulse and the detumbling, the wheels' stored momentum
    plus the rest of robot and target is the start value to the integrator's error: the balance is
    no more than the total momentum's drift (Pinocchio's centroidal momentum of the robot and the
    free target, then of the merged robot), which the grasp itself does not move (round-off); the
    wheels' saturations after the grasp are told on the scene's clock."""
    scene = variant(tmp_path, "capture_wheels", **SHORT_CAPTURE)
    setup = prepare(scene)
    outcome = simulate(scene)
    assert outcome.status == "completed"
    rows, pre, post = outcome.extra_telemetry["wheels"], outcome.extra_telemetry["pre_capture"], outcome.telemetry
    assert len(rows.t) == len(pre.t) + len(post.t) and rows.t[len(pre.t)] == rows.t[len(pre.t) - 1]
    body = TargetBody(setup.target)
    flying = body.momentum(*body.initial_state())[3:]
    merged = outcome.figures.robot.model
    total = np.array([angular_momentum(setup.robot.model, q, v) + flying for q, v in zip(pre.q, pre.v)]
                     + [angular_momentum(merged, q, v) for q, v in zip(post.q, post.v)])
    drift = np.linalg.norm(total - total[0], axis=1)
    balance, scale = drift_and_scale(rows.balance, rows.stored)
    grasp = len(pre.t)
    assert abs(drift[grasp] - drift[grasp - 1]) < 1e-13 * np.abs(total).max()  # the impulse is internal
    assert scale > 1.0 and outcome.summary["wheel_momentum_balance_max"] == balance
    assert balance <= 2.0 * drift.max() + 1e-13 * scale
    events = outcome.summary["wheel_saturation_events"]  # on the scene's clock: the grasp's torque peak
    assert events and min(e["t"] for e in events) >= outcome.summary["impact_time"] > 0.2
    assert np.allclose(rows.stored + rows.rest, total, rtol=0.0, atol=2.0 * drift.max() + 1e-13 * np.abs(total).max())


@pytest.mark.slow
def test_idle_wheels_of_no_inertia_leave_a_capture_as_it_is_without_wheels(tmp_path):
    """Wheels under no law (``[attitude] kind = "none"``) whose rotors weigh 1e-9 kg give the
    robot the states of the same capture without wheels to 1e-12 (round-off: the rotors' share of
    the robot's mass is 1e-11); rotors of 2 kg change them by more than 1e-5, so the comparison can
    fail."""
    def states(scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        outcome = simulate(scene)
        assert outcome.status == "completed"
        pre, post = outcome.extra_telemetry["pre_capture"], outcome.telemetry
        return np.concatenate((pre.q, post.q)), np.concatenate((pre.v, post.v)), post.t

    bare = states(variant(tmp_path / "bare", "capture_wheels", drop=("wheels", "attitude"), **SHORT_CAPTURE))
    nv_arm = bare[1].shape[1]
    differences = []
    for mass in (1e-9, 2.0):
        q, v, t = states(variant(tmp_path / str(mass), "capture_wheels", attitude={"kind": "none"},
                                 wheels={"mass": mass, "inertia": 0.025 * mass}, **SHORT_CAPTURE))
        assert len(t) == len(bare[2])  # the same grasp period
        differences.append(max(np.abs(q[:, :bare[0].shape[1]] - bare[0]).max(), np.abs(v[:, :nv_arm] - bare[1]).max()))
    assert differences[0] < 1e-12 < 1e-5 < differences[1]


def test_the_law_gives_the_attitude_acceleration_on_a_closed_loop(tmp_path):
    """On the satellite with its hands joined, at a random velocity the loop allows, the closed
    dynamics under the law's wheel torques turn the base with the attitude law's acceleration
    ``Kp log(R^T R_d) - Kd omega`` (base frame); the tree's law, blind to the loop, misses it."""
    setup = prepare(variant(tmp_path, "satellite_hands_joined", "capture_wheels"))
    closed = setup.model
    wheels = Wheels(setup.wheels.robot, tuple(dataclasses.replace(w, max_torque=1e9, max_momentum=1e9)
                                              for w in setup.wheels.wheels))
    model, q = wheels.robot.model, setup.q0
    _, v = random_state(wheels.robot, np.random.default_rng(4), speed=0.5)
    data = model.createData()
    from freefloat.dynamics.closures import kinematics, stacked

    kinematics(model, data, q, v)
    J = stacked(list(closed.closures), model, data, drift=False)[1]
    v = v - np.linalg.pinv(J) @ (J @ v)
    target = pin.rpy.rpyToMatrix(0.1, -0.2, 0.3)
    alpha_d = 7.0 * pin.log3(pin.Quaternion(q[3:7]).toRotationMatrix().T @ target) - 3.0 * v[3:6]
    misses = []
    for law in (WheelAttitudeControl(wheels, None, target, 7.0, 3.0, ClosedModel(wheels.robot, closed.closures)),
                WheelAttitudeControl(wheels, None, target, 7.0, 3.0)):
        tau = np.concatenate((np.zeros(6), law.torque(0.0, q, v)))
        a = ClosedModel(wheels.robot, closed.closures).acceleration(q, v, tau)
        misses.append(np.abs(a[3:6] - alpha_d).max())
    assert misses[0] < 1e-9 * max(1.0, np.abs(alpha_d).max()) < 1e-3 < misses[1]


@pytest.mark.slow
def test_wheels_on_a_closed_loop_keep_the_balance(tmp_path):
    """The satellite with its hands joined, tumbling, its wheels holding the base: the loop's
    constraint forces are internal, so the wheels' balance and the total angular momentum's drift
    (Pinocchio's centroidal momentum) stay at the integrator's error, the loop stays closed and the
    base's rate falls."""
    outcome = simulate(variant(tmp_path, "satellite_hands_joined", "capture_wheels", simulation={"duration": 0.3}))
    tel, rows = outcome.telemetry, outcome.extra_telemetry["wheels"]
    total = np.array([angular_momentum(outcome.figures.robot.model, q, v) for q, v in zip(tel.q, tel.v)])
    drift = np.linalg.norm(total - total[0], axis=1).max()
    balance, scale = drift_and_scale(rows.balance, rows.stored)
    assert outcome.status == "completed" and scale > 1.0
    assert drift < 1e-12 * np.abs(total).max() and balance <= 2.0 * drift + 1e-13 * scale
    assert outcome.summary["closure_drift_max"] < 1e-10
    rate = np.linalg.norm(tel.base_twist[:, 3:], axis=1)
    assert rate[-1] < 0.5 * rate[0]


@pytest.mark.slow
def test_wheels_with_locked_joints_run_on_the_reduced_robot(tmp_path):
    """``simulation.lock = "auto"`` on the satellite whose right arm stays still locks that arm, never
    a wheel; the wheels are mounted on the reduced robot, and the full robot's telemetry keeps the
    wheels' balance and the total angular momentum (Pinocchio, full model) at the integrator's
    error (the unlocked run's drift); the wheels store what they store unlocked, to the held
    arm's motion within a period."""
    sections = {"task": {"displacement": {"left_tool0": 20.0}, "duration": 0.3}, "simulation": {"duration": 0.3}}
    locked = variant(tmp_path / "l", "satellite_wheels", **{**sections, "simulation": {"duration": 0.3, "lock": "auto"}})
    setup = prepare(locked)
    assert setup.lock is not None and set(setup.lock.names) == {n for n in setup.robot.joint_names
                                                                if n.startswith("right_")}
    moved = setup.plant_wheels
    assert [w.name for w in moved.wheels] == [w.name for w in setup.wheels.wheels]
    assert np.array_equal(moved.robot.model.names[moved.wheels[0].joint_id], "wheel_x")
    assert (moved.columns < setup.wheels.columns).all()
    outcome = simulate(locked)
    tel, rows = outcome.telemetry, outcome.extra_telemetry["wheels"]
    free = simulate(variant(tmp_path / "f", "satellite_wheels", **sections))
    model = setup.robot.model
    assert tel.q.shape[1] == model.nq
    drifts = []
    for run in (outcome, free):
        total = np.array([angular_momentum(model, q, v) for q, v in zip(run.telemetry.q, run.telemetry.v)])
        drifts.append(np.linalg.norm(total - total[0], axis=1).max())
    balance, scale = drift_and_scale(rows.balance, rows.stored)
    assert scale > 0.1 and drifts[0] < 2.0 * drifts[1] + 1e-13 * scale < 1e-8 * scale
    assert balance <= 2.0 * drifts[0] + 1e-13 * scale
    assert np.allclose(rows.stored, free.extra_telemetry["wheels"].stored, rtol=0.0, atol=1e-3 * scale)
