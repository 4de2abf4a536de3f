"""The experiment registry: every scene kind has one experiment, chosen by the scene."""

from __future__ import annotations

import dataclasses

import pytest

from freefloat import SceneError
from freefloat.app.experiments import EXPERIMENTS, experiment_for
from freefloat.app.scenes import builtin_scenes, load_scene


@pytest.mark.parametrize("name", sorted(builtin_scenes()))
def test_every_builtin_scene_has_its_experiment(name):
    """Each built-in scene's kind picks the experiment registered for that kind."""
    scene = load_scene(builtin_scenes()[name])
    assert experiment_for(scene).kind == scene.kind


def test_scene_kinds_follow_the_scene(tmp_path):
    """A [target] makes a capture, a detumble task a detumbling, a [mechanism] a mechanism run."""
    scenes = {name: load_scene(path) for name, path in builtin_scenes().items()}
    assert scenes["capture_planar"].kind == "capture"
    assert scenes["detumble_impulse_arm1_joint4"].kind == "detumbling"
    assert scenes["four_arm_joint_space"].kind == "joint_space"
    assert scenes["five_bar_sliding_mode"].kind == "mechanism"
    assert set(EXPERIMENTS) == {s.kind for s in scenes.values()}


def test_an_unknown_kind_is_named_with_the_known_ones():
    """A scene of a kind no experiment runs is refused, naming the kind and the valid ones."""

    @dataclasses.dataclass
    class Odd:
        name: str = "odd"
        kind: str = "orbit_transfer"

    with pytest.raises(SceneError, match="kind 'orbit_transfer'.*joint_space"):
        experiment_for(Odd())
