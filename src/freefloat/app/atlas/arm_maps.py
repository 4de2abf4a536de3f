"""What the space-robot kinds (:mod:`.workspace`, :mod:`.singularities`) evaluate at a grid point:
one end-effector of a free-floating robot, some of its joints set by the point, the others held
at a reference posture.

At each point (the base at the reference pose: base-link frame on the inertial axes) the compiled
GJM core (:func:`freefloat.gjm.model_of`) gives the end-effector's rows of the generalized
Jacobian J* (eq 82; the E-GJM block J_S^i of eq 89 when only the arm's own columns are kept) and
of the fixed-base Jacobian Jm (eq 76), restricted to the mapped arm's joint columns; their
singular values, condition numbers and manipulabilities are taken in one batched SVD per chunk.
Rows: ``[vx, vy, wz]`` of the end-effector frame origin on a planar base, ``[v; w]`` (6) on a free
base, inertial frame.

Positions: the end-effector relative to the system CoM (the free-floating view: at zero momentum
the CoM is fixed, Vafa and Dubowsky's virtual ground) and relative to the base CoM (the fixed-base
view), m, inertial axes at the reference base attitude.

With a momentum M = [P; L about the system CoM] (inertial frame), eq 88 adds the drift
``J0E H0^-1 M_base`` to the end-effector velocity (M_base = [P; L + (r_C - r_0) x P], about the base
CoM); ``hold_rate`` is the least joint-rate norm of the arm that cancels it, ||J*^+ drift|| (rad/s),
``drift_left`` what no arm joint rate can cancel (m/s and rad/s mixed: the residual's norm).
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...arguments import MAX_MAGNITUDE
from ...documents import start_angles
from ...dynamics import gjm
from ...dynamics.gjm import GJMState
from ...dynamics.gjm.kinematics import BodyKinematics
from ...errors import InvalidArgument, RobotModelError, UnknownName, spelled
from ...robot.joints import JointCoordinates
from ...robot.loading import load_robot
from ...robot.robot import Robot
from .kinds import Options

#: Rows of an end-effector's 6-row block kept on each base: vx, vy, wz in the plane.
ROWS = {"planar": (0, 1, 5), "free": (0, 1, 2, 3, 4, 5)}
#: sigma_min / sigma_max below which a Jacobian counts as singular (default of --tolerance).
TOLERANCE = 1e-3
#: Places of the compiled core's outputs (GJMState's field order; the body kinematics last).
_H0, _JM, _J0E, _JSTAR, _EE = (GJMState._fields.index(f) for f in ("H0", "Jm", "J0E", "Jstar", "ee_position"))
_R0, _COM = (BodyKinematics._fields.index(f) for f in ("r0", "com"))
#: The options both space-robot kinds read.
OPTIONS = frozenset({"grid", "axes", "end_effector", "momentum", "tolerance", "base", "posture"})


@dataclass(frozen=True)
class ArmMap:
    """The picklable context of a map (the robot is loaded once per process by :func:`robot_of`).

    Attributes:
        target: the robot's name or URDF file.
        base: ``"free"`` or ``"planar"``.
        end_effector: the mapped end-effector's frame name; ``index`` its place in
            ``robot.end_effectors``.
        arm_joints: the arm's joint names (base outwards): the Jacobians' columns.
        columns: their indices among the actuated joints (n,).
        axes: the grid's joint names; ``axis_index`` their indices among the actuated joints.
        limits: each axis's (low, high), rad or m.
        posture: every actuated joint's reference position (n,), the axes' overwritten per point.
        momentum: [P; L about the system CoM] (6,), inertial frame, or None.
        tolerance: sigma_min / sigma_max below which a Jacobian counts as singular.
        rows: the end-effector block's rows kept (see :data:`ROWS`).
    """

    target: str
    base: str
    end_effector: str
    index: int
    arm_joints: tuple[str, ...]
    columns: tuple[int, ...]
    axes: tuple[str, ...]
    axis_index: tuple[int, ...]
    limits: tuple[tuple[float, float], ...]
    posture: tuple[float, ...]
    momentum: tuple[float, ...] | None
    tolerance: float
    rows: tuple[int, ...]


@functools.lru_cache(maxsize=8)
def robot_of(target: str, base: str) -> Robot:
    """The robot ``target`` (name or URDF file) on a ``base`` base, loaded once per process."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the loader's notes were shown when the map was prepared
        return load_robot(target, base=base, visuals=False)


