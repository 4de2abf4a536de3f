"""freefloat: dynamics, simulation and control of free-floating multi-arm space robots, on Pinocchio."""

import importlib

from .errors import FreefloatError, RobotModelError, SceneError, SimulationDiverged

__version__ = "0.1.0"

__all__ = [
    "Arm", "FreefloatError", "Robot", "RobotModelError", "SceneError", "SimulationDiverged",
    "load_robot", "__version__",
]

#: Public names imported on first use, so that ``import freefloat`` (and the command line's
#: start) loads no heavy library before the command line can take over Ctrl-C.
_LAZY = {"load_robot": ".robot.loading", "Robot": ".robot.robot", "Arm": ".robot.robot"}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'freefloat' has no attribute '{name}'")
