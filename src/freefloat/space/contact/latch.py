"""The latch of a capture by contact: once the hand has touched the target for a set time with
their relative speed at the contact point below a set speed, the existing weld closes (the exact
impulse of :func:`~freefloat.dynamics.closures.closing_impulse` on the hand's weld to the target,
:func:`~freefloat.space.dual_capture.grasp_welds`), which stops the remaining relative motion and
keeps robot + target momentum. The hold is checked at the end of each control period, where the
engine calls its ``stop``."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...dynamics.closures import ClosingImpulse, closing_impulse
from ...errors import InvalidArgument
from ..dual_capture import grasp_welds
from .field import ContactField


@dataclass(frozen=True)
class Latch:
    """When the weld closes.

    Attributes:
        hold_time: how long the shapes must have touched, every period end of it below ``speed``, s.
        speed: the largest relative speed at the contact point, m/s.
    """

    hold_time: float = 0.05
    speed: float = 0.01

    def __post_init__(self) -> None:
        for name, value in (("hold_time", self.hold_time), ("speed", self.speed)):
            if not (math.isfinite(value) and value > 0.0):
                raise InvalidArgument(f"latch: {name} must be a positive number, got {value!r}")


class LatchWatch:
    """``stop(t, q, v)`` for the engine's run: True at the first period end at which the field's
    shapes have touched at ``latch.speed`` or slower at every period end of the last
    ``latch.hold_time`` s (one watch per run: it keeps the time the hold began).

    Attributes:
        closed_at: the time it fired, s, or None.
    """

    def __init__(self, field: ContactField, latch: Latch):
        self.field, self.latch = field, latch
        self.since: float | None = None
        self.closed_at: float | None = None

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> bool:
        near, velocity = self.field.nearest(q, v)
        if near.depth <= 0.0 or float(np.linalg.norm(velocity)) >= self.latch.speed:
            self.since = None
            return False
        self.since = t if self.since is None else self.since
        if t - self.since >= self.latch.hold_time * (1.0 - 1e-9):
            self.closed_at = t
            return True
        return False


def close_weld(model: pin.Model, hand: str, q: np.ndarray, v: np.ndarray) -> ClosingImpulse:
    """The weld of frame ``hand`` to the target (joint ``target`` of ``model``, as
    :func:`~.target.with_free_target` builds it) closed at ``(q, v)`` by the exact impulse: the
    velocities after (nv,), the impulse (6,) and the relative twist it removed."""
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    return closing_impulse(model, data, q, v, grasp_welds(model, data, (hand,)))
