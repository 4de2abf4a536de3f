"""Conversions between Pinocchio's state and the dissertation's base conventions.

Pinocchio (free-flyer root): ``q = [p; quat]`` is the pose of the base-LINK frame, ``v_b = [v; w]``
the twist of that frame expressed in itself (local). A planar root joint has ``q = [x, y, cos, sin]``
and ``v_b = [vx, vy, wz]`` in the same local sense; it is embedded here as the 6-vector
``[vx, vy, 0, 0, 0, wz]``.

Dissertation (sec 3.1.2) and SPART: the base reference point is the base CoM ``r0`` (inertial
frame), and the base twist is ``x0dot = [v0; w0]``: velocity of the base CoM and angular velocity,
both in the inertial frame. With ``R`` the base-link orientation and ``c`` the base CoM in the
base-link frame:

.. math::
    v_0 = R (v + w \\times c), \\qquad w_0 = R w.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import InvalidArgument
from .robot import Robot

PLANAR_ROWS = np.array([0, 1, 5])  # rows of a 6-D local twist that a planar joint moves


def skew(x: np.ndarray) -> np.ndarray:
    """Cross-product matrix: ``skew(x) @ y == cross3(x, y)`` (shape (3, 3))."""
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` for two 3-vectors (3,); several times faster than ``np.cross`` at this size."""
    ax, ay, az = a.tolist()
    bx, by, bz = b.tolist()
    return np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])


def cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` along the last axis of two broadcastable (..., 3) arrays.

    Same result as ``np.cross(a, b)``; written out because ``np.cross`` spends most of its time
    moving axes when the arrays are small, as in the per-link loops of a serial chain.
    """
    a1, a2, a3 = a[..., 0], a[..., 1], a[..., 2]
    b1, b2, b3 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack((a2 * b3 - a3 * b2, a3 * b1 - a1 * b3, a1 * b2 - a2 * b1), axis=-1)


def twist_map(rotation: np.ndarray, com: np.ndarray) -> np.ndarray:
    """Map ``T`` with ``x0dot = T @ v_b`` (shape (6, 6)).

    Args:
        rotation: base-link orientation R, base-link frame to inertial (3, 3).
        com: base CoM c in the base-link frame, m (3,).
    """
    T = np.zeros((6, 6))
    T[:3, :3] = rotation
    T[:3, 3:] = -rotation @ skew(com)
    T[3:, 3:] = rotation
    return T


def local_to_inertial_twist(rotation: np.ndarray, com: np.ndarray, v_local: np.ndarray) -> np.ndarray:
    """Base twist ``x0dot = [v0; w0]`` (base CoM, inertial) from the base-link local twist (6,)."""
    w = v_local[3:]
    return np.concatenate((rotation @ (v_local[:3] + cross3(w, com)), rotation @ w))


def inertial_to_local_twist(rotation: np.ndarray, com: np.ndarray, x0dot: np.ndarray) -> np.ndarray:
    """Base-link local twist [v; w] (6,) from ``x0dot = [v0; w0]`` (base CoM, inertial)."""
    w = rotation.T @ x0dot[3:]
    return np.concatenate((rotation.T @ x0dot[:3] - cross3(w, com), w))


def momentum_about_origin(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``[P; L about the inertial origin]`` (6,), inertial frame, kg m/s and kg m^2/s.

    From Pinocchio's centroidal momentum; leaves the forward kinematics and ``data.com[0]`` (the
    system CoM, inertial frame) at (q, v) in ``data``.
    """
    hg = pin.computeCentroidalMomentum(model, data, q, v)
    return pin.SE3(np.eye(3), data.com[0]).act(hg).vector


def base_link_placement(robot: Robot, q: np.ndarray) -> pin.SE3:
    """Pose of the base-link frame in the inertial frame."""
    if robot.base == "free":
        return pin.XYZQUATToSE3(q[:7])
    c, s = q[2], q[3]
    return pin.SE3(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), np.array([q[0], q[1], 0.0]))


def base_local_twist(robot: Robot, v: np.ndarray) -> np.ndarray:
    """Base-link twist [v; w] in its own frame (6,), planar bases embedded."""
    if robot.base == "free":
        return v[:6].copy()
    out = np.zeros(6)
    out[PLANAR_ROWS] = v[:3]
    return out


def base_acceleration(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Base acceleration ``x0ddot = [dv0/dt; dw0/dt]`` of the base CoM, inertial frame (6,).

    From Pinocchio's ``a`` (nv,), whose base part is the time derivative of the local base-link
    twist components: with ``u = v + w x c``,

    .. math:: \\dot v_0 = R (\\dot v + \\dot w \\times c + w \\times u), \\qquad \\dot w_0 = R \\dot w.
    """
    R = base_link_placement(robot, q).rotation
    vel, acc = base_local_twist(robot, v), base_local_twist(robot, a)
    w, c = vel[3:], robot.base_com
    u = vel[:3] + cross3(w, c)
    return np.concatenate((R @ (acc[:3] + cross3(acc[3:], c) + cross3(w, u)), R @ acc[3:]))


def local_base_acceleration(robot: Robot, q: np.ndarray, v: np.ndarray, x0ddot: np.ndarray) -> np.ndarray:
    """Pinocchio's base acceleration (n_base,) from ``x0ddot`` (6,): the inverse of
    :func:`base_acceleration` (``dw = R^T dw0``, ``dv = R^T dv0 - dw x c - w x u``)."""
    R = base_link_placement(robot, q).rotation
    vel = base_local_twist(robot, v)
    w, c = vel[3:], robot.base_com
    dw = R.T @ x0ddot[3:]
    local = np.concatenate((R.T @ x0ddot[:3] - cross3(dw, c) - cross3(w, vel[:3] + cross3(w, c)), dw))
    return local if robot.base == "free" else local[PLANAR_ROWS]


def base_state(robot: Robot, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The dissertation's base state from Pinocchio's.

    Returns:
        ``(r0, R0, x0dot)``: base CoM position (3,) and base CoM frame orientation (3, 3) in the
        inertial frame, and the base twist [v0; w0] of the base CoM, inertial frame (6,).
    """
    link = base_link_placement(robot, q)
    com_frame = link.rotation @ robot.base_com_rotation
    r0 = link.translation + link.rotation @ robot.base_com
    x0dot = local_to_inertial_twist(link.rotation, robot.base_com, base_local_twist(robot, v))
    return r0, com_frame, x0dot


def state_from_base(
    robot: Robot,
    r0: np.ndarray,
    rotation0: np.ndarray,
    x0dot: np.ndarray,
    joint_q: np.ndarray,
    joint_v: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio ``(q, v)`` from the dissertation's base state and the joint coordinates.

    Args:
        r0: base CoM position, inertial frame, m (3,).
        rotation0: base CoM frame orientation, inertial frame (3, 3).
        x0dot: base twist [v0; w0] of the base CoM, inertial frame (6,).
        joint_q: Pinocchio configuration of the actuated joints (nq - base nq,).
        joint_v: actuated joint velocities (n_joints,).

    Raises:
        FreefloatError: for a planar base, when the pose or twist leaves the inertial xy-plane.
    """
    link_rotation = rotation0 @ robot.base_com_rotation.T
    link_position = r0 - link_rotation @ robot.base_com
    v_local = inertial_to_local_twist(link_rotation, robot.base_com, np.asarray(x0dot, dtype=float))
    if robot.base == "free":
        q_base = pin.SE3ToXYZQUAT(pin.SE3(link_rotation, link_position))
        v_base = v_local
    else:
        off_plane = np.delete(v_local, PLANAR_ROWS)
        tilt = np.linalg.norm(link_rotation[2] - [0.0, 0.0, 1.0])
        if abs(link_position[2]) > 1e-12 or tilt > 1e-12 or np.abs(off_plane).max() > 1e-12:
            raise InvalidArgument(
                "planar base: the base pose and twist must stay in the inertial xy-plane "
                f"(z offset {link_position[2]:.3g} m, tilt {tilt:.3g}, out-of-plane twist "
                f"{np.abs(off_plane).max():.3g}); load the robot with base='free'"
            )
        q_base = np.array([link_position[0], link_position[1], link_rotation[0, 0], link_rotation[1, 0]])
        v_base = v_local[PLANAR_ROWS]
    return np.concatenate((q_base, joint_q)), np.concatenate((v_base, joint_v))
