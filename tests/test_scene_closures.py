"""A robot scene's [[closures]] (freefloat.app.experiments.scene_closures): assembled, run, refused."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.app import runner
from freefloat.app.scenes import load_scene
from freefloat.dynamics.closures import kinematics, stacked
from freefloat.errors import SceneError

from .conftest import quiet_scene, scene_variant, toml_text

JOINED = "satellite_hands_joined"


def joined(tmp_path, **sections):
    return quiet_scene(tmp_path, JOINED, **sections)


def test_the_loop_is_assembled_and_its_velocity_projected(tmp_path):
    """From the zero posture the hands are brought together (residual under 1e-10) and the initial
    velocity keeps the loop closed (J v0 = 0), the base's tumble kept in it."""
    setup = runner.prepare(joined(tmp_path))
    model, data = setup.robot.model, setup.robot.model.createData()
    kinematics(model, data, setup.q0, setup.v0)
    e, J, _ = stacked(list(setup.model.closures), model, data, drift=False)
    assert np.abs(e).max() <= 1e-10 and np.abs(J @ setup.v0).max() <= 1e-12
    assert np.abs(setup.v0[3:6]).max() > 0.01


def test_a_torque_free_closed_chain_keeps_momentum_and_energy(tmp_path):
    """0.2 s of the tumbling closed chain: momentum and energy drift under 1e-10, the loop open by
    under 1e-10 m."""
    done = runner.simulate(joined(tmp_path, simulation={"duration": 0.2}))
    summary = done.summary
    assert summary["momentum_drift_max"] < 1e-10 and summary["energy_drift_max"] < 1e-10
    assert summary["closure_drift_max"] < 1e-10


@pytest.mark.parametrize("closure, message", [
    ({"frames": ["left_tool0", "no_such_frame"]}, r"'closures\[0\]\.frames' names 'no_such_frame', which is no frame"),
    ({"frames": ["left_tool0", "left_tool0"]}, r"'closures\[0\]\.frames' must name two different frames"),
    ({"frames": ["left_tool0"]}, r"'closures\[0\]\.frames' must name two different frames"),
    ({"frames": ["left_tool0", "right_tool0"], "kind": "hinge"}, r"'closures\.kind' is 'hinge'; valid: point, revolute"),
    ({"frames": ["left_tool0", "right_tool0"], "stiffness": 3.0}, r"stiffness"),
])
def test_bad_closures_are_refused_naming_the_file_and_the_closure(tmp_path, closure, message):
    """A frame the robot lacks, a frame joined to itself, one frame, an unknown kind or key: a
    SceneError naming the scene file and the closure."""
    import tomllib

    path = scene_variant(tmp_path / "s.toml", JOINED)
    raw = tomllib.loads(path.read_text())
    raw["closures"] = [closure]
    path.write_text(toml_text(raw))
    with pytest.raises(SceneError, match=message) as error:
        runner.prepare(load_scene(path))
    assert str(path) in str(error.value)


@pytest.mark.slow
def test_a_loop_that_cannot_close_is_refused(tmp_path):
    """A weld between the base and a tool 0.6 m away with the arm's joints locked out of reach:
    the error names the closure, its frames and the residual."""
    import tomllib

    path = scene_variant(tmp_path / "s.toml", JOINED)
    raw = tomllib.loads(path.read_text())
    raw["closures"] = [{"frames": ["left_tool0", "right_tool0"], "kind": "weld"},
                       {"frames": ["left_base_link", "left_tool0"], "kind": "point"}]
    path.write_text(toml_text(raw))
    with pytest.raises(SceneError, match=r"'closures\[\d\]' \(.* - .*\) cannot be assembled from \[initial\]: residual"):
        runner.prepare(load_scene(path))


def test_closures_with_a_controller_are_refused(tmp_path):
    """The robot controllers do not know the loop: a scene with [[closures]] and a controller is
    refused naming 'controller.kind'."""
    scene = joined(tmp_path, controller={"kind": "computed_torque"}, task={"kind": "joint_quintic"})
    with pytest.raises(SceneError, match=r"\[\[closures\]\] run torque-free \('controller.kind"):
        runner.prepare(scene)
