"""A run folder's scene.toml is the scene as it ran: read back it is the same scene, and rerun it
gives the same results, for built-in scenes, ``--robot`` runs, ``model = "auto"`` and batches."""

from __future__ import annotations

import dataclasses
import json
import tomllib

import pytest

from freefloat.app.batch import Band, run_batch
from freefloat.app.cli import main
from freefloat.app.scenes import builtin_scenes, find_scene, load_scene, parse_scene
from freefloat.app.scenes.as_run import scene_as_run
from freefloat.paths import URDF_DIR

from .conftest import scene_variant

#: Summary entries that are not results of the simulation.
NOT_RESULTS = {"sim_wall_time_s", "wall_time_s", "versions", "scene", "model_choice", "model_auto", "written",
               "skipped"}


def results(folder) -> dict:
    """The numbers and statuses of a run's summary.json."""
    summary = json.loads((folder / "summary.json").read_text())
    return {k: v for k, v in summary.items() if k not in NOT_RESULTS}


@pytest.mark.parametrize("name", sorted(builtin_scenes()))
def test_every_built_in_scene_reads_back_equal(name):
    """scene_as_run's text parses to the same scene, key for key."""
    scene = find_scene(name)
    assert parse_scene(tomllib.loads(scene_as_run(scene))) == dataclasses.replace(scene, source=None)


def test_a_user_file_is_named_by_its_absolute_path(tmp_path, monkeypatch):
    """A URDF beside the user's scene is written as an absolute path, so the saved scene finds it
    from the run folder; a built-in file keeps its bare name."""
    urdf = tmp_path / "mine.urdf"
    urdf.write_text((URDF_DIR / "four_arm_planar.urdf").read_text())
    path = scene_variant(tmp_path / "scene.toml", "tumbling", robot={"urdf": "mine.urdf"})
    monkeypatch.chdir(tmp_path.parent)
    assert tomllib.loads(scene_as_run(load_scene(path)))["robot"]["urdf"] == str(urdf.resolve())
    assert tomllib.loads(scene_as_run(find_scene("tumbling")))["robot"]["urdf"] == "four_arm_planar.urdf"


@pytest.mark.slow
def test_a_robot_run_reruns_from_its_saved_scene(tmp_path):
    """``simulate --robot ur5`` writes a scene.toml naming ur5 (it named the tumbling scene's
    four-arm robot); rerunning that file gives the same summary."""
    first, again = tmp_path / "first", tmp_path / "again"
    assert main(["simulate", "--robot", "ur5", "--out", str(first), "--quiet", "--no-figures", "--no-html"]) == 0
    assert load_scene(first / "scene.toml").robot.urdf == "ur5"
    assert main(["simulate", str(first / "scene.toml"), "--out", str(again), "--quiet"]) == 0
    assert results(again) == results(first)


@pytest.mark.slow
def test_the_model_auto_chose_is_written_and_reruns_alike(tmp_path):
    """A scene with ``model = "auto"`` is saved with the model and lock it chose, and the rerun
    runs that plant with the same results."""
    path = scene_variant(tmp_path / "auto.toml", "tumbling", simulation={"model": "auto", "duration": 0.2})
    first, again = tmp_path / "first", tmp_path / "again"
    assert main(["simulate", str(path), "--out", str(first), "--quiet", "--no-figures", "--no-html"]) == 0
    chose = json.loads((first / "summary.json").read_text())["model_choice"]
    saved = load_scene(first / "scene.toml").simulation
    assert (saved.model, saved.lock) == (chose["model"], chose["lock"]) and saved.model != "auto"
    assert main(["simulate", str(first / "scene.toml"), "--out", str(again), "--quiet"]) == 0
    assert results(again) == results(first)


def test_a_batch_reruns_from_its_saved_scene(tmp_path):
    """A batch's scene.toml, batched again with the same seed and bands, gives the same rows."""
    scene = load_scene(scene_variant(tmp_path / "short.toml", "four_arm_joint_space", simulation={"duration": 0.05}))
    bands = [Band("joint_rate", 2.0)]
    first = run_batch(scene, tmp_path / "first", 2, bands, seed=3)
    again = run_batch(load_scene(tmp_path / "first" / "scene.toml"), tmp_path / "again", 2, bands, seed=3)
    strip = [{k: v for k, v in row.items() if "time" not in k} for row in first.rows]
    assert strip == [{k: v for k, v in row.items() if "time" not in k} for row in again.rows]
