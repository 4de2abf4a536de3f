"""A constant wrench field of your own, registered into freefloat.ENVIRONMENTS from outside the
package.

A scene names this file (``plugins = ["constant_wrench.py"]``) and adds the field as
``[[environment]] kind = "constant_wrench"`` with the keys ``link``, ``force`` and ``torque``;
the Python loop evaluates it at every integrator stage (it has no compiled twin) and the run's
summary balances the momentum and energy against what it applied::

    freefloat simulate examples/constant_wrench.toml

The field pushes ``link`` at its CoM with a force ``F`` and a torque ``n``, both fixed in the
inertial frame, so the system's linear momentum grows by exactly ``F t``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from freefloat import ENVIRONMENTS, EnvironmentSpec, InvalidArgument


@dataclass(frozen=True)
class ConstantWrenchSettings:
    """``[[environment]]`` keys of kind ``"constant_wrench"``: the ``link`` (URDF name), the
    ``force`` (N) and ``torque`` (N m), inertial frame, applied at the link's CoM."""

    link: str
    force: tuple[float, float, float] = (0.0, 0.0, 0.0)
    torque: tuple[float, float, float] = (0.0, 0.0, 0.0)


class ConstantWrench:
    """A :class:`freefloat.WrenchField`: a constant inertial wrench on one link's CoM."""

    def __init__(self, robot, settings: ConstantWrenchSettings):
        model = robot.model
        if not model.existBodyName(settings.link):
            raise InvalidArgument(f"constant_wrench: no link '{settings.link}'")
        frame = model.frames[model.getFrameId(settings.link, pin.FrameType.BODY)]
        self.model, self.data, self.joint = model, model.createData(), frame.parentJoint
        self.com = frame.placement.act(robot.link_coms[settings.link])  # in the joint frame, m
        self.force, self.torque = np.array(settings.force, float), np.array(settings.torque, float)

    def forces(self, t: float, q: np.ndarray, v: np.ndarray) -> list:
        """The wrench in the link's joint frame, moment about the joint origin (njoints forces)."""
        pin.forwardKinematics(self.model, self.data, q)
        rotation = self.data.oMi[self.joint].rotation
        force = rotation.T @ self.force
        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        out[self.joint] = pin.Force(force, rotation.T @ self.torque + np.cross(self.com, force))
        return out

    def wrench(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``[F; r x F + n]`` about the inertial origin, inertial frame (6,)."""
        pin.forwardKinematics(self.model, self.data, q)
        r = self.data.oMi[self.joint].act(self.com)
        return np.concatenate((self.force, np.cross(r, self.force) + self.torque))


ENVIRONMENTS.register(EnvironmentSpec("constant_wrench", "a constant inertial wrench on a link's CoM",
                                      ConstantWrenchSettings, ConstantWrench))
