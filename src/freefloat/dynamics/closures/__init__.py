"""Loop closures on any Pinocchio tree, fixed or floating base: kinds (:data:`KINDS`: point,
revolute, weld), their rows (:mod:`.closure`), the constrained dynamics (:mod:`.constrained`)
and the impulse that closes loops at an instant (:mod:`.impulse`)."""

from __future__ import annotations

from .closure import Closure, ClosureRows, FrameMotion, evaluate, frame_motion, kinematics, stacked
from .constrained import ClosedModel, ConstrainedSolution, closure_drift, delassus_solve, solve
from .impulse import ClosingImpulse, closing_impulse
from .kinds import ALIASES, KINDS, ClosureKind, closure_kind

__all__ = [
    "ALIASES",
    "KINDS",
    "ClosedModel",
    "ClosingImpulse",
    "Closure",
    "ClosureKind",
    "ClosureRows",
    "ConstrainedSolution",
    "FrameMotion",
    "closing_impulse",
    "closure_drift",
    "closure_kind",
    "delassus_solve",
    "evaluate",
    "frame_motion",
    "kinematics",
    "solve",
    "stacked",
]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
