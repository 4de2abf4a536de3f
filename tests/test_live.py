"""The live viewer of ``freefloat simulate --view``: a meshcat server showing the run as it is
computed, then replaying it."""

from __future__ import annotations

import warnings

import pytest

from freefloat import load_robot
from freefloat.app.cli import main
from freefloat.app.viz.live import LiveView
from freefloat.dynamics.telemetry import Telemetry
from freefloat.paths import URDF_DIR

from .conftest import scene_variant


@pytest.fixture(scope="module")
def live():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(URDF_DIR / "two_arm_planar.urdf")
    view = LiveView(robot)
    yield view, robot
    view.close()


def chunk(robot, q):
    tel = Telemetry.allocate(1, robot.model.nq, robot.model.nv, robot.n_joints, len(robot.end_effectors))
    tel.q[:] = q
    return tel


def test_the_server_holds_the_robot_and_follows_each_chunk(live):
    """Every visual geometry is on the server, and showing another configuration changes the
    scene it serves (showing the same one again does not)."""
    view, robot = live
    before = view.viewer.static_html()
    assert before.count("data:application/octet-binary;base64") >= robot.visual_model.ngeoms
    q = robot.neutral()
    q[6] = 0.7
    view.show(chunk(robot, q))
    moved = view.viewer.static_html()
    view.show(chunk(robot, q))
    assert moved != before and view.viewer.static_html() == moved


def test_simulate_view_runs_live_then_replays(tmp_path, monkeypatch, capsys):
    """--view shows a joint-space run live, replays it, closes the server and exits 0; the viewer's
    address is printed once (meshcat printed it too, and the replay a third time)."""
    import webbrowser

    opened = []
    monkeypatch.setattr(webbrowser, "open", lambda url: opened.append(url) or True)
    scene = scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.05},
                          output={"figures": False, "html": False})
    assert main(["simulate", str(scene), "--view", "--quiet", "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert opened and opened[0].startswith("http://127.0.0.1:") and "replaying the run in the live viewer" in out
    assert out.count("http://") == 1 and f"live viewer: {opened[0]}" in out
