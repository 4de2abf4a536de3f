"""The experiment registry: every scene kind has one experiment, chosen by the scene (the one
registered experiment that takes it, or the one its top-level ``kind`` names)."""

from __future__ import annotations

import csv
import dataclasses
import subprocess
import sys
import tomllib

import pytest

import freefloat
from freefloat import InvalidArgument, SceneError
from freefloat.app.experiments import EXPERIMENTS, experiment_for
from freefloat.app.scenes import MechanismScene, builtin_scenes, kinds, load_scene
from freefloat.inputs import toml_text
from freefloat.registry import Registry

from . import toy_experiment
from .conftest import scene_variant


@pytest.mark.parametrize("name", sorted(builtin_scenes()))
def test_every_builtin_scene_has_its_experiment(name):
    """Each built-in scene's kind picks the experiment registered for that kind."""
    scene = load_scene(builtin_scenes()[name])
    assert experiment_for(scene).name == scene.kind


def old_kind(scene) -> str:
    """The kind as the scene schema hand-listed it before the experiments declared what they take."""
    if isinstance(scene, MechanismScene):
        return "mechanism"
    if "free_target" in scene.sections:
        return "contact_capture"
    if scene.target is not None:
        if scene.target.second_end_effector:
            return "two_hand_capture"
        return "capture_identification" if "identification" in scene.sections else "capture"
    return "detumbling" if scene.task.kind == "detumble" else "joint_space"


@pytest.mark.parametrize("name", sorted(builtin_scenes()))
def test_every_builtin_scene_keeps_its_kind(name):
    """The experiment that takes a built-in scene is the kind the old hand-kept rule gave (an
    [identification] makes a capture_identification), and no other registered experiment that
    reads its sections takes it."""
    scene = load_scene(builtin_scenes()[name])
    assert scene.kind == old_kind(scene)
    assert [e.name for e in EXPERIMENTS.values()
            if set(getattr(scene, "sections", {})) <= set(e.sections) and e.takes(scene)] == [old_kind(scene)]


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


def kind_scene(tmp_path, builtin: str = "tumbling", kind: str | None = None, **sections: dict):
    """The built-in scene with a short run, the given sections, and the top-level ``kind``."""
    path = scene_variant(tmp_path / "s.toml", builtin, simulation={"duration": 0.01},
                         output={"figures": False, "html": False}, **sections)
    if kind is not None:
        path.write_text(toml_text({"kind": kind, **tomllib.loads(path.read_text())}))
    return load_scene(path)


def test_a_scene_may_name_the_kind_that_takes_it(tmp_path):
    """A top-level kind naming the experiment that takes the scene is its kind, and it is kept
    in the scene as run."""
    from freefloat.app.scenes.as_run import scene_as_run

    scene = kind_scene(tmp_path, kind="joint_space")
    assert scene.named_kind == "joint_space" and scene.kind == "joint_space"
    assert tomllib.loads(scene_as_run(scene))["kind"] == "joint_space"


def test_a_misspelt_kind_is_named_with_the_nearest(tmp_path):
    """A top-level kind no experiment is registered under is refused with the nearest kind."""
    with pytest.raises(SceneError, match="'kind' is 'joint_spac'; did you mean 'joint_space'"):
        experiment_for(kind_scene(tmp_path, kind="joint_spac"))


def test_a_kind_that_does_not_take_the_scene_says_why(tmp_path):
    """A top-level kind whose experiment does not take the scene is refused, saying which scenes
    it takes and which kind this scene is."""
    with pytest.raises(SceneError, match=r"'kind' is 'capture', but that experiment takes robot scenes with a "
                                         r"\[target\].*this scene is a 'joint_space' scene"):
        experiment_for(kind_scene(tmp_path, kind="capture"))
    with pytest.raises(SceneError, match="'kind' is 'joint_space', but that experiment takes robot scenes"):
        experiment_for(kind_scene(tmp_path, "five_bar_sliding_mode", kind="joint_space"))


def test_a_scene_no_experiment_takes_lists_the_kinds(tmp_path, monkeypatch):
    """Without the experiment that takes it, a scene is refused, naming it and the kinds."""
    scene, others = kind_scene(tmp_path), Registry("experiment kind")
    for experiment in EXPERIMENTS.values():
        if experiment.name != "joint_space":
            others.register(experiment)
    monkeypatch.setattr(kinds, "EXPERIMENTS", others)
    with pytest.raises(SceneError, match="no experiment kind takes this scene; experiment kinds: detumbling, "
                                         "capture, capture_identification, two_hand_capture, mechanism"):
        experiment_for(scene)


