"""Tests of freefloat.app.viz.figure_job: a robot run's figures as one job for the figure helper."""

from __future__ import annotations

import pickle

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
