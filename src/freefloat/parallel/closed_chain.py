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
    kind = "point"                            # or "frame": the two frames coincide (6-D)

:func:`read_closures` turns it into Pinocchio's fixed-base model with one
``RigidConstraintModel`` per closure (CONTACT_3D for a point, CONTACT_6D for a frame), the
independent reference. :func:`load_closed_chain` also builds Orsino's :class:`ParallelMechanism`
for mechanisms whose closures are points joining chain tips (the 5R): chains read from the tree,
one per closure frame, the platform a massless point whose listed coordinates every tip must
match. Mechanisms with frame closures build theirs from the same tree
(:mod:`freefloat.parallel.rsu_ppap`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import FreefloatError
from ..inputs import read_toml, reject_unknown
from ..robot.urdf_checks import check_joints, check_numbers, read_urdf
from .mechanism import ParallelMechanism
from .serial import SerialChain

AXES = {"x": 0, "y": 1, "z": 2}


KINDS = {"point": pin.ContactType.CONTACT_3D, "frame": pin.ContactType.CONTACT_6D}
#: Joint types a chain takes, with the axis they turn about or slide along (in the joint frame).
AXIS_JOINTS = {"JointModelRX": (False, 0), "JointModelRY": (False, 1), "JointModelRZ": (False, 2),
               "JointModelPX": (True, 0), "JointModelPY": (True, 1), "JointModelPZ": (True, 2)}
#: Rotations taking z onto x, y, z: a joint about axis a is ``T Rz(q) T^-1``.
Z_TO_AXIS = (pin.rpy.rpyToMatrix(0.0, np.pi / 2, 0.0), pin.rpy.rpyToMatrix(-np.pi / 2, 0.0, 0.0), np.eye(3))


@dataclass
class Closures:
    """Pinocchio's side of a closure file.

    Attributes:
        path: the closure file.
        spec: its parsed content.
        model: Pinocchio's model of the spanning tree, gravity set: fixed-base, or on the root
            joint :func:`read_closures` was given.
        constraints: one ``RigidConstraintModel`` per closure (LOCAL frame).
        frames: the two frame names of each closure.
        actuated: Pinocchio joint ids of the actuated joints.
    """

    path: Path
    spec: dict
    model: pin.Model
    constraints: list
    frames: list[tuple[str, str]]
    actuated: list[int]

    @property
    def urdf(self) -> Path:
        """The spanning tree's URDF file (the ``urdf`` key, beside the closure file)."""
        return self.path.parent / self.spec["urdf"]

    def frame_id(self, name: str, key: str) -> int:
        """Frame id of ``name``, which the file's ``key`` gave.

        Raises:
            FreefloatError: naming the file, the key and the URDF when there is no such frame.
        """
        if not self.model.existFrame(name):
            raise FreefloatError(f"{self.path}: '{key}' names frame '{name}', which is not in {self.spec['urdf']}")
        return self.model.getFrameId(name)


@dataclass
class ClosedChain:
    """Both models of one mechanism.

    Attributes:
        mechanism: Orsino's model, coordinates ``[q#; chain joints in closure order]``.
        model: Pinocchio's fixed-base model of the spanning tree.
        constraints: one ``RigidConstraintModel`` per closure.
        joint_coordinates: Pinocchio joint id -> index of its coordinate in Orsino's ``q``.
        actuated: Pinocchio joint ids of the actuated joints.
        urdf: the spanning tree's URDF file.
    """

    mechanism: ParallelMechanism
    model: pin.Model
    constraints: list
    joint_coordinates: dict[int, int]
    actuated: list[int]
    urdf: Path

    def pinocchio_q(self, q: np.ndarray) -> np.ndarray:
        """Pinocchio configuration (nq,) from Orsino's ``q`` (the platform coordinates dropped);
        also maps rates and accelerations (every joint has one coordinate)."""
        out = np.zeros(self.model.nq)
        for j, i in self.joint_coordinates.items():
            out[self.model.idx_qs[j]] = q[i]
        return out


def read_closures(path: str | Path, root_joint: pin.JointModel | None = None) -> Closures:
    """Read a closure file and its URDF into Pinocchio's constrained model.

    Args:
        root_joint: None for a fixed base (the URDF's root link is the world frame); a planar or
            free-flyer joint model to put the tree on a moving base (its joint 1, named
            ``root_joint``; :mod:`freefloat.parallel.free_base`).

    Raises:
        FreefloatError: naming the file and the key for a missing URDF, an unknown frame or
            joint, a closure that is not a pair of frames, or an unknown closure kind.
    """
    path = Path(path)
    spec = read_toml(path, "closure file")
    _check_types(path, spec)
    urdf = path.parent / spec["urdf"]
    if not urdf.is_file():
        raise FreefloatError(f"{path}: 'urdf' file {urdf} does not exist")
    tree = read_urdf(urdf)
    check_numbers(urdf, tree)
    check_joints(urdf, tree)
    try:
        model = pin.buildModelFromUrdf(str(urdf)) if root_joint is None else pin.buildModelFromUrdf(str(urdf), root_joint)
    except (RuntimeError, ValueError) as exc:
        raise FreefloatError(f"{urdf}: Pinocchio's URDF parser refuses it ({exc})") from exc
    model.gravity = pin.Motion(np.asarray(spec.get("gravity", [0.0, 0.0, 0.0]), float), np.zeros(3))
    out = Closures(path, spec, model, [], [], [])
    for name in spec["actuated"]:
        if not model.existJointName(name):
            raise FreefloatError(f"{path}: 'actuated' names joint '{name}', which is not in {urdf.name}")
        out.actuated.append(model.getJointId(name))
    out.frame_id(spec["platform"].get("frame", ""), "platform.frame")
    for i, closure in enumerate(spec["closures"]):
        frames, kind = closure.get("frames", []), closure.get("kind", "point")
        if len(frames) != 2:
            raise FreefloatError(f"{path}: 'closures[{i}].frames' must name two frames, got {frames}")
        if kind not in KINDS:
            raise FreefloatError(f"{path}: 'closures[{i}].kind' must be one of {list(KINDS)}, got '{kind}'")
        if frames[0] == frames[1]:
            raise FreefloatError(f"{path}: 'closures[{i}].frames' joins frame '{frames[0]}' to itself; a closure "
                                 "joins two different frames")
        placements = [model.frames[out.frame_id(name, f"closures[{i}].frames")] for name in frames]
        out.constraints.append(pin.RigidConstraintModel(KINDS[kind], model, placements[0].parentJoint, placements[0].placement,
                                                        placements[1].parentJoint, placements[1].placement,
                                                        pin.ReferenceFrame.LOCAL))
        out.frames.append(tuple(frames))
    return out


def _check_types(path: Path, spec: dict) -> None:
    """The closure file's keys have the types :func:`read_closures` reads.

    Raises:
        FreefloatError: naming the file and the key.
    """
    reject_unknown(f"{path}: ", spec, ("urdf", "gravity", "actuated", "platform", "closures"))
    for key in ("urdf", "actuated", "platform", "closures"):
        if key not in spec:
            raise FreefloatError(f"{path}: missing key '{key}'")
    expected = {"urdf": (str, "a file name"), "platform": (dict, "a table"), "closures": (list, "an array of tables")}
    for key, (kind, what) in expected.items():
        if not isinstance(spec[key], kind):
            raise FreefloatError(f"{path}: '{key}' must be {what}, got {spec[key]!r}")
    if not isinstance(spec["actuated"], list) or not all(isinstance(n, str) for n in spec["actuated"]):
        raise FreefloatError(f"{path}: 'actuated' must be a list of joint names, got {spec['actuated']!r}")
    reject_unknown(f"{path}: ", spec["platform"], ("frame", "coordinates"), "platform")
    if not isinstance(spec["platform"].get("frame", ""), str):
        raise FreefloatError(f"{path}: 'platform.frame' must be a frame name, got {spec['platform']['frame']!r}")
    coordinates = spec["platform"].get("coordinates", ["x", "y", "z"])
    if not isinstance(coordinates, list) or not all(isinstance(c, str) for c in coordinates):
        raise FreefloatError(f"{path}: 'platform.coordinates' must be a list of axis names, got {coordinates!r}")
    for i, closure in enumerate(spec["closures"]):
        if not isinstance(closure, dict) or not isinstance(closure.get("kind", "point"), str) or not (
                isinstance(closure.get("frames", []), list) and all(isinstance(f, str) for f in closure.get("frames", []))):
            raise FreefloatError(f"{path}: 'closures[{i}]' must be a table with 'frames' (two frame names) and "
                                 f"'kind' (a name), got {closure!r}")
        reject_unknown(f"{path}: ", closure, ("frames", "kind"), f"closures[{i}]")
    gravity = spec.get("gravity", [0.0, 0.0, 0.0])
    if not (isinstance(gravity, list) and len(gravity) == 3 and all(
            isinstance(g, (int, float)) and not isinstance(g, bool) and np.isfinite(g) for g in gravity)):
        raise FreefloatError(f"{path}: 'gravity' must be three finite numbers (m/s^2), got {gravity!r}")


def load_closed_chain(path: str | Path) -> ClosedChain:
    """Both models of a mechanism whose closures join chain tips at the platform point (the 5R).

    Raises:
        FreefloatError: as :func:`read_closures`, and for a frame closure or a platform
            coordinate not x/y/z.
    """
    closures = read_closures(path)
    model, spec = closures.model, closures.spec
    coords = spec["platform"].get("coordinates", ["x", "y", "z"])
    if not coords or any(c not in AXES for c in coords):
        raise FreefloatError(f"{closures.path}: 'platform.coordinates' must be a list of x, y, z; got {coords}")
    for i, closure in enumerate(spec["closures"]):
        if closure.get("kind", "point") != "point":
            raise FreefloatError(f"{closures.path}: 'closures[{i}].kind' is '{closure['kind']}'; tip-to-tip mechanisms "
                                 "take point closures (frame closures need their own builder, see rsu_ppap)")
    chains, chain_joints, tips = [], [], []
    for pair in closures.frames:
        for name in pair:
            if name not in tips:
                tips.append(name)
                chain, joints = chain_from_tree(model, model.getFrameId(name))
                chains.append(chain)
                chain_joints.append(joints)
    order = [j for joints in chain_joints for j in joints]
    shared = sorted({model.names[j] for j in order if order.count(j) > 1})
    if shared:
        raise FreefloatError(f"{closures.path}: joints {', '.join(shared)} lie on more than one chain to a closure "
                             "frame; tip-to-tip mechanisms need chains that share no joint")
    loose = [model.names[j] for j in range(1, model.njoints) if j not in order]
    if loose:
        raise FreefloatError(f"{closures.path}: joints {', '.join(loose)} of {closures.urdf.name} lie on no chain from "
                             "the root to a closure frame ('closures' frames)")
    axes = [AXES[c] for c in coords]
    p, n_tips = len(axes), len(chains)
    D = np.vstack([np.eye(p)] * n_tips)
    E = np.zeros((p * n_tips, 3 * n_tips))
    for t in range(n_tips):
        for r, axis in enumerate(axes):
            E[p * t + r, 3 * t + axis] = 1.0
    mech = ParallelMechanism(chains=tuple(chains), platform_mass=np.zeros((p, p)), platform_gravity=np.zeros(p),
                             D=D, d=np.zeros(p * n_tips), E=E, F=np.zeros((p * n_tips, len(order))),
                             actuated=np.array([p + order.index(j) for j in closures.actuated]))
    return ClosedChain(mech, model, closures.constraints, {j: p + i for i, j in enumerate(order)}, closures.actuated,
                       closures.urdf)


def chain_from_tree(model: pin.Model, frame: int) -> tuple[SerialChain, list[int]]:
    """The serial chain from the root to ``frame``'s joint: placements from the tree, inertias
    in the joint frames, the tip at the frame's origin. Revolute and prismatic joints along x,
    y or z of their frames; an x or y axis is turned onto Orsino's z by ``P_i = placement T``,
    ``L_i = T^-1`` (``T`` in :data:`Z_TO_AXIS`).

    Raises:
        FreefloatError: naming a joint of another type.
    """
    joints = []
    j = model.frames[frame].parentJoint
    while j > 0:
        joints.append(j)
        j = model.parents[j]
    joints.reverse()
    placement, link, prismatic = [], [], []
    for j in joints:
        kind = model.joints[j].shortname()
        if kind not in AXIS_JOINTS:
            raise FreefloatError(f"joint '{model.names[j]}' is {kind}: closed-chain models take revolute or prismatic "
                                 f"joints along x, y or z of their frames")
        slides, axis = AXIS_JOINTS[kind]
        turn = pin.SE3(Z_TO_AXIS[axis], np.zeros(3))
        placement.append((model.jointPlacements[j] * turn).homogeneous)
        link.append(turn.inverse().homogeneous)
        prismatic.append(slides)
    inertias = [model.inertias[j] for j in joints]
    chain = SerialChain(placement=np.array(placement), link=np.array(link), prismatic=np.array(prismatic),
                        mass=np.array([I.mass for I in inertias]), com=np.array([I.lever for I in inertias]),
                        inertia=np.array([I.inertia for I in inertias]), base=np.eye(4),
                        tip_point=model.frames[frame].placement.translation.copy(),
                        gravity=model.gravity.linear.copy())
    return chain, joints
