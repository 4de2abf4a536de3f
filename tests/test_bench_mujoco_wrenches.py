"""External wrenches written as MuJoCo's ``xfrc_applied`` are the generalized forces Pinocchio
gets from the same wrenches (force at the link's CoM, inertial frame)."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.wrenches import ExternalWrench, WrenchProfiles
from freefloat.lab.bench.in_mujoco.mjcf import mjcf_from_model
from freefloat.lab.bench.in_mujoco.state import to_mujoco, velocity_map
from freefloat.lab.bench.in_mujoco.wrenches import MujocoWrenches
from freefloat.lab.bench.scenes.detumbling import detumbling_scene


@pytest.fixture(scope="module")
def scene():
    """The detumbling bench scene (balanced two-arm robot on a free base)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return detumbling_scene(0.05)


def _mujoco_generalized_force(scene, wrenches, q, v) -> np.ndarray:
    """``M (qacc(xfrc) - qacc(0))``: the generalized force (MuJoCo's coordinates) of the wrenches."""
    model = mujoco.MjModel.from_xml_string(mjcf_from_model(scene.model))
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = to_mujoco(q, v)
    mujoco.mj_forward(model, data)
    free = data.qacc.copy()
    MujocoWrenches(scene.robot, wrenches, lambda name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)).apply(
        0.0, q, data.xfrc_applied)
    mujoco.mj_forward(model, data)
    M = np.empty((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    return M @ (data.qacc - free)


@pytest.mark.parametrize("link", ["arm1_link4", "arm1_ee", "base_link"])
def test_xfrc_applied_is_pinocchios_generalized_force(scene, link):
    """A random force and torque on a link (arm1_ee: its CoM 0.25 m from its MuJoCo body's) at a
    random state: MuJoCo's generalized force equals ``S^T J^T f`` from Pinocchio
    (``-rnea(q, 0, 0, fext)`` without gravity) to 1e-9 relative."""
    rng = np.random.default_rng(4)
    model = scene.model
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    v = rng.normal(size=model.nv)
    wrench = ExternalWrench(link, tuple(rng.normal(size=3) * 10.0), tuple(rng.normal(size=3)))
    field = WrenchProfiles(scene.robot, [wrench])
    field.activate(0.0)
    zero_gravity = model.copy()
    zero_gravity.gravity.setZero()
    tau = -pin.rnea(zero_gravity, zero_gravity.createData(), q, np.zeros(model.nv), np.zeros(model.nv),
                    field.forces(q))
    expected = velocity_map(q, model.nv).T @ tau
    assert np.abs(expected).max() > 1.0
    np.testing.assert_allclose(_mujoco_generalized_force(scene, (wrench,), q, v), expected,
                               rtol=1e-9, atol=1e-9 * np.abs(expected).max())
