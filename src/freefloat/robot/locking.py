"""Joint locking: a robot with some joints held at fixed positions, as a smaller Pinocchio model.

A locked joint is removed by ``pin.buildReducedModel`` at its position in a full configuration:
its child bodies are welded to its parent, so the reduced model's dynamics are the full model's
with the locked coordinates' accelerations constrained to zero. With ``F`` the free velocity
coordinates (base included) and ``L`` the locked ones of the full model, ``M a + b = tau + s``
with ``a_L = 0`` and ``s`` nonzero on ``L`` only (the constraint's generalized force) gives

.. math:: M_{FF} a_F = \\tau_F - b_F, \\qquad s_L = M_{LF} a_F + b_L - \\tau_L,

where ``a_F`` is the reduced model's acceleration and ``s_L`` the torque a brake must apply to hold
the locked joints (the locked rows of the inverse dynamics at ``a``, minus ``tau_L``). Frames
(end-effectors, the base CoM frame, every link) keep their names, so kinematics and telemetry of
the reduced robot read as the full robot's.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import RobotModelError, did_you_mean
from .loading import arm_of
from .robot import Robot


@dataclass(frozen=True, eq=False)
class LockedJoints:
    """A robot with joints locked, and the maps between its reduced and full coordinates.

    Attributes:
        full: the robot with every joint.
        robot: the reduced robot (locked joints removed; same base, frames and end-effectors;
            no visual geometry).
        names: locked joint names, in the full model's order.
        q_lock: full configuration whose locked-joint entries are the locked positions (full nq,).
        free_q: index in the full q of each reduced q entry (reduced nq,).
        free_v: index in the full v of each reduced v entry, base first (reduced nv,).
        locked_v: indices in the full v of the locked coordinates (nv - reduced nv,).
    """

    full: Robot
    robot: Robot
    names: tuple[str, ...]
    q_lock: np.ndarray
    free_q: np.ndarray
    free_v: np.ndarray
    locked_v: np.ndarray

    @property
    def free_joints(self) -> np.ndarray:
        """Columns of the full joint vector (n_joints,) kept by the reduced robot."""
        return self.free_v[self.full.n_base:] - self.full.n_base

    @property
    def locked_joints(self) -> np.ndarray:
        """Columns of the full joint vector (n_joints,) that are locked."""
        return self.locked_v - self.full.n_base

    def reduce(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The reduced state ``(q[free_q], v[free_v])`` of a full state (rows of a 2-D array too)."""
        return q[..., self.free_q].copy(), v[..., self.free_v].copy()

    def expand(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The full state of a reduced one: locked positions from :attr:`q_lock`, locked rates 0
        (rows of a 2-D array too)."""
        q_full = np.broadcast_to(self.q_lock, (*q.shape[:-1], self.full.model.nq)).copy()
        v_full = np.zeros((*v.shape[:-1], self.full.model.nv))
        q_full[..., self.free_q] = q
        v_full[..., self.free_v] = v
        return q_full, v_full

    def holding_torque(self, q: np.ndarray, v: np.ndarray, a_free: np.ndarray, tau: np.ndarray,
                       fext: Sequence[pin.Force] | None = None, data: pin.Data | None = None) -> np.ndarray:
        """The brake torques ``s_L`` that keep the locked joints still (module docstring), from the
        reduced robot's accelerations: ``s = RNEA(q, v, a)_L - tau_L`` with ``a_F = a_free``, ``a_L = 0``.

        Args:
            q, v: full state (nq,), (nv,) (locked rates zero).
            a_free: the reduced robot's accelerations at that state (reduced nv,), e.g. its ABA.
            tau: full generalized forces (nv,), Pinocchio order (zero base rows for a free base).
            fext: one wrench per full-model joint (joint frame), or None.
            data: a ``pin.Data`` of the full model to reuse, or None.

        Returns:
            Torques (N m) or forces (N) on the locked coordinates, order of :attr:`locked_v`.
        """
        model = self.full.model
        data = model.createData() if data is None else data
        a = np.zeros(model.nv)
        a[self.free_v] = a_free
        needed = pin.rnea(model, data, q, v, a) if fext is None else pin.rnea(model, data, q, v, a, fext)
        return needed[self.locked_v] - tau[self.locked_v]


def lock_joints(robot: Robot, names: Sequence[str], q: np.ndarray) -> LockedJoints:
    """``robot`` with the joints ``names`` locked at their positions in ``q`` (full nq,).

    Raises:
        RobotModelError: naming the file and the joint when a name is not an actuated joint (the
            floating base cannot be locked) or is given twice, or when ``names`` is empty.
    """
    model = robot.model
    where = robot.urdf_path.name
    if not names:
        raise RobotModelError(f"{where}: no joint to lock")
    for name in names:
        if name not in robot.joint_names:
            raise RobotModelError(f"{where}: cannot lock '{name}': not an actuated joint"
                                  f"{did_you_mean(name, robot.joint_names, 'joints')}")
        if list(names).count(name) > 1:
            raise RobotModelError(f"{where}: joint '{name}' is named twice in the joints to lock")
    q = np.asarray(q, dtype=float)
    ids = sorted(model.getJointId(name) for name in names)
    # buildReducedModel looks frames up by name alone and fails when a link shares a joint's name
    # (a root link called "base"): reduce a copy whose joints have unique names, then restore them.
    unique = {name: f"\x00joint{j}" for j, name in enumerate(model.names)}
    reduced = _renamed(pin.buildReducedModel(_renamed(pin.Model(model), unique), ids, q),
                       {new: old for old, new in unique.items()})
    free_q, free_v = [], []
    for j in range(1, reduced.njoints):
        full_id = model.getJointId(reduced.names[j])
        free_q.extend(range(model.idx_qs[full_id], model.idx_qs[full_id] + model.nqs[full_id]))
        free_v.extend(range(model.idx_vs[full_id], model.idx_vs[full_id] + model.nvs[full_id]))
    locked_v = [i for j in ids for i in range(model.idx_vs[j], model.idx_vs[j] + model.nvs[j])]
    small = dataclasses.replace(robot, model=reduced, visual_model=None,
                                arms=tuple(arm_of(reduced, ee) for ee in robot.end_effectors))
    return LockedJoints(full=robot, robot=small, names=tuple(model.names[j] for j in ids), q_lock=q.copy(),
                        free_q=np.array(free_q, dtype=int), free_v=np.array(free_v, dtype=int),
                        locked_v=np.array(locked_v, dtype=int))


def _renamed(model: pin.Model, names: dict[str, str]) -> pin.Model:
    """``model`` with its joints, and the frames of joints (fixed ones too), renamed by ``names``."""
    for j, name in enumerate(model.names):
        model.names[j] = names.get(name, name)
    for frame in model.frames:
        if frame.type in (pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT):
            frame.name = names.get(frame.name, frame.name)
    return model


__all__ = ["LockedJoints", "lock_joints"]
