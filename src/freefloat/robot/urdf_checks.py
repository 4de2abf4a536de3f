"""Checks of a URDF before and after Pinocchio builds it, so that a bad file is refused with its
file, link, joint and attribute named instead of loading as a different robot.

Before: the text is UTF-8 XML without a DTD (no entity expansion, no external entities,
whatever the XML libraries' defaults), every number is finite, joint names are unique, and the
model fits in memory. After: Pinocchio's parse (urdfdom) carries the same masses and inertias as
:mod:`.urdf_model`'s, body by body, and the free-floating mass matrix is not singular.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import RobotModelError, did_you_mean, few
from ..paths import URDF_DIR
from .urdf_model import UrdfModel

#: Bytes of one Pinocchio ``Data`` per nv^3 (measured: 4.2 GB at nv = 406, 0.56 GB at nv = 206).
DATA_BYTES_PER_NV3 = 65.0
#: ``Data`` objects a simulation holds at once (plant, recorder, controller, models).
DATA_PER_RUN = 6
#: Largest size of any number in a URDF (SI units; beyond it products of them overflow).
MAX_MAGNITUDE = 1e15
#: Deepest XML nesting accepted (a URDF needs about 5 levels).
MAX_DEPTH = 64
#: Longest link, joint or frame name accepted (names end up in legends, tables and file names).
MAX_NAME = 256
#: Share of the machine's memory a robot may take.
MEMORY_SHARE = 0.5


def read_urdf(path: Path, raw: bytes | None = None) -> ET.Element:
    """The URDF's XML root, parsed by the standard library after refusing any DTD.

    Args:
        path: the file, named in every error.
        raw: its bytes when already read (the loader hashes exactly what it checks); None: read.

    Raises:
        RobotModelError: naming the file when it is not UTF-8, declares a DTD or entities, is
            not well-formed XML (with the line and column) or is nested absurdly deep.
    """
    raw = path.read_bytes() if raw is None else raw
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RobotModelError(f"{path}: not UTF-8 text (byte {exc.start})") from exc
    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise RobotModelError(f"{path}: declares a DTD or entities (<!DOCTYPE/<!ENTITY); a URDF needs neither, "
                              "and freefloat refuses them (entity expansion, external files)")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line, column = exc.position
        raise RobotModelError(f"{path}: not well-formed XML at line {line}, column {column} ({exc})") from exc
    stack = [(root, 1)]
    while stack:
        element, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise RobotModelError(f"{path}: XML nested more than {MAX_DEPTH} levels deep (<{element.tag}>); "
                                  "a URDF needs a few")
        stack.extend((child, depth + 1) for child in element)
    return root


def check_numbers(path: Path, root: ET.Element) -> None:
    """Every numeric attribute of every link and joint is finite.

    Raises:
        RobotModelError: naming the link or joint, the element and the attribute.
    """
    for kind in ("link", "joint"):
        for owner in root.findall(kind):
            for element in owner.iter():
                for attribute, value in element.attrib.items():
                    if attribute in ("name", "filename", "link", "type"):
                        continue
                    for token in value.split():
                        try:
                            number = float(token)
                        except ValueError:
                            continue
                        if not math.isfinite(number) or abs(number) > MAX_MAGNITUDE:
                            raise RobotModelError(
                                f"{path}: {kind} '{owner.get('name')}' <{element.tag} {attribute}=\"{value}\">: "
                                f"'{token}' is not a finite number of at most {MAX_MAGNITUDE:g} in size")


def check_joints(path: Path, root: ET.Element) -> None:
    """Link and joint names are at most :data:`MAX_NAME` long, joint names are unique, a mimic
    joint follows a joint that exists, and the model fits in memory (Pinocchio's ``Data`` grows
    as nv^3).

    Raises:
        RobotModelError: naming the over-long name, the repeated joint, the mimic joint and the
            joint it names, or the joint count with the memory estimate.
    """
    for kind in ("link", "joint"):
        for element in root.findall(kind):
            name = element.get("name") or ""
            if len(name) > MAX_NAME:
                raise RobotModelError(f"{path}: {kind} '{name[:40]}...' has a name of {len(name)} characters; "
                                      f"at most {MAX_NAME}")
    names = [joint.get("name") for joint in root.findall("joint")]
    counts: dict[str | None, int] = {}
    for name in names:
        counts[name] = counts.get(name, 0) + 1
    for name, count in counts.items():
        if count > 1:
            raise RobotModelError(f"{path}: joint '{name}' is defined {count} times")
    for joint in root.findall("joint"):
        for mimic in joint.findall("mimic"):
            if mimic.get("joint") not in counts:
                raise RobotModelError(f"{path}: joint '{joint.get('name')}' <mimic joint=\"{mimic.get('joint')}\">: "
                                      f"no joint of that name{did_you_mean(mimic.get('joint'), counts, 'joints')}")
    check_memory(path, sum(joint.get("type") in ("revolute", "continuous", "prismatic") for joint in root.findall("joint")))


def check_memory(path: Path, joints: int) -> None:
    """A robot of ``joints`` movable joints on a free-flyer base fits in this machine's memory
    (:func:`usable_memory`; checked on every load, the cached ones too: the machine may change).

    Raises:
        RobotModelError: naming the file, the joint count and the memory estimate.
    """
    nv = 6 + joints
    need = DATA_PER_RUN * DATA_BYTES_PER_NV3 * nv**3
    have = usable_memory()
    if need > have:
        raise RobotModelError(
            f"{path}: {joints} movable joints: a simulation would need about {need / 1e9:.1f} GB "
            f"(Pinocchio's Data grows as nv^3, ~{DATA_BYTES_PER_NV3 * nv**3 / 1e9:.1f} GB each), more than "
            f"{have / 1e9:.1f} GB ({MEMORY_SHARE:.0%} of this machine's memory)")


def usable_memory() -> float:
    """Bytes a robot or a run may take: :data:`MEMORY_SHARE` of this machine's memory."""
    return MEMORY_SHARE * os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def is_built_in(path: Path) -> bool:
    """Whether ``path`` is one of freefloat's own robots (in :data:`~freefloat.paths.URDF_DIR`),
    whose inertias break the triangle inequality on purpose."""
    return path.resolve().parent == URDF_DIR.resolve()


