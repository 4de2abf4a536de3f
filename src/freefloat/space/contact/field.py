"""Contact as a wrench field of the environment: two shapes, each fixed to a link of the model the
loop simulates (or to the inertial frame: link ``"world"``), pressed together by a
:class:`~.law.ContactLaw` at the contact point of :func:`~.shapes.proximity`, equal and opposite
on the two bodies (internal: robot + target momentum is unchanged; against the world, the
field's ``wrench`` is what the world gave)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument, did_you_mean
from ...robot.conventions import cross3
from ...robot.robot import Robot
from .law import ContactLaw
from .shapes import Proximity, Shape, proximity

#: The link name of the inertial frame (a fixed obstacle).
WORLD = "world"


@dataclass(frozen=True)
class ContactSettings:
    """``[[environment]]`` keys of kind ``"contact"``: the two links (``first``, ``second``; URDF
    link names, or ``"world"`` for a fixed obstacle), each one's shape (``*_shape``: sphere, box,
    capsule, cylinder), sizes (``*_size``, m: see :data:`~.shapes.SHAPES`) and the shape frame's
    origin in the link frame (``*_offset``, m); the law's ``stiffness`` (N/m^n), ``exponent``,
    ``damping`` (N s/m^(n+1)), ``friction`` (mu) and ``slip_speed`` (m/s)."""

    first: str
    second: str
    first_shape: str = "sphere"
    first_size: tuple[float, ...] = (0.05,)
    first_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    second_shape: str = "sphere"
    second_size: tuple[float, ...] = (0.05,)
    second_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    stiffness: float = 1e5
    exponent: float = 1.5
    damping: float = 0.0
    friction: float = 0.0
    slip_speed: float = 1e-3

    def __post_init__(self) -> None:
        self.law()
        for side in ("first", "second"):
            Shape(getattr(self, f"{side}_shape"), tuple(getattr(self, f"{side}_size")), f"contact: {side}_size")

    def law(self) -> ContactLaw:
        """The contact law of these keys."""
        return ContactLaw(self.stiffness, self.exponent, self.damping, self.friction, self.slip_speed)


class ContactField:
    """Contact between two shapes on two bodies of ``model``: a wrench field (``forces(t, q, v)``,
    ``wrench(t, q, v)``) for the engine and the balances.

    Args:
        model: the Pinocchio model the loop simulates (robot and target in one tree).
        joints: the joints (2,) whose bodies carry the shapes (0: the inertial frame).
        placements: each shape frame in its joint's frame (2,).
        shapes: the two shapes.
        law: the contact law.
    """

    def __init__(self, model: pin.Model, joints: tuple[int, int], placements: tuple[pin.SE3, pin.SE3],
                 shapes: tuple[Shape, Shape], law: ContactLaw):
        if joints[0] == joints[1]:
            raise InvalidArgument(f"contact: both shapes are on joint {model.names[joints[0]]!r}; "
                                  "contact acts between two bodies")
        self.model, self.data, self.law = model, model.createData(), law
        self.joints, self.placements = joints, placements
        self.geometries = tuple(shape.geometry() for shape in shapes)

    def contact(self, q: np.ndarray, v: np.ndarray) -> tuple[Proximity, np.ndarray] | None:
        """Where the shapes touch at ``(q, v)`` and the force on the second body there (inertial
        frame, N (3,)), or None while they are apart; runs the forward kinematics."""
        near, velocity = self.nearest(q, v)
        if near.depth <= 0.0:
            return None
        return near, self.law.force(near.depth, near.normal, velocity)

    def nearest(self, q: np.ndarray, v: np.ndarray) -> tuple[Proximity, np.ndarray]:
        """Where the shapes are closest at ``(q, v)`` (touching or not), and the second body's
        material velocity relative to the first's at that point, inertial frame, m/s (3,)."""
        pin.forwardKinematics(self.model, self.data, q, v)
        oMi = self.data.oMi
        a, b = self.joints
        near = proximity(self.geometries[0], oMi[a] * self.placements[0], self.geometries[1], oMi[b] * self.placements[1])
        return near, self._point_velocity(b, near.point) - self._point_velocity(a, near.point)

    def _point_velocity(self, joint: int, point: np.ndarray) -> np.ndarray:
        """Velocity of ``joint``'s body's material point at ``point`` (inertial), inertial frame (3,)."""
        if joint == 0:
            return np.zeros(3)
        placement, twist = self.data.oMi[joint], self.data.v[joint]
        return placement.rotation @ (twist.linear + cross3(twist.angular, placement.actInv(point)))

    def forces(self, t: float, q: np.ndarray, v: np.ndarray) -> list[pin.Force] | None:
        """One ``pin.Force`` per joint (model.njoints): the contact force on each of the two bodies
        at the contact point, joint-frame axes, moment about the joint origin (``fext``); None
        while the shapes are apart."""
        touch = self.contact(q, v)
        if touch is None:
            return None
        near, force = touch
        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        for joint, sign in zip(self.joints, (-1.0, 1.0)):
            if joint > 0:
                placement = self.data.oMi[joint]
                local = placement.rotation.T @ (sign * force)
                out[joint] = pin.Force(local, cross3(placement.actInv(near.point), local))
        return out

    def wrench(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The total it applies to the model's bodies, [force; torque about the inertial origin]
        (6,), N and N m, inertial frame: zero between two bodies (internal), the world's push on
        the body when one shape is the world's."""
        touch = self.contact(q, v)
        total = np.zeros(6)
        if touch is None:
            return total
        near, force = touch
        for joint, sign in zip(self.joints, (-1.0, 1.0)):
            if joint > 0:
                total += np.concatenate((sign * force, cross3(near.point, sign * force)))
        return total


def shape_frame(model: pin.Model, link: str, offset: tuple[float, float, float], key: str) -> tuple[int, pin.SE3]:
    """The joint carrying ``link`` (a frame of the model: a URDF link or another frame; or a joint
    name, such as a target's free-flyer ``"target"``; 0 for ``"world"``) and the shape frame in
    its joint's frame: that frame moved by ``offset`` (its axes, m).

    Raises:
        InvalidArgument: for a name the model does not have (naming ``key``).
    """
    shift = pin.SE3(np.eye(3), np.asarray(offset, float))
    if link == WORLD:
        return 0, shift
    frames = {f.name: f for f in reversed(model.frames)}  # the first of a name wins (a URDF link's BODY frame)
    if link in frames:
        frame = frames[link]
        return frame.parentJoint, frame.placement * shift
    if model.existJointName(link):
        return model.getJointId(link), shift
    names = sorted(set(frames) | set(model.names) | {WORLD})
    raise InvalidArgument(f"contact: {key} link '{link}' does not exist{did_you_mean(link, names, 'links')}")


def contact_field(robot: Robot | pin.Model, settings: ContactSettings) -> ContactField:
    """The field of a scene's contact on ``robot`` (or a Pinocchio model): ``build(robot,
    settings)`` of an environment registry entry whose settings are :class:`ContactSettings`."""
    model = robot.model if isinstance(robot, Robot) else robot
    frames = [shape_frame(model, getattr(settings, side), getattr(settings, f"{side}_offset"), side)
              for side in ("first", "second")]
    shapes = tuple(Shape(getattr(settings, f"{side}_shape"), tuple(getattr(settings, f"{side}_size")),
                         f"contact: {side}_size") for side in ("first", "second"))
    return ContactField(model, (frames[0][0], frames[1][0]), (frames[0][1], frames[1][1]), shapes, settings.law())
