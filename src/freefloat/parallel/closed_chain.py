"""Closed-chain mechanisms as data: a URDF spanning tree plus a closure file.

A URDF cannot express a loop (and urdfdom fails on one with a misleading message), so a
mechanism is its spanning tree in ``urdf/<name>.urdf`` and a TOML file beside it that states
what the tree leaves out:

.. code-block:: toml

    urdf = "five_bar.urdf"
    gravity = [0.0, -9.8, 0.0]
    actuated = ["c1_joint1", "c2_joint1"]     # joint names
    [platform]
    frame = "c1_ee"                           # the point whose coordinates are q#
    coordinates = ["x", "y"]                  # which of its inertial coordinates
    [[closures]]
    frames = ["c1_ee", "c2_ee"]               # these two points coincide (3-D point contact)

:func:`load_closed_chain` turns it into both models: Orsino's :class:`ParallelMechanism`
(chains read from the tree, one per closure frame, the platform a massless point whose listed
coordinates both chain tips must match) and Pinocchio's fixed-base model with one
``RigidConstraintModel`` (CONTACT_3D) per closure, the independent reference.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import FreefloatError
from .mechanism import ParallelMechanism
from .serial import SerialChain

AXES = {"x": 0, "y": 1, "z": 2}


@dataclass
class ClosedChain:
    """Both models of one mechanism.

    Attributes:
        mechanism: Orsino's model, coordinates ``[q#; chain joints in closure order]``.
        model: Pinocchio's fixed-base model of the spanning tree.
        constraints: one CONTACT_3D ``RigidConstraintModel`` per closure.
        chain_joints: Pinocchio joint ids of each chain, base outwards.
        actuated: Pinocchio joint ids of the actuated joints.
    """

    mechanism: ParallelMechanism
    model: pin.Model
    constraints: list
    chain_joints: list[list[int]]
    actuated: list[int]

    def pinocchio_q(self, q: np.ndarray) -> np.ndarray:
        """Pinocchio configuration (nq,) from Orsino's ``q`` (the platform coordinates dropped)."""
        out = np.zeros(self.model.nq)
        start = self.mechanism.p
        for joints in self.chain_joints:
            for j in joints:
                out[self.model.idx_qs[j]] = q[start]
                start += 1
        return out


def load_closed_chain(path: str | Path) -> ClosedChain:
    """Read a closure file and its URDF.

    Raises:
        FreefloatError: naming the file and the key for a missing URDF, an unknown frame or
            joint, a closure that is not a pair of points, or a platform coordinate not x/y/z.
    """
    path = Path(path)
    try:
        spec = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise FreefloatError(f"{path}: cannot read the closure file ({exc})") from exc
    for key in ("urdf", "actuated", "platform", "closures"):
        if key not in spec:
            raise FreefloatError(f"{path}: missing key '{key}'")
    urdf = path.parent / spec["urdf"]
    if not urdf.is_file():
        raise FreefloatError(f"{path}: 'urdf' file {urdf} does not exist")
    model = pin.buildModelFromUrdf(str(urdf))
    model.gravity = pin.Motion(np.asarray(spec.get("gravity", [0.0, 0.0, 0.0]), float), np.zeros(3))

    def frame_id(name: str, key: str) -> int:
        if not model.existFrame(name):
            raise FreefloatError(f"{path}: '{key}' names frame '{name}', which is not in {urdf.name}")
        return model.getFrameId(name)

    def joint_id(name: str) -> int:
        if not model.existJointName(name):
            raise FreefloatError(f"{path}: 'actuated' names joint '{name}', which is not in {urdf.name}")
        return model.getJointId(name)

    coords = spec["platform"].get("coordinates", ["x", "y", "z"])
    if not coords or any(c not in AXES for c in coords):
        raise FreefloatError(f"{path}: 'platform.coordinates' must be a list of x, y, z; got {coords}")
    frame_id(spec["platform"].get("frame", ""), "platform.frame")
    chains, chain_joints, constraints, tips = [], [], [], []
    for i, closure in enumerate(spec["closures"]):
        frames = closure.get("frames", [])
        if len(frames) != 2:
            raise FreefloatError(f"{path}: 'closures[{i}].frames' must name two frames, got {frames}")
        ids = [frame_id(name, f"closures[{i}].frames") for name in frames]
        placements = [(model.frames[f].parentJoint, model.frames[f].placement) for f in ids]
        constraints.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, placements[0][0], placements[0][1],
                                                    placements[1][0], placements[1][1], pin.ReferenceFrame.LOCAL))
        for f in ids:
            if model.frames[f].name not in tips:
                tips.append(model.frames[f].name)
                chain, joints = chain_from_tree(model, f)
                chains.append(chain)
                chain_joints.append(joints)
    axes = [AXES[c] for c in coords]
    p, n_tips = len(axes), len(chains)
    D = np.vstack([np.eye(p)] * n_tips)
    E = np.zeros((p * n_tips, 3 * n_tips))
    for t in range(n_tips):
        for r, axis in enumerate(axes):
            E[p * t + r, 3 * t + axis] = 1.0
    n_joints = sum(c.dof for c in chains)
    order = [j for joints in chain_joints for j in joints]
    actuated = [joint_id(name) for name in spec["actuated"]]
    mech = ParallelMechanism(chains=tuple(chains), platform_mass=np.zeros((p, p)), platform_gravity=np.zeros(p),
                             D=D, d=np.zeros(p * n_tips), E=E, F=np.zeros((p * n_tips, n_joints)),
                             actuated=np.array([p + order.index(j) for j in actuated]))
    return ClosedChain(mech, model, constraints, chain_joints, actuated)


def chain_from_tree(model: pin.Model, frame: int) -> tuple[SerialChain, list[int]]:
    """The serial chain from the root to ``frame``'s joint: placements from the tree, ``L = I``,
    inertias in the joint frames, the tip at the frame's origin. Revolute-z and prismatic-z
    joints only (what a DH-style URDF gives)."""
    joints = []
    j = model.frames[frame].parentJoint
    while j > 0:
        joints.append(j)
        j = model.parents[j]
    joints.reverse()
    prismatic = []
    for j in joints:
        kind = model.joints[j].shortname()
        if kind not in ("JointModelRZ", "JointModelPZ"):
            raise FreefloatError(f"joint '{model.names[j]}' is {kind}: closed-chain models take joints about/along z")
        prismatic.append(kind == "JointModelPZ")
    inertias = [model.inertias[j] for j in joints]
    chain = SerialChain(placement=np.array([model.jointPlacements[j].homogeneous for j in joints]),
                        link=np.tile(np.eye(4), (len(joints), 1, 1)), prismatic=np.array(prismatic),
                        mass=np.array([I.mass for I in inertias]), com=np.array([I.lever for I in inertias]),
                        inertia=np.array([I.inertia for I in inertias]), base=np.eye(4),
                        tip_point=model.frames[frame].placement.translation.copy(),
                        gravity=model.gravity.linear.copy())
    return chain, joints
