"""Load any URDF as a free-floating robot.

The URDF is read by :mod:`.urdf_model` and checked here (urdfdom accepts files that cannot be a
floating-base tree); Pinocchio then builds the model with a floating root joint on the root
link. The base reference point is the root link's centre of mass, as in the dissertation (sec
3.1.2) and in SPART.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import os
import re
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..arguments import MAX_MAGNITUDE, real_array
from ..errors import FreefloatNote, FreefloatWarning, InvalidArgument, RobotModelError, did_you_mean
from .catalog import example_robot_data_share, find_robot, is_name  # noqa: F401  (the share: imported from here)
from .inertias import balanced
from .load_cache import CheckedLoad, cache_folder, entry_inputs
from .load_cache import read as read_cached
from .load_cache import write as write_cached
from .robot import BASE_DOFS, Arm, Robot
from .urdf_checks import (
    check_joints,
    check_mass_matrix,
    check_memory,
    check_numbers,
    compare_friction,
    compare_parses,
    physics_notes,
    read_urdf,
)
from .urdf_model import Joint, UrdfModel, parse_urdf
from .visuals import missing_meshes, missing_note, visual_meshes
from .visuals import visual_model as build_visuals

MOVABLE = {"revolute", "continuous", "prismatic"}
SUPPORTED = MOVABLE | {"fixed"}
ROOT_JOINT_NAME = "base"
#: A gripper part is at most this many movable joints below its hand.
GRIPPER_JOINTS = 2
#: Names of gripper parts.
GRIPPER_WORDS = re.compile(r"finger|gripper|thumb|jaw|claw", re.IGNORECASE)
BASE_COM_FRAME = "base_com"
#: What ``load_robot(inertias=...)`` takes: the URDF's inertias, or a balanced copy of them.
INERTIAS = ("as_given", "balanced")


#: The store of :func:`remembered_loads` in effect (None: every call loads).
_remembered: contextvars.ContextVar[dict | None] = contextvars.ContextVar("remembered_loads", default=None)


@contextlib.contextmanager
def remembered_loads(store: dict) -> Iterator[None]:
    """Within the block, :func:`load_robot` loads and checks a file once per ``store``: a call with
    the same arguments on the same file, unchanged (size and modification time), gets a copy of
    the robot loaded before (its own ``pin.Model``) and the same warnings. For a worker that runs
    many scenes on one robot (``freefloat batch``: about 12 ms of parsing and checks per run of the
    four-arm robot); ``store`` (a dict the caller keeps) lives as long as the caller wants."""
    token = _remembered.set(store)
    try:
        yield
    finally:
        _remembered.reset(token)


def load_robot(
    path: str | Path,
    base: str = "free",
    end_effectors: list[str] | tuple[str, ...] | None = None,
    gravity: tuple[float, float, float] | np.ndarray = (0.0, 0.0, 0.0),
    visuals: bool = True,
    inertias: str = "as_given",
    cache: bool = True,
) -> Robot:
    """Load a URDF as a free-floating robot.

    Args:
        path: URDF file, or the name of a robot freefloat knows (``"ur5"``, ``"solo12"``, see
            :mod:`freefloat.robot.catalog`).
        base: floating root joint, ``"free"`` (6 DOF) or ``"planar"`` (x, y, yaw in the inertial
            xy-plane: model no more than a planar scene needs).
        end_effectors: link names to use as end-effectors; by default every leaf link reached
            through at least one movable joint, in Pinocchio's depth-first order, a gripper's
            fingers and a wrist's tool and sensor frames counting as one (see
            :func:`_merge_grippers`).
        gravity: gravity vector in the inertial frame, m/s^2 (space: zero, the default).
        visuals: build the visual geometry (meshes through ``package://`` or relative paths).
        inertias: ``"as_given"``, or ``"balanced"``: every body's least principal moments raised
            until ``I1 + I2 >= I3`` holds, mass and CoM kept (a physical copy of a URDF whose
            inertias no rigid body has, :func:`freefloat.robot.inertias.balanced`).
        cache: read and write the on-disk cache of checked loads (:mod:`.load_cache`, keyed by the
            file's content): a process that loads an unchanged file again skips the parse, the
            checks and the model build, and warns the same. Off also with ``FREEFLOAT_CACHE_DIR=""``.

    Returns:
        The :class:`~freefloat.robot.Robot`.

    Raises:
        InvalidArgument: for a path that is no path or name, or a gravity that is not three finite
            numbers of at most 1e15.
        RobotModelError: naming the file and the link or joint, when the file cannot be a
            floating-base tree (missing parent, two roots, a loop, negative mass, an inertia that is
            not positive definite, an unsupported joint type) or an end-effector does not exist.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise InvalidArgument(f"load_robot: 'path' must be a URDF file or a robot's name, got {path!r}")
    path = Path(path)
    try:
        gravity = real_array("gravity", gravity, (3,))
    except InvalidArgument:
        raise InvalidArgument(f"load_robot: 'gravity' must be three finite numbers (m/s^2) of at most "
                              f"{MAX_MAGNITUDE:g}, got {gravity!r}") from None
    if base not in BASE_DOFS:
        raise RobotModelError(f"base must be one of {sorted(BASE_DOFS)}, got {base!r}")
    if inertias not in INERTIAS:
        raise InvalidArgument(f"load_robot: 'inertias' must be one of {', '.join(INERTIAS)}, got {inertias!r}")
    if isinstance(end_effectors, str):
        raise RobotModelError(f"end_effectors must be a list of link names, got the string {end_effectors!r}; "
                              f"write [{end_effectors!r}]")
    if not path.is_file() and is_name(path):
        path = find_robot(str(path))
    if not path.is_file():
        raise RobotModelError(f"{path}: no such URDF file")
    store, key = _remembered.get(), None
    if store is not None:
        stat = path.stat()
        key = (str(path.resolve()), stat.st_mtime_ns, stat.st_size, base,
               None if end_effectors is None else tuple(end_effectors), tuple(gravity.tolist()), visuals, inertias)
        if key in store:
            robot = store[key]
            for note in robot.warnings:
                warnings.warn(note, FreefloatWarning, stacklevel=2)
            for note in robot.notes:
                warnings.warn(note, FreefloatNote, stacklevel=2)
            return dataclasses.replace(robot, model=pin.Model(robot.model))
    robot = _load(path, base, end_effectors, gravity, visuals, inertias, cache)
    if store is not None:
        store[key] = dataclasses.replace(robot, model=pin.Model(robot.model))
    return robot


def _load(path: Path, base: str, end_effectors: list[str] | tuple[str, ...] | None, gravity: np.ndarray, visuals: bool,
          inertias: str, cache: bool) -> Robot:
    """:func:`load_robot` of a checked path and arguments: the checked model from the on-disk cache
    (:mod:`.load_cache`) or from the file, then what depends on other files (meshes)."""
    raw = path.read_bytes()
    folder = cache_folder() if cache else None
    inputs = entry_inputs(raw, path, base, end_effectors, inertias) if folder is not None else {}
    checked = read_cached(folder, inputs) if folder is not None else None
    xml = None
    if checked is None:
        checked, xml = _check(path, raw, base, end_effectors, inertias)
        if folder is not None:
            write_cached(folder, inputs, checked)
    else:
        check_memory(path, checked.model.nv - BASE_DOFS[base])
    model = checked.model
    model.gravity = pin.Motion(np.asarray(gravity, dtype=float), np.zeros(3))

    notes = list(checked.warnings)
    missing = missing_meshes(path, list(checked.meshes))
    if missing:
        notes.append(missing_note(path, missing))
    if visuals:
        xml = xml if xml is not None else _pinocchio_xml(read_urdf(path, raw))[0]
        visual_model = build_visuals(path, model, ET.fromstring(xml), missing, notes)
    else:
        visual_model = None
    for note in notes:
        warnings.warn(note, FreefloatWarning, stacklevel=3)
    for note in checked.notes:
        warnings.warn(note, FreefloatNote, stacklevel=3)
    return Robot(
        model=model,
        visual_model=visual_model,
        urdf_path=path,
        base_link=checked.base_link,
        base=base,
        base_com=checked.base_com,
        base_com_rotation=checked.base_com_rotation,
        end_effectors=checked.end_effectors,
        arms=tuple(arm_of(model, name) for name in checked.end_effectors),
        link_coms=checked.link_coms,
        warnings=tuple(notes),
        notes=checked.notes,
        missing_meshes=tuple(missing),
    )


def _check(path: Path, raw: bytes, base: str, end_effectors: list[str] | tuple[str, ...] | None,
           inertias: str) -> tuple[CheckedLoad, str]:
    """Parse, check and build the URDF ``raw`` (the bytes of ``path``): what the cache keeps, and
    the URDF text given to Pinocchio (for the visual geometry)."""
    tree = read_urdf(path, raw)
    check_numbers(path, tree)
    check_joints(path, tree)
    urdf = parse_urdf(path, tree)

    notes: list[str] = []
    root = _check_tree(path, urdf)
    _check_inertias(path, urdf, root, notes)
    physics, facts = physics_notes(path, urdf, triangle=inertias == "as_given")
    notes += physics
    mimics = [f"'{j.name}' (<mimic joint=\"{j.mimic.joint}\">)" for j in urdf.joints if j.mimic is not None]
    if mimics:
        notes.append(f"{path.name}: joint(s) {', '.join(mimics)} are loaded as independent joints: freefloat does not "
                     "enforce <mimic> (drive them together yourself, or remove the tag)")
    xml, unlimited = _pinocchio_xml(tree)
    if unlimited:
        notes.append(
            f"{path.name}: joints {', '.join(unlimited)} have no <limit>; loaded as unbounded"
        )

    root_joint = pin.JointModelFreeFlyer() if base == "free" else pin.JointModelPlanar()
    try:
        model = pin.buildModelFromXML(xml, root_joint, ROOT_JOINT_NAME)
    except (RuntimeError, ValueError) as exc:
        raise RobotModelError(f"{path}: Pinocchio's URDF parser refuses it ({exc})") from exc
    compare_parses(path, model, urdf)
    compare_friction(path, model, urdf)
    notes += check_mass_matrix(path, model)
    if inertias == "balanced":
        model = balanced(model)[0]

    base_inertial = urdf.link_map[root].inertial
    com_pose = np.eye(4) if base_inertial is None else base_inertial.origin
    model.addFrame(
        pin.Frame(BASE_COM_FRAME, 1, 0, pin.SE3(com_pose[:3, :3], com_pose[:3, 3]), pin.FrameType.OP_FRAME)
    )
    return CheckedLoad(
        model=model,
        base_link=root,
        base_com=com_pose[:3, 3].copy(),
        base_com_rotation=com_pose[:3, :3].copy(),
        end_effectors=_end_effectors(path, model, urdf, end_effectors),
        link_coms={
            link.name: link.inertial.origin[:3, 3].copy() if link.inertial is not None else np.zeros(3)
            for link in urdf.links
        },
        warnings=tuple(notes),
        notes=tuple(facts),
        meshes=tuple(visual_meshes(tree)),
    ), xml


def _check_tree(path: Path, robot: UrdfModel) -> str:
    """Check that links and joints form one tree; return the root link name."""
    links = [link.name for link in robot.links]
    if not links:
        raise RobotModelError(f"{path}: no <link>")
    for name in {n for n in links if links.count(n) > 1}:
        raise RobotModelError(f"{path}: link '{name}' is defined more than once")
    parent_of: dict[str, str] = {}
    for joint in robot.joints:
        if joint.type not in SUPPORTED:
            raise RobotModelError(
                f"{path}: joint '{joint.name}' has type '{joint.type}'; supported inside the tree: "
                f"{', '.join(sorted(SUPPORTED))} (the floating base is added by freefloat)"
            )
        for role, link in (("parent", joint.parent), ("child", joint.child)):
            if link not in links:
                raise RobotModelError(
                    f"{path}: joint '{joint.name}' names {role} link '{link}', which does not exist"
                )
        if joint.child in parent_of:
            raise RobotModelError(
                f"{path}: link '{joint.child}' is the child of joints '{parent_of[joint.child]}' and "
                f"'{joint.name}': a loop. A URDF must be a tree; describe loop closures beside it"
            )
        if joint.type in MOVABLE and np.linalg.norm(joint.axis) < 1e-12:
            raise RobotModelError(f"{path}: joint '{joint.name}' has a zero axis")
        parent_of[joint.child] = joint.name
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        what = "no root (the joints form a loop)" if not roots else f"{len(roots)} roots: {roots}"
        raise RobotModelError(f"{path}: {what}; a floating-base robot needs exactly one root link")
    children: dict[str, list[str]] = {name: [] for name in links}
    for joint in robot.joints:
        children[joint.parent].append(joint.child)
    reached, stack = set(), [roots[0]]
    while stack:
        link = stack.pop()
        reached.add(link)
        stack.extend(children[link])
    if len(reached) != len(links):
        cut_off = sorted(set(links) - reached)
        raise RobotModelError(f"{path}: links {cut_off} form a loop not attached to root '{roots[0]}'")
    return roots[0]


def _check_inertias(path: Path, robot: UrdfModel, root: str, notes: list[str]) -> None:
    """Reject negative masses and impossible inertias; note idealised (singular) ones.

    An inertia with a negative eigenvalue is rejected. A massive link whose inertia is only
    positive semi-definite (a planar ``izz``-only or rod idealisation, as in SPART's ManiSat) is
    loaded with a note: the free-floating mass matrix may then be singular in some postures.
    """
    singular = []
    for link in robot.links:
        mass = 0.0 if link.inertial is None else link.inertial.mass
        inertia = np.zeros((3, 3)) if link.inertial is None else link.inertial.inertia
        if not np.isfinite(mass) or mass < 0.0:
            raise RobotModelError(f"{path}: link '{link.name}' has mass {mass}; a mass must be >= 0")
        eig = np.linalg.eigvalsh(0.5 * (inertia + inertia.T))
        if not np.all(np.isfinite(eig)) or eig.min() < -1e-12 * max(1.0, eig.max()):
            raise RobotModelError(
                f"{path}: link '{link.name}' has an inertia that is not positive definite "
                f"(eigenvalues {np.array2string(eig, precision=4)})"
            )
        if mass > 0.0 and eig.min() <= 0.0:
            singular.append(link.name)
        if link.name == root and mass <= 0.0:
            notes.append(
                f"{path.name}: root link '{root}' has no mass; the base reference point is its "
                "<inertial> origin"
            )
    if singular:
        notes.append(
            f"{path.name}: links {', '.join(singular)} have singular (semi-definite) inertias; "
            "loaded as idealised bodies"
        )


def _pinocchio_xml(root: ET.Element) -> tuple[str, list[str]]:
    """URDF text for Pinocchio, with a wide ``<limit>`` added where urdfdom requires one."""
    unlimited = []
    for joint in root.iter("joint"):
        if joint.get("type") in ("revolute", "prismatic") and joint.find("limit") is None:
            ET.SubElement(
                joint, "limit", lower="-1e9", upper="1e9", effort="1e9", velocity="1e9"
            )
            unlimited.append(joint.get("name"))
    return ET.tostring(root, encoding="unicode"), unlimited


def _end_effectors(
    path: Path, model: pin.Model, robot: UrdfModel, names: list[str] | tuple[str, ...] | None
) -> tuple[str, ...]:
    """End-effector link names, checked or found as leaves behind a movable joint."""
    links = [link.name for link in robot.links]
    if names is not None:
        for name in names:
            if name not in links:
                raise RobotModelError(f"{path}: end-effector '{name}' is not a link{did_you_mean(name, links, 'links')}")
        return tuple(names)
    parents = {joint.parent for joint in robot.joints}
    leaves = [
        frame.name
        for frame in model.frames
        if frame.type == pin.FrameType.BODY and frame.name not in parents and frame.parentJoint > 1
    ]
    if not leaves:
        raise RobotModelError(f"{path}: no leaf link behind a movable joint: no end-effector found")
    return _merge_grippers(model, robot, leaves)


def _merge_grippers(model: pin.Model, robot: UrdfModel, leaves: list[str]) -> tuple[str, ...]:
    """Leaves that hang below a common branching link behind a movable joint and look like a
    gripper's parts count as one end-effector: the only one of them fixed to that link when there
    is exactly one (a tool centre point), otherwise the link itself. A leaf looks like a gripper
    part when it is fixed to that link (tool and sensor frames) or is at most
    :data:`GRIPPER_JOINTS` prismatic joints below it, or joints or links named like fingers
    (:data:`GRIPPER_WORDS`). Two fingers as two end-effectors make the GJM singular (Panda:
    condition number 6e16); a Y-shaped arm with revolute branches keeps both ends."""
    joint_to: dict[str, Joint] = {joint.child: joint for joint in robot.joints}
    children: dict[str, int] = {}
    for joint in robot.joints:
        children[joint.parent] = children.get(joint.parent, 0) + 1

    def branch(leaf: str) -> tuple[str, bool]:
        """The nearest ancestor with several children, and whether ``leaf`` is a gripper part."""
        link, movable, named = leaf, [], bool(GRIPPER_WORDS.search(leaf))
        while link in joint_to:
            joint = joint_to[link]
            if joint.type in MOVABLE:
                movable.append(joint.type)
                named = named or bool(GRIPPER_WORDS.search(joint.name))
            link = joint.parent
            if children[link] > 1:
                break
        part = not movable or (len(movable) <= GRIPPER_JOINTS and (named or set(movable) == {"prismatic"}))
        return link, part

    hubs = {leaf: branch(leaf) for leaf in leaves}
    chosen = []
    for leaf in leaves:
        hub, _ = hubs[leaf]
        group = [(name, part) for name, (h, part) in hubs.items() if h == hub]
        behind_movable = model.existBodyName(hub) and model.frames[model.getBodyId(hub)].parentJoint > 1
        if len(group) < 2 or not behind_movable or not all(part for _, part in group):
            chosen.append(leaf)
            continue
        fixed = [name for name, _ in group if joint_to[name].parent == hub and joint_to[name].type == "fixed"]
        pick = fixed[0] if len(fixed) == 1 else hub
        if pick not in chosen:
            chosen.append(pick)
    return tuple(chosen)


def arm_of(model: pin.Model, end_effector: str) -> Arm:
    """The movable joints from the base to ``end_effector``, base outwards."""
    joint_id = model.frames[model.getFrameId(end_effector)].parentJoint
    chain = []
    while joint_id > 1:
        chain.append(joint_id)
        joint_id = model.parents[joint_id]
    chain.reverse()
    v_indices = np.concatenate(
        [np.arange(model.idx_vs[j], model.idx_vs[j] + model.nvs[j]) for j in chain]
    ) if chain else np.zeros(0, dtype=int)
    return Arm(end_effector, tuple(model.names[j] for j in chain), v_indices.astype(int))
