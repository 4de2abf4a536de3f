"""Nested RMS (eq 140) and rotation angles."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics.metrics import momentum_drift, nested_rms, rotation_angle, settling_time

from .conftest import REPO


def test_nested_rms_layers_joint_arm_overall():
    """Per joint over time, per arm over joints, then over arms: an analytic case."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    errors = np.zeros((4, 16))
    errors[:, 0] = [1.0, -1.0, 1.0, -1.0]  # arm 1 joint 1: rms 1
    errors[:, 4:8] = 2.0  # arm 2: every joint rms 2
    overall, per_arm = nested_rms(errors, robot)
    assert per_arm == {"arm1_ee": 0.5, "arm2_ee": 2.0, "arm3_ee": 0.0, "arm4_ee": 0.0}
    assert overall == np.sqrt((0.25 + 4.0) / 4.0)


def test_rotation_angle_is_accurate_for_tiny_angles():
    """A 1e-12 rad rotation is measured as 1e-12 rad (arccos would give 0)."""
    q0 = pin.Quaternion(pin.exp3(np.array([0.3, -0.2, 0.1])))
    q1 = q0 * pin.Quaternion(pin.exp3(np.array([0.0, 0.0, 1e-12])))
    angle = rotation_angle(np.array([q1.coeffs()]), q0.coeffs())
    np.testing.assert_allclose(angle, [1e-12], rtol=1e-6)


def test_com_drift_discounts_the_motion_momentum_demands():
    """A CoM moving uniformly with the initial momentum has zero drift; a kink shows up."""
    from freefloat.dynamics.metrics import free_com_motion
    from freefloat.dynamics.telemetry import Telemetry

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    tel = Telemetry.allocate(11, robot.model.nq, robot.model.nv, robot.n_joints, 4)
    tel.t[:] = np.linspace(0.0, 1.0, 11)
    tel.momentum[:, :3] = [42.0, 0.0, -84.0]  # 42 kg robot: CoM velocity (1, 0, -2) m/s
    tel.com[:] = np.outer(tel.t, [1.0, 0.0, -2.0])
    np.testing.assert_allclose(free_com_motion(tel, robot), tel.com, atol=1e-14)
    tel.com[5:, 1] += 1e-3
    assert np.abs(tel.com - free_com_motion(tel, robot)).max() == pytest.approx(1e-3)


def test_momentum_drift_is_the_larger_vector_norm_change():
    """An analytic case: P changes by (3, 4, 0) (norm 5) at sample 1, L by (0, 0, 2) at sample 2."""
    momentum = np.zeros((3, 6))
    momentum[1, :3] = [3.0, 4.0, 0.0]
    momentum[2, 5] = 2.0
    assert momentum_drift(momentum + 7.0) == 5.0


@pytest.mark.parametrize("signal, expected", [
    ([5.0, 2.0, 0.5, 0.2, 0.1], 2.0),    # below 1 from t = 2 on
    ([5.0, 0.5, 3.0, 0.2, 0.1], 3.0),    # dips below, rises again: settles at the last crossing
    ([0.5, 0.2, 0.1, 0.1, 0.1], 0.0),    # below from the start
    ([5.0, 0.5, 0.2, 0.1, 4.0], None),   # above at the end: not settled
])
def test_settling_time_is_the_last_crossing_below_the_threshold(signal, expected):
    """Analytic cases on t = 0..4 s with threshold 1."""
    assert settling_time(np.arange(5.0), np.array(signal), 1.0) == expected


def test_band_settling_time_of_an_exponential_decay():
    """x = 0.5 + exp(-t) over 10 s: it stays within 2 % of its largest change from the final value
    from t = -ln(0.02 (1 - e^-10) + e^-10) ~ ln 50 s on (to the 1e-4 s sampling)."""
    from freefloat.dynamics.metrics import band_settling_time

    t = np.linspace(0.0, 10.0, 100_001)
    expected = -np.log(0.02 * (1.0 - np.exp(-10.0)) + np.exp(-10.0))
    assert band_settling_time(t, 0.5 + np.exp(-t)) == pytest.approx(expected, abs=1e-4)
    assert band_settling_time(t, np.full_like(t, 3.0)) == 0.0  # a constant rate is settled from the start


def test_spin_summary_of_a_body_spun_up_then_stopped():
    """A base turning at 2 rad/s about z that stops linearly from t = 1 to 2 s: peak 2, final 0,
    within 2 % of 2 rad/s after t = 1.98 s (the next 10 ms sample); the end-effectors turn with it."""
    from freefloat.dynamics.metrics import spin_summary
    from freefloat.dynamics.telemetry import Telemetry

    robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", base="planar", visuals=False)
    t = np.linspace(0.0, 3.0, 301)
    rate = 2.0 * np.clip(2.0 - t, 0.0, 1.0)
    tel = Telemetry.allocate(len(t), robot.model.nq, robot.model.nv, robot.n_joints, 2)
    tel.t[:], tel.base_twist[:, 5] = t, rate
    tel.q[:] = robot.neutral()
    tel.v[:, 2] = rate  # planar base: [vx, vy, wz] in the base frame
    s = spin_summary(robot, tel)
    assert s["base_angular_velocity_max"] == 2.0 and s["base_angular_velocity_final"] == 0.0
    assert s["base_angular_velocity_settling_time"] == pytest.approx(1.99)
    assert s["end_effector_angular_velocity_max"] == {"arm1_ee": pytest.approx(2.0), "arm2_ee": pytest.approx(2.0)}


def test_planar_drift_counts_only_what_the_planar_joint_conserves():
    """On a planar base, a torque-free run's Lx, Ly (changed by the planar joint's reaction
    torques) are no drift: momentum_drift_max is at round-off while the six-component change is not."""
    from freefloat.dynamics.integrators import make_integrator
    from freefloat.dynamics.metrics import conservation, momentum_drift
    from freefloat.dynamics.models import ExactModel
    from freefloat.dynamics.simulation import run

    from .conftest import torque_free

    robot, _, q0, v0 = torque_free("planar", seed=3, speed=1.0)
    tel = run(robot, q0, v0, 0.5, 0.005, make_integrator("rkmk4", robot.model, substeps=4), ExactModel(robot)).telemetry
    assert momentum_drift(tel.momentum) > 1e-3  # Lx, Ly do change
    assert conservation(tel, robot)["momentum_drift_max"] < 1e-8
