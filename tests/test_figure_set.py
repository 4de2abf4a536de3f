"""Which figures a run draws: ``[output] figures`` and ``figure_formats`` in a scene, and
``freefloat simulate --figures``; unknown names refused with the choices, the chosen set written
and nothing else, none when the set is empty."""

from __future__ import annotations

import pytest

from freefloat.app import figure_set
from freefloat.app.cli import main
from freefloat.app.run_folder import RECORD
from freefloat.app.scenes import load_scene
from freefloat.errors import SceneError

from .conftest import scene_variant

#: What every run folder holds besides its figures.
DATA = {"telemetry.npz", "summary.json", "scene.toml"}


def _scene(tmp_path, **output):
    """The default scene shortened to 20 ms, its ``[output]`` table updated with ``output``."""
    return scene_variant(tmp_path / "scene.toml", "four_arm_joint_space", simulation={"duration": 0.02},
                         output={"html": False, **output})


def _figures(out) -> set[str]:
    return {p.name for p in out.iterdir()} - DATA - {RECORD}


@pytest.mark.parametrize("value", [["joint_errors", "torqes"], ["all", 3], "torques"])
def test_scene_refuses_an_unknown_figure_listing_the_choices(tmp_path, value):
    """A name not in the registry, a non-string or a bare string is refused naming the key; an
    unknown name with every valid one."""
    with pytest.raises(SceneError, match=r"'output\.figures'") as error:
        load_scene(_scene(tmp_path, figures=value))
    if value[-1] == "torqes":
        assert "unknown figure 'torqes'; valid: all, " + ", ".join(figure_set.FIGURES) in str(error.value)


def test_scene_refuses_an_unknown_format(tmp_path):
    with pytest.raises(SceneError, match=r"'output\.figure_formats' must be a non-empty list of png, pdf"):
        load_scene(_scene(tmp_path, figure_formats=["png", "svg"]))


def test_the_command_refuses_an_unknown_figure(tmp_path, capsys):
    """--figures with an unknown name: exit 2, the message lists the names, no folder."""
    assert main(["simulate", str(_scene(tmp_path)), "--out", str(tmp_path / "out"), "--quiet",
                 "--figures", "torques,paths"]) == 2
    assert "--figures: unknown figure 'paths'; valid: all, joint_errors" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_the_chosen_figures_are_written_in_the_chosen_formats(tmp_path):
    """A scene's list of figures and formats: those figures, PNG and PDF, and no other."""
    out = tmp_path / "out"
    scene = _scene(tmp_path, figures=["torques", "base_trajectory"], figure_formats=["png", "pdf"])
    assert main(["simulate", str(scene), "--out", str(out), "--quiet"]) == 0
    assert _figures(out) == {"torques.png", "torques.pdf", "base_trajectory.png", "base_trajectory.pdf"}


@pytest.mark.slow
def test_the_command_line_choice_replaces_the_scene_s(tmp_path):
    """--figures NAME,... overrides the scene's set; 'all' draws every figure the run has."""
    scene = _scene(tmp_path, figures=["torques"])
    assert main(["simulate", str(scene), "--out", str(tmp_path / "one"), "--quiet", "--figures", "com_drift"]) == 0
    assert _figures(tmp_path / "one") == {"com_drift.png"}
    assert main(["simulate", str(scene), "--out", str(tmp_path / "all"), "--quiet", "--figures", "all"]) == 0
    assert _figures(tmp_path / "all") == {f"{name}.png" for name in (
        "joint_errors", "torques", "base_trajectory", "end_effector_paths", "end_effector_displacement", "com_drift")}


@pytest.mark.parametrize("how", ["scene", "command"])
def test_an_empty_set_writes_no_figure(tmp_path, how):
    """figures = [] in the scene, or --figures '': the run writes its data and no figure."""
    scene = _scene(tmp_path, figures=[]) if how == "scene" else _scene(tmp_path)
    extra = ["--figures", ""] if how == "command" else []
    assert main(["simulate", str(scene), "--out", str(tmp_path / "out"), "--quiet", *extra]) == 0
    assert _figures(tmp_path / "out") == set()


@pytest.mark.slow
def test_the_default_set_is_lean_and_true_means_it(tmp_path):
    """With no [output] figures (or true) the default job draws the default set: its tracking,
    torques and conservation figures."""
    for value, out in ((None, tmp_path / "absent"), (True, tmp_path / "true")):
        scene = _scene(tmp_path, **({} if value is None else {"figures": value}))
        assert main(["simulate", str(scene), "--out", str(out), "--quiet"]) == 0
        assert _figures(out) == {"joint_errors.png", "torques.png", "com_drift.png"}
