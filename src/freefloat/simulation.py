"""Public alias of :mod:`freefloat.dynamics.simulation` (``freefloat.simulation.run`` and friends)."""

from .dynamics.simulation import *  # noqa: F403
from .dynamics.simulation import __all__  # noqa: F401
