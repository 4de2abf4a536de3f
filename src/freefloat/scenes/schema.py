"""Scene files: TOML validated against a schema, with errors that name the key.

A scene names the robot, initial state, task, controller, integrator, step and duration. Angles
(joint angles, base attitude, angular rates, task displacements) are in the unit given by the
top-level ``angle_unit`` ("deg" or "rad"); lengths in m, times in s.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import MISSING, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from ..errors import SceneError
from ..integrators import INTEGRATORS
from ..models import MODELS

if TYPE_CHECKING:
    from .mechanism_schema import MechanismScene


@dataclass(frozen=True)
class RobotSection:
    """``[robot]``: URDF (absolute, relative to the scene file, or a built-in robot file name),
    floating base kind, end-effector link names (default: leaves), gravity (m/s^2, inertial)."""

    urdf: str
    base: str = "free"
    end_effectors: tuple[str, ...] | None = None
    gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)


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
class WrenchSection:
    """``[[wrenches]]``: a wrench on ``link`` at its CoM (inertial frame, N and N m), from
    ``start`` to ``end`` s, rising linearly over ``rise`` s (the dissertation's capture model)."""

    link: str
    force: tuple[float, float, float] = (0.0, 0.0, 0.0)
    torque: tuple[float, float, float] = (0.0, 0.0, 0.0)
    start: float = 0.0
    end: float = 1e9
    rise: float = 0.0


@dataclass(frozen=True)
class TargetSection:
    """``[target]``: a rigid target that reaches ``end_effector`` at ``contact_time`` s flying
    freely (velocity, inertial, m/s; spin along a principal axis, in angle_unit per s), is grasped
    by an exact inelastic impulse, then detumbled by the ``[task]``. Mass kg, inertia (principal,
    kg m^2), grasp point in the target frame from its CoM (m), display size (m)."""

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


@dataclass(frozen=True)
class ControllerSection:
    """``[controller]``: ``kind = "none"`` or ``"computed_torque"`` with scalar gains Kp, Kd and
    the dynamics model it uses."""

    kind: str = "none"
    model: str = "exact"
    kp: float = 10.0
    kd: float = 100.0


@dataclass(frozen=True)
class SimulationSection:
    """``[simulation]``: duration and control period (s), plant model, integrator and its
    settings, telemetry stride."""

    duration: float = 1.0
    control_period: float = 1e-3
    model: str = "exact"
    integrator: str = "rkmk4"
    substeps: int = 1
    rtol: float = 1e-10
    atol: float = 1e-12
    record_every: int = 1


@dataclass(frozen=True)
class OutputSection:
    """``[output]``: which artefacts a run writes."""

    figures: bool = True
    html: bool = True
    html_fps: float = 30.0


@dataclass(frozen=True)
class Scene:
    """A validated scene. ``source`` is the file it came from (None for one built in code)."""

    name: str
    robot: RobotSection
    description: str = ""
    angle_unit: str = "deg"
    initial: InitialSection = InitialSection()
    task: TaskSection = TaskSection()
    controller: ControllerSection = ControllerSection()
    simulation: SimulationSection = SimulationSection()
    output: OutputSection = OutputSection()
    wrenches: tuple[WrenchSection, ...] = ()
    target: TargetSection | None = None
    source: Path | None = None

    @property
    def angle_scale(self) -> float:
        """Factor from the scene's angle unit to rad."""
        return math.pi / 180.0 if self.angle_unit == "deg" else 1.0


class Rules(NamedTuple):
    """Value rules of one scene kind, keyed by ``(section, key)`` (section ``""``: top level):
    the allowed strings, and the numbers that must be > 0 or >= 0."""

    choices: dict[tuple[str, str], tuple[str, ...]]
    positive: set[tuple[str, str]]
    non_negative: set[tuple[str, str]]


SECTIONS = {
    "robot": RobotSection, "initial": InitialSection, "task": TaskSection,
    "controller": ControllerSection, "simulation": SimulationSection, "output": OutputSection,
    "target": TargetSection,
}
CHOICES = {
    ("robot", "base"): ("free", "planar"),
    ("task", "kind"): ("none", "joint_quintic", "detumble"),
    ("task", "method"): ("min_norm", "single", "null_space", "least_squares"),
    ("controller", "kind"): ("none", "computed_torque"),
    ("controller", "model"): tuple(MODELS),
    ("simulation", "model"): tuple(MODELS),
    ("simulation", "integrator"): tuple(INTEGRATORS),
    ("", "angle_unit"): ("deg", "rad"),
}
POSITIVE = {
    ("task", "duration"), ("simulation", "duration"), ("simulation", "control_period"),
    ("simulation", "substeps"), ("simulation", "rtol"), ("simulation", "atol"),
    ("simulation", "record_every"), ("output", "html_fps"), ("target", "mass"), ("target", "contact_time"),
    ("target", "tolerance"),
}
NON_NEGATIVE = {("controller", "kp"), ("controller", "kd"), ("task", "start"), ("wrenches", "start"),
                ("wrenches", "rise")}
RULES = Rules(CHOICES, POSITIVE, NON_NEGATIVE)


def load_scene(path: str | Path) -> Scene | MechanismScene:
    """Read and validate a scene file: a robot scene, or a mechanism scene when it has a
    ``[mechanism]`` section.

    Raises:
        SceneError: naming the file and the key for unknown keys, wrong types, impossible values.
    """
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text())
    except FileNotFoundError as exc:
        raise SceneError(f"{path}: no such scene file") from exc
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML ({exc})") from exc
    return parse_scene(raw, source=path)


