"""Scenes with locked joints (freefloat.app.experiments.locked_run): which joints, and the run
read back on the full robot."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.app import runner
from freefloat.app.experiments import experiment_for as experiment_for_scene
from freefloat.dynamics.telemetry import Telemetry
from freefloat.errors import SceneError

from .conftest import ONE_ARM_TASK, quiet_scene


def test_auto_locks_exactly_the_joints_the_controller_holds_still(tmp_path):
    """``lock = "auto"`` locks every joint of the three arms the task does not move, and no other."""
    setup = runner.prepare(quiet_scene(tmp_path, task=ONE_ARM_TASK, simulation={"duration": 0.05, "lock": "auto"}))
    assert setup.lock.names == tuple(f"arm{a}_joint{j}" for a in (2, 3, 4) for j in (1, 2, 3, 4))


def test_auto_locks_nothing_in_a_torque_free_scene(tmp_path):
    """Torque-free joints are not held, so ``lock = "auto"`` locks none of them."""
    setup = runner.prepare(quiet_scene(tmp_path, "tumbling", simulation={"duration": 0.05, "lock": "auto"}))
    assert setup.lock is None


def test_unknown_locked_joint_is_refused_naming_the_key_and_the_joint(tmp_path):
    """A name in ``robot.locked_joints`` that is no joint fails naming the key and the name."""
    bad = quiet_scene(tmp_path, robot={"locked_joints": ["arm9_joint1"]}, simulation={"duration": 0.05})
    with pytest.raises(SceneError, match="'robot.locked_joints': 'arm9_joint1' is neither a joint"):
        runner.prepare(bad)


def test_a_locked_joint_the_task_moves_is_refused_naming_both_keys(tmp_path):
    """Locking a joint that ``task.displacement`` moves fails naming both keys and the joint."""
    bad = quiet_scene(tmp_path, robot={"locked_joints": ["arm1_joint2"]}, simulation={"duration": 0.05})
    with pytest.raises(SceneError, match="'robot.locked_joints' names arm1_joint2, which 'task.displacement' moves"):
        runner.prepare(bad)


def test_a_locked_joint_with_an_initial_rate_is_refused(tmp_path):
    """Locking a joint that starts moving fails naming ``initial.joint_velocities``."""
    bad = quiet_scene(tmp_path, "tumbling", robot={"locked_joints": ["arm3_joint1"]},
                initial={"joint_velocities": {"arm3_joint1": 1.0}}, simulation={"duration": 0.05})
    with pytest.raises(SceneError, match="arm3_joint1, which 'initial.joint_velocities' moves"):
        runner.prepare(bad)


def test_locked_run_keeps_the_full_joint_vector_with_the_locked_angles_constant(tmp_path):
    """The written telemetry has every joint; the locked ones keep their initial angles and zero rates."""
    locked = quiet_scene(tmp_path, task=ONE_ARM_TASK, simulation={"duration": 0.05, "lock": "auto"})
    runner.simulate(locked, out=tmp_path / "out")
    tel = Telemetry.load(tmp_path / "out" / "telemetry.npz")
    assert tel.joint_positions.shape[1] == 16 and tel.q.shape[1] == 20
    held = tel.joint_positions[:, 4:]
    assert np.array_equal(held, np.broadcast_to(held[0], held.shape)) and held[0, 0] == pytest.approx(np.pi / 2)
    assert not np.any(tel.v[:, 3 + 4:]) and np.array_equal(tel.joint_reference[:, 4:], held)


def test_locked_run_follows_the_unlocked_one_and_its_brakes_give_the_holding_torque(tmp_path):
    """Arm 1 moves as in the unlocked run (to 1e-5 rad: the held joints move by the zero-order hold there), and at the start the brakes' torque equals
    the torque the unlocked controller applies to the held joints."""
    moving = {"joint_positions": {"arm2_joint1": 90.0}, "joint_velocities": {"arm1_joint1": 20.0}}
    full = runner.simulate(quiet_scene(tmp_path, task=ONE_ARM_TASK, initial=moving, simulation={"duration": 0.05})).telemetry
    locked = runner.simulate(quiet_scene(tmp_path, task=ONE_ARM_TASK, initial=moving,
                                   simulation={"duration": 0.05, "lock": "auto"})).telemetry
    assert np.abs(locked.joint_positions - full.joint_positions).max() < 1e-5
    assert np.abs(full.joint_positions[:, 4:] - full.joint_positions[0, 4:]).max() > 0.0  # the unlocked run moves them
    assert np.abs(full.tau[0, 4:]).max() > 1e-3
    assert np.abs(locked.tau[0] - full.tau[0]).max() < 1e-9 * np.abs(full.tau[0]).max()


def test_locked_free_floating_robot_conserves_its_momentum(tmp_path):
    """A tumbling free-base robot with two arms braked keeps its nonzero momentum to round-off."""
    tumbling = quiet_scene(tmp_path, "tumbling", robot={"locked_joints": ["arm2_ee", "arm3_joint2"]},
                     initial={"joint_positions": {"arm2_joint1": 30.0}, "joint_velocities": {"arm1_joint1": 20.0}},
                     simulation={"duration": 0.2})
    outcome = runner.simulate(tumbling)
    momentum = outcome.telemetry.momentum
    assert np.abs(momentum[0]).max() > 0.1
    assert np.abs(momentum - momentum[0]).max() < 1e-11
    assert np.abs(outcome.telemetry.joint_positions[:, 4:8] - np.radians([30.0, 0.0, 0.0, 0.0])).max() == 0.0


def test_locking_is_refused_in_a_detumbling_scene(tmp_path):
    """A detumbling scene's controller moves every joint, so ``robot.locked_joints`` is refused there."""
    bad = quiet_scene(tmp_path, "detumble_impulse_arm1_joint4", robot={"locked_joints": ["arm2_joint1"]})
    with pytest.raises(SceneError, match="joint-space and torque-free scenes only; this is a detumbling scene"):
        runner.prepare(bad)


