"""Tests of freefloat.app.view and ``freefloat view``: a saved run's page, reopened or rebuilt."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from freefloat.app.cli import main
from freefloat.app.runner import simulate
from freefloat.app.scenes import find_scene
from freefloat.app.view import run_page
from freefloat.dynamics.telemetry import Telemetry
from freefloat.errors import FreefloatError

from .pages import animation, packets


def _run(folder, html: bool):
    """The default scene for 0.1 s (no figures), with or without its page."""
    scene = find_scene("four_arm_joint_space")
    scene = dataclasses.replace(scene, simulation=dataclasses.replace(scene.simulation, duration=0.1),
                                output=dataclasses.replace(scene.output, figures=False, html=html))
    simulate(scene, out=folder)
    return folder


def test_missing_page_is_rebuilt_from_the_telemetry(tmp_path):
    """A robot run written without its page gets one whose base follows the recorded q."""
    folder = _run(tmp_path / "run", html=False)
    assert not (folder / "trajectory.html").exists()
    page = run_page(folder, fps=100.0)
    telemetry = Telemetry.load(folder / "telemetry.npz")
    base = next(tracks for path, tracks in animation(packets(page)).items() if path.endswith("/base"))
    np.testing.assert_allclose(base[".position"][-1][1][:2], telemetry.q[-1, :2], atol=1e-12)


def test_existing_page_is_returned_as_is(tmp_path):
    """A run that has its page is not rewritten."""
    folder = _run(tmp_path / "run", html=True)
    before = (folder / "trajectory.html").stat().st_mtime_ns
    assert run_page(folder) == folder / "trajectory.html"
    assert (folder / "trajectory.html").stat().st_mtime_ns == before


def test_a_folder_without_a_run_is_named(tmp_path):
    """A folder with no run in it is refused, named."""
    with pytest.raises(FreefloatError, match=f"'{tmp_path}' is not a run folder"):
        run_page(tmp_path)


def test_a_capture_run_without_page_is_not_rebuilt(tmp_path):
    """A run whose summary is a capture's (the target is not in the telemetry) asks for a rerun
    with its page: the scene's key from Python, the option on the command line."""
    from freefloat.errors import command_line

    folder = _run(tmp_path / "run", html=False)
    summary = json.loads((folder / "summary.json").read_text())
    (folder / "summary.json").write_text(json.dumps(dict(summary, impact_time=0.5)))
    with pytest.raises(FreefloatError, match=r"again with \[output\] html = true"):
        run_page(folder)
    with pytest.raises(FreefloatError, match="without --no-html"), command_line():
        run_page(folder)


def test_view_command_prints_the_page(tmp_path, capsys):
    """``freefloat view RUN_DIR --no-browser`` prints the page's path and exits 0."""
    folder = _run(tmp_path / "run", html=False)
    assert main(["view", str(folder), "--no-browser"]) == 0
    assert capsys.readouterr().out.strip() == str(folder / "trajectory.html")


def test_simulate_view_opens_the_written_page(tmp_path, monkeypatch):
    """``freefloat simulate --view`` on a run the live viewer does not show (a mechanism) opens
    the run's page, by its file URI, once it is written (robot runs: tests/test_live.py)."""
    import webbrowser

    opened = []
    monkeypatch.setattr(webbrowser, "open", opened.append)
    scene = tmp_path / "short.toml"
    scene.write_text((find_scene("five_bar_computed_torque").source.read_text())
                     .replace("duration = 0.5", "duration = 0.002").replace("reaching_phase = 0.2", "reaching_phase = 0.0"))
    assert main(["simulate", str(scene), "--out", str(tmp_path / "run"), "--quiet", "--no-figures", "--view"]) == 0
    assert opened == [(tmp_path / "run" / "trajectory.html").resolve().as_uri()]
