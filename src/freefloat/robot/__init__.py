"""The robot layer: a URDF loaded into a Pinocchio model with a floating base, and its conventions.

``loading`` (URDF -> :class:`Robot`, checks, end-effectors, arms, the base CoM frame),
``urdf_model`` (a URDF's links and joints read with the standard library), ``robot``
(:class:`Robot`, :class:`Arm`), ``conventions`` (Pinocchio's base state <-> the dissertation's
base twist [v0; w0] of the base CoM, inertial frame), ``joints`` (actuated joint coordinates <->
Pinocchio q), ``locking`` (joints held still, removed from the model), ``attitude`` (the
dissertation's Euler angles), ``jerk`` (the jerk of bodies, frames and link CoMs by the
composition of motion) and ``builders`` (robots as data -> URDF).

May import: :mod:`freefloat.errors`, :mod:`freefloat.paths`. Nothing above it.
"""

from .loading import BASE_COM_FRAME, load_robot
from .robot import Arm, Robot

__all__ = ["Arm", "BASE_COM_FRAME", "Robot", "load_robot"]
