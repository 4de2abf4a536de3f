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
    coordinates = ["x", "y"]                  # which of its inertial coordinates (and "rz", its angle)
    [[closures]]
    frames = ["c1_ee", "c2_ee"]               # these two points coincide (3-D point contact)
    kind = "point"                            # or "revolute" (5-D: origins and z axes), "weld" (6-D; alias "frame")
    slip_speed = 0.01                         # optional: Coulomb friction's tanh(qdot / v_s), rad/s (m/s)
    [joints.c1_joint1]                        # optional, per joint: overrides the URDF's <dynamics>
    armature = 2.0e-3                         # rotor inertia x gear ratio^2, kg m^2 (kg on a slide)
    damping = 1.0e-3                          # viscous friction, N m s/rad (N s/m)
    friction = 0.04                           # Coulomb friction, N m (N)

A joint's friction is read from the URDF's ``<dynamics damping friction>`` (Pinocchio's
``model.damping`` and ``model.friction``) unless ``[joints]`` gives it; its armature (which a
URDF cannot state) from ``[joints]`` only. Both go into Pinocchio's model (``model.armature``,
``damping``, ``friction``) and into Orsino's chains, so the two models carry the same terms
(:mod:`freefloat.dynamics.friction` for the friction law).

:func:`read_closures` turns it into Pinocchio's fixed-base model with one
``RigidConstraintModel`` per closure (CONTACT_3D for a point, CONTACT_6D for a frame), the
independent reference. :func:`load_closed_chain` also builds Orsino's :class:`ParallelMechanism`
for mechanisms whose closures are points joining chain tips (the 5R): chains read from the tree,
one per closure frame, the platform a massless point whose listed coordinates every tip must
match; or, with the platform's angle ``rz`` among the coordinates, a planar platform whose tips
are welded to each other (the 3-RRR, :mod:`freefloat.parallel.three_rrr`). Other mechanisms with
frame closures build theirs from the same tree (:mod:`freefloat.parallel.rsu_ppap`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..dynamics.closures import ALIASES, KINDS, Closure, closure_kind
from ..dynamics.friction import SLIP_SPEED, JointFriction
from ..errors import ClosureFileError, RobotModelError, did_you_mean
from ..inputs import read_toml, reject_unknown
from ..robot.joints import slides
from ..robot.urdf_checks import check_joints, check_numbers, read_urdf
from .mechanism import AngularConstraints, ParallelMechanism
from .serial import SerialChain

AXES = {"x": 0, "y": 1, "z": 2}
#: The platform coordinate of a planar platform's angle about N's z axis, rad.
ROTATION = "rz"

#: Joint types a chain takes, with the axis they turn about or slide along (in the joint frame).
AXIS_JOINTS = {"JointModelRX": (False, 0), "JointModelRY": (False, 1), "JointModelRZ": (False, 2),
               "JointModelPX": (True, 0), "JointModelPY": (True, 1), "JointModelPZ": (True, 2)}
#: The ``[joints.<name>]`` keys of a closure file and the Pinocchio model field each sets.
JOINT_TERMS = {"armature": "armature", "damping": "damping", "friction": "friction"}
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
        constraints: Pinocchio's ``RigidConstraintModel`` (LOCAL frame) for the closures: one per
            point or weld, two per revolute (:func:`pinocchio_constraints`).
        frames: the two frame names of each closure.
        actuated: Pinocchio joint ids of the actuated joints.
        closures: one :class:`~freefloat.dynamics.closures.Closure` per closure (point, revolute or
            weld; ``frame`` is a weld).
    """

    path: Path
    spec: dict
    model: pin.Model
    constraints: list
    frames: list[tuple[str, str]]
    actuated: list[int]
    closures: list[Closure] = field(default_factory=list)

    @property
    def slip_speed(self) -> float:
        """The Coulomb friction's slip speed (``slip_speed``; default
        :data:`~freefloat.dynamics.friction.SLIP_SPEED`), rad/s or m/s."""
        return float(self.spec.get("slip_speed", SLIP_SPEED))

    @property
    def friction(self) -> JointFriction | None:
        """The tree's joint friction over its velocity coordinates (nv,), or None without any
        (what Pinocchio's plants take beside the model: it ignores ``model.damping`` and
        ``model.friction``)."""
        friction = JointFriction.of_model(self.model, self.slip_speed)
        return friction if friction else None

    @property
    def urdf(self) -> Path:
        """The spanning tree's URDF file (the ``urdf`` key, beside the closure file)."""
        return self.path.parent / self.spec["urdf"]

    def frame_id(self, name: str, key: str) -> int:
        """Frame id of ``name``, which the file's ``key`` gave.

        Raises:
            ClosureFileError: naming the file, the key and the URDF when there is no such frame.
        """
        if not self.model.existFrame(name):
            raise ClosureFileError(f"{self.path}: '{key}' names frame '{name}', which is not in {self.spec['urdf']}"
                                   f"{did_you_mean(name, [f.name for f in self.model.frames], 'frames')}")
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
        closures: the closures, one :class:`~freefloat.dynamics.closures.Closure` each.
        friction: the tree's joint friction (nv,), or None (the file's, as :attr:`Closures.friction`).
    """

    mechanism: ParallelMechanism
    model: pin.Model
    constraints: list
    joint_coordinates: dict[int, int]
    actuated: list[int]
    urdf: Path
    closures: list[Closure] = field(default_factory=list)
    friction: JointFriction | None = None

    def actuators(self) -> list[tuple[str, str]]:
        """Each actuated joint, in order: its name and its effort's unit (``"N"`` for a prismatic
        joint, ``"N m"`` otherwise)."""
        return [(self.model.names[j], "N" if slides(self.model.joints[j]) else "N m") for j in self.actuated]

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
        ClosureFileError: naming the file and the key for a missing URDF, an unknown frame or
            joint, a closure that is not a pair of frames, or an unknown closure kind.
    """
    path = Path(path)
    spec = read_toml(path, "closure file")
    _check_types(path, spec)
    urdf = path.parent / spec["urdf"]
    if not urdf.is_file():
        raise ClosureFileError(f"{path}: 'urdf' file {urdf} does not exist")
    tree = read_urdf(urdf)
    check_numbers(urdf, tree)
    check_joints(urdf, tree)
    try:
        model = pin.buildModelFromUrdf(str(urdf)) if root_joint is None else pin.buildModelFromUrdf(str(urdf), root_joint)
    except (RuntimeError, ValueError) as exc:
        raise RobotModelError(f"{urdf}: Pinocchio's URDF parser refuses it ({exc})") from exc
    model.gravity = pin.Motion(np.asarray(spec.get("gravity", [0.0, 0.0, 0.0]), float), np.zeros(3))
    _set_joint_terms(path, spec.get("joints", {}), model)
    out = Closures(path, spec, model, [], [], [])
    for name in spec["actuated"]:
        if not model.existJointName(name):
            raise ClosureFileError(f"{path}: 'actuated' names joint '{name}', which is not in {urdf.name}"
                                   f"{did_you_mean(name, model.names[1:], 'joints')}")
        out.actuated.append(model.getJointId(name))
    out.frame_id(spec["platform"].get("frame", ""), "platform.frame")
    for i, closure in enumerate(spec["closures"]):
        frames, kind = closure.get("frames", []), closure_kind(closure.get("kind", "point"))
        if len(frames) != 2:
            raise ClosureFileError(f"{path}: 'closures[{i}].frames' must name two frames, got {frames}")
        if kind is None:
            raise ClosureFileError(f"{path}: 'closures[{i}].kind' is '{closure['kind']}'"
                                   f"{did_you_mean(closure['kind'], (*KINDS, *ALIASES))}")
        if frames[0] == frames[1]:
            raise ClosureFileError(f"{path}: 'closures[{i}].frames' joins frame '{frames[0]}' to itself; a closure "
                                   "joins two different frames")
        placements = [model.frames[out.frame_id(name, f"closures[{i}].frames")] for name in frames]
        out.closures.append(Closure(f"closures[{i}]", kind, placements[0].parentJoint, placements[0].placement,
                                    placements[1].parentJoint, placements[1].placement, tuple(frames)))
        out.constraints.extend(pinocchio_constraints(model, out.closures[-1]))
        out.frames.append(tuple(frames))
    return out


