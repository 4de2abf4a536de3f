"""Scene files: TOML validated against a schema, with errors that name the key.

A scene names the robot, initial state, task, controller, integrator, step and duration. Angles
(joint angles, base attitude, angular rates, task displacements) are in the unit given by the
top-level ``angle_unit`` ("deg" or "rad"); lengths in m, times in s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ...dynamics.closures.kinds import ALIASES, KINDS
from ...dynamics.integrators import INTEGRATORS, check_settings
from ...dynamics.models import MODELS
from ...dynamics.sensors import SensorSettings
from ...dynamics.simulation import BACKENDS
from ...errors import InvalidArgument, SceneError
from ...robot.loading import INERTIAS
from .. import controllers, environments  # registries read when a scene is parsed (they may still be loading now)
from .fields import (
    MAX_HTML_FPS,
    EntrySection,
    OutputSection,
    PluginsFirst,
    Rules,
    at_most,
    choice,
    parse_entry,
    parse_section,
    reject_unknown,
    typed,
    whole_number_of,
)
from .kinds import Kinded, kind_sections, parse_kind_sections
from .sensor_section import parse_sensors


@dataclass(frozen=True)
class RobotSection:
    """``[robot]``: URDF (absolute, relative to the scene file, a built-in robot file name, or the
    name of a robot of :mod:`freefloat.robot.catalog` such as ``"ur5"``),
    floating base kind, end-effector link names (default: leaves), gravity (m/s^2, inertial), and
    the joints held still at their initial positions by brakes (a joint, or an end-effector = every
    joint of its arm; removed from the model, :mod:`freefloat.robot.locking`), and ``inertias``:
    ``"as_given"`` or ``"balanced"`` (a physical copy of inertias that break ``I1 + I2 >= I3``,
    :func:`freefloat.robot.inertias.balanced`)."""

    urdf: str
    base: str = "free"
    end_effectors: tuple[str, ...] | None = None
    gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    locked_joints: tuple[str, ...] | None = None
    inertias: str = "as_given"


@dataclass(frozen=True)
class InitialSection:
    """``[initial]``: base CoM pose and twist (inertial frame, XYZ Euler angles) and joint state
    (tables keyed by joint name; joints not named start at zero)."""

    base_position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    base_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    base_linear_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    base_angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    joint_positions: dict[str, float] = field(default_factory=dict)
    joint_velocities: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class TaskSection:
    """``[task]``: ``kind = "none"``; ``"joint_quintic"``: every joint moves by
    ``displacement[name]`` (key: a joint, or an end-effector meaning all joints of its arm) in
    ``duration`` s; ``"detumble"``: from ``start`` s, stop the end-effector velocity ``rows``
    (``"arm1_ee:wz"``, components vx..wz, angular, linear, all) with ``mission_joints`` (default
    all) by ``method`` (min_norm, single, null_space, least_squares)."""

    kind: str = "none"
    duration: float = 1.0
    displacement: dict[str, float] = field(default_factory=dict)
    rows: tuple[str, ...] | None = None
    mission_joints: tuple[str, ...] | None = None
    method: str = "min_norm"
    start: float = 0.0


@dataclass(frozen=True)
class ClosureSection:
    """``[[closures]]``: a loop closure between two frames of the robot (link or frame names),
    active from the start: ``kind`` ``"point"`` (the origins coincide), ``"revolute"`` (and the z
    axes align: a hinge about the first frame's z) or ``"weld"`` (the frames coincide); see
    :mod:`freefloat.dynamics.closures`. Simulated with Baumgarte rate ``simulation.baumgarte``."""

    frames: tuple[str, ...] | None = None
    kind: str = "point"


@dataclass(frozen=True)
class TargetSection:
    """``[target]``: a rigid target that reaches ``end_effector`` at ``contact_time`` s flying
    freely (velocity, inertial, m/s; spin along a principal axis, in angle_unit per s), is grasped
    by an exact inelastic impulse, then detumbled by the ``[task]``. Mass kg, inertia (principal,
    kg m^2), grasp point in the target frame from its CoM (m), display size (m). With
    ``second_end_effector`` both hands grasp it at once (:mod:`freefloat.space.dual_capture`): its
    grasp point ``second_grasp`` (target frame, m) must meet that hand at ``contact_time`` too
    (default: where the hand is then)."""

    end_effector: str
    mass: float = 10.0
    inertia: tuple[float, float, float] = (1.0, 1.0, 1.0)
    grasp: tuple[float, float, float] = (0.0, 0.0, 0.0)
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_at_contact: tuple[float, float, float] = (0.0, 0.0, 0.0)
    contact_time: float = 0.5
    tolerance: float = 1e-3
    size: tuple[float, float, float] = (0.3, 0.3, 0.3)
    second_end_effector: str = ""
    second_grasp: tuple[float, ...] | None = None


@dataclass(frozen=True)
class WheelSection:
    """``[[wheels]]``: a reaction wheel on the base (:mod:`freefloat.robot.wheels`): ``joint``, a
    continuous joint of the URDF on the base, or one freefloat adds: its joint ``name``, spin
    ``axis`` and rotor centre ``position`` (base-link frame, m), rotor ``mass`` (kg), axial
    ``inertia`` and ``transverse_inertia`` (kg m^2; default half the axial); either way its limits,
    ``max_momentum`` (stored momentum ``|I Omega|``, N m s) and ``max_torque`` (N m)."""

    max_momentum: float
    max_torque: float
    joint: str = ""
    name: str = ""
    axis: tuple[float, ...] | None = None
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mass: float = 1.0
    inertia: float = 0.01
    transverse_inertia: float | None = None


@dataclass(frozen=True)
class AttitudeSection:
    """``[attitude]``: what the ``[[wheels]]`` do: ``kind = "hold"``, computed torque on the base
    attitude (gains ``kp`` 1/s^2, ``kd`` 1/s) toward ``rpy`` (XYZ Euler angles in angle_unit;
    default the initial attitude), composed with the arm's controller
    (:mod:`freefloat.space.control.wheel_attitude`); ``"none"``: the wheels get no torque."""

    kind: str = "hold"
    kp: float = 4.0
    kd: float = 4.0
    rpy: tuple[float, ...] | None = None


@dataclass(frozen=True)
class ApproachSection:
    """``[approach]`` (with a ``[target]``): plan the pre-capture motion of ``target.end_effector``
    (and ``second_end_effector``, onto its grasp point) from t = 0 to ``target.contact_time`` (:mod:`freefloat.space.planning`) and track it by
    computed torque (``[controller]`` gains and model). The target's grasp point meets the hand
    then at the hand's start position plus ``reach`` (inertial, m), with its own velocity.
    ``method``: ``"null_space"`` (reaction null space), ``"min_norm"`` (J*^+) or ``"optimised"``
    (SLSQP); limits ``max_joint_rate`` (angle_unit/s) and ``max_torque`` (N m) for every joint
    (default each joint's URDF ``<limit>``); ``mission_joints`` (default all); ``steps`` of the
    planning grid; ``compare``: also plan ``min_norm`` and report the attitude-change ratio;
    ``start`` (s): the posture is held until then (from rest), then the approach runs to the
    contact; ``match``: ``"position"`` (the grasp point's position and velocity) or ``"pose"``
    (also each hand's orientation onto a handle turning with the target: the hand's start
    orientation turned by ``turn``, a rotation vector in angle_unit about inertial axes, at the
    contact, and the target's angular velocity)."""

    method: str = "null_space"
    reach: tuple[float, float, float] = (0.0, 0.0, 0.0)
    max_joint_rate: float | None = None
    max_torque: float | None = None
    mission_joints: tuple[str, ...] | None = None
    steps: int = 200
    compare: bool = True
    start: float = 0.0
    match: str = "position"
    turn: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class SimulationSection:
    """``[simulation]``: duration and control period (s), plant model (a registry name, or
    ``"auto"``: the cheapest whose predicted state error over the run stays under ``tolerance``,
    rad or m and rad/s or m/s, see :mod:`freefloat.app.experiments.model_choice`), integrator and its
    settings, telemetry stride, and ``project_momentum``: after each control period, the
    velocity nearest in the kinetic-energy metric with the start momentum (for torque-free or
    internally actuated runs without gravity or wrenches, whose momentum is conserved);
    ``lock``: ``"auto"`` also locks every joint the scene never moves (see
    :func:`freefloat.app.experiments.locked_run.never_moved`), ``"none"`` only
    ``robot.locked_joints``; the ``backend`` of the loop: ``"compiled"``
    (:mod:`freefloat.dynamics.compiled`), ``"python"``, or ``"auto"``: compiled when the run allows
    it (exact plant, no momentum projection, no or computed-torque control on the exact model, no
    wrenches, no stop event)."""

    duration: float = 1.0
    control_period: float = 1e-3
    model: str = "auto"
    tolerance: float = 1e-6
    integrator: str = "rkmk4"
    substeps: int = 1
    rtol: float = 1e-10
    atol: float = 1e-12
    record_every: int = 1
    project_momentum: bool = False
    lock: str = "none"
    backend: str = "auto"
    baumgarte: float = 0.0


@dataclass(frozen=True)
class Scene(PluginsFirst, Kinded):
    """A validated scene. ``source`` is the file it came from (None for one built in code);
    ``plugins`` the modules it imported first (files as absolute paths, or module names);
    ``named_kind`` its top-level ``kind`` ("": its ``kind`` is the experiment kind that takes it,
    :func:`~freefloat.app.scenes.kinds.kind_of`); ``sections`` the tables that registered
    experiment kinds declare (name -> settings)."""

    name: str
    robot: RobotSection
    description: str = ""
    angle_unit: str = "deg"
    initial: InitialSection = InitialSection()
    task: TaskSection = TaskSection()
    controller: EntrySection = field(default_factory=lambda: no_controller())
    simulation: SimulationSection = SimulationSection()
    output: OutputSection = OutputSection()
    environment: tuple[EntrySection, ...] = ()
    target: TargetSection | None = None
    closures: tuple[ClosureSection, ...] = ()
    approach: ApproachSection | None = None
    wheels: tuple[WheelSection, ...] = ()
    attitude: AttitudeSection | None = None
    sensors: SensorSettings | None = None
    source: Path | None = None
    plugins: tuple[str, ...] = ()
    named_kind: str = ""
    sections: dict[str, Any] = field(default_factory=dict)

    @property
    def wrenches(self) -> tuple[Any, ...]:
        """The settings (:class:`~freefloat.app.environments.WrenchProfile`) of the
        ``wrench_profile`` fields: ``[[wrenches]]`` tables and ``[[environment]]`` of that kind."""
        return tuple(e.settings for e in self.environment if e.kind == "wrench_profile")

    @property
    def angle_scale(self) -> float:
        """Factor from the scene's angle unit to rad."""
        return math.pi / 180.0 if self.angle_unit == "deg" else 1.0


def no_controller() -> EntrySection:
    """``[controller] kind = "none"`` with the default gains (a scene without the section)."""
    return EntrySection("none", controllers.CONTROLLERS["none"].settings())


SECTIONS = {
    "robot": RobotSection, "initial": InitialSection, "task": TaskSection,
    "simulation": SimulationSection, "output": OutputSection,
    "target": TargetSection, "approach": ApproachSection, "attitude": AttitudeSection,
}
CHOICES = {
    ("robot", "base"): ("free", "planar"),
    ("robot", "inertias"): INERTIAS,
    ("task", "kind"): ("none", "joint_quintic", "detumble"),
    ("task", "method"): ("min_norm", "single", "null_space", "least_squares"),
    ("simulation", "model"): lambda: ("auto", *MODELS),
    ("simulation", "integrator"): lambda: tuple(INTEGRATORS),
    ("simulation", "lock"): ("none", "auto"),
    ("simulation", "backend"): BACKENDS,
    ("closures", "kind"): lambda: (*KINDS, *ALIASES),
    ("", "angle_unit"): ("deg", "rad"),
    ("approach", "method"): ("null_space", "min_norm", "optimised"),
    ("approach", "match"): ("position", "pose"),
    ("attitude", "kind"): ("hold", "none"),
}
POSITIVE = {
    ("task", "duration"), ("simulation", "duration"), ("simulation", "control_period"),
    ("simulation", "substeps"), ("simulation", "rtol"), ("simulation", "atol"), ("simulation", "tolerance"),
    ("simulation", "record_every"), ("output", "html_fps"), ("target", "mass"), ("target", "contact_time"),
    ("target", "tolerance"),
    ("approach", "max_joint_rate"), ("approach", "max_torque"), ("approach", "steps"),
    ("wheels", "max_momentum"), ("wheels", "max_torque"), ("wheels", "mass"), ("wheels", "inertia"),
    ("wheels", "transverse_inertia"),
}
NON_NEGATIVE = {("task", "start"), ("wrenches", "start"),
                ("attitude", "kp"), ("attitude", "kd"),
                ("wrenches", "rise"), ("simulation", "baumgarte"), ("approach", "start")}
RULES = Rules(CHOICES, POSITIVE, NON_NEGATIVE)


def parse_robot_scene(raw: dict[str, Any], source: Path | None = None) -> Scene:
    """Validate a robot scene given as a dict (the parsed TOML)."""
    where = f"{source}: " if source else "scene: "
    top = {"name", "kind", "description", "angle_unit", "plugins", "controller", "wrenches", "environment", "closures",
           "wheels", "sensors", *SECTIONS}
    reject_unknown(where, "", raw, top | set(kind_sections()))
    if "name" not in raw or "robot" not in raw:
        raise SceneError(f"{where}'name' and [robot] are required")
    kwargs: dict[str, Any] = {
        "name": typed(where, "name", raw["name"], str),
        "named_kind": typed(where, "kind", raw.get("kind", ""), str),
        "description": typed(where, "description", raw.get("description", ""), str),
        "angle_unit": choice(where, "", "angle_unit", raw.get("angle_unit", "deg"), RULES),
    }
    for section, cls in SECTIONS.items():
        if section in raw:
            kwargs[section] = parse_section(where, section, cls, raw[section], RULES)
    kwargs["sections"] = parse_kind_sections(where, raw, RULES, top)
    kwargs["controller"] = parse_entry(where, "controller", raw.get("controller", {}), controllers.serving("robot"),
                                       "none", RULES, "controllers of robot scenes")
    wrenches = raw.get("wrenches", [])
    if not isinstance(wrenches, list):
        raise SceneError(f"{where}'wrenches' must be an array of tables ([[wrenches]]), got {wrenches!r}")
    kwargs["environment"] = parse_environment(where, raw, wrenches)
    closures = raw.get("closures", [])
    if not isinstance(closures, list):
        raise SceneError(f"{where}'closures' must be an array of tables ([[closures]]), got {closures!r}")
    kwargs["closures"] = tuple(parse_section(where, "closures", ClosureSection, c, RULES) for c in closures)
    for i, closure in enumerate(kwargs["closures"]):
        if closure.frames is None or len(closure.frames) != 2 or closure.frames[0] == closure.frames[1]:
            raise SceneError(f"{where}'closures[{i}].frames' must name two different frames, got "
                             f"{list(closure.frames or ())}")
    kwargs["wheels"] = parse_wheels(where, raw)
    if "attitude" in kwargs and not kwargs["wheels"]:
        raise SceneError(f"{where}[attitude] drives the reaction wheels: add [[wheels]] or remove it")
    if "approach" in kwargs and "target" not in kwargs:
        raise SceneError(f"{where}[approach] plans the approach to a [target]: add one")
    if "sensors" in raw:
        kwargs["sensors"] = parse_sensors(where, raw["sensors"])
    scene = Scene(**kwargs, source=source)
    sim = scene.simulation
    whole_number_of(where, sim.duration, sim.control_period, "simulation.duration", "simulation.control_period")
    try:
        check_settings(sim.substeps, sim.rtol, sim.atol)
    except InvalidArgument as exc:  # "'substeps' must be ..." -> "'simulation.substeps' must be ..."
        raise SceneError(f"{where}{str(exc).replace(chr(39), chr(39) + 'simulation.', 1)}") from None
    if sim.project_momentum and (scene.environment or any(scene.robot.gravity)):
        raise SceneError(f"{where}'simulation.project_momentum' holds the momentum constant, but this scene's "
                         f"{'[[wrenches]]' if scene.wrenches else '[[environment]]' if scene.environment else 'robot.gravity'} "
                         "change it; remove one of them")
    at_most(where, scene.output.html_fps, MAX_HTML_FPS, "output.html_fps")
    if scene.sensors is not None and (scene.controller.kind == "none" or scene.target is not None):
        raise SceneError(f"{where}[sensors] feed the [controller] of a joint-space or detumbling scene; this scene "
                         f"{'has no controller' if scene.controller.kind == 'none' else 'is a capture'}: remove "
                         "[sensors]")
    return scene




def parse_environment(where: str, raw: dict[str, Any], wrenches: list) -> tuple[EntrySection, ...]:
    """The scene's fields: its ``[[wrenches]]`` (``wrench_profile`` fields, the old spelling),
    then its ``[[environment]]`` tables, each naming a kind of
    :data:`freefloat.app.environments.ENVIRONMENTS` with that entry's keys.

    Raises:
        SceneError: naming ``environment`` when it is not an array of tables, an unknown kind
            (with the nearest), or the entry's key that is wrong.
    """
    profile = environments.ENVIRONMENTS["wrench_profile"].settings
    old = tuple(EntrySection("wrench_profile", parse_section(where, "wrenches", profile, w, RULES)) for w in wrenches)
    tables = raw.get("environment", [])
    if not isinstance(tables, list):
        raise SceneError(f"{where}'environment' must be an array of tables ([[environment]]), got {tables!r}")
    return old + tuple(parse_entry(where, "environment", table, environments.ENVIRONMENTS, None, RULES,
                                   "environment fields") for table in tables)


def parse_wheels(where: str, raw: dict[str, Any]) -> tuple[WheelSection, ...]:
    """``[[wheels]]``: each names a URDF ``joint`` or adds a wheel (``name`` and ``axis``).

    Raises:
        SceneError: naming ``wheels[i]`` when it has both or neither, or an axis not of three
            numbers.
    """
    tables = raw.get("wheels", [])
    if not isinstance(tables, list):
        raise SceneError(f"{where}'wheels' must be an array of tables ([[wheels]]), got {tables!r}")
    wheels = tuple(parse_section(where, "wheels", WheelSection, w, RULES) for w in tables)
    for i, wheel in enumerate(wheels):
        if bool(wheel.joint) == bool(wheel.name or wheel.axis is not None):
            raise SceneError(f"{where}'wheels[{i}]' needs either 'joint' (a continuous joint of the URDF) or "
                             "'name' and 'axis' (a wheel freefloat adds), not both")
        if not wheel.joint and (not wheel.name or wheel.axis is None or len(wheel.axis) != 3):
            raise SceneError(f"{where}'wheels[{i}]': an added wheel needs 'name' and an 'axis' of three numbers")
    return wheels
