"""Which joints a robot scene locks, and its telemetry read back on the full robot.

``robot.locked_joints`` names joints held still by brakes; ``simulation.lock = "auto"`` adds every
joint the scene never moves (:func:`never_moved`). The loop then runs on the reduced robot
(:mod:`freefloat.robot.locking`), and :func:`full_telemetry` writes its rows for the full robot:
the locked joints at their constant positions with zero rates, and as their torque the brake's
holding torque, so that figures, page and summary read as those of the full robot.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ...dynamics.telemetry import Telemetry
from ...dynamics.wrenches import ExternalWrench, WrenchProfiles
from ...errors import RobotModelError, SceneError
from ...robot.joints import JointCoordinates
from ...robot.locking import LockedJoints, lock_joints
from ...robot.robot import Robot
from ..scenes import Scene


def never_moved(scene: Scene, displacement: np.ndarray, v0: np.ndarray, n_base: int) -> np.ndarray:
    """Columns of the joint vector (n_joints,) the scene never moves: ``True`` where the
    computed-torque controller holds the joint at a constant reference.

    A joint never moves when all of these hold: ``controller.kind = "computed_torque"`` on a
    ``task.kind = "joint_quintic"`` task (the controller acts on every joint), the task does not
    displace it (``task.displacement`` zero for it: its reference is its initial position, its
    reference rate and acceleration zero) and its initial rate is zero (its initial error too).
    The controller then asks for zero acceleration of that joint at the start of every control
    period; the full robot still moves it a little within a period, by the zero-order hold of
    the torques and by any error of the controller's model. Locking drops that motion: it is what
    ``simulation.model = "auto"``'s pilot measures against the unlocked run.

    Args:
        displacement: the task's displacement per joint column (n_joints,).
        v0: the initial full velocity (nv,).
        n_base: base velocity coordinates of v0.
    """
    if scene.kind != "joint_space" or scene.controller.kind != "computed_torque" \
            or scene.task.kind != "joint_quintic":
        return np.zeros(len(displacement), dtype=bool)
    return (displacement == 0.0) & (v0[n_base:] == 0.0)


def lock_for(scene: Scene, robot: Robot, q0: np.ndarray, v0: np.ndarray, displacement: np.ndarray,
             explicit: np.ndarray, driven: Sequence[int] | np.ndarray = ()) -> LockedJoints | None:
    """The scene's locked robot at the start ``q0`` (None when no joint is locked).

    Args:
        displacement: the task's displacement per joint column (n_joints,).
        explicit: ``True`` on the columns ``robot.locked_joints`` names (n_joints,).
        driven: columns a law of their own moves whatever the task (reaction wheels), which
            ``simulation.lock = "auto"`` never locks.

    Raises:
        SceneError: naming the key, when a joint named in ``robot.locked_joints`` has an initial
            rate (``initial.joint_velocities``) or a task displacement (``task.displacement``),
            or the scene is a detumbling or capture scene (its controller moves every joint).
    """
    names = np.array(robot.joint_names)
    where = f"scene '{scene.name}': 'robot.locked_joints'"
    if explicit.any() and scene.kind != "joint_space":
        raise SceneError(f"{where}: joints can be locked in joint-space and torque-free scenes only; this is a "
                         f"{scene.kind} scene, whose controller moves every joint")
    for key, values in (("initial.joint_velocities", v0[robot.n_base:]), ("task.displacement", displacement)):
        moving = explicit & (values != 0.0)
        if moving.any():
            raise SceneError(f"{where} names {', '.join(names[moving])}, which '{key}' moves; a locked joint stays "
                             "still at its initial position")
    locked = explicit.copy()
    if scene.simulation.lock == "auto":
        moved = never_moved(scene, displacement, v0, robot.n_base)
        moved[np.asarray(driven, dtype=int)] = False
        locked |= moved
    if not locked.any():
        return None
    try:
        return lock_joints(robot, list(names[locked]), q0)
    except RobotModelError as exc:
        raise SceneError(f"{where}: {exc}") from exc


def full_telemetry(lock: LockedJoints, telemetry: Telemetry, wrenches: tuple[ExternalWrench, ...] = ()) -> Telemetry:
    """``telemetry`` of a run of ``lock.robot`` as rows of the full robot ``lock.full``.

    ``q``, ``v``, ``joint_positions`` and ``joint_reference`` gain the locked joints (their
    positions, zero rates, their positions as reference where the row has one); ``tau`` gains the
    brakes' holding torques at each row's state, torques and active wrenches (from the reduced
    robot's ABA there, :meth:`~freefloat.robot.locking.LockedJoints.holding_torque`). Every other column (base,
    end-effectors, CoM, momentum, energy, work) is the same for both robots and kept.
    """
    full, small, free, locked = lock.full, lock.robot, lock.free_joints, lock.locked_joints
    q, v = lock.expand(telemetry.q, telemetry.v)
    held = JointCoordinates(full).get(lock.q_lock)[locked]
    fields = (WrenchProfiles(full, wrenches), WrenchProfiles(small, wrenches)) if wrenches else None
    tau = _columns(telemetry.tau, free, locked, np.zeros(len(locked)))
    generalized, data, data_small = np.zeros(full.model.nv), full.model.createData(), small.model.createData()
    for k, (t, q_small, v_small) in enumerate(zip(telemetry.t, telemetry.q, telemetry.v)):
        generalized[full.n_base:] = tau[k]
        active = fields is not None and fields[0].activate(float(t)) and fields[1].activate(float(t))
        fext_small = [fields[1].forces(q_small)] if active else []
        a = pin.aba(small.model, data_small, q_small, v_small, generalized[lock.free_v], *fext_small)
        tau[k, locked] = lock.holding_torque(q[k], v[k], a, generalized, fields[0].forces(q[k]) if active else None,
                                             data)
    reference = _columns(telemetry.joint_reference, free, locked, held)
    reference[np.isnan(telemetry.joint_reference).all(axis=1)] = np.nan
    return dataclasses.replace(telemetry, q=q, v=v, tau=tau, joint_reference=reference,
                               joint_positions=_columns(telemetry.joint_positions, free, locked, held))


def _columns(values: np.ndarray, free: np.ndarray, locked: np.ndarray, constant: np.ndarray) -> np.ndarray:
    """Rows of the full joint vector (N, n_joints) from the free columns ``values`` (N, n_free) and
    the locked columns' ``constant`` (n_locked,)."""
    out = np.empty((len(values), len(free) + len(locked)))
    out[:, free] = values
    out[:, locked] = constant
    return out


__all__ = ["full_telemetry", "lock_for", "never_moved"]
