"""Exceptions raised by freefloat. Every message names the file, link, joint or key at fault, and
an unknown name the nearest valid ones (:func:`did_you_mean`)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

#: Most valid names an error message lists; the rest are counted.
LISTED = 20
#: How alike (difflib's ratio, 0 to 1) a valid name must be to a mistyped one to be suggested.
CLOSE = 0.6


def few(names: Iterable[str], shown: int = 3) -> str:
    """``names`` joined, the first ``shown`` of them and how many more (a message stays short)."""
    names = list(names)
    rest = len(names) - shown
    return ", ".join(names[:shown]) + (f" and {rest} more" if rest > 0 else "")


def did_you_mean(name: object, choices: Iterable[object], label: str = "valid", full_list: str = "") -> str:
    """What an error about the unknown ``name`` says after naming it: the nearest of ``choices``
    (up to three, by difflib's similarity, case ignored), then the valid names, at most
    :data:`LISTED` of them.

    ``"; did you mean 'rkmk4'? (valid: euler, explicit_euler, ...)"``, or ``"; valid: ..."`` when
    nothing is close.

    Args:
        label: what the list is (``"valid"``, ``"joints"``, ``"built-in"``, ...).
        full_list: where to see every name when the list is cut (``"freefloat scenes"``).
    """
    choices = [str(c) for c in dict.fromkeys(choices)]
    if not choices:
        return f"; there are no {label} names" if label == "valid" else f"; {label}: none"
    typed = difflib.SequenceMatcher(b=str(name).lower())
    likeness = {}
    for choice in choices:
        typed.set_seq1(choice.lower())
        likeness[choice] = typed.ratio()
    close = sorted((c for c in choices if likeness[c] >= CLOSE), key=lambda c: -likeness[c])[:3]  # ties: in order
    listing = few(choices, LISTED)
    if len(choices) > LISTED and full_list:
        listing += f", listed by {full_list}"
    if not close:
        return f"; {label}: {listing}"
    quoted = [f"'{c}'" for c in close]
    nearest = quoted[0] if len(quoted) == 1 else f"{', '.join(quoted[:-1])} or {quoted[-1]}"
    return f"; did you mean {nearest}? ({label}: {listing})"


class FreefloatError(Exception):
    """Base class of every error freefloat raises on purpose."""


class RobotModelError(FreefloatError):
    """A URDF or robot description that cannot be a floating-base tree."""


class SceneError(FreefloatError):
    """A scene file with an unknown key, a wrong type or an impossible value."""


class SimulationDiverged(FreefloatError):
    """The state became non-finite or blew up; the message gives the time and the quantity."""


class SingularityError(FreefloatError):
    """A Jacobian inversion too ill-conditioned to trust; the message gives the condition number
    and the configuration."""


class InvalidArgument(FreefloatError, ValueError):
    """A function argument of the wrong shape, not finite, or out of its domain; the message names
    the argument."""


class UnknownName(InvalidArgument, KeyError):
    """A name not in its registry (integrator, model, controller, mechanism, experiment kind, bench
    scene, ...); the message gives the nearest valid names and lists the valid choices
    (:func:`did_you_mean`).

    Attributes:
        kind: what was named (e.g. ``"integrator"``).
        name: the name given.
        choices: the valid names.
    """

    def __init__(self, kind: str, name: object, choices):
        self.kind, self.name, self.choices = kind, name, tuple(choices)
        super().__init__(f"unknown {kind} {name!r}{did_you_mean(name, self.choices)}")

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0])


class BadShape(InvalidArgument):
    """An array of the wrong shape; the message names the argument, the shape expected and the
    shape given."""


class NotAssembled(FreefloatError):
    """A closed chain that cannot be assembled (loop-closure residual not driven to zero) at the
    pose asked for; the message gives the pose and the residual."""


class InfeasiblePlan(FreefloatError):
    """A motion plan that cannot meet its request (a target out of reach, a limit violated, a
    deadline too short); the message names what fails, where and by how much.

    Attributes:
        reason: what fails, one of :data:`REASONS` (maps count refusals by it).
    """

    #: What can fail: the grasp point out of reach, a joint-rate limit, a torque limit, the optimiser.
    REASONS = ("reach", "joint_rate", "torque", "optimiser")

    def __init__(self, message: str, reason: str):
        super().__init__(message)
        self.reason = reason


class TelemetryFileError(FreefloatError):
    """A telemetry file (``.npz``) that is missing, damaged or of another kind; the message names
    the file and what is wrong with it."""


class FreefloatWarning(UserWarning):
    """Something in a file or a setting was taken with a stated assumption (missing limits, a mesh
    left out, inertias no rigid body has, ...): worth checking."""


class FreefloatNote(FreefloatWarning):
    """A fact about what was loaded that is as intended, stated once so that nothing is silent
    (freefloat's own robots' inertias as the dissertation prints them, the file a robot's name
    picks); the command line prints it as ``freefloat: note: ...``."""


class MissingExtra(FreefloatError):
    """A command or call that needs an optional part of freefloat (an extra of pyproject.toml)
    that is not installed; the message names it and the line that installs it."""
