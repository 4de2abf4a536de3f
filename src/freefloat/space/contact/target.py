"""A free target body in the robot's own model, for contact: a second root on scalar joints, so
that the engine's loop (whose telemetry reads one number per joint coordinate) flies it with the
robot. The body hangs from the inertial frame on a 3-D translation joint (``target_translation``,
its CoM's inertial position, m) and a ZYX spherical joint (``target``, the body's yaw, pitch and
roll, rad: Pinocchio's ``JointModelSphericalZYX``): together a free rigid body, exact away from
pitch +-90 deg (the Euler angles' singularity), the robot's base stays joint 1."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument
from ...robot.robot import Robot

#: The target's body frame (its CoM, principal axes) and spherical joint.
TARGET = "target"


def with_free_target(robot: Robot, mass: float, inertia: tuple[float, float, float]) -> Robot:
    """``robot`` with a free body of ``mass`` (kg) and principal moments ``inertia`` (kg m^2) about
    its CoM appended as a second root (module docstring); its coordinates (6,) are the last six of
    ``q`` and ``v``: CoM position and velocity (inertial frame, m and m/s), then the ZYX angles
    and their rates (rad, rad/s). A body frame ``target`` sits at its CoM."""
    if not (mass > 0.0 and min(inertia) > 0.0):
        raise InvalidArgument(f"target: mass {mass!r} kg and inertia {inertia!r} kg m^2 must be positive")
    model = pin.Model(robot.model)
    slide = model.addJoint(0, pin.JointModelTranslation(), pin.SE3.Identity(), f"{TARGET}_translation")
    turn = model.addJoint(slide, pin.JointModelSphericalZYX(), pin.SE3.Identity(), TARGET)
    model.appendBodyToJoint(turn, pin.Inertia(mass, np.zeros(3), np.diag(np.asarray(inertia, float))), pin.SE3.Identity())
    model.addBodyFrame(TARGET, turn, pin.SE3.Identity(), 0)
    return dataclasses.replace(robot, model=model, visual_model=None)


def target_state(position: np.ndarray, velocity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The target's coordinates (6,) and velocities (6,) at CoM ``position`` (m, inertial (3,)) and
    CoM ``velocity`` (m/s, inertial (3,)), not turned and not spinning."""
    return np.concatenate((np.asarray(position, float), np.zeros(3))), np.concatenate((np.asarray(velocity, float), np.zeros(3)))
