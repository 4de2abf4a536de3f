"""``freefloat bench``: speed against accuracy, measured side by side in one process.

``suites`` (``freefloat bench --suite NAME``: one registry of the benchmarks, each a module of
measurements in parts, and ``options``: what the command asks of every suite); ``race`` (the
default suite, freefloat's integrators against MuJoCo's, work against precision: what a scene is,
the sweep, the accuracy bands, the chart and the output folder) over ``scenes`` (its scenes,
one registry) with ``in_mujoco`` (the robot, its state, its wrenches and a closed chain in
MuJoCo's terms); ``command`` (the command's arguments and run). MuJoCo is an optional extra
(``pip install -e ".[bench]"``); only the MuJoCo runs import it.
"""

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
