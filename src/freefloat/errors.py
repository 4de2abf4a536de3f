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


class TelemetryFileError(FreefloatError):
    """A telemetry file (``.npz``) that is missing, damaged or of another kind; the message names
    the file and what is wrong with it."""
