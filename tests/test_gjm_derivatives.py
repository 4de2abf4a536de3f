"""Analytic time derivatives of the GJM Jacobians and of the E-GJM, against finite differences."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given, settings

from freefloat.dynamics import gjm
from freefloat.space.control.inverse_egjm import InverseEGJM
from freefloat.space.control.task_space import TaskSpaceComputedTorque, pinv_rate

from .conftest import random_robots, random_state, robot_from_case

#: (GJMRates field, function of the GJMState it differentiates)
FIELDS = (
    ("Jm_dot", lambda s: s.Jm),
    ("J0E_dot", lambda s: s.J0E),
    ("H0inv_H0m_dot", lambda s: -s.J0),
    ("J0_dot", lambda s: s.J0),
    ("Jstar_dot", lambda s: s.Jstar),
)


def along(f, robot, q, v, a=None, h: float = 1e-3):
    """Fourth-order central difference of ``f(q(t), v(t))`` at t = 0 along q(t) = q (+) v t,
    v(t) = v + a t (a = 0 when None)."""
    a = np.zeros_like(v) if a is None else a
    values = [f(pin.integrate(robot.model, q, v * t), v + a * t) for t in (-2 * h, -h, h, 2 * h)]
    return (values[0] - 8.0 * values[1] + 8.0 * values[2] - values[3]) / (12.0 * h)


def relative(x: np.ndarray, ref: np.ndarray) -> float:
    """``max |x - ref| / max(1, max |ref|)``."""
    return float(np.abs(x - ref).max() / max(1.0, np.abs(ref).max()))


@pytest.mark.parametrize("base", ["free", "planar"])
@pytest.mark.parametrize("backend", gjm.BACKENDS)
@settings(max_examples=20, deadline=None)
@given(random_robots(max_links=6))
def test_jacobian_rates_match_central_differences(tmp_path_factory, backend, base, case):
    """dJm/dt, dJ0E/dt, d(H0^-1 H0m)/dt, dJ0/dt and dJ*/dt equal differences along q (+) v t to 1e-8."""
    robot, rng = robot_from_case(tmp_path_factory, case, base=base)
    q, v = random_state(robot, rng)
    rates = gjm.jacobian_rates(robot, q, v, backend)
    for field, of in FIELDS:
        fd = along(lambda qt, vt: of(gjm.compute(robot, qt, vt, backend)), robot, q, v)
        assert relative(getattr(rates, field), fd) < 1e-8, field


@settings(max_examples=20, deadline=None)
@given(random_robots(max_links=6))
def test_egjm_drift_rate_matches_a_torque_free_motion(tmp_path_factory, case):
    """d/dt (J0E H0^-1 M), eq 88's momentum term, equals differences along a torque-free motion."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    a = pin.aba(robot.model, robot.model.createData(), q, v, np.zeros(robot.model.nv))
    rates = gjm.jacobian_rates(robot, q, v)
    fd = along(lambda qt, vt: gjm.jacobian_rates(robot, qt, vt).drift, robot, q, v, a)
    assert relative(rates.drift_dot, fd) < 1e-8


@pytest.mark.parametrize("damping", [0.0, 0.1])
def test_pseudo_inverse_rate_matches_differences(damping):
    """d/dt [J^+ e] (plain and damped) equals differences for a wide J(t) and e(t) of full rank."""
    rng = np.random.default_rng(1)
    J0, J1, J2, e0, e1 = rng.normal(size=(3, 3, 5)).tolist() + rng.normal(size=(2, 3)).tolist()
    J = lambda t: np.array(J0) + np.array(J1) * t + np.array(J2) * t**2  # noqa: E731
    e = lambda t: np.array(e0) + np.array(e1) * t                         # noqa: E731
    solve = (lambda A, b: np.linalg.pinv(A) @ b) if damping == 0.0 else \
        (lambda A, b: A.T @ np.linalg.solve(A @ A.T + damping**2 * np.eye(3), b))
    h = 1e-4
    fd = sum(c * solve(J(t), e(t)) for c, t in ((1, -2 * h), (-8, -h), (8, h), (-1, 2 * h))) / (12 * h)
    assert relative(pinv_rate(J(0.0), np.array(J1), damping)(e(0.0), np.array(e1)), fd) < 1e-9


@settings(max_examples=15, deadline=None)
@given(random_robots(min_links=3, max_links=6))
def test_task_space_law_qddot_is_the_derivative_of_eq_138(tmp_path_factory, case):
    """The analytic qddot_d equals differences of eq 138's qdot_d along a torque-free motion, to
    1e-6 plus the differences' own error (estimated from steps h and h / 2: near-singular rows
    make qddot_d large and the differences coarse)."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    state = gjm.compute(robot, q, v)
    rows = np.arange(min(3, robot.n_joints))
    assume(np.linalg.svd(state.Jstar[rows], compute_uv=False)[-1] > 1e-3)  # away from singular rows
    x0, x1 = rng.normal(size=(2, len(rows)))
    inverse = InverseEGJM(rows)
    ctrl = TaskSpaceComputedTorque(robot, inverse, lambda t: x0 + x1 * t, np.zeros(robot.n_joints), 1e-3,
                                   acceleration=lambda t: x1)
    qddot_d = ctrl.reference_joint(0.0, q, v)[2]
    a = pin.aba(robot.model, robot.model.createData(), q, v, np.zeros(robot.model.nv))

    def differences(h: float) -> np.ndarray:
        values = [inverse.joint_rates(gjm.compute(robot, pin.integrate(robot.model, q, v * t), v + a * t), x0 + x1 * t)
                  for t in (-2 * h, -h, h, 2 * h)]
        return (values[0] - 8.0 * values[1] + 8.0 * values[2] - values[3]) / (12.0 * h)

    coarse, fine = differences(1e-3), differences(5e-4)
    assert relative(qddot_d, fine) < 1e-6 + relative(coarse, fine)


@settings(max_examples=20, deadline=None)
@given(random_robots(max_links=6))
def test_jm_rate_equals_pinocchios_frame_jacobian_time_variation(tmp_path_factory, case):
    """dJm/dt equals the joint columns of Pinocchio's LOCAL_WORLD_ALIGNED frame Jacobian time variation."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q, v = random_state(robot, rng)
    model, data = robot.model, robot.model.createData()
    pin.computeJointJacobiansTimeVariation(model, data, q, v)
    pin.updateFramePlacements(model, data)
    ref = np.vstack([pin.getFrameJacobianTimeVariation(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
                     for fid in robot.end_effector_frame_ids])[:, robot.n_base:]
    assert relative(gjm.jacobian_rates(robot, q, v).Jm_dot, ref) < 1e-12
