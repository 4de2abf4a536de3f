"""freefloat: dynamics, simulation and control of free-floating multi-arm space robots and of
closed-chain parallel mechanisms, on Pinocchio.

The public API, from one place::

    from freefloat import load_robot, run, ComputedTorque, five_bar, PlatformControl, simulate

One call runs a scene (:func:`simulate`: a built-in name, a scene file or a ``Scene``; a folder
written only when ``out`` is given), one runs the engine (:func:`run`: a robot or a plant, an
integrator, a model, a controller), and both return a :class:`Result` (summary, telemetry,
status, message, folder). Names are imported when first used (``import freefloat`` stays
cheap), and so are the subpackages, reachable as attributes (``freefloat.gjm.compute``,
``freefloat.dynamics``, ``freefloat.space``, ``freefloat.parallel``, ``freefloat.robot``,
``freefloat.app``), which hold the rest (layers: robot < dynamics < space | parallel < app, see
docs/architecture.md).
"""

from __future__ import annotations

from .errors import (
    BadShape,
    ClosureFileError,
    DataFileError,
    FreefloatError,
    FreefloatNote,
    FreefloatWarning,
    InfeasiblePlan,
    InvalidArgument,
    MissingExtra,
    NotAssembled,
    PluginError,
    RobotModelError,
    RunFolderError,
    SceneError,
    SimulationDiverged,
    SingularityError,
    TargetMissed,
    TelemetryFileError,
    UnknownName,
)
from .lazy import lazy_exports

__version__ = "0.1.0"

#: Public name -> the module that defines it (imported on first use).
_PUBLIC = {
    # robot
    "load_robot": "freefloat.robot.loading", "Robot": "freefloat.robot.robot", "Arm": "freefloat.robot.robot",
    # the GJM layer (also the module freefloat.gjm) and its check against Pinocchio
    "check_robot": "freefloat.dynamics.verify",
    # dynamics models, integrators, plants, the loop
    "MODELS": "freefloat.dynamics.models", "make_model": "freefloat.dynamics.models",
    "INTEGRATORS": "freefloat.dynamics.integrators", "make_integrator": "freefloat.dynamics.integrators",
    "PLANTS": "freefloat.dynamics.plants", "CoupledChainPlant": "freefloat.dynamics.plants",
    "ConstraintDynamicsPlant": "freefloat.dynamics.plants",
    "run": "freefloat.dynamics.simulation", "Result": "freefloat.dynamics.result", "Sampled": "freefloat.dynamics.sampled",
    "Telemetry": "freefloat.dynamics.telemetry", "PlantTelemetry": "freefloat.dynamics.telemetry",
    "MechanismTelemetry": "freefloat.dynamics.telemetry",
    # space-robot controllers and tasks
    "ComputedTorque": "freefloat.space.control", "QuinticTrajectory": "freefloat.space.control",
    "TaskSpaceComputedTorque": "freefloat.space.control.task_space",
    "DetumblingController": "freefloat.space.control.detumbling_control",
    # closed-chain mechanisms and their control
    "ParallelMechanism": "freefloat.parallel.mechanism", "five_bar": "freefloat.parallel.five_bar",
    "load_rsu_ppap": "freefloat.parallel.rsu_ppap", "load_closed_chain": "freefloat.parallel.closed_chain",
    "MECHANISMS": ("freefloat.parallel.registry", "REGISTRY"), "PlatformControl": "freefloat.parallel.sliding_mode",
    "design_gains": "freefloat.parallel.sliding_mode",
    # scenes, runs, bench
    "load_scene": "freefloat.app.scenes", "find_scene": "freefloat.app.scenes",
    "simulate": "freefloat.app.runner",
    # extension points: a user's controller, environment or experiment kind, registered by name
    "CONTROLLERS": "freefloat.app.controllers", "ControllerSpec": "freefloat.app.controllers",
    "ControlContext": "freefloat.app.controllers", "Rules": "freefloat.app.scenes.fields",
    "ENVIRONMENTS": "freefloat.app.environments", "EnvironmentSpec": "freefloat.app.environments",
    "EXPERIMENTS": "freefloat.app.experiments", "Experiment": "freefloat.app.experiments",
    "WrenchField": "freefloat.dynamics.wrenches", "ExternalWrench": "freefloat.dynamics.wrenches",
    "use": "freefloat.registry",
}


__getattr__ = lazy_exports(__name__, _PUBLIC, globals())


def __dir__() -> list[str]:
    import pkgutil  # the subpackages and modules too (reachable as attributes), without importing them

    return sorted([*__all__, *(m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_"))])


#: The error and warning types, defined in freefloat.errors (every one is exported).
_ERRORS = ("BadShape", "ClosureFileError", "DataFileError", "FreefloatError", "FreefloatNote", "FreefloatWarning",
           "InfeasiblePlan", "InvalidArgument", "MissingExtra", "NotAssembled", "PluginError", "RobotModelError",
           "RunFolderError", "SceneError", "SimulationDiverged", "SingularityError", "TargetMissed",
           "TelemetryFileError", "UnknownName")

__all__ = sorted([*_PUBLIC, *_ERRORS, "__version__"])