def _set_joint_terms(path: Path, joints: dict, model: pin.Model) -> None:
    """Write the closure file's ``[joints.<name>]`` armature, damping and friction into the model's
    fields (over the URDF's ``<dynamics>``).

    Raises:
        ClosureFileError: naming the file and the key for an unknown joint (with the nearest name),
            a joint with more than one coordinate, or a value that is not a finite number >= 0.
    """
    names = [model.names[j] for j in range(1, model.njoints)]
    for name, terms in joints.items():
        if not model.existJointName(name):
            raise ClosureFileError(f"{path}: '[joints.{name}]' names no joint of the URDF"
                                   f"{did_you_mean(name, names, 'joints')}")
        j = model.getJointId(name)
        if model.nvs[j] != 1:
            raise ClosureFileError(f"{path}: '[joints.{name}]': joint '{name}' has {model.nvs[j]} coordinates; armature "
                                   "and friction are for joints of one")
        for key, value in terms.items():
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value) and value >= 0):
                raise ClosureFileError(f"{path}: 'joints.{name}.{key}' must be a finite number >= 0, got {value!r}")
            getattr(model, JOINT_TERMS[key])[model.idx_vs[j]] = float(value)


#: Pinocchio's contact for each closure kind it has; a revolute closure is two point contacts on its
#: hinge, :data:`HINGE_SPAN` m apart (the same motions allowed, one row redundant).
PINOCCHIO_CONTACTS = {"point": pin.ContactType.CONTACT_3D, "weld": pin.ContactType.CONTACT_6D}
HINGE_SPAN = 0.1


