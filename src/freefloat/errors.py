"""Exceptions raised by freefloat. Every message names the file, link, joint or key at fault."""


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
    scene, ...); the message lists the valid choices.

    Attributes:
        kind: what was named (e.g. ``"integrator"``).
        name: the name given.
        choices: the valid names.
    """

    def __init__(self, kind: str, name: object, choices):
        self.kind, self.name, self.choices = kind, name, tuple(choices)
        super().__init__(f"unknown {kind} {name!r}; valid: {', '.join(map(str, self.choices))}")

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


class MissingExtra(FreefloatError):
    """A command or call that needs an optional part of freefloat (an extra of pyproject.toml)
    that is not installed; the message names it and the line that installs it."""
