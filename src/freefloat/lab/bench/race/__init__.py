"""The race against MuJoCo (the ``mujoco`` suite, ``freefloat bench``'s default): ``scene`` (what
a scene of the race is), ``sweep`` (wall time and errors per method), ``summary`` (the cheapest
method per accuracy band), ``chart`` (work against precision) and ``report`` (the output folder)."""

from ....lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