def parse_scene(raw: dict[str, Any], source: Path | None = None) -> Scene | MechanismScene:
    """Validate a scene given as a dict (the parsed TOML)."""
    if "mechanism" in raw:
        from .mechanism_schema import parse_mechanism_scene

        return parse_mechanism_scene(raw, source)
    where = f"{source}: " if source else "scene: "
    top = {"name", "description", "angle_unit", "wrenches", *SECTIONS}
    _no_unknown(where, "", raw, top)
    if "name" not in raw or "robot" not in raw:
        raise SceneError(f"{where}'name' and [robot] are required")
    kwargs: dict[str, Any] = {
        "name": _typed(where, "name", raw["name"], str),
        "description": _typed(where, "description", raw.get("description", ""), str),
        "angle_unit": _choice(where, "", "angle_unit", raw.get("angle_unit", "deg")),
    }
    for section, cls in SECTIONS.items():
        if section in raw:
            kwargs[section] = _section(where, section, cls, raw[section])
    wrenches = raw.get("wrenches", [])
    if not isinstance(wrenches, list):
        raise SceneError(f"{where}'wrenches' must be an array of tables ([[wrenches]]), got {wrenches!r}")
    kwargs["wrenches"] = tuple(_section(where, "wrenches", WrenchSection, w) for w in wrenches)
    return Scene(**kwargs, source=source)


def _section(where: str, section: str, cls: type, raw: Any, rules: Rules = RULES) -> Any:
    """A section's dataclass from its table; how each value is checked follows the field's type
    annotation (and ``rules``)."""
    if not isinstance(raw, dict):
        raise SceneError(f"{where}[{section}] must be a table, got {type(raw).__name__}")
    fields_ = cls.__dataclass_fields__
    _no_unknown(where, section, raw, set(fields_))
    missing = [k for k, f in fields_.items() if f.default is MISSING
               and f.default_factory is MISSING and k not in raw]
    if missing:
        raise SceneError(f"{where}[{section}] needs key '{missing[0]}'")
    values = {}
    for key, value in raw.items():
        kind, name = fields_[key].type, f"{section}.{key}"
        if kind == "str":
            values[key] = _choice(where, section, key, _typed(where, name, value, str), rules)
        elif kind == "bool":
            values[key] = _typed(where, name, value, bool)
        elif kind in ("int", "float"):
            values[key] = _number(where, section, key, value, int if kind == "int" else float, rules)
        elif kind == "tuple[str, ...] | None":
            values[key] = _names(where, name, value)
        elif kind == "tuple[float, float, float]":
            values[key] = _vector(where, name, value, 3)
        elif kind in ("tuple[float, ...]", "tuple[float, ...] | None"):
            values[key] = _vector(where, name, value, None)
        elif kind == "tuple[int, int]":
            values[key] = _indices(where, name, value, 2)
        elif kind == "tuple[tuple[float, ...], ...] | None":
            values[key] = _matrix(where, name, value)
        elif kind == "dict[str, tuple[float, ...]]":
            values[key] = {k: _vector(where, f"{name}.{k}", v, None)
                           for k, v in _typed(where, name, value, dict).items()}
        else:
            values[key] = _table(where, name, value)
    return cls(**values)


