"""External wrenches of a freefloat scene as MuJoCo's ``xfrc_applied``.

freefloat applies each wrench's force at its link's CoM and gives both parts in the inertial
frame (:class:`freefloat.dynamics.wrenches.ExternalWrench`); MuJoCo's ``xfrc_applied[body]`` is
``[force; torque]`` in the world frame with the force at the body's CoM. The MJCF of :mod:`.mjcf`
has one body per Pinocchio joint (the links it moves merged), so the torque is moved from the
link's CoM to the body's: ``n_body = n + (c_link - c_body) x f``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ....dynamics.wrenches import ExternalWrench, WrenchProfiles
from ....robot.robot import Robot


class MujocoWrenches:
    """Writes a scene's wrenches, held at their values at the start of a control period.

    Args:
        robot: the freefloat robot the MJCF was written from.
        wrenches: its external wrenches.
        body_of: MuJoCo body id of a Pinocchio joint name (``mj_name2id`` of the MJCF body).
    """

    def __init__(self, robot: Robot, wrenches: tuple[ExternalWrench, ...], body_of):
        self.field = WrenchProfiles(robot, wrenches)
        self.model, self.data = robot.model, robot.model.createData()
        self.body_of = body_of

    def apply(self, t: float, q: np.ndarray, xfrc_applied: np.ndarray) -> None:
        """Set ``xfrc_applied`` (nbody, 6) to the wrenches active at ``t`` for Pinocchio's ``q``."""
        xfrc_applied[:] = 0.0
        if not self.field.activate(t):
            return
        pin.forwardKinematics(self.model, self.data, q)
        for joint, com, force, torque in zip(*self.field.active()):
            placement = self.data.oMi[joint]
            lever = placement.rotation @ (com - self.model.inertias[joint].lever)   # c_link - c_body, world axes
            body = self.body_of(self.model.names[joint])
            xfrc_applied[body, :3] += force
            xfrc_applied[body, 3:] += torque + np.cross(lever, force)