def physics_notes(path: Path, robot: UrdfModel, triangle: bool = True) -> tuple[list[str], list[str]]:
    """What loads but no real robot has: inertias that break the triangle inequality (no rigid
    body can have them; MuJoCo refuses them; skipped with ``triangle=False``), joint limits with
    lower > upper.

    Returns:
        ``(warnings, notes)``: what to check in the file, each at most two lines saying what to do;
        and what is so on purpose, one line each (freefloat's own robots' inertias, as the
        dissertation prints them).
    """
    notes, facts = [], []
    broken = {}
    for link in robot.links if triangle else ():
        if link.inertial is None:
            continue
        moments = np.linalg.eigvalsh(0.5 * (link.inertial.inertia + link.inertial.inertia.T))
        if moments.max() > 0 and moments[0] + moments[1] < moments[2] * (1 - 1e-9):
            broken[link.name] = moments
    if broken:
        worst = max(broken, key=lambda name: broken[name][2] / (broken[name][0] + broken[name][1] + 1e-300))
        m = broken[worst]
        if is_built_in(path):
            facts.append(f"{path.name}: {len(broken)} links' inertias break I1 + I2 >= I3 as the dissertation prints "
                         'them, kept to reproduce its numbers (a physical copy: [robot] inertias = "balanced")')
        else:
            notes.append(f"{path.name}: {len(broken)} links' inertias break I1 + I2 >= I3 ({few(broken)}; worst "
                         f"{worst}: {m[0]:.3g} + {m[1]:.3g} < {m[2]:.3g}), no rigid body has them: check the links' "
                         '<inertia>.\n  Pinocchio simulates them as given (MuJoCo refuses them); a physical copy: '
                         '[robot] inertias = "balanced" (load_robot(..., inertias="balanced")).')
    inverted = [j.name for j in robot.joints if j.limit is not None and j.limit.lower is not None
                and j.limit.upper is not None and j.limit.lower > j.limit.upper]
    if inverted:
        notes.append(f"{path.name}: joints {few(inverted)} have lower limit > upper limit; swap them in the URDF")
    return notes, facts


