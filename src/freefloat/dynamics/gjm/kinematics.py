"""Hand-built forward kinematics of the bodies, vectorised over the tree (dissertation sec 3.1).

Computed from the model's static joint placements, axes and body inertias only (no Pinocchio
kinematics or dynamics algorithm at run time). Bodies are Pinocchio's: body 0 is the base (the
floating root joint's body, fixed-joint children merged), body b >= 1 is moved by actuated joint
b. Every quantity is in the inertial frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ...errors import RobotModelError
from ...robot.conventions import base_link_placement
from ...robot.joints import JointCoordinates
from ...robot.robot import Robot


@dataclass(frozen=True)
class TreeStructure:
    """Static description of the tree, extracted once per robot.

    Attributes:
        parent: parent body of each actuated body (n,), 0 = base.
        levels: actuated body indices grouped by depth, shallowest first.
        placement: joint placements in their parent body frames, homogeneous (n, 4, 4).
        axis: joint axis in its own frame (n, 3), unit.
        axis_skew: ``[axis]x`` (n, 3, 3), for Rodrigues' formula.
        axis_skew_sq: ``[axis]x^2`` (n, 3, 3).
        revolute: True for revolute joints, False for prismatic (n,).
        mass: body masses (n + 1,), base first.
        com: body CoMs in the body frame (n + 1, 3); base CoM in the base-LINK frame.
        inertia: body rotational inertias about their CoM, body frame (n + 1, 3, 3).
        ancestor: ``ancestor[b, j]`` is True when joint j moves body b (n + 1, n); joint j moves
            its own body.
    """

    parent: np.ndarray
    levels: tuple[np.ndarray, ...]
    placement: np.ndarray
    axis: np.ndarray
    axis_skew: np.ndarray
    axis_skew_sq: np.ndarray
    revolute: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    ancestor: np.ndarray

    @classmethod
    def of(cls, robot: Robot) -> TreeStructure:
        """Read the structure of ``robot``'s model (joint 1 floating, joints 2.. 1-DOF)."""
        model = robot.model
        data = model.createData()
        pin.computeJointJacobians(model, data, pin.neutral(model))
        n = model.njoints - 2
        parent, axis, revolute = np.zeros(n, dtype=int), np.zeros((n, 3)), np.zeros(n, dtype=bool)
        for b in range(1, n + 1):
            j = b + 1
            if model.nvs[j] != 1:
                raise RobotModelError(f"joint '{model.names[j]}': the GJM needs 1-DOF joints, it has {model.nvs[j]}")
            S = np.asarray(data.joints[j].S).reshape(6)
            revolute[b - 1] = np.linalg.norm(S[3:]) > 0.5
            axis[b - 1] = S[3:] if revolute[b - 1] else S[:3]
            parent[b - 1] = model.parents[j] - 1
        depth = np.zeros(n + 1, dtype=int)
        for b in range(1, n + 1):
            depth[b] = depth[parent[b - 1]] + 1
        ancestor = np.zeros((n + 1, n), dtype=bool)
        for b in range(1, n + 1):
            ancestor[b] = ancestor[parent[b - 1]]
            ancestor[b, b - 1] = True
        inertias = [model.inertias[j] for j in range(1, model.njoints)]
        K = np.zeros((n, 3, 3))
        K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
        return cls(
            parent=parent,
            levels=tuple(np.flatnonzero(depth[1:] == d) for d in range(1, depth.max() + 1)),
            placement=np.array([model.jointPlacements[j].homogeneous for j in range(2, model.njoints)]).reshape(n, 4, 4),
            axis=axis,
            axis_skew=K - K.transpose(0, 2, 1),
            axis_skew_sq=(K - K.transpose(0, 2, 1)) @ (K - K.transpose(0, 2, 1)),
            revolute=revolute,
            mass=np.array([I.mass for I in inertias]),
            com=np.array([I.lever for I in inertias]),
            inertia=np.array([I.inertia for I in inertias]),
            ancestor=ancestor,
        )


class BodyKinematics(NamedTuple):
    """Positions and orientations of every body at one configuration, inertial frame (a named
    tuple: the compiled core builds one per call, and a tuple costs a quarter of a dataclass).

    Attributes:
        r0: base reference point (base-link CoM), m (3,).
        R0: base CoM frame orientation (3, 3).
        rotation: body frame orientations (n + 1, 3, 3), base first.
        origin: body frame origins (n + 1, 3); the base's is the base-LINK frame origin.
        joint_position: joint origins p_j (n, 3).
        joint_axis: joint axes k_j (n, 3).
        com: body CoMs r_i (n + 1, 3).
        inertia: body inertias about their CoM, inertial axes (n + 1, 3, 3).
    """

    r0: np.ndarray
    R0: np.ndarray
    rotation: np.ndarray
    origin: np.ndarray
    joint_position: np.ndarray
    joint_axis: np.ndarray
    com: np.ndarray
    inertia: np.ndarray


def forward_kinematics(robot: Robot, tree: TreeStructure, coords: JointCoordinates, q: np.ndarray) -> BodyKinematics:
    """Body poses at configuration q (nq,): joint motions by Rodrigues' formula, then one batched
    4x4 product per tree level, from the base outwards."""
    n = len(tree.parent)
    theta = coords.get(q)
    angle = np.where(tree.revolute, theta, 0.0)[:, None, None]
    motion = np.zeros((n, 4, 4))
    motion[:, :3, :3] = np.eye(3) + np.sin(angle) * tree.axis_skew + (1.0 - np.cos(angle)) * tree.axis_skew_sq
    motion[:, :3, 3] = np.where(tree.revolute[:, None], 0.0, tree.axis * theta[:, None])
    motion[:, 3, 3] = 1.0
    local = tree.placement @ motion
    base = base_link_placement(robot, q)
    pose = np.empty((n + 1, 4, 4))
    pose[0] = base.homogeneous
    for level in tree.levels:
        pose[level + 1] = pose[tree.parent[level]] @ local[level]
    rotation, origin = pose[:, :3, :3], pose[:, :3, 3]
    return BodyKinematics(
        r0=base.act(robot.base_com),
        R0=base.rotation @ robot.base_com_rotation,
        rotation=rotation,
        origin=origin,
        joint_position=origin[1:],
        joint_axis=(rotation[1:] @ tree.axis[:, :, None])[:, :, 0],
        com=origin + (rotation @ tree.com[:, :, None])[:, :, 0],
        inertia=rotation @ tree.inertia @ rotation.transpose(0, 2, 1),
    )