def default_base(target: str) -> str:
    """``planar`` for freefloat's planar robots (a file or name ending in ``_planar``), else ``free``."""
    return "planar" if Path(target).stem.endswith("_planar") else "free"


def reference_posture(robot: Robot, target: str) -> np.ndarray:
    """The held joints' positions (n,): the dissertation's Table 4 start (arms stretched, arms 2
    and 4 at 90 deg) for the four-arm robot, each joint's mid-range otherwise (zero for a joint
    whose range includes it symmetrically or has none)."""
    if Path(target).stem == "four_arm_planar":
        return start_angles(0.0)
    low, high = joint_limits(robot)
    return np.where(np.isfinite(low) & np.isfinite(high), 0.5 * (low + high), 0.0)


def joint_limits(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """Each actuated joint's position range (n,), (n,), clipped to [-pi, pi] where it is wider or
    absent (rad; m for a prismatic joint, whose missing limits give [-pi, pi] m too); continuous
    joints over [-pi, pi]."""
    model = robot.model
    low, high = np.full(robot.n_joints, -np.pi), np.full(robot.n_joints, np.pi)
    for k, joint in enumerate(range(2, model.njoints)):
        if model.nqs[joint] == 1:
            i = model.idx_qs[joint]
            low[k], high[k] = max(model.lowerPositionLimit[i], -np.pi), min(model.upperPositionLimit[i], np.pi)
    return low, high


def _posture(robot: Robot, target: str, given: tuple[tuple[str, float], ...] | None,
             axes: tuple[str, ...]) -> np.ndarray:
    """The reference posture with the ``--posture`` values (deg for revolute joints, m for
    prismatic ones) put in; ``axes`` are the map's axes, which ``--posture`` may not set.

    Raises:
        UnknownName: a joint that is not the robot's, listing its joints.
        InvalidArgument: a value that is not finite, or a joint that is an axis of the map.
    """
    posture = reference_posture(robot, target)
    joints = robot.joint_names
    for name, value in given or ():
        if name not in joints:
            raise UnknownName(f"joint of {target} ({spelled('posture=', '--posture')})", name, joints)
        if name in axes:
            raise InvalidArgument(f"{spelled('posture=', '--posture')} {name}={value}: '{name}' is an axis of the map ({spelled('axes=', '--axes')}: "
                                  f"{', '.join(axes)}), which sweeps its range; {spelled('posture', '--posture')} sets the joints held fixed")
        if not np.isfinite(value):
            raise InvalidArgument(f"{spelled('posture=', '--posture')} {name}={value}: needs a finite value")
        revolute = gjm.model_of(robot).tree.revolute[joints.index(name)]
        posture[joints.index(name)] = np.radians(value) if revolute else value
    return posture


def prepare(target: str, options: Options, all_arm_joints: bool) -> ArmMap:
    """The context of a map of ``target``; the default axes are all the arm's joints
    (``all_arm_joints``) or its first two.

    Raises:
        RobotModelError: a robot without end-effectors, or an unknown file or name.
        UnknownName: an end-effector or axis that is not the robot's, listing the valid ones.
        InvalidArgument: a momentum of the wrong length, a tolerance outside (0, 1).
    """
    base = options.base or default_base(target)
    robot = load_robot(target, base=base, visuals=False)
    if not robot.end_effectors:
        raise RobotModelError(f"{target}: the robot has no end-effector (no leaf link below a movable joint); "
                              "an atlas maps an end-effector")
    name = options.end_effector or robot.end_effectors[0]
    if name not in robot.end_effectors:
        raise UnknownName(f"end-effector of {target}", name, robot.end_effectors)
    index = robot.end_effectors.index(name)
    arm = robot.arms[index]
    joints = robot.joint_names
    axes = options.axes or (arm.joints if all_arm_joints else arm.joints[:2])
    for axis in axes:
        if axis not in joints:
            raise UnknownName(f"joint of {target} ({spelled('axes=', '--axes')})", axis, arm.joints)
    if len(set(axes)) != len(axes):
        raise InvalidArgument(f"{spelled('axes=', '--axes')} names a joint twice: {', '.join(axes)}")
    low, high = joint_limits(robot)
    axis_index = tuple(joints.index(a) for a in axes)
    tolerance = TOLERANCE if options.tolerance is None else options.tolerance
    if not 0 < tolerance < 1:
        raise InvalidArgument(f"{spelled('tolerance=', '--tolerance')} must be in (0, 1), got {tolerance}")
    return ArmMap(target=str(target), base=base, end_effector=name, index=index, arm_joints=arm.joints,
                  columns=tuple(int(i) for i in arm.v_indices - robot.n_base), axes=tuple(axes),
                  axis_index=axis_index, limits=tuple((float(low[i]), float(high[i])) for i in axis_index),
                  posture=tuple(float(x) for x in _posture(robot, target, options.posture, tuple(axes))),
                  momentum=_momentum(options.momentum, base), tolerance=tolerance, rows=ROWS[base])


def _momentum(values: tuple[float, ...] | None, base: str) -> tuple[float, ...] | None:
    """[P; L] (6,) from the 6 numbers given, or the planar [Px, Py, Lz]; None for none or zero.

    Raises:
        InvalidArgument: for another count, a value that is not finite or beyond
            :data:`~freefloat.arguments.MAX_MAGNITUDE`, or out-of-plane components (Pz, Lx, Ly) on a planar base.
    """
    if values is None:
        return None
    m = np.asarray(values, dtype=float)
    if base == "planar" and m.size == 3:
        m = np.array([m[0], m[1], 0.0, 0.0, 0.0, m[2]])
    if m.size != 6 or not np.all(np.isfinite(m)) or np.any(np.abs(m) > MAX_MAGNITUDE):
        planar = " or 3 [Px Py Lz]" if base == "planar" else ""
        raise InvalidArgument(f"{spelled('momentum=', '--momentum')} takes 6 finite numbers [Px Py Pz Lx Ly Lz]{planar} "
                              f"(N s, N m s, about the system CoM) of magnitude at most {MAX_MAGNITUDE:g}, "
                              f"got {list(values)}")
    if base == "planar" and (out := [name for name, x in zip(("Pz", "Lx", "Ly"), m[[2, 3, 4]]) if x != 0]):
        given = ", ".join(f"{x:g}" for x in m[[2, 3, 4]] if x != 0)
        raise InvalidArgument(f"{spelled('momentum=', '--momentum')} gives {', '.join(out)} = {given}"
                              " on a planar base, which moves in its plane: the map takes Px, Py, Lz only (give "
                              f"those three, or {spelled('base=' + repr('free'), '--base free')})")
    return tuple(m) if np.any(m) else None


def described(context: ArmMap) -> dict:
    """What a map's summary says of its setting: robot, base, end-effector, axes, tolerance and
    the held posture (joint: position, deg for revolute joints, m for prismatic ones)."""
    robot = robot_of(context.target, context.base)
    revolute = gjm.model_of(robot).tree.revolute
    return {"robot": context.target, "base": context.base, "end_effector": context.end_effector,
            "axes": list(context.axes), "tolerance": context.tolerance,
            "posture": {name: float(np.degrees(x) if turns else x) + 0.0  # no -0.0
                        for name, x, turns in zip(robot.joint_names, context.posture, revolute)}}


def reference_point(context: ArmMap) -> tuple[np.ndarray, np.ndarray]:
    """The system CoM and the base CoM (3,), (3,) at the reference posture, inertial frame, m."""
    robot = robot_of(context.target, context.base)
    q = robot.neutral()
    JointCoordinates(robot).set(q, np.array(context.posture))
    kin = gjm.model_of(robot).kinematics(q)
    mass = gjm.model_of(robot).tree.mass
    return mass @ kin.com / mass.sum(), kin.r0


def evaluate(context: ArmMap, points: np.ndarray) -> dict[str, np.ndarray]:
    """Every quantity of the module's docstring at ``points`` (m, len(axes)): ``ee_from_com`` and
    ``ee_from_base`` (m, 3); ``radius_free`` and ``radius_fixed`` (m,), their norms (in-plane on a
    planar base); ``sv_free`` and ``sv_fixed`` (m, r) singular values of the J* and Jm blocks,
    descending, r = min(rows, arm joints); ``cond_*`` (inf where sigma_min is 0), ``manipulability_*``
    (their product) and ``singular_*`` (sigma_min / sigma_max < tolerance) of each; with a momentum,
    ``drift`` (m, rows), ``hold_rate`` and ``drift_left`` (m,)."""
    robot = robot_of(context.target, context.base)
    model, coords = gjm.model_of(robot), JointCoordinates(robot)
    v = np.zeros(robot.model.nv)
    block = slice(6 * context.index, 6 * context.index + 6)
    axes, m = np.array(context.axis_index), len(points)
    n_bodies = len(model.tree.mass)
    # per point only the compiled call and slice copies; the selections and sums per chunk, batched
    Jstar, Jm = np.empty((m, 6, robot.n_joints)), np.empty((m, 6, robot.n_joints))
    ee, r0, coms = np.empty((m, 3)), np.empty((m, 3)), np.empty((m, n_bodies, 3))
    J0E, H0 = (np.empty((m, 6, 6)), np.empty((m, 6, 6))) if context.momentum is not None else (None, None)
    angles = np.tile(np.array(context.posture), (m, 1))
    angles[:, axes] = points
    configurations = np.tile(robot.neutral(), (m, 1))
    coords.set(configurations.T, angles.T)  # every row at once (columns of the transposed views)
    for k, q in enumerate(configurations):
        raw = model.core.compute(q, v)  # GJMState's fields as a tuple (gjm.compute without the wrapping)
        Jstar[k], Jm[k] = raw[_JSTAR][block], raw[_JM][block]
        ee[k] = raw[_EE][context.index]
        kinematics = raw[-1]
        r0[k], coms[k] = kinematics[_R0], kinematics[_COM]
        if J0E is not None:
            J0E[k], H0[k] = raw[_J0E][block], raw[_H0]
    mass = model.tree.mass
    com = np.einsum("b,kbi->ki", mass / mass.sum(), coms)
    kept, columns = list(context.rows), list(context.columns)
    Jstar, Jm = Jstar[:, kept][:, :, columns], Jm[:, kept][:, :, columns]
    drift = None
    if J0E is not None:
        P, L = np.array(context.momentum[:3]), np.array(context.momentum[3:])
        about_base = np.concatenate((np.broadcast_to(P, (m, 3)), L + np.cross(com - r0, P)), axis=1)
        drift = np.einsum("kij,kj->ki", J0E[:, kept], np.linalg.solve(H0, about_base[..., None])[..., 0])
    out = {"ee_from_com": ee - com, "ee_from_base": ee - r0}
    plane = slice(0, 2) if context.base == "planar" else slice(0, 3)
    out["radius_free"] = np.linalg.norm(out["ee_from_com"][:, plane], axis=1)
    out["radius_fixed"] = np.linalg.norm(out["ee_from_base"][:, plane], axis=1)
    for name, J in (("free", Jstar), ("fixed", Jm)):
        sv = np.linalg.svd(J, compute_uv=False)
        out[f"sv_{name}"] = sv
        out[f"cond_{name}"] = np.where(sv[:, -1] > 0, sv[:, 0] / np.where(sv[:, -1] > 0, sv[:, -1], 1.0), np.inf)
        out[f"manipulability_{name}"] = np.prod(sv, axis=1)
        out[f"singular_{name}"] = sv[:, -1] < context.tolerance * sv[:, 0]
    if drift is not None:
        hold = -np.einsum("kij,kj->ki", np.linalg.pinv(Jstar), drift)
        out["drift"] = drift
        out["hold_rate"] = np.linalg.norm(hold, axis=1)
        out["drift_left"] = np.linalg.norm(drift + np.einsum("kij,kj->ki", Jstar, hold), axis=1)
    return out
