"""Controller kinds by name: the built-ins' plants and tasks, and the detumbling kind beside its
old spelling."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from freefloat.app.controllers import CONTROLLERS, serving
from freefloat.app.experiments import experiment_for
from freefloat.app.scenes import builtin_scenes, parse_scene
from freefloat.errors import SceneError
from freefloat.space.control.detumbling_control import DetumblingController


def test_the_builtin_kinds_serve_their_plants():
    """Robot scenes may name none, computed_torque and detumbling; mechanism scenes computed_torque
    (its platform variant, with its own settings) and sliding_mode."""
    robot, mechanism = serving("robot"), serving("mechanism")
    assert {"none", "computed_torque", "detumbling"} <= set(robot) and "sliding_mode" not in robot
    assert {"computed_torque", "sliding_mode"} <= set(mechanism) and "none" not in mechanism
    assert robot["computed_torque"] is CONTROLLERS["computed_torque"]
    assert mechanism["computed_torque"].settings is not robot["computed_torque"].settings


def scene_with(name: str, **controller):
    """Built-in scene ``name`` with its [controller] keys changed."""
    path = builtin_scenes()[name]
    raw = tomllib.loads(path.read_text())
    raw["controller"].update(controller)
    return parse_scene(raw, path)


def test_detumbling_is_the_old_computed_torque_spelling_on_a_detumble_task():
    """kind = "detumbling" and kind = "computed_torque" on a detumble task build the same
    detumbling law: the same torques after the start."""
    old, new = (experiment_for(s).prepare(s) for s in (scene_with("detumble_impulse_baseline"),
                                                       scene_with("detumble_impulse_baseline", kind="detumbling")))
    assert isinstance(old.controller, DetumblingController) and isinstance(new.controller, DetumblingController)
    t = old.scene.task.start + 0.01
    np.testing.assert_array_equal(old.controller.torque(t, old.q0, old.v0), new.controller.torque(t, new.q0, new.v0))


def test_a_controller_refuses_a_task_it_does_not_serve():
    """The detumbling kind on a joint-quintic scene is refused, naming the task it needs."""
    scene = scene_with("four_arm_joint_space", kind="detumbling")
    with pytest.raises(SceneError, match="controller 'detumbling' needs task.kind 'detumble'"):
        experiment_for(scene).prepare(scene)


def test_an_entry_without_settings_of_its_keys_is_refused_by_name():
    """A controller whose settings are not a dataclass, or have a 'kind' field, or serve an
    unknown plant, is refused when it is declared, naming it."""
    from dataclasses import dataclass

    from freefloat.app.controllers import ControllerSpec, JointGains
    from freefloat.errors import InvalidArgument

    @dataclass(frozen=True)
    class WithKind:
        kind: str = "x"

    with pytest.raises(InvalidArgument, match="controller 'pid': settings must be a dataclass"):
        ControllerSpec("pid", "", dict, lambda context, settings: None)
    with pytest.raises(InvalidArgument, match="controller 'pid': settings WithKind has a field 'kind'"):
        ControllerSpec("pid", "", WithKind, lambda context, settings: None)
    with pytest.raises(InvalidArgument, match="plants must be among"):
        ControllerSpec("pid", "", JointGains, lambda context, settings: None, plants=("satellite",))
