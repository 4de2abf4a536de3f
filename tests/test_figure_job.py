"""Tests of freefloat.app.viz.figure_job: a run's figures as one job for the figure helper."""

from __future__ import annotations

import pickle
import subprocess
import sys

import pytest

import freefloat
from freefloat.app.outputs import JOB_BYTES
from freefloat.app.viz.plotting import choose

from .conftest import scene_variant


def test_a_figure_job_pickles_without_its_robots_visual_geometry(tmp_path):
    """The job sent to the helper leaves out the robot's visual geometry (the UR5 meshes' collision
    structures pickled to 353 MB, past the job's size limit :data:`JOB_BYTES`, so a mesh robot's
    figures were drawn in the run's own process); unpickled, it draws the same figures."""
    scene = scene_variant(tmp_path / "s.toml", "satellite_dual_arm", simulation={"duration": 0.02})
    job = freefloat.simulate(scene).figures
    assert job.robot.visual_model is not None
    data = pickle.dumps(job, protocol=pickle.HIGHEST_PROTOCOL)
    assert len(data) < JOB_BYTES / 4
    sent = pickle.loads(data)
    assert sent.robot.visual_model is None and sent.robot.model.nv == job.robot.model.nv
    with choose(frozenset({"torques", "angular_momentum"}), ("png",)):
        drawn = [p.name for p in sent(tmp_path / "sent")]
        assert drawn == [p.name for p in job(tmp_path / "here")] and drawn


@pytest.mark.slow
def test_a_mechanism_run_s_figures_are_drawn_by_the_helper_not_in_its_process(tmp_path):
    """A mechanism run sends its figures to the helper as one job (Pinocchio's constraint models,
    which do not pickle, left out) and never imports matplotlib itself; the job, unpickled, draws
    what it draws in place."""
    scene = scene_variant(tmp_path / "s.toml", "five_bar_sliding_mode", simulation={"duration": 0.02})
    code = ("import sys, pickle, freefloat\n"
            f"done = freefloat.simulate({str(scene)!r}, out={str(tmp_path / 'run')!r})\n"
            "print('matplotlib' in sys.modules, len(pickle.dumps(done.figures)) > 0)")
    printed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert printed.returncode == 0, printed.stderr
    assert printed.stdout.split()[-2:] == ["False", "True"]
    job = freefloat.simulate(scene).figures
    with choose(frozenset({"efforts", "platform_tracking"}), ("png",)):
        drawn = [p.name for p in pickle.loads(pickle.dumps(job))(tmp_path / "sent")]
        assert drawn == [p.name for p in job(tmp_path / "here")] == ["platform_tracking.png", "efforts.png"]
