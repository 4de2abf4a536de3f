"""A user's controller and wrench field, written outside the package (examples/), found by
freefloat.simulate on a scene file, by the batch command on that file and by the Python API, with
no edit to freefloat; each run checked against the law it applies."""

from __future__ import annotations

import csv
import tomllib

import numpy as np
import pytest

import freefloat
from freefloat.app.cli import main
from freefloat.app.scenes import parse_scene
from freefloat.errors import InvalidArgument, SceneError, UnknownName
from freefloat.inputs import toml_text

from .conftest import REPO

EXAMPLES = REPO / "examples"
PD_SCENE, WRENCH_SCENE = EXAMPLES / "pd_controller.toml", EXAMPLES / "constant_wrench.toml"
#: The example scenes' settings.
KP, KD = 100.0, 20.0
FORCE, TORQUE = np.array([2.0, -1.0, 0.5]), np.array([0.0, 0.0, 0.3])


def pd_torque(telemetry) -> np.ndarray:
    """``kp (goal - q) - kd qdot`` at every row but the last (which holds the previous period's
    torque) (N - 1, n_joints); the goal is the telemetry's reference."""
    tel = telemetry
    error = tel.joint_reference - tel.joint_positions
    return (KP * error - KD * tel.v[:, 6:])[:-1]


def test_a_pd_controller_of_a_users_module_runs_from_a_scene_file():
    """simulate on a scene that names the PD module: every held torque is kp e - kd qdot at the
    period's start (the Python law, to round-off) and the joints close on the set point."""
    result = freefloat.simulate(PD_SCENE)
    tel = result.telemetry
    assert result.status == "completed" and len(tel.t) == 2001
    assert np.abs(tel.tau[:-1] - pd_torque(tel)).max() <= 1e-12 * np.abs(tel.tau).max()
    error = np.linalg.norm(tel.joint_reference - tel.joint_positions, axis=1)
    assert error[-1] < 0.3 * error[0] and (np.diff(error[::250]) < 0).all()


@pytest.mark.slow
def test_the_pd_controller_runs_in_a_batch_of_spawned_workers(tmp_path):
    """freefloat batch on the PD scene with two worker processes (spawned: they import the
    plug-in from the scene) gives the rows simulate gives."""
    out = tmp_path / "batch"
    assert main(["batch", str(PD_SCENE), "--runs", "2", "--workers", "2", "--quiet", "--out", str(out)]) == 0
    rows = list(csv.DictReader((out / "runs.csv").open()))
    expected = freefloat.simulate(PD_SCENE).summary["tracking_rms_overall"]
    assert [r["status"] for r in rows] == ["completed"] * 2
    assert all(float(r["tracking_rms_overall"]) == pytest.approx(expected, rel=1e-12) for r in rows)


def test_the_pd_controller_is_found_from_python():
    """freefloat.use registers the PD module; its entry, built on a context, runs in
    freefloat.run and holds kp e - kd qdot."""
    freefloat.use(EXAMPLES / "pd_controller.py")
    robot = freefloat.load_robot(REPO / "src" / "freefloat" / "urdf" / "four_arm_planar.urdf", visuals=False)
    goal = np.full(robot.n_joints, 0.2)
    reference = freefloat.QuinticTrajectory(np.zeros(robot.n_joints), goal, 1.0)
    entry = freefloat.CONTROLLERS["pd"]
    law = entry.build(freefloat.ControlContext(None, robot, reference, 1e-3), entry.settings(kp=KP, kd=KD))
    result = freefloat.run(robot, robot.neutral(), np.zeros(robot.model.nv), 0.2, 1e-3, controller=law)
    assert result.status == "completed"
    np.testing.assert_array_equal(result.telemetry.tau[:-1], pd_torque(result.telemetry))


def test_a_constant_wrench_field_of_a_users_module_runs_from_a_scene_file():
    """simulate on a scene that names the field: the linear momentum grows by F t (to 1e-9), the
    Python loop runs it, and the summary balances momentum and energy against what it applied."""
    result = freefloat.simulate(WRENCH_SCENE)
    tel, summary = result.telemetry, result.summary
    change = tel.momentum[:, :3] - tel.momentum[0, :3]
    assert np.abs(change - np.outer(tel.t, FORCE)).max() < 1e-9
    assert summary["loop"] == "python" and summary["external_impulse"][:3] == pytest.approx(0.5 * FORCE, abs=1e-12)
    assert summary["momentum_balance_max"] < 1e-7 and summary["energy_balance_max"] < 1e-7
    assert summary["external_work"] > 1e-3  # the field did work, which the energy balance counts


