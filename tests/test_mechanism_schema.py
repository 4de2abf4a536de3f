"""Mechanism scenes: the built-in ones carry sec 5.6's numbers; bad keys, types and values are
rejected naming the scene file and the key."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from freefloat import SceneError
from freefloat.app.scenes import (
    MechanismScene,
    Scene,
    builtin_scenes,
    find_scene,
    load_scene,
    parse_scene,
)

SOURCE = Path("/scenes/bad_mechanism.toml")


def smc_raw() -> dict:
    return tomllib.loads(builtin_scenes()["five_bar_sliding_mode"].read_text())


def test_sliding_mode_scene_has_the_documents_numbers():
    """five_bar_sliding_mode: the 15 % plant, lambda = 40, eq 187's gains, eq 189's circle, RK4 at
    0.1 ms with Baumgarte 100 for 0.5 s, the error measured after 0.2 s."""
    scene = find_scene("five_bar_sliding_mode")
    assert isinstance(scene, MechanismScene)
    assert (scene.mechanism.name, scene.mechanism.plant, scene.controller.kind) == ("five_bar", "true_15", "sliding_mode")
    assert (scene.controller.lam, scene.controller.n, scene.controller.T) == (40.0, (75.3, 108.0), ((1.25, 0.92), (1.68, 1.65)))
    assert scene.controller.n_ij == {"0,0": (37.0, 54.1), "1,0": (22.7, 35.5), "1,1": (17.5, 28.5)}
    assert (scene.trajectory.center, scene.trajectory.radius, scene.trajectory.rate) == ((0.0, 0.17), 0.07, 28.57)
    assert (scene.simulation.duration, scene.simulation.step, scene.simulation.baumgarte) == (0.5, 1e-4, 100.0)
    assert scene.metrics.reaching_phase == 0.2


def test_computed_torque_scene_differs_only_in_the_controller():
    """five_bar_computed_torque runs the same experiment under eq 190."""
    smc, ct = find_scene("five_bar_sliding_mode"), find_scene("five_bar_computed_torque")
    assert ct.controller.kind == "computed_torque" and ct.controller.lam == smc.controller.lam
    assert (ct.mechanism, ct.initial, ct.trajectory, ct.simulation, ct.metrics) == (
        smc.mechanism, smc.initial, smc.trajectory, smc.simulation, smc.metrics)


def test_free_base_scenes_put_the_fixed_base_scenes_on_a_satellite():
    """five_bar_free_base is five_bar_sliding_mode on a 5 kg planar base at zero gravity;
    rsu_ppap_free_base is rsu_ppap_computed_torque on a 50 kg free base at zero gravity."""
    for free, fixed, kind, mass in (("five_bar_free_base", "five_bar_sliding_mode", "planar", 5.0),
                                    ("rsu_ppap_free_base", "rsu_ppap_computed_torque", "free", 50.0)):
        a, b = find_scene(free), find_scene(fixed)
        assert (a.mechanism.base, a.mechanism.base_mass, a.mechanism.gravity) == (kind, mass, (0.0, 0.0, 0.0))
        assert (a.mechanism.name, a.mechanism.plant, a.controller, a.trajectory, a.simulation, a.initial) == (
            b.mechanism.name, b.mechanism.plant, b.controller, b.trajectory, b.simulation, b.initial)
        assert b.mechanism.base == "fixed"


def test_robot_scenes_stay_robot_scenes():
    """A scene without [mechanism] is still a robot scene."""
    assert isinstance(find_scene("four_arm_joint_space"), Scene)


@pytest.mark.parametrize(("edit", "message"), [
    (lambda r: r["controller"].update(gain=3.0), "unknown [controller] key 'gain'"),
    (lambda r: r.update(angle_unit="deg"), "unknown top-level key 'angle_unit'"),
    (lambda r: r["mechanism"].update(name="six_bar"), "'mechanism.name' is 'six_bar'; did you mean 'five_bar'? (valid: five_bar"),
    (lambda r: r["mechanism"].update(plant="true_30"), "'mechanism.plant' is 'true_30'; did you mean 'true_50' or 'true_15'? (valid for 'five_bar': nominal"),
    (lambda r: r["mechanism"].pop("closure"), "[mechanism] needs key 'closure'"),
    (lambda r: r.pop("trajectory"), "a mechanism scene needs 'trajectory'"),
    (lambda r: r["controller"].pop("T"), "'sliding_mode' needs 'controller.n' and 'controller.T'"),
    (lambda r: r["controller"].update(kind="computed_torque"), "does not use them"),
    (lambda r: r["controller"].update(kind="pid"), "'controller.kind' is 'pid'; valid: computed_torque, sliding_mode"),
    (lambda r: r["controller"].update(lam=-40.0), "'controller.lam' must be > 0"),
    (lambda r: r["controller"].update(T=[[1.0, 2.0], [3.0]]), "'controller.T' must be a list of equally long rows"),
    (lambda r: r["controller"].update(n_ij={"0,0": "big"}), "'controller.n_ij.0,0' must be a list of one or more"),
    (lambda r: r["trajectory"].update(axes=[1, 1]), "'trajectory.axes' must be a list of 2 distinct integers"),
    (lambda r: r["simulation"].update(integrator="rk45"), "'simulation.integrator' is 'rk45'; did you mean 'rk4' or 'rkmk4'? (valid: rk4, euler, explicit_euler, rkmk3, rkmk4"),
    (lambda r: r["simulation"].update(step=1.0), "'simulation.step' (1.0 s) is longer than 'simulation.duration'"),
    (lambda r: r["simulation"].update(baumgarte=-1.0), "'simulation.baumgarte' must be >= 0"),
    (lambda r: r.update(metrics={"reaching_phase": 1e3}), "'metrics.reaching_phase' (1000.0 s) is not shorter than"),
    (lambda r: r["initial"].update(platform=[]), "'initial.platform' must be a list of one or more finite numbers"),
    (lambda r: r["mechanism"].update(base="floating"), "'mechanism.base' is 'floating'; valid: fixed, planar, free"),
    (lambda r: r["mechanism"].update(base="planar", base_mass=-2.0), "'mechanism.base_mass' must be > 0"),
    (lambda r: r["mechanism"].update(base="free", base_mass="heavy"), "'mechanism.base_mass' must be a number"),
    (lambda r: r["mechanism"].update(base="free", base_inertia=[1.0, 2.0]),
     "'mechanism.base_inertia' must be three finite numbers"),
    (lambda r: r["mechanism"].update(base="free", base_inertia=[[1.0, 0.0, 0.0]] * 3),
     "'mechanism.base_inertia' must be a list of one or more finite numbers"),
    (lambda r: r["mechanism"].update(base="free", base_inertia=[1.0, 1.0, 3.0]),
     "'mechanism.base_inertia' must be three positive principal moments"),
    (lambda r: r["mechanism"].update(base="planar", base_com=[0.0, 0.1]), "'mechanism.base_com' must be three finite"),
    (lambda r: r["mechanism"].update(base_mass=5.0), "'mechanism.base_mass' describes the base body, which plays no "
                                                     "part on a fixed base"),
    (lambda r: r["mechanism"].update(gravity=[0.0, -9.8]), "'mechanism.gravity' must be three finite numbers"),
    (lambda r: r["mechanism"].update(dynamics="orsino"), "'mechanism.dynamics' is 'orsino'; valid: auto, coupled_chain"),
    (lambda r: r["mechanism"].update(base="planar", dynamics="coupled_chain"),
     "'mechanism.dynamics' is 'coupled_chain', which models a fixed base; on a 'planar' base use"),
])
def test_bad_values_name_the_file_and_the_key(edit, message):
    """Unknown keys, unknown mechanisms and plants, missing or unused gains, wrong types and
    impossible values fail with the scene file and the key in the message."""
    raw = smc_raw()
    edit(raw)
    with pytest.raises(SceneError) as err:
        parse_scene(raw, source=SOURCE)
    assert str(err.value).startswith(f"{SOURCE}: ") and message in str(err.value)


def test_load_scene_names_the_file(tmp_path):
    """A mechanism scene file with a bad key fails naming that file."""
    path = tmp_path / "m.toml"
    path.write_text(builtin_scenes()["five_bar_sliding_mode"].read_text().replace("lam = 40.0", "lam = 40.0\nlamda = 1.0"))
    with pytest.raises(SceneError, match=f"{path}: unknown \\[controller\\] key 'lamda'"):
        load_scene(path)