def _no_unknown(where: str, section: str, raw: dict, allowed: set[str]) -> None:
    for key in raw:
        if key not in allowed:
            name = f"[{section}] key '{key}'" if section else f"top-level key '{key}'"
            raise SceneError(f"{where}unknown {name}; allowed: {', '.join(sorted(allowed))}")


def _typed(where: str, key: str, value: Any, kind: type) -> Any:
    if not isinstance(value, kind):
        raise SceneError(f"{where}'{key}' must be a {kind.__name__}, got {value!r}")
    return value


def _number(where: str, section: str, key: str, value: Any, kind: type, rules: Rules = RULES) -> float | int:
    name = f"{section}.{key}"
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (
        kind is int and not isinstance(value, int)
    ):
        raise SceneError(f"{where}'{name}' must be a{'n integer' if kind is int else ' number'}, got {value!r}")
    if not math.isfinite(value):
        raise SceneError(f"{where}'{name}' must be finite, got {value!r}")
    if (section, key) in rules.positive and value <= 0:
        raise SceneError(f"{where}'{name}' must be > 0, got {value!r}")
    if (section, key) in rules.non_negative and value < 0:
        raise SceneError(f"{where}'{name}' must be >= 0, got {value!r}")
    return kind(value)


def _choice(where: str, section: str, key: str, value: Any, rules: Rules = RULES) -> str:
    options = rules.choices.get((section, key))
    if options is not None and value not in options:
        name = f"{section}.{key}" if section else key
        raise SceneError(f"{where}'{name}' is {value!r}; valid: {', '.join(options)}")
    return value


def _names(where: str, key: str, value: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(x, str) for x in value):
        raise SceneError(f"{where}'{key}' must be a list of names, got {value!r}")
    return tuple(value)


def _vector(where: str, key: str, value: Any, size: int | None) -> tuple[float, ...]:
    """A list of finite numbers, of length ``size`` (None: any length but empty)."""
    if (not isinstance(value, list) or len(value) != (size or len(value)) or not value
            or not all(_finite(x) for x in value)):
        raise SceneError(f"{where}'{key}' must be a list of {size or 'one or more'} finite numbers, got {value!r}")
    return tuple(float(x) for x in value)


def _matrix(where: str, key: str, value: Any) -> tuple[tuple[float, ...], ...]:
    """A list of equally long rows of finite numbers."""
    rows = [_vector(where, key, row, None) for row in _typed(where, key, value, list)]
    if not rows or len({len(r) for r in rows}) != 1:
        raise SceneError(f"{where}'{key}' must be a list of equally long rows of numbers, got {value!r}")
    return tuple(rows)


def _indices(where: str, key: str, value: Any, size: int) -> tuple[int, ...]:
    """A list of ``size`` distinct non-negative integers."""
    if (not isinstance(value, list) or len(value) != size or len(set(value)) != size
            or not all(isinstance(x, int) and not isinstance(x, bool) and x >= 0 for x in value)):
        raise SceneError(f"{where}'{key}' must be a list of {size} distinct integers >= 0, got {value!r}")
    return tuple(value)


def _finite(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _table(where: str, key: str, value: Any) -> dict[str, float]:
    if not isinstance(value, dict) or not all(_finite(x) for x in value.values()):
        raise SceneError(f"{where}'{key}' must be a table of finite numbers keyed by name, got {value!r}")
    return {k: float(x) for k, x in value.items()}