def test_the_constant_wrench_runs_in_a_batch(tmp_path):
    """freefloat batch on the field's scene reports the balance that simulate reports."""
    out = tmp_path / "batch"
    assert main(["batch", str(WRENCH_SCENE), "--runs", "1", "--quiet", "--out", str(out)]) == 0
    row = next(csv.DictReader((out / "runs.csv").open()))
    assert row["status"] == "completed" and float(row["linear_momentum_balance_max"]) < 1e-9
    assert float(row["external_impulse[0]"]) == pytest.approx(0.5 * FORCE[0], abs=1e-12)


def test_the_constant_wrench_is_found_from_python():
    """freefloat.use registers the field; built from its entry it runs in freefloat.run (the
    Python loop; the compiled one refuses it by name) with the momentum growing by F t."""
    freefloat.use(EXAMPLES / "constant_wrench.py")
    robot = freefloat.load_robot(REPO / "src" / "freefloat" / "urdf" / "four_arm_planar.urdf", visuals=False)
    entry = freefloat.ENVIRONMENTS["constant_wrench"]
    field = entry.build(robot, entry.settings("arm1_link2", tuple(FORCE), tuple(TORQUE)))
    q0, v0 = robot.neutral(), np.zeros(robot.model.nv)
    result = freefloat.run(robot, q0, v0, 0.2, 1e-3, environment=(field,))
    tel = result.telemetry
    assert result.backend == "python"
    assert np.abs(tel.momentum[:, :3] - tel.momentum[0, :3] - np.outer(tel.t, FORCE)).max() < 1e-9
    with pytest.raises(InvalidArgument, match="ConstantWrench has no compiled twin"):
        freefloat.run(robot, q0, v0, 0.2, 1e-3, environment=(field,), backend="compiled")


@pytest.mark.parametrize(("change", "message"), [
    (lambda r: r["controller"].update(kind="pdd"), "'controller.kind' is 'pdd'; did you mean 'pd'"),
    (lambda r: r["controller"].update(kpp=1.0), "unknown \\[controller\\] key 'kpp'; did you mean 'kp'"),
    (lambda r: r["controller"].update(kd=-1.0), "'controller.kd' must be >= 0"),
    (lambda r: r["controller"].update(kp="high"), "'controller.kp' must be a number"),
    (lambda r: r["task"].update(kind="none"), None),
])
def test_a_plugin_controllers_keys_are_checked_as_a_builtins(change, message):
    """The PD entry's settings and rules check a scene's [controller] table: an unknown kind or
    key with the nearest name, a type, a range; and the task it serves."""
    raw = tomllib.loads(PD_SCENE.read_text())
    change(raw)
    if message is None:  # parses; refused when the controller is built
        with pytest.raises(SceneError, match="controller 'pd' needs task.kind 'joint_quintic'"):
            freefloat.simulate(parse_scene(raw, PD_SCENE))
        return
    with pytest.raises(SceneError, match=message):
        parse_scene(raw, PD_SCENE)


def test_a_plugin_fields_kind_and_keys_are_checked_as_a_builtins():
    """An [[environment]] table of an unknown kind or with an unknown key is refused with the
    nearest name; the registry itself answers UnknownName."""
    raw = tomllib.loads(WRENCH_SCENE.read_text())
    raw["environment"][0]["kind"] = "constant_wrenches"
    with pytest.raises(SceneError, match="'environment.kind' is 'constant_wrenches'; did you mean 'constant_wrench'"):
        parse_scene(raw, WRENCH_SCENE)
    raw["environment"][0].update(kind="constant_wrench", forse=[1.0, 0.0, 0.0])
    with pytest.raises(SceneError, match="unknown \\[environment\\] key 'forse'; did you mean 'force'"):
        parse_scene(raw, WRENCH_SCENE)
    with pytest.raises(UnknownName, match="did you mean 'constant_wrench'"):
        freefloat.ENVIRONMENTS.get("constant_wrenc")


def test_a_missing_plugin_file_is_named():
    """A scene naming a plug-in file that does not exist is refused, naming the key and the file."""
    raw = tomllib.loads(PD_SCENE.read_text())
    raw["plugins"] = ["no_such_pd.py"]
    with pytest.raises(SceneError, match="'plugins': plug-in file .*no_such_pd.py: no such file"):
        parse_scene(raw, PD_SCENE)


