"""Public alias of :mod:`freefloat.dynamics.gjm` (``freefloat.gjm.compute`` and friends)."""

from .dynamics.gjm import *  # noqa: F403
from .dynamics.gjm import __all__  # noqa: F401
