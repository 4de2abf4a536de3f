"""After a capture (dissertation sec 5.3): the angular momentum L(t) drawn (fig 41), and the
baseline scene without detumbling (figs 42-44) against the detumbling one."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.app import runner
from freefloat.app.experiments.robot_run import prepare_robot
from freefloat.app.scenes import builtin_scenes, load_scene
from freefloat.app.viz.figures import angular_momentum_figure
from freefloat.dynamics.metrics import angular_speeds

from .conftest import scene_variant
from .test_capture import planar_capture_setup


def test_angular_momentum_figure_draws_pinocchios_centroidal_momentum_after_a_capture():
    """The figure's upper panel (about the system CoM) is Pinocchio's centroidal angular momentum
    of the merged robot at each recorded state after the grasp, the lower one the recorded L
    about the origin, which is it plus com x P."""
    from freefloat.space.capture import capture_and_detumble

    robot, target = planar_capture_setup()
    res = capture_and_detumble(robot, target, "arm1_ee", [("arm1_ee", "wz")], None, detumble_time=0.2)
    tel, model = res.post, res.merged.model
    data = model.createData()
    centroidal = np.array([pin.computeCentroidalMomentum(model, data, q, v).angular.copy() for q, v in zip(tel.q, tel.v)])
    fig = angular_momentum_figure(tel)
    about_com, about_origin = ([np.asarray(line.get_ydata(), float) for line in ax.get_lines()] for ax in fig.axes[:2])
    shown = np.asarray(fig.axes[0].get_lines()[0].get_xdata(), float)
    rows = np.searchsorted(tel.t, shown)
    scale = np.abs(centroidal).max()
    assert scale > 0.5  # the target's spin: L is not trivially zero
    np.testing.assert_allclose(np.column_stack(about_com), centroidal[rows], rtol=0, atol=1e-10 * scale)
    com = np.array([pin.centerOfMass(model, data, q) for q in tel.q])
    linear = np.array([pin.computeCentroidalMomentum(model, data, q, v).linear.copy() for q, v in zip(tel.q, tel.v)])
    np.testing.assert_allclose(np.column_stack(about_origin), (centroidal + np.cross(com, linear))[rows], rtol=0,
                               atol=1e-10 * scale)


@pytest.mark.slow
def test_capture_and_detumble_scenes_write_the_angular_momentum_figure(tmp_path):
    """capture_planar (after the grasp) and a detumble impulse scene write angular_momentum."""
    for name in ("capture_planar", "detumble_impulse_arm1_joint4"):
        out = tmp_path / name
        runner.simulate(load_scene(scene_variant(tmp_path / f"{name}.toml", name, simulation={"duration": 0.6})), out=out)
        assert (out / "angular_momentum.png").is_file()


def _end_effector_spin(name: str) -> tuple[np.ndarray, np.ndarray]:
    """Times (N,) and arm 1's end-effector angular speed (N,), rad/s, of the built-in scene."""
    run = runner.simulate(name)
    robot = prepare_robot(load_scene(builtin_scenes()[name])).robot
    return run.telemetry.t, angular_speeds(robot, run.telemetry)[1][:, 0]


@pytest.mark.slow
def test_without_detumbling_the_end_effector_keeps_turning():
    """Baseline (joints held): arm 1's end-effector turns at the same rate from 0.5 s (posture
    back) to the end, within 1 %; with detumbling (scenario 1) the same rate falls below 1e-6 of
    its value at 0.1 s by the end."""
    t, held = _end_effector_spin("detumble_impulse_baseline")
    k = np.searchsorted(t, 0.5 - 1e-9)
    assert held[k] > 1e-3 and abs(held[-1] - held[k]) < 0.01 * held[k]
    t, detumbled = _end_effector_spin("detumble_impulse_arm1_joint4")
    k = np.searchsorted(t, 0.1 - 1e-9)
    assert detumbled[-1] < 1e-6 * detumbled[k]