def pinocchio_constraints(model: pin.Model, closure: Closure) -> list:
    """Pinocchio's ``RigidConstraintModel`` (LOCAL) equivalent to ``closure``: one contact for a
    point or weld, two point contacts on the hinge (frame 1's z axis) for a revolute."""
    def contact(kind: str, lift: float) -> pin.RigidConstraintModel:
        shift = pin.SE3(np.eye(3), np.array([0.0, 0.0, lift]))
        return pin.RigidConstraintModel(PINOCCHIO_CONTACTS[kind], model, closure.joint1, closure.placement1 * shift,
                                        closure.joint2, closure.placement2 * shift, pin.ReferenceFrame.LOCAL)
    if closure.kind.name == "revolute":
        return [contact("point", 0.0), contact("point", HINGE_SPAN)]
    return [contact(closure.kind.name, 0.0)]


def _check_types(path: Path, spec: dict) -> None:
    """The closure file's keys have the types :func:`read_closures` reads.

    Raises:
        ClosureFileError: naming the file and the key.
    """
    reject_unknown(f"{path}: ", spec, ("urdf", "gravity", "actuated", "platform", "closures", "slip_speed", "joints"))
    for key in ("urdf", "actuated", "platform", "closures"):
        if key not in spec:
            raise ClosureFileError(f"{path}: missing key '{key}'")
    expected = {"urdf": (str, "a file name"), "platform": (dict, "a table"), "closures": (list, "an array of tables")}
    for key, (kind, what) in expected.items():
        if not isinstance(spec[key], kind):
            raise ClosureFileError(f"{path}: '{key}' must be {what}, got {spec[key]!r}")
    if not isinstance(spec["actuated"], list) or not all(isinstance(n, str) for n in spec["actuated"]):
        raise ClosureFileError(f"{path}: 'actuated' must be a list of joint names, got {spec['actuated']!r}")
    reject_unknown(f"{path}: ", spec["platform"], ("frame", "coordinates"), "platform")
    if not isinstance(spec["platform"].get("frame", ""), str):
        raise ClosureFileError(f"{path}: 'platform.frame' must be a frame name, got {spec['platform']['frame']!r}")
    coordinates = spec["platform"].get("coordinates", ["x", "y", "z"])
    if not isinstance(coordinates, list) or not all(isinstance(c, str) for c in coordinates):
        raise ClosureFileError(f"{path}: 'platform.coordinates' must be a list of axis names, got {coordinates!r}")
    for i, closure in enumerate(spec["closures"]):
        if not isinstance(closure, dict) or not isinstance(closure.get("kind", "point"), str) or not (
                isinstance(closure.get("frames", []), list) and all(isinstance(f, str) for f in closure.get("frames", []))):
            raise ClosureFileError(f"{path}: 'closures[{i}]' must be a table with 'frames' (two frame names) and "
                                   f"'kind' (a name), got {closure!r}")
        reject_unknown(f"{path}: ", closure, ("frames", "kind"), f"closures[{i}]")
    joints = spec.get("joints", {})
    if not isinstance(joints, dict) or not all(isinstance(t, dict) for t in joints.values()):
        raise ClosureFileError(f"{path}: 'joints' must be a table of tables ([joints.<joint name>]), got {joints!r}")
    for name, terms in joints.items():
        reject_unknown(f"{path}: ", terms, JOINT_TERMS, f"joints.{name}")
    slip = spec.get("slip_speed", SLIP_SPEED)
    if not (isinstance(slip, (int, float)) and not isinstance(slip, bool) and np.isfinite(slip) and slip > 0):
        raise ClosureFileError(f"{path}: 'slip_speed' must be a positive speed (rad/s or m/s), got {slip!r}")
    gravity = spec.get("gravity", [0.0, 0.0, 0.0])
    if not (isinstance(gravity, list) and len(gravity) == 3 and all(
            isinstance(g, (int, float)) and not isinstance(g, bool) and np.isfinite(g) for g in gravity)):
        raise ClosureFileError(f"{path}: 'gravity' must be three finite numbers (m/s^2), got {gravity!r}")


