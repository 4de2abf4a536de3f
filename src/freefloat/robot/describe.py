"""A loaded robot described in plain text: what ``freefloat info`` prints, so that users learn
joint and link names, the end-effectors and the base reference point without reading the URDF."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .robot import Robot
from .urdf_checks import read_urdf
from .urdf_model import parse_urdf


def describe(robot: Robot) -> str:
    """Joints (type, axis in the joint frame, limits), links with masses, the end-effectors and
    their arms, the base reference point, and the loader's notes."""
    model = robot.model
    urdf = parse_urdf(robot.urdf_path, read_urdf(robot.urdf_path))
    lines = [f"{robot.urdf_path}", f"  base: {robot.base} ({model.nv - robot.n_joints} DOF) on link "
             f"'{robot.base_link}'; reference point: its CoM at {_vector(robot.base_com)} m in the link frame",
             f"  total mass {pin.computeTotalMass(model):.6g} kg; nq = {model.nq}, nv = {model.nv}", "",
             f"  joints ({robot.n_joints} movable):"]
    for joint in urdf.joints:
        if joint.type == "fixed":
            continue
        limit = joint.limit
        bounds = ("unbounded" if limit is None or limit.lower is None or joint.type == "continuous"
                  else f"[{limit.lower:.6g}, {limit.upper:.6g}] {'m' if joint.type == 'prismatic' else 'rad'}")
        lines.append(f"    {joint.name:<28} {joint.type:<10} axis {_vector(joint.axis)}  {bounds}  "
                     f"({joint.parent} -> {joint.child})")
    lines += ["", f"  links ({len(urdf.links)}):"]
    for link in urdf.links:
        mass = 0.0 if link.inertial is None else link.inertial.mass
        lines.append(f"    {link.name:<28} {mass:.6g} kg")
    lines += ["", f"  end-effectors ({len(robot.end_effectors)}):"]
    for arm in robot.arms:
        lines.append(f"    {arm.end_effector:<28} arm: {', '.join(arm.joints) or '(no movable joint)'}")
    if robot.warnings:
        lines += ["", "  warnings:", *[f"    {note}" for note in robot.warnings]]
    if robot.notes:
        lines += ["", "  notes:", *[f"    {note}" for note in robot.notes]]
    return "\n".join(lines)


def _vector(x: np.ndarray) -> str:
    return "(" + ", ".join(f"{v:.4g}" for v in x) + ")"
