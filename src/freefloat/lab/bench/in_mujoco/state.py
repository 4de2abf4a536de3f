"""Pinocchio's free-flyer state against MuJoCo's (for a model written by :mod:`.mjcf`).

Pinocchio: ``q = [p; quat (x, y, z, w); joints]``, ``v = [v_local; w_local; joint rates]`` with
``v_local`` the velocity of the base-frame origin in the base frame. MuJoCo's free joint:
``qpos = [p; quat (w, x, y, z); joints]``, ``qvel = [R v_local; w_local; joint rates]`` (linear
velocity of the body origin in the world frame, angular velocity in the body frame). Both order the
joints depth-first, as :mod:`.mjcf` writes them.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def _rotation(q: np.ndarray) -> np.ndarray:
    return pin.Quaternion(q[6], q[3], q[4], q[5]).normalized().toRotationMatrix()


def to_mujoco(q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(qpos, qvel)`` of the Pinocchio state ``(q, v)`` (shapes (nq,), (nv,) on both sides)."""
    qpos = np.concatenate([q[:3], [q[6]], q[3:6], q[7:]])
    qvel = np.concatenate([_rotation(q) @ v[:3], v[3:]])
    return qpos, qvel


def from_mujoco(qpos: np.ndarray, qvel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio ``(q, v)`` of MuJoCo's ``(qpos, qvel)``; inverse of :func:`to_mujoco`."""
    q = np.concatenate([qpos[:3], qpos[4:7], [qpos[3]], qpos[7:]])
    v = np.concatenate([_rotation(q).T @ qvel[:3], qvel[3:]])
    return q, v


def velocity_map(q: np.ndarray, nv: int) -> np.ndarray:
    """``S`` (nv, nv) with ``v = S qvel``: MuJoCo's mass matrix is ``S^T M S`` for Pinocchio's M."""
    s = np.eye(nv)
    s[:3, :3] = _rotation(q).T
    return s
