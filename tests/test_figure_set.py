"""Which figures a run draws: ``[output] figures`` and ``figure_formats`` in a scene, and
``freefloat simulate --figures``; unknown names refused with the choices, the chosen set written
and nothing else, none when the set is empty."""

from __future__ import annotations

import json

import pytest

from freefloat.app import figure_set
from freefloat.app.cli import main
from freefloat.app.run_folder import RECORD
from freefloat.app.scenes import load_scene
from freefloat.errors import LISTED, SceneError

from .conftest import scene_variant

#: What every run folder holds besides its figures.
DATA = {"telemetry.npz", "summary.json", "scene.toml"}


def _scene(tmp_path, **output):
    """The default scene shortened to 20 ms, its ``[output]`` table updated with ``output``."""
    return scene_variant(tmp_path / "scene.toml", "four_arm_joint_space", simulation={"duration": 0.02},
                         output={"html": False, **output})


def _figures(out) -> set[str]:
    return {p.name for p in out.iterdir() if not p.name.startswith("telemetry_")} - DATA - {RECORD}


@pytest.mark.parametrize("value", [["joint_errors", "torqes"], ["all", 3], "torques"])
def test_scene_refuses_an_unknown_figure_listing_the_choices(tmp_path, value):
    """A name not in the registry, a non-string or a bare string is refused naming the key; an
    unknown name with every valid one."""
    with pytest.raises(SceneError, match=r"'output\.figures'") as error:
        load_scene(_scene(tmp_path, figures=value))
    if value[-1] == "torqes":
        message = str(error.value)
        assert "unknown figure 'torqes'; did you mean 'torques'? (valid: all, " in message
        whole = message.endswith(", ".join(figure_set.FIGURES) + ")")
        assert whole if len(figure_set.FIGURES) < LISTED else message.endswith("listed by docs/commands.md)")


def test_scene_refuses_an_unknown_format(tmp_path):
    with pytest.raises(SceneError, match=r"'output\.figure_formats' must be a non-empty list of png, pdf"):
        load_scene(_scene(tmp_path, figure_formats=["png", "svg"]))


def test_the_command_refuses_an_unknown_figure(tmp_path, capsys):
    """--figures with an unknown name: exit 2, the message lists the names, no folder."""
    assert main(["simulate", str(_scene(tmp_path)), "--out", str(tmp_path / "out"), "--quiet",
                 "--figures", "torques,paths"]) == 2
    assert "--figures: unknown figure 'paths'; valid: all, joint_errors" in capsys.readouterr().err  # none near
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


#: What every robot run's motion is drawn as (outside the default set).
MOTION = {"base_trajectory", "end_effector_paths", "end_effector_displacement"}
SPIN = {"angular_rates", "angular_momentum"}
#: What every mechanism run draws.
MECHANISM = {"platform_tracking", "efforts", "loop_closure_drift"}
JOINT_SPACE = MOTION | {"joint_errors", "torques", "com_drift"}
CAPTURE = MOTION | SPIN | {"torques", "com_drift"}
DETUMBLING = MOTION | SPIN | {"joint_errors", "torques", "conservation_balance"}
#: The figures each built-in scene's task and controller call for.
CALLED_FOR = {
    "capture_planar": CAPTURE, "capture_satellite": CAPTURE, "capture_identified": CAPTURE | {"identification"},
    "capture_in_orbit": CAPTURE - {"com_drift"} | {"conservation_balance", "relative_orbit"},
    "capture_wheels": CAPTURE | {"reaction_wheels"},
    **dict.fromkeys(("capture_planned_planar", "capture_planned_planar_pose", "capture_planned_satellite"),
                    CAPTURE | {"approach_joint_errors"}),
    **dict.fromkeys(("capture_two_hands_planar", "capture_two_hands_satellite"), CAPTURE | {"closed_loop"}),
    **dict.fromkeys(("capture_planned_two_hands_planar", "capture_planned_two_hands_satellite"),
                    CAPTURE | {"closed_loop", "approach_joint_errors"}),
    **dict.fromkeys(("detumble_impulse_arm1_joint3", "detumble_impulse_arm1_joint4", "detumble_impulse_arm2_joint4",
                     "detumble_impulse_baseline", "detumble_impulse_both_arms", "detumble_sensed"), DETUMBLING),
    "detumble_impulse_wheel": DETUMBLING | {"reaction_wheels"},
    "five_bar_computed_torque": MECHANISM, "rsu_ppap_computed_torque": MECHANISM,
    "five_bar_sliding_mode": MECHANISM | {"sliding_variables"}, "five_bar_revolute": MECHANISM | {"sliding_variables"},
    "rsu_ppap_sliding_mode": MECHANISM | {"sliding_variables"},
    "five_bar_free_base": MECHANISM | {"sliding_variables", "base_attitude", "momentum"},
    "rsu_ppap_free_base": MECHANISM | {"base_attitude", "momentum"},
    "four_arm_joint_space": JOINT_SPACE, "satellite_dual_arm": JOINT_SPACE,
    "satellite_wheels": JOINT_SPACE | {"reaction_wheels"},
    "satellite_momentum_dump": JOINT_SPACE - {"com_drift"} | {"conservation_balance", "reaction_wheels", "thrusters"},
    "satellite_thruster_hold": JOINT_SPACE - {"com_drift"} | {"conservation_balance", "thrusters"},
    "satellite_hands_joined": MOTION | {"com_drift", "closed_loop"},
    "tumbling": MOTION | {"com_drift"}, "orbit_libration": MOTION | {"conservation_balance", "relative_orbit"},
    **dict.fromkeys(("contact_capture", "contact_rebound_fast"), MOTION | {"com_drift", "contact"}),
}


def test_every_builtin_scene_calls_for_the_figures_of_its_task_and_controller():
    """Each built-in scene's figure set follows its kind, task, controller, wrenches, closures,
    wheels and base: no torques without a controller, no sliding variables under computed torque,
    the momentum balance where wrenches act."""
    from freefloat.app.scenes import builtin_scenes

    assert set(CALLED_FOR) == set(builtin_scenes())
    for name, path in builtin_scenes().items():
        assert set(figure_set.called_for(load_scene(path))) == CALLED_FOR[name], name


@pytest.mark.slow
@pytest.mark.parametrize(("name", "duration"), [("rsu_ppap_computed_torque", 0.05), ("five_bar_free_base", 0.05),
                                              ("tumbling", 0.05), ("orbit_libration", 50.0)])
def test_a_run_writes_the_figures_its_task_calls_for(tmp_path, name, duration):
    """With every figure chosen, a short run writes those its scene calls for, less those the
    summary names as not drawn (data identically zero): a computed-torque mechanism no
    sliding_variables, a run in orbit (a field of the environment) its conservation_balance."""
    scene = scene_variant(tmp_path / "scene.toml", name, simulation={"duration": duration},
                          output={"html": False, "figures": ["all"]})
    out = tmp_path / "out"
    assert main(["simulate", str(scene), "--out", str(out), "--quiet"]) == 0
    not_drawn = set(json.loads((out / "summary.json").read_text()).get("figures_not_drawn", {}))
    assert _figures(out) == {f"{figure}.png" for figure in CALLED_FOR[name] - not_drawn}
