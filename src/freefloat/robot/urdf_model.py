"""A URDF's links and joints as frozen dataclasses, read from the XML tree with the standard
library (``urdf_checks.read_urdf`` reads the tree): what the loader checks and cross-checks
against Pinocchio's parse, without yourdfpy's import (trimesh, networkx, lxml: about 0.65 s).

The fields and defaults are yourdfpy's: a missing ``<origin>`` or ``xyz``/``rpy`` is the identity,
a missing ``<axis>`` is (1, 0, 0), a link without ``<inertial>`` has ``inertial = None``, a joint
without ``<limit>`` or ``<mimic>`` has None there, a ``<limit>`` attribute left out is None, a
``<mimic>`` has multiplier 1 and offset 0 unless given, a ``<dynamics>`` attribute left out is 0
(urdfdom's reading; yourdfpy's is None). Where yourdfpy and urdfdom (Pinocchio's
parser) read a file differently this reader refuses it, naming the file, the link or joint and
the attribute: an ``<inertial>`` without ``<mass value>`` or without all six ``<inertia>``
moments (urdfdom drops the whole ``<inertial>``, yourdfpy fills in 0 kg or unit moments), an
``<axis>`` without ``xyz`` (urdfdom: a zero axis; yourdfpy: (1, 0, 0)), a vector of other than
three numbers, and a joint type URDF does not define. Visuals and collisions are not read:
Pinocchio builds the geometry itself.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ..errors import RobotModelError, did_you_mean

#: The joint types URDF defines.
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
#: The six moments an ``<inertia>`` must give.
MOMENTS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


@dataclasses.dataclass(frozen=True, eq=False)
class Inertial:
    """A link's mass properties. ``origin``: 4x4 pose of the inertial frame (its origin the CoM)
    in the link frame; ``mass`` kg; ``inertia``: 3x3 about the CoM in the inertial frame, kg m^2
    (arrays read-only)."""

    mass: float
    origin: np.ndarray
    inertia: np.ndarray

    def __post_init__(self) -> None:
        _read_only(self.origin, self.inertia)


@dataclasses.dataclass(frozen=True, eq=False)
class Link:
    """A ``<link>``: its name and mass properties (None: no ``<inertial>``, a massless link)."""

    name: str
    inertial: Inertial | None


@dataclasses.dataclass(frozen=True)
class Limit:
    """A ``<limit>``: position bounds (rad or m), effort (N m or N) and velocity (rad/s or m/s),
    None where the attribute is left out."""

    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None


@dataclasses.dataclass(frozen=True)
class Dynamics:
    """A ``<dynamics>``: viscous ``damping`` (N m s/rad or N s/m) and Coulomb ``friction`` (N m or
    N), each >= 0 (Pinocchio's ``model.damping`` and ``model.friction``; the law is
    :class:`freefloat.dynamics.friction.JointFriction`'s)."""

    damping: float
    friction: float


@dataclasses.dataclass(frozen=True)
class Mimic:
    """A ``<mimic>``: this joint's position is ``multiplier * q[joint] + offset``."""

    joint: str
    multiplier: float
    offset: float


@dataclasses.dataclass(frozen=True, eq=False)
class Joint:
    """A ``<joint>``. ``origin``: 4x4 pose of the joint frame in the parent link's frame (the
    child link's frame at zero position); ``axis``: (3,) in the joint frame, as written (not
    normalised); arrays read-only; ``dynamics``: its ``<dynamics>``, None without one."""

    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    limit: Limit | None
    mimic: Mimic | None
    dynamics: Dynamics | None = None

    def __post_init__(self) -> None:
        _read_only(self.origin, self.axis)


@dataclasses.dataclass(frozen=True, eq=False)
class UrdfModel:
    """A URDF's robot name, links and joints, in file order."""

    name: str
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]

    @functools.cached_property
    def link_map(self) -> dict[str, Link]:
        """Links by name (the last of a repeated name; the loader refuses repeats)."""
        return {link.name: link for link in self.links}


def _read_only(*arrays: np.ndarray) -> None:
    for array in arrays:
        array.flags.writeable = False


def parse_urdf(path: Path, root: ET.Element) -> UrdfModel:
    """The links and joints of the URDF ``root`` (the tree of the file ``path``, named in errors).

    Raises:
        RobotModelError: naming the file, the link or joint, the element and the attribute that is
            missing, not a number, not three numbers, or a joint type URDF does not define.
    """
    reader = _Reader(path)
    if root.tag != "robot":
        raise RobotModelError(f"{path}: the root element is <{root.tag}>, not <robot>")
    name = reader.required(root, "name")
    return UrdfModel(name, tuple(reader.link(e) for e in root.findall("link")),
                     tuple(reader.joint(e) for e in root.findall("joint")))


