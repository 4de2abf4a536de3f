"""Momentum projection: momentum kept to round-off, the M-nearest correction, bad root joints refused."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.dynamics.integrators import MomentumProjection, make_integrator
from freefloat.robot.conventions import momentum_about_origin

from .conftest import CONSERVED, torque_free


@pytest.fixture(scope="module", params=["free", "planar"])
def tumbling(request):
    """A torque-free SC_3DoF tumbling on the given base: robot, f, q0, v0."""
    return torque_free(request.param, seed=3, speed=2.0)


def drift(robot, integrator, f, q, v, periods: int = 200, dt: float = 0.005) -> float:
    data = robot.model.createData()
    rows = CONSERVED[robot.base]
    start = momentum_about_origin(robot.model, data, q, v)[rows]
    for _ in range(periods):
        q, v = integrator.advance(f, q, v, dt)
    return float(np.abs(momentum_about_origin(robot.model, data, q, v)[rows] - start).max())


def test_projection_keeps_momentum_where_euler_drifts(tumbling):
    """Over 1 s of Euler at 5 ms the conserved momentum drifts > 1e-4; projected, < 1e-12."""
    robot, f, q0, v0 = tumbling
    assert drift(robot, make_integrator("euler", robot.model), f, q0, v0) > 1e-4
    assert drift(robot, make_integrator("euler", robot.model, project_momentum=True), f, q0, v0) < 1e-12


def test_correction_is_mass_orthogonal_to_the_momentum_null_space(tumbling):
    """The velocity change is M-orthogonal to every velocity that carries no momentum."""
    robot, f, q0, v0 = tumbling
    projected = make_integrator("euler", robot.model, project_momentum=True)
    q, v_projected = projected.advance(f, q0, v0, 0.01)
    _, v_plain = make_integrator("euler", robot.model).advance(f, q0, v0, 0.01)
    A = projected.momentum_map(q)
    null = np.linalg.svd(A)[2][A.shape[0]:]  # (nv - r, nv) rows spanning the null space of A
    M = pin.crba(robot.model, robot.model.createData(), q)
    M = np.triu(M) + np.triu(M, 1).T
    dv = v_projected - v_plain
    assert np.linalg.norm(dv) > 1e-8
    np.testing.assert_allclose(null @ M @ dv, 0.0, atol=1e-12)


def test_projection_keeps_rkmk4_fourth_order(tumbling):
    """Projected RKMK4 still divides the final-state error by ~16 when the step halves."""
    robot, f, q0, v0 = tumbling
    q_ref, v_ref = make_integrator("dopri5", robot.model, rtol=1e-13, atol=1e-14).advance(f, q0, v0, 0.5)
    e = []
    for n in (50, 100):
        integrator = make_integrator("rkmk4", robot.model, project_momentum=True)
        q, v = q0, v0
        for _ in range(n):
            q, v = integrator.advance(f, q, v, 0.5 / n)
        e.append(np.linalg.norm(np.concatenate((pin.difference(robot.model, q_ref, q), v - v_ref))))
    assert 12.0 < e[0] / e[1] < 20.0


def test_fixed_base_is_refused_naming_the_root_joint():
    """A model whose root joint is revolute cannot be projected; the error names that joint."""
    model = pin.buildSampleModelManipulator()
    with pytest.raises(ValueError, match=f"planar root joint; joint '{model.names[1]}' is JointModelR"):
        MomentumProjection(make_integrator("euler", model), model)