def test_holding_torque_with_a_wrench_keeps_the_locked_joint_still_in_the_full_model(tmp_path):
    """Under an external wrench, the recorded brake torque applied to the full robot with the same wrench
    gives the locked joint zero acceleration."""
    import pinocchio as pin

    from freefloat.dynamics.wrenches import ExternalWrench, WrenchProfiles

    pushed = quiet_scene(tmp_path, "tumbling", robot={"locked_joints": ["arm2_joint2"]}, simulation={"duration": 0.02})
    wrench = ExternalWrench("arm2_link4", force=(3.0, -2.0, 0.0), torque=(0.0, 0.0, 1.5))
    setup = runner.prepare(pushed)
    setup.wrenches = (wrench,)
    tel = experiment_for_scene(pushed).run(setup).telemetry
    robot, k = setup.robot, 10
    field = WrenchProfiles(robot, (wrench,))
    field.activate(float(tel.t[k]))
    tau = np.zeros(robot.model.nv)
    tau[robot.n_base:] = tel.tau[k]
    a = pin.aba(robot.model, robot.model.createData(), tel.q[k], tel.v[k], tau, field.forces(tel.q[k]))
    locked = setup.lock.locked_v
    assert abs(tel.tau[k, locked - robot.n_base]).max() > 1e-3
    assert np.abs(a[locked]).max() < 1e-9 * np.abs(a).max()


def test_checkpointed_chunks_of_a_locked_run_have_every_joint(tmp_path):
    """Each telemetry chunk handed to the checkpoint (what a killed run leaves) is the full robot's."""
    chunks = []
    locked = quiet_scene(tmp_path, task=ONE_ARM_TASK, simulation={"duration": 0.05, "lock": "auto"})
    runner.simulate(locked, checkpoint=chunks.append)
    assert chunks and all(c.q.shape[1] == 20 and c.tau.shape[1] == 16 for c in chunks)
    assert sum(len(c.t) for c in chunks) == 51