def load_closed_chain(path: str | Path) -> ClosedChain:
    """Both models of a mechanism whose closures join chain tips at the platform point (the 5R),
    or weld chain tips to each other in a planar loop about N's z axis with the platform's angle
    ``rz`` among its coordinates (a rotating platform, the 3-RRR): one angular row per tip,
    ``P`` on ``rz`` and ``Q`` on the tip's angular velocity about z (eqs 101-102), the angle of
    every tip frame's x axis from N's x axis.

    Raises:
        ClosureFileError: as :func:`read_closures`, and for a weld closure without ``rz`` (or ``rz``
            with another closure kind), a revolute or welded loop that is not planar, a welded tip
            frame whose z axis is not N's, or a platform coordinate not x/y/z/rz.
    """
    closures = read_closures(path)
    model, spec = closures.model, closures.spec
    coords = spec["platform"].get("coordinates", ["x", "y", "z"])
    if not coords or any(c not in AXES and c != ROTATION for c in coords) or coords.count(ROTATION) > 1:
        raise ClosureFileError(f"{closures.path}: 'platform.coordinates' must be a list of x, y, z (and at most one "
                               f"'{ROTATION}', the platform's angle about z, with weld closures); got {coords}")
    rotates = ROTATION in coords
    for closure in closures.closures:
        if (closure.kind.name == "weld") != rotates:
            raise ClosureFileError(
                f"{closures.path}: '{closure.name}.kind' is a weld; tip-to-tip mechanisms take point or planar revolute "
                "closures, or weld closures of a platform whose angle 'rz' is among 'platform.coordinates'"
                if not rotates else f"{closures.path}: 'platform.coordinates' has '{ROTATION}', the platform's angle, but "
                f"'{closure.name}.kind' is {closure.kind.name}: a rotating platform's tips are welded to each other "
                "(kind = \"weld\")")
    chains, chain_joints, tips = [], [], []
    for pair in closures.frames:
        for name in pair:
            if name not in tips:
                tips.append(name)
                chain, joints = chain_from_tree(model, model.getFrameId(name), closures.slip_speed)
                chains.append(chain)
                chain_joints.append(joints)
    order = [j for joints in chain_joints for j in joints]
    shared = sorted({model.names[j] for j in order if order.count(j) > 1})
    if shared:
        raise ClosureFileError(f"{closures.path}: joints {', '.join(shared)} lie on more than one chain to a closure "
                               "frame; tip-to-tip mechanisms need chains that share no joint")
    loose = [model.names[j] for j in range(1, model.njoints) if j not in order]
    if loose:
        raise ClosureFileError(f"{closures.path}: joints {', '.join(loose)} of {closures.urdf.name} lie on no chain from "
                               "the root to a closure frame ('closures' frames)")
    for closure in closures.closures:
        if closure.kind.name != "point":
            _check_planar_hinge(closures, closure, order)
    if rotates:
        _check_tips_turn_about_z(closures, tips)
    p, n_tips = len(coords), len(chains)
    moves = [i for i, c in enumerate(coords) if c in AXES]
    D = np.vstack([np.eye(p)[moves]] * n_tips)
    E = np.zeros((len(moves) * n_tips, 3 * n_tips))
    for t in range(n_tips):
        for r, i in enumerate(moves):
            E[len(moves) * t + r, 3 * t + AXES[coords[i]]] = 1.0
    angular = None
    if rotates:  # eq 101: P rz' - Q w = 0 per tip, Q reading the tip's angular velocity about z
        P = np.zeros((n_tips, p))
        P[:, coords.index(ROTATION)] = 1.0
        Q = np.zeros((n_tips, 3 * n_tips))
        Q[np.arange(n_tips), 3 * np.arange(n_tips) + 2] = 1.0
        # the chain's last link turned by the tip frame's fixed rotation is the tip frame, Rz(rz)
        reference = np.array([model.frames[model.getFrameId(name)].placement.rotation.T for name in tips])
        angular = AngularConstraints(P=P, Q=Q, R=np.zeros((n_tips, len(order))), reference=reference,
                                     offset=np.zeros(n_tips))
    mech = ParallelMechanism(chains=tuple(chains), platform_mass=np.zeros((p, p)), platform_gravity=np.zeros(p),
                             D=D, d=np.zeros(len(D)), E=E, F=np.zeros((len(D), len(order))),
                             actuated=np.array([p + order.index(j) for j in closures.actuated]), angular=angular)
    return ClosedChain(mech, model, closures.constraints, {j: p + i for i, j in enumerate(order)}, closures.actuated,
                       closures.urdf, closures.closures, closures.friction)