@dataclasses.dataclass
class _Reader:
    """Reads the elements of one file, naming it and the link or joint under way in errors."""

    path: Path
    #: The link or joint being read, as errors name it ("link 'arm1'"; "a" before its name is known).
    owner: str = "the"

    def error(self, element: ET.Element, problem: str, attribute: str | None = None) -> RobotModelError:
        value = None if attribute is None else element.get(attribute)
        written = "" if value is None else f' {attribute}="{value}"'
        return RobotModelError(f"{self.path}: {self.owner} <{element.tag}{written}>: {problem}")

    def required(self, element: ET.Element, attribute: str) -> str:
        value = element.get(attribute)
        if value is None:
            raise self.error(element, f"no '{attribute}' attribute")
        return value

    def child(self, element: ET.Element, tag: str) -> ET.Element:
        found = element.find(tag)
        if found is None:
            raise self.error(element, f"no <{tag}>")
        return found

    def number(self, element: ET.Element, attribute: str, default: float | None = None) -> float | None:
        text = element.get(attribute)
        if text is None:
            return default
        try:
            return float(text)
        except ValueError:
            raise self.error(element, f"'{text}' is not a number", attribute) from None

    def vector(self, element: ET.Element, attribute: str, default: str) -> list[float]:
        text = element.get(attribute, default)
        try:
            values = [float(token) for token in text.split()]
        except ValueError:
            raise self.error(element, "not three numbers", attribute) from None
        if len(values) != 3:
            raise self.error(element, f"{len(values)} numbers; 3 expected", attribute)
        return values

    def origin(self, element: ET.Element | None) -> np.ndarray:
        """4x4 pose of an ``<origin xyz rpy>``: rotation Rz(yaw) Ry(pitch) Rx(roll) (fixed axes x,
        y, z in turn), then the translation; the identity when absent."""
        pose = np.eye(4)
        if element is None:
            return pose
        pose[:3, 3] = self.vector(element, "xyz", "0 0 0")
        roll, pitch, yaw = self.vector(element, "rpy", "0 0 0")
        si, sj, sk = math.sin(roll), math.sin(pitch), math.sin(yaw)
        ci, cj, ck = math.cos(roll), math.cos(pitch), math.cos(yaw)
        pose[:3, :3] = [[cj * ck, sj * si * ck - ci * sk, sj * ci * ck + si * sk],
                        [cj * sk, sj * si * sk + ci * ck, sj * ci * sk - si * ck],
                        [-sj, cj * si, cj * ci]]
        return pose

    def link(self, element: ET.Element) -> Link:
        self.owner = "a"
        name = self.required(element, "name")
        self.owner = f"link '{name}'"
        inertial = element.find("inertial")
        if inertial is None:
            return Link(name, None)
        mass, moments = self.child(inertial, "mass"), self.child(inertial, "inertia")
        for part, attribute in [(mass, "value"), *((moments, m) for m in MOMENTS)]:
            self.required(part, attribute)
        xx, xy, xz, yy, yz, zz = (self.number(moments, m) for m in MOMENTS)
        inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        return Link(name, Inertial(self.number(mass, "value"), self.origin(inertial.find("origin")), inertia))

    def joint(self, element: ET.Element) -> Joint:
        self.owner = "a"
        name = self.required(element, "name")
        self.owner = f"joint '{name}'"
        kind = self.required(element, "type")
        if kind not in JOINT_TYPES:
            raise self.error(element, f"'{kind}' is no URDF joint type{did_you_mean(kind, JOINT_TYPES)}", "type")
        parent, child = (self.required(self.child(element, tag), "link") for tag in ("parent", "child"))
        axis = element.find("axis")
        if axis is not None and axis.get("xyz") is None:
            raise self.error(axis, "no 'xyz' attribute (urdfdom reads a zero axis, yourdfpy (1, 0, 0)); write it")
        limit, mimic, dynamics = element.find("limit"), element.find("mimic"), element.find("dynamics")
        return Joint(
            name, kind, parent, child, self.origin(element.find("origin")),
            np.array([1.0, 0.0, 0.0] if axis is None else self.vector(axis, "xyz", "")),
            None if limit is None else Limit(*(self.number(limit, a) for a in ("lower", "upper", "effort", "velocity"))),
            None if mimic is None else Mimic(self.required(mimic, "joint"), self.number(mimic, "multiplier", 1.0),
                                             self.number(mimic, "offset", 0.0)),
            None if dynamics is None else self.dynamics(dynamics),
        )

    def dynamics(self, element: ET.Element) -> Dynamics:
        """A ``<dynamics>``; an attribute left out is 0."""
        values = {}
        for attribute in ("damping", "friction"):
            values[attribute] = self.number(element, attribute, 0.0)
            if values[attribute] < 0.0:
                raise self.error(element, "negative: friction dissipates energy, it cannot feed it in", attribute)
        return Dynamics(**values)
