"""Pinocchio's free-flyer state against MuJoCo's: a round trip, and MuJoCo's own momentum and
energy at the mapped state equal Pinocchio's."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from freefloat.lab.bench.in_mujoco.mjcf import mjcf_from_model
from freefloat.lab.bench.in_mujoco.state import from_mujoco, to_mujoco
from freefloat.lab.bench.scenes.tumbling import tumbling_scene
from freefloat.robot.conventions import momentum_about_origin


@pytest.fixture(scope="module", params=["dual_arm", "four_arm"])
def scene(request):
    """A bench scene (four-arm: its balanced copy)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return tumbling_scene(request.param)


def test_round_trip_restores_the_state(scene):
    """from_mujoco(to_mujoco(q, v)) gives back (q, v)."""
    q, v = from_mujoco(*to_mujoco(scene.q0, scene.v0))
    np.testing.assert_allclose(q, scene.q0, atol=1e-15)
    np.testing.assert_allclose(v, scene.v0, atol=1e-15)


def test_mujoco_momentum_and_energy_at_the_mapped_state_equal_pinocchio(scene):
    """Zero steps: MuJoCo's subtree momentum about the origin and its kinetic energy at the mapped
    initial state equal Pinocchio's (non-zero) momentum and energy to 1e-12 relative."""
    mj = mujoco.MjModel.from_xml_string(mjcf_from_model(scene.model))
    data = mujoco.MjData(mj)
    data.qpos[:], data.qvel[:] = to_mujoco(scene.q0, scene.v0)
    mujoco.mj_forward(mj, data)
    mujoco.mj_subtreeVel(mj, data)
    mass, com = mj.body_subtreemass[0], data.subtree_com[0]
    linear = mass * data.subtree_linvel[0]
    angular = data.subtree_angmom[0] + np.array([com[1] * linear[2] - com[2] * linear[1],
                                                 com[2] * linear[0] - com[0] * linear[2],
                                                 com[0] * linear[1] - com[1] * linear[0]])
    pdata = scene.model.createData()
    h = momentum_about_origin(scene.model, pdata, scene.q0, scene.v0)
    assert np.linalg.norm(h) > 1e-3
    np.testing.assert_allclose(np.concatenate([linear, angular]), h, rtol=0, atol=1e-12 * np.linalg.norm(h))
    energy = pin.computeKineticEnergy(scene.model, pdata, scene.q0, scene.v0)
    assert abs(data.energy[1] - energy) <= 1e-12 * energy