def compare_parses(path: Path, model: pin.Model, robot: UrdfModel) -> None:
    """Pinocchio's bodies (links merged through fixed joints) have the masses and inertias that
    :func:`.urdf_model.parse_urdf` read from the same file (urdfdom silently drops an inertia or a whole <inertial>
    it cannot read).

    Raises:
        RobotModelError: naming the body, both masses or the inertia difference.
    """
    # per Pinocchio body: mass, first moment m c and rotational inertia about the joint origin
    merged = np.zeros((model.njoints, 1 + 3 + 9))
    for link in robot.links:
        if not model.existBodyName(link.name) or link.inertial is None:
            continue
        frame = model.frames[model.getBodyId(link.name)]
        inertial = link.inertial
        R = frame.placement.rotation @ inertial.origin[:3, :3]
        com = frame.placement.act(inertial.origin[:3, 3])
        merged[frame.parentJoint] += _moments(inertial.mass, com, R @ inertial.inertia @ R.T)
    for j in range(1, model.njoints):
        built = model.inertias[j]
        difference = np.abs(merged[j] - _moments(built.mass, built.lever, built.inertia)).max()
        if difference > 1e-9 * max(1.0, np.abs(merged[j]).max()):
            raise RobotModelError(
                f"{path}: body of joint '{model.names[j]}' has mass {built.mass:.6g} kg in Pinocchio's parse but "
                f"{merged[j][0]:.6g} kg in freefloat's (mass, CoM or inertia differ by {difference:.3g}): the two "
                "URDF parsers read the file differently")


def compare_friction(path: Path, model: pin.Model, robot: UrdfModel) -> None:
    """Pinocchio's ``model.damping`` and ``model.friction`` hold each movable joint's
    ``<dynamics>`` as :func:`.urdf_model.parse_urdf` read it (0 where absent).

    Raises:
        RobotModelError: naming the joint and both readings.
    """
    for joint in robot.joints:
        if not model.existJointName(joint.name):
            continue
        j = model.getJointId(joint.name)
        rows = slice(model.idx_vs[j], model.idx_vs[j] + model.nvs[j])
        read = (0.0, 0.0) if joint.dynamics is None else (joint.dynamics.damping, joint.dynamics.friction)
        built = (model.damping[rows], model.friction[rows])
        if not all(np.allclose(b, r, rtol=1e-12, atol=0.0) for b, r in zip(built, read)):
            raise RobotModelError(f"{path}: joint '{joint.name}' has <dynamics damping friction> {read} in freefloat's "
                                  f"parse but {[b.tolist() for b in built]} in Pinocchio's: the two URDF parsers read the "
                                  "file differently")


def _moments(mass: float, com: np.ndarray, inertia_at_com: np.ndarray) -> np.ndarray:
    """[m, m c (3), I about the origin (9, row-major)] of a body: mass kg, CoM m, inertia about
    its CoM kg m^2, all in one frame."""
    about_origin = inertia_at_com + mass * (com @ com * np.eye(3) - np.outer(com, com))
    return np.concatenate(([mass], mass * np.asarray(com), about_origin.ravel()))


def check_mass_matrix(path: Path, model: pin.Model) -> list[str]:
    """The robot has mass, and notes the joints that move no inertia (the free-floating mass
    matrix is then singular and forward dynamics fails at the first step).

    Raises:
        RobotModelError: when the whole robot is massless.
    """
    if pin.computeTotalMass(model) <= 0.0:
        raise RobotModelError(f"{path}: every link is massless; a floating robot needs mass")
    M = pin.crba(model, model.createData(), pin.neutral(model))
    diagonal = np.diag(M)
    scale = max(1e-300, np.abs(diagonal).max())
    idle = [model.names[j] for j in range(2, model.njoints)
            if (diagonal[model.idx_vs[j]:model.idx_vs[j] + model.nvs[j]] <= 1e-12 * scale).any()]
    if idle:
        return [f"{path.name}: joints {', '.join(idle)} move only massless links (no inertia about their axes): "
                "the free-floating mass matrix is singular and forward dynamics fails"]
    if np.linalg.eigvalsh(0.5 * (M + M.T)).min() <= 1e-12 * scale:
        return [f"{path.name}: the free-floating mass matrix is singular at the neutral posture"]
    return []