TOY_MODEL = '''
from freefloat import MODELS
from freefloat.dynamics.models import ExactModel, ModelSpec

CALLS = [0]


class CountedExact(ExactModel):
    """Pinocchio's ABA, counting its evaluations."""

    name = "counted_exact"

    def acceleration(self, q, v, tau, fext=None):
        CALLS[0] += 1
        return super().acceleration(q, v, tau, fext)


MODELS.register(ModelSpec("counted_exact", "ABA, counted", False, lambda robot, backend: CountedExact(robot)))
'''


def test_a_dynamics_model_of_a_users_module_is_the_plant_of_a_scene(tmp_path):
    """A model registered by a scene's plug-in is the plant of its run: the Python loop calls it
    at every stage (4 per period for rkmk4) and the run ends where the exact model's run ends."""
    (tmp_path / "toy_counted_model.py").write_text(TOY_MODEL)
    raw = tomllib.loads((REPO / "src" / "freefloat" / "app" / "scenes" / "tumbling.toml").read_text())
    raw["robot"]["urdf"] = str(REPO / "src" / "freefloat" / "urdf" / "four_arm_planar.urdf")
    raw["simulation"].update(duration=0.05)
    raw["output"] = {"figures": False, "html": False}
    exact = freefloat.simulate(parse_scene(raw, tmp_path / "exact.toml"))
    raw.update(plugins=["toy_counted_model.py"])
    raw["simulation"].update(model="counted_exact")
    module = freefloat.use(tmp_path / "toy_counted_model.py")
    before = module.CALLS[0]
    toy = freefloat.simulate(parse_scene(raw, tmp_path / "toy.toml"))
    assert toy.summary["loop"] == "python" and toy.summary["model_evaluations"] == 4 * 50
    assert module.CALLS[0] - before >= 4 * 50  # the loop's, and the run-size check's few
    np.testing.assert_allclose(toy.telemetry.v[-1], exact.telemetry.v[-1], rtol=0, atol=1e-12)


@pytest.mark.slow
def test_a_dynamics_model_of_a_users_module_is_the_plant_of_a_batch(tmp_path):
    """freefloat batch on a scene whose plug-in registers the plant model runs it in its worker
    (the rows complete on the Python loop with rkmk4's 4 evaluations a period)."""
    # its own name: the simulate test's module may be registered in this process already
    (tmp_path / "toy_batch_model.py").write_text(TOY_MODEL.replace("counted_exact", "counted_in_batch"))
    raw = tomllib.loads((REPO / "src" / "freefloat" / "app" / "scenes" / "tumbling.toml").read_text())
    raw["robot"]["urdf"] = str(REPO / "src" / "freefloat" / "urdf" / "four_arm_planar.urdf")
    raw["simulation"].update(duration=0.05, model="counted_in_batch")
    raw.update(plugins=["toy_batch_model.py"], output={"figures": False, "html": False})
    (tmp_path / "toy.toml").write_text(toml_text(raw))
    out = tmp_path / "batch"
    assert main(["batch", str(tmp_path / "toy.toml"), "--runs", "2", "--workers", "2", "--quiet", "--out", str(out)]) == 0
    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert [r["status"] for r in rows] == ["completed", "completed"]
    assert {r["model_evaluations"] for r in rows} == {str(4 * 50)}


def test_a_run_folder_of_a_plugin_scene_reruns_it(tmp_path):
    """The scene.toml a run of the field's scene writes names the plug-in by its absolute path and
    the field as [[environment]]: run again from there, it gives the same momentum."""
    first = freefloat.simulate(WRENCH_SCENE, out=tmp_path / "run")
    text = (tmp_path / "run" / "scene.toml").read_text()
    assert str(EXAMPLES / "constant_wrench.py") in text and 'kind = "constant_wrench"' in text
    again = freefloat.simulate(tmp_path / "run" / "scene.toml")
    np.testing.assert_array_equal(again.telemetry.momentum, first.telemetry.momentum)


def test_a_capture_refuses_a_controller_without_its_gains():
    """A capture scene naming the PD kind is refused by name (its laws read the computed-torque
    gains), not run with a law it does not apply."""
    path = REPO / "src" / "freefloat" / "app" / "scenes" / "capture_planar.toml"
    raw = tomllib.loads(path.read_text())
    raw.update(plugins=[str(EXAMPLES / "pd_controller.py")])
    raw["controller"] = {"kind": "pd", "kp": 1.0}
    with pytest.raises(SceneError, match="a capture's laws are computed torque .* not controller 'pd'"):
        freefloat.simulate(parse_scene(raw, path))
