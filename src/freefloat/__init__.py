"""freefloat: dynamics, simulation and control of free-floating multi-arm space robots, on Pinocchio."""

from .errors import FreefloatError, RobotModelError, SceneError, SimulationDiverged
from .robot.loading import load_robot
from .robot.robot import Arm, Robot

__version__ = "0.1.0"

__all__ = [
    "Arm", "FreefloatError", "Robot", "RobotModelError", "SceneError", "SimulationDiverged",
    "load_robot", "__version__",
]
