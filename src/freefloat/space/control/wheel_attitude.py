"""Base attitude control with reaction wheels, composed with the arm's controller.

The arm's controller (computed torque on a joint reference, the detumbling law, or none) decides
how the arm joints move; the wheels decide how the base turns. Each control period:

1. The arm's law is evaluated on the arm's view of the state, the wheel rates set to zero: its
   GJM then carries the momentum ``M - H_0w Omega`` (eqs 84-88 with the wheels' stored momentum
   as the non-zero momentum term), so a detumbling solve stops the rows it is asked to with the
   wheels spinning. The arm accelerations it intends, ``a_P``, are the exact forward dynamics of
   its torques at that view (for computed torque on the exact model, ``qddot_d + Kp e + Kd edot``).
2. With ``F`` the base and the other free coordinates (the wheels, and the arm when it has no
   controller), the base and wheel rows of ``M a + b = tau`` give

   .. math:: M_{FF} a_F = \\tau_F - M_{FP} a_P - b_F, \\qquad \\tau_F = S_w^T \\tau_w,

   so the base angular acceleration is affine in the wheel torques, ``alpha = G tau_w + f``:
   ``f`` holds the arm's reaction (the coupling ``H_0m qddot`` and the velocity terms), fed
   forward. The wheel torques are the least-squares solution of ``G tau_w = alpha_d`` with the
   attitude law (computed torque on SO(3) in the base frame, the target held):

   .. math:: \\alpha_d = K_p \\log(R^T R_d) - K_d\\, \\omega_0 .

3. A wheel at its stored-momentum limit ``max_momentum`` that these torques would spin faster
   is held at its speed instead (the other wheels do what they can), and each torque is limited
   to ``max_torque``; every period a limit acts is counted and each start of a saturation is an
   event (:attr:`WheelAttitudeControl.events`), never a silent clip.
4. The arm torques are the inverse dynamics (RNEA) with the arm accelerations ``a_P`` and the
   base and wheel accelerations these wheel torques give: the arm moves as its law intends
   whatever the wheels do.

With three wheels whose axes span space (one about z on a planar base) and no limit reached,
the base angular acceleration is ``alpha_d`` exactly. On a robot whose loops are closed
(:class:`~freefloat.dynamics.closures.ClosedModel`, its arm joints passive) the affine map of step 2
is read from the closed dynamics instead, ``a(tau) = a(0) + sum_i a(e_i) - a(0)`` over the
wheel torques (their constraint forces included), so the base follows ``alpha_d`` there too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...dynamics.models.base import DynamicsModel
from ...dynamics.simulation import Controller
from ...errors import InvalidArgument
from ...robot.joints import JointCoordinates
from ...robot.wheels import Wheels

#: Singular values of ``G`` below this fraction of the largest are cut (wheels that cannot turn
#: the base about some axis leave that axis to itself).
RCOND = 1e-10


@dataclass(frozen=True)
class SaturationEvent:
    """A wheel reaching a limit.

    Attributes:
        t: time of the control period where it starts, s.
        wheel: the wheel's joint name.
        limit: ``"torque"`` (the law asked more than ``max_torque``) or ``"momentum"`` (the wheel
            is at ``max_momentum`` and the law asked it to spin faster).
        asked: the torque the law asked of the wheel, N m: before its torque limit (``"torque"``),
            or what the attitude alone asked (``"momentum"``).
    """

    t: float
    wheel: str
    limit: str
    asked: float


class BaseAttitude:
    """The base attitude error and angular velocity in the base-link frame.

    Free-flyer base: ``e = log3(R^T R_d)`` (3,) and ``omega`` the local angular velocity (3,);
    planar base: the yaw error wrapped to (-pi, pi] and the yaw rate, (1,) each.

    Args:
        base: ``"free"`` or ``"planar"``.
        target: the desired base-link rotation in the inertial frame (3, 3).
    """

    def __init__(self, base: str, target: np.ndarray):
        self.free = base == "free"
        self.target = np.asarray(target, dtype=float)
        self.rows = np.arange(3, 6) if self.free else np.array([2])
        self.yaw = float(np.arctan2(self.target[1, 0], self.target[0, 0]))

    def error(self, q: np.ndarray) -> np.ndarray:
        """Attitude error, rad ((3,) free, (1,) planar)."""
        if self.free:
            rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
            return pin.log3(rotation.T @ self.target)
        return np.array([np.angle(np.exp(1j * (self.yaw - np.arctan2(q[3], q[2]))))])

    def rate(self, v: np.ndarray) -> np.ndarray:
        """Base angular velocity in the base-link frame, rad/s ((3,) free, (1,) planar)."""
        return v[self.rows]


class WheelAttitudeControl:
    """Reaction wheels holding the base attitude while the arm's own law moves the arm.

    Implements :class:`~freefloat.dynamics.simulation.Controller` for the robot with wheels (the
    module docstring gives the law).

    Args:
        wheels: the robot with its wheels.
        arm: the arm's controller on the same robot (its torques on the wheels are ignored), or
            None: the arm joints are passive (zero torque).
        target: the desired base-link rotation (3, 3), inertial frame; None: the wheels get no
            torque (free wheels; the arm still moves as its law intends).
        kp: attitude stiffness, 1/s^2.
        kd: attitude damping, 1/s.
        closed: the plant's forward dynamics when its loops are closed (a
            :class:`~freefloat.dynamics.closures.ClosedModel` of its own, for the law alone: its
            ``acceleration(q, v, tau)``), with ``arm`` None; None: the tree's.
        t0: the time of the run's start on the clock the saturation events are told in, s.

    Attributes:
        events: each start of a saturation, in time order.
        saturated_periods: per wheel (nw,), the control periods in which a limit acted.
    """

    def __init__(self, wheels: Wheels, arm: Controller | None, target: np.ndarray | None, kp: float = 0.0,
                 kd: float = 0.0, closed: DynamicsModel | None = None, t0: float = 0.0):
        if closed is not None and arm is not None:
            raise InvalidArgument("WheelAttitudeControl: a closed loop's arm joints are passive (arm None)")
        robot = wheels.robot
        self.wheels, self.arm, self.kp, self.kd, self.closed, self.t0 = wheels, arm, kp, kd, closed, t0
        self.target = target
        self.model, self.data = robot.model, robot.model.createData()
        self.attitude = None if target is None else BaseAttitude(robot.base, target)
        self.coords = JointCoordinates(robot)
        nb, nv = robot.n_base, robot.model.nv
        self.nb = nb
        self.prescribed = wheels.arm_columns + nb if arm is not None else np.zeros(0, dtype=int)
        self.free = np.setdiff1d(np.arange(nv), self.prescribed)
        self.wheel_in_free = np.searchsorted(self.free, wheels.v_indices)
        self.tau_full = np.zeros(nv)
        self.events: list[SaturationEvent] = []
        self.saturated_periods = np.zeros(len(wheels.wheels), dtype=int)
        self._saturated = np.zeros((2, len(wheels.wheels)), dtype=bool)  # rows: torque, momentum
        self._wheel_angles = np.zeros(len(wheels.wheels))

    def continued(self, wheels: Wheels, arm: Controller | None, t0: float) -> WheelAttitudeControl:
        """The same law (target, gains) on ``wheels`` (the same wheels on another robot: a capture's
        merged robot) under the arm's controller ``arm``, for a run that starts at ``t0`` s of this
        law's clock: its saturation record (events, periods) continues this one's."""
        law = WheelAttitudeControl(wheels, arm, self.target, self.kp, self.kd, t0=self.t0 + t0)
        law.events, law.saturated_periods, law._saturated = self.events, self.saturated_periods, self._saturated
        return law

    def reference(self, t: float) -> np.ndarray | None:
        """The arm's reference (n_joints,), with the wheel rows at the wheels' measured angles of
        the last period (a wheel has no position reference); None without an arm controller or
        when the arm's law has none."""
        ref = None if self.arm is None else self.arm.reference(t)
        if ref is None:
            return None
        ref = np.array(ref, dtype=float)
        ref[self.wheels.columns] = self._wheel_angles
        return ref

    def arm_acceleration(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The accelerations the arm's law intends for the prescribed coordinates (len(P),):
        forward dynamics of all its torques (its wheel rows too: a computed-torque law couples
        them) at its view of the state (wheel rates zero)."""
        if self.arm is None:
            return np.zeros(0)
        view = self.wheels.without_rates(v)
        self.tau_full[:] = 0.0
        self.tau_full[self.nb:] = self.arm.torque(t, q, view)
        return pin.aba(self.model, self.data, q, view, self.tau_full)[self.prescribed]

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Joint torques (n_joints,): the arm's from inverse dynamics, the wheels' from the
        attitude law within their limits."""
        a_P = self.arm_acceleration(t, q, v)
        model, data, P, F = self.model, self.data, self.prescribed, self.free
        X = self.closed_response(q, v) if self.closed is not None else self.tree_response(q, v, a_P)
        tau_w = np.zeros(len(self.wheel_in_free))
        if self.attitude is not None:
            alpha_d = self.kp * self.attitude.error(q) - self.kd * self.attitude.rate(v)
            tau_w = self.wheel_torques(t, X, alpha_d, self.wheels.speeds(v))
        a = np.zeros(model.nv)
        a[P] = a_P
        a[F] = X[:, 0] + X[:, 1:] @ tau_w
        tau = np.zeros(model.nv)
        tau[P] = pin.rnea(model, data, q, v, a)[P]
        tau[self.wheels.v_indices] = tau_w
        self._wheel_angles = self.coords.get(q)[self.wheels.columns]
        return tau[self.nb:]

    def tree_response(self, q: np.ndarray, v: np.ndarray, a_P: np.ndarray) -> np.ndarray:
        """``X = [x0, Xw]`` (len(F), 1 + nw): the free coordinates' accelerations ``x0 + Xw tau_w``
        of the tree with ``a_P`` prescribed (the base and wheel rows of ``M a + b = tau``)."""
        model, data, P, F = self.model, self.data, self.prescribed, self.free
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        b = pin.nonLinearEffects(model, data, q, v)
        rhs = -b[F] - M[np.ix_(F, P)] @ a_P
        unit = np.zeros((len(F), len(self.wheel_in_free)))
        unit[self.wheel_in_free, np.arange(len(self.wheel_in_free))] = 1.0
        return np.linalg.solve(M[np.ix_(F, F)], np.column_stack((rhs, unit)))

    def closed_response(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``X = [x0, Xw]`` (nv, 1 + nw) of the closed loop (every coordinate free): its
        accelerations without wheel torque, and their change per unit torque of each wheel (the
        closed dynamics are affine in the torques)."""
        tau = np.zeros(self.model.nv)
        x0 = self.closed.acceleration(q, v, tau)
        columns = [x0]
        for i in self.wheels.v_indices:
            tau[:] = 0.0
            tau[i] = 1.0
            columns.append(self.closed.acceleration(q, v, tau) - x0)
        return np.column_stack(columns)

    def wheel_torques(self, t: float, X: np.ndarray, alpha_d: np.ndarray, speeds: np.ndarray) -> np.ndarray:
        """The wheel torques (nw,) for the base angular acceleration ``alpha_d`` within the limits.

        ``X = [x0, Xw]`` gives the free coordinates' accelerations ``a_F = x0 + Xw tau_w``
        (len(F), 1 + nw). The least-squares torques for ``alpha_d`` are asked first; a wheel
        at its momentum limit that they would spin faster is held at its speed instead (its
        acceleration relative to the base zero, the other wheels doing what they can for
        ``alpha_d``: least squares in the null space of the holding rows); then each torque is
        clipped to its limit. Each period a limit acts is counted, and each start of a wheel's
        torque or momentum saturation recorded as an event."""
        w, rows = self.wheels, self.attitude.rows  # base rows come first in F
        G, f = X[rows, 1:], X[rows, 0]
        A, a0 = X[self.wheel_in_free, 1:], X[self.wheel_in_free, 0]  # wheel accelerations a0 + A tau
        asked = np.linalg.pinv(G, rcond=RCOND) @ (alpha_d - f)
        full = np.abs(speeds) * w.inertias >= w.max_momenta
        at_speed = np.zeros(len(asked), dtype=bool)
        tau = asked
        for _ in w.wheels:  # holding some wheels may make another at its limit spin faster
            faster = full & ~at_speed & ((a0 + A @ tau) * speeds > 0.0)
            if not faster.any():
                break
            at_speed |= faster
            C = A[at_speed]
            held = np.linalg.pinv(C, rcond=RCOND) @ -a0[at_speed]
            _, sv, Vt = np.linalg.svd(C)
            N = Vt[np.count_nonzero(sv > RCOND * sv[0]):].T  # basis of C's null space (nw, nw - rank)
            tau = held + N @ np.linalg.pinv(G @ N, rcond=RCOND) @ (alpha_d - f - G @ held) if N.size else held
        clipped = np.clip(tau, -w.max_torques, w.max_torques)
        limited = np.array([clipped != tau, at_speed])
        for kind, i in zip(*np.nonzero(limited & ~self._saturated)):
            self.events.append(SaturationEvent(self.t0 + t, w.wheels[i].name, ("torque", "momentum")[kind],
                                               float((tau, asked)[kind][i])))
        self.saturated_periods += limited.any(axis=0)
        self._saturated = limited
        return clipped


__all__ = ["RCOND", "BaseAttitude", "SaturationEvent", "WheelAttitudeControl"]
