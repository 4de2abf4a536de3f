"""Robot scenes' shared preparation (freefloat.app.experiments.robot_run): the keys it refuses."""

from __future__ import annotations

import pytest

from freefloat import SceneError
from freefloat.app.experiments.robot_run import prepare_robot

from .conftest import quiet_scene


@pytest.mark.parametrize("builtin, sections, key", [
    ("four_arm_joint_space", {"controller": {"torque_limit": 1e-6}}, "controller.torque_limit"),
    ("capture_planar", {"controller": {"squeeze": 5.0}}, "controller.squeeze"),
    ("capture_planar", {"target": {"second_grasp": [0.1, 0.0, 0.0]}}, "target.second_grasp"),
])
def test_a_two_hand_key_in_another_scene_is_refused_naming_it(tmp_path, builtin, sections, key):
    """A torque limit in a joint-space scene, or a squeeze or second grasp on a one-hand capture,
    which the run would ignore, is refused naming the key and the file."""
    with pytest.raises(SceneError, match=rf"s.toml: '{key}' is read by two-hand captures only"):
        prepare_robot(quiet_scene(tmp_path, builtin, **sections))
