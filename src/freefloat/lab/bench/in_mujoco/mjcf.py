"""MJCF text for MuJoCo from a loaded free-floating :class:`~freefloat.robot.Robot`.

The MJCF is written from the Pinocchio model, not from the URDF: one MuJoCo body per Pinocchio
joint, placed by ``model.jointPlacements`` (the body frame is the joint frame), carrying that
joint's inertia (fixed links already merged by Pinocchio). The root body has a free joint, gravity
is zero, contacts and constraints are off and joints are unlimited, so both sides simulate the
same torque-free multibody system. Needs no ``mujoco`` import.

MuJoCo refuses a body whose principal moments break the triangle inequality
``I1 + I2 >= I3``, which no real body can do but a URDF can state (the four-arm robot's links:
Izz 0.065 > 0.0321 + 0.0277). :func:`balanced_model` makes a corrected copy; the comparison then
runs on that copy on both sides.
"""

from __future__ import annotations

import warnings
from xml.sax.saxutils import quoteattr

import numpy as np
import pinocchio as pin

from ....errors import RobotModelError, few
from ....robot.inertias import balanced
from ....robot.robot import Robot

#: Pinocchio joint kinds written as MuJoCo joints, with their axis in the joint frame.
_AXES = {"RX": (1.0, 0.0, 0.0), "RY": (0.0, 1.0, 0.0), "RZ": (0.0, 0.0, 1.0),
         "PX": (1.0, 0.0, 0.0), "PY": (0.0, 1.0, 0.0), "PZ": (0.0, 0.0, 1.0)}


class InertiaBalanceWarning(UserWarning):
    """A robot's inertias break the triangle inequality; the comparison uses a balanced copy."""


def _num(values) -> str:
    return " ".join(f"{x:.17g}" for x in np.ravel(values))


def joint_axis(model: pin.Model, joint_id: int) -> tuple[str, np.ndarray]:
    """MuJoCo joint type (``"hinge"`` or ``"slide"``) and unit axis (3,) in the joint frame.

    Raises:
        RobotModelError: for a joint kind MuJoCo's hinge/slide cannot express, naming the joint.
    """
    joint = model.joints[joint_id]
    kind = joint.shortname().removeprefix("JointModel")
    name = model.names[joint_id]
    if kind in _AXES:
        return ("hinge" if kind[0] == "R" else "slide"), np.array(_AXES[kind])
    if kind in ("RevoluteUnaligned", "PrismaticUnaligned"):
        return ("hinge" if kind[0] == "R" else "slide"), np.asarray(joint.extract().axis, dtype=float)
    raise RobotModelError(f"joint '{name}' ({kind}): no MuJoCo equivalent in the MJCF export "
                          "(revolute and prismatic joints only; a continuous joint's (cos, sin) has none)")


def balanced_model(model: pin.Model) -> pin.Model:
    """:func:`freefloat.robot.inertias.balanced`'s copy, with a warning giving the largest
    relative change (it changes the robot, and both sides of the comparison use it)."""
    copy, changes = balanced(model)
    if changes:
        warnings.warn(f"the inertias of {len(changes)} bodies ({few(changes)}) break the triangle "
                      "inequality and MuJoCo refuses them; both sides use a balanced copy whose least principal "
                      f"moments are raised by up to {max(changes.values()):.1%}", InertiaBalanceWarning, stacklevel=2)
    return copy


def _body(model: pin.Model, joint_id: int, children: dict[int, list[int]], indent: str) -> list[str]:
    placement = model.jointPlacements[joint_id]
    inertia = model.inertias[joint_id]
    if inertia.mass <= 0.0:
        raise RobotModelError(f"joint '{model.names[joint_id]}' moves a body of zero mass: MuJoCo refuses it")
    quat = pin.Quaternion(placement.rotation)
    body_i = inertia.inertia
    name = quoteattr(model.names[joint_id])
    lines = [f'{indent}<body name={name} pos="{_num(placement.translation)}" '
             f'quat="{_num([quat.w, quat.x, quat.y, quat.z])}">']
    if joint_id == 1:
        lines.append(f'{indent}  <freejoint name={name}/>')
    else:
        kind, axis = joint_axis(model, joint_id)
        lines.append(f'{indent}  <joint name={name} type="{kind}" axis="{_num(axis)}" '
                     'limited="false"/>')
    lines.append(f'{indent}  <inertial pos="{_num(inertia.lever)}" mass="{inertia.mass:.17g}" fullinertia="'
                 f'{_num([body_i[0, 0], body_i[1, 1], body_i[2, 2], body_i[0, 1], body_i[0, 2], body_i[1, 2]])}"/>')
    for child in children.get(joint_id, []):
        lines += _body(model, child, children, indent + "  ")
    lines.append(f"{indent}</body>")
    return lines


def mjcf_from_model(model: pin.Model, name: str = "robot", timestep: float = 1e-3,
                    integrator: str = "RK4", energy: bool = True) -> str:
    """MJCF of a Pinocchio model whose joint 1 is a free-flyer (zero gravity, contacts off).

    Args:
        model: free-flyer Pinocchio model (every other joint revolute or prismatic, one DOF).
        name: MuJoCo model name.
        timestep: MuJoCo ``timestep``, s.
        integrator: MuJoCo integrator name (``Euler``, ``implicitfast``, ``RK4``, ...).
        energy: MuJoCo computes the energy at each step (its ``energy`` flag; off where only
            speed is compared).

    Raises:
        RobotModelError: the root is not a free-flyer, a joint kind has no MuJoCo equivalent, or a
            moving body has no mass.
    """
    if model.njoints < 2 or model.joints[1].shortname() != "JointModelFreeFlyer":
        raise RobotModelError(f"{name}: MJCF export needs a free-flyer root joint (load with base='free')")
    children: dict[int, list[int]] = {}
    for j in range(2, model.njoints):
        children.setdefault(model.parents[j], []).append(j)
    return "\n".join([
        f"<mujoco model={quoteattr(name)}>",
        '  <compiler angle="radian" autolimits="false"/>',
        f'  <option gravity="0 0 0" timestep="{timestep:.17g}" integrator="{integrator}">',
        f'    <flag contact="disable" constraint="disable" energy="{"enable" if energy else "disable"}"/>',
        "  </option>",
        "  <worldbody>",
        *_body(model, 1, children, "    "),
        "  </worldbody>",
        "</mujoco>",
    ])


def mjcf(robot: Robot, timestep: float = 1e-3, integrator: str = "RK4") -> str:
    """MJCF of a free-floating robot as loaded (see :func:`mjcf_from_model`)."""
    if robot.base != "free":
        raise RobotModelError(f"{robot.urdf_path}: MJCF export needs base='free', got {robot.base!r}")
    return mjcf_from_model(robot.model, robot.urdf_path.stem, timestep, integrator)
