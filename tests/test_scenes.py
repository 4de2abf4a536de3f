"""Scene files: the built-in scenes validate; bad keys, types and values are named."""

from __future__ import annotations

import tomllib

import pytest

from freefloat import SceneError
from freefloat.app.runner import prepare
from freefloat.app.scenes import (
    DEFAULT_SCENE,
    Scene,
    builtin_scenes,
    find_scene,
    load_scene,
    parse_scene,
)


def default_raw() -> dict:
    return tomllib.loads(builtin_scenes()[DEFAULT_SCENE].read_text())


def test_default_scene_is_the_dissertation_chapter_4_task():
    """The default scene is 4 arms, 5 s at 1 ms, Kp = 10, Kd = 100, +-5 deg per arm."""
    scene = find_scene(DEFAULT_SCENE)
    assert (scene.simulation.duration, scene.simulation.control_period) == (5.0, 0.001)
    assert (scene.controller.kp, scene.controller.kd, scene.task.duration) == (10.0, 100.0, 5.0)
    assert scene.task.displacement == {"arm1_ee": 5.0, "arm2_ee": -5.0, "arm3_ee": -5.0, "arm4_ee": 5.0}


ROBOT_SCENES = sorted(name for name, path in builtin_scenes().items() if isinstance(load_scene(path), Scene))
#: The scenes that take over 1 s to prepare on busy cores (the satellite's meshes, a planned
#: approach): marked slow, the other scenes stay in the quick subset.
SLOW_TO_PREPARE = {"capture_planned_planar", "capture_planned_planar_pose", "capture_planned_satellite",
                   "capture_planned_two_hands_planar", "capture_planned_two_hands_satellite", "capture_satellite",
                   "capture_two_hands_satellite", "capture_wheels", "satellite_dual_arm", "satellite_hands_joined",
                   "satellite_wheels", "satellite_momentum_dump", "satellite_thruster_hold", "capture_in_orbit"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW_TO_PREPARE else n
                                  for n in ROBOT_SCENES])
def test_builtin_scenes_prepare(name):
    """Every built-in robot scene resolves its robot, state, model, integrator and controller."""
    prepared = prepare(find_scene(name))
    assert prepared.q0.shape == (prepared.robot.model.nq,)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda r: r.update(colour="red"), "unknown top-level key 'colour'"),
        (lambda r: r["simulation"].update(dt=0.001), "unknown [simulation] key 'dt'"),
        (lambda r: r["simulation"].update(control_period=-0.001), "'simulation.control_period' must be > 0"),
        (lambda r: r["simulation"].update(duration="5"), "'simulation.duration' must be a number"),
        (lambda r: r["simulation"].update(substeps=1.5), "'simulation.substeps' must be an integer"),
        (lambda r: r["simulation"].update(integrator="rk45"), "'simulation.integrator' is 'rk45'; did you mean 'rkmk4'? (valid: euler"),
        (lambda r: r["controller"].update(model="magic"), "'controller.model' is 'magic'; valid: exact"),
        (lambda r: r["controller"].update(kp=-1.0), "'controller.kp' must be >= 0"),
        (lambda r: r["robot"].update(base="spherical"), "'robot.base' is 'spherical'; valid: free, planar"),
        (lambda r: r["robot"].pop("urdf"), "[robot] needs key 'urdf'"),
        (lambda r: r["initial"].update(base_position=[0, 0]), "'initial.base_position' must be a list of 3"),
        (lambda r: r["task"].update(displacement={"arm1_ee": "five"}), "'task.displacement' must be a table"),
        (lambda r: r.update(angle_unit="grad"), "'angle_unit' is 'grad'; did you mean 'rad'? (valid: deg, rad)"),
    ],
)
def test_bad_scene_values_are_named(edit, message):
    """Unknown keys, wrong types and impossible values are rejected with the key in the message."""
    raw = default_raw()
    edit(raw)
    with pytest.raises(SceneError) as err:
        parse_scene(raw)
    assert message in str(err.value)


def test_unknown_joint_in_a_table_is_named():
    """A joint table naming a joint that does not exist fails with the key and the valid names."""
    raw = default_raw()
    raw["initial"]["joint_positions"]["arm5_joint1"] = 1.0
    with pytest.raises(SceneError, match="'initial.joint_positions': 'arm5_joint1' is neither a joint"):
        prepare(parse_scene(raw, source=builtin_scenes()[DEFAULT_SCENE]))


def test_missing_robot_file_is_named():
    """A URDF that cannot be found fails naming robot.urdf."""
    raw = default_raw()
    raw["robot"]["urdf"] = "no_such_robot.urdf"
    with pytest.raises(SceneError, match="robot.urdf 'no_such_robot.urdf' not found"):
        prepare(parse_scene(raw))


def test_a_mistyped_scene_name_gets_the_nearest_builtins():
    """A mistyped scene name is refused with the nearest built-in scenes first, and a list cut to a
    few names that says where to see them all (it listed all 27)."""
    with pytest.raises(SceneError, match=r"'five_bar_slidng_mode' is neither .*; did you mean 'five_bar_sliding_mode'"
                                         r".*listed by freefloat scenes"):
        find_scene("five_bar_slidng_mode")
    with pytest.raises(SceneError, match=r"built-in: capture_\w+, capture_\w+, .* and \d+ more"):
        find_scene("not_a_scene")


def test_momentum_projection_is_a_scene_option_that_holds_the_momentum(tmp_path):
    """[simulation] project_momentum = true holds the momentum of a semi-implicit Euler tumbling
    run at round-off, where the plain run drifts."""
    from freefloat.app.runner import simulate

    from .conftest import scene_variant

    drifts = []
    for project in (False, True):
        scene = load_scene(scene_variant(tmp_path / f"s{project}.toml", "tumbling",
                                         simulation={"integrator": "euler", "duration": 0.5, "project_momentum": project}))
        drifts.append(simulate(scene).summary["momentum_drift_max"])
    assert drifts[1] < 1e-10 < drifts[0]


@pytest.mark.parametrize(("section", "values", "named"), [
    ("robot", {"gravity": [0.0, 0.0, -9.81]}, "robot.gravity"),
])
def test_momentum_projection_is_refused_where_momentum_changes(tmp_path, section, values, named):
    """Projection with gravity (or wrenches) would hold a momentum the physics changes: refused."""
    from .conftest import scene_variant

    path = scene_variant(tmp_path / "s.toml", "tumbling", simulation={"project_momentum": True}, **{section: values})
    with pytest.raises(SceneError, match=f"project_momentum.*{named}"):
        load_scene(path)


def test_momentum_projection_is_refused_with_wrenches():
    """A detumbling scene's impulse wrenches change the momentum: projection refused, naming them."""
    raw = tomllib.loads(builtin_scenes()["detumble_impulse_arm1_joint4"].read_text())
    raw["simulation"]["project_momentum"] = True
    with pytest.raises(SceneError, match=r"project_momentum.*\[\[wrenches\]\]"):
        parse_scene(raw)
