"""Detumbling through a closed loop: the detumbling solve of eqs 115-120 projected on the closure
constraints, and computed torque in the constrained dynamics with the loop's internal wrench chosen.

After a two-arm grasp the target closes a loop: base - arm 1 - target - arm 2 - base. With the
base eliminated by momentum conservation (Pinocchio coordinates ``v = [v_b; qdot]``, ``M``
partitioned at the base), a velocity ``J v`` of any rows becomes ``J* qdot + J_b M_bb^-1 p_b``
with ``J* = J_q - J_b M_bb^-1 M_bq`` (the generalized Jacobian, eq 82, of those rows) and
``p_b = (M v)_b``. Each control period:

1. **Rates**: the least-norm mission-joint rates that stop the task rows (eq 115 through the
   GJM) *and* keep the closure's relative velocity at ``-beta e`` (the loop closed):
   ``[J*_rows; J*_c] qdot_S = [-J0E H0^-1 M; -J_c,b M_bb^-1 p_b - beta e]``.
2. **Accelerations**: ``qddot_d = (qdot_d - qdot_d^-)/T + K_d (qdot_d - qdot)`` (the law of
   :mod:`.detumbling_control`), projected on the closure's acceleration constraint
   ``J*_c qddot = -gamma - 2 beta J_c v - beta^2 e + J_c,b M_bb^-1 (h_b - J_c,b^T lambda)``.
3. **Internal wrench**: the closure force ``lambda`` (what arm 2 applies on the target at its
   grasp) is free: the loop's null space. It is chosen so that each hand carries half of the
   target's inertial wrench (``m a_c``, ``I w' + w x I w`` at its CoM) plus a squeeze ``s`` (N)
   along the line from grasp 2 to grasp 1: the internal wrench is then ``[s u; 0]``.
4. **Torques**: ``tau = H* qddot + c* - J*_c^T lambda`` (exact model). Torques are affine in
   ``qddot_d``: when one exceeds ``torque_limit`` (N m), the largest share of ``qddot_d`` within
   the limit is taken, so the internal wrench stays as chosen (only when even zero ``qddot_d``
   exceeds it are the torques scaled down as a whole).

With these torques the plant's constrained dynamics (:class:`~freefloat.dynamics.closures.ClosedModel`,
the same Baumgarte rate) gives exactly ``qddot`` and ``lambda`` (tests/test_loop_detumbling.py).
The compiled loop runs the same law in C++ (:meth:`LoopDetumblingController.compiled_law`); this
class stays the readable reference.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
import pinocchio as pin

from ...dynamics import gjm
from ...dynamics.closures import Closure, frame_motion, kinematics, stacked
from ...dynamics.compiled import closure_arrays
from ...robot.robot import Robot
from ..detumbling import check_task


@dataclass
class LoopLog:
    """What the law planned, one entry per control period.

    Attributes:
        t: period start, s.
        rows_residual: largest remaining velocity of the task rows in the rate solve.
        saturated: whether the torques were scaled down to the limit.
    """

    t: list[float] = field(default_factory=list)
    rows_residual: list[float] = field(default_factory=list)
    saturated: list[bool] = field(default_factory=list)


@dataclass
class LoopDetumblingLaw:
    """The two-hand detumbling law (``LoopDetumblingController``, steps 1-4 of its module
    docstring) as the compiled loop runs it (``cpp/sim/loop_detumbling_law.hpp``).

    Attributes:
        rows: stacked end-effector rows to stop (r,), into the 6k rows ``[v_E; w_E]``.
        joints: mission joint indices (s,).
        kd: rate gain, 1/s.
        period: T, the backward-difference period, s.
        baumgarte: the closure's Baumgarte rate beta, 1/s.
        squeeze: s, N.
        torque_limit: N m per joint; 0: none.
        closure: the weld between the second hand (frame 1) and its grasp on the target.
        target_joint, target_placement: the frame at the target's CoM (principal axes).
        mass, inertia: the target's mass (kg) and principal moments (3,), kg m^2.
        first_joint, first_placement: the first hand's frame.
        previous: the previous period's ``qdot_d`` (n,), or None.
        force: the previous period's closure force lambda (6,).
        report: called after each compiled chunk with ``(previous, force, t, rows_residual,
            saturated)``, the last three the log entries of the chunk's periods (lists).
    """

    rows: np.ndarray
    joints: np.ndarray
    kd: float
    period: float
    baumgarte: float
    squeeze: float
    torque_limit: float
    closure: Any
    target_joint: int
    target_placement: pin.SE3
    mass: float
    inertia: np.ndarray
    first_joint: int
    first_placement: pin.SE3
    previous: np.ndarray | None
    force: np.ndarray
    report: Callable[[np.ndarray | None, np.ndarray, list, list, list], None]

    kind: ClassVar[str] = "loop_detumbling"
    #: It works on the plant's closures: never on a robot of the controller's own.
    plant_bound: ClassVar[bool] = True

    def install(self, simulation: Any, robot: Robot) -> None:
        """Hand this law to the compiled loop (``_sim.Simulation.set_loop_detumbling``)."""
        simulation.set_loop_detumbling(
            [int(r) for r in self.rows], [int(j) for j in self.joints], self.kd, self.period, self.baumgarte,
            self.squeeze, self.torque_limit, closure_arrays(self.closure), int(self.target_joint),
            self.target_placement.homogeneous, self.mass, np.asarray(self.inertia, float), int(self.first_joint),
            self.first_placement.homogeneous, self.previous, np.asarray(self.force, float))

    def collect(self, simulation: Any) -> None:
        """Hand the state and log the compiled loop kept over a chunk to :attr:`report`."""
        self.report(*simulation.take_loop_detumbling_state())


class LoopDetumblingController:
    """Detumble a target held by two hands (module docstring).

    Args:
        robot: the merged robot (target attached to the first hand's body).
        closure: the weld between the second hand and its grasp frame on the target.
        target_frame: the frame at the target's CoM (axes: its principal axes).
        target_mass, target_inertia: kg, principal moments kg m^2 (3,).
        rows: stacked end-effector rows to stop (:func:`freefloat.space.detumbling.task_rows`).
        joints: mission joint indices (:func:`freefloat.space.detumbling.joint_indices`).
        control_period: T, s.
        kd: rate gain, 1/s.
        baumgarte: the closure's Baumgarte rate beta, 1/s (the plant's).
        squeeze: s, N (0: no internal force).
        torque_limit: N m per joint; 0: none.
    """

    def __init__(self, robot: Robot, closure: Closure, target_frame: str, target_mass: float,
                 target_inertia: np.ndarray, rows: np.ndarray, joints: np.ndarray, control_period: float,
                 kd: float = 100.0, baumgarte: float = 0.0, squeeze: float = 0.0, torque_limit: float = 0.0):
        check_task(rows, joints, "least_squares")
        if closure.kind.name != "weld":
            raise ValueError(f"closure '{closure.name}' is a {closure.kind.name}; a two-hand grasp is a weld")
        self.robot, self.closure, self.rows, self.joints = robot, closure, rows, joints
        self.T, self.kd, self.beta, self.squeeze, self.limit = control_period, kd, baumgarte, squeeze, torque_limit
        self.model, self.data = robot.model, robot.model.createData()
        self.target = self.model.frames[self.model.getFrameId(target_frame)]
        self.mass, self.inertia = float(target_mass), np.diag(np.asarray(target_inertia, float))
        self.first_grasp = self.model.frames[self.model.getFrameId(robot.end_effectors[0])]
        self._qdot_prev: np.ndarray | None = None
        self._force = np.zeros(6)
        self.log = LoopLog()

    def _share(self, a: np.ndarray) -> np.ndarray:
        """Step 3's closure force (6,), frame-1 axes, at the state ``self.data`` holds."""
        return grasp_share(self.model, self.data, self.closure, self.target, self.mass, self.inertia,
                           self.first_grasp, a, self.squeeze).force

    def compiled_law(self) -> LoopDetumblingLaw:
        """This law for the compiled loop (:mod:`freefloat.dynamics.compiled`), with the state it
        has so far (previous rates and closure force); its log is kept complete through it."""
        return LoopDetumblingLaw(self.rows, self.joints, self.kd, self.T, self.beta, self.squeeze, self.limit,
                                 self.closure, self.target.parentJoint, self.target.placement, self.mass,
                                 np.diag(self.inertia), self.first_grasp.parentJoint, self.first_grasp.placement,
                                 self._qdot_prev, self._force, self._absorb)

    def _absorb(self, previous: np.ndarray | None, force: np.ndarray, t: list, residuals: list, saturated: list) -> None:
        """Take over the compiled law's state and log after a chunk (see :class:`LoopDetumblingLaw`)."""
        self._qdot_prev, self._force = previous, force
        self.log.t.extend(t)
        self.log.rows_residual.extend(residuals)
        self.log.saturated.extend(saturated)

    def reference(self, t: float) -> np.ndarray | None:
        """No joint reference (the rates are solved each period)."""
        return None

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (n,) at time ``t`` for the measured state."""
        model, data, nb = self.model, self.data, self.robot.n_base
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        h = pin.nonLinearEffects(model, data, q, v)
        kinematics(model, data, q, v)
        e, Jc, gamma = stacked([self.closure], model, data)
        Mbb, Mbq = M[:nb, :nb], M[:nb, nb:]
        Jcb, Jcq = Jc[:, :nb], Jc[:, nb:]
        base_coupling = np.linalg.solve(Mbb, np.column_stack((Mbq, M[:nb] @ v, h[:nb], Jcb.T)))
        n = Mbq.shape[1]
        to_base, momentum, bias, reaction = (base_coupling[:, :n], base_coupling[:, n], base_coupling[:, n + 1],
                                             base_coupling[:, n + 2:])
        Jc_star = Jcq - Jcb @ to_base
        qdot_d = self._rates(q, v, Jc_star, Jcb @ momentum + self.beta * e)
        qddot_d = self.kd * (qdot_d - v[nb:])
        if self._qdot_prev is not None:
            qddot_d += (qdot_d - self._qdot_prev) / self.T
        self._qdot_prev = qdot_d
        projector = np.linalg.pinv(Jc_star, rcond=1e-10)
        H_star = M[nb:, nb:] - Mbq.T @ to_base
        c_star = h[nb:] - Mbq.T @ bias

        def torques(desired: np.ndarray) -> np.ndarray:
            """Steps 2-4 for the desired joint accelerations (affine in them)."""
            force = self._force
            for _ in range(2):  # lambda moves the base only through J_c,b (zero when both frames ride on the tree)
                target = -gamma - 2.0 * self.beta * (Jc @ v) - self.beta**2 * e + Jcb @ (bias - reaction @ force)
                qddot = desired - projector @ (Jc_star @ desired - target)
                force = self._share(np.concatenate((reaction @ force - to_base @ qddot - bias, qddot)))
            self._force = force
            return H_star @ qddot + c_star - Jc_star.T @ force

        tau = torques(qddot_d)
        saturated = bool(self.limit > 0.0 and np.abs(tau).max() > self.limit)
        if saturated:  # the largest share s of qddot_d within the limit; the internal wrench stays as chosen
            tau = self._within_limit(torques(0.0 * qddot_d), tau)
        self.log.t.append(t)
        self.log.saturated.append(saturated)
        return tau

    def _within_limit(self, hold: np.ndarray, full: np.ndarray) -> np.ndarray:
        """``hold + s (full - hold)`` with the largest ``s`` in [0, 1] keeping every torque within
        the limit (torques are affine in the desired accelerations); when ``hold`` (no desired
        acceleration) already exceeds it, ``hold`` scaled down to it."""
        peak = np.abs(hold).max()
        if peak >= self.limit:
            return hold * (self.limit / peak)
        step = full - hold
        with np.errstate(divide="ignore", invalid="ignore"):
            room = np.where(step > 0, (self.limit - hold) / step, np.where(step < 0, (-self.limit - hold) / step, np.inf))
        return hold + min(1.0, float(room.min())) * step

    def _rates(self, q: np.ndarray, v: np.ndarray, Jc_star: np.ndarray, closure_drift: np.ndarray) -> np.ndarray:
        """Least-norm mission-joint rates (n,) stopping the rows with the loop kept closed (step 1)."""
        state = gjm.compute(self.robot, q, v)
        rows_drift = state.J0E[self.rows] @ np.linalg.solve(state.H0, state.momentum_base)
        A = np.vstack((state.Jstar[np.ix_(self.rows, self.joints)], Jc_star[:, self.joints]))
        b = np.concatenate((-rows_drift, -closure_drift))
        qdot = np.zeros(self.robot.n_joints)
        qdot[self.joints] = np.linalg.pinv(A, rcond=1e-10) @ b
        self.log.rows_residual.append(float(np.abs(state.Jstar[self.rows] @ qdot + rows_drift).max(initial=0.0)))
        return qdot


@dataclass(frozen=True)
class GraspShare:
    """The equal share of a held target's inertial wrench at one state and acceleration.

    Attributes:
        force: the closure force lambda (6,) that gives each hand half the target's inertial wrench
            plus ``squeeze`` N along ``direction``: [force; moment about the second grasp point],
            in the closure's frame-1 axes (the second hand's), acting on the target.
        hand_rotation: frame 1's orientation, inertial (3, 3).
        grasp: the second grasp point, inertial, m (3,).
        com: the target's CoM, inertial, m (3,).
        direction: unit vector from the second grasp point to the first, inertial (3,).
    """

    force: np.ndarray
    hand_rotation: np.ndarray
    grasp: np.ndarray
    com: np.ndarray
    direction: np.ndarray


def grasp_share(model: pin.Model, data: pin.Data, closure: Closure, target: pin.Frame, mass: float,
                inertia: np.ndarray, first_grasp: pin.Frame, a: np.ndarray, squeeze: float) -> GraspShare:
    """Step 3 of the law at the state ``data`` holds (:func:`~freefloat.dynamics.closures.kinematics`)
    and the acceleration ``a`` (nv,): the target's inertial wrench at its CoM, ``[m a_c; I w' + w x I w]``
    (``target``: its CoM frame, principal axes; ``inertia`` (3, 3) principal, kg m^2), halved, plus
    the squeeze along the line between the grasps (``first_grasp``: the first hand's frame)."""
    motion = frame_motion(model, data, target.parentJoint, target.placement)
    R, w = motion.pose.rotation, motion.angular_velocity
    I_world = R @ inertia @ R.T
    linear = mass * (motion.jacobian[:3] @ a + motion.acceleration)
    angular = I_world @ (motion.jacobian[3:] @ a + motion.angular_acceleration) + np.cross(w, I_world @ w)
    hand = data.oMi[closure.joint1] * closure.placement1
    grasp = (data.oMi[closure.joint2] * closure.placement2).translation
    other = (data.oMi[first_grasp.parentJoint] * first_grasp.placement).translation
    direction = (other - grasp) / max(np.linalg.norm(other - grasp), 1e-12)
    f = 0.5 * linear + squeeze * direction
    moment = 0.5 * angular - np.cross(grasp - motion.pose.translation, f)
    return GraspShare(np.concatenate((hand.rotation.T @ f, hand.rotation.T @ moment)), hand.rotation, grasp,
                      motion.pose.translation, direction)


def internal_wrench(robot: Robot, closure: Closure, target_frame: str, target_mass: float,
                    target_inertia: np.ndarray, q: np.ndarray, v: np.ndarray, a: np.ndarray,
                    force: np.ndarray) -> tuple[float, np.ndarray]:
    """The loop's internal wrench at a state with acceleration ``a`` and closure force ``force``:
    arm 2's wrench on the target minus half the target's inertial wrench, at the target's CoM,
    inertial axes, [force; moment] (6,), and its force along grasp 2 -> grasp 1 (the squeeze, N)."""
    model = robot.model
    data = model.createData()
    kinematics(model, data, q, v)
    frames = [model.frames[model.getFrameId(name)] for name in (target_frame, robot.end_effectors[0])]
    share = grasp_share(model, data, closure, frames[0], float(target_mass),
                        np.diag(np.asarray(target_inertia, float)), frames[1], a, 0.0)
    df = share.hand_rotation @ (force[:3] - share.force[:3])
    dn = share.hand_rotation @ (force[3:] - share.force[3:])
    return float(df @ share.direction), np.concatenate((df, dn + np.cross(share.grasp - share.com, df)))
