"""Pinocchio's exact counterparts of the GJM quantities, mapped to the GJM convention.

Pinocchio's CRBA gives ``M`` for ``v = [v_b; qdot]`` (base-LINK twist, local). With
``x0dot = T v_b`` (:func:`freefloat.robot.conventions.twist_map`) the kinetic energy gives

.. math:: H_0 = T^{-T} M_{bb} T^{-1}, \\quad H_{0m} = T^{-T} M_{bq}, \\quad H_m = M_{qq},

and the frame Jacobian ``J = [J_b, J_q]`` (LOCAL_WORLD_ALIGNED) gives ``J0E = J_b T^{-1}``,
``Jm = J_q``. Momenta come from Pinocchio's centroidal momentum, moved from the CoM to the base
CoM and to the origin.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ..errors import InvalidArgument
from ..robot.conventions import base_link_placement, base_state, momentum_about_origin, twist_map
from ..robot.robot import Robot


class ReferenceState(NamedTuple):
    """Pinocchio's values for the fields of :class:`freefloat.gjm.GJMState` of the same name."""

    H0: np.ndarray
    H0m: np.ndarray
    Hm: np.ndarray
    Hstar: np.ndarray
    J0: np.ndarray
    Jm: np.ndarray
    J0E: np.ndarray
    Jstar: np.ndarray
    momentum_base: np.ndarray
    momentum_origin: np.ndarray
    ee_velocity: np.ndarray


def reference(robot: Robot, q: np.ndarray, v: np.ndarray, data: pin.Data | None = None) -> ReferenceState:
    """Exact GJM-convention quantities from CRBA, centroidal momentum and frame Jacobians.

    Raises:
        FreefloatError: for a planar base (its 3 base coordinates cannot give the 6x6 H0).
    """
    if robot.base != "free":
        raise InvalidArgument("the Pinocchio reference of H0 needs a free-flyer base: load with base='free'")
    model = robot.model
    data = data or model.createData()
    nb = robot.n_base
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    link = base_link_placement(robot, q)
    T = twist_map(link.rotation, robot.base_com)  # x0dot = T v_b
    Tinv = np.linalg.inv(T)
    H0 = Tinv.T @ M[:nb, :nb] @ Tinv
    H0m = Tinv.T @ M[:nb, nb:]
    Hm = M[nb:, nb:]
    coupling = np.linalg.solve(M[:nb, :nb], M[:nb, nb:])
    Hstar = Hm - M[nb:, :nb] @ coupling
    J0 = -T @ coupling
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    jac = [pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED) for fid in robot.end_effector_frame_ids]
    J = np.vstack(jac) if jac else np.zeros((0, model.nv))
    Jm = J[:, nb:]
    J0E = J[:, :nb] @ Tinv
    Jstar = Jm - J[:, :nb] @ coupling
    momentum_origin = momentum_about_origin(model, data, q, v)
    P, r0 = momentum_origin[:3], base_state(robot, q, v)[0]
    momentum_base = np.concatenate((P, momentum_origin[3:] - np.cross(r0, P)))
    return ReferenceState(H0, H0m, Hm, Hstar, J0, Jm, J0E, Jstar, momentum_base, momentum_origin, J @ v)