def _check_planar_hinge(closures: Closures, closure: Closure, joints: list[int]) -> None:
    """A revolute or weld closure of a tip-to-tip mechanism must close a planar loop: every
    revolute joint of its chains turns about the plane's normal (the hinge's direction, or N's z
    for a weld) and every prismatic one slides across it (checked at the neutral pose, which these
    joints keep). Its rows out of the plane (three of a revolute's five, three of a weld's six) are
    then always met, and Orsino's point (and angle) model of the tips is exact.

    Raises:
        ClosureFileError: naming the closure and the first joint out of the plane.
    """
    model, data = closures.model, closures.model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    revolute = closure.kind.name == "revolute"
    normal = (data.oMi[closure.joint1] * closure.placement1).rotation[:, 2] if revolute else np.array([0.0, 0.0, 1.0])
    for j in joints:
        slides, axis = AXIS_JOINTS[model.joints[j].shortname()]
        direction = data.oMi[j].rotation[:, axis]
        off = abs(direction @ normal) if slides else np.linalg.norm(np.cross(direction, normal))
        if off > 1e-9:
            raise ClosureFileError(f"{closures.path}: '{closure.name}' is a {closure.kind.name} closure, but joint "
                                   f"'{model.names[j]}' {'slides along' if slides else 'turns about'} a direction "
                                   f"out of {'its hinge' if revolute else 'the xy plane'}'s plane; tip-to-tip mechanisms "
                                   f"take {closure.kind.name} closures of planar loops only")


def _check_tips_turn_about_z(closures: Closures, tips: list[str]) -> None:
    """Each welded tip frame of a rotating platform has N's z as its z axis (at the neutral pose,
    which the planar loop keeps): its orientation is then ``Rz(angle)``, the angle the ``rz`` rows read.

    Raises:
        ClosureFileError: naming the first tip frame whose z axis is not N's z.
    """
    model, data = closures.model, closures.model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    for name in tips:
        z = data.oMf[model.getFrameId(name)].rotation[:, 2]
        if abs(z[2] - 1.0) > 1e-9:
            raise ClosureFileError(f"{closures.path}: frame '{name}' has its z axis along {np.round(z, 6).tolist()}; the "
                                   f"tips of a platform with an angle '{ROTATION}' need N's z axis (0, 0, 1) as theirs")


def chain_from_tree(model: pin.Model, frame: int, slip_speed: float = SLIP_SPEED) -> tuple[SerialChain, list[int]]:
    """The serial chain from the root to ``frame``'s joint: placements from the tree, inertias
    in the joint frames, the tip at the frame's origin, each joint's armature, damping and
    friction from ``model.armature``, ``damping``, ``friction`` (Coulomb regularised with
    ``slip_speed``). Revolute and prismatic joints along x,
    y or z of their frames; an x or y axis is turned onto Orsino's z by ``P_i = placement T``,
    ``L_i = T^-1`` (``T`` in :data:`Z_TO_AXIS`).

    Raises:
        ClosureFileError: naming a joint of another type.
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
            raise RobotModelError(f"joint '{model.names[j]}' is {kind}: closed-chain models take revolute or prismatic "
                                  f"joints along x, y or z of their frames")
        slides, axis = AXIS_JOINTS[kind]
        turn = pin.SE3(Z_TO_AXIS[axis], np.zeros(3))
        placement.append((model.jointPlacements[j] * turn).homogeneous)
        link.append(turn.inverse().homogeneous)
        prismatic.append(slides)
    inertias = [model.inertias[j] for j in joints]
    rows = [model.idx_vs[j] for j in joints]
    armature = np.array(model.armature)[rows]
    friction = JointFriction.of_model(model, slip_speed)[rows]
    chain = SerialChain(placement=np.array(placement), link=np.array(link), prismatic=np.array(prismatic),
                        mass=np.array([I.mass for I in inertias]), com=np.array([I.lever for I in inertias]),
                        inertia=np.array([I.inertia for I in inertias]), base=np.eye(4),
                        tip_point=model.frames[frame].placement.translation.copy(),
                        gravity=model.gravity.linear.copy(), armature=armature if armature.any() else None,
                        friction=friction if friction else None)
    return chain, joints