def test_a_scene_s_kind_is_known_in_a_process_that_imported_only_the_scenes():
    """A scene's kind asked in a fresh process that imported the scenes alone: the first lookup
    imports the experiments, which register the built-in kinds."""
    code = ("import sys; from freefloat.app.scenes import find_scene; "
            "print('freefloat.app.experiments' in sys.modules, find_scene('four_arm_joint_space').kind)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False", "joint_space"]


def test_two_experiments_taking_one_scene_is_a_programming_error(tmp_path, monkeypatch):
    """Two registered experiments taking a scene that names no kind are named, both; the scene
    that names one of them runs as that one."""
    monkeypatch.setitem(EXPERIMENTS, "coast", toy_experiment.EXPERIMENT)
    with pytest.raises(InvalidArgument, match="experiment kinds 'joint_space' and 'coast' both take scene "
                                              "'tumbling'"):
        experiment_for(kind_scene(tmp_path))
    assert kind_scene(tmp_path, kind="coast").kind == "coast"


def test_a_users_kind_runs_from_its_own_section(tmp_path, monkeypatch):
    """A user's experiment registered from outside freefloat takes the scene with its own section
    (which no built-in reads; kept in the scene as run) and runs it through freefloat.simulate:
    its summary has the section's label and its telemetry is joint_space's on the same scene."""
    from freefloat.app.scenes.as_run import scene_as_run

    monkeypatch.setitem(EXPERIMENTS, "coast", toy_experiment.EXPERIMENT)
    scene = kind_scene(tmp_path, coast={"label": "adrift"})
    assert scene.kind == "coast" and scene.sections["coast"] == toy_experiment.CoastSettings("adrift")
    assert tomllib.loads(scene_as_run(scene))["coast"] == {"label": "adrift"}  # the run folder's scene reruns it
    result = freefloat.simulate(scene)
    plain = freefloat.simulate(dataclasses.replace(scene, sections={}, named_kind="joint_space"))
    assert result.status == "completed" and result.summary["coast_label"] == "adrift"
    assert "coast_label" not in plain.summary
    assert (result.telemetry.q == plain.telemetry.q).all()


def test_a_users_kind_runs_when_the_scene_names_it(tmp_path, monkeypatch):
    """A scene naming the user's kind at the top level runs as it (its section's defaults)."""
    monkeypatch.setitem(EXPERIMENTS, "coast", toy_experiment.EXPERIMENT)
    result = freefloat.simulate(kind_scene(tmp_path, kind="coast"))
    assert result.status == "completed" and result.summary["coast_label"] == "coasting"


def test_a_users_section_is_checked_as_a_builtin(tmp_path, monkeypatch):
    """A section of a registered kind refuses an unknown key with the nearest; without the kind
    registered, the section is an unknown key of the scene."""
    with pytest.raises(SceneError, match="coast"):
        kind_scene(tmp_path, coast={"label": "adrift"})
    monkeypatch.setitem(EXPERIMENTS, "coast", toy_experiment.EXPERIMENT)
    with pytest.raises(SceneError, match="did you mean 'label'"):
        kind_scene(tmp_path, coast={"lable": "adrift"})


def test_a_users_kind_runs_in_a_batch(tmp_path, monkeypatch):
    """freefloat batch on a scene with the user's section runs the user's kind in every run (in
    this process: the kind registered here)."""
    from freefloat.app.cli import main

    monkeypatch.setitem(EXPERIMENTS, "coast", toy_experiment.EXPERIMENT)
    scene = kind_scene(tmp_path, coast={"label": "adrift"})
    out = tmp_path / "batch"
    assert main(["batch", str(scene.source), "--runs", "2", "--workers", "1", "--quiet", "--out", str(out)]) == 0
    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert [(r["status"], r["coast_label"]) for r in rows] == [("completed", "adrift")] * 2


def test_a_kind_declaring_a_builtin_section_is_refused(tmp_path, monkeypatch):
    """An experiment kind whose section is a built-in key of the scene is named when a scene is
    read (it would otherwise keep every built-in kind from that scene)."""
    clash = dataclasses.replace(toy_experiment.EXPERIMENT, sections={"robot": toy_experiment.CoastSettings})
    monkeypatch.setitem(EXPERIMENTS, "coast", clash)
    with pytest.raises(InvalidArgument, match="experiment kind 'coast' declares the section 'robot'"):
        kind_scene(tmp_path)
