"""Base attitude as the dissertation's Euler angles (eqs 9-11), against the quaternion/Lie group.

Eq 9 composes ``R0 = R_phi R_theta R_psi`` with ``R_phi`` about z, ``R_theta`` about y and
``R_psi`` about x, i.e. ``R0 = Rz(phi) Ry(theta) Rx(psi)`` for ``Gamma0 = [phi, theta, psi]``.
(As printed, ``R_theta`` has ``-sin(theta)`` in both off-diagonal entries and is not a rotation;
the proper ``Ry`` is used here.) Differentiating gives the inertial angular velocity

.. math::
    \\omega_0 = R_E(\\Gamma_0) \\dot\\Gamma_0, \\quad R_E = \\begin{bmatrix}
    0 & -\\sin\\phi & \\cos\\phi\\cos\\theta \\\\ 0 & \\cos\\phi & \\sin\\phi\\cos\\theta \\\\
    1 & 0 & -\\sin\\theta \\end{bmatrix},

singular at ``theta = +-90 deg`` (``det R_E = -cos theta``). Eq 11 as printed,
``[[1, 0, -sin t], [0, cos t, cos t sin p], [0, -sin t, cos p cos t]]``, lists the rows in the
order (z, y, x) and has ``cos theta`` and ``-sin theta`` where ``cos phi`` and ``-sin phi`` belong.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin


def rotation_zyx(angles: np.ndarray) -> np.ndarray:
    """``Rz(phi) Ry(theta) Rx(psi)`` for ``angles = [phi, theta, psi]`` (3, 3)."""
    phi, theta, psi = angles
    return pin.rpy.rpyToMatrix(psi, theta, phi)


def euler_rate_matrix(angles: np.ndarray, printed: bool = False) -> np.ndarray:
    """``R_E`` with ``omega0 = R_E Gammadot`` (inertial frame, rows x, y, z) (3, 3); ``printed``
    gives eq 11 exactly as printed instead."""
    phi, theta, _ = angles
    sp, cp, st, ct = np.sin(phi), np.cos(phi), np.sin(theta), np.cos(theta)
    if printed:
        return np.array([[1.0, 0.0, -st], [0.0, ct, ct * sp], [0.0, -st, cp * ct]])
    return np.array([[0.0, -sp, cp * ct], [0.0, cp, sp * ct], [1.0, 0.0, -st]])


def integrate_euler_angles(omega: Callable[[float], np.ndarray], angles0: np.ndarray, duration: float,
                           step: float) -> tuple[np.ndarray, np.ndarray]:
    """RK4 on ``Gammadot = R_E^-1 omega0(t)``: times (N,) and angles (N, 3).

    Near ``theta = +-90 deg`` ``R_E`` is singular: the solve returns whatever the numbers give
    (huge rates, NaN), which is what the comparison is meant to show.
    """
    def rate(t: float, angles: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            try:
                return np.linalg.solve(euler_rate_matrix(angles), omega(t))
            except np.linalg.LinAlgError:
                return np.full(3, np.nan)

    steps = int(round(duration / step))
    times, out = np.arange(steps + 1) * step, np.empty((steps + 1, 3))
    out[0] = angles0
    for k in range(steps):
        t, y = times[k], out[k]
        k1 = rate(t, y)
        k2 = rate(t + step / 2, y + step / 2 * k1)
        k3 = rate(t + step / 2, y + step / 2 * k2)
        k4 = rate(t + step, y + step * k3)
        out[k + 1] = y + step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return times, out


def integrate_rotation(omega: Callable[[float], np.ndarray], R0: np.ndarray, duration: float,
                       step: float) -> np.ndarray:
    """Lie-group (RKMK4 on SO(3), world-frame omega) rotations (N, 3, 3): no singularity."""
    steps = int(round(duration / step))
    out = np.empty((steps + 1, 3, 3))
    out[0] = R0
    for k in range(steps):
        t, h = k * step, step
        w1, w2, w4 = omega(t), omega(t + h / 2), omega(t + h)
        # For world-frame omega, R(t+h) = exp(theta) R(t); RKMK4 with dexp^-1 to second order.
        k1 = w1
        k2 = w2 - 0.5 * np.cross(0.5 * h * k1, w2)
        k3 = w2 - 0.5 * np.cross(0.5 * h * k2, w2)
        k4 = w4 - 0.5 * np.cross(h * k3, w4)
        theta = h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out[k + 1] = pin.exp3(theta) @ out[k]
    return out


def rotation_error(R: np.ndarray, R_ref: np.ndarray) -> np.ndarray:
    """Angle of ``R_ref^T R`` (rad), row by row for stacks (N, 3, 3) -> (N,)."""
    return np.array([np.linalg.norm(pin.log3(a.T @ b)) if np.all(np.isfinite(b)) else np.nan
                     for a, b in zip(R_ref, R)])
