"""MJCF text of a closed-chain mechanism: its Pinocchio spanning tree on a fixed, planar or free
base, each closure a MuJoCo equality constraint between two sites.

One MuJoCo body per Pinocchio joint, placed by ``model.jointPlacements`` (the body frame is the
joint frame), carrying that joint's inertia; one hinge or slide joint per body, unlimited, no
armature or damping; gravity the model's; contacts off. A moving base (:mod:`freefloat.parallel.free_base`)
is Pinocchio's root joint: a planar root is written as three joints of the root body (slides
along x and y, then a hinge about z, named ``<root>_x``, ``<root>_y``, ``<root>_yaw``), a
free-flyer root as a ``<freejoint>`` (:data:`ROOT_JOINTS`; :mod:`.mechanism` maps the
states). A point closure (``CONTACT_3D``) is a
``<connect>`` of two sites at its two placements, a frame closure (``CONTACT_6D``) a ``<weld>``
(the site frames coincide). MuJoCo's constraints are soft: each gets ``solref`` and ``solimp``
chosen stiff: impedance 0.9999 (:data:`SOLIMP`, MuJoCo's largest) and time constant twice the
step, critically damped (:data:`TIMECONST_STEPS`; MuJoCo clamps shorter ones), so the closures
stiffen as the step shrinks and MuJoCo converges to the rigid mechanism. Needs no ``mujoco`` import.

MuJoCo refuses bodies whose principal moments break the triangle inequality, as the 5R's planar
links (moments 0, 0, Jz) do; they are written balanced (:func:`.mjcf.balanced_model`), which for
hinges about parallel axes leaves the joint-space mass matrix unchanged (the bench checks it).
"""

from __future__ import annotations

import warnings
from xml.sax.saxutils import quoteattr

import numpy as np
import pinocchio as pin

from .mjcf import InertiaBalanceWarning, _num, balanced_model, joint_axis

#: MuJoCo's constraint softness for the closures: ``solref = (TIMECONST_STEPS timestep, 1)``
#: (time constant, s; damping ratio) and ``solimp`` ``dmin dmax width midpoint power``
#: (impedance 0.9999 everywhere).
TIMECONST_STEPS = 2.0
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
#: Pinocchio contact type -> MuJoCo equality.
EQUALITIES = {pin.ContactType.CONTACT_3D: "connect", pin.ContactType.CONTACT_6D: "weld"}
#: MuJoCo joints of a root joint of a moving base: name suffix, type, axis (the root body's frame).
PLANAR_JOINTS = (("_x", "slide", (1.0, 0.0, 0.0)), ("_y", "slide", (0.0, 1.0, 0.0)), ("_yaw", "hinge", (0.0, 0.0, 1.0)))
ROOT_JOINTS = ("JointModelPlanar", "JointModelFreeFlyer")


def _joints(model: pin.Model, joint_id: int, indent: str) -> list[str]:
    """The MuJoCo joint lines of Pinocchio joint ``joint_id`` (a root joint of :data:`ROOT_JOINTS`,
    or one hinge or slide)."""
    name = model.names[joint_id]
    kind = model.joints[joint_id].shortname()
    if kind == "JointModelFreeFlyer":
        return [f"{indent}<freejoint name={quoteattr(name)}/>"]
    if kind == "JointModelPlanar":
        return [f'{indent}<joint name={quoteattr(name + suffix)} type="{joint}" axis="{_num(axis)}" limited="false"/>'
                for suffix, joint, axis in PLANAR_JOINTS]
    joint, axis = joint_axis(model, joint_id)
    return [f'{indent}<joint name={quoteattr(name)} type="{joint}" axis="{_num(axis)}" limited="false"/>']


def _pose(placement: pin.SE3) -> str:
    quat = pin.Quaternion(placement.rotation)
    return f'pos="{_num(placement.translation)}" quat="{_num([quat.w, quat.x, quat.y, quat.z])}"'


def _body(model: pin.Model, joint_id: int, children: dict[int, list[int]], sites: dict[int, list[str]],
          indent: str) -> list[str]:
    inertia = model.inertias[joint_id]
    name = quoteattr(model.names[joint_id])
    I = inertia.inertia
    lines = [f"{indent}<body name={name} {_pose(model.jointPlacements[joint_id])}>", *_joints(model, joint_id, indent + "  "),
             (f'{indent}  <inertial pos="{_num(inertia.lever)}" mass="{inertia.mass:.17g}" '
              f'fullinertia="{_num([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>'),
             *[indent + "  " + site for site in sites.get(joint_id, [])]]
    for child in children.get(joint_id, []):
        lines += _body(model, child, children, sites, indent + "  ")
    return lines + [f"{indent}</body>"]


def mechanism_mjcf(model: pin.Model, constraints: list, timestep: float, integrator: str) -> str:
    """MJCF of a tree ``model`` (fixed base, or a root joint of :data:`ROOT_JOINTS`) with ``constraints`` (Pinocchio ``RigidConstraintModel``
    s, point or frame) as equalities ``closure<i>`` between sites ``closure<i>_a``, ``closure<i>_b``.

    Args:
        timestep: MuJoCo ``timestep``, s.
        integrator: ``Euler``, ``implicitfast`` or ``RK4``.

    Raises:
        RobotModelError: a joint kind MuJoCo's hinge or slide cannot express.
    """
    with warnings.catch_warnings(), np.errstate(divide="ignore"):  # planar links (moments 0, 0, Jz): module docstring
        warnings.simplefilter("ignore", InertiaBalanceWarning)
        model = balanced_model(model)
    children: dict[int, list[int]] = {}
    for j in range(1, model.njoints):
        children.setdefault(model.parents[j], []).append(j)
    sites: dict[int, list[str]] = {}
    equalities = []
    soft = f'solref="{_num([TIMECONST_STEPS * timestep, 1.0])}" solimp="{_num(SOLIMP)}"'
    for i, cm in enumerate(constraints):
        for side, joint, placement in (("a", cm.joint1_id, cm.joint1_placement), ("b", cm.joint2_id, cm.joint2_placement)):
            sites.setdefault(joint, []).append(f'<site name="closure{i}_{side}" {_pose(placement)}/>')
        equalities.append(f'    <{EQUALITIES[cm.type]} name="closure{i}" site1="closure{i}_a" site2="closure{i}_b" {soft}/>')
    gravity = model.gravity.linear
    return "\n".join([
        f"<mujoco model={quoteattr(model.name or 'mechanism')}>",
        '  <compiler angle="radian" autolimits="false"/>',
        f'  <option gravity="{_num(gravity)}" timestep="{timestep:.17g}" integrator="{integrator}" tolerance="1e-12">',
        '    <flag contact="disable"/>',
        "  </option>",
        "  <worldbody>",
        *["    " + site for site in sites.get(0, [])],
        *[line for root in children.get(0, []) for line in _body(model, root, children, sites, "    ")],
        "  </worldbody>",
        "  <equality>",
        *equalities,
        "  </equality>",
        "</mujoco>",
    ])
