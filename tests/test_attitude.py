"""Euler angles of eqs 9-11 against rotation-matrix derivatives and the analytic rotation."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.robot.attitude import (
    euler_rate_matrix,
    integrate_euler_angles,
    integrate_rotation,
    rotation_error,
    rotation_zyx,
)


def angular_velocity_by_differences(angles, rates, h=1e-6):
    """World-frame omega from central differences of R(Gamma): [w]x = Rdot R^T."""
    Rdot = (rotation_zyx(angles + h * rates) - rotation_zyx(angles - h * rates)) / (2 * h)
    W = Rdot @ rotation_zyx(angles).T
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


def test_corrected_rate_matrix_matches_the_rotation_derivative():
    """omega0 = R_E Gammadot holds for the corrected R_E at random angles and rates."""
    rng = np.random.default_rng(0)
    for _ in range(20):
        angles, rates = rng.uniform(-1.4, 1.4, 3), rng.normal(size=3)
        np.testing.assert_allclose(euler_rate_matrix(angles) @ rates, angular_velocity_by_differences(angles, rates), atol=1e-8)


def test_printed_eq_11_is_wrong_away_from_zero_angles():
    """Eq 11 as printed differs from the rotation derivative by O(1) at generic angles."""
    angles, rates = np.array([0.7, -0.4, 0.3]), np.array([0.2, 1.0, -0.5])
    truth = angular_velocity_by_differences(angles, rates)
    printed_zyx = euler_rate_matrix(angles, printed=True) @ rates  # rows in (z, y, x) order
    assert np.abs(printed_zyx[::-1] - truth).max() > 0.1


@pytest.mark.slow
def test_euler_angles_fail_near_pitch_90_where_the_lie_group_does_not():
    """A spin passing 3e-4 rad from theta = 90 deg: Euler-angle RK4 loses ~1e-3 rad, the Lie group 1e-14."""
    def run(eps):
        w = np.array([eps, 1.0, eps])
        exact = np.array([pin.exp3(w * t) for t in np.arange(3001) * 1e-3])
        _, angles = integrate_euler_angles(lambda t: w, np.zeros(3), 3.0, 1e-3)
        euler = rotation_error(np.array([rotation_zyx(a) for a in angles]), exact)
        lie = rotation_error(integrate_rotation(lambda t: w, np.eye(3), 3.0, 1e-3), exact)
        return np.nanmax(euler), lie.max()

    far_euler, far_lie = run(0.1)      # min |cos theta| = 0.2
    near_euler, near_lie = run(1e-4)   # min |cos theta| = 3e-4
    assert far_euler < 1e-11 and near_euler > 1e-4
    assert max(far_lie, near_lie) < 1e-12
