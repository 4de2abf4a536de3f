"""A robot scene's ``[sensors]`` section: its keys are the sensors' settings records, each bad key
is named, and the section survives the run folder's scene.toml."""

from __future__ import annotations

import tomllib

import pytest

from freefloat import SceneError
from freefloat.app.runner import prepare
from freefloat.app.scenes import builtin_scenes, parse_scene
from freefloat.app.scenes.as_run import scene_as_run
from freefloat.dynamics.sensors import Channel, MomentumKalman

SCENE = "detumble_impulse_arm1_joint4"


def sensed(sensors: dict, name: str = SCENE):
    """The built-in scene ``name`` with ``[sensors]`` = ``sensors``, parsed."""
    raw = tomllib.loads(builtin_scenes()[name].read_text())
    raw["sensors"] = sensors
    return parse_scene(raw, source=builtin_scenes()[name])


def test_keys_are_the_settings_records():
    """Each group's table becomes its Channel, ``momentum`` the MomentumKalman, groups not given stay ideal."""
    scene = sensed({"seed": 7, "joint_rate": {"noise": 0.01, "delay": 2, "every": 10},
                    "base_twist": {"noise": [1e-3, 2e-3, 3e-3], "bias": 0.5},
                    "momentum": {"restart": [0.015], "false_alarm": 1e-4}})
    s = scene.sensors
    assert s.seed == 7 and s.joint_rate == Channel(noise=0.01, delay=2, every=10)
    assert s.base_twist == Channel(noise=(1e-3, 2e-3, 3e-3), bias=0.5)
    assert s.base_pose.ideal and s.joint_position.ideal
    assert s.momentum == MomentumKalman(restart=(0.015,), false_alarm=1e-4)


@pytest.mark.parametrize("sensors, message", [
    ({"joint_rates": {"noise": 0.01}}, "joint_rates.*did you mean.*joint_rate"),
    ({"joint_rate": {"nois": 0.01}}, "nois.*did you mean.*noise"),
    ({"joint_rate": {"noise": -0.01}}, r"\[sensors.joint_rate\].*noise"),
    ({"joint_rate": {"every": 0}}, "'sensors.joint_rate.every' must be > 0"),
    ({"joint_rate": {"delay": 1.5}}, "'sensors.joint_rate.delay' must be an integer"),
    ({"seed": -1}, "'sensors.seed' must be >= 0"),
    ({"momentum": {"linear_process_noise": 0.0}}, "'sensors.momentum.linear_process_noise' must be > 0"),
    ({"momentum": {"false_alarm": 2.0}}, r"\[sensors.momentum\].*false_alarm"),
    ({"joint_rate": 0.01}, "'sensors.joint_rate' must be a dict"),
])
def test_bad_keys_are_named(sensors, message):
    """An unknown key (with the nearest), a bad value or type fails naming ``sensors.<key>``."""
    with pytest.raises(SceneError, match=message):
        sensed(sensors)


def test_a_noise_per_component_must_match_the_robot():
    """A per-component noise of the wrong count fails when the scene is prepared, naming [sensors] and the group."""
    scene = sensed({"joint_rate": {"noise": [0.01, 0.01]}})
    with pytest.raises(SceneError, match=r"\[sensors\].*joint_rate"):
        prepare(scene)


@pytest.mark.parametrize("name, what", [("tumbling", "has no controller"), ("capture_planar", "is a capture")])
def test_sensors_without_a_law_that_reads_them_are_refused(name, what):
    """A scene whose controller would not read [sensors] (none, or a capture's laws) refuses the section."""
    with pytest.raises(SceneError, match=f"{what}: remove"):
        sensed({"seed": 1}, name)


def test_the_run_folder_scene_keeps_the_sensors_and_seed():
    """The scene as run (a run folder's scene.toml) parses back to the same sensors, seed included."""
    scene = parse_scene(tomllib.loads(builtin_scenes()["detumble_sensed"].read_text()),
                        source=builtin_scenes()["detumble_sensed"])
    again = parse_scene(tomllib.loads(scene_as_run(scene)), source=scene.source)
    assert again.sensors == scene.sensors and again.sensors.seed == 1 and again.sensors.momentum is not None
