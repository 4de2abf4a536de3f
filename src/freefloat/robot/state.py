"""Checks of a robot state (Pinocchio q, v) handed to freefloat's public functions."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..arguments import bounded, reals
from ..errors import InvalidArgument
from .robot import Robot

#: How far the unit-norm blocks of q (base quaternion, planar and continuous-joint (cos, sin))
#: may be from norm 1.
UNIT_TOLERANCE = 1e-6


def check_state(robot: Robot, q: np.ndarray, v: np.ndarray | None = None) -> None:
    """Check a configuration ``q`` (nq,) and velocity ``v`` (nv,) in Pinocchio's convention.

    Raises:
        InvalidArgument: naming ``q`` or ``v`` when it is not real numbers, the size is wrong, a
            value is not finite or above :data:`~freefloat.arguments.MAX_MAGNITUDE`, or
            a unit-norm block (the free-flyer quaternion [qx, qy, qz, qw], the planar base's and
            continuous joints' (cos, sin)) is not of norm 1.
    """
    model = robot.model
    q = reals("q", q)
    if q.shape != (model.nq,):
        raise InvalidArgument(f"q must have shape ({model.nq},) for '{robot.urdf_path.name}', got {q.shape}")
    if not np.isfinite(q).all():
        raise InvalidArgument(f"q has non-finite entries at {np.flatnonzero(~np.isfinite(q)).tolist()}")
    bounded("q", q)
    if not pin.isNormalized(model, q, UNIT_TOLERANCE):
        raise InvalidArgument(
            "q's unit-norm blocks (base quaternion [qx, qy, qz, qw] or (cos, sin) pairs) are off norm 1 "
            f"(a zero quaternion is no rotation); q[:7] = {np.array2string(q[:7], precision=4)}; normalise them "
            "(pinocchio.normalize) or build q with freefloat.robot.conventions.state_from_base"
        )
    if v is None:
        return
    v = reals("v", v)
    if v.shape != (model.nv,):
        raise InvalidArgument(f"v must have shape ({model.nv},) for '{robot.urdf_path.name}', got {v.shape}")
    if not np.isfinite(v).all():
        raise InvalidArgument(f"v has non-finite entries at {np.flatnonzero(~np.isfinite(v)).tolist()}")
    bounded("v", v)
