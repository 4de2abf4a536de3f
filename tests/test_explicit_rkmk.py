"""RKMK6 and RKMK8: their orders on the free-flyer and planar bases, momentum kept to that order."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.app.runner import prepare
from freefloat.app.scenes import DEFAULT_SCENE, load_scene
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.simulation import run as simulate
from freefloat.robot.conventions import momentum_about_origin

from .conftest import CONSERVED, scene_variant, torque_free


@pytest.fixture(scope="module", params=["free", "planar"])
def tumbling(request):
    """A torque-free SC_3DoF tumbling on the given base, with a tight dopri5 reference after 1 s."""
    robot, f, q0, v0 = torque_free(request.param, seed=0, speed=1.0)
    reference = make_integrator("dopri5", robot.model, rtol=1e-13, atol=1e-14).advance(f, q0, v0, 1.0)
    return robot, f, q0, v0, reference


def run(tumbling, substeps: int, name: str = "rkmk6") -> tuple[np.ndarray, np.ndarray]:
    robot, f, q0, v0, _ = tumbling
    return make_integrator(name, robot.model, substeps=substeps).advance(f, q0, v0, 1.0)


def test_rkmk6_is_sixth_order(tumbling):
    """Halving the RKMK6 step divides the final-state error by ~64 (45-90: not 32, not 128)."""
    robot, _, _, _, (q_ref, v_ref) = tumbling
    e = []
    for n in (20, 40):
        q, v = run(tumbling, n)
        e.append(np.linalg.norm(np.concatenate((pin.difference(robot.model, q_ref, q), v - v_ref))))
    assert 45.0 < e[0] / e[1] < 90.0


def test_rkmk6_keeps_momentum_to_sixth_order(tumbling):
    """The conserved momentum components drift by ~64x less when the step halves."""
    robot, _, q0, v0, _ = tumbling
    data = robot.model.createData()
    rows = CONSERVED[robot.base]
    start = momentum_about_origin(robot.model, data, q0, v0)[rows]
    drift = [np.linalg.norm(momentum_about_origin(robot.model, data, *run(tumbling, n))[rows] - start) for n in (20, 40)]
    assert 45.0 < drift[0] / drift[1] < 90.0


#: Step counts (per 1 s) where the RKMK8 error is asymptotic and well above the reference's floor.
RKMK8_STEPS = {"free": (20, 40), "planar": (10, 20)}


def test_rkmk8_is_eighth_order(tumbling):
    """Halving the RKMK8 step divides the final-state error by ~256 (180-360: not 128, not 512)."""
    robot, _, _, _, (q_ref, v_ref) = tumbling
    e = []
    for n in RKMK8_STEPS[robot.base]:
        q, v = run(tumbling, n, "rkmk8")
        e.append(np.linalg.norm(np.concatenate((pin.difference(robot.model, q_ref, q), v - v_ref))))
    assert 180.0 < e[0] / e[1] < 360.0


def test_rkmk6_counts_seven_evaluations_per_step(tumbling):
    """Each RKMK6 step calls the acceleration seven times."""
    robot, f, q0, v0, _ = tumbling
    integrator = make_integrator("rkmk6", robot.model, substeps=3)
    integrator.advance(f, q0, v0, 0.01)
    assert integrator.evaluations() == 21


def test_a_scene_selects_rkmk6(tmp_path):
    """A scene naming rkmk6 steps its loop with it: 7 evaluations per substep."""
    scene = load_scene(scene_variant(tmp_path / "s.toml", DEFAULT_SCENE,
                                     simulation={"integrator": "rkmk6", "substeps": 2, "duration": 0.005},
                                     output={"figures": False, "html": False}))
    p = prepare(scene)
    dt = scene.simulation.control_period
    result = simulate(p.robot, p.q0, p.v0, 5 * dt, dt, p.integrator, p.model, p.controller)
    assert p.integrator.name == "rkmk6" and result.evaluations == 7 * 2 * 5
