"""Public alias of :mod:`freefloat.dynamics.models` (``freefloat.models.make_model`` and friends)."""

from .dynamics.models import *  # noqa: F403
from .dynamics.models import __all__  # noqa: F401
