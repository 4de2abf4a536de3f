"""Actuated joint positions as plain numbers (angles in rad, displacements in m).

Pinocchio stores a continuous (unbounded revolute) joint as ``[cos, sin]`` in ``q``; everything
user-facing in freefloat (references, errors, telemetry) uses one number per actuated velocity
coordinate instead, in Pinocchio's joint order.
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin

from ..errors import RobotModelError
from .robot import Robot

#: Pinocchio's sliding joints by ``JointModel.shortname()``: a URDF prismatic joint along x, y or
#: z loads as P{X,Y,Z}, along another axis as PrismaticUnaligned.
SLIDING = frozenset({"JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"})


def slides(joint: pin.JointModel) -> bool:
    """Whether ``joint`` is prismatic: its coordinate a displacement (m), its effort a force (N)."""
    return joint.shortname() in SLIDING


@functools.lru_cache(maxsize=16)
def prismatic_columns(robot: Robot) -> np.ndarray:
    """Whether each joint velocity coordinate (Pinocchio joints 2..) slides (n_joints,) bool,
    read-only; kept for the last robots (a robot hashes by identity and its joints do not
    change): a scene's tables ask five times per run, and reading the joints costs 0.2 ms at
    nv 134."""
    model = robot.model
    idx_vs, nvs = list(model.idx_vs), list(model.nvs)  # each attribute read copies the whole vector
    mask = np.zeros(robot.n_joints, dtype=bool)
    for j, joint in enumerate(model.joints):
        if j >= 2 and slides(joint):
            start = idx_vs[j] - robot.n_base
            mask[start:start + nvs[j]] = True
    mask.flags.writeable = False
    return mask


class JointCoordinates:
    """Reads and writes actuated joint positions in a Pinocchio configuration.

    Args:
        robot: the robot whose joints (Pinocchio joints 2..) are mapped.

    Attributes:
        scalar_q, scalar_pos: q indices of the one-number joints and their position indices.
        circle_q, circle_pos: q index of the cos of each continuous joint and its position index.
    """

    def __init__(self, robot: Robot):
        model = robot.model
        idx_qs, idx_vs, nqs, nvs = list(model.idx_qs), list(model.idx_vs), list(model.nqs), list(model.nvs)  # a read
        scalar_q, scalar_pos, circle_q, circle_pos = [], [], [], []  # of model.idx_qs copies it: once, not per joint
        for j in range(2, model.njoints):
            iq, iv = idx_qs[j], idx_vs[j] - robot.n_base
            nq, nv = nqs[j], nvs[j]
            if nq == nv:
                scalar_q.extend(range(iq, iq + nq))
                scalar_pos.extend(range(iv, iv + nv))
            elif (nq, nv) == (2, 1):
                circle_q.append(iq)
                circle_pos.append(iv)
            else:
                raise RobotModelError(f"joint '{model.names[j]}': nq={nq}, nv={nv} is not supported")
        self.n = robot.n_joints
        nbq = nqs[1]
        self._plain = not circle_q and scalar_q == list(range(nbq, model.nq))
        self._slice = slice(nbq, model.nq)
        self.scalar_q = np.array(scalar_q, dtype=int)
        self.scalar_pos = np.array(scalar_pos, dtype=int)
        self.circle_q = np.array(circle_q, dtype=int)
        self.circle_pos = np.array(circle_pos, dtype=int)

    def get(self, q: np.ndarray) -> np.ndarray:
        """Actuated joint positions (n_joints,) from a configuration q (nq,)."""
        if self._plain:
            return q[self._slice].copy()
        out = np.empty(self.n)
        out[self.scalar_pos] = q[self.scalar_q]
        out[self.circle_pos] = np.arctan2(q[self.circle_q + 1], q[self.circle_q])
        return out

    def set(self, q: np.ndarray, positions: np.ndarray) -> None:
        """Write actuated joint positions (n_joints,) into q (nq,) in place."""
        q[self.scalar_q] = positions[self.scalar_pos]
        q[self.circle_q] = np.cos(positions[self.circle_pos])
        q[self.circle_q + 1] = np.sin(positions[self.circle_pos])
