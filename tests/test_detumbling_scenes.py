"""The detumbling and capture scenes end to end through ``freefloat simulate``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from freefloat import SceneError
from freefloat.app.cli import main
from freefloat.app.runner import prepare
from freefloat.app.scenes import builtin_scenes, parse_scene
from freefloat.dynamics.telemetry import Telemetry

from .pages import animation as _animation
from .pages import packets as _packets


def run_scene(name, tmp_path):
    out = tmp_path / name
    assert main(["simulate", name, "--out", str(out), "--quiet"]) == 0
    return out, json.loads((out / "summary.json").read_text())


@pytest.mark.slow
def test_capture_scene_grasps_and_stops_the_target(tmp_path):
    """capture_planar: exact momentum balance at the grasp, target rotation below 1e-6 rad/s, target in the HTML."""
    out, s = run_scene("capture_planar", tmp_path)
    assert s["momentum_balance_error"] < 1e-10 and s["target_angular_velocity_final"] < 1e-6
    assert s["settling_time"] < 1.0 and s["peak_joint_torque"] > 0 and "base_angular_velocity_final" in s
    held = s["end_effector_angular_velocity_final"]["arm1_ee"]  # the end-effector holding the target
    assert held == pytest.approx(s["target_angular_velocity_final"], abs=1e-12) and (out / "angular_rates.png").exists()
    assert s["figures_not_drawn"] == {"joint_errors": "the run has no joint reference"}
    assert (out / "telemetry_pre_capture.npz").exists()
    assert Telemetry.load(out / "telemetry_pre_capture.npz").t[-1] == pytest.approx(s["impact_time"])
    tracks = [tracks for path, tracks in _animation(_packets(out / "trajectory.html")).items() if path.endswith("extra/target")]
    assert len(tracks) == 1
    first, last = np.array(tracks[0][".position"][0][1]), np.array(tracks[0][".position"][-1][1])
    np.testing.assert_allclose(first, [7.75 + 0.25 + 0.4 * 0.5, 0.0, 0.0], atol=1e-6)  # back-propagated start
    tel = Telemetry.load(out / "telemetry.npz")
    assert abs(np.linalg.norm(last - tel.ee_position[-1, 0]) - 0.25) <= 1e-3  # grasp offset, within the contact tolerance


@pytest.mark.slow
def test_impulse_scene_stops_the_chosen_end_effector(tmp_path):
    """Sec 5.3 scenario 1: after the 500 N m impulse, arm 1's rotation stops with joint 4 alone."""
    out, s = run_scene("detumble_impulse_arm1_joint4", tmp_path)
    tel = Telemetry.load(out / "telemetry.npz")
    assert s["detumbled_rows_speed_final"] < 1e-6 and s["settling_time"] < 1.0
    rates = np.abs(tel.v[-1, 3:])  # planar base: 3 base coordinates
    assert rates[3] > 1e-3 and np.delete(rates, 3).max() < 1e-6  # only the mission joint keeps turning
    assert s["external_impulse"][5] == pytest.approx(500.0 * 0.007, rel=1e-12)  # the sampled impulse
    assert s["momentum_balance_relative"] < 1e-7 and "momentum_drift_max" not in s  # a balance, not a drift


@pytest.mark.slow
def test_impulse_scene_draws_spin_decay_and_balance_not_drift(tmp_path):
    """A detumbling run with a wrench draws its angular rates and its conservation balance, no
    CoM and momentum drift; the base spin settles (2 % band) well before the run ends."""
    out, s = run_scene("detumble_impulse_arm2_joint4", tmp_path)
    names = {p.name for p in out.iterdir()}
    assert {"angular_rates.png", "conservation_balance.png", "torques.png"} <= names and "com_drift.png" not in names
    assert 0.0 < s["base_angular_velocity_settling_time"] < 0.5
    assert s["base_angular_velocity_max"] > s["base_angular_velocity_final"]
    assert s["end_effector_angular_velocity_final"]["arm2_ee"] < 1e-6


def scene_raw(name):
    import tomllib

    raw = tomllib.loads(builtin_scenes()[name].read_text())
    return raw


@pytest.mark.parametrize(("edit", "message"), [
    (lambda r: r["task"].pop("rows"), "needs 'task.rows'"),
    (lambda r: r["task"].update(rows=["arm1_ee"]), "'task.rows' item 'arm1_ee' must be 'end_effector:component'"),
    (lambda r: r["task"].update(rows=["arm7_ee:wz"]), "no end-effector 'arm7_ee'"),
    (lambda r: r["task"].update(mission_joints=["arm1_joint7"]), "no joint 'arm1_joint7'"),
    (lambda r: r["task"].update(method="magic"), "'task.method' is 'magic'"),
])
def test_bad_detumble_tasks_are_named(edit, message):
    """A detumble task with missing or wrong rows, joints or method fails naming the key."""
    raw = scene_raw("detumble_impulse_arm1_joint4")
    edit(raw)
    with pytest.raises(SceneError, match=message):
        prepare(parse_scene(raw, source=builtin_scenes()["detumble_impulse_arm1_joint4"]))


def test_capture_with_an_unknown_end_effector_is_named(tmp_path):
    """A target aimed at an end-effector that does not exist fails naming target.end_effector."""
    from freefloat.app.runner import simulate

    raw = scene_raw("capture_planar")
    raw["target"]["end_effector"] = "arm5_ee"
    with pytest.raises(SceneError, match="target.end_effector 'arm5_ee'"):
        simulate(parse_scene(raw, source=builtin_scenes()["capture_planar"]))
