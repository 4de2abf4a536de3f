"""Controllers a scene names: ``[controller] kind = "..."``, one entry of :data:`CONTROLLERS` per
kind, built-in or a user's.

An entry (:class:`ControllerSpec`) carries what a scene may set (``settings``, a frozen dataclass
whose fields are the ``[controller]`` keys besides ``kind``, checked by the scene schema with the
entry's ``rules``) and how to build the law from a :class:`ControlContext`. The law is any object
with ``torque(t, q, v)`` and ``reference(t)`` (:class:`freefloat.dynamics.simulation.Controller`);
one with ``compiled_law()`` may run in the compiled loop, any other runs in the Python loop, with
the same telemetry and status. A user's module registers its own::

    @dataclass(frozen=True)
    class PDSettings:
        kp: float = 100.0   # 1/s^2 (N m/rad on a unit inertia)
        kd: float = 20.0

    CONTROLLERS.register(ControllerSpec("pd", "joint PD to the task's goal", PDSettings, build_pd))

and a scene names it (``plugins = ["my_pd.py"]``, then ``[controller] kind = "pd"``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ..dynamics.models import MODELS
from ..dynamics.sensors import Sensed, Sensors
from ..errors import InvalidArgument, SceneError
from ..parallel.sliding_mode import PlatformControl, printed_gains
from ..registry import Registry
from ..space.control import ComputedTorque
from ..space.control.detumbling_control import DetumblingController
from ..space.control.thruster_control import ThrusterHold
from ..space.thrusters import ThrusterSet
from .scenes.fields import NO_RULES, Rules, check_settings

#: Plant kinds a controller may serve: robot scenes (``[robot]``) and mechanism scenes (``[mechanism]``).
PLANT_KINDS = ("robot", "mechanism")


class DetumbleTask(NamedTuple):
    """A ``task.kind = "detumble"`` resolved on the plant: end-effector ``rows`` to stop and the
    mission ``joints`` (index arrays of :func:`freefloat.space.detumbling.task_rows` and
    ``joint_indices``), the ``start`` time (s) and the solver ``method``."""

    rows: np.ndarray
    joints: np.ndarray
    start: float
    method: str


@dataclass(frozen=True)
class ControlContext:
    """What a controller is built from.

    Attributes:
        scene: the scene (a :class:`~freefloat.app.scenes.Scene` or ``MechanismScene``).
        plant: what the law acts on: the robot the loop simulates (the reduced robot when joints
            are locked), or a mechanism scene's nominal :class:`~freefloat.parallel.mechanism.ParallelMechanism`.
        reference: the task's reference: a :class:`~freefloat.space.control.QuinticTrajectory`
            over the plant's joints (``task.kind = "joint_quintic"``), a :class:`DetumbleTask`
            (``"detumble"``), the platform reference ``t -> (q#_d, qdot#_d, qddot#_d)`` of a
            mechanism scene, or None (no task).
        control_period: the zero-order-hold period, s.
        angle_scale: factor from the scene's angle unit to rad (1 for mechanism scenes).
        environment: the fields of the scene's ``[[environment]]`` built on the plant (a law that
            commands one, as the thruster laws command the thrusters, finds it here).
        wheels: the plant's reaction wheels (:class:`~freefloat.robot.wheels.Wheels`), or None.
    """

    scene: Any
    plant: Any
    reference: Any
    control_period: float
    angle_scale: float = 1.0
    environment: tuple[Any, ...] = ()
    wheels: Any = None

    @property
    def where(self) -> str:
        """The scene file (or name) for error messages."""
        return f"{self.scene.source}: " if self.scene.source else f"scene '{self.scene.name}': "


@dataclass(frozen=True)
class ControllerSpec:
    """One controller kind.

    Attributes:
        name: the ``[controller] kind`` that names it.
        description: one line for listings.
        settings: a frozen dataclass: its fields are the ``[controller]`` keys besides ``kind``
            (defaults; the docstring gives each key's unit and meaning).
        build: ``build(context, settings) -> controller`` (None: no control, a torque-free run);
            raises :class:`~freefloat.errors.SceneError` naming the key for what the scene got
            wrong.
        plants: the plant kinds it serves (:data:`PLANT_KINDS`).
        tasks: the ``task.kind`` values it serves in a robot scene (empty: any).
        rules: choices and ranges of its settings, keyed ``("controller", key)``.
        variants: the same kind on other plant kinds, with their own settings and builder (a
            robot's and a mechanism's computed torque are one name).
    """

    name: str
    description: str
    settings: type
    build: Callable[[ControlContext, Any], Any]
    plants: tuple[str, ...] = ("robot",)
    tasks: tuple[str, ...] = ()
    rules: Rules = NO_RULES
    variants: tuple[ControllerSpec, ...] = ()

    def __post_init__(self) -> None:
        check_settings("controller", self.name, self.settings)
        unknown = [p for p in self.plants if p not in PLANT_KINDS]
        if unknown or not callable(self.build):
            raise InvalidArgument(f"controller '{self.name}': plants must be among {PLANT_KINDS} and build callable, got "
                                  f"plants {self.plants} and build {self.build!r}")

    def on(self, plant: str) -> ControllerSpec | None:
        """The entry that serves ``plant`` (this one or a variant), or None."""
        return next((s for s in (self, *self.variants) if plant in s.plants), None)


#: Every controller kind by name.
CONTROLLERS: Registry[ControllerSpec] = Registry("controller")


def serving(plant: str) -> dict[str, ControllerSpec]:
    """The controller kinds a scene on ``plant`` may name, with the entry that serves it."""
    return {name: entry for name, spec in CONTROLLERS.items() if (entry := spec.on(plant)) is not None}


def build_controller(context: ControlContext, plant: str = "robot") -> Any:
    """The law the scene's ``[controller]`` names, built on ``context``; with the scene's
    ``[sensors]`` (robot scenes), that law reading them: ``Sensed(law, sensors)``
    (:mod:`freefloat.dynamics.sensors`; with every sensor ideal the run is the law's own).

    Raises:
        SceneError: a robot scene whose ``task.kind`` the controller does not serve, what
            the entry's builder refuses, or a ``[sensors]`` group's ``noise`` or ``bias`` whose
            count is neither 1 nor its components'.
    """
    scene = context.scene
    entry = CONTROLLERS[scene.controller.kind].on(plant)
    task = getattr(scene, "task", None)
    if entry.tasks and task is not None and task.kind not in entry.tasks:
        raise SceneError(f"scene '{scene.name}': controller '{entry.name}' needs task.kind "
                         f"{' or '.join(repr(k) for k in entry.tasks)}")
    law = entry.build(context, scene.controller.settings)
    settings = getattr(scene, "sensors", None)
    if law is None or settings is None:
        return law
    try:
        return Sensed(law, Sensors(context.plant, settings, context.control_period))
    except InvalidArgument as exc:
        raise SceneError(f"{context.where}[sensors] {exc}") from exc


@dataclass(frozen=True)
class JointGains:
    """A robot's computed-torque gains: ``kp`` (1/s^2) and ``kd`` (1/s), scalar (K = k I), the
    dynamics ``model`` the law uses (:data:`freefloat.models.MODELS`); for a two-hand capture, the
    ``squeeze`` between the hands (N) and a ``torque_limit`` per joint (N m; none when absent)."""

    model: str = "exact"
    kp: float = 10.0
    kd: float = 100.0
    squeeze: float = 0.0
    torque_limit: float | None = None


GAIN_RULES = Rules({("controller", "model"): lambda: tuple(MODELS)}, {("controller", "torque_limit")},
                   {("controller", "kp"), ("controller", "kd")})


@dataclass(frozen=True)
class PlatformGains:
    """A mechanism's platform control: lambda ``lam`` (1/s); for sliding mode (eq 153 with eq
    167's gain) ``n`` (p,), ``T`` (p, p), ``n_ij`` keyed ``"i,j"`` (i >= j, 0-based) (p,) and the
    switching function ``saturation`` (``tanh(100 s)`` or ``sign``)."""

    lam: float
    saturation: str = "tanh"
    n: tuple[float, ...] | None = None
    T: tuple[tuple[float, ...], ...] | None = None
    n_ij: dict[str, tuple[float, ...]] = field(default_factory=dict)


PLATFORM_RULES = Rules({("controller", "saturation"): ("tanh", "sign")}, {("controller", "lam")}, set())


def _quintic(context: ControlContext, gains: JointGains) -> Any:
    """Computed torque on the joint quintic (eqs 136-137); on a detumble task, the detumbling law
    (the old spelling ``kind = "computed_torque"`` of ``"detumbling"``)."""
    if isinstance(context.reference, DetumbleTask):
        return _detumbling(context, gains)
    return ComputedTorque(context.plant, context.reference, gains.kp, gains.kd, gains.model)


def _detumbling(context: ControlContext, gains: JointGains) -> DetumblingController:
    """Hold, then detumble the task's rows (dissertation sec 5.3, eqs 115-120, 134)."""
    task = context.reference
    return DetumblingController(context.plant, task.rows, task.joints, task.start, context.control_period, task.method,
                                gains.kp, gains.kd, gains.model)


def _platform(context: ControlContext, gains: PlatformGains) -> PlatformControl:
    """Computed torque in platform coordinates (eq 190)."""
    return PlatformControl(context.plant, context.reference, gains.lam, None, gains.saturation)


def _sliding_mode(context: ControlContext, gains: PlatformGains) -> PlatformControl:
    """Sliding mode in platform coordinates (eq 153 with eq 167's gain).

    Raises:
        SceneError: naming ``controller.n``, ``T`` or ``n_ij`` of the wrong size, or a bad ``n_ij`` key.
    """
    where, mechanism = context.where, context.plant
    p = mechanism.p

    def sized(key: str, value: Any, shape: tuple[int, ...]) -> np.ndarray:
        array = np.asarray(value, float)
        if array.shape != shape:
            raise SceneError(f"{where}'{key}' must have shape {shape} for '{context.scene.mechanism.name}' "
                             f"(p = {p} platform coordinates), got {array.shape}")
        return array

    law = printed_gains(sized("controller.n", gains.n, (p,)), sized("controller.T", gains.T, (p, p)),
                        {_pair(where, key, p): sized(f"controller.n_ij.{key}", v, (p,)) for key, v in gains.n_ij.items()})
    return PlatformControl(mechanism, context.reference, gains.lam, law, gains.saturation)


@dataclass(frozen=True)
class ThrusterGains:
    """Thrusters holding the base pose: ``kp`` (1/s^2) and ``kd`` (1/s), on the attitude and the
    position alike."""

    kp: float = 1.0
    kd: float = 2.0


@dataclass(frozen=True)
class DumpGains(ThrusterGains):
    """Momentum dumping: the hold's ``kp`` (1/s^2) and ``kd`` (1/s), and ``dump_rate`` (1/s), the
    rate at which the wheels' stored momentum is braked."""

    dump_rate: float = 0.5


THRUSTER_RULES = Rules({}, {("controller", "dump_rate")}, {("controller", "kp"), ("controller", "kd")})


def _thrusters(context: ControlContext) -> ThrusterSet:
    """The scene's thrusters.

    Raises:
        SceneError: when the scene has none, more than one set, or a minimum impulse bit that one
            control period cannot give.
    """
    found = [f for f in context.environment if isinstance(f, ThrusterSet)]
    if len(found) != 1:
        raise SceneError(f"{context.where}controller '{context.scene.controller.kind}' commands thrusters: give "
                         f"exactly one [[environment]] kind = \"thrusters\", got {len(found)}")
    try:
        found[0].check_period(context.control_period)
    except InvalidArgument as exc:
        raise SceneError(f"{context.where}{exc}") from exc
    return found[0]


def _thruster_hold(context: ControlContext, gains: ThrusterGains) -> ThrusterHold:
    """Thrusters hold the base pose it starts from (:mod:`freefloat.space.control.thruster_control`)."""
    return ThrusterHold(context.plant, _thrusters(context), context.control_period, gains.kp, gains.kd)


def _momentum_dump(context: ControlContext, gains: DumpGains) -> ThrusterHold:
    """The wheels braked to zero stored momentum while the thrusters hold the base.

    Raises:
        SceneError: without ``[[wheels]]`` or thrusters.
    """
    if context.wheels is None:
        raise SceneError(f"{context.where}controller 'momentum_dump' dumps the momentum of reaction wheels: give "
                         "[[wheels]]")
    return ThrusterHold(context.plant, _thrusters(context), context.control_period, gains.kp, gains.kd,
                        context.wheels, gains.dump_rate)


def _pair(where: str, key: str, p: int) -> tuple[int, int]:
    """``"i,j"`` -> (i, j) with 0 <= j <= i < p.

    Raises:
        SceneError: naming ``controller.n_ij`` and the key.
    """
    try:
        i, j = (int(x) for x in key.split(","))
    except ValueError:
        i = j = -1
    if not 0 <= j <= i < p:
        raise SceneError(f"{where}'controller.n_ij' key '{key}' must be \"i,j\" with 0 <= j <= i < {p}")
    return i, j


CONTROLLERS.register(ControllerSpec(
    "none", "no control: the robot moves torque-free (the gains still set a capture's laws)", JointGains,
    lambda context, gains: None, rules=GAIN_RULES))
CONTROLLERS.register(ControllerSpec(
    "computed_torque", "computed torque on the joint quintic (eqs 136-137), or the detumbling law on a detumble task",
    JointGains, _quintic, tasks=("joint_quintic", "detumble"), rules=GAIN_RULES,
    variants=(ControllerSpec("computed_torque", "computed torque in platform coordinates (eq 190)", PlatformGains,
                             _platform, plants=("mechanism",), rules=PLATFORM_RULES),)))
CONTROLLERS.register(ControllerSpec(
    "detumbling", "hold, then stop end-effector velocity rows with the mission joints (sec 5.3)", JointGains,
    _detumbling, tasks=("detumble",), rules=GAIN_RULES))
CONTROLLERS.register(ControllerSpec(
    "sliding_mode", "sliding mode in platform coordinates (eq 153, eq 167's gains)", PlatformGains, _sliding_mode,
    plants=("mechanism",), rules=PLATFORM_RULES))
CONTROLLERS.register(ControllerSpec(
    "thruster_hold", "thrusters hold the base's attitude and position (PD on the locked robot, NNLS allocation)",
    ThrusterGains, _thruster_hold, tasks=("none",), rules=THRUSTER_RULES))
CONTROLLERS.register(ControllerSpec(
    "momentum_dump", "wheels braked to zero stored momentum while thrusters hold the base and take the momentum out",
    DumpGains, _momentum_dump, tasks=("none",), rules=THRUSTER_RULES))

__all__ = ["CONTROLLERS", "PLANT_KINDS", "ControlContext", "ControllerSpec", "DetumbleTask", "JointGains",
           "DumpGains", "PlatformGains", "ThrusterGains", "build_controller", "serving"]
