"""The runner: one life cycle for every experiment kind, from scene to written folder."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from freefloat import FreefloatError
from freefloat.app import runner
from freefloat.app.scenes import load_scene
from freefloat.dynamics.simulation import run
from freefloat.dynamics.telemetry import Telemetry

from .conftest import scene_variant


def test_run_scene_writes_exactly_what_the_bare_loop_computes(tmp_path):
    """The pipeline adds nothing to the numbers: its telemetry equals dynamics.simulation.run on
    the prepared setup, bit for bit."""
    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.05},
                                     output={"figures": False, "html": False}))
    done = runner.run_scene(scene, tmp_path / "out")
    setup = runner.prepare(scene)
    bare = run(setup.robot, setup.q0, setup.v0, 0.05, scene.simulation.control_period, setup.integrator,
               setup.model, setup.controller)
    written = Telemetry.load(tmp_path / "out" / "telemetry.npz")
    for name in ("t", "q", "v", "tau", "momentum", "energy"):
        assert np.array_equal(getattr(written, name), getattr(bare.telemetry, name)), name
    assert done.outcome.status == json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "completed"


def test_an_unwritable_folder_is_refused_before_the_run(tmp_path):
    """An output folder under a file fails at once, naming the folder, with nothing simulated."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space"))
    started = time.perf_counter()
    with pytest.raises(FreefloatError, match="output folder .*file/out.* cannot be written"):
        runner.run_scene(scene, blocker / "out")
    assert time.perf_counter() - started < 5.0


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_keep_what_was_computed(tmp_path, signum):
    """A run stopped by SIGTERM or SIGHUP exits 1 and writes its samples, as Ctrl-C does."""
    scene = scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 500.0},
                          output={"figures": False, "html": False})
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "freefloat", "simulate", str(scene), "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, "COLUMNS": "80"})
    deadline = time.monotonic() + 60
    while "step" not in proc.stderr.readline():  # the progress bar (text mode reads up to each \r)
        assert time.monotonic() < deadline and proc.poll() is None, "the run never started"
    time.sleep(0.5)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=60)
    summary = json.loads((out / "summary.json").read_text())
    assert proc.returncode == 1 and summary["status"] == "interrupted", err
    assert 1 < len(Telemetry.load(out / "telemetry.npz").t) < 500_001
