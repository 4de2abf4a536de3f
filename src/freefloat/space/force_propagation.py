"""External wrenches on end-effectors mapped to joint torques, three ways plus the exact answer
(dissertation sec 3.6, eqs 98-105).

The question answered: which joint torques ``tau_eq`` act on the joints like the wrenches do,
i.e. give the same joint accelerations with the base free. Wrenches ``F_i = [f_i; n_i]`` act at
end-effector frame origins, inertial frame.

- ``fixed_base``: ``Jm^T F``, the fixed-base Jacobian transpose (eq 103).
- ``generalized``: ``J*^T F``, the generalized Jacobian transpose (eq 98).
- ``newton_euler``: the multi-arm Newton-Euler propagation of sec 3.6 with the joints locked:
  the whole robot accelerates as one rigid body under F (eq 104, with the gyroscopic
  ``w x I w`` of the structure turning at the base angular velocity), every body's inertial
  wrench follows, and each joint carries the wrench of the bodies beyond it (eq 105); the joint
  torque that keeps it locked is ``-tau_eq``.
- ``exact``: Pinocchio's ABA with and without the wrenches, ``tau_eq = H* (qddot_F - qddot_0)``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..dynamics import gjm
from ..dynamics.models.exact import joint_space_dynamics
from ..errors import did_you_mean
from ..robot.robot import Robot


def stacked_wrench(robot: Robot, wrenches: dict[str, np.ndarray]) -> np.ndarray:
    """``[f_1; n_1; ...; f_k; n_k]`` (6k,) in ``robot.end_effectors`` order; missing ones are zero.

    Raises:
        ValueError: naming an end-effector that does not exist.
    """
    F = np.zeros(6 * len(robot.end_effectors))
    for name, wrench in wrenches.items():
        if name not in robot.end_effectors:
            raise ValueError(f"no end-effector '{name}'{did_you_mean(name, robot.end_effectors, 'end-effectors')}")
        i = robot.end_effectors.index(name)
        F[6 * i:6 * i + 6] = wrench
    return F


def exact_equivalent_torques(robot: Robot, q: np.ndarray, v: np.ndarray, wrenches: dict[str, np.ndarray]) -> np.ndarray:
    """``H* (qddot_F - qddot_0)`` from Pinocchio's ABA (n,)."""
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, q)
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    for name, wrench in wrenches.items():
        frame = model.frames[model.getFrameId(name)]
        joint = data.oMi[frame.parentJoint]
        origin = data.oMf[model.getFrameId(name)].translation
        world = pin.Force(np.asarray(wrench[:3]), np.asarray(wrench[3:]) + np.cross(origin, wrench[:3]))
        fext[frame.parentJoint] += joint.actInv(world)
    tau = np.zeros(model.nv)
    nb = robot.n_base
    a_F = pin.aba(model, data, q, v, tau, fext)
    a_0 = pin.aba(model, data, q, v, tau)
    H_star, _ = joint_space_dynamics(robot, data, q, v)
    return H_star @ (a_F[nb:] - a_0[nb:])


def newton_euler_equivalent_torques(robot: Robot, q: np.ndarray, v: np.ndarray, wrenches: dict[str, np.ndarray]) -> np.ndarray:
    """Sec 3.6: locked joints, rigid-body response, inward wrench balance per joint (n,)."""
    model_gjm = gjm.model_of(robot)
    s = model_gjm.compute(q, v)
    tree, kin = model_gjm.tree, s.kinematics
    m, com, inertia = tree.mass, kin.com, kin.inertia
    total = m.sum()
    c = m @ com / total
    lever = com - c
    I_eq = inertia.sum(axis=0) + (m @ (lever * lever).sum(axis=1)) * np.eye(3) - (m[:, None] * lever).T @ lever
    F = stacked_wrench(robot, wrenches).reshape(-1, 6)
    force = F[:, :3].sum(axis=0)
    torque = (F[:, 3:] + np.cross(s.ee_position - c, F[:, :3])).sum(axis=0)
    w = s.x0dot[3:]
    alpha = np.linalg.solve(I_eq, torque - np.cross(w, I_eq @ w))   # eq 104
    acc = force / total + np.cross(alpha, lever) + np.cross(w, np.cross(w, lever))
    inertial_f = m[:, None] * acc                                     # (n + 1, 3)
    inertial_n = inertia @ alpha + np.cross(w, inertia @ w)
    tau = np.zeros(robot.n_joints)
    ee_body = model_gjm.ee_body
    for j in range(robot.n_joints):
        beyond = tree.ancestor[:, j]
        p, k = kin.joint_position[j], kin.joint_axis[j]
        f = inertial_f[beyond].sum(axis=0)
        n = (inertial_n[beyond] + np.cross(com[beyond] - p, inertial_f[beyond])).sum(axis=0)
        carried = tree.ancestor[ee_body, j]
        f -= F[carried, :3].sum(axis=0)
        n -= (F[carried, 3:] + np.cross(s.ee_position[carried] - p, F[carried, :3])).sum(axis=0)
        locked = k @ n if tree.revolute[j] else k @ f                   # eq 105
        tau[j] = -locked
    return tau


def equivalent_torques(robot: Robot, q: np.ndarray, v: np.ndarray, wrenches: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """All four mappings of ``wrenches`` (end-effector name -> [f; n], inertial) to joint torques (n,)."""
    s = gjm.compute(robot, q, v)
    F = stacked_wrench(robot, wrenches)
    return {
        "fixed_base": s.Jm.T @ F,
        "generalized": s.Jstar.T @ F,
        "newton_euler": newton_euler_equivalent_torques(robot, q, v, wrenches),
        "exact": exact_equivalent_torques(robot, q, v, wrenches),
    }
